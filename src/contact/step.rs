//! The collision-free step size of a line search: the largest fraction of a step that keeps
//! every pair of features at the gap the IPC Toolkit's rule asks for.
//!
//! A pair (a vertex and a triangle, or two edges) at distance `d0` at the start of the step
//! must stay at least `g = min_distance + (1 - rescaling) (d0 - min_distance)` apart. The
//! step size is the earliest time any pair comes within its `g` (exact CCD with that minimum
//! distance: within [`crate::ccd::TOI_TOLERANCE`] below it, never above), or 1 when none
//! does. Since `g >= min_distance`, it is never past the exact earliest impact at
//! `min_distance`. `g` is computed in `f64` from the pair's exact closest features (the
//! distance within the bound of [`crate::distance`]) and rounded up, so the kept gap is
//! never below the rule's.
//!
//! How it differs from the IPC Toolkit's `compute_collision_free_stepsize` (Tight Inclusion
//! narrow phase, `conservative_rescaling = 0.8`): ipctk caps the kept gap at `1e-4` (absolute,
//! `min(0.2 (d0 - dmin), 1e-4) + dmin`), measures it per axis (Tight Inclusion's box
//! distance), reports the lower end of an interval of width up to `1e-6`, and when a time
//! below `1e-6` comes out it tests again at `dmin` alone and scales that time by 0.8. dhcd
//! applies the rule as stated, exactly, for every pair.
//!
//! Which pairs are tested: the earliest impact at `min_distance` is found first (plain CCD);
//! the step is at most that time, so the walk then tests only pairs that can reach their gap
//! by it (the distance at t0 against the most the features can approach by then, decided
//! exactly). Any pair that reaches its `g` closes by `rescaling (d0 -
//! min_distance)` within the step, which it cannot do unless `d0 - min_distance <= M /
//! rescaling`, `M` the most two vertices can approach each other by the first impact `T`;
//! so every such pair comes within `min_distance + (1 - rescaling) M / rescaling` of the
//! other, and the walk culls at that distance. `M` is `T` times the diameter of the set of
//! vertex displacements (with the zero displacement of still objects): two points of two
//! features move relative to each other by a difference of two convex combinations of
//! displacements, at most that diameter. A mesh translating as a whole has `M = 0` and
//! culls at `min_distance`. The diameter is bounded by the smaller of twice the largest
//! displacement and the diagonal of the displacements' bounding box.
//!
//! The gap walk's bounds and boxes are fitted over `[0, T]` only (plus the walk's pruning
//! slack), not the whole step ([`Swept::until`]): with `T` small, as when a contact is
//! already close, far fewer leaf and feature pairs meet. Each pair found is then tested on
//! its exact motion, as every other. Per pair, [`Gap`] culls before computing any distance:
//! a pair reaches its gap only if `d0 <= min_distance + A / rescaling`, `A` the largest
//! relative displacement of a vertex of one feature and one of the other by `T`.
//!
//! Where the first impact is early (its walk restarted on bounds fitted short of the step,
//! as on most simulation steps), the gap walk would meet nearly the pairs of the first
//! impact's last pass again. That pass then culls at the gap walk's distance for its own
//! horizon (at least the one for `T`: the distance grows with the time) and lists the pairs
//! its batch cull leaves as able to reach their gap by that horizon; the gap rule is tested
//! on the list and no second walk runs ([`crate::query::ccd`]'s `listed`). A pass over the
//! whole step lists the same way when the relative motion is small against the edges
//! ([`WHOLE_STEP_LISTING`]): a sheet sliding or bending a little, with no impact, then costs
//! one walk. A list past [`MAX_LISTED`] pairs is dropped for the walk.

use std::sync::atomic::AtomicU64;

use crate::bv::BoundingVolume;
use crate::ccd::CcdOptions;
use crate::control::Budget;
use crate::counters::Counters;
use crate::error::{Error, Result};
use crate::hierarchy::Hierarchy;
use crate::par::Par;
use crate::query::ccd::{
    checked_step, earliest_bound, gap_over_listed, horizon_for, run, run_passes,
    whole_mesh_is_clear, Gap, Listed, Listing, Swept, MAX_LISTED,
};
use crate::query::{CcdMode, CcdQuery, Impacts, Motion};
use crate::walk::Workspace;

