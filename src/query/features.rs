//! The feature-pair layer under the queries on features (proximity, CCD, and through them
//! the contact set and the step size): the candidate feature pairs of one leaf pair,
//! enumerated once, generic over the decision each query makes of a candidate.
//!
//! Ownership makes each candidate unique: every vertex belongs to one leaf (its own
//! vertices, the ones first seen in it) and so does every edge (the leaf of its first
//! triangle), so a vertex-triangle pair is met only in the leaf pair (vertex's leaf,
//! triangle's leaf) and an edge pair only in the pair of their leaves, however many
//! triangles share the features. Inside a leaf pair, features are culled first by the other
//! leaf's union box grown by the query's margin, then pair by pair by their boxes grown by it
//! ([`Candidates`]); in a self query, pairs sharing a vertex are skipped. Boxes are `f32`,
//! closed, rounded outward from the positions; a leaf's boxes are six rows (`lo xyz`, `hi
//! xyz`) tested 64 at a time by [`boxes_meet_from`].

use std::ops::Range;

use pulp::Simd;

use crate::counters::Counters;

use dhcd_kernels::overlap::{boxes_meet_from, BoxRows, MAX_BOX_ROW};

pub(crate) type FeatureBox = ([f32; 3], [f32; 3]);

/// The most candidates of one kind the queries stage at once for their batch filters
/// (`dhcd_kernels::apart`): a leaf pair whose features could give more (vertices times
/// triangles, edges times edges) is enumerated in parts of the first leaf's features
/// ([`parts`]), so the scratch stays bounded however large the leaves (a fixed-depth tree's
/// leaves may hold thousands of triangles). Pairs of default leaves (64 triangles) are one
/// part.
pub(crate) const MAX_STAGED: usize = 1 << 16;

/// `range` in consecutive parts, each of at most `MAX_STAGED / per` items (at least one): the
/// parts of a leaf's features whose candidates, at most `per` each, can be staged together.
pub(crate) fn parts(range: Range<usize>, per: usize) -> impl Iterator<Item = Range<usize>> {
    let step = (MAX_STAGED / per.max(1)).max(1);
    let end = range.end;
    range.step_by(step).map(move |s| s..(s + step).min(end))
}

/// The union of the first `n` boxes of `rows` (empty: `+inf..-inf`).
// PERF: vector min / max on the dispatched backend; a fold of `f32::min` stayed scalar (4-6%
// of a proximity query). Boxes hold no NaN, so the vector min is `f32::min`.
#[inline(always)]
fn union_of<S: Simd>(simd: S, rows: &BoxRows, n: usize) -> FeatureBox {
    // No closures: one may be compiled without the backend's target features.
    let lo = [
        row_min(simd, &rows[0][..n]),
        row_min(simd, &rows[1][..n]),
        row_min(simd, &rows[2][..n]),
    ];
    let hi = [
        row_max(simd, &rows[3][..n]),
        row_max(simd, &rows[4][..n]),
        row_max(simd, &rows[5][..n]),
    ];
    (lo, hi)
}

/// The least of `row` (`+inf` if empty).
#[inline(always)]
fn row_min<S: Simd>(simd: S, row: &[f32]) -> f32 {
    let (head, tail) = S::as_simd_f32s(row);
    let mut m = simd.splat_f32s(f32::INFINITY);
    for &x in head {
        m = simd.min_f32s(m, x);
    }
    let mut least = simd.reduce_min_f32s(m);
    for &x in tail {
        least = least.min(x);
    }
    least
}

/// The greatest of `row` (`-inf` if empty).
#[inline(always)]
fn row_max<S: Simd>(simd: S, row: &[f32]) -> f32 {
    let (head, tail) = S::as_simd_f32s(row);
    let mut m = simd.splat_f32s(f32::NEG_INFINITY);
    for &x in head {
        m = simd.max_f32s(m, x);
    }
    let mut most = simd.reduce_max_f32s(m);
    for &x in tail {
        most = most.max(x);
    }
    most
}

