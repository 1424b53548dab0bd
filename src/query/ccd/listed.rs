//! The feature pairs of a walk, kept for a second test of the same pairs under another rule.
//!
//! The step size ([`crate::contact::step`]) tests two rules on nearly the same pairs: the
//! first impact at the minimum distance, then, up to that impact `T`, each pair's gap. The
//! gap walk's pairs are those whose boxes over `[0, by]` (`by` just above `T`) meet within
//! its culling distance `c(by)`, which grows with `by`. The first impact's last pass has
//! bounds fitted up to a horizon `H >= by` (the horizon only falls as the best time does);
//! when that pass culls at `c(H)` instead of the minimum distance alone, it meets every pair
//! the gap walk would (boxes over a longer interval, grown by more), and it lists them. The
//! gap rule is then tested on that list ([`gap_over_listed`]), pair by pair on its exact
//! motion as in the walk, instead of a second walk over nearly the same candidates; the
//! larger culling distance costs the first walk little where `H` is small, which is where
//! a pass lists (bounds fitted short of the whole step, [`super::run_passes`]), or where
//! `c(1)` itself is small ([`Listing::whole_step`]: a step with no early impact then runs
//! one walk, not two).
//!
//! The list is a superset: every pair the pass meets except those its batch cull proves
//! unable to come within their gap by `H` ([`Gap::motion_cull`], in `f64` lanes). No exact
//! reach test runs in the walk (on pairs touching at t0 it is the slow exact path, and it
//! was most of a step where every vertex touches); the list's test culls each 64 pairs
//! again at the best time so far, then tests the rest exactly at their gap, as the gap walk
//! would.
//!
//! The list is bounded ([`Listing::most`], [`MAX_LISTED`] for the step size); past it the
//! list is dropped and the caller walks again. Results are the gap walk's: the same pairs
//! tested under the same rule with the same shared bound, settled the same way
//! ([`SweptQuery::settle_earliest`]).

use std::sync::atomic::{AtomicBool, AtomicU64, AtomicUsize, Ordering};

use rayon::prelude::*;

use pulp::{Simd, WithSimd};

use super::{
    edge_edge_points, vertex_face_points, CcdQuery, EdgeImpact, FaceImpact, Gap, ImpactOut,
    Impacts, MotionCull, Swept, SweptQuery, VertexImpact, MAX_PAIRS,
};
use crate::bv::BoundingVolume;
use crate::control::Budget;
use crate::counters::Counters;
use crate::error::Result;
use crate::par::Par;
use crate::walk::Query;

/// The most feature pairs a walk lists (at most 16 bytes each: 64 MiB); past it the list is
/// dropped and the caller walks again.
pub(crate) const MAX_LISTED: usize = 1 << 22;

/// Listed pairs per parallel task of [`gap_over_listed`].
const LISTED_PER_TASK: usize = 2048;

/// Feature pairs a walk met, by internal indices.
#[derive(Default)]
pub(crate) struct Listed {
    /// A vertex of `a` and a triangle of `b` (in a self query, both of the one mesh).
    pub(super) vertex_face: Vec<[u32; 2]>,
    /// A vertex of `b` and a triangle of `a` (pair queries only).
    pub(super) face_vertex: Vec<[u32; 2]>,
    /// An edge of `a` and an edge of `b`, each as internal vertex indices in the order the
    /// pair is reported in (the smaller original index first).
    pub(super) edge_edge: Vec<[[u32; 2]; 2]>,
}

impl Listed {
    /// Pairs held.
    pub(crate) fn len(&self) -> usize {
        self.vertex_face.len() + self.face_vertex.len() + self.edge_edge.len()
    }

    /// Pairs held of each kind: vertex-face, face-vertex, edge-edge.
    #[cfg(test)]
    pub(crate) fn counts(&self) -> [usize; 3] {
        [
            self.vertex_face.len(),
            self.face_vertex.len(),
            self.edge_edge.len(),
        ]
    }

    /// `other`'s pairs after this one's.
    pub(super) fn append(&mut self, mut other: Listed) {
        self.vertex_face.append(&mut other.vertex_face);
        self.face_vertex.append(&mut other.face_vertex);
        self.edge_edge.append(&mut other.edge_edge);
    }
}

/// What a walk lists: among the pairs its bounds meet culled at `cull_for(horizon)` at
/// least, those its batch cull does not prove unable to reach their gap under `gap` by the
/// walk's horizon; at most `most` of them, or none.
pub(crate) struct Listing<'a> {
    pub(crate) cull_for: &'a (dyn Fn(f64) -> f64 + Sync),
    pub(crate) gap: Gap,
    pub(crate) most: usize,
    /// Passes over the whole step list too, not only those fitted short of it.
    pub(crate) whole_step: bool,
}

