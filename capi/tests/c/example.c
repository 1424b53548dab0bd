/* dhcd from C: build meshes, deform, collide, self-collide, a scene; check and print.
 * Exits non-zero on any mismatch. Built and run by capi/tests/c/run.sh. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "dhcd.h"

static int failures = 0;

#define CHECK(cond)                                                         \
  do {                                                                      \
    if (!(cond)) {                                                          \
      fprintf(stderr, "%s:%d: check failed: %s\n", __FILE__, __LINE__, #cond); \
      failures++;                                                           \
    }                                                                       \
  } while (0)

#define OK(call)                                                            \
  do {                                                                      \
    int rc_ = (call);                                                       \
    if (rc_ != DHCD_OK) {                                                   \
      fprintf(stderr, "%s:%d: %s failed (%d): %s\n", __FILE__, __LINE__, #call, rc_, \
              dhcd_last_error_message());                                   \
      exit(1);                                                              \
    }                                                                       \
  } while (0)

/* An n x n grid of unit cells scaled by `cell`: (n+1)^2 vertices, 2 n^2 triangles. */
static void grid(int n, float cell, float *pos, uint32_t *tris) {
  for (int j = 0; j <= n; j++)
    for (int i = 0; i <= n; i++) {
      float *p = pos + 3 * (j * (n + 1) + i);
      p[0] = i * cell;
      p[1] = j * cell;
      p[2] = 0.0f;
    }
  int t = 0;
  for (int j = 0; j < n; j++)
    for (int i = 0; i < n; i++) {
      uint32_t a = j * (n + 1) + i, b = a + 1, c = a + n + 2, d = a + n + 1;
      uint32_t *q = tris + 3 * t;
      q[0] = a; q[1] = b; q[2] = c;
      q[3] = a; q[4] = c; q[5] = d;
      t += 2;
    }
}

static int sorted2(const DhcdContacts *c) {
  for (size_t k = 1; k < c->count; k++) {
    const uint32_t *p = c->pairs + 2 * (k - 1), *q = c->pairs + 2 * k;
    if (!(p[0] < q[0] || (p[0] == q[0] && p[1] < q[1]))) return 0;
  }
  return 1;
}

static int same(const DhcdContacts *x, const DhcdContacts *y) {
  return x->count == y->count &&
         (x->count == 0 || memcmp(x->pairs, y->pairs, 2 * x->count * sizeof(uint32_t)) == 0);
}