/// The step-size rule's parameters.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StepOptions {
    /// The distance no pair may come within (finite, `>= 0`; default 0).
    pub min_distance: f64,
    /// The fraction of each pair's distance above `min_distance` a step may close, in
    /// `(0, 1]` (default 0.8, the IPC Toolkit's `conservative_rescaling`).
    pub rescaling: f64,
}

impl Default for StepOptions {
    fn default() -> Self {
        Self {
            min_distance: 0.0,
            rescaling: 0.8,
        }
    }
}

impl StepOptions {
    /// `Ok` iff the options are valid ([`Error::InvalidMinDistance`],
    /// [`Error::InvalidRescaling`] otherwise).
    pub fn validate(&self) -> Result<()> {
        CcdOptions {
            t_max: 1.0,
            min_distance: self.min_distance,
        }
        .validate()?;
        if self.rescaling > 0.0 && self.rescaling <= 1.0 {
            Ok(())
        } else {
            Err(Error::InvalidRescaling(self.rescaling))
        }
    }
}

/// A collision-free step size and the pairs that limit it.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct StepSize {
    /// The largest fraction of the step, in `[0, 1]`, the rule allows (1: no pair comes
    /// within its gap).
    pub step: f64,
    /// The pairs that reach their gap at `step` (within [`crate::ccd::TOI_TOLERANCE`]),
    /// their times of impact against their own gaps; `counters` the work of both walks (the
    /// first impact's and the gap walk's), `contacts` the limiting pairs.
    pub limiting: Impacts,
}

/// The rule's culling distance for the motions `steps` (see the [module](self)); `still`:
/// some object that can pair with them does not move (its displacement, zero, counts).
fn cull_distance(options: &StepOptions, steps: &[Motion<'_>], still: bool, by: f64) -> f64 {
    let s = options.rescaling;
    // Rounded up: a few ulps of slack on every operation above.
    // Pairs need only reach their gap by time `by`: vertices move `by` of their step.
    let d = options.min_distance + (1.0 - s) / s * approach_bound(steps, still) * by;
    let d = d * (1.0 + 16.0 * f64::EPSILON);
    if d.is_finite() {
        d
    } else {
        f64::MAX
    }
}

/// An upper bound on `|u_i - u_j|` over every two vertices of `steps` (and the zero
/// displacement when `still`), `u = x1 - x0` exactly: the smaller of twice the largest `|u|`
/// and the diagonal of the box of the `u`, each rounded up.
fn approach_bound(steps: &[Motion<'_>], still: bool) -> f64 {
    let (mut lo, mut hi) = if still {
        ([0.0f64; 3], [0.0f64; 3])
    } else {
        ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3])
    };
    let mut largest = 0.0f64;
    for m in steps {
        for (p, q) in m.x0.iter().zip(m.x1) {
            let u = [q[0] - p[0], q[1] - p[1], q[2] - p[2]];
            largest = largest.max((u[0] * u[0] + u[1] * u[1] + u[2] * u[2]).sqrt());
            for k in 0..3 {
                lo[k] = lo[k].min(u[k]);
                hi[k] = hi[k].max(u[k]);
            }
        }
    }
    if largest == 0.0 {
        // No vertex moves (or none at all): nothing approaches.
        return 0.0;
    }
    // Each computed `u` is within half an ulp of the exact one per coordinate (at most
    // `EPSILON * largest`); the box's extents grow by twice that, the norm by its rounding.
    let slack = 4.0 * f64::EPSILON * largest;
    let extent = |k: usize| (hi[k] - lo[k]).max(0.0) + slack;
    let diagonal = (extent(0).powi(2) + extent(1).powi(2) + extent(2).powi(2)).sqrt();
    (2.0 * largest).min(diagonal) * (1.0 + 16.0 * f64::EPSILON)
}

