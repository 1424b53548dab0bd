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
//! a pass lists (bounds fitted short of the whole step, [`super::run_passes`]).
//!
//! The list is bounded ([`Listing::most`], [`MAX_LISTED`] for the step size); past it the
//! list is dropped and the caller walks again. Results are the gap walk's: the same pairs tested under the same rule with the
//! same shared bound, settled the same way ([`SweptQuery::settle_earliest`]).

use std::sync::atomic::{AtomicBool, AtomicU64, AtomicUsize, Ordering};

use rayon::prelude::*;

use super::{
    edge_edge_points, vertex_face_points, CcdQuery, EdgeImpact, FaceImpact, Gap, ImpactOut,
    Impacts, Swept, SweptQuery, VertexImpact,
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

    /// `other`'s pairs after this one's.
    pub(super) fn append(&mut self, mut other: Listed) {
        self.vertex_face.append(&mut other.vertex_face);
        self.face_vertex.append(&mut other.face_vertex);
        self.edge_edge.append(&mut other.edge_edge);
    }
}

/// What a walk lists: the pairs that may reach their gap under `gap` by the walk's horizon,
/// among those its bounds meet culled at `cull_for(horizon)` at least; at most `most` of
/// them, or none.
pub(crate) struct Listing<'a> {
    pub(crate) cull_for: &'a (dyn Fn(f64) -> f64 + Sync),
    pub(crate) gap: Gap,
    pub(crate) most: usize,
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
    q.merge(
        &mut out,
        q.each_listed(&listed.vertex_face, par, SweptQuery::vertex_face),
    );
    q.merge(
        &mut out,
        q.each_listed(&listed.face_vertex, par, SweptQuery::face_vertex),
    );
    q.merge(
        &mut out,
        q.each_listed(&listed.edge_edge, par, SweptQuery::edge_edge),
    );
    budget.finish()?;
    q.settle_earliest(&mut out);
    budget.finish()?;
    let counters = Counters {
        prim_tests: listed.len() as u64,
        ..Counters::default()
    };
    Ok(q.impacts(out, counters))
}

impl<K: BoundingVolume> SweptQuery<'_, '_, K> {
    /// `test` on each of `pairs` into one output, in tasks of [`LISTED_PER_TASK`] pairs
    /// when `par` is parallel (outputs merged in task order).
    fn each_listed<T: Sync>(
        &self,
        pairs: &[T],
        par: Par,
        test: impl Fn(&Self, &T, &mut ImpactOut) + Sync,
    ) -> ImpactOut {
        let run = |chunk: &[T]| {
            let mut out = ImpactOut::default();
            for (i, p) in chunk.iter().enumerate() {
                if i % crate::control::POLL_EVERY as usize == 0 && self.budget.stopped() {
                    break;
                }
                let before = out.len();
                test(self, p, &mut out);
                self.budget.add(out.len() - before);
            }
            out
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
    /// of the moment. The list holds only pairs that may reach their gap by the listing
    /// walk's horizon ([`Gap::may_reach`], an exact distance test that is costly for pairs
    /// touching at t0); it is not tested again for the shorter time of the moment, as the
    /// test at the gap decides those pairs anyway.
    #[inline(always)]
    fn listed_toi(&self, vertex_face: bool, x0: &[[f64; 3]; 4], x1: &[[f64; 3]; 4]) -> Option<f64> {
        let gap = self.gap.as_ref().expect("a gap rule");
        let o = gap.at_gap(vertex_face, x0, self.options_now());
        self.pair_toi_with(vertex_face, x0, x1, &o)
    }

    /// A listed vertex of `a` against a triangle of `b`.
    #[inline(always)]
    fn vertex_face(&self, &[v, t]: &[u32; 2], out: &mut ImpactOut) {
        let (v, t) = (v as usize, t as usize);
        let (x0, x1) = vertex_face_points(self.a, v, self.b, t);
        if let Some(toi) = self.listed_toi(true, &x0, &x1) {
            self.found(toi);
            let impact = VertexImpact {
                vertex: self.a.tree().vert_order()[v],
                triangle: self.b.tree().tri_order()[t],
                toi,
            };
            self.budget.push(&mut out.vertex_face, impact);
        }
    }

    /// A listed vertex of `b` against a triangle of `a` (pair queries).
    #[inline(always)]
    fn face_vertex(&self, &[v, t]: &[u32; 2], out: &mut ImpactOut) {
        let (v, t) = (v as usize, t as usize);
        let (x0, x1) = vertex_face_points(self.b, v, self.a, t);
        if let Some(toi) = self.listed_toi(true, &x0, &x1) {
            self.found(toi);
            let impact = FaceImpact {
                triangle: self.a.tree().tri_order()[t],
                vertex: self.b.tree().vert_order()[v],
                toi,
            };
            self.budget.push(&mut out.face_vertex, impact);
        }
    }

    /// A listed edge of `a` against an edge of `b`.
    #[inline(always)]
    fn edge_edge(&self, &[ea, eb]: &[[u32; 2]; 2], out: &mut ImpactOut) {
        let (x0, x1) = edge_edge_points(self.a, ea, self.b, eb);
        if let Some(toi) = self.listed_toi(false, &x0, &x1) {
            self.found(toi);
            let ids = |s: &Swept<'_, K>, e: [u32; 2]| e.map(|v| s.tree().vert_order()[v as usize]);
            let impact = EdgeImpact {
                a: ids(self.a, ea),
                b: ids(self.b, eb),
                toi,
            };
            self.budget.push(&mut out.edge_edge, impact);
        }
    }
}
