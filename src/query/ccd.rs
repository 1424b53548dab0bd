//! Continuous collision detection over a step: every vertex-triangle and edge-edge pair
//! that touches at some time of the step, with its time of impact, or only the earliest.
//!
//! Every vertex moves on the straight line from its position at t0 to its position at t1
//! (`t` in `[0, 1]`). The walk is the one of every query, on the bounds of each region over
//! the whole step ([`crate::bv::swept`]: the union box, or the moving ball of DH and
//! spheres), tested with SIMD kernels; two regions whose features touch during the step
//! have bounds that meet during the step, so every colliding pair lies in a leaf pair the
//! walk reaches. As for proximity, each vertex and each edge belongs to one leaf (so each
//! feature pair is met in one leaf pair, however many triangles share it). A leaf pair is
//! skipped when on one axis a leaf lies beyond the other by more than the minimum distance
//! at t0 and at t1 (the gap along a fixed axis is concave in t under linear motion: two
//! leaves moving the same way, whose boxes over the step overlap, are apart all step). Each
//! leaf pair then culls its feature pairs by their own boxes over the step (in `f32`,
//! rounded outward, grown by the minimum distance), stages them, and ends 64 at a time those
//! certainly apart over `[0, t_max]` in `f64` lanes (not under the step size's per-pair
//! minimum distances): along the line between their centroids at t0
//! ([`dhcd_kernels::apart::centroids_apart_with`], the first axis of [`crate::ccd`]'s cull),
//! then, for the pairs that axis leaves, by their distance at t0 against the most their
//! relative motion closes by `t_max` ([`dhcd_kernels::apart::apart_beyond_motion_with`]:
//! the neighbours of a sheet that slides or bends a little); the exact test of
//! [`crate::ccd`] decides the rest:
//! whether the pair touches in `[0, t_max]` is exact for the `f64` input, and the time of
//! impact is never later than the true one and at most [`crate::ccd::TOI_TOLERANCE`]
//! earlier.
//!
//! **Modes** ([`CcdMode`]). `All` reports every colliding pair with its time of impact.
//! `Earliest` is what a line search asks: the least time of impact `toi`, and every pair
//! whose own time of impact is at most `toi + TOI_TOLERANCE`. That holds every pair whose
//! exact first contact is the earliest one (ties included, however many), and no pair whose
//! exact first contact is more than `2 * TOI_TOLERANCE` after it. The walk keeps the
//! earliest time found so far (shared by all threads) and tests each later pair only up to
//! it plus a slack, so most pairs stop early; the pairs found near the best are then tested
//! again over the whole interval, so the answer does not depend on the order, the threads,
//! the method or which path (float filter or exact) decided a pair. (Its work counters do
//! depend on the order.) Once the best time is below an eighth of the time the bounds
//! reach, the walk starts again on bounds fitted only up to that time plus the slack
//! ([`Swept::until`]): where some contact is close at t0, as in most simulation steps,
//! bounds over the first instants of the step meet far fewer pairs than bounds over all of
//! it. A time limit below 1 fits the bounds up to it the same way, in both modes.
//!
//! Results are in the caller's original indices, sorted, the same for every method and thread
//! count. `prim_tests` counts the feature pairs given to the exact test, `contacts` the
//! pairs reported, `bv_updates` the bounds fitted over the step.

use std::borrow::Cow;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};

use pulp::Simd;

use super::features::{
    bounds_of, parts, CandidateEdge, Candidates, FeatureBox, LeafEdges, LeafTriangles, LeafVertices,
};
use crate::bv::swept::{f32_down, f32_up, Step};
use crate::bv::BoundingVolume;
use crate::ccd::{self, CcdOptions, TOI_TOLERANCE};
use crate::control::Budget;
use crate::counters::Counters;
use crate::error::{Positions, Result};
use crate::hierarchy::Hierarchy;
use crate::mesh::check_positions_f64;
use crate::par::Par;
use crate::tree::RegionTree;
use crate::walk::{self, Query, Side, Workspace};
use dhcd_kernels::apart::{
    apart_beyond_motion_with, centroids_apart_with, MovingPoints, MAX_PAIRS,
};
use dhcd_kernels::narrow::low_bits;
use dhcd_kernels::overlap::BoxRows;
use listed::ListedCount;
pub(crate) use listed::{gap_over_listed, Listed, Listing, MAX_LISTED};

mod listed;

/// One mesh's motion over a step: every vertex's position at t0 and at t1, in the mesh's
/// vertex order (`f64`, finite and within the `f32` range, as [`crate::Mesh::new_f64`]
/// asks).
#[derive(Clone, Copy, Debug)]
pub struct Motion<'a> {
    /// Positions at the start of the step (t = 0).
    pub x0: &'a [[f64; 3]],
    /// Positions at the end of the step (t = 1).
    pub x1: &'a [[f64; 3]],
}

impl<'a> Motion<'a> {
    /// The step from `x0` to `x1` (checked by the query: same length as the mesh, finite).
    pub fn new(x0: &'a [[f64; 3]], x1: &'a [[f64; 3]]) -> Self {
        Self { x0, x1 }
    }
}

/// What a CCD query reports.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum CcdMode {
    /// Every colliding pair with its time of impact.
    #[default]
    All,
    /// The earliest time of impact, with every pair whose time of impact is within
    /// [`TOI_TOLERANCE`] of it (every pair whose exact first contact is the earliest).
    Earliest,
}

/// A CCD query: the narrow-phase options (time limit, minimum distance) and the mode.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct CcdQuery {
    /// Time limit and minimum distance.
    pub options: CcdOptions,
    /// All pairs, or the earliest time.
    pub mode: CcdMode,
}

impl CcdQuery {
    /// Every colliding pair over the whole step, at distance 0.
    pub fn all() -> Self {
        Self::default()
    }

    /// The earliest time of impact over the whole step, at distance 0.
    pub fn earliest() -> Self {
        Self {
            mode: CcdMode::Earliest,
            ..Self::default()
        }
    }

    /// Pairs collide when they come within `d` (checked by the query: finite, `>= 0`).
    pub fn with_min_distance(mut self, d: f64) -> Self {
        self.options.min_distance = d;
        self
    }

    /// Only times in `[0, t_max]` count (checked by the query: `t_max` in `[0, 1]`).
    pub fn with_t_max(mut self, t_max: f64) -> Self {
        self.options.t_max = t_max;
        self
    }
}

/// A vertex that meets a triangle during the step: in a pair query, a vertex of the first
/// mesh and a triangle of the second (see [`FaceImpact`] for the other way round); in a self
/// query, a vertex and a triangle not containing it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct VertexImpact {
    /// The vertex (original index).
    pub vertex: u32,
    /// The triangle (original index).
    pub triangle: u32,
    /// Time of impact in `[0, t_max]`: never after the first contact, at most
    /// [`TOI_TOLERANCE`] before it.
    pub toi: f64,
}

/// A triangle of the first mesh met by a vertex of the second during the step (pair
/// queries only).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FaceImpact {
    /// The triangle of the first mesh (original index).
    pub triangle: u32,
    /// The vertex of the second mesh (original index).
    pub vertex: u32,
    /// Time of impact, as in [`VertexImpact::toi`].
    pub toi: f64,
}

/// Two edges that meet during the step: `a` of the first mesh and `b` of the second (pair
/// queries), or two edges of one mesh sharing no vertex with `a < b` (self queries); each
/// edge is its two vertices' original indices, smaller first.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EdgeImpact {
    /// The edge of the first mesh (or the first edge of a self pair).
    pub a: [u32; 2],
    /// The edge of the second mesh (or the second edge of a self pair).
    pub b: [u32; 2],
    /// Time of impact, as in [`VertexImpact::toi`].
    pub toi: f64,
}

/// Result of a CCD query, in the caller's original indices.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Impacts {
    /// Sorted by `(vertex, triangle)`.
    pub vertex_face: Vec<VertexImpact>,
    /// Sorted by `(triangle, vertex)`; empty in a self query.
    pub face_vertex: Vec<FaceImpact>,
    /// Sorted by `(a, b)`.
    pub edge_edge: Vec<EdgeImpact>,
    /// The earliest time of impact of the step (`None`: nothing collides).
    pub toi: Option<f64>,
    /// `bv_tests` (node pairs tested over the step), `bv_updates` (bounds fitted over the
    /// step), `prim_tests` (feature pairs given to the exact test), `contacts` (pairs
    /// reported).
    pub counters: Counters,
}

/// Every vertex-triangle and edge-edge pair of `a` and `b` that collides during the step
/// (`a_motion`, `b_motion`), on the calling thread. Errors: invalid options
/// ([`crate::Error::InvalidTimeLimit`], [`crate::Error::InvalidMinDistance`]) or
/// positions ([`crate::Error::WrongVertexCount`], [`crate::Error::NonFinite`],
/// [`crate::Error::OutOfRange`]), nothing computed.
///
/// The hierarchies give their region trees and triangles (and DH its central vertices);
/// their current poses are not read: the positions are the motions'.
pub fn ccd_pair<K: BoundingVolume>(
    a: &Hierarchy<K>,
    a_motion: Motion<'_>,
    b: &Hierarchy<K>,
    b_motion: Motion<'_>,
    query: &CcdQuery,
) -> Result<Impacts> {
    ccd_pair_with(
        a,
        a_motion,
        b,
        b_motion,
        query,
        &mut Workspace::default(),
        Par::Seq,
    )
}

/// [`ccd_pair`] with caller-owned scratch and a choice of parallelism. The result does not
/// depend on `par`.
pub fn ccd_pair_with<K: BoundingVolume>(
    a: &Hierarchy<K>,
    a_motion: Motion<'_>,
    b: &Hierarchy<K>,
    b_motion: Motion<'_>,
    query: &CcdQuery,
    ws: &mut Workspace,
    par: Par,
) -> Result<Impacts> {
    query.options.validate()?;
    let sa = Swept::new(a, a_motion)?;
    let sb = Swept::new(b, b_motion)?;
    let best = earliest_bound(query);
    let control = ws.control.clone();
    let budget = Budget::new(&control);
    Ok(run(
        &sa,
        &sb,
        false,
        query,
        best.as_ref(),
        &budget,
        None,
        ws,
        par,
    )?
    .0)
}