/// The gap walk's query (earliest mode, culling at [`cull_distance`] for pairs that must
/// reach their gap by `by`) and the rule; `still` as for [`cull_distance`].
pub(crate) fn query_for(
    options: &StepOptions,
    steps: &[Motion<'_>],
    still: bool,
    by: f64,
) -> (CcdQuery, Gap) {
    let query = CcdQuery {
        options: CcdOptions {
            t_max: 1.0,
            min_distance: cull_distance(options, steps, still, by),
        },
        mode: CcdMode::Earliest,
    };
    (query, Gap::of(options))
}

/// The step size of `a` against `b` (the same for a self query) moving by `motions`: the
/// first impact at the minimum distance, then each pair's gap up to it, on the pairs the
/// first impact's last pass listed (when it listed them, at most `most_listed`) or by a
/// second walk.
#[allow(clippy::too_many_arguments)]
fn step_between<K: BoundingVolume>(
    a: &Swept<'_, K>,
    b: &Swept<'_, K>,
    self_query: bool,
    motions: &[Motion<'_>],
    options: &StepOptions,
    most_listed: usize,
    ws: &mut Workspace,
    par: Par,
) -> Result<StepSize> {
    let control = ws.control.clone();
    let budget = Budget::new(&control);
    // The first impact's passes fitted short of the step list their pairs, culled at the
    // gap walk's distance for their horizon (see `query::ccd::listed`).
    let cull_for = |horizon: f64| cull_distance(options, motions, false, horizon);
    let listing = Listing {
        cull_for: &cull_for,
        gap: Gap::of(options),
        most: most_listed,
        whole_step: lists_whole_step(a, b, self_query, motions, options),
    };
    let (best, first_work, listed) =
        first_impact(a, b, self_query, options, Some(&listing), &budget, ws, par)?;
    // The latest time a pair that limits the step can reach its gap.
    let until = by(&best);
    let (query, gap) = query_for(options, motions, false, until);
    let mut limiting = match listed {
        Some(listed) => gap_over_listed(
            a, b, self_query, &query, &best, &budget, gap, until, &listed, par,
        )?,
        // The walk fits its bounds over `[0, until]` only, knowing the first impact.
        None => {
            let gap = Some(gap);
            run(a, b, self_query, &query, Some(&best), &budget, gap, ws, par)?.0
        }
    };
    add_first_walk(&mut limiting.counters, first_work);
    Ok(StepSize {
        step: step_at(limiting.toi),
        limiting,
    })
}

/// The most the gap walk's culling distance over the whole step may exceed the minimum
/// distance, as a fraction of the mean edge length at t0, for the first impact's passes over
/// the whole step to list ([`lists_whole_step`]).
const WHOLE_STEP_LISTING: f64 = 1.0 / 16.0;

/// Whether the first impact's passes over the whole step list their pairs for the gap
/// rule (see [`crate::query::ccd`]'s `listed`): when the gap walk's culling distance over
/// the whole step exceeds the minimum distance by at most [`WHOLE_STEP_LISTING`] times the
/// mean edge length at t0. The first walk then meets nearly the candidates it meets anyway
/// (a distance well below the spacing of the features adds few), and a step whose first
/// impact is late or none runs one walk, not two. Where the relative motion is large
/// against the features (layers closing in, bodies meeting), the larger distance costs the
/// first walk more than the second walk it saves, and a pass over the whole step does not
/// list. The mean is taken over at most [`EDGE_SAMPLE`] evenly spaced edges of each side:
/// it only picks the work, never the answer.
fn lists_whole_step<K: BoundingVolume>(
    a: &Swept<'_, K>,
    b: &Swept<'_, K>,
    self_query: bool,
    motions: &[Motion<'_>],
    options: &StepOptions,
) -> bool {
    let extra = cull_distance(options, motions, false, 1.0) - options.min_distance;
    if extra <= 0.0 {
        return true;
    }
    let sides: &[&Swept<'_, K>] = if self_query { &[a] } else { &[a, b] };
    let (mut sum, mut edges) = (0.0f64, 0usize);
    for (s, m) in sides.iter().zip(motions) {
        let all = &s.tree().tables().edges;
        let stride = all.len().div_ceil(EDGE_SAMPLE).max(1);
        for &[u, v] in all.iter().step_by(stride) {
            let (p, q) = (m.x0[u as usize], m.x0[v as usize]);
            sum += ((p[0] - q[0]).powi(2) + (p[1] - q[1]).powi(2) + (p[2] - q[2]).powi(2)).sqrt();
            edges += 1;
        }
    }
    edges > 0 && extra <= WHOLE_STEP_LISTING * (sum / edges as f64)
}

/// The most edges of a side [`lists_whole_step`] measures.
const EDGE_SAMPLE: usize = 1024;

/// The earliest impact at the minimum distance (plain CCD, cheap: culled at that
/// distance), as the starting bound of the step-size walk: every pair reaches its gap (at
/// least the minimum distance) no later than it reaches the minimum distance, so the step is
/// at most this time, and pairs that cannot reach their gap by then are never tested. Also
/// the feature pairs of its last pass when that pass listed them under `listing`
/// ([`run_passes`]).
#[allow(clippy::too_many_arguments)]
fn first_impact<K: BoundingVolume>(
    a: &Swept<'_, K>,
    b: &Swept<'_, K>,
    self_query: bool,
    options: &StepOptions,
    listing: Option<&Listing<'_>>,
    budget: &Budget<'_>,
    ws: &mut Workspace,
    par: Par,
) -> Result<(AtomicU64, Counters, Option<Listed>)> {
    let query = first_impact_query(options);
    let best = earliest_bound(&query).expect("earliest mode");
    let (impacts, _, listed) = run_passes(
        a,
        b,
        self_query,
        &query,
        Some(&best),
        budget,
        None,
        listing,
        ws,
        par,
    )?;
    Ok((bound_at(impacts.toi), impacts.counters, listed))
}

/// The plain CCD query of the first impact at the minimum distance.
pub(crate) fn first_impact_query(options: &StepOptions) -> CcdQuery {
    CcdQuery {
        options: CcdOptions {
            t_max: 1.0,
            min_distance: options.min_distance,
        },
        mode: CcdMode::Earliest,
    }
}

/// The gap walk's starting bound: the first impact's time (`None`: no impact, no bound).
pub(crate) fn bound_at(toi: Option<f64>) -> AtomicU64 {
    AtomicU64::new(toi.unwrap_or(f64::INFINITY).to_bits())
}

/// The latest time a pair that limits the step can reach its gap: the first impact plus
/// the walk's pruning slack (rounded up), at most 1.
pub(crate) fn by(best: &AtomicU64) -> f64 {
    horizon_for(f64::from_bits(
        best.load(std::sync::atomic::Ordering::Relaxed),
    ))
}

/// The gap walk's counters plus the first walk's work: the step size's counters hold both
/// walks' work, and `contacts` still counts the limiting pairs.
pub(crate) fn add_first_walk(counters: &mut Counters, first_walk: Counters) {
    let contacts = counters.contacts;
    *counters += first_walk;
    counters.contacts = contacts;
}

/// The step allowed by the earliest time any pair reaches its gap (`None`: none does).
pub(crate) fn step_at(toi: Option<f64>) -> f64 {
    toi.map_or(1.0, |t| t.clamp(0.0, 1.0))
}

/// The collision-free step size of one mesh moving by `motion` (self contacts), on the
/// calling thread.
pub fn collision_free_stepsize<K: BoundingVolume>(
    h: &Hierarchy<K>,
    motion: Motion<'_>,
    options: &StepOptions,
) -> Result<StepSize> {
    collision_free_stepsize_with(h, motion, options, &mut Workspace::default(), Par::Seq)
}

/// [`collision_free_stepsize`] with scratch and parallelism (the step does not depend on
/// it).
pub fn collision_free_stepsize_with<K: BoundingVolume>(
    h: &Hierarchy<K>,
    motion: Motion<'_>,
    options: &StepOptions,
    ws: &mut Workspace,
    par: Par,
) -> Result<StepSize> {
    options.validate()?;
    let step = checked_step(h.tree(), motion)?;
    // No pair can reach its gap when none comes within the gap walk's culling distance
    // over the whole step.
    let reach = cull_distance(options, &[motion], false, 1.0).max(options.min_distance);
    if whole_mesh_is_clear(h.tree(), &step, 1.0, reach) {
        Budget::new(&ws.control).finish()?;
        return Ok(StepSize {
            step: 1.0,
            limiting: Impacts::default(),
        });
    }
    let s = Swept::of_step(h, std::borrow::Cow::Owned(step));
    step_between(&s, &s, true, &[motion], options, MAX_LISTED, ws, par)
}

/// The collision-free step size of `a` and `b` moving by their motions (the pairs between
/// them only), on the calling thread.
pub fn collision_free_stepsize_pair<K: BoundingVolume>(
    a: &Hierarchy<K>,
    a_motion: Motion<'_>,
    b: &Hierarchy<K>,
    b_motion: Motion<'_>,
    options: &StepOptions,
    ws: &mut Workspace,
    par: Par,
) -> Result<StepSize> {
    options.validate()?;
    let sa = Swept::new(a, a_motion)?;
    let sb = Swept::new(b, b_motion)?;
    let motions = [a_motion, b_motion];
    step_between(&sa, &sb, false, &motions, options, MAX_LISTED, ws, par)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The largest `|u_i - u_j|` over every two displacements (and zero when `still`).
    fn brute_force(steps: &[Motion<'_>], still: bool) -> f64 {
        let mut u: Vec<[f64; 3]> = steps
            .iter()
            .flat_map(|m| m.x0.iter().zip(m.x1))
            .map(|(p, q)| [q[0] - p[0], q[1] - p[1], q[2] - p[2]])
            .collect();
        if still {
            u.push([0.0; 3]);
        }
        let mut most = 0.0f64;
        for a in &u {
            for b in &u {
                let d = (0..3).map(|k| (a[k] - b[k]).powi(2)).sum::<f64>().sqrt();
                most = most.max(d);
            }
        }
        most
    }

    /// A 12 x 12 jittered sheet folded onto itself at x = 0.6: its triangles, and its
    /// positions with the far layer lifted `lift` above the near one, the jitter drawn from
    /// `seed`.
    fn folded_sheet(lift: f32, seed: u64) -> (Vec<[u32; 3]>, Vec<[f64; 3]>) {
        use crate::shapes::{fold_x, grid, jitter};
        let rest = grid(12, 12, 0.1, [0.0; 3]);
        let jittered = jitter(&fold_x(rest.positions(), 0.6), [1e-3, 1e-3, 2e-4], seed);
        let at = jittered.iter().zip(rest.positions());
        let lifted = at.map(|(p, r)| [p[0], p[1], p[2] + if r[0] > 0.6 { lift } else { 0.0 }]);
        let lifted = lifted.map(|p| p.map(f64::from)).collect();
        (rest.triangles().to_vec(), lifted)
    }

    /// The rules the listing tests run: the IPC Toolkit's default, one with a minimum
    /// distance, and a small rescaling (a large culling distance).
    const RULES: [StepOptions; 3] = [
        StepOptions {
            min_distance: 0.0,
            rescaling: 0.8,
        },
        StepOptions {
            min_distance: 1e-4,
            rescaling: 0.8,
        },
        StepOptions {
            min_distance: 0.0,
            rescaling: 0.5,
        },
    ];

    /// The first impact's walk under `o` with its listing (`whole_step`: passes over the
    /// whole step list too): its time, its list's pairs of each kind ([`Listed::counts`]),
    /// which must be more than a few, and the candidates its passes met.
    fn first_impact_listing<K: BoundingVolume>(
        a: &Swept<'_, K>,
        b: &Swept<'_, K>,
        self_query: bool,
        motions: &[Motion<'_>],
        o: &StepOptions,
        whole_step: bool,
        at: &str,
    ) -> (f64, [usize; 3], u64) {
        let control = crate::control::Control::default();
        let budget = Budget::new(&control);
        let cull_for = |horizon: f64| cull_distance(o, motions, false, horizon);
        let listing = Listing {
            cull_for: &cull_for,
            gap: Gap::of(o),
            most: MAX_LISTED,
            whole_step,
        };
        let mut ws = Workspace::default();
        let (best, work, listed) = first_impact(
            a,
            b,
            self_query,
            o,
            Some(&listing),
            &budget,
            &mut ws,
            Par::Seq,
        )
        .unwrap();
        let first = f64::from_bits(best.load(std::sync::atomic::Ordering::Relaxed));
        let listed = listed.unwrap_or_else(|| panic!("{at}: the last pass lists"));
        assert!(listed.len() > 3, "{at}: {} pairs listed", listed.len());
        (first, listed.counts(), work.prim_tests)
    }

    /// The step from the list is the walk's, with the same limiting pairs, and the walk
    /// tested nodes the list did not.
    fn assert_list_matches_walk(from_list: &StepSize, walked: &StepSize, at: &str) {
        assert_eq!(from_list.step, walked.step, "{at}");
        let (l, w) = (&from_list.limiting, &walked.limiting);
        assert_eq!(l.vertex_face, w.vertex_face, "{at}");
        assert_eq!(l.face_vertex, w.face_vertex, "{at}");
        assert_eq!(l.edge_edge, w.edge_edge, "{at}");
        assert_eq!(l.toi, w.toi, "{at}");
        // The walk's node tests are counted, the list's only its pairs.
        assert!(w.counters.bv_tests > l.counters.bv_tests, "{at}");
    }

    /// A step where nothing touches but pairs reach their gap, its relative motion small:
    /// the first impact's one pass over the whole step lists (fewer pairs than it met: its
    /// batch cull ended some), and the step from that list, below 1 with some limiting pair,
    /// is the second walk's on 1 and 2 threads. Returns the list's pairs of each kind.
    fn assert_whole_step_list_matches_walk<K: BoundingVolume>(
        a: &Swept<'_, K>,
        b: &Swept<'_, K>,
        self_query: bool,
        motions: &[Motion<'_>],
        o: &StepOptions,
        at: &str,
    ) -> [usize; 3] {
        assert!(lists_whole_step(a, b, self_query, motions, o), "{at}");
        let (first, listed, met) = first_impact_listing(a, b, self_query, motions, o, true, at);
        assert_eq!(first, f64::INFINITY, "{at}: nothing touches");
        // One pass (no impact, no restart).
        let total: usize = listed.iter().sum();
        assert!(
            (total as u64) < met,
            "{at}: listed {total} of {met} candidates"
        );
        let mut ws = Workspace::default();
        for par in [Par::Seq, Par::Rayon(2)] {
            let mut step = |most: usize| {
                step_between(a, b, self_query, motions, o, most, &mut ws, par).unwrap()
            };
            let (from_list, walked) = (step(MAX_LISTED), step(0));
            let at = format!("{at} {par:?}");
            assert!(from_list.step < 1.0, "{at}: some pair reaches its gap");
            let l = &from_list.limiting;
            let limited = l.vertex_face.len() + l.face_vertex.len() + l.edge_edge.len();
            assert!(limited > 0, "{at}: no limiting pair");
            assert_list_matches_walk(&from_list, &walked, &at);
        }
        listed
    }

    /// A jittered sheet folded onto itself, its far layer just above the near one at t0 and
    /// pushed through it by t1: the first impact comes early in the step, so its walk
    /// restarts on bounds fitted short of the step and its last pass lists its pairs. The
    /// step from that list is the second walk's (the list refused: at most no pair, or
    /// fewer than it meets), with the same limiting pairs, for every method, rule and
    /// thread count.
    #[test]
    fn the_listed_pairs_give_the_second_walks_step() {
        use crate::{Hierarchy, Mesh, Options};
        let (triangles, x0) = folded_sheet(2e-3, 1);
        let (_, x1) = folded_sheet(-0.05, 2);
        let m = Mesh::new_f64(x0.clone(), triangles).unwrap();
        let motions = [Motion::new(&x0, &x1)];
        crate::for_each_method!(K => {
            let h = Hierarchy::<K>::new(&m, Options::default()).unwrap();
            let s = Swept::new(&h, motions[0]).unwrap();
            for o in &RULES {
                let at = format!("{:?} {o:?}", K::METHOD);
                let (first, listed, _) =
                    first_impact_listing(&s, &s, true, &motions, o, false, &at);
                assert!(first < 1.0 / 16.0, "{at}: the first impact at {first}");
                let mut ws = Workspace::default();
                for par in [Par::Seq, Par::Rayon(2)] {
                    let mut step = |most: usize| {
                        step_between(&s, &s, true, &motions, o, most, &mut ws, par).unwrap()
                    };
                    let from_list = step(MAX_LISTED);
                    for most in [0, 3, listed.iter().sum::<usize>() / 2] {
                        let walked = step(most);
                        let at = format!("{at} {par:?} at most {most}");
                        assert!(walked.step < 1.0, "{at}");
                        assert_list_matches_walk(&from_list, &walked, &at);
                    }
                }
            }
        });
    }

    /// The same folded sheet, its far layer closing from 2e-3 to 6e-4 above the near one
    /// (the same jitter at both ends): nothing touches, but pairs reach their gap late in
    /// the step. The relative motion is small against the edges, so the first impact's pass
    /// over the whole step lists; the step from that list is the second walk's, with the
    /// same limiting pairs, for every method, rule and thread count.
    #[test]
    fn a_pass_over_the_whole_step_lists_when_the_motion_is_small() {
        use crate::{Hierarchy, Mesh, Options};
        let (triangles, x0) = folded_sheet(2e-3, 1);
        let (_, x1) = folded_sheet(6e-4, 1);
        let m = Mesh::new_f64(x0.clone(), triangles).unwrap();
        let motions = [Motion::new(&x0, &x1)];
        crate::for_each_method!(K => {
            let h = Hierarchy::<K>::new(&m, Options::default()).unwrap();
            let s = Swept::new(&h, motions[0]).unwrap();
            for o in &RULES {
                let at = format!("{:?} {o:?}", K::METHOD);
                assert_whole_step_list_matches_walk(&s, &s, true, &motions, o, &at);
            }
        });
    }

    /// Two separate sheets, the upper one closing from 2e-3 to 6e-4 above the lower (a pair
    /// query): its pass over the whole step lists vertices of each against triangles of the
    /// other, and the step from that list is the second walk's, for every method, rule and
    /// thread count.
    #[test]
    fn a_pair_query_over_the_whole_step_lists_both_sides() {
        use crate::shapes::{grid, jitter};
        use crate::{Hierarchy, Mesh, Options};
        let rest = grid(12, 12, 0.1, [0.0; 3]);
        let sheet = |seed: u64, lift: f32| -> Vec<[f64; 3]> {
            let jittered = jitter(rest.positions(), [1e-3, 1e-3, 2e-4], seed);
            jittered
                .iter()
                .map(|p| [p[0], p[1], p[2] + lift].map(f64::from))
                .collect()
        };
        let (low, high0, high1) = (sheet(1, 0.0), sheet(2, 2e-3), sheet(2, 6e-4));
        let lower = Mesh::new_f64(low.clone(), rest.triangles().to_vec()).unwrap();
        let upper = Mesh::new_f64(high0.clone(), rest.triangles().to_vec()).unwrap();
        let motions = [Motion::new(&low, &low), Motion::new(&high0, &high1)];
        crate::for_each_method!(K => {
            let ha = Hierarchy::<K>::new(&lower, Options::default()).unwrap();
            let hb = Hierarchy::<K>::new(&upper, Options::default()).unwrap();
            let sa = Swept::new(&ha, motions[0]).unwrap();
            let sb = Swept::new(&hb, motions[1]).unwrap();
            for o in &RULES {
                let at = format!("{:?} {o:?}", K::METHOD);
                let [vf, fv, ee] =
                    assert_whole_step_list_matches_walk(&sa, &sb, false, &motions, o, &at);
                assert!(vf > 0 && fv > 0 && ee > 0, "{at}: listed {vf} {fv} {ee}");
            }
        });
    }

    #[test]
    fn a_translation_approaches_nothing_unless_something_stays_still() {
        let x0: Vec<[f64; 3]> = (0..50)
            .map(|i| [0.1 * i as f64, (0.37 * i as f64).sin(), 1e3])
            .collect();
        let x1: Vec<[f64; 3]> = x0.iter().map(|p| [p[0] + 0.5, p[1] - 0.25, p[2]]).collect();
        let m = [Motion::new(&x0, &x1)];
        let alone = approach_bound(&m, false);
        assert!((0.0..1e-12).contains(&alone), "{alone}");
        let beside_a_wall = approach_bound(&m, true);
        assert!(
            beside_a_wall >= (0.5f64 * 0.5 + 0.25 * 0.25).sqrt(),
            "{beside_a_wall}"
        );
        assert_eq!(approach_bound(&[Motion::new(&x0, &x0)], true), 0.0);
    }

    #[test]
    fn the_bound_is_never_below_the_largest_relative_displacement() {
        let mut state = 7u64;
        let mut draw = || crate::shapes::splitmix64(&mut state) as f64 / u64::MAX as f64 - 0.5;
        for case in 0..200 {
            let n = 1 + case % 9;
            let scale = [1e-9, 1.0, 1e6][case % 3];
            let x0: Vec<[f64; 3]> = (0..n).map(|_| [draw(), draw(), draw()]).collect();
            let x1: Vec<[f64; 3]> = x0
                .iter()
                .map(|p| [p[0] + scale * draw(), p[1] + scale * draw(), p[2]])
                .collect();
            let y0: Vec<[f64; 3]> = (0..n).map(|_| [draw(), draw(), draw()]).collect();
            let y1: Vec<[f64; 3]> = y0.iter().map(|p| [p[0] + 3.0, p[1], p[2]]).collect();
            let steps = [Motion::new(&x0, &x1), Motion::new(&y0, &y1)];
            for still in [false, true] {
                for k in [1, 2] {
                    let exact = brute_force(&steps[..k], still);
                    let bound = approach_bound(&steps[..k], still);
                    assert!(bound >= exact, "case {case}: {bound} < {exact}");
                    assert!(
                        bound <= 2.0 * exact + 1e-9 * scale,
                        "case {case}: {bound} loose"
                    );
                }
            }
        }
    }
}