/// The bits of boxes `base..base + 64` of the first `n` of `rows` that meet `probe` (bit
/// `j` for box `base + j`).
#[inline(always)]
fn meeting<S: Simd>(simd: S, probe: &FeatureBox, rows: &BoxRows, base: usize, n: usize) -> u64 {
    boxes_meet_from(simd, probe.0, probe.1, rows, base, n)
}

/// Whether two closed boxes meet.
#[inline(always)]
fn meet(a: &FeatureBox, b: &FeatureBox) -> bool {
    (0..3).all(|k| a.0[k] <= b.1[k] && b.0[k] <= a.1[k])
}

/// `b` grown by `m` along every axis, rounded outward.
#[inline(always)]
fn grown(b: &FeatureBox, m: f32) -> FeatureBox {
    (
        b.0.map(|x| (x - m).next_down()),
        b.1.map(|x| (x + m).next_up()),
    )
}

/// The closed box of points `p` (`f32` values of the hierarchy's positions), widened by an
/// ulp when they are roundings of `f64` positions, so it holds the exact points too.
#[inline(always)]
pub(crate) fn points_box<const N: usize>(p: [[f32; 3]; N], rounded: bool) -> FeatureBox {
    let mut b = (p[0], p[0]);
    for q in &p[1..] {
        b.0 = std::array::from_fn(|k| b.0[k].min(q[k]));
        b.1 = std::array::from_fn(|k| b.1[k].max(q[k]));
    }
    if rounded {
        (b.0.map(f32::next_down), b.1.map(f32::next_up))
    } else {
        b
    }
}

/// An edge (internal vertex indices) as its original indices, smaller first, and its
/// internal indices in that same order. `order` maps internal to original indices.
#[inline(always)]
fn ordered_edge(order: &[u32], [s, t]: [u32; 2]) -> ([u32; 2], [u32; 2]) {
    let (os, ot) = (order[s as usize], order[t as usize]);
    if os < ot {
        ([os, ot], [s, t])
    } else {
        ([ot, os], [t, s])
    }
}

/// A leaf's triangles as candidates: their boxes (the first `len` of six rows), the internal
/// index of the first, and every triangle's corners (internal indices).
pub(crate) struct LeafTriangles<'a> {
    pub(crate) rows: BoxRows<'a>,
    pub(crate) len: usize,
    pub(crate) first: usize,
    pub(crate) corners: &'a [[u32; 3]],
}

/// A leaf's own edges as candidates (internal vertex indices) with their boxes, and the
/// internal-to-original vertex order of their mesh.
pub(crate) struct LeafEdges<'a> {
    pub(crate) edges: &'a [[u32; 2]],
    pub(crate) rows: BoxRows<'a>,
    pub(crate) order: &'a [u32],
}

/// An edge of a candidate pair: its original vertex indices, smaller first, and its
/// internal indices in the same order ([`ordered_edge`]).
#[derive(Clone, Copy)]
pub(crate) struct CandidateEdge {
    pub(crate) ids: [u32; 2],
    pub(crate) internal: [u32; 2],
}

/// The candidate enumeration of one query: the boxes' growth and whether the two sides are
/// one mesh. `stopped` is read before each row of 64 boxes, so a query stops promptly when
/// its budget says so (a row may hold pairs that take the exact path).
pub(crate) struct Candidates<'c> {
    pub(crate) self_query: bool,
    /// The query's distance as an `f32` not below it: the boxes' growth.
    pub(crate) margin: f32,
    pub(crate) stopped: &'c dyn Fn() -> bool,
}

