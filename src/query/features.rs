//! The feature-pair layer under the queries on features (proximity, CCD, and through them
//! the contact set and the step size): the candidate feature pairs of one leaf pair,
//! enumerated once, generic over the decision each query makes of a candidate.
//!
//! Ownership makes each candidate unique: every vertex belongs to one leaf (its own
//! vertices, the ones first seen in it) and so does every edge (the leaf of its first
//! triangle), so a vertex-triangle pair is met only in the leaf pair (vertex's leaf,
//! triangle's leaf) and an edge pair only in the pair of their leaves, however many
//! triangles share the features. Inside a leaf pair, features are culled first by the other
//! leaf's bounds (a box holding all its boxes, kept with the leaf's boxes rather than computed
//! per leaf pair) grown by the query's margin, then pair by pair by their boxes grown by it
//! ([`Candidates`]); in a self query, pairs sharing a vertex are skipped. Boxes are `f32`,
//! closed, rounded outward from the positions; a leaf's boxes are six rows (`lo xyz`, `hi
//! xyz`) tested 64 at a time by [`boxes_meet_from`], the vertices' and edges' against the
//! other leaf's bounds as well as each one's against the other leaf's boxes.

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

/// The bits of boxes `base..base + 64` of the first `n` of `rows` that meet `probe` (bit
/// `j` for box `base + j`).
#[inline(always)]
fn meeting<S: Simd>(simd: S, probe: &FeatureBox, rows: &BoxRows, base: usize, n: usize) -> u64 {
    boxes_meet_from(simd, probe.0, probe.1, rows, base, n)
}

/// `b` grown by `m` along every axis, rounded outward.
#[inline(always)]
fn grown(b: &FeatureBox, m: f32) -> FeatureBox {
    (
        b.0.map(|x| (x - m).next_down()),
        b.1.map(|x| (x + m).next_up()),
    )
}

/// A leaf's triangles as candidates: their boxes (the first `len` of six rows) and a box
/// holding them all (`bounds`), the internal index of the first, and every triangle's corners
/// (internal indices).
pub(crate) struct LeafTriangles<'a> {
    pub(crate) rows: BoxRows<'a>,
    pub(crate) len: usize,
    pub(crate) bounds: FeatureBox,
    pub(crate) first: usize,
    pub(crate) corners: &'a [[u32; 3]],
}

/// A leaf's own vertices as candidates: their boxes (six rows, one entry per vertex of its
/// run) and the internal index of the first.
pub(crate) struct LeafVertices<'a> {
    pub(crate) rows: BoxRows<'a>,
    pub(crate) first: usize,
}

/// A leaf's own edges as candidates: each as its internal and (`ids`, same place) original
/// vertex indices, the smaller original index first (`tree::edges::LeafEdges`), with their
/// boxes and a box holding them all (`bounds`).
pub(crate) struct LeafEdges<'a> {
    pub(crate) edges: &'a [[u32; 2]],
    pub(crate) ids: &'a [[u32; 2]],
    pub(crate) rows: BoxRows<'a>,
    pub(crate) bounds: FeatureBox,
}

/// The box of `rows`' first `n` boxes (empty: `+inf..-inf`): the bounds a leaf keeps with
/// its boxes.
pub(crate) fn bounds_of(rows: &BoxRows, n: usize) -> FeatureBox {
    let least = |row: &[f32]| row[..n].iter().fold(f32::INFINITY, |m, &x| m.min(x));
    let most = |row: &[f32]| row[..n].iter().fold(f32::NEG_INFINITY, |m, &x| m.max(x));
    (
        [least(rows[0]), least(rows[1]), least(rows[2])],
        [most(rows[3]), most(rows[4]), most(rows[5])],
    )
}

/// An edge of a candidate pair: its original vertex indices, smaller first, and its
/// internal indices in the same order.
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
    /// The vertices `vertices.first + i` for `i` in `within` (of one leaf) against the
    /// triangles `tris` of another (or the same) leaf: `decide(v, t)` (internal indices) for
    /// every pair whose grown boxes meet, but a triangle containing the vertex in a self
    /// query; each counted in `prim_tests`.
    // PERF: mask loops, not closures around the box tests: a closure may be compiled without
    // the dispatched target features (the kernel then calls every intrinsic).
    #[inline(always)]
    pub(crate) fn vertices_vs_triangles<S: Simd>(
        &self,
        simd: S,
        vertices: &LeafVertices<'_>,
        within: Range<usize>,
        tris: &LeafTriangles<'_>,
        counters: &mut Counters,
        mut decide: impl FnMut(usize, usize),
    ) {
        let (rv, rows, n) = (&vertices.rows, &tris.rows, tris.len);
        let near = grown(&tris.bounds, self.margin);
        for base_v in within.clone().step_by(MAX_BOX_ROW) {
            let mut near_bits = meeting(simd, &near, rv, base_v, within.end);
            while near_bits != 0 {
                let i = base_v + near_bits.trailing_zeros() as usize;
                near_bits &= near_bits - 1;
                let v = vertices.first + i;
                let vbox = (
                    [rv[0][i], rv[1][i], rv[2][i]],
                    [rv[3][i], rv[4][i], rv[5][i]],
                );
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
        let near = grown(&b.bounds, self.margin);
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
                let x = CandidateEdge {
                    ids: a.ids[i],
                    internal: ea[i],
                };
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
                        let y = CandidateEdge {
                            ids: b.ids[j],
                            internal: eb[j],
                        };
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