/// Every vertex-triangle pair (the triangle not containing the vertex) and edge-edge pair
/// (sharing no vertex) of one mesh that collides during the step, on the calling thread.
pub fn self_ccd<K: BoundingVolume>(
    h: &Hierarchy<K>,
    motion: Motion<'_>,
    query: &CcdQuery,
) -> Result<Impacts> {
    self_ccd_with(h, motion, query, &mut Workspace::default(), Par::Seq)
}

/// [`self_ccd`] with caller-owned scratch and a choice of parallelism.
pub fn self_ccd_with<K: BoundingVolume>(
    h: &Hierarchy<K>,
    motion: Motion<'_>,
    query: &CcdQuery,
    ws: &mut Workspace,
    par: Par,
) -> Result<Impacts> {
    query.options.validate()?;
    let step = checked_step(h.tree(), motion)?;
    let control = ws.control.clone();
    let budget = Budget::new(&control);
    if whole_mesh_is_clear(
        h.tree(),
        &step,
        query.options.t_max,
        query.options.min_distance,
    ) {
        budget.finish()?;
        return Ok(Impacts::default());
    }
    let s = Swept::of_step(h, Cow::Owned(step));
    let best = earliest_bound(query);
    Ok(run(&s, &s, true, query, best.as_ref(), &budget, None, ws, par)?.0)
}

/// Whether no feature pair of the whole mesh comes within `distance` by `horizon` of
/// `step` ([`super::clearance`] on the root): nothing to fit or walk, as for a smooth sheet
/// moving a small step. The walk would ask the same of the root first.
pub(crate) fn whole_mesh_is_clear(
    tree: &RegionTree,
    step: &Step,
    horizon: f64,
    distance: f64,
) -> bool {
    super::clearance::motion_is_clear(tree, 0, &step.x0, &step.x1, horizon, distance)
}

/// One hierarchy over a step: its positions at t0 and t1 (internal order), its node bounds
/// over the step (fitted lazily by the walk), and the boxes over the step of its triangles
/// (internal order) and own edges (leaf-edge order), as six rows each.
pub(crate) struct Swept<'h, K: BoundingVolume> {
    h: &'h Hierarchy<K>,
    /// The exact tests' positions.
    step: Cow<'h, Step>,
    /// The positions the bounds and boxes are fitted to, when not `step`'s: t0 and a time
    /// `by < 1` of the step ([`Swept::until`]).
    culling: Option<Step>,
    /// The time `culling` reaches (1: the whole step).
    horizon: f64,
    /// A bound on how far `culling`'s positions at `horizon` lie from the exact points of
    /// the motion ([`horizon_error`]; 0 for the whole step).
    horizon_error: f64,
    /// `step`'s largest coordinate magnitude: the rounding bound of the exact tests' culls
    /// ([`ccd::pair_until`]).
    magnitude: f64,
    bounds: K::Swept,
    /// Each vertex's box over the culling positions ([`vertex_boxes`]), as six rows.
    vertex_rows: [Vec<f32>; 6],
    tri_rows: [Vec<f32>; 6],
    edge_rows: [Vec<f32>; 6],
    /// Per node (filled for leaves): the box of its triangles' corners and its own vertices,
    /// at t0 and at t1.
    leaf_ends: Vec<[FeatureBox; 2]>,
    /// Per node (filled for leaves): the box of its triangles' boxes and that of its own
    /// edges' boxes, over the culling positions.
    leaf_bounds: Vec<[FeatureBox; 2]>,
}

/// A bound on how far a position at a time `by` of `steps`, computed in `f64` as `x0 + by
/// (x1 - x0)` ([`Swept::until`]), lies from the exact point: three roundings of values at
/// most twice the largest coordinate `M` in size, at most `4 EPSILON M` per coordinate, so
/// `8 EPSILON M` in norm (rounded up), `M` = `magnitude`, the step's largest coordinate.
fn horizon_error(magnitude: f64) -> f64 {
    (8.0 * f64::EPSILON * magnitude).next_up()
}

/// The largest coordinate magnitude of a step's positions, at t0 and t1.
fn largest_magnitude(step: &Step) -> f64 {
    let mut largest = 0.0f64;
    for p in step.x0.iter().chain(&step.x1) {
        largest = largest.max(p[0].abs()).max(p[1].abs()).max(p[2].abs());
    }
    largest
}

/// Two leaves' points certainly farther than `margin` apart all step: on some axis, one
/// leaf's box lies beyond the other's by more than `margin` at t0 and at t1, on the same
/// side. The gap along a fixed axis between two sets of linearly moving points is concave
/// in t (a minimum of linear functions minus a maximum of them), so its ends bound it; the
/// boxes are rounded outward and the margin's sum rounded up, so the test is certain. This
/// ends the leaf pairs whose boxes over the step overlap only because both leaves move the
/// same way (a sheet sliding in its plane, a body translating), before their feature pairs
/// are enumerated.
#[inline(always)]
fn leaves_apart(a: &[FeatureBox; 2], b: &[FeatureBox; 2], margin: f32) -> bool {
    let beyond =
        |lo: &FeatureBox, hi: &FeatureBox, k: usize| (lo.1[k] + margin).next_up() < hi.0[k];
    (0..3).any(|k| {
        (beyond(&a[0], &b[0], k) && beyond(&a[1], &b[1], k))
            || (beyond(&b[0], &a[0], k) && beyond(&b[1], &a[1], k))
    })
}

/// `motion`'s positions (checked: the mesh's vertex count, finite, in range) in `tree`'s
/// internal vertex order.
pub(crate) fn checked_step(tree: &RegionTree, motion: Motion<'_>) -> Result<Step> {
    check_positions_f64(motion.x0, tree.vertex_total(), Positions::Start)?;
    check_positions_f64(motion.x1, tree.vertex_total(), Positions::End)?;
    Ok(Step::gather(tree, motion.x0, motion.x1))
}

/// Every vertex's position at t0 and at t1 of `step`, each rounded outward to `f32`: `[lo0,
/// hi0, lo1, hi1]`. Rounding outward is monotone (`f32_down(min(x, y)) = min(f32_down(x),
/// f32_down(y))`), so the box of any set of these points is the `f32` min and max of its
/// vertices' entries, the same box as rounding the `f64` box once: each vertex is rounded
/// once rather than once per feature and node that holds it.
fn vertex_ends(step: &Step) -> Vec<[[f32; 3]; 4]> {
    step.x0
        .iter()
        .zip(&step.x1)
        .map(|(p, q)| {
            [
                p.map(f32_down),
                p.map(f32_up),
                q.map(f32_down),
                q.map(f32_up),
            ]
        })
        .collect()
}

/// Each vertex's box over the step (both ends), from [`vertex_ends`].
fn vertex_boxes(ends: &[[[f32; 3]; 4]]) -> Vec<[f32; 6]> {
    ends.iter()
        .map(|[lo0, hi0, lo1, hi1]| {
            let lo = std::array::from_fn::<f32, 3, _>(|k| lo0[k].min(lo1[k]));
            let hi = std::array::from_fn::<f32, 3, _>(|k| hi0[k].max(hi1[k]));
            [lo[0], lo[1], lo[2], hi[0], hi[1], hi[2]]
        })
        .collect()
}

/// Six rows of boxes, one per point set: the union of its vertices' boxes ([`vertex_boxes`]).
fn box_rows<const N: usize>(
    sets: impl ExactSizeIterator<Item = [u32; N]>,
    boxes: &[[f32; 6]],
) -> [Vec<f32>; 6] {
    let mut rows: [Vec<f32>; 6] = std::array::from_fn(|_| Vec::with_capacity(sets.len()));
    for s in sets {
        let mut b = boxes[s[0] as usize];
        for &v in &s[1..] {
            let c = &boxes[v as usize];
            for k in 0..3 {
                b[k] = b[k].min(c[k]);
                b[3 + k] = b[3 + k].max(c[3 + k]);
            }
        }
        for (row, x) in rows.iter_mut().zip(b) {
            row.push(x);
        }
    }
    rows
}

impl<'h, K: BoundingVolume> Swept<'h, K> {
    pub(crate) fn new(h: &'h Hierarchy<K>, motion: Motion<'_>) -> Result<Self> {
        Ok(Self::of_step(
            h,
            Cow::Owned(checked_step(h.tree(), motion)?),
        ))
    }

    /// `h` over `step` (its positions in `h`'s internal order, checked).
    pub(crate) fn of_step(h: &'h Hierarchy<K>, step: Cow<'h, Step>) -> Self {
        let magnitude = largest_magnitude(&step);
        Self::fitted(h, step, magnitude, None)
    }

