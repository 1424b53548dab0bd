//! Proximity: every vertex-triangle and edge-edge pair whose closed features are within a
//! distance `d`, decided exactly, with its squared distance and closest sub-features.
//!
//! The walk is the contact query's with the node test grown by `d` ([`Within`]): two regions
//! holding features within `d` of each other have volumes within `d`, so every such pair
//! lies in a leaf pair the walk reaches. Each leaf pair's candidate feature pairs come from
//! the feature-pair layer ([`super::features`]: each pair once, culled by boxes grown by `d`,
//! in `f32`, rounded outward for `f64` hierarchies). They are staged, then decided 64 at a
//! time: the `f64` batch filters of [`dhcd_kernels::apart`] end the pairs certainly farther
//! than `d` apart (a separating direction with a proven error bound, 8 pairs a vector on
//! AVX-512), and the exact tests of [`crate::distance`] decide the rest.
//!
//! Results are in the caller's original indices, sorted, and the same for every thread count
//! and every method. `prim_tests` counts the feature pairs given to the exact test; `contacts`
//! the pairs reported.

use pulp::Simd;

use dhcd_kernels::apart::{point_triangles_apart_with, segments_apart_with, FourPoints, MAX_PAIRS};

use super::features::{parts, CandidateEdge, Candidates, LeafEdges, LeafTriangles, LeafVertices};
use super::{LeafAction, NodeTest, Posed, PosedQuery, Within};
use crate::bv::BoundingVolume;
use crate::control::Budget;
use crate::counters::Counters;
use crate::distance::{self, EdgeEdge, PointTriangle};
use crate::error::{Error, Result};
use crate::hierarchy::Hierarchy;
use crate::par::Par;
use crate::walk::{self, Workspace};

/// A vertex within the distance of a triangle: in a pair query, a vertex of the first
/// hierarchy and a triangle of the second (see [`FaceVertex`] for the other way round); in a
/// self query, a vertex and a triangle not containing it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct VertexFace {
    /// The vertex (original index).
    pub vertex: u32,
    /// The triangle (original index).
    pub triangle: u32,
    /// Squared distance between the point and the closed triangle (see [`crate::distance`]
    /// for its accuracy).
    pub distance_sq: f64,
    /// Which sub-feature of the triangle is closest (IPC's point-triangle distance types).
    pub kind: PointTriangle,
}

/// A triangle of the first hierarchy within the distance of a vertex of the second (pair
/// queries only).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FaceVertex {
    /// The triangle of the first hierarchy (original index).
    pub triangle: u32,
    /// The vertex of the second hierarchy (original index).
    pub vertex: u32,
    /// Squared distance of the closed features (exact decision, rounded value).
    pub distance_sq: f64,
    /// Which sub-features are closest (IPC's point-triangle distance type).
    pub kind: PointTriangle,
}

/// Two edges within the distance: `a` of the first hierarchy and `b` of the second (pair
/// queries), or two edges of one mesh sharing no vertex with `a < b` (self queries). Each
/// edge is its two vertices' original indices, smaller first; the distance type names them
/// in that order (`EA0` is `a[0]`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EdgePair {
    /// The edge of the first hierarchy (or the first edge of a self pair).
    pub a: [u32; 2],
    /// The edge of the second hierarchy (or the second edge of a self pair).
    pub b: [u32; 2],
    /// Squared distance of the closed segments (exact decision, rounded value).
    pub distance_sq: f64,
    /// Which sub-features are closest (IPC's edge-edge distance type).
    pub kind: EdgeEdge,
}

/// Result of a proximity query: every feature pair within the distance, in the caller's
/// original indices, sorted, and the counted work.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Proximity {
    /// Sorted by `(vertex, triangle)`.
    pub vertex_face: Vec<VertexFace>,
    /// Sorted by `(triangle, vertex)`; empty in a self query.
    pub face_vertex: Vec<FaceVertex>,
    /// Sorted by `(a, b)`.
    pub edge_edge: Vec<EdgePair>,
    /// `bv_tests` and `bv_updates` as for contacts, `prim_tests` the feature pairs given to
    /// the exact test, `contacts` the pairs reported.
    pub counters: Counters,
}