/// The pairs a walk's tasks have listed, against [`Listing::most`].
#[derive(Default)]
pub(super) struct ListedCount {
    total: AtomicUsize,
    full: AtomicBool,
}

impl ListedCount {
    /// The walk met more pairs to list than it may hold: its list is incomplete.
    #[inline(always)]
    pub(super) fn full(&self) -> bool {
        self.full.load(Ordering::Relaxed)
    }

    /// Counts the pairs `list` gained since it held `before`, against `most`.
    #[inline(always)]
    pub(super) fn add(&self, list: &Listed, before: usize, most: usize) {
        let n = list.len() - before;
        if n > 0 && self.total.fetch_add(n, Ordering::Relaxed) + n > most {
            self.full.store(true, Ordering::Relaxed);
        }
    }
}

/// The step size's gap rule on `listed` (the pairs of the first impact's last pass, which
/// hold every pair the gap walk up to `by` would meet): the walk's answer without the walk.
/// `query`, `best` (the first impact's time), `gap` and `by` are the gap walk's.
#[allow(clippy::too_many_arguments)]
pub(crate) fn gap_over_listed<K: BoundingVolume>(
    a: &Swept<'_, K>,
    b: &Swept<'_, K>,
    self_query: bool,
    query: &CcdQuery,
    best: &AtomicU64,
    budget: &Budget<'_>,
    gap: Gap,
    by: f64,
    listed: &Listed,
    par: Par,
) -> Result<Impacts> {
    let q = SweptQuery::new(
        a,
        b,
        self_query,
        query.options,
        None,
        Some(best),
        budget,
        Some(gap),
    );
    // The pair tests see the horizon the gap walk's bounds would have reached.
    let q = SweptQuery { horizon: by, ..q };
    let mut out = ImpactOut::default();
    let vertex_face = q.each_listed(
        &listed.vertex_face,
        true,
        par,
        SweptQuery::vertex_face_poses::<false>,
        SweptQuery::vertex_face::<false>,
    );
    q.merge(&mut out, vertex_face);
    let face_vertex = q.each_listed(
        &listed.face_vertex,
        true,
        par,
        SweptQuery::vertex_face_poses::<true>,
        SweptQuery::vertex_face::<true>,
    );
    q.merge(&mut out, face_vertex);
    let edge_edge = q.each_listed(
        &listed.edge_edge,
        false,
        par,
        SweptQuery::edge_edge_poses,
        SweptQuery::edge_edge,
    );
    q.merge(&mut out, edge_edge);
    budget.finish()?;
    q.settle_earliest(&mut out);
    budget.finish()?;
    let counters = Counters {
        prim_tests: listed.len() as u64,
        ..Counters::default()
    };
    Ok(q.impacts(out, counters))
}

impl<'s, 'h, K: BoundingVolume> SweptQuery<'s, 'h, K> {
    /// The gap rule on each of `pairs` (`vf`: vertex-triangle pairs) into one output, in
    /// tasks of [`LISTED_PER_TASK`] pairs when `par` is parallel (outputs merged in task
    /// order): `points` reads a pair's two poses, `report` records its impact.
    fn each_listed<T: Sync>(
        &self,
        pairs: &[T],
        vf: bool,
        par: Par,
        points: impl Fn(&Self, &T) -> ([[f64; 3]; 4], [[f64; 3]; 4]) + Sync,
        report: impl Fn(&Self, &T, f64, &mut ImpactOut) + Sync,
    ) -> ImpactOut {
        let run = |chunk: &[T]| {
            dhcd_kernels::arch().dispatch(ListedOp {
                q: self,
                pairs: chunk,
                vf,
                points: &points,
                report: &report,
            })
        };
        if !par.is_parallel() || pairs.len() <= LISTED_PER_TASK {
            return run(pairs);
        }
        par.install(|| {
            pairs
                .par_chunks(LISTED_PER_TASK)
                .map(run)
                .reduce(ImpactOut::default, |mut x, y| {
                    self.merge(&mut x, y);
                    x
                })
        })
    }

    /// The time a listed pair reaches its gap: its exact test at the gap, with the options
    /// of the moment. No exact reach test ([`Gap::may_reach`]) runs before it: that is a
    /// distance test, slow on pairs touching at t0, and the test at the gap decides the same
    /// pairs (the batch cull before it ends most that cannot reach their gap by then).
    #[inline(always)]
    fn listed_toi(&self, vertex_face: bool, x0: &[[f64; 3]; 4], x1: &[[f64; 3]; 4]) -> Option<f64> {
        let gap = self.gap.as_ref().expect("a gap rule");
        let o = gap.at_gap(vertex_face, x0, self.options_now());
        self.pair_toi_with(vertex_face, x0, x1, &o)
    }

