/* dhcd from C: build meshes, deform, collide, self-collide, a scene, f64 hierarchies,
 * proximity and continuous collision detection; check and print.
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

/* Whether n elements of size `size` at x and y are equal (both NULL when n == 0). */
static int same_array(const void *x, const void *y, size_t n, size_t size) {
  return n == 0 ? x == NULL && y == NULL : memcmp(x, y, n * size) == 0;
}

static int same_proximity(const DhcdProximity *x, const DhcdProximity *y) {
  return x->vf_count == y->vf_count && x->fv_count == y->fv_count &&
         x->ee_count == y->ee_count &&
         same_array(x->vertex_face, y->vertex_face, 2 * x->vf_count, sizeof(uint32_t)) &&
         same_array(x->vf_distance_sq, y->vf_distance_sq, x->vf_count, sizeof(double)) &&
         same_array(x->vf_type, y->vf_type, x->vf_count, 1) &&
         same_array(x->face_vertex, y->face_vertex, 2 * x->fv_count, sizeof(uint32_t)) &&
         same_array(x->fv_distance_sq, y->fv_distance_sq, x->fv_count, sizeof(double)) &&
         same_array(x->fv_type, y->fv_type, x->fv_count, 1) &&
         same_array(x->edge_edge, y->edge_edge, 4 * x->ee_count, sizeof(uint32_t)) &&
         same_array(x->ee_distance_sq, y->ee_distance_sq, x->ee_count, sizeof(double)) &&
         same_array(x->ee_type, y->ee_type, x->ee_count, 1) &&
         memcmp(&x->counters, &y->counters, sizeof(DhcdCounters)) == 0;
}

/* Whether two CCD results are equal, every array and the counters. */
static int same_impacts(const DhcdImpacts *x, const DhcdImpacts *y) {
  return x->vf_count == y->vf_count && x->fv_count == y->fv_count &&
         x->ee_count == y->ee_count && x->toi == y->toi &&
         same_array(x->vertex_face, y->vertex_face, 2 * x->vf_count, sizeof(uint32_t)) &&
         same_array(x->vf_toi, y->vf_toi, x->vf_count, sizeof(double)) &&
         same_array(x->face_vertex, y->face_vertex, 2 * x->fv_count, sizeof(uint32_t)) &&
         same_array(x->fv_toi, y->fv_toi, x->fv_count, sizeof(double)) &&
         same_array(x->edge_edge, y->edge_edge, 4 * x->ee_count, sizeof(uint32_t)) &&
         same_array(x->ee_toi, y->ee_toi, x->ee_count, sizeof(double)) &&
         memcmp(&x->counters, &y->counters, sizeof(DhcdCounters)) == 0;
}