/// Checks a proximity distance: finite and `>= 0`.
pub(crate) fn check_distance(d: f64) -> Result<()> {
    if d.is_finite() && d >= 0.0 {
        Ok(())
    } else {
        Err(Error::InvalidDistance(d))
    }
}

/// Every vertex-triangle and edge-edge pair of `a` and `b` within distance `d` (finite,
/// `>= 0`; else [`Error::InvalidDistance`]), on the calling thread.
pub fn proximity<K: BoundingVolume>(
    a: &Hierarchy<K>,
    b: &Hierarchy<K>,
    d: f64,
) -> Result<Proximity> {
    proximity_with(a, b, d, &mut Workspace::default(), Par::Seq)
}

/// [`proximity`] with caller-owned scratch and a choice of parallelism. The result does not
/// depend on `par`.
pub fn proximity_with<K: BoundingVolume>(
    a: &Hierarchy<K>,
    b: &Hierarchy<K>,
    d: f64,
    ws: &mut Workspace,
    par: Par,
) -> Result<Proximity> {
    proximity_in(a, b, d, ws, par, Rows::Sorted)
}

/// [`proximity_with`] with its rows in the order `rows`.
pub(crate) fn proximity_in<K: BoundingVolume>(
    a: &Hierarchy<K>,
    b: &Hierarchy<K>,
    d: f64,
    ws: &mut Workspace,
    par: Par,
    rows: Rows,
) -> Result<Proximity> {
    check_distance(d)?;
    let control = ws.control.clone();
    let budget = Budget::new(&control);
    let posed = Posed::pair(a, b, Within::distance(d));
    Ok(run(posed, d, &budget, ws, par, rows)?.0)
}

/// Every vertex-triangle pair (the triangle not containing the vertex) and edge-edge pair
/// (sharing no vertex) of one mesh within distance `d`, on the calling thread.
pub fn self_proximity<K: BoundingVolume>(h: &Hierarchy<K>, d: f64) -> Result<Proximity> {
    self_proximity_with(h, d, &mut Workspace::default(), Par::Seq)
}

/// [`self_proximity`] with caller-owned scratch and a choice of parallelism.
pub fn self_proximity_with<K: BoundingVolume>(
    h: &Hierarchy<K>,
    d: f64,
    ws: &mut Workspace,
    par: Par,
) -> Result<Proximity> {
    self_proximity_in(h, d, ws, par, Rows::Sorted)
}

/// [`self_proximity_with`] with its rows in the order `rows`.
pub(crate) fn self_proximity_in<K: BoundingVolume>(
    h: &Hierarchy<K>,
    d: f64,
    ws: &mut Workspace,
    par: Par,
    rows: Rows,
) -> Result<Proximity> {
    check_distance(d)?;
    let control = ws.control.clone();
    let budget = Budget::new(&control);
    let posed = Posed::single(h, Within::distance(d));
    Ok(run(posed, d, &budget, ws, par, rows)?.0)
}

/// The order of a proximity query's rows.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Rows {
    /// Each kind sorted as [`Proximity`] says (the public queries' order).
    Sorted,
    /// As the walk found them, which depends on the thread count: for a caller that orders
    /// them itself (the contact set sorts them by contact).
    AsFound,
}

/// The proximity query on `posed` (distance already checked), its rows in the order `rows`,
/// counted against `budget`; also
/// the nodes fitted on each side (the scene credits them per object). An error when the
/// budget stopped the walk (this walk or another sharing the budget).
pub(crate) fn run<K: BoundingVolume>(
    posed: Posed<'_, K, Within>,
    d: f64,
    budget: &Budget<'_>,
    ws: &mut Workspace,
    par: Par,
    rows: Rows,
) -> Result<(Proximity, [u64; 2])> {
    let margin = posed.node_test.margin;
    let q = PosedQuery {
        posed,
        action: Features { d, margin, budget },
    };
    let w = walk::walk(&q, ws, par);
    budget.finish()?;
    let mut p = w.out.result;
    if rows == Rows::Sorted {
        sort_rows(&mut p);
    }
    p.counters = w.counters;
    p.counters.contacts = (p.vertex_face.len() + p.face_vertex.len() + p.edge_edge.len()) as u64;
    Ok((p, w.fitted))
}