impl Candidates<'_> {
    /// The vertices `vertices` (internal, of one leaf; `vertex_box(v)` their boxes) against
    /// the triangles `tris` of another (or the same) leaf: `decide(v, t)` (internal indices)
    /// for every pair whose grown boxes meet, but a triangle containing the vertex in a self
    /// query; each counted in `prim_tests`.
    // PERF: mask loops, not closures around the box tests: a closure may be compiled without
    // the dispatched target features (the kernel then calls every intrinsic).
    #[inline(always)]
    pub(crate) fn vertices_vs_triangles<S: Simd>(
        &self,
        simd: S,
        vertices: Range<usize>,
        vertex_box: impl Fn(usize) -> FeatureBox,
        tris: &LeafTriangles<'_>,
        counters: &mut Counters,
        mut decide: impl FnMut(usize, usize),
    ) {
        let (rows, n) = (&tris.rows, tris.len);
        let near = grown(&union_of(simd, rows, n), self.margin);
        for v in vertices {
            let vbox = vertex_box(v);
            if !meet(&vbox, &near) {
                continue;
            }
            let probe = grown(&vbox, self.margin);
            for base in (0..n).step_by(MAX_BOX_ROW) {
                if (self.stopped)() {
                    return;
                }
                let mut bits = meeting(simd, &probe, rows, base, n);
                while bits != 0 {
                    let t = tris.first + base + bits.trailing_zeros() as usize;
                    bits &= bits - 1;
                    if self.self_query && tris.corners[t].contains(&(v as u32)) {
                        continue;
                    }
                    counters.prim_tests += 1;
                    decide(v, t);
                }
            }
        }
    }

    /// The own edges `a[within]` of one leaf against `b` of another (`same_leaf`: the same
    /// leaf of a self query, each unordered pair once): `decide(x, y)` for every pair whose
    /// grown boxes meet, but edges sharing a vertex in a self query; each counted in
    /// `prim_tests`. `x` is `a`'s edge and `y` `b`'s, but in a self query the edge with the
    /// smaller original indices comes first (both sides are then one mesh).
    #[allow(clippy::too_many_arguments)]
    #[inline(always)]
    pub(crate) fn edges_vs_edges<S: Simd>(
        &self,
        simd: S,
        a: &LeafEdges<'_>,
        within: Range<usize>,
        b: &LeafEdges<'_>,
        same_leaf: bool,
        counters: &mut Counters,
        mut decide: impl FnMut(CandidateEdge, CandidateEdge),
    ) {
        let (ea, eb) = (a.edges, b.edges);
        let (ra, rb) = (&a.rows, &b.rows);
        let near = grown(&union_of(simd, rb, eb.len()), self.margin);
        for base_a in within.clone().step_by(MAX_BOX_ROW) {
            let mut near_bits = meeting(simd, &near, ra, base_a, within.end);
            while near_bits != 0 {
                let i = base_a + near_bits.trailing_zeros() as usize;
                near_bits &= near_bits - 1;
                let [u0, u1] = ea[i];
                let abox = (
                    [ra[0][i], ra[1][i], ra[2][i]],
                    [ra[3][i], ra[4][i], ra[5][i]],
                );
                let probe = grown(&abox, self.margin);
                let (ids, internal) = ordered_edge(a.order, ea[i]);
                let x = CandidateEdge { ids, internal };
                // A leaf with itself: only j > i.
                let from = if same_leaf { i + 1 } else { 0 };
                for base in (from..eb.len()).step_by(MAX_BOX_ROW) {
                    if (self.stopped)() {
                        return;
                    }
                    let mut bits = meeting(simd, &probe, rb, base, eb.len());
                    while bits != 0 {
                        let j = base + bits.trailing_zeros() as usize;
                        bits &= bits - 1;
                        let [w0, w1] = eb[j];
                        if self.self_query && (u0 == w0 || u0 == w1 || u1 == w0 || u1 == w1) {
                            continue;
                        }
                        counters.prim_tests += 1;
                        let (ids, internal) = ordered_edge(b.order, eb[j]);
                        let y = CandidateEdge { ids, internal };
                        if self.self_query && y.ids < x.ids {
                            decide(y, x);
                        } else {
                            decide(x, y);
                        }
                    }
                }
            }
        }
    }
}