    /// The sides holding a listed pair's vertex and triangle: `a` and `b`, or `b` and `a`
    /// when `flipped` (a vertex of `b` against a triangle of `a`, pair queries only).
    #[inline(always)]
    fn vertex_and_face_sides(&self, flipped: bool) -> (&'s Swept<'h, K>, &'s Swept<'h, K>) {
        if flipped {
            (self.b, self.a)
        } else {
            (self.a, self.b)
        }
    }

    /// A listed vertex and triangle (of `b` and `a` when `FLIPPED`): its poses.
    #[inline(always)]
    fn vertex_face_poses<const FLIPPED: bool>(
        &self,
        &[v, t]: &[u32; 2],
    ) -> ([[f64; 3]; 4], [[f64; 3]; 4]) {
        let (sv, st) = self.vertex_and_face_sides(FLIPPED);
        vertex_face_points(sv, v as usize, st, t as usize)
    }

    /// A listed edge of `a` and edge of `b`: its poses.
    #[inline(always)]
    fn edge_edge_poses(&self, &[ea, eb]: &[[u32; 2]; 2]) -> ([[f64; 3]; 4], [[f64; 3]; 4]) {
        edge_edge_points(self.a, ea, self.b, eb)
    }

    /// A listed vertex and triangle (of `b` and `a` when `FLIPPED`) reach their gap at
    /// `toi`: a vertex-face impact, or a face-vertex one when flipped.
    #[inline(always)]
    fn vertex_face<const FLIPPED: bool>(&self, &[v, t]: &[u32; 2], toi: f64, out: &mut ImpactOut) {
        let (sv, st) = self.vertex_and_face_sides(FLIPPED);
        let vertex = sv.tree().vert_order()[v as usize];
        let triangle = st.tree().tri_order()[t as usize];
        if FLIPPED {
            let impact = FaceImpact {
                triangle,
                vertex,
                toi,
            };
            self.budget.push(&mut out.face_vertex, impact);
        } else {
            let impact = VertexImpact {
                vertex,
                triangle,
                toi,
            };
            self.budget.push(&mut out.vertex_face, impact);
        }
    }

    /// A listed edge of `a` against an edge of `b` reaches its gap at `toi`.
    #[inline(always)]
    fn edge_edge(&self, &[ea, eb]: &[[u32; 2]; 2], toi: f64, out: &mut ImpactOut) {
        let ids = |s: &Swept<'_, K>, e: [u32; 2]| e.map(|v| s.tree().vert_order()[v as usize]);
        let impact = EdgeImpact {
            a: ids(self.a, ea),
            b: ids(self.b, eb),
            toi,
        };
        self.budget.push(&mut out.edge_edge, impact);
    }
}

/// The gap rule on one task's listed pairs, on the dispatched backend: 64 at a time, the
/// batch cull of the gap walk ([`SweptQuery::batch_cull`]: the pairs that cannot come
/// within their gap by the best time so far) before the exact test at the gap: the listing
/// pass culled at its own horizon, which the best time may be far below.
struct ListedOp<'q, 's, 'h, K: BoundingVolume, T, P, R> {
    q: &'q SweptQuery<'s, 'h, K>,
    pairs: &'q [T],
    vf: bool,
    points: &'q P,
    report: &'q R,
}

impl<'s, 'h, K, T, P, R> WithSimd for ListedOp<'_, 's, 'h, K, T, P, R>
where
    K: BoundingVolume,
    P: Fn(&SweptQuery<'s, 'h, K>, &T) -> ([[f64; 3]; 4], [[f64; 3]; 4]),
    R: Fn(&SweptQuery<'s, 'h, K>, &T, f64, &mut ImpactOut),
{
    type Output = ImpactOut;

    #[inline(always)]
    fn with_simd<S: Simd>(self, simd: S) -> ImpactOut {
        let q = self.q;
        let mut out = ImpactOut::default();
        let mut motion = [MotionCull::default(), MotionCull::default()];
        for chunk in self.pairs.chunks(MAX_PAIRS) {
            if q.budget.stopped() {
                break;
            }
            let n = chunk.len();
            for (i, pair) in chunk.iter().enumerate() {
                let (x0, x1) = (self.points)(q, pair);
                out.staged.points.set(i, &x0, &x1);
            }
            // PERF: the kernel in this dispatched body, not in a closure (see `batch_cull`).
            let culled = q.batch_cull(simd, &out.staged.points, n, self.vf, false, &mut motion);
            let mut undecided = culled.to_read(n, false);
            while undecided != 0 {
                let i = undecided.trailing_zeros() as usize;
                undecided &= undecided - 1;
                let (x0, x1) = out.staged.points.get(i);
                if let Some(toi) = q.listed_toi(self.vf, &x0, &x1) {
                    q.found(toi);
                    let before = out.len();
                    (self.report)(q, &chunk[i], toi, &mut out);
                    q.budget.add(out.len() - before);
                }
            }
        }
        out
    }
}
