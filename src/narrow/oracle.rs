//! Brute-force oracles: every triangle pair through the exact test.

use super::predicates::Coordinate;
use super::tritri::{tri_tri, Decide};
use crate::mesh::Mesh;
use crate::precision::Precision;

/// The triangles of a mesh as corner coordinates of type `C`, with their closed boxes.
struct Tris<C> {
    corners: Vec<[[C; 3]; 3]>,
    boxes: Vec<[[C; 3]; 2]>,
}

impl<C: Coordinate> Tris<C> {
    fn new(m: &Mesh, positions: &[[C; 3]]) -> Self {
        let corners: Vec<[[C; 3]; 3]> = m
            .triangles()
            .iter()
            .map(|t| t.map(|v| positions[v as usize]))
            .collect();
        let boxes = corners
            .iter()
            .map(|c| {
                let mut b = [c[0], c[0]];
                for p in &c[1..] {
                    for k in 0..3 {
                        if p[k] < b[0][k] {
                            b[0][k] = p[k];
                        }
                        if p[k] > b[1][k] {
                            b[1][k] = p[k];
                        }
                    }
                }
                b
            })
            .collect();
        Self { corners, boxes }
    }

    #[inline]
    fn meet(&self, i: usize, other: &Self, j: usize) -> bool {
        let (a, b) = (&self.boxes[i], &other.boxes[j]);
        (0..3).all(|k| a[1][k] >= b[0][k] && b[1][k] >= a[0][k])
    }

    #[inline]
    fn intersect(&self, i: usize, other: &Self, j: usize) -> bool {
        self.meet(i, other, j) && tri_tri(&self.corners[i], &other.corners[j], &mut Decide)
    }
}

/// Exact brute-force oracle: every `(ta, tb)` with intersecting closed triangles, sorted
/// ascending, exact for the meshes' precision (`f64` when either mesh is `f64`). `O(|a| |b|)`.
pub fn brute_force_pairs(a: &Mesh, b: &Mesh) -> Vec<[u32; 2]> {
    if a.precision() == Precision::F64 || b.precision() == Precision::F64 {
        let (pa, pb) = (a.to_f64_positions(), b.to_f64_positions());
        pairs(&Tris::new(a, &pa), &Tris::new(b, &pb))
    } else {
        pairs(&Tris::new(a, a.positions()), &Tris::new(b, b.positions()))
    }
}

fn pairs<C: Coordinate>(a: &Tris<C>, b: &Tris<C>) -> Vec<[u32; 2]> {
    let mut out = Vec::new();
    for i in 0..a.corners.len() {
        for j in 0..b.corners.len() {
            if a.intersect(i, b, j) {
                out.push([i as u32, j as u32]);
            }
        }
    }
    out
}

/// Self-collision oracle: every `(ti, tj)`, `ti < tj`, intersecting, excluding pairs that
/// share a vertex index; sorted ascending; exact for the mesh's precision. `O(n^2)`.
pub fn brute_force_self_pairs(m: &Mesh) -> Vec<[u32; 2]> {
    match m.positions_f64() {
        Some(p) => self_pairs(m, &Tris::new(m, p)),
        None => self_pairs(m, &Tris::new(m, m.positions())),
    }
}

fn self_pairs<C: Coordinate>(m: &Mesh, t: &Tris<C>) -> Vec<[u32; 2]> {
    let tris = m.triangles();
    let mut out = Vec::new();
    for i in 0..tris.len() {
        for j in i + 1..tris.len() {
            if tris[i].iter().any(|v| tris[j].contains(v)) {
                continue;
            }
            if t.intersect(i, t, j) {
                out.push([i as u32, j as u32]);
            }
        }
    }
    out
}