    /// The same hierarchy and step, its bounds and boxes fitted over `[0, by]` only, for a
    /// walk whose pairs are tested up to `by` (earliest mode once a time of impact is
    /// known, the step size's gap walk, a time limit below 1): far fewer pairs meet when
    /// `by` is small. The positions at `by` are computed in `f64`, each within
    /// [`horizon_error`] of the exact point of its line, and the ends of a linear motion
    /// bound it in between (boxes, leaf ends) or make it a moving ball: so the bounds hold
    /// every pair that comes within a margin by `by` once the walk's margin is grown by
    /// that error on each side ([`SweptQuery::new`]).
    pub(crate) fn until<'s>(&'s self, by: f64) -> Swept<'s, K> {
        let step = Cow::Borrowed(self.step.as_ref());
        if by >= 1.0 {
            return Swept::fitted(self.h, step, self.magnitude, None);
        }
        let at = |(p, q): (&[f64; 3], &[f64; 3])| -> [f64; 3] {
            std::array::from_fn(|k| p[k] + by * (q[k] - p[k]))
        };
        let culling = Step {
            x0: self.step.x0.clone(),
            x1: self.step.x0.iter().zip(&self.step.x1).map(at).collect(),
        };
        let mut s = Swept::fitted(self.h, step, self.magnitude, Some(culling));
        s.horizon = by;
        s.horizon_error = horizon_error(s.magnitude);
        s
    }

    /// The time the bounds and boxes reach (1: the whole step).
    pub(crate) fn horizon(&self) -> f64 {
        self.horizon
    }

    /// `h`'s bounds and boxes fitted to `culling` (or `step`); `magnitude` is `step`'s
    /// largest coordinate magnitude ([`largest_magnitude`]).
    fn fitted(
        h: &'h Hierarchy<K>,
        step: Cow<'h, Step>,
        magnitude: f64,
        culling: Option<Step>,
    ) -> Self {
        let tree = h.tree();
        let fit = culling.as_ref().unwrap_or(&step);
        let vertex_ends = vertex_ends(fit);
        let boxes = vertex_boxes(&vertex_ends);
        let tri_rows = box_rows(tree.triangles().iter().copied(), &boxes);
        let edge_rows = box_rows(tree.leaf_edges().all().iter().copied(), &boxes);
        let triangles = tree.triangles();
        let vertex_rows = std::array::from_fn(|f| boxes.iter().map(|b| b[f]).collect());
        let mut ends = Vec::with_capacity(tree.node_count());
        let mut leaf_bounds = Vec::with_capacity(tree.node_count());
        for n in 0..tree.node_count() {
            // An empty box stays `+inf..-inf`.
            let mut lo = [[f32::INFINITY; 3]; 2];
            let mut hi = [[f32::NEG_INFINITY; 3]; 2];
            if tree.is_leaf(n) {
                // Its triangles' corners and its own vertices (free points included).
                let corners = triangles[tree.tri_range(n)].iter().flatten();
                for v in corners.map(|&v| v as usize).chain(tree.vert_run(n)) {
                    let [lo0, hi0, lo1, hi1] = &vertex_ends[v];
                    for k in 0..3 {
                        lo[0][k] = lo[0][k].min(lo0[k]);
                        hi[0][k] = hi[0][k].max(hi0[k]);
                        lo[1][k] = lo[1][k].min(lo1[k]);
                        hi[1][k] = hi[1][k].max(hi1[k]);
                    }
                }
            }
            ends.push([0, 1].map(|e| (lo[e], hi[e])));
            let of = |rows: &[Vec<f32>; 6], r: std::ops::Range<usize>| {
                let rows: BoxRows<'_> = std::array::from_fn(|f| &rows[f][r.clone()]);
                bounds_of(&rows, r.len())
            };
            leaf_bounds.push(match tree.leaf_rank(n) {
                Some(rank) => [
                    of(&tri_rows, tree.tri_range(n)),
                    of(&edge_rows, tree.leaf_edges().range_of_rank(rank)),
                ],
                None => [([f32::INFINITY; 3], [f32::NEG_INFINITY; 3]); 2],
            });
        }
        Self {
            h,
            bounds: K::swept(tree),
            step,
            culling,
            horizon: 1.0,
            horizon_error: 0.0,
            magnitude,
            vertex_rows,
            tri_rows,
            edge_rows,
            leaf_ends: ends,
            leaf_bounds,
        }
    }

    pub(crate) fn tree(&self) -> &'h RegionTree {
        self.h.tree()
    }

    /// The positions the bounds and boxes are fitted to (see [`Swept::until`]).
    fn culling(&self) -> &Step {
        self.culling.as_ref().unwrap_or(&self.step)
    }

    /// The boxes over the step of leaf `leaf`'s triangles.
    fn tri_boxes(&self, leaf: usize) -> BoxRows<'_> {
        let r = self.tree().tri_range(leaf);
        std::array::from_fn(|f| &self.tri_rows[f][r.clone()])
    }

    /// Leaf `leaf`'s own edges and their boxes over the step, as candidates.
    fn edges(&self, leaf: usize) -> LeafEdges<'_> {
        let tree = self.tree();
        let rank = tree.leaf_rank(leaf).expect("a leaf");
        let edges = tree.leaf_edges();
        let r = edges.range_of_rank(rank);
        LeafEdges {
            edges: edges.of_rank(rank),
            ids: edges.ids_of_rank(rank),
            rows: std::array::from_fn(|f| &self.edge_rows[f][r.clone()]),
            bounds: self.leaf_bounds[leaf][1],
        }
    }

    /// Leaf `leaf`'s own vertices and their boxes over the step, as candidates.
    fn vertices(&self, leaf: usize) -> LeafVertices<'_> {
        let r = self.tree().vert_run(leaf);
        LeafVertices {
            rows: std::array::from_fn(|f| &self.vertex_rows[f][r.clone()]),
            first: r.start,
        }
    }
}

/// In earliest mode a pair is tested up to the best time so far plus this, so every pair
/// that ties with the final answer is found. The best so far is some pair's time, at least
/// `t*_min - TOI_TOLERANCE`; a pair that ties ([`ties_with`]) has `t* <= toi + TOI_TOLERANCE
/// <= least + 2 TOI_TOLERANCE <= t*_min + 2 TOI_TOLERANCE`, below that bound plus `3
/// TOI_TOLERANCE`, and its time found under the bound is within `3 TOI_TOLERANCE` of the
/// least found, which `settle_earliest` keeps.
const PRUNE_SLACK: f64 = 4.0 * TOI_TOLERANCE;

/// The CCD walk: two hierarchies over a step, the exact test and the mode.
struct SweptQuery<'s, 'h, K: BoundingVolume> {
    a: &'s Swept<'h, K>,
    b: &'s Swept<'h, K>,
    self_query: bool,
    options: CcdOptions,
    /// The culling distance of the node tests: the minimum distance (the step size's
    /// culling distance when `gap` is set), grown by the rounding of the positions the
    /// bounds are fitted to ([`Swept::until`]).
    cull: f64,
    /// `cull` as an `f32` not below it: the leaf and feature boxes' growth.
    margin: f32,
    /// Earliest mode: the walk stops, to start again on bounds fitted up to the best time,
    /// once [`horizon_for`] the best time is at most this ([`RESTART_FACTOR`]).
    restart_below: Option<f64>,
    /// The walk stopped for that.
    abandoned: AtomicBool,
    /// The walk lists the feature pairs it meets that the batch cull does not prove unable
    /// to reach their gap under the listing's rule by the walk's horizon ([`run_passes`]),
    /// up to the listing's `most` (counted in `listed`).
    listing: Option<&'s Listing<'s>>,
    listed: ListedCount,
    /// Earliest mode: the least time of impact found so far, by this walk or any other
    /// sharing the bound ([`earliest_bound`]).
    best: Option<&'s AtomicU64>,
    /// The result pairs so far, against the query's limit, and cancellation.
    budget: &'s Budget<'s>,
    /// The step-size rule: each pair's minimum distance from its distance at t0 (the
    /// options' minimum distance is then only the walk's culling distance).
    gap: Option<Gap>,
    /// Both sides' largest coordinate magnitude ([`ccd::pair_until`]).
    magnitude: f64,
    /// The time both sides' bounds and boxes reach ([`Swept::horizon`]).
    horizon: f64,
}

/// A pair's own boxes over `[0, t_max]` are tested ([`ccd::pair_until`]) only when `t_max`
/// is below this fraction of the walk's horizon. The walk's boxes, fitted over the horizon,
/// met; over nearly the same interval the pair's own boxes meet too, and the test is wasted
/// work (an earliest walk's last pass, where `t_max` is the best time and the horizon just
/// above it: it ended 173 of rod-twist's 1,386,719 pairs, and cost 17% of the pass). Below
/// the restart threshold a walk fits its bounds again, unless it has no restart left; then
/// the pair's boxes stand in for that refit.
const BOXES_UNTIL_BELOW: f64 = 1.0 / RESTART_FACTOR;

/// The IPC Toolkit's step-size rule: a pair at distance `d0` at t0 must stay at least
/// `min_distance + (1 - rescaling) (d0 - min_distance)` apart.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Gap {
    pub(crate) min_distance: f64,
    pub(crate) rescaling: f64,
}

impl Gap {
    /// The rule of the step-size options.
    pub(crate) fn of(options: &crate::contact::StepOptions) -> Self {
        Self {
            min_distance: options.min_distance,
            rescaling: options.rescaling,
        }
    }

    /// The options of one pair (`vertex_face`: `x0` is `[v, t0, t1, t2]`, else `[a0, a1,
    /// b0, b1]`, at t0): its minimum distance by the rule, from its distance at t0 (the
    /// exact closest features' `f64` distance, rounded up a few ulps so that the kept gap is
    /// never below the rule's).
    ///
    /// `None` when the pair cannot reach its gap before `o.t_max`. By then its features
    /// approach each other by at most `A = t_max` times the largest relative displacement of
    /// a vertex of one and a vertex of the other (a point of a feature is a fixed convex
    /// combination of its vertices), so reaching the gap `g = dmin + (1 - s)(d0 - dmin)`
    /// needs `d0 <= g + A`, that is `d0 <= dmin + A / s`: decided exactly on the positions
    /// at t0 before any distance is computed (most pairs are culled by their boxes there).
    #[inline]
    pub(crate) fn options(
        &self,
        vertex_face: bool,
        x0: &[[f64; 3]; 4],
        x1: &[[f64; 3]; 4],
        o: CcdOptions,
    ) -> Option<CcdOptions> {
        if !self.may_reach(vertex_face, x0, x1, o.t_max) {
            return None;
        }
        Some(self.at_gap(vertex_face, x0, o))
    }