/// Sorts each kind of row as [`Proximity`] says.
fn sort_rows(p: &mut Proximity) {
    p.vertex_face
        .sort_unstable_by_key(|x| (u64::from(x.vertex) << 32) | u64::from(x.triangle));
    p.face_vertex
        .sort_unstable_by_key(|x| (u64::from(x.triangle) << 32) | u64::from(x.vertex));
    // PERF: one 128-bit key; the arrays compared field by field made the proximity query
    // 3-5% slower on cloth-ball and rod-twist. A counting sort by `a[0]` (`crate::sort`)
    // was no faster on cloth-ball (7 rows a vertex: the scatter and a second buffer), nor
    // was a 64-bit key where the indices fit in 16 bits (the moves of the 32-byte rows
    // cost more than the comparisons).
    p.edge_edge
        .sort_unstable_by_key(|x| crate::sort::as_one([x.a[0], x.a[1], x.b[0], x.b[1]]));
}

/// The leaf action: the feature pairs of a leaf pair.
struct Features<'b, 'c> {
    d: f64,
    /// `d` as an `f32` not below it: the boxes' growth.
    margin: f32,
    /// The result pairs so far, against the query's limit.
    budget: &'b Budget<'c>,
}

/// What a proximity walk task produces, and its scratch.
struct FeatureOut {
    result: Proximity,
    /// The candidates of a leaf pair waiting for the batch filters.
    batch: Box<Batch>,
}

/// A leaf pair's candidates, staged for the batch filters ([`dhcd_kernels::apart`]), and the
/// points of up to [`MAX_PAIRS`] of them.
#[derive(Default)]
struct Batch {
    /// Vertex-triangle pairs (internal indices).
    vertex_triangles: Vec<(u32, u32)>,
    /// Edge pairs.
    edges: Vec<(CandidateEdge, CandidateEdge)>,
    /// The four points of each pair of the current chunk.
    points: FourPoints,
}

/// One side of a leaf pair: a hierarchy and one of its leaves.
#[derive(Clone, Copy)]
struct Leaf<'h, K: BoundingVolume> {
    h: &'h Hierarchy<K>,
    node: usize,
}

impl<'h, K: BoundingVolume> Leaf<'h, K> {
    /// The leaf's own edges as candidates.
    fn edges(&self) -> LeafEdges<'h> {
        let tree = self.h.tree();
        let boxes = self.h.leaf_feature_boxes(self.node);
        let rank = tree.leaf_rank(self.node).expect("a leaf");
        LeafEdges {
            edges: tree.leaf_edges().of_rank(rank),
            ids: tree.leaf_edges().ids_of_rank(rank),
            rows: boxes.edges,
            bounds: boxes.edge_bounds,
        }
    }

    /// The leaf's own vertices as candidates.
    fn vertices(&self) -> LeafVertices<'h> {
        LeafVertices {
            rows: self.h.leaf_feature_boxes(self.node).vertices,
            first: self.h.tree().vert_run(self.node).start,
        }
    }
}

impl<'h, K: BoundingVolume> LeafAction<'h, K> for Features<'_, '_> {
    type Out = FeatureOut;

    fn out(&self) -> FeatureOut {
        FeatureOut {
            result: Proximity::default(),
            batch: Box::default(),
        }
    }