/// Brute-force proximity oracle: every vertex of `a` against every triangle of `b` and the
/// other way, and every unique edge of `a` against every unique edge of `b`, through the
/// exact tests of [`crate::distance`] at distance `d`; in the order and form of
/// [`crate::query::proximity`]'s result (every vertex, free points included; `counters`
/// zero but `contacts`). `O(|a| |b|)`.
pub fn brute_force_proximity(a: &Mesh, b: &Mesh, d: f64) -> crate::query::Proximity {
    use crate::distance::{edge_edge_within, point_triangle_within};
    use crate::query::{EdgePair, FaceVertex, Proximity, VertexFace};
    let (pa, pb) = (a.to_f64_positions(), b.to_f64_positions());
    let mut out = Proximity::default();
    let tri = |m: &Mesh, p: &[[f64; 3]], t: usize| m.triangles()[t].map(|v| p[v as usize]);
    for v in 0..a.vertex_count() as u32 {
        for t in 0..b.triangle_count() {
            if let Some((d2, kind)) = point_triangle_within(pa[v as usize], tri(b, &pb, t), d) {
                out.vertex_face.push(VertexFace {
                    vertex: v,
                    triangle: t as u32,
                    distance_sq: d2,
                    kind,
                });
            }
        }
    }
    for t in 0..a.triangle_count() {
        for v in 0..b.vertex_count() as u32 {
            if let Some((d2, kind)) = point_triangle_within(pb[v as usize], tri(a, &pa, t), d) {
                out.face_vertex.push(FaceVertex {
                    triangle: t as u32,
                    vertex: v,
                    distance_sq: d2,
                    kind,
                });
            }
        }
    }
    out.face_vertex
        .sort_unstable_by_key(|x| (x.triangle, x.vertex));
    for ea in unique_edges(a) {
        for eb in unique_edges(b) {
            let (p, q) = (ea.map(|v| pa[v as usize]), eb.map(|v| pb[v as usize]));
            if let Some((d2, kind)) = edge_edge_within(p[0], p[1], q[0], q[1], d) {
                out.edge_edge.push(EdgePair {
                    a: ea,
                    b: eb,
                    distance_sq: d2,
                    kind,
                });
            }
        }
    }
    out.counters.contacts =
        (out.vertex_face.len() + out.face_vertex.len() + out.edge_edge.len()) as u64;
    out
}

/// Brute-force self-proximity oracle: every vertex against every triangle not containing
/// it, every pair of unique edges sharing no vertex (`a < b`), as
/// [`crate::query::self_proximity`] reports them. `O(n^2)`.
pub fn brute_force_self_proximity(m: &Mesh, d: f64) -> crate::query::Proximity {
    use crate::distance::{edge_edge_within, point_triangle_within};
    use crate::query::{EdgePair, Proximity, VertexFace};
    let p = m.to_f64_positions();
    let mut out = Proximity::default();
    for v in 0..m.vertex_count() as u32 {
        for (t, corners) in m.triangles().iter().enumerate() {
            if corners.contains(&v) {
                continue;
            }
            let tri = corners.map(|c| p[c as usize]);
            if let Some((d2, kind)) = point_triangle_within(p[v as usize], tri, d) {
                out.vertex_face.push(VertexFace {
                    vertex: v,
                    triangle: t as u32,
                    distance_sq: d2,
                    kind,
                });
            }
        }
    }
    let edges = unique_edges(m);
    for (i, ea) in edges.iter().enumerate() {
        for eb in &edges[i + 1..] {
            if ea.iter().any(|v| eb.contains(v)) {
                continue;
            }
            let (x, y) = (ea.map(|v| p[v as usize]), eb.map(|v| p[v as usize]));
            if let Some((d2, kind)) = edge_edge_within(x[0], x[1], y[0], y[1], d) {
                out.edge_edge.push(EdgePair {
                    a: *ea,
                    b: *eb,
                    distance_sq: d2,
                    kind,
                });
            }
        }
    }
    out.counters.contacts = (out.vertex_face.len() + out.edge_edge.len()) as u64;
    out
}

/// Every colliding vertex-triangle and edge-edge pair of meshes `a` and `b` over a step,
/// by testing every pair with [`crate::ccd`]: the reference of [`crate::ccd_pair`] (the
/// meshes give the triangles; the motions the positions; `toi` the least time).
pub fn brute_force_ccd(
    a: &Mesh,
    am: crate::query::Motion<'_>,
    b: &Mesh,
    bm: crate::query::Motion<'_>,
    options: &crate::ccd::CcdOptions,
) -> crate::query::Impacts {
    use crate::ccd::{edge_edge, vertex_face};
    use crate::query::{EdgeImpact, FaceImpact, Impacts, VertexImpact};
    let mut out = Impacts::default();
    let vf = |vm: &crate::query::Motion<'_>, v: u32, tm: &crate::query::Motion<'_>, t: [u32; 3]| {
        let x0 = [
            vm.x0[v as usize],
            tm.x0[t[0] as usize],
            tm.x0[t[1] as usize],
            tm.x0[t[2] as usize],
        ];
        let x1 = [
            vm.x1[v as usize],
            tm.x1[t[0] as usize],
            tm.x1[t[1] as usize],
            tm.x1[t[2] as usize],
        ];
        vertex_face(&x0, &x1, options)
    };
    for v in 0..a.vertex_count() as u32 {
        for (t, &corners) in b.triangles().iter().enumerate() {
            if let Some(toi) = vf(&am, v, &bm, corners) {
                out.vertex_face.push(VertexImpact {
                    vertex: v,
                    triangle: t as u32,
                    toi,
                });
            }
        }
    }
    for (t, &corners) in a.triangles().iter().enumerate() {
        for v in 0..b.vertex_count() as u32 {
            if let Some(toi) = vf(&bm, v, &am, corners) {
                out.face_vertex.push(FaceImpact {
                    triangle: t as u32,
                    vertex: v,
                    toi,
                });
            }
        }
    }
    for ea in unique_edges(a) {
        for eb in unique_edges(b) {
            let x0 = [
                am.x0[ea[0] as usize],
                am.x0[ea[1] as usize],
                bm.x0[eb[0] as usize],
                bm.x0[eb[1] as usize],
            ];
            let x1 = [
                am.x1[ea[0] as usize],
                am.x1[ea[1] as usize],
                bm.x1[eb[0] as usize],
                bm.x1[eb[1] as usize],
            ];
            if let Some(toi) = edge_edge(&x0, &x1, options) {
                out.edge_edge.push(EdgeImpact { a: ea, b: eb, toi });
            }
        }
    }
    finish_impacts(&mut out);
    out
}