    /// `o` with the pair's gap as its minimum distance, from its distance at t0 (`x0`),
    /// without [`Gap::may_reach`]'s cull (the test at the gap decides the same pairs).
    #[inline]
    pub(crate) fn at_gap(
        &self,
        vertex_face: bool,
        x0: &[[f64; 3]; 4],
        o: CcdOptions,
    ) -> CcdOptions {
        use crate::distance::{edge_edge_distance_sq, point_triangle_distance_sq};
        let d0_sq = if vertex_face {
            point_triangle_distance_sq(x0[0], [x0[1], x0[2], x0[3]]).0
        } else {
            edge_edge_distance_sq(x0[0], x0[1], x0[2], x0[3]).0
        };
        let d0 = d0_sq.sqrt();
        let g = self.min_distance + (1.0 - self.rescaling) * (d0 - self.min_distance);
        let g = (g * (1.0 + 16.0 * f64::EPSILON)).max(0.0);
        let g = if g.is_finite() { g } else { f64::MAX };
        CcdOptions {
            min_distance: g,
            ..o
        }
    }

    /// The minimum distance and closing factor with which the motion cull
    /// ([`apart_beyond_motion_with`]) ends exactly the pairs that cannot come within their
    /// kept gap (as [`Gap::at_gap`] computes it) by `t_max`; `None` for a rule it cannot
    /// serve (`rescaling` not in `(2^-40, 1]`).
    ///
    /// The cull proves `d0 > delta' + closing A t` for the relative motion `A` over `[0,
    /// t]`, so the distance at `t` is at least `d0 - A t`. The kept gap is the rule's `g =
    /// dmin + (1 - s)(d0 - dmin)` computed from a rounded `d0` and raised by `16 EPSILON`:
    /// at most `g + 20 EPSILON d0` (`g <= d0` whenever `d0 >= dmin`, and a pair with `d0 <
    /// dmin` is never certified). With `closing >= 1 / (s - 64 EPSILON)` and `delta' >= s dmin
    /// closing`, `d0 > delta' + closing A t` gives `(s - 64 EPSILON) d0 > s dmin + A t`, so
    /// `d0 - A t > g + 64 EPSILON d0`, above the kept gap.
    pub(crate) fn motion_cull(&self) -> Option<(f64, f64)> {
        let s = self.rescaling;
        if !(s > 2f64.powi(-40) && s <= 1.0) {
            return None;
        }
        // Rounded so that each is at least its exact value.
        let closing = (1.0 / (s - 64.0 * f64::EPSILON).next_down()).next_up();
        let delta = ((self.min_distance * s) * closing) * (1.0 + 2f64.powi(-50));
        (delta.is_finite() && closing.is_finite()).then_some((delta, closing))
    }

    /// Whether the pair can reach its gap before `t_max` (see [`Gap::options`]): `false`
    /// when `d0 > dmin + A / s`, decided exactly on the positions at t0.
    #[inline]
    pub(crate) fn may_reach(
        &self,
        vertex_face: bool,
        x0: &[[f64; 3]; 4],
        x1: &[[f64; 3]; 4],
        t_max: f64,
    ) -> bool {
        // PERF: indexed loops, not `array::map`: copies of the arrays through the stack
        // stalled on store forwarding.
        let norm_sq = |v: &[f64; 3]| v[0] * v[0] + v[1] * v[1] + v[2] * v[2];
        let mut u = [[0.0f64; 3]; 4];
        for k in 0..4 {
            for c in 0..3 {
                u[k][c] = x1[k][c] - x0[k][c];
            }
        }
        let split = if vertex_face { 1 } else { 2 };
        // The largest |u_i - u_j| over a vertex i of the first feature and j of the second
        // (the square root of the largest square: sqrt is monotone), plus the rounding of
        // the computed displacements and differences (a few ulps of |u_i| + |u_j|, at most
        // twice the longest |u_k|).
        let mut longest_sq = 0.0f64;
        for v in &u {
            longest_sq = longest_sq.max(norm_sq(v));
        }
        let mut relative_sq = 0.0f64;
        for i in 0..split {
            for j in split..4 {
                let d = [u[i][0] - u[j][0], u[i][1] - u[j][1], u[i][2] - u[j][2]];
                relative_sq = relative_sq.max(norm_sq(&d));
            }
        }
        let relative = relative_sq.sqrt() + 8.0 * f64::EPSILON * longest_sq.sqrt();
        // Within [0, t_max] (in earliest mode the best time so far) a vertex moves `t_max`
        // of its displacement. The pair is kept at the rounded-up gap of `at_gap` (at most
        // `g + 20 EPSILON d0`, see `motion_cull`), which it reaches only if `(s - 20
        // EPSILON) d0 <= s dmin + A t`: divided by `s - 64 EPSILON`, as the motion cull's
        // closing factor, so that no pair the exact test at that gap would find is refused
        // (the walk and the list then find the same pairs). Rounded up (each operation
        // above is within a few ulps).
        let s = self.rescaling - 64.0 * f64::EPSILON;
        if s <= 0.0 {
            return true;
        }
        let reach = ((self.min_distance * self.rescaling + relative * t_max) / s)
            * (1.0 + 16.0 * f64::EPSILON);
        !reach.is_finite() || within_at_start(vertex_face, x0, reach)
    }
}

#[derive(Default)]
struct ImpactOut {
    vertex_face: Vec<VertexImpact>,
    face_vertex: Vec<FaceImpact>,
    edge_edge: Vec<EdgeImpact>,
    /// The feature pairs met, when the walk lists them.
    listed: Listed,
    /// Scratch of the task, not a result: a leaf pair's candidates on their way to the
    /// batch cull.
    staged: Box<Staged>,
}

/// A leaf pair's candidates staged for the batch cull ([`SweptQuery::batch_cull`]), and the
/// poses of up to [`MAX_PAIRS`] of them.
#[derive(Default)]
struct Staged {
    /// Vertex-triangle pairs (internal indices).
    vertex_triangles: Vec<(u32, u32)>,
    /// Edge pairs.
    edges: Vec<(CandidateEdge, CandidateEdge)>,
    /// The two poses of each pair of the current chunk.
    points: MovingPoints,
    /// Whether the motion cull is paying on this task's pairs: for the impact test, and
    /// for a listing walk's list.
    motion: [MotionCull; 2],
}

/// When the motion cull ([`apart_beyond_motion_with`]) runs. It pays where it ends many of
/// the pairs the first axis leaves (a sheet sliding or bending a little, the earliest
/// impact's short horizon: nearly all of them) and costs where it ends few (every pair of
/// bodies closing in over a whole step: armadillo's all-pairs query ends 0.3% and was 6%
/// slower with it). So it runs while it ends at least a quarter of the pairs it sees, judged
/// every [`MotionCull::WINDOW`] pairs; after a poor window it rests for
/// [`MotionCull::REST`] windows' worth of pairs, then tries again. Which pairs it ends never
/// changes an answer, only the work.
#[derive(Default)]
struct MotionCull {
    seen: u32,
    ended: u32,
    /// Pairs still to pass by before it runs again.
    resting: u32,
}

impl MotionCull {
    const WINDOW: u32 = 4096;
    const REST: u32 = 16;

    /// Whether it runs on the next `pairs` pairs; counts them as passed by when resting.
    #[inline(always)]
    fn runs(&mut self, pairs: u32) -> bool {
        if self.resting == 0 {
            return true;
        }
        self.resting = self.resting.saturating_sub(pairs);
        false
    }

    /// It saw `seen` pairs and ended `ended` of them.
    #[inline(always)]
    fn record(&mut self, seen: u32, ended: u32) {
        self.seen += seen;
        self.ended += ended;
        if self.seen >= Self::WINDOW {
            if self.ended * 4 < self.seen {
                self.resting = Self::REST * Self::WINDOW;
            }
            (self.seen, self.ended) = (0, 0);
        }
    }
}

impl ImpactOut {
    /// Pairs held.
    fn len(&self) -> usize {
        self.vertex_face.len() + self.face_vertex.len() + self.edge_edge.len()
    }

    /// The least time of impact of every pair held (`None`: no pair).
    fn least_toi(&self) -> Option<f64> {
        self.vertex_face
            .iter()
            .map(|x| x.toi)
            .chain(self.face_vertex.iter().map(|x| x.toi))
            .chain(self.edge_edge.iter().map(|x| x.toi))
            .reduce(f64::min)
    }
}

/// Earliest mode's bound on the time of impact (`None` in all mode): the least time found so
/// far, as `f64` bits (all times are `>= 0`, so their order is the integers'). Walks that
/// share one bound prune each other's tests; each still settles its own answer
/// ([`SweptQuery::settle_earliest`]), and [`keep_earliest`] settles several walks' answers.
pub(crate) fn earliest_bound(query: &CcdQuery) -> Option<AtomicU64> {
    (query.mode == CcdMode::Earliest).then(|| AtomicU64::new(f64::INFINITY.to_bits()))
}

/// In earliest mode, a walk whose best time of impact falls to `1 / RESTART_FACTOR` of its
/// bounds' horizon (or below) stops and starts again on bounds fitted up to that time
/// ([`Swept::until`]): where a contact is close, far fewer pairs meet over the start of the
/// step than over all of it. The work before the restart is lost, so the horizon must have
/// shrunk enough to pay for it.
const RESTART_FACTOR: f64 = 8.0;

/// The most restarts of one walk (each shrinks the horizon by [`RESTART_FACTOR`] at least).
const MAX_RESTARTS: u32 = 3;

/// The latest time a pair that ties with the best time of impact `best` so far can first
/// touch, rounded up, at most 1: every pair the earliest answer can hold touches by then
/// (see [`PRUNE_SLACK`]), so a walk's bounds need not reach past it.
pub(crate) fn horizon_for(best: f64) -> f64 {
    (best + 8.0 * TOI_TOLERANCE).next_up().min(1.0)
}

/// The time a walk's bounds must reach: the time limit, and in earliest mode
/// [`horizon_for`] the best time so far.
fn wanted_horizon(options: &CcdOptions, best: Option<&AtomicU64>) -> f64 {
    let best = best.map_or(f64::INFINITY, |b| f64::from_bits(b.load(Ordering::Relaxed)));
    options.t_max.min(horizon_for(best))
}