int main(void) {
  /* 1. Two single triangles crossing: exactly the pair [0, 0], and its segment. */
  const float ta[9] = {0, 0, 0, 2, 0, 0, 0, 2, 0};
  const float tb[9] = {0.5f, 0.5f, -1, 0.5f, 0.5f, 1, 0.2f, 0.8f, 0};
  const uint32_t one[3] = {0, 1, 2};
  DhcdHierarchy *a = NULL, *b = NULL;
  OK(dhcd_hierarchy_new(DHCD_METHOD_DH, 5, ta, 3, one, 1, &a));
  OK(dhcd_hierarchy_new(DHCD_METHOD_DH, 5, tb, 3, one, 1, &b));
  DhcdContacts c = {0};
  OK(dhcd_collide(a, b, 1, &c));
  CHECK(c.count == 1 && c.pairs[0] == 0 && c.pairs[1] == 0);
  float seg[6];
  OK(dhcd_contact_segments(a, b, c.pairs, c.count, seg));
  printf("single triangles: %zu contact, segment (%g %g %g)-(%g %g %g)\n", c.count, seg[0],
         seg[1], seg[2], seg[3], seg[4], seg[5]);
  /* The segment runs from (0.5, 0.5, 0) to (0.2, 0.8, 0), in either order. */
  float lo = fminf(seg[0], seg[3]), hi = fmaxf(seg[0], seg[3]);
  CHECK(fabsf(lo - 0.2f) < 1e-5f && fabsf(hi - 0.5f) < 1e-5f);
  CHECK(seg[2] == 0.0f && seg[5] == 0.0f);
  dhcd_contacts_free(&c);
  CHECK(c.pairs == NULL && c.count == 0);

  /* Deform: move B away; no contacts. */
  float far[9];
  for (int k = 0; k < 9; k++) far[k] = tb[k] + (k % 3 == 0 ? 10.0f : 0.0f);
  OK(dhcd_hierarchy_update_positions(b, far, 3));
  OK(dhcd_collide(a, b, 1, &c));
  CHECK(c.count == 0 && c.pairs == NULL);
  OK(dhcd_contact_segments(a, b, c.pairs, c.count, NULL)); /* empty: nothing to write */
  dhcd_contacts_free(&c);

  /* Errors: null, wrong length, same handle twice, wrong kind. */
  CHECK(dhcd_collide(a, NULL, 1, &c) == DHCD_ERR_NULL);
  printf("expected error: %s\n", dhcd_last_error_message());
  CHECK(dhcd_hierarchy_update_positions(b, far, 2) == DHCD_ERR_LENGTH_MISMATCH);
  CHECK(dhcd_collide(a, a, 1, &c) == DHCD_ERR_INVALID_ARGUMENT);
  DhcdHierarchy *box = NULL;
  OK(dhcd_hierarchy_new(DHCD_METHOD_AABB, 5, ta, 3, one, 1, &box));
  CHECK(dhcd_collide(a, box, 1, &c) == DHCD_ERR_WRONG_KIND);
  printf("expected error: %s\n", dhcd_last_error_message());
  const uint32_t bad[3] = {0, 1, 7};
  DhcdHierarchy *none = NULL;
  CHECK(dhcd_hierarchy_new(DHCD_METHOD_DH, 5, ta, 3, bad, 1, &none) == DHCD_ERR_INVALID_MESH);
  CHECK(none == NULL);
  dhcd_hierarchy_free(box);
  dhcd_hierarchy_free(a);
  dhcd_hierarchy_free(b);

  /* 2. Two grids, the second folded up through the first: contacts for every kind, the
   * same set for every kind and thread count. */
  enum { N = 12 };
  const size_t nv = (N + 1) * (N + 1), nt = 2 * N * N;
  float *g = malloc(3 * nv * sizeof(float)), *h = malloc(3 * nv * sizeof(float));
  uint32_t *gt = malloc(3 * nt * sizeof(uint32_t));
  grid(N, 1.0f / N, g, gt);
  /* h: the grid turned vertical (y -> z), shifted to cross the first at y = 0.53. */
  for (size_t v = 0; v < nv; v++) {
    h[3 * v + 0] = g[3 * v + 0] + 0.03f;
    h[3 * v + 1] = 0.53f + 0.05f * sinf(7.0f * g[3 * v + 0]);
    h[3 * v + 2] = g[3 * v + 1] - 0.5f;
  }
  DhcdContacts first = {0};
  const int methods[3] = {DHCD_METHOD_DH, DHCD_METHOD_SPHERE, DHCD_METHOD_AABB};
  const char *names[3] = {"dh", "sphere", "aabb"};
  for (int m = 0; m < 3; m++) {
    DhcdHierarchy *ga = NULL, *gb = NULL;
    OK(dhcd_hierarchy_new(methods[m], 4, g, nv, gt, nt, &ga));
    OK(dhcd_hierarchy_new(methods[m], 4, g, nv, gt, nt, &gb)); /* rest pose: flat */
    OK(dhcd_hierarchy_update_positions(gb, h, nv));            /* deform */
    DhcdContacts seq = {0}, par = {0};
    OK(dhcd_collide(ga, gb, 1, &seq));
    OK(dhcd_hierarchy_update_positions(gb, h, nv)); /* same pose: lazily refitted again */
    OK(dhcd_collide(ga, gb, 2, &par));
    CHECK(seq.count > 0 && sorted2(&seq) && same(&seq, &par));
    CHECK(seq.counters.contacts == seq.count);
    printf("grids, %s: %zu contacts, N_V %llu, N_P %llu, N_U %llu\n", names[m], seq.count,
           (unsigned long long)seq.counters.bv_tests, (unsigned long long)seq.counters.prim_tests,
           (unsigned long long)seq.counters.bv_updates);
    if (m == 0) {
      first = seq;
    } else {
      CHECK(same(&first, &seq));
      dhcd_contacts_free(&seq);
    }
    dhcd_contacts_free(&par);
    dhcd_hierarchy_free(ga);
    dhcd_hierarchy_free(gb);
  }

  /* 3. Self-collision: one mesh made of both grids (disjoint vertex sets) has exactly
   * the contacts between them, with the second grid's triangles offset by nt. */
  float *both = malloc(6 * nv * sizeof(float));
  uint32_t *bt = malloc(6 * nt * sizeof(uint32_t));
  memcpy(both, g, 3 * nv * sizeof(float));
  memcpy(both + 3 * nv, h, 3 * nv * sizeof(float));
  for (size_t k = 0; k < 3 * nt; k++) {
    bt[k] = gt[k];
    bt[3 * nt + k] = gt[k] + (uint32_t)nv;
  }
  DhcdHierarchy *s = NULL;
  OK(dhcd_hierarchy_new(DHCD_METHOD_SPHERE, 5, both, 2 * nv, bt, 2 * nt, &s));
  DhcdContacts self = {0};
  OK(dhcd_self_collide(s, 0, &self));
  CHECK(self.count == first.count);
  for (size_t k = 0; k < self.count && k < first.count; k++) {
    CHECK(self.pairs[2 * k] == first.pairs[2 * k]);
    CHECK(self.pairs[2 * k + 1] == first.pairs[2 * k + 1] + nt);
  }
  printf("self-collision: %zu contacts\n", self.count);
  DhcdContacts again = {0};
  OK(dhcd_self_collide(s, 0, &again)); /* the same pose again: the same contacts */
  CHECK(same(&self, &again));
  dhcd_contacts_free(&again);
  dhcd_contacts_free(&self);
  dhcd_hierarchy_free(s);

  /* 4. A scene: the two grids and a far-away third; contacts only between 0 and 1. */
  DhcdScene *scene = NULL;
  OK(dhcd_scene_new(DHCD_METHOD_DH, 4, &scene));
  uint64_t id0, id1, id2;
  OK(dhcd_scene_add(scene, g, nv, gt, nt, 0, &id0));
  OK(dhcd_scene_add(scene, g, nv, gt, nt, 0, &id1));
  OK(dhcd_scene_add(scene, g, nv, gt, nt, 1, &id2));
  CHECK(id0 == 0 && id1 == 1 && id2 == 2);
  OK(dhcd_scene_update_positions(scene, id1, h, nv));
  float *crossing = malloc(3 * nv * sizeof(float)); /* h's pose, before moving it away */
  memcpy(crossing, h, 3 * nv * sizeof(float));
  for (size_t v = 0; v < nv; v++) h[3 * v + 0] += 100.0f;
  OK(dhcd_scene_update_positions(scene, id2, h, nv));
  DhcdSceneContacts sc = {0};
  OK(dhcd_scene_contacts(scene, 2, &sc));
  CHECK(sc.count == first.count);
  for (size_t k = 0; k < sc.count && k < first.count; k++) {
    const uint64_t *q = sc.pairs + 4 * k;
    CHECK(q[0] == id0 && q[2] == id1);
    CHECK(q[1] == first.pairs[2 * k] && q[3] == first.pairs[2 * k + 1]);
  }
  printf("scene: %zu contacts, N_V %llu\n", sc.count, (unsigned long long)sc.counters.bv_tests);
  dhcd_scene_contacts_free(&sc);
  OK(dhcd_scene_remove(scene, id1));
  CHECK(dhcd_scene_remove(scene, id1) == DHCD_ERR_UNKNOWN_OBJECT);
  printf("expected error: %s\n", dhcd_last_error_message());
  OK(dhcd_scene_contacts(scene, 1, &sc));
  CHECK(sc.count == 0);
  dhcd_scene_contacts_free(&sc);

  /* Several objects in one call: entry k gives object ids[k] the vertex_counts[k] vertices
   * at poses[k]. Every entry is checked before any is applied, so a repeated or removed id
   * moves nothing. Then id2 takes the crossing pose (and id0 its flat one again): id0 and
   * id2 have exactly the contacts id0 and id1 had. */
  const uint64_t ids[2] = {id2, id0};
  const float *poses[2] = {crossing, g};
  const size_t vertex_counts[2] = {nv, nv};
  const uint64_t twice[2] = {id2, id2}, removed[2] = {id2, id1};
  CHECK(dhcd_scene_update_many(scene, twice, poses, vertex_counts, 2, 1) ==
        DHCD_ERR_REPEATED_OBJECT);
  printf("expected error: %s\n", dhcd_last_error_message());
  CHECK(dhcd_scene_update_many(scene, removed, poses, vertex_counts, 2, 1) ==
        DHCD_ERR_UNKNOWN_OBJECT);
  OK(dhcd_scene_contacts(scene, 1, &sc));
  CHECK(sc.count == 0); /* nothing moved */
  dhcd_scene_contacts_free(&sc);
  OK(dhcd_scene_update_many(scene, ids, poses, vertex_counts, 2, 2));
  OK(dhcd_scene_update_many(scene, NULL, NULL, NULL, 0, 1)); /* no entries: nothing to do */
  OK(dhcd_scene_contacts(scene, 1, &sc));
  CHECK(sc.count == first.count);
  for (size_t k = 0; k < sc.count && k < first.count; k++) {
    const uint64_t *q = sc.pairs + 4 * k;
    CHECK(q[0] == id0 && q[2] == id2);
    CHECK(q[1] == first.pairs[2 * k] && q[3] == first.pairs[2 * k + 1]);
  }
  printf("scene after dhcd_scene_update_many: %zu contacts\n", sc.count);
  dhcd_scene_contacts_free(&sc);
  /* One call per simulation step: the same update, then the contacts (one trip to the
   * thread pool instead of two). The poses are the same, so are the contacts. */
  OK(dhcd_scene_step(scene, ids, poses, vertex_counts, 2, 2, &sc));
  CHECK(sc.count == first.count);
  printf("scene after dhcd_scene_step: %zu contacts\n", sc.count);
  dhcd_scene_contacts_free(&sc);
  dhcd_scene_free(scene);
  free(crossing);

  dhcd_contacts_free(&first);
  free(g);
  free(h);
  free(gt);
  free(both);
  free(bt);
  if (failures) {
    fprintf(stderr, "%d checks failed\n", failures);
    return 1;
  }
  printf("all checks passed\n");
  return 0;
}
