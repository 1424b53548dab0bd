//! Calibration of the cost model `T = N_V*C_V + N_P*C_P + N_U*C_U` on this machine, from
//! the real kernels on the experiment's own frames.
//!
//! For a calibration frame, every object gets the frame's positions and every object pair is
//! queried once (lazy refit included), which records each pair's overlapping leaf pairs and
//! each object's fitted nodes. Then, `reps` times:
//!
//! * **fixed**: `update_positions` of every object (validation, position copy into the
//!   internal order, invalidation): a cost per step that does not depend on `N_*`;
//! * **`C_U`**: `invalidate` + `refit_nodes(fitted)` of every object, divided by the `N_U` it
//!   counts (the same nodes the query refitted);
//! * **`C_V`**: `broad_phase` of every pair with every node it tests already fitted (so no
//!   refit inside), divided by `N_V`;
//! * **`C_P`**: `narrow_phase` of every pair's recorded leaf pairs, divided by `N_P`.
//!
//! The constant is pooled over the calibration frames from each frame's least time:
//! `C = sum_f min_rep(t_f) / sum_f N_f`. The machine is shared (other processes preempt
//! ours), so the least time over repetitions is the least-disturbed one; the measured step
//! times use the same statistic, so model and measurement compare like with like. Pooling
//! weights frames by their work, as the run does. The spread is that of every single sample
//! `t / N` (all frames and repetitions): median, min, max, quartiles. The per-frame
//! constants show how they move over the run.
//!
//! Calibration frames are calibrated right after they are measured (interleaved with the
//! measurement), so both see the same machine load.

use std::time::Instant;

use dhcd::calibration::Calibration;
use dhcd::AnyHierarchy;
use dhcd::Counters;
use dhcd::Par;
use dhcd::Workspace;

use super::{two_mut, ExperimentError};

/// Median, extremes and quartiles of a sample.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Spread {
    pub median: f64,
    pub min: f64,
    pub max: f64,
    pub p25: f64,
    pub p75: f64,
    pub samples: usize,
}

impl Spread {
    /// The spread of `xs` (all zero when empty).
    pub fn of(xs: &[f64]) -> Self {
        if xs.is_empty() {
            return Self::default();
        }
        let mut v = xs.to_vec();
        v.sort_by(f64::total_cmp);
        Self {
            median: quantile(&v, 0.5),
            min: v[0],
            max: v[v.len() - 1],
            p25: quantile(&v, 0.25),
            p75: quantile(&v, 0.75),
            samples: v.len(),
        }
    }
}

/// Linear-interpolated quantile of sorted `v` (non-empty).
fn quantile(v: &[f64], q: f64) -> f64 {
    let x = q * (v.len() - 1) as f64;
    let (i, f) = (x.floor() as usize, x.fract());
    if i + 1 < v.len() {
        v[i] * (1.0 - f) + v[i + 1] * f
    } else {
        v[i]
    }
}

/// Median of `xs` (sorts it; 0 when empty).
pub fn median(xs: &mut [f64]) -> f64 {
    if xs.is_empty() {
        return 0.0;
    }
    xs.sort_by(f64::total_cmp);
    quantile(xs, 0.5)
}

/// The constants of one calibration frame (least time over repetitions) and its counts.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct FrameCosts {
    pub frame: usize,
    pub counters: Counters,
    pub c_v_ns: f64,
    pub c_p_ns: f64,
    pub c_u_ns: f64,
    pub fixed_ns: f64,
}

/// One calibrated constant: the pooled value and the spread of the single samples.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Constant {
    /// `sum_f min_rep(t_f) / sum_f N_f` (ns per operation).
    pub value: f64,
    /// Spread of the single samples `t / N` over frames and repetitions.
    pub spread: Spread,
}

/// Calibrated constants of one method.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Costs {
    /// ns per BV-pair test (traversal: test + expansion + frontier bookkeeping).
    pub c_v: Constant,
    /// ns per triangle-pair test (exact narrow phase).
    pub c_p: Constant,
    /// ns per BV update (refit of one node).
    pub c_u: Constant,
    /// ns per step of `update_positions` of every object (not in the paper's model).
    pub fixed_ns: Constant,
    pub per_frame: Vec<FrameCosts>,
}

impl Costs {
    /// `N_V*C_V + N_P*C_P + N_U*C_U` with the pooled constants.
    pub fn predict(&self, c: &Counters) -> f64 {
        c.bv_tests as f64 * self.c_v.value
            + c.prim_tests as f64 * self.c_p.value
            + c.bv_updates as f64 * self.c_u.value
    }
}

/// `count` frames spread evenly over `0..frames` (the last one included), distinct.
pub fn calibration_frames(frames: usize, count: usize) -> Vec<usize> {
    let count = count.min(frames).max(1);
    let mut v: Vec<usize> = (1..=count).map(|k| k * frames / count - 1).collect();
    v.dedup();
    v
}

fn per(t: f64, n: u64) -> Option<f64> {
    (n > 0).then(|| t / n as f64)
}