/// The CCD walk of `a` against `b` (options checked), pruned by `best` in earliest mode and
/// counted against `budget`; also the bounds fitted on each side. An error when the budget
/// stopped the walk (this walk or another sharing the budget).
///
/// The walk's bounds are fitted up to the time limit, or in earliest mode the best time
/// so far when one is known ([`Swept::until`], when that is before `a`'s and `b`'s own
/// horizons); in earliest mode the walk starts again on tighter bounds when its best time
/// falls far enough ([`RESTART_FACTOR`]). Pairs are tested on their exact motions either
/// way, so the answer is the same; the work of every walk is counted.
#[allow(clippy::too_many_arguments)]
pub(crate) fn run<K: BoundingVolume>(
    a: &Swept<'_, K>,
    b: &Swept<'_, K>,
    self_query: bool,
    query: &CcdQuery,
    best: Option<&AtomicU64>,
    budget: &Budget<'_>,
    gap: Option<Gap>,
    ws: &mut Workspace,
    par: Par,
) -> Result<(Impacts, [u64; 2])> {
    let (impacts, fitted, _) =
        run_passes(a, b, self_query, query, best, budget, gap, None, ws, par)?;
    Ok((impacts, fitted))
}

/// [`run`], and with `listing` the feature pairs met by its last pass that may reach their
/// gap by the pass's horizon (a superset, see [`listed`]), when that pass's bounds were
/// fitted short of the whole step or the listing asks for whole-step passes too
/// ([`Listing::whole_step`]): each such pass culls at the listing's distance for its
/// horizon at least. `None` when no such pass ran or it met more pairs than the listing's
/// `most`.
#[allow(clippy::too_many_arguments)]
pub(crate) fn run_passes<K: BoundingVolume>(
    a: &Swept<'_, K>,
    b: &Swept<'_, K>,
    self_query: bool,
    query: &CcdQuery,
    best: Option<&AtomicU64>,
    budget: &Budget<'_>,
    gap: Option<Gap>,
    listing: Option<&Listing<'_>>,
    ws: &mut Workspace,
    par: Par,
) -> Result<(Impacts, [u64; 2], Option<Listed>)> {
    let mut counters = Counters::default();
    let mut fitted = [0u64; 2];
    let mut restarts = 0;
    let fit = |by: f64| (a.until(by), (!self_query).then(|| b.until(by)));
    let wanted = wanted_horizon(&query.options, best);
    let mut horizon = (wanted < a.horizon().min(b.horizon())).then(|| fit(wanted));
    loop {
        let (sa, sb) = match &horizon {
            Some((ua, ub)) => (ua, ub.as_ref().unwrap_or(ua)),
            None => (a, b),
        };
        let restart_below = (best.is_some() && restarts < MAX_RESTARTS)
            .then(|| sa.horizon().min(sb.horizon()) / RESTART_FACTOR);
        // A pass over the whole step lists only when the listing says so (see `listed`).
        let listing = listing.filter(|l| l.whole_step || sa.horizon().min(sb.horizon()) < 1.0);
        let q = SweptQuery::new(
            sa,
            sb,
            self_query,
            query.options,
            listing,
            best,
            budget,
            gap,
        );
        let q = SweptQuery { restart_below, ..q };
        let w = walk::walk(&q, ws, par);
        budget.finish()?;
        counters += w.counters;
        fitted = [0, 1].map(|k| fitted[k] + w.fitted[k]);
        if q.abandoned.load(Ordering::Relaxed) {
            // Its pairs are found again by the next walk.
            budget.release(w.out.len());
            restarts += 1;
            horizon = Some(fit(wanted_horizon(&query.options, best)));
            continue;
        }
        let mut out = w.out;
        let listed = std::mem::take(&mut out.listed);
        let listed = (q.listing.is_some() && !q.listed.full()).then_some(listed);
        if query.mode == CcdMode::Earliest {
            q.settle_earliest(&mut out);
            budget.finish()?;
        }
        return Ok((q.impacts(out, counters), fitted, listed));
    }
}

impl<'s, 'h, K: BoundingVolume> SweptQuery<'s, 'h, K> {
    /// The walk of `a` against `b`, its culling distance grown by the rounding of the
    /// positions their bounds are fitted to (each within its `horizon_error`).
    #[allow(clippy::too_many_arguments)]
    fn new(
        a: &'s Swept<'h, K>,
        b: &'s Swept<'h, K>,
        self_query: bool,
        options: CcdOptions,
        listing: Option<&'s Listing<'s>>,
        best: Option<&'s AtomicU64>,
        budget: &'s Budget<'s>,
        gap: Option<Gap>,
    ) -> Self {
        let horizon = a.horizon.min(b.horizon);
        // A listing walk culls at the larger of its own distance and the listing's.
        let listing_cull = listing.map_or(0.0, |l| (l.cull_for)(horizon));
        let mut cull = options.min_distance.max(listing_cull);
        if a.horizon_error > 0.0 || b.horizon_error > 0.0 {
            cull = (cull + a.horizon_error + b.horizon_error).next_up();
            if !cull.is_finite() {
                cull = f64::MAX;
            }
        }
        Self {
            a,
            b,
            self_query,
            options,
            cull,
            margin: f32_up(cull),
            restart_below: None,
            abandoned: AtomicBool::new(false),
            listing,
            listed: ListedCount::default(),
            best,
            budget,
            gap,
            magnitude: a.magnitude.max(b.magnitude),
            horizon,
        }
    }

    /// The answer of a finished walk: its pairs sorted, with the work counted.
    fn impacts(&self, mut out: ImpactOut, mut counters: Counters) -> Impacts {
        out.vertex_face
            .sort_unstable_by_key(|x| (u64::from(x.vertex) << 32) | u64::from(x.triangle));
        out.face_vertex
            .sort_unstable_by_key(|x| (u64::from(x.triangle) << 32) | u64::from(x.vertex));
        out.edge_edge.sort_unstable_by_key(|x| (x.a, x.b));
        let toi = out.least_toi();
        counters.contacts =
            (out.vertex_face.len() + out.face_vertex.len() + out.edge_edge.len()) as u64;
        Impacts {
            vertex_face: out.vertex_face,
            face_vertex: out.face_vertex,
            edge_edge: out.edge_edge,
            toi,
            counters,
        }
    }
}

/// Earliest mode over several walks that shared one bound: `least`, the least of their
/// times, and in each walk only the pairs that tie with it ([`ties_with`]); a walk left
/// with none is emptied, with `toi` `None`. A walk whose own answer is later may have been
/// cut short by another's bound, but every pair that ties with the least time is found
/// whatever the bound (see [`PRUNE_SLACK`]), so the answer does not depend on the order.
pub(crate) fn keep_earliest(walks: &mut [Impacts]) -> Option<f64> {
    let least = walks.iter().filter_map(|w| w.toi).reduce(f64::min)?;
    for w in walks.iter_mut() {
        let tie = |toi: f64| ties_with(toi, least);
        w.vertex_face.retain(|x| tie(x.toi));
        w.face_vertex.retain(|x| tie(x.toi));
        w.edge_edge.retain(|x| tie(x.toi));
        w.counters.contacts =
            (w.vertex_face.len() + w.face_vertex.len() + w.edge_edge.len()) as u64;
        if w.counters.contacts == 0 {
            w.toi = None;
        }
    }
    Some(least)
}

/// Earliest mode's rule: a pair whose time of impact is `toi` is reported with the least
/// time `least` iff `toi <= least + TOI_TOLERANCE`. Every returned time is at most
/// [`TOI_TOLERANCE`] below the pair's exact first contact `t*` and never above it, so every
/// pair whose `t*` is the earliest exact contact is reported (its `toi <= t* = t*_min <=
/// least + TOI_TOLERANCE`), and none whose `t*` is more than `2 * TOI_TOLERANCE` after it.
/// The rule reads only each pair's own time over the whole interval, which does not depend
/// on the path (float filter or exact) that computed it, the method or the threads.
#[inline]
pub(crate) fn ties_with(toi: f64, least: f64) -> bool {
    toi <= least + TOI_TOLERANCE
}