/* The row of p->face_vertex that is [t, v], or -1. */
static long find_face_vertex(const DhcdProximity *p, uint32_t t, uint32_t v) {
  for (size_t k = 0; k < p->fv_count; k++)
    if (p->face_vertex[2 * k] == t && p->face_vertex[2 * k + 1] == v) return (long)k;
  return -1;
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

  /* Errors: null, wrong length, same handle twice, wrong method. */
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

  /* 2. Two grids, the second folded up through the first: contacts for every method, the
   * same set for every method and thread count. */
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

  /* 5. f64 hierarchies: triangle B's lowest corner 1e-9 above triangle A (in the plane
   * z = 1, where a float's spacing is 1.2e-7). As doubles they do not touch; rounded to
   * floats, B's corner would lie on A. Within 2e-9, B's corner is A's face's. */
  const double da[9] = {0, 0, 1, 2, 0, 1, 0, 2, 1};
  const double db[9] = {0.5, 0.5, 1 + 1e-9, 0.5, 0.5, 2, 0.2, 0.8, 2};
  DhcdHierarchy *a64 = NULL, *b64 = NULL;
  OK(dhcd_hierarchy_new_f64(DHCD_METHOD_DH, 0, da, 3, one, 1, &a64));
  OK(dhcd_hierarchy_new_f64(DHCD_METHOD_DH, 0, db, 3, one, 1, &b64));
  int precision = 0;
  OK(dhcd_hierarchy_precision(a64, &precision));
  CHECK(precision == DHCD_PRECISION_F64);
  OK(dhcd_collide(a64, b64, 1, &c));
  CHECK(c.count == 0);
  dhcd_contacts_free(&c);
  DhcdProximity px = {0};
  OK(dhcd_proximity(a64, b64, 2e-9, 1, &px));
  const double gap = (1 + 1e-9) - 1; /* exact in double */
  CHECK(px.vf_count == 0 && px.ee_count == 0 && px.fv_count == 1);
  CHECK(px.vertex_face == NULL && px.edge_edge == NULL);
  if (px.fv_count == 1) {
    CHECK(px.face_vertex[0] == 0 && px.face_vertex[1] == 0); /* A's triangle, B's vertex */
    CHECK(px.fv_type[0] == DHCD_PT_P_T && px.fv_distance_sq[0] == gap * gap);
  }
  printf("f64 pair: no contact, %zu face-vertex pair within 2e-9 (distance^2 %g)\n",
         px.fv_count, px.fv_count ? px.fv_distance_sq[0] : -1.0);
  dhcd_proximity_free(&px);
  CHECK(px.face_vertex == NULL && px.fv_count == 0);
  CHECK(dhcd_proximity(a64, b64, -1.0, 1, &px) == DHCD_ERR_INVALID_ARGUMENT);
  printf("expected error: %s\n", dhcd_last_error_message());
  CHECK(dhcd_hierarchy_update_positions(b64, tb, 3) == DHCD_ERR_PRECISION);
  printf("expected error: %s\n", dhcd_last_error_message());
  /* B's corner 1e-9 below A's plane, in double: they cross. */
  double down[9];
  memcpy(down, db, sizeof down);
  down[2] = 1 - 1e-9;
  OK(dhcd_hierarchy_update_positions_f64(b64, down, 3));
  OK(dhcd_collide(a64, b64, 1, &c));
  CHECK(c.count == 1);
  dhcd_contacts_free(&c);
  dhcd_hierarchy_free(a64);
  dhcd_hierarchy_free(b64);

  /* 6. Self-proximity of an f64 mesh of two parallel grids 0.05 apart, within 0.1: every
   * pair is within the distance, the same on 1 and 2 threads, and the pairs between the
   * layers are exactly those of the pair query between the two grids (indices of the
   * upper grid offset by nv and nt). */
  const double dist = 0.1;
  double *lower = malloc(3 * nv * sizeof(double)), *upper = malloc(3 * nv * sizeof(double));
  double *layers = malloc(6 * nv * sizeof(double));
  for (size_t k = 0; k < 3 * nv; k++) {
    lower[k] = g[k];
    upper[k] = k % 3 == 2 ? 0.05 : g[k];
  }
  memcpy(layers, lower, 3 * nv * sizeof(double));
  memcpy(layers + 3 * nv, upper, 3 * nv * sizeof(double));
  DhcdHierarchy *hl = NULL, *hu = NULL, *sheets = NULL;
  OK(dhcd_hierarchy_new_f64(DHCD_METHOD_AABB, 4, lower, nv, gt, nt, &hl));
  OK(dhcd_hierarchy_new_f64(DHCD_METHOD_AABB, 4, upper, nv, gt, nt, &hu));
  OK(dhcd_hierarchy_new_f64(DHCD_METHOD_AABB, 4, layers, 2 * nv, bt, 2 * nt, &sheets));
  DhcdProximity pair = {0}, self1 = {0}, self2 = {0};
  OK(dhcd_proximity(hl, hu, dist, 1, &pair));
  OK(dhcd_self_proximity(sheets, dist, 1, &self1));
  OK(dhcd_self_proximity(sheets, dist, 2, &self2));
  CHECK(same_proximity(&self1, &self2));
  CHECK(pair.vf_count > 0 && pair.fv_count > 0 && pair.ee_count > 0);
  CHECK(self1.vf_count > 0 && self1.ee_count > 0 && self1.fv_count == 0);
  CHECK(self1.counters.contacts == self1.vf_count + self1.ee_count);
  size_t vf_across = 0, fv_across = 0, ee_across = 0;
  for (size_t k = 0; k < self1.vf_count; k++) {
    const uint32_t v = self1.vertex_face[2 * k], t = self1.vertex_face[2 * k + 1];
    const uint32_t *tri = bt + 3 * t;
    CHECK(v != tri[0] && v != tri[1] && v != tri[2]);
    CHECK(self1.vf_distance_sq[k] <= dist * dist * (1 + 1e-12));
    CHECK(self1.vf_type[k] <= DHCD_PT_P_T);
    if (v < nv && t >= nt) { /* a lower vertex, an upper triangle: the pair's vertex_face */
      size_t j = vf_across++;
      CHECK(j < pair.vf_count);
      if (j < pair.vf_count) {
        CHECK(pair.vertex_face[2 * j] == v && pair.vertex_face[2 * j + 1] == t - nt);
        CHECK(pair.vf_distance_sq[j] == self1.vf_distance_sq[k]);
        CHECK(pair.vf_type[j] == self1.vf_type[k]);
      }
    } else if (v >= nv && t < nt) { /* an upper vertex, a lower triangle: face_vertex */
      long j = find_face_vertex(&pair, t, v - (uint32_t)nv);
      fv_across++;
      CHECK(j >= 0);
      if (j >= 0) {
        CHECK(pair.fv_distance_sq[j] == self1.vf_distance_sq[k]);
        CHECK(pair.fv_type[j] == self1.vf_type[k]);
      }
    }
  }
  for (size_t k = 0; k < self1.ee_count; k++) {
    const uint32_t *e = self1.edge_edge + 4 * k;
    CHECK(e[0] < e[1] && e[2] < e[3] && (e[0] < e[2] || (e[0] == e[2] && e[1] < e[3])));
    CHECK(e[0] != e[2] && e[0] != e[3] && e[1] != e[2] && e[1] != e[3]);
    CHECK(self1.ee_distance_sq[k] <= dist * dist * (1 + 1e-12));
    CHECK(self1.ee_type[k] <= DHCD_EE_EA_EB);
    if (e[1] < nv && e[2] >= nv) { /* an edge of each layer */
      size_t j = ee_across++;
      CHECK(j < pair.ee_count);
      if (j < pair.ee_count) {
        const uint32_t *q = pair.edge_edge + 4 * j;
        CHECK(q[0] == e[0] && q[1] == e[1] && q[2] + nv == e[2] && q[3] + nv == e[3]);
        CHECK(pair.ee_distance_sq[j] == self1.ee_distance_sq[k]);
        CHECK(pair.ee_type[j] == self1.ee_type[k]);
      }
    }
  }
  CHECK(vf_across == pair.vf_count && fv_across == pair.fv_count && ee_across == pair.ee_count);
  printf("f64 self-proximity within %g: %zu vertex-face, %zu edge-edge pairs (%zu, %zu and %zu "
         "between the layers, as the pair query)\n",
         dist, self1.vf_count, self1.ee_count, vf_across, fv_across, ee_across);
  dhcd_proximity_free(&pair);
  dhcd_proximity_free(&self1);
  dhcd_proximity_free(&self2);
  dhcd_proximity_free(&self2); /* twice: no-op */
  CHECK(self2.vertex_face == NULL && self2.vf_count == 0);
  dhcd_hierarchy_free(hl);
  dhcd_hierarchy_free(hu);
  dhcd_hierarchy_free(sheets);
  free(lower);
  free(upper);
  free(layers);

  /* 7. Continuous collision detection (double positions at t0 and t1, for hierarchies of
   * either precision). A single vertex falling through a triangle: it touches at t = 0.5;
   * the time is never later and at most 1e-12 earlier. */
  const double vf0[12] = {0.25, 0.25, 1, 0, 0, 0, 1, 0, 0, 0, 1, 0};
  const double vf1[12] = {0.25, 0.25, -1, 0, 0, 0, 1, 0, 0, 0, 1, 0};
  double toi = -1;
  CHECK(dhcd_vertex_face_ccd(vf0, vf1, 1.0, 0.0, &toi) == 1);
  CHECK(toi <= 0.5 && 0.5 - toi <= 1e-12);
  CHECK(dhcd_vertex_face_ccd(vf0, vf1, 0.25, 0.0, &toi) == 0 && toi == INFINITY);
  /* Two parallel edges 1 apart that never move: within 1, never touching. */
  const double ee[12] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 1, 1, 0};
  CHECK(dhcd_edge_edge_ccd(ee, ee, 1.0, 0.0, &toi) == 0);
  CHECK(dhcd_edge_edge_ccd(ee, ee, 1.0, 1.0, &toi) == 1 && toi == 0.0);
  toi = 7;
  CHECK(dhcd_edge_edge_ccd(ee, ee, 2.0, 0.0, &toi) == DHCD_ERR_INVALID_ARGUMENT && toi == 7);
  printf("expected error: %s\n", dhcd_last_error_message());

  /* Tunnelling: one mesh of two parallel grids, the upper one 0.05 above the lower at t0
   * and 0.05 below it at t1. Neither pose has a contact; over the step the layers meet at
   * t = 0.5. Self-CCD of the mesh on an f32 hierarchy finds the pairs between the layers
   * (the same on 1 and 2 threads); the pair query between the two grids finds the same
   * ones. */
  double *c0 = malloc(6 * nv * sizeof(double)), *c1 = malloc(6 * nv * sizeof(double));
  for (size_t k = 0; k < 3 * nv; k++) {
    const int axis = (int)(k % 3);
    c0[k] = c1[k] = g[k];                                      /* the lower grid stays */
    c0[3 * nv + k] = axis == 2 ? 0.05 : g[k] + (axis == 0 ? 0.02 : 0.03);
    c1[3 * nv + k] = axis == 2 ? -0.05 : c0[3 * nv + k];
  }
  /* The hierarchies may be built from any pose: CCD takes its positions from c0 and c1. */
  DhcdHierarchy *layered = NULL, *still = NULL, *moving = NULL;
  OK(dhcd_hierarchy_new(DHCD_METHOD_DH, 0, both, 2 * nv, bt, 2 * nt, &layered));
  OK(dhcd_hierarchy_new(DHCD_METHOD_DH, 0, g, nv, gt, nt, &still));
  OK(dhcd_hierarchy_new(DHCD_METHOD_DH, 0, g, nv, gt, nt, &moving));
  DhcdImpacts all1 = {0}, all2 = {0}, early = {0}, pair_ccd = {0};
  OK(dhcd_self_ccd(layered, c0, c1, 2 * nv, 1.0, 0.0, 0, 1, &all1));
  OK(dhcd_self_ccd(layered, c0, c1, 2 * nv, 1.0, 0.0, 0, 2, &all2));
  CHECK(same_impacts(&all1, &all2));
  CHECK(all1.vf_count > 0 && all1.ee_count > 0 && all1.fv_count == 0);
  CHECK(all1.toi <= 0.5 && 0.5 - all1.toi <= 1e-12);
  CHECK(all1.counters.contacts == all1.vf_count + all1.ee_count);
  for (size_t k = 0; k < all1.vf_count; k++) {
    const uint32_t v = all1.vertex_face[2 * k], t = all1.vertex_face[2 * k + 1];
    CHECK((v < nv) == (t >= nt)); /* a vertex of one layer, a triangle of the other */
    CHECK(all1.vf_toi[k] <= 0.5 && 0.5 - all1.vf_toi[k] <= 1e-12);
  }
  /* Earliest mode: the same first time, and only pairs reaching it. */
  OK(dhcd_self_ccd(layered, c0, c1, 2 * nv, 1.0, 0.0, 1, 1, &early));
  CHECK(early.toi == all1.toi);
  CHECK(early.vf_count + early.ee_count >= 1);
  CHECK(early.vf_count <= all1.vf_count && early.ee_count <= all1.ee_count);
  for (size_t k = 0; k < early.vf_count; k++) CHECK(early.vf_toi[k] == early.toi);
  for (size_t k = 0; k < early.ee_count; k++) CHECK(early.ee_toi[k] == early.toi);
  /* The pair query: the lower grid still, the upper one moving. */
  OK(dhcd_ccd(still, c0, c1, nv, moving, c0 + 3 * nv, c1 + 3 * nv, nv, 1.0, 0.0, 0, 2,
              &pair_ccd));
  CHECK(pair_ccd.vf_count + pair_ccd.fv_count == all1.vf_count);
  CHECK(pair_ccd.ee_count == all1.ee_count && pair_ccd.toi == all1.toi);
  size_t across = 0;
  for (size_t k = 0; k < all1.vf_count; k++) {
    const uint32_t v = all1.vertex_face[2 * k], t = all1.vertex_face[2 * k + 1];
    if (v < nv) { /* a lower vertex, an upper triangle: the pair's vertex_face, in order */
      const size_t j = across++;
      CHECK(j < pair_ccd.vf_count);
      if (j < pair_ccd.vf_count) {
        CHECK(pair_ccd.vertex_face[2 * j] == v && pair_ccd.vertex_face[2 * j + 1] + nt == t);
        CHECK(pair_ccd.vf_toi[j] == all1.vf_toi[k]);
      }
    }
  }
  CHECK(across == pair_ccd.vf_count);
  printf("self-CCD of two layers passing through each other: %zu vertex-face, %zu edge-edge "
         "pairs, first at t = %.17g; the pair query: %zu + %zu + %zu\n",
         all1.vf_count, all1.ee_count, all1.toi, pair_ccd.vf_count, pair_ccd.fv_count,
         pair_ccd.ee_count);
  /* Errors: a time limit out of [0, 1]; the result is left empty. */
  DhcdImpacts bad_ccd = all2;
  CHECK(dhcd_self_ccd(layered, c0, c1, 2 * nv, 2.0, 0.0, 0, 1, &bad_ccd) ==
        DHCD_ERR_INVALID_ARGUMENT);
  CHECK(bad_ccd.vertex_face == NULL && bad_ccd.vf_count == 0 && bad_ccd.toi == INFINITY);
  printf("expected error: %s\n", dhcd_last_error_message());
  CHECK(dhcd_self_ccd(layered, c0, c1, nv, 1.0, 0.0, 0, 1, &bad_ccd) ==
        DHCD_ERR_LENGTH_MISMATCH);
  /* The same step in a scene: the lower grid (object 0) still at its stored pose, the upper
   * one (object 1) moving; a far grid (object 2) is culled. Rows carry object ids; they are
   * the pair query's. */
  DhcdScene *ccd_scene = NULL;
  uint64_t id_lower = 0, id_upper = 0, id_far = 0;
  float *far_grid = malloc(3 * nv * sizeof(float));
  for (size_t k = 0; k < 3 * nv; k++) far_grid[k] = g[k] + (k % 3 == 0 ? 100.0f : 0.0f);
  OK(dhcd_scene_new(DHCD_METHOD_DH, 0, &ccd_scene));
  OK(dhcd_scene_add(ccd_scene, g, nv, gt, nt, 0, &id_lower));
  OK(dhcd_scene_add(ccd_scene, g, nv, gt, nt, 0, &id_upper));
  OK(dhcd_scene_add(ccd_scene, far_grid, nv, gt, nt, 0, &id_far));
  const double *up0[1] = {c0 + 3 * nv}, *up1[1] = {c1 + 3 * nv};
  const size_t up_count[1] = {nv};
  DhcdSceneImpacts si = {0};
  OK(dhcd_scene_ccd(ccd_scene, &id_upper, up0, up1, up_count, 1, 1.0, 0.0, 0, 2, &si));
  CHECK(si.vf_count == pair_ccd.vf_count && si.fv_count == pair_ccd.fv_count);
  CHECK(si.ee_count == pair_ccd.ee_count && si.toi == pair_ccd.toi);
  for (size_t k = 0; k < si.vf_count && k < pair_ccd.vf_count; k++) {
    CHECK(si.vertex_face[4 * k] == id_lower && si.vertex_face[4 * k + 2] == id_upper);
    CHECK(si.vertex_face[4 * k + 1] == pair_ccd.vertex_face[2 * k]);
    CHECK(si.vertex_face[4 * k + 3] == pair_ccd.vertex_face[2 * k + 1]);
    CHECK(si.vf_toi[k] == pair_ccd.vf_toi[k]);
  }
  printf("scene CCD of the same step: %zu + %zu + %zu pairs, first at t = %.17g\n",
         si.vf_count, si.fv_count, si.ee_count, si.toi);
  dhcd_scene_impacts_free(&si);
  /* The same object twice: an error, the result empty. */
  const uint64_t twice_up[2] = {id_upper, id_upper};
  const double *up0s[2] = {up0[0], up0[0]}, *up1s[2] = {up1[0], up1[0]};
  const size_t up_counts[2] = {nv, nv};
  CHECK(dhcd_scene_ccd(ccd_scene, twice_up, up0s, up1s, up_counts, 2, 1.0, 0.0, 0, 1, &si) ==
        DHCD_ERR_REPEATED_OBJECT);
  CHECK(si.vertex_face == NULL && si.vf_count == 0 && si.toi == INFINITY);
  dhcd_scene_free(ccd_scene);
  free(far_grid);

  dhcd_impacts_free(&all1);
  dhcd_impacts_free(&all2);
  dhcd_impacts_free(&early);
  dhcd_impacts_free(&pair_ccd);
  dhcd_impacts_free(&pair_ccd); /* twice: no-op */
  CHECK(pair_ccd.edge_edge == NULL && pair_ccd.ee_count == 0);
  dhcd_hierarchy_free(layered);
  dhcd_hierarchy_free(still);
  dhcd_hierarchy_free(moving);
  free(c0);
  free(c1);

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
