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
//! rescaling`, `M` twice the largest vertex displacement by the first impact `T` (`T` times
//! that of the step); so every such pair comes within `min_distance + (1 - rescaling) M /
//! rescaling` of the other, and the walk culls at that distance.

use std::sync::atomic::AtomicU64;

use crate::bv::BoundingVolume;
use crate::ccd::CcdOptions;
use crate::control::Budget;
use crate::counters::Counters;
use crate::error::{Error, Result};
use crate::hierarchy::Hierarchy;
use crate::par::Par;
use crate::query::ccd::{earliest_bound, run, Gap, Swept};
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

/// The rule's culling distance for the motions `steps` (see the [module](self)).
fn cull_distance(options: &StepOptions, steps: &[Motion<'_>], by: f64) -> f64 {
    let mut largest = 0.0f64;
    for m in steps {
        for (p, q) in m.x0.iter().zip(m.x1) {
            let d = ((p[0] - q[0]).powi(2) + (p[1] - q[1]).powi(2) + (p[2] - q[2]).powi(2)).sqrt();
            largest = largest.max(d);
        }
    }
    let s = options.rescaling;
    // Rounded up: a few ulps of slack on every operation above.
    // Pairs need only reach their gap by time `by`: vertices move `by` of their step.
    let d = options.min_distance + (1.0 - s) / s * 2.0 * largest * by;
    let d = d * (1.0 + 16.0 * f64::EPSILON);
    if d.is_finite() {
        d
    } else {
        f64::MAX
    }
}

/// The gap walk's query (earliest mode, culling at [`cull_distance`] for pairs that must
/// reach their gap by `by`) and the rule.
pub(crate) fn query_for(options: &StepOptions, steps: &[Motion<'_>], by: f64) -> (CcdQuery, Gap) {
    let query = CcdQuery {
        options: CcdOptions {
            t_max: 1.0,
            min_distance: cull_distance(options, steps, by),
        },
        mode: CcdMode::Earliest,
    };
    let gap = Gap {
        min_distance: options.min_distance,
        rescaling: options.rescaling,
    };
    (query, gap)
}

/// The step size of `a` against `b` (the same for a self query) moving by `motions`: the
/// first impact at the minimum distance, then the walk at each pair's gap, bounded by it.
#[allow(clippy::too_many_arguments)]
fn step_between<K: BoundingVolume>(
    a: &Swept<'_, K>,
    b: &Swept<'_, K>,
    self_query: bool,
    motions: &[Motion<'_>],
    options: &StepOptions,
    ws: &mut Workspace,
    par: Par,
) -> Result<StepSize> {
    let control = ws.control.clone();
    let budget = Budget::new(&control);
    let (best, first_work) = first_impact(a, b, self_query, options, &budget, ws, par)?;
    let (query, gap) = query_for(options, motions, by(&best));
    let (mut limiting, _) = run(
        a,
        b,
        self_query,
        &query,
        Some(&best),
        &budget,
        Some(gap),
        ws,
        par,
    )?;
    add_first_walk(&mut limiting.counters, first_work);
    Ok(StepSize {
        step: step_at(limiting.toi),
        limiting,
    })
}

/// The earliest impact at the minimum distance (plain CCD, cheap: culled at that
/// distance), as the starting bound of the step-size walk: every pair reaches its gap (at
/// least the minimum distance) no later than it reaches the minimum distance, so the step is
/// at most this time, and pairs that cannot reach their gap by then are never tested.
#[allow(clippy::too_many_arguments)]
fn first_impact<K: BoundingVolume>(
    a: &Swept<'_, K>,
    b: &Swept<'_, K>,
    self_query: bool,
    options: &StepOptions,
    budget: &Budget<'_>,
    ws: &mut Workspace,
    par: Par,
) -> Result<(AtomicU64, Counters)> {
    let query = first_impact_query(options);
    let best = earliest_bound(&query).expect("earliest mode");
    let (impacts, _) = run(a, b, self_query, &query, Some(&best), budget, None, ws, par)?;
    Ok((bound_at(impacts.toi), impacts.counters))
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
    let t = f64::from_bits(best.load(std::sync::atomic::Ordering::Relaxed));
    (t + 8.0 * crate::ccd::TOI_TOLERANCE).next_up().min(1.0)
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
    let s = Swept::new(h, motion)?;
    step_between(&s, &s, true, &[motion], options, ws, par)
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
    step_between(&sa, &sb, false, &[a_motion, b_motion], options, ws, par)
}