impl<K: BoundingVolume> SweptQuery<'_, '_, K> {
    fn side(&self, side: Side) -> &Swept<'_, K> {
        match side {
            Side::A => self.a,
            Side::B => self.b,
        }
    }

    /// The options of the next exact test: in earliest mode, up to the best time so far
    /// plus [`PRUNE_SLACK`].
    #[inline(always)]
    fn options_now(&self) -> CcdOptions {
        let mut o = self.options;
        if let Some(best) = &self.best {
            let b = f64::from_bits(best.load(Ordering::Relaxed));
            o.t_max = o.t_max.min((b + PRUNE_SLACK).next_up());
        }
        o
    }

    #[inline(always)]
    fn found(&self, toi: f64) {
        if let Some(best) = &self.best {
            best.fetch_min(toi.to_bits(), Ordering::Relaxed);
        }
    }

    /// Earliest mode, after the walk: every pair found within [`PRUNE_SLACK`] of the best is
    /// given the time a test over the whole interval gives it ([`Self::settled_toi`]); the
    /// least of those times and the pairs that tie with it ([`ties_with`]) are the answer
    /// (the same whatever the order of the walk).
    fn settle_earliest(&self, out: &mut ImpactOut) {
        let best = out.least_toi().unwrap_or(f64::INFINITY);
        let near = |toi: f64| toi <= best + PRUNE_SLACK;
        let (a, b) = (self.a, self.b);
        // Original -> internal indices of each side.
        let [va, vb] = [a, b].map(|s| inverse(s.tree().vert_order()));
        let [ta, tb] = [a, b].map(|s| inverse(s.tree().tri_order()));
        let (va, vb, ta, tb) = (&va, &vb, &ta, &tb);
        let vf = |v: u32, t: u32, a_has_vertex: bool, toi: f64| {
            let (sv, st, iv, it) = if a_has_vertex {
                (a, b, va, tb)
            } else {
                (b, a, vb, ta)
            };
            let (x0, x1) =
                vertex_face_points(sv, iv[v as usize] as usize, st, it[t as usize] as usize);
            self.settled_toi(true, &x0, &x1, toi)
        };
        let mut vertex_face: Vec<VertexImpact> = Vec::new();
        for x in out.vertex_face.iter().filter(|x| near(x.toi)) {
            if let Some(toi) = vf(x.vertex, x.triangle, true, x.toi) {
                vertex_face.push(VertexImpact { toi, ..*x });
            }
        }
        let mut face_vertex: Vec<FaceImpact> = Vec::new();
        for x in out.face_vertex.iter().filter(|x| near(x.toi)) {
            if let Some(toi) = vf(x.vertex, x.triangle, false, x.toi) {
                face_vertex.push(FaceImpact { toi, ..*x });
            }
        }
        let mut edge_edge: Vec<EdgeImpact> = Vec::new();
        for x in out.edge_edge.iter().filter(|x| near(x.toi)) {
            // Pair queries: `a` is the first mesh's; self queries: both are one mesh's.
            let ea = x.a.map(|v| va[v as usize]);
            let eb = x.b.map(|v| vb[v as usize]);
            let (x0, x1) = edge_edge_points(a, ea, b, eb);
            if let Some(toi) = self.settled_toi(false, &x0, &x1, x.toi) {
                edge_edge.push(EdgeImpact { toi, ..*x });
            }
        }
        let mut settled = ImpactOut {
            vertex_face,
            face_vertex,
            edge_edge,
            listed: Listed::default(),
            staged: Box::default(),
        };
        let least = settled.least_toi().unwrap_or(f64::INFINITY);
        settled.vertex_face.retain(|x| ties_with(x.toi, least));
        settled.face_vertex.retain(|x| ties_with(x.toi, least));
        settled.edge_edge.retain(|x| ties_with(x.toi, least));
        *out = settled;
    }

    /// The time the exact test over the query's whole interval `[0, t_max]` gives a pair
    /// the walk found at `toi` (under a bound pruned to the best time so far), tested
    /// again only when it may differ:
    /// - `toi == t_max`: the walk's test ran with the query's own `t_max` (a pruned bound
    ///   lies below it, and a time never exceeds its bound), so with the same options: the
    ///   same answer;
    /// - `toi == 0` and the pair within its minimum distance at t0 (exact): its earliest
    ///   contact `t*` is 0, and every answer lies in `[t* - TOI_TOLERANCE, t*]` and in
    ///   `[0, t_max]`: 0.
    ///
    /// Steps whose earliest time is 0 (sheets resting on each other) or `t_max` (contact
    /// at the end of the step) settle their tied pairs without a second test.
    fn settled_toi(
        &self,
        vertex_face: bool,
        x0: &[[f64; 3]; 4],
        x1: &[[f64; 3]; 4],
        toi: f64,
    ) -> Option<f64> {
        if toi == self.options.t_max {
            return Some(toi);
        }
        let o = pair_options(vertex_face, x0, x1, &self.options, self.gap.as_ref())?;
        // t* = 0 when within the pair's minimum distance at t0.
        if toi == 0.0 && within_at_start(vertex_face, x0, o.min_distance) {
            return Some(toi);
        }
        self.pair_toi_with(vertex_face, x0, x1, &o)
    }

    /// The exact test of one pair the walk found (`vertex_face`: `x0 = [v, t0, t1, t2]`,
    /// else `[a0, a1, b0, b1]`), with the options of the moment and the pair's own.
    #[inline(always)]
    fn pair_toi(&self, vertex_face: bool, x0: &[[f64; 3]; 4], x1: &[[f64; 3]; 4]) -> Option<f64> {
        let o = self.options_now();
        let o = pair_options(vertex_face, x0, x1, &o, self.gap.as_ref())?;
        self.pair_toi_with(vertex_face, x0, x1, &o)
    }

    /// [`Self::pair_toi`] with the pair's own options already known.
    #[inline(always)]
    fn pair_toi_with(
        &self,
        vertex_face: bool,
        x0: &[[f64; 3]; 4],
        x1: &[[f64; 3]; 4],
        options: &CcdOptions,
    ) -> Option<f64> {
        let stop = || self.budget.poll();
        // Stopped: no answer; the budget has stopped the query, which returns the error.
        // The pair's boxes over `[0, t_max]` end a pair the walk's boxes (over its horizon)
        // did not only when `t_max` is well inside that horizon.
        let boxes_until = options.t_max < BOXES_UNTIL_BELOW * self.horizon;
        ccd::pair_until(
            vertex_face,
            x0,
            x1,
            options,
            self.magnitude,
            boxes_until,
            &stop,
        )
        .unwrap_or(None)
    }
}

/// The inverse of a permutation given as internal -> original indices.
fn inverse(order: &[u32]) -> Vec<u32> {
    let mut inv = vec![0u32; order.len()];
    for (i, &o) in order.iter().enumerate() {
        inv[o as usize] = i as u32;
    }
    inv
}

/// The corners of internal vertex `v` of `sv` and internal triangle `t` of `st` at t0 and
/// t1 (`[v, t0, t1, t2]`).
#[inline(always)]
fn vertex_face_points<K: BoundingVolume>(
    sv: &Swept<'_, K>,
    v: usize,
    st: &Swept<'_, K>,
    t: usize,
) -> ([[f64; 3]; 4], [[f64; 3]; 4]) {
    let [c0, c1, c2] = st.tree().triangles()[t];
    let [c0, c1, c2] = [c0 as usize, c1 as usize, c2 as usize];
    let (p, q) = (&sv.step, &st.step);
    (
        [p.x0[v], q.x0[c0], q.x0[c1], q.x0[c2]],
        [p.x1[v], q.x1[c0], q.x1[c1], q.x1[c2]],
    )
}

/// The corners of edge `ea` of `sa` and edge `eb` of `sb` (internal vertex indices) at t0
/// and t1 (`[a0, a1, b0, b1]`).
// PERF: indexed loads into the arrays, not `map` over the endpoints: copies of the pieces
// through the stack stalled on store forwarding (~12% of an all-pairs CCD step).
#[inline(always)]
fn edge_edge_points<K: BoundingVolume>(
    sa: &Swept<'_, K>,
    [a0, a1]: [u32; 2],
    sb: &Swept<'_, K>,
    [b0, b1]: [u32; 2],
) -> ([[f64; 3]; 4], [[f64; 3]; 4]) {
    let [a0, a1, b0, b1] = [a0 as usize, a1 as usize, b0 as usize, b1 as usize];
    let (p, q) = (&sa.step, &sb.step);
    (
        [p.x0[a0], p.x0[a1], q.x0[b0], q.x0[b1]],
        [p.x1[a0], p.x1[a1], q.x1[b0], q.x1[b1]],
    )
}

/// What the batch cull decided of a chunk's staged pairs ([`SweptQuery::batch_cull`]).
struct Culled {
    /// Certainly farther than their minimum distance apart over `[0, t_max]`: no contact.
    apart: u64,
    /// In a listing walk: certainly unable to come within their gap by the walk's horizon,
    /// so not listed.
    unreachable: u64,
}

impl Culled {
    /// The pairs of `0..n` whose points are read: those left to the impact test, and in a
    /// walk that `lists`, those left to the listing's test.
    #[inline(always)]
    fn to_read(&self, n: usize, lists: bool) -> u64 {
        let all = low_bits(n);
        let to_list = if lists { all & !self.unreachable } else { 0 };
        (all & !self.apart) | to_list
    }
}

/// A pair's own options: the query's, or with the step-size rule its minimum distance from
/// its distance at t0 (`None`: it cannot reach it before `t_max`).
#[inline(always)]
fn pair_options(
    vertex_face: bool,
    x0: &[[f64; 3]; 4],
    x1: &[[f64; 3]; 4],
    options: &CcdOptions,
    gap: Option<&Gap>,
) -> Option<CcdOptions> {
    match gap {
        None => Some(*options),
        Some(g) => g.options(vertex_face, x0, x1, *options),
    }
}

/// The pair (`vertex_face`: `x0 = [v, t0, t1, t2]`, else `[a0, a1, b0, b1]`) is within `d`
/// at t0, exactly (closed features, as the CCD itself sees contact).
fn within_at_start(vertex_face: bool, x0: &[[f64; 3]; 4], d: f64) -> bool {
    use crate::distance::{edge_edge_within, point_triangle_within};
    if vertex_face {
        point_triangle_within(x0[0], [x0[1], x0[2], x0[3]], d).is_some()
    } else {
        edge_edge_within(x0[0], x0[1], x0[2], x0[3], d).is_some()
    }
}

impl<'s, 'h, K: BoundingVolume> Query for SweptQuery<'s, 'h, K> {
    type Block = K::SweptBlock<'s>;
    type Out = ImpactOut;

    #[inline(always)]
    fn tree(&self, side: Side) -> &RegionTree {
        self.side(side).tree()
    }

    #[inline(always)]
    fn is_self(&self) -> bool {
        self.self_query
    }

    fn out(&self) -> ImpactOut {
        ImpactOut::default()
    }

    #[inline(always)]
    fn group<S: Simd>(&self, _simd: S, side: Side, g: usize) -> (K::SweptBlock<'s>, bool) {
        let s: &'s Swept<'h, K> = match side {
            Side::A => self.a,
            Side::B => self.b,
        };
        K::swept_group(&s.bounds, s.h.nodes(), s.h.tree(), s.culling(), g)
    }

    #[inline(always)]
    fn test<S: Simd>(&self, simd: S, a: Self::Block, i: usize, b: Self::Block, n: usize) -> u32 {
        K::swept_test(simd, a, i, b, n, self.cull)
    }

    #[inline(always)]
    fn extent(&self, block: Self::Block, i: usize) -> f32 {
        K::swept_extent(block, i)
    }