/// Calibration samples of one frame of one method (combined over frames by `combine`).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct FrameSamples {
    pub frame: usize,
    pub counters: Counters,
    /// Per constant (`C_V`, `C_P`, `C_U`, fixed): the time of every repetition (ns).
    pub times: [Vec<f64>; 4],
}

impl FrameSamples {
    fn counts(&self) -> [u64; 4] {
        let c = &self.counters;
        [c.bv_tests, c.prim_tests, c.bv_updates, 1]
    }
}

/// Calibrates one method on one frame: hierarchies `hs` (one per object) get `frame`'s
/// positions, every pair is queried once, then the four measurements are repeated `reps`
/// times.
pub(super) fn calibrate_frame(
    hs: &mut [AnyHierarchy],
    frame: &[Vec<[f32; 3]>],
    frame_index: usize,
    pairs: &[(usize, usize)],
    reps: usize,
    par: Par,
) -> Result<FrameSamples, ExperimentError> {
    let mut ws = Workspace::default();
    for (h, p) in hs.iter_mut().zip(frame) {
        h.update_positions(p)?;
    }
    let mut counters = Counters::default();
    let mut leaves = Vec::with_capacity(pairs.len());
    for &(i, j) in pairs {
        let (a, b) = two_mut(hs, i, j);
        counters += a.collide(b, &mut ws, par)?.counters;
    }
    // The query runs the narrow phase as it finds leaf pairs; record them with a broad
    // phase over the now fitted hierarchies (it refits nothing).
    for &(i, j) in pairs {
        let (a, b) = two_mut(hs, i, j);
        leaves.push(a.broad_phase(b, &mut ws, par)?.leaf_pairs);
    }
    let fitted: Vec<Vec<u32>> = hs.iter().map(AnyHierarchy::fitted_nodes).collect();
    let mut times: [Vec<f64>; 4] = Default::default();
    for _ in 0..reps {
        // fixed: update_positions (validates, copies, invalidates).
        let t = Instant::now();
        for (h, p) in hs.iter_mut().zip(frame) {
            h.update_positions(p)?;
        }
        let fixed = t.elapsed().as_nanos() as f64;
        // C_U: the step's refit, alone.
        let t = Instant::now();
        let mut nu = 0;
        for (h, ids) in hs.iter_mut().zip(&fitted) {
            h.invalidate();
            nu += h.refit_nodes(ids, par)?;
        }
        let tu = t.elapsed().as_nanos() as f64;
        debug_assert_eq!(nu, counters.bv_updates);
        // C_V: traversal with everything already fitted.
        let t = Instant::now();
        let mut nv = 0;
        for &(i, j) in pairs {
            let (a, b) = two_mut(hs, i, j);
            let c = a.broad_phase(b, &mut ws, par)?.counters;
            debug_assert_eq!(c.bv_updates, 0);
            nv += c.bv_tests;
        }
        let tv = t.elapsed().as_nanos() as f64;
        debug_assert_eq!(nv, counters.bv_tests);
        // C_P: exact tests of the recorded leaf pairs.
        let t = Instant::now();
        let mut np = 0;
        for (&(i, j), l) in pairs.iter().zip(&leaves) {
            np += hs[i].narrow_phase(&hs[j], l, par)?.counters.prim_tests;
        }
        let tp = t.elapsed().as_nanos() as f64;
        debug_assert_eq!(np, counters.prim_tests);
        for (k, t) in [tv, tp, tu, fixed].into_iter().enumerate() {
            times[k].push(t);
        }
    }
    Ok(FrameSamples {
        frame: frame_index,
        counters,
        times,
    })
}

/// The constants from the samples of all calibration frames: per constant,
/// `sum_f min_rep(t_f) / sum_f N_f`, and the spread of every single sample `t / N`.
pub(super) fn combine(frames: &[FrameSamples]) -> Costs {
    let mut pooled = [(0.0, 0u64); 4];
    let mut all: [Vec<f64>; 4] = Default::default();
    let mut per_frame = Vec::with_capacity(frames.len());
    for f in frames {
        let counts = f.counts();
        let mut best = [0.0; 4];
        for k in 0..4 {
            best[k] = least(&f.times[k]);
            pooled[k].0 += best[k];
            pooled[k].1 += counts[k];
            all[k].extend(f.times[k].iter().filter_map(|&t| per(t, counts[k])));
        }
        let c = |k: usize| per(best[k], counts[k]).unwrap_or(0.0);
        per_frame.push(FrameCosts {
            frame: f.frame,
            counters: f.counters,
            c_v_ns: c(0),
            c_p_ns: c(1),
            c_u_ns: c(2),
            fixed_ns: c(3),
        });
    }
    let constant = |k: usize| Constant {
        value: per(pooled[k].0, pooled[k].1).unwrap_or(0.0),
        spread: Spread::of(&all[k]),
    };
    Costs {
        c_v: constant(0),
        c_p: constant(1),
        c_u: constant(2),
        fixed_ns: constant(3),
        per_frame,
    }
}

/// The least of `xs` (0 when empty): on a shared machine, the least-disturbed repetition.
pub fn least(xs: &[f64]) -> f64 {
    xs.iter().copied().reduce(f64::min).unwrap_or(0.0)
}