/// [`brute_force_ccd`] of one mesh against itself: vertex-triangle pairs with the vertex not
/// a corner, edge pairs sharing no vertex (`a < b`); the reference of [`crate::self_ccd`].
pub fn brute_force_self_ccd(
    m: &Mesh,
    motion: crate::query::Motion<'_>,
    options: &crate::ccd::CcdOptions,
) -> crate::query::Impacts {
    use crate::ccd::{edge_edge, vertex_face};
    use crate::query::{EdgeImpact, Impacts, VertexImpact};
    let (x0, x1) = (motion.x0, motion.x1);
    let mut out = Impacts::default();
    for v in 0..m.vertex_count() as u32 {
        for (t, corners) in m.triangles().iter().enumerate() {
            if corners.contains(&v) {
                continue;
            }
            let ids = [v, corners[0], corners[1], corners[2]];
            let (p0, p1) = (ids.map(|i| x0[i as usize]), ids.map(|i| x1[i as usize]));
            if let Some(toi) = vertex_face(&p0, &p1, options) {
                out.vertex_face.push(VertexImpact {
                    vertex: v,
                    triangle: t as u32,
                    toi,
                });
            }
        }
    }
    let edges = unique_edges(m);
    for (i, ea) in edges.iter().enumerate() {
        for eb in &edges[i + 1..] {
            if ea.iter().any(|v| eb.contains(v)) {
                continue;
            }
            let ids = [ea[0], ea[1], eb[0], eb[1]];
            let (p0, p1) = (ids.map(|i| x0[i as usize]), ids.map(|i| x1[i as usize]));
            if let Some(toi) = edge_edge(&p0, &p1, options) {
                out.edge_edge.push(EdgeImpact {
                    a: *ea,
                    b: *eb,
                    toi,
                });
            }
        }
    }
    finish_impacts(&mut out);
    out
}

/// What earliest mode returns given the all-mode result `all` of a walk and the least time
/// `least` over every walk that shared the query (`all.toi` for one walk): the pairs whose
/// time is within [`crate::ccd::TOI_TOLERANCE`] of `least`, the least of their times (`None`
/// if none) and their count; the work counters as `all`'s.
pub fn earliest_of(all: &crate::query::Impacts, least: Option<f64>) -> crate::query::Impacts {
    let mut e = all.clone();
    let bound = least.map_or(f64::NEG_INFINITY, |t| t + crate::ccd::TOI_TOLERANCE);
    e.vertex_face.retain(|x| x.toi <= bound);
    e.face_vertex.retain(|x| x.toi <= bound);
    e.edge_edge.retain(|x| x.toi <= bound);
    finish_impacts(&mut e);
    e
}

/// The earliest time and the count of an oracle's result (its lists are in order).
fn finish_impacts(out: &mut crate::query::Impacts) {
    out.toi = out
        .vertex_face
        .iter()
        .map(|x| x.toi)
        .chain(out.face_vertex.iter().map(|x| x.toi))
        .chain(out.edge_edge.iter().map(|x| x.toi))
        .reduce(f64::min);
    out.counters.contacts =
        (out.vertex_face.len() + out.face_vertex.len() + out.edge_edge.len()) as u64;
}

/// The unique edges of the triangles, each as its vertices smaller first, ascending.
fn unique_edges(m: &Mesh) -> Vec<[u32; 2]> {
    let mut e: Vec<[u32; 2]> = m
        .triangles()
        .iter()
        .flat_map(|t| (0..3).map(move |k| [t[k].min(t[(k + 1) % 3]), t[k].max(t[(k + 1) % 3])]))
        .collect();
    e.sort_unstable();
    e.dedup();
    e
}
