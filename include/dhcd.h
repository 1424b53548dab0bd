/*
 * dhcd — Distance Hierarchy collision detection for deformable triangle meshes: C ABI.
 *
 * Hand-written; tests/capi.rs checks that every dhcd_* function and DHCD_* constant
 * declared here is exported by the library (src/capi.rs) and vice versa.
 * See docs/LINKING_FROM_C.md.
 *
 * Conventions:
 *  - fallible functions return DHCD_OK (0) or a negative DHCD_ERR_* code; then
 *    dhcd_last_error_message() describes the failure (per thread);
 *  - arrays are flat: positions are x,y,z per vertex (3 * vertex_count floats),
 *    triangles are 3 vertex indices each (3 * triangle_count uint32_t);
 *  - triangle indices in results are the caller's original indices;
 *  - `threads`: 1 = calling thread, 0 = all cores, n = a pool of n threads
 *    (results never depend on it);
 *  - a handle must not be used from two threads at once.
 */
#ifndef DHCD_H
#define DHCD_H

#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

#define DHCD_OK 0
#define DHCD_ERR_NULL -1
#define DHCD_ERR_INVALID_ARGUMENT -2
#define DHCD_ERR_INVALID_MESH -3
#define DHCD_ERR_LENGTH_MISMATCH -4
#define DHCD_ERR_WRONG_KIND -5
#define DHCD_ERR_UNKNOWN_OBJECT -6
#define DHCD_ERR_STALE_CONTACT -7
#define DHCD_ERR_PANIC -8

#define DHCD_METHOD_DH 0
#define DHCD_METHOD_SPHERE 1
#define DHCD_METHOD_AABB 2

/* Opaque handles. */
typedef struct DhcdHierarchy DhcdHierarchy;
typedef struct DhcdScene DhcdScene;

/* Counted work of a query (the cost model's N_V, N_P, N_U, and the contacts). */
typedef struct DhcdCounters {
  uint64_t bv_tests;
  uint64_t prim_tests;
  uint64_t bv_updates;
  uint64_t contacts;
} DhcdCounters;

/* count pairs at pairs[2k], pairs[2k+1], sorted; pairs is NULL when count == 0.
 * Release with dhcd_contacts_free. */
typedef struct DhcdContacts {
  uint32_t *pairs;
  size_t count;
  DhcdCounters counters;
} DhcdContacts;

/* count quadruples [object_a, tri_a, object_b, tri_b] at pairs[4k..4k+3], sorted;
 * object_a < object_b (== for self-contacts). Release with dhcd_scene_contacts_free. */
typedef struct DhcdSceneContacts {
  uint64_t *pairs;
  size_t count;
  DhcdCounters counters;
} DhcdSceneContacts;

/* Message of the last failed call on this thread; never NULL; valid until the next
 * failing call on this thread. */
const char *dhcd_last_error_message(void);

/* Hierarchies of single objects. levels: 0 for the adaptive default tree (leaves of at
 * most 8 triangles), 1..16 for the paper's fixed depth (the paper uses 5). */
int dhcd_hierarchy_new(int method, uint32_t levels, const float *positions,
                       size_t vertex_count, const uint32_t *triangles,
                       size_t triangle_count, DhcdHierarchy **out);
void dhcd_hierarchy_free(DhcdHierarchy *h);
int dhcd_hierarchy_method(const DhcdHierarchy *h, int *out);
int dhcd_hierarchy_update_positions(DhcdHierarchy *h, const float *positions,
                                    size_t vertex_count);

/* Queries. a and b must be different handles of the same kind. */
int dhcd_collide(DhcdHierarchy *a, DhcdHierarchy *b, uint32_t threads, DhcdContacts *out);
int dhcd_self_collide(DhcdHierarchy *h, uint32_t threads, DhcdContacts *out);
void dhcd_contacts_free(DhcdContacts *c);

/* Contact detail: segments receives 6 floats (p.xyz, q.xyz) per pair. For
 * self-contacts pass the same hierarchy as a and b. With count == 0, pairs and
 * segments may be NULL. */
int dhcd_contact_segments(const DhcdHierarchy *a, const DhcdHierarchy *b,
                          const uint32_t *pairs, size_t count, float *segments);

/* Scenes of many objects. Object ids are never reused. */
int dhcd_scene_new(int method, uint32_t levels, DhcdScene **out);
void dhcd_scene_free(DhcdScene *s);
int dhcd_scene_add(DhcdScene *s, const float *positions, size_t vertex_count,
                   const uint32_t *triangles, size_t triangle_count, int self_collision,
                   uint64_t *out_id);
int dhcd_scene_remove(DhcdScene *s, uint64_t id);
int dhcd_scene_update_positions(DhcdScene *s, uint64_t id, const float *positions,
                                size_t vertex_count);
int dhcd_scene_set_self_collision(DhcdScene *s, uint64_t id, int on);
int dhcd_scene_contacts(DhcdScene *s, uint32_t threads, DhcdSceneContacts *out);
void dhcd_scene_contacts_free(DhcdSceneContacts *c);

#ifdef __cplusplus
}
#endif

#endif /* DHCD_H */