    /// Clear when no pair of the node comes within the walk's culling distance by its
    /// horizon, on the exact motion.
    #[inline(always)]
    fn clear(&self, x: usize) -> bool {
        let step = self.a.step.as_ref();
        super::clearance::motion_is_clear(
            self.a.tree(),
            x,
            &step.x0,
            &step.x1,
            self.horizon,
            self.cull,
        )
    }

    #[inline(always)]
    fn leaf_pair<S: Simd>(
        &self,
        simd: S,
        x: usize,
        y: usize,
        counters: &mut Counters,
        out: &mut ImpactOut,
    ) {
        let (a, b, self_query) = (self.a, self.b, self.self_query);
        if !(self_query && x == y) && leaves_apart(&a.leaf_ends[x], &b.leaf_ends[y], self.margin) {
            return;
        }
        let tv = |s: &Swept<'_, K>, v: usize| s.tree().vert_order()[v];
        let tt = |s: &Swept<'_, K>, t: usize| s.tree().tri_order()[t];
        let before = out.len();
        let budget = self.budget;
        let ImpactOut {
            vertex_face,
            face_vertex,
            edge_edge,
            listed,
            staged,
        } = out;
        let listed_before = listed.len();
        let mut lists = self.listing.filter(|_| !self.listed.full()).map(|_| listed);
        let stopped = || budget.stopped();
        let candidates = Candidates {
            self_query,
            margin: self.margin,
            stopped: &stopped,
        };
        let list = lists.as_mut().map(|l| &mut l.vertex_face);
        self.vertices_vs_triangles(
            simd,
            &candidates,
            a,
            x,
            b,
            y,
            counters,
            staged,
            list,
            |v, t, toi| {
                budget.push(
                    vertex_face,
                    VertexImpact {
                        vertex: tv(a, v),
                        triangle: tt(b, t),
                        toi,
                    },
                )
            },
        );
        if !(self_query && x == y) {
            // In a self query both sides are the one mesh: a vertex of `b` is one of `a`.
            let list = lists.as_mut().map(|l| {
                if self_query {
                    &mut l.vertex_face
                } else {
                    &mut l.face_vertex
                }
            });
            self.vertices_vs_triangles(
                simd,
                &candidates,
                b,
                y,
                a,
                x,
                counters,
                staged,
                list,
                |v, t, toi| {
                    if self_query {
                        budget.push(
                            vertex_face,
                            VertexImpact {
                                vertex: tv(b, v),
                                triangle: tt(a, t),
                                toi,
                            },
                        )
                    } else {
                        budget.push(
                            face_vertex,
                            FaceImpact {
                                triangle: tt(a, t),
                                vertex: tv(b, v),
                                toi,
                            },
                        )
                    }
                },
            );
        }
        let list = lists.as_mut().map(|l| &mut l.edge_edge);
        self.edges_vs_edges(simd, &candidates, x, y, counters, staged, list, edge_edge);
        if let (Some(l), Some(listing)) = (lists, self.listing) {
            self.listed.add(l, listed_before, listing.most);
        }
        budget.add(out.len() - before);
    }

    fn merge(&self, out: &mut ImpactOut, other: ImpactOut) {
        self.budget.extend(&mut out.vertex_face, &other.vertex_face);
        self.budget.extend(&mut out.face_vertex, &other.face_vertex);
        self.budget.extend(&mut out.edge_edge, &other.edge_edge);
        if self.listing.is_some() && !self.listed.full() {
            out.listed.append(other.listed);
        }
    }

    #[inline(always)]
    fn stopped(&self, poll: bool) -> bool {
        let stopped = if poll {
            self.budget.poll()
        } else {
            self.budget.stopped()
        };
        if let (Some(below), Some(best)) = (self.restart_below, self.best) {
            if horizon_for(f64::from_bits(best.load(Ordering::Relaxed))) <= below {
                self.abandoned.store(true, Ordering::Relaxed);
                return true;
            }
        }
        stopped
    }
}

impl<K: BoundingVolume> SweptQuery<'_, '_, K> {
    /// The own vertices of leaf `x` of `sv` against the triangles of leaf `y` of `st`:
    /// `emit(vertex, triangle, toi)` (internal indices) for each pair that collides, and
    /// into `list` each the batch cull leaves for it when the walk lists.
    #[allow(clippy::too_many_arguments)]
    #[inline(always)]
    fn vertices_vs_triangles<S: Simd>(
        &self,
        simd: S,
        candidates: &Candidates<'_>,
        sv: &Swept<'_, K>,
        x: usize,
        st: &Swept<'_, K>,
        y: usize,
        counters: &mut Counters,
        staged: &mut Staged,
        mut list: Option<&mut Vec<[u32; 2]>>,
        mut emit: impl FnMut(usize, usize, f64),
    ) {
        let rows = st.tri_boxes(y);
        let tris = LeafTriangles {
            len: rows[0].len(),
            rows,
            bounds: st.leaf_bounds[y][0],
            first: st.tree().tri_range(y).start,
            corners: st.tree().triangles(),
        };
        let vertices = sv.vertices(x);
        // PERF: the closure only stages the pair; the batch cull runs in the dispatched body
        // (a closure may be compiled without the backend's target features).
        for part in parts(0..vertices.rows[0].len(), tris.len) {
            let pending = &mut staged.vertex_triangles;
            candidates.vertices_vs_triangles(simd, &vertices, part, &tris, counters, |v, t| {
                pending.push((v as u32, t as u32))
            });
            let mut from = 0;
            while from < staged.vertex_triangles.len() {
                let n = (staged.vertex_triangles.len() - from).min(MAX_PAIRS);
                let chunk = &staged.vertex_triangles[from..from + n];
                for (i, &(v, t)) in chunk.iter().enumerate() {
                    let (x0, x1) = vertex_face_points(sv, v as usize, st, t as usize);
                    staged.points.set(i, &x0, &x1);
                }
                let culled = self.batch_cull(
                    simd,
                    &staged.points,
                    n,
                    true,
                    list.is_some(),
                    &mut staged.motion,
                );
                let mut undecided = culled.to_read(n, list.is_some());
                while undecided != 0 {
                    let i = undecided.trailing_zeros() as usize;
                    undecided &= undecided - 1;
                    let (v, t) = chunk[i];
                    let (x0, x1) = staged.points.get(i);
                    if let Some(l) = list.as_deref_mut() {
                        if culled.unreachable & (1 << i) == 0 {
                            l.push([v, t]);
                        }
                    }
                    if culled.apart & (1 << i) != 0 {
                        continue;
                    }
                    if let Some(toi) = self.pair_toi(true, &x0, &x1) {
                        self.found(toi);
                        emit(v as usize, t as usize, toi);
                    }
                }
                from += n;
            }
            staged.vertex_triangles.clear();
        }
    }

    /// The own edges of leaf `x` of A against those of leaf `y` of B (a leaf with itself:
    /// each unordered pair once): each pair that collides into `out`, and into `list` each
    /// the batch cull leaves for it when the walk lists.
    #[allow(clippy::too_many_arguments)]
    #[inline(always)]
    fn edges_vs_edges<S: Simd>(
        &self,
        simd: S,
        candidates: &Candidates<'_>,
        x: usize,
        y: usize,
        counters: &mut Counters,
        staged: &mut Staged,
        mut list: Option<&mut Vec<[[u32; 2]; 2]>>,
        out: &mut Vec<EdgeImpact>,
    ) {
        let (sa, sb) = (self.a, self.b);
        let (a, b) = (sa.edges(x), sb.edges(y));
        let same_leaf = self.self_query && x == y;
        // PERF: staged, as in `vertices_vs_triangles`.
        for part in parts(0..a.edges.len(), b.edges.len()) {
            let pending = &mut staged.edges;
            candidates.edges_vs_edges(simd, &a, part, &b, same_leaf, counters, |ex, ey| {
                pending.push((ex, ey));
            });
            let mut from = 0;
            while from < staged.edges.len() {
                let n = (staged.edges.len() - from).min(MAX_PAIRS);
                let chunk = &staged.edges[from..from + n];
                for (i, (ex, ey)) in chunk.iter().enumerate() {
                    // `ex` is of A (or, in a self query, of the one mesh), `ey` of B; the exact
                    // test takes the edges in the reported order.
                    let (x0, x1) = edge_edge_points(sa, ex.internal, sb, ey.internal);
                    staged.points.set(i, &x0, &x1);
                }
                let culled = self.batch_cull(
                    simd,
                    &staged.points,
                    n,
                    false,
                    list.is_some(),
                    &mut staged.motion,
                );
                let mut undecided = culled.to_read(n, list.is_some());
                while undecided != 0 {
                    let i = undecided.trailing_zeros() as usize;
                    undecided &= undecided - 1;
                    let (ex, ey) = &chunk[i];
                    let (x0, x1) = staged.points.get(i);
                    if let Some(l) = list.as_deref_mut() {
                        if culled.unreachable & (1 << i) == 0 {
                            l.push([ex.internal, ey.internal]);
                        }
                    }
                    if culled.apart & (1 << i) != 0 {
                        continue;
                    }
                    if let Some(toi) = self.pair_toi(false, &x0, &x1) {
                        self.found(toi);
                        self.budget.push(
                            out,
                            EdgeImpact {
                                a: ex.ids,
                                b: ey.ids,
                                toi,
                            },
                        );
                    }
                }
                from += n;
            }
            staged.edges.clear();
        }
    }