    #[inline(always)]
    fn leaf_pair<S: Simd, T: NodeTest>(
        &self,
        posed: &Posed<'h, K, T>,
        simd: S,
        x: usize,
        y: usize,
        counters: &mut Counters,
        out: &mut FeatureOut,
    ) {
        let (lx, ly) = (
            Leaf {
                h: posed.a,
                node: x,
            },
            Leaf {
                h: posed.b,
                node: y,
            },
        );
        let self_query = posed.self_query;
        let FeatureOut { result: res, batch } = out;
        let budget = self.budget;
        let before = res.vertex_face.len() + res.face_vertex.len() + res.edge_edge.len();
        let stopped = || budget.stopped();
        let candidates = Candidates {
            self_query,
            margin: self.margin,
            stopped: &stopped,
        };
        // Vertices of x against triangles of y, and (but for a leaf with itself) the other way.
        self.vertices_vs_triangles(
            simd,
            &candidates,
            [lx, ly],
            counters,
            batch,
            |v, t, d2, kind| {
                budget.push(
                    &mut res.vertex_face,
                    VertexFace {
                        vertex: v,
                        triangle: t,
                        distance_sq: d2,
                        kind,
                    },
                )
            },
        );
        if !(self_query && x == y) {
            self.vertices_vs_triangles(
                simd,
                &candidates,
                [ly, lx],
                counters,
                batch,
                |v, t, d2, kind| {
                    if self_query {
                        budget.push(
                            &mut res.vertex_face,
                            VertexFace {
                                vertex: v,
                                triangle: t,
                                distance_sq: d2,
                                kind,
                            },
                        )
                    } else {
                        budget.push(
                            &mut res.face_vertex,
                            FaceVertex {
                                triangle: t,
                                vertex: v,
                                distance_sq: d2,
                                kind,
                            },
                        )
                    }
                },
            );
        }
        self.edges_vs_edges(
            simd,
            &candidates,
            [lx, ly],
            counters,
            batch,
            &mut res.edge_edge,
        );
        let after = res.vertex_face.len() + res.face_vertex.len() + res.edge_edge.len();
        budget.add(after - before);
    }

    fn merge(&self, out: &mut FeatureOut, other: FeatureOut) {
        let (r, o) = (&mut out.result, other.result);
        self.budget.extend(&mut r.vertex_face, &o.vertex_face);
        self.budget.extend(&mut r.face_vertex, &o.face_vertex);
        self.budget.extend(&mut r.edge_edge, &o.edge_edge);
    }

    #[inline(always)]
    fn clear<T: NodeTest>(&self, posed: &Posed<'h, K, T>, x: usize) -> bool {
        super::clearance::pose_is_clear(posed.a, x, self.d)
    }

    #[inline(always)]
    fn stopped(&self, poll: bool) -> bool {
        if poll {
            self.budget.poll()
        } else {
            self.budget.stopped()
        }
    }
}

impl Features<'_, '_> {
    /// The own vertices of leaf `lv` against the triangles of leaf `lt`: `emit(vertex,
    /// triangle, distance_sq, type)` for each pair within the distance (original indices).
    /// Candidates go through `batch`: the batch filter ends the pairs certainly farther
    /// apart, the exact test decides the rest.
    #[inline(always)]
    fn vertices_vs_triangles<S: Simd, K: BoundingVolume>(
        &self,
        simd: S,
        candidates: &Candidates<'_>,
        [lv, lt]: [Leaf<'_, K>; 2],
        counters: &mut Counters,
        batch: &mut Batch,
        mut emit: impl FnMut(u32, u32, f64, PointTriangle),
    ) {
        let (tv, tt) = (lv.h.tree(), lt.h.tree());
        let leaf_tris = lt.h.leaf_tris(simd, lt.node);
        let soa = &leaf_tris.soa;
        let tris = LeafTriangles {
            rows: [
                soa.lo(0),
                soa.lo(1),
                soa.lo(2),
                soa.hi(0),
                soa.hi(1),
                soa.hi(2),
            ],
            len: leaf_tris.len,
            bounds: soa.bounds().expect("a cached leaf's triangles have bounds"),
            first: tt.tri_range(lt.node).start,
            corners: tt.triangles(),
        };
        let vertices = lv.vertices();
        // PERF: the closure only stages the pair; the filter runs in the dispatched body
        // (see `edges_vs_edges`).
        for part in parts(0..tv.vert_run(lv.node).len(), tris.len) {
            let staged = &mut batch.vertex_triangles;
            candidates.vertices_vs_triangles(simd, &vertices, part, &tris, counters, |v, t| {
                staged.push((v as u32, t as u32))
            });
            let at = |c: u32| lt.h.position_f64(c as usize);
            let mut from = 0;
            while from < batch.vertex_triangles.len() {
                let n = (batch.vertex_triangles.len() - from).min(MAX_PAIRS);
                for i in 0..n {
                    let (v, t) = batch.vertex_triangles[from + i];
                    let [c0, c1, c2] = tris.corners[t as usize];
                    let pv = lv.h.position_f64(v as usize);
                    batch.points.set(i, [pv, at(c0), at(c1), at(c2)]);
                }
                let apart = point_triangles_apart_with(simd, &batch.points, n, self.d);
                for (i, &(v, t)) in batch.vertex_triangles[from..from + n].iter().enumerate() {
                    if apart & (1 << i) != 0 {
                        continue;
                    }
                    let [pv, t0, t1, t2] = batch.points.get(i);
                    if let Some((d2, kind)) =
                        distance::point_triangle_within(pv, [t0, t1, t2], self.d)
                    {
                        emit(
                            tv.vert_order()[v as usize],
                            tt.tri_order()[t as usize],
                            d2,
                            kind,
                        );
                    }
                }
                from += n;
            }
            batch.vertex_triangles.clear();
        }
    }

    /// The own edges of leaf `la` against those of `lb` (a leaf with itself: each unordered
    /// pair once): each pair within the distance into `out`. Candidates go through `batch`:
    /// the batch filter ends the pairs certainly farther apart, the exact test decides the
    /// rest.
    #[inline(always)]
    fn edges_vs_edges<S: Simd, K: BoundingVolume>(
        &self,
        simd: S,
        candidates: &Candidates<'_>,
        [la, lb]: [Leaf<'_, K>; 2],
        counters: &mut Counters,
        batch: &mut Batch,
        out: &mut Vec<EdgePair>,
    ) {
        let (a, b) = (la.edges(), lb.edges());
        let same_leaf = candidates.self_query && la.node == lb.node;
        // PERF: the closure only stages the pair; the filter runs here, in the dispatched
        // body (a closure may be compiled without the backend's target features, and then
        // every SIMD operation is a call).
        for part in parts(0..a.edges.len(), b.edges.len()) {
            candidates.edges_vs_edges(simd, &a, part, &b, same_leaf, counters, |x, y| {
                batch.edges.push((x, y));
            });
            let (pa, pb) = (
                |v: u32| la.h.position_f64(v as usize),
                |v: u32| lb.h.position_f64(v as usize),
            );
            let mut from = 0;
            while from < batch.edges.len() {
                let n = (batch.edges.len() - from).min(MAX_PAIRS);
                for i in 0..n {
                    // `x` is of `la` (or, in a self query, of the one mesh), `y` of `lb`; the
                    // exact test takes the endpoints in the reported order, so its type names
                    // them so.
                    // PERF: one load per endpoint, not `map` over the edges: copies of the
                    // points through the stack stalled on store forwarding.
                    let (x, y) = batch.edges[from + i];
                    let ([x0, x1], [y0, y1]) = (x.internal, y.internal);
                    batch.points.set(i, [pa(x0), pa(x1), pb(y0), pb(y1)]);
                }
                let apart = segments_apart_with(simd, &batch.points, n, self.d);
                for (i, &(x, y)) in batch.edges[from..from + n].iter().enumerate() {
                    if apart & (1 << i) != 0 {
                        continue;
                    }
                    let [a0, a1, b0, b1] = batch.points.get(i);
                    if let Some((d2, kind)) = distance::edge_edge_within(a0, a1, b0, b1, self.d) {
                        self.budget.push(
                            out,
                            EdgePair {
                                a: x.ids,
                                b: y.ids,
                                distance_sq: d2,
                                kind,
                            },
                        );
                    }
                }
                from += n;
            }
            batch.edges.clear();
        }
    }
}