    /// The batch cull of the staged pairs (the first `n` of `points`): those certainly
    /// farther than the minimum distance apart over `[0, t_max]`, `t_max` the query's now (in
    /// earliest mode the best time so far plus the slack; it only decreases, so the pairs are
    /// apart up to any later `t_max` too), whose exact test would find no contact. Along the
    /// centroids' line first; the pairs it leaves by their distance at t0 against their
    /// relative motion, when that pays. Under the step size's per-pair gaps, the pairs that
    /// cannot come within theirs ([`Gap::motion_cull`]). A walk that `lists` also ends, for
    /// its list, the pairs that cannot come within their gap by its horizon.
    #[inline(always)]
    fn batch_cull<S: Simd>(
        &self,
        simd: S,
        points: &MovingPoints,
        n: usize,
        vf: bool,
        lists: bool,
        [motion, motion_listing]: &mut [MotionCull; 2],
    ) -> Culled {
        let all = low_bits(n);
        let t_end = self.options_now().t_max;
        // PERF: `if let`, not closures around the kernel: a closure may be compiled without
        // the backend's target features (every vector operation a call: 2.3x slower).
        if let Some(gap) = &self.gap {
            let mut apart = 0;
            if let Some((delta, closing)) = gap.motion_cull() {
                let horizon = (delta, closing, t_end);
                apart = self.motion_cull(simd, points, (n, vf, all), horizon, motion);
            }
            return Culled {
                apart,
                unreachable: 0,
            };
        }
        let delta = self.options.min_distance;
        let along = centroids_apart_with(simd, points, n, vf, delta, self.magnitude, t_end);
        let ended = self.motion_cull(
            simd,
            points,
            (n, vf, all & !along),
            (delta, 1.0, t_end),
            motion,
        );
        let mut unreachable = 0;
        if let Some(listing) = self.listing.filter(|_| lists) {
            if let Some((d, closing)) = listing.gap.motion_cull() {
                let horizon = (d, closing, self.horizon);
                unreachable = self.motion_cull(simd, points, (n, vf, all), horizon, motion_listing);
            }
        }
        Culled {
            apart: along | ended,
            unreachable,
        }
    }

    /// The motion cull ([`apart_beyond_motion_with`]) on the pairs `among` of the first `n`
    /// staged (`vf`: vertex-face) at minimum distance `delta`, closing factor `closing` and
    /// horizon `t_end`, when `motion` says it pays (else none).
    #[inline(always)]
    fn motion_cull<S: Simd>(
        &self,
        simd: S,
        points: &MovingPoints,
        (n, vf, among): (usize, bool, u64),
        (delta, closing, t_end): (f64, f64, f64),
        motion: &mut MotionCull,
    ) -> u64 {
        let seen = among.count_ones();
        if seen == 0 || !motion.runs(seen) {
            return 0;
        }
        let m = self.magnitude;
        let ended = apart_beyond_motion_with(simd, points, n, vf, delta, closing, m, t_end) & among;
        motion.record(seen, ended.count_ones());
        ended
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Pair motions on a coarse grid, so pairs that reach their gap exactly are frequent:
    /// 6000 cases of (vertex-face?, x0, x1, rule, horizon), vertex-face and edge-edge
    /// alternating, the rule's rescaling taken from `rescalings`.
    fn coarse_grid_pairs(
        seed: u64,
        rescalings: &[f64],
    ) -> impl Iterator<Item = (bool, [[f64; 3]; 4], [[f64; 3]; 4], Gap, f64)> + '_ {
        let mut state = seed;
        let mut grid = move |steps: u64, size: f64| {
            state = state
                .wrapping_mul(6_364_136_223_846_793_005)
                .wrapping_add(1_442_695_040_888_963_407);
            ((state >> 33) % (2 * steps + 1)) as f64 * size - steps as f64 * size
        };
        (0..6000).map(move |case| {
            let x0: [[f64; 3]; 4] =
                std::array::from_fn(|_| std::array::from_fn(|_| grid(8, 0.125)));
            let x1: [[f64; 3]; 4] =
                std::array::from_fn(|i| std::array::from_fn(|k| x0[i][k] + grid(4, 1.0 / 32.0)));
            let gap = Gap {
                min_distance: [0.0, 1.0 / 64.0, 0.125][case % 3],
                rescaling: rescalings[(case / 3) % rescalings.len()],
            };
            let t_max = [1.0, 0.5, 0.2][(case / (3 * rescalings.len())) % 3];
            (case % 2 == 0, x0, x1, gap, t_max)
        })
    }

    /// The exact test at the gap `gap` keeps the pair at finds no contact up to `t_max`.
    fn assert_stays_outside_kept_gap(
        gap: &Gap,
        vf: bool,
        x0: &[[f64; 3]; 4],
        x1: &[[f64; 3]; 4],
        t_max: f64,
    ) {
        let o = CcdOptions::new(t_max, 0.0).unwrap();
        let at_gap = gap.at_gap(vf, x0, o);
        let exact = if vf {
            crate::ccd::vertex_face_exact(x0, x1, &at_gap)
        } else {
            crate::ccd::edge_edge_exact(x0, x1, &at_gap)
        };
        assert_eq!(
            exact, None,
            "vf {vf} {x0:?} -> {x1:?} {gap:?} until {t_max}"
        );
    }

    /// Under the step size's rule, every pair the motion cull ends (at [`Gap::motion_cull`]'s
    /// distance and closing) stays outside the gap it would be kept at: the exact test at
    /// that gap finds no contact up to the horizon; and the cull ends a fair share (not
    /// vacuous).
    #[test]
    fn the_motion_cull_keeps_every_pair_outside_its_gap() {
        use dhcd_kernels::reference::moving_apart_beyond_motion;
        let (mut ended, mut total) = (0u32, 0u32);
        for (vf, x0, x1, gap, t_max) in
            coarse_grid_pairs(0x2545_f491_4f6c_dd1d, &[0.8, 0.5, 1.0, 0.3])
        {
            let m = x0
                .iter()
                .chain(&x1)
                .flatten()
                .fold(0.0f64, |m, x| m.max(x.abs()));
            let (delta, closing) = gap.motion_cull().expect("a rule the cull serves");
            total += 1;
            if moving_apart_beyond_motion(&x0, &x1, vf, delta, closing, m, t_max) {
                ended += 1;
                assert_stays_outside_kept_gap(&gap, vf, &x0, &x1, t_max);
            }
        }
        assert!(ended > total / 4, "{ended} of {total}");
    }

    /// The reach test refuses only pairs that stay outside the gap they would be kept at,
    /// for small rescalings too, where the kept gap's rounding is largest against the
    /// rule's; and it refuses a fair share (not vacuous).
    #[test]
    fn the_reach_test_refuses_only_pairs_outside_their_kept_gap() {
        let (mut refused, mut total) = (0u32, 0u32);
        let rescalings = [0.8, 0.5, 0.1, 0.25, 0.01];
        for (vf, x0, x1, gap, t_max) in coarse_grid_pairs(0x9e37_79b9_7f4a_7c15, &rescalings) {
            total += 1;
            if !gap.may_reach(vf, &x0, &x1, t_max) {
                refused += 1;
                assert_stays_outside_kept_gap(&gap, vf, &x0, &x1, t_max);
            }
        }
        assert!(refused > total / 4, "{refused} of {total}");
    }

    /// A vertex 1 above a face closing in by `1 - g` reaches the rule's gap `g` exactly at
    /// the end of the step: not ended; a little less motion, or a shorter horizon, is.
    #[test]
    fn the_motion_cull_keeps_a_pair_that_reaches_its_gap() {
        use dhcd_kernels::reference::moving_apart_beyond_motion;
        let tri = [[-1.0, -1.0, 0.0], [2.0, -1.0, 0.0], [-1.0, 2.0, 0.0]];
        let gap = Gap {
            min_distance: 0.0,
            rescaling: 0.75,
        };
        let (delta, closing) = gap.motion_cull().unwrap();
        let x0 = [[0.0, 0.0, 1.0], tri[0], tri[1], tri[2]];
        // Gap 0.25: down by 0.75 reaches it at t = 1.
        let x1 = [[0.0, 0.0, 0.25], tri[0], tri[1], tri[2]];
        assert!(!moving_apart_beyond_motion(
            &x0, &x1, true, delta, closing, 2.0, 1.0
        ));
        assert!(moving_apart_beyond_motion(
            &x0, &x1, true, delta, closing, 2.0, 0.99
        ));
        let short = [[0.0, 0.0, 0.2501], tri[0], tri[1], tri[2]];
        assert!(moving_apart_beyond_motion(
            &x0, &short, true, delta, closing, 2.0, 1.0
        ));
        // Rules the cull cannot serve.
        for rescaling in [0.0, 1.5, f64::NAN] {
            let g = Gap {
                min_distance: 0.0,
                rescaling,
            };
            assert_eq!(g.motion_cull(), None);
        }
    }

    fn boxed(lo: [f32; 3], hi: [f32; 3]) -> FeatureBox {
        (lo, hi)
    }

    /// Leaves apart on one axis at both ends, on the same side, are apart; leaves that swap
    /// sides during the step (they pass each other), or whose gap is within the margin at
    /// either end, are not.
    #[test]
    fn leaves_are_apart_only_on_one_side_at_both_ends() {
        let unit = |x: f32| boxed([x, 0.0, 0.0], [x + 1.0, 1.0, 1.0]);
        // Both translate by 10 along x, 2 apart: apart all step.
        let a = [unit(0.0), unit(10.0)];
        let b = [unit(3.0), unit(13.0)];
        assert!(leaves_apart(&a, &b, 0.0));
        assert!(leaves_apart(&b, &a, 0.0));
        assert!(leaves_apart(&a, &b, 1.5));
        // The gap (2) is not more than the margin.
        assert!(!leaves_apart(&a, &b, 2.0));
        // b passes a: right of it at t0, left of it at t1.
        let passing = [unit(3.0), unit(5.0)];
        assert!(!leaves_apart(&a, &passing, 0.0));
        // Touching at t1 (closed boxes).
        let touching = [unit(3.0), unit(11.0)];
        assert!(!leaves_apart(&a, &touching, 0.0));
        // Apart on y at both ends, overlapping on x.
        let above = [
            boxed([0.5, 2.0, 0.0], [1.0, 3.0, 1.0]),
            boxed([10.5, 2.0, 0.0], [11.0, 3.0, 1.0]),
        ];
        assert!(leaves_apart(&a, &above, 0.5));
        // An infinite margin culls nothing.
        assert!(!leaves_apart(&a, &b, f32::INFINITY));
    }
}
