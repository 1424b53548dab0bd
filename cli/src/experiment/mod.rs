//! The paper's experiment: deformable objects pushed into each other, simulated once, then
//! every hierarchy method processes the identical frames, with counted work, measured time, and
//! the cost model `T = N_V*C_V + N_P*C_P + N_U*C_U` calibrated on this machine.
//!
//! Phases of [`run`]:
//!
//! 1. **Simulate** ([`Phase::Simulate`]): the scene ([`pawn_scene`] or [`scene_with_mesh`])
//!    advances `frames - 1` times; each frame's contacts (all object pairs, DH hierarchies)
//!    feed the next [`Simulation::step`]. All frames' positions are kept.
//! 2. **Measure** ([`Phase::Measure`]): per step, per method, `update_positions` on every
//!    object (update time), then every object pair (query time, the lazy refit happens
//!    inside). Each step is replayed `timing_reps` times (a replay redoes the whole update and
//!    refit) and the least time kept (the machine is shared: the least-disturbed replay); the
//!    method order rotates per step so that no method always runs on caches warmed by
//!    another. Contacts must be identical across methods (and equal
//!    to the simulation's), else [`ExperimentError::ContactMismatch`].
//! 3. **Calibrate** (module [`cost`]): `C_V`, `C_P`, `C_U` and the fixed position-copy cost
//!    per method, from the real kernels on frames spread over the run, each calibrated right
//!    after it is measured (same machine load).
//!
//! When DH is measured, the measure phase also replays the frames for the **refit study**
//! ([`RefitStudy`]): DH with every radius refitted eagerly, exactly and as the bottom-up
//! bound `r_p = max_c(|C_p - C_c| + r_c)`, the refit timed apart from the query, so the
//! report weighs the cheaper refit against the work the looser radii add (`N_V`, `N_P`).
//!
//! Results do not depend on the thread count (counters and contacts; times do).

pub mod cost;
pub mod output;

use std::sync::Arc;
use std::time::Instant;

use crate::sim::{pawn_scene, scene_with_mesh, ObjectContact, SimConfig, SimError, Simulation};
use dhcd::bv::Method;
use dhcd::calibration::Calibration;
use dhcd::error::Error;
use dhcd::tree::{RegionTree, TreeShape, PAPER_LEVELS};
use dhcd::AnyHierarchy;
use dhcd::Counters;
use dhcd::Mesh;
use dhcd::Par;
use dhcd::Workspace;
use dhcd::{CentralVertex, Options, Refit};

pub use cost::{Constant, Costs, Spread};

/// What can stop the experiment.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum ExperimentError {
    #[error(transparent)]
    Dhcd(#[from] Error),
    #[error(transparent)]
    Sim(#[from] SimError),
    /// A count of the [`Config`] that must be at least 1 (frames, threads, repetitions).
    #[error("{0} must be at least 1")]
    ZeroCount(&'static str),
    #[error("at least one method is needed")]
    NoMethods,
    #[error("method {0} is listed twice")]
    DuplicateMethod(Method),
    /// Two methods found different contacts on the same frames: impossible for exact
    /// conservative hierarchies, so a bug in dhcd.
    #[error(
        "contacts differ at step {step}, objects {object_a}-{object_b}: {method_a} found {count_a} triangle pairs, {method_b} found {count_b}"
    )]
    ContactMismatch {
        step: usize,
        object_a: usize,
        object_b: usize,
        method_a: &'static str,
        count_a: usize,
        method_b: &'static str,
        count_b: usize,
    },
}

/// Parameters of [`run`].
#[derive(Clone, Debug)]
pub struct Config {
    /// Time steps (frames) processed by every method; frame 0 is the initial scene.
    pub frames: usize,
    /// Levels of the region trees (the paper: 5).
    pub levels: usize,
    /// Methods to measure, in report order (no duplicates).
    pub methods: Vec<Method>,
    /// Threads of each query, as [`Par::threads`] takes them: 1 sequential, 0 all cores,
    /// `n` at most the machine's threads; above [`dhcd::Par::MAX_THREADS`] an error.
    pub threads: usize,
    /// Seed of the scene (object turns, wobble phases).
    pub seed: u64,
    /// The object mesh (eight copies); `None`: the built-in pawn.
    pub mesh: Option<Mesh>,
    /// The DH central vertex (the paper's: closest to the rest centroid).
    pub central: CentralVertex,
    /// Simulator parameters (its `seed` is replaced by [`Config::seed`]).
    pub sim: SimConfig,
    /// Replays of every measured step; the least time is kept.
    pub timing_reps: usize,
    /// Calibration frames, spread evenly over the run.
    pub calibration_frames: usize,
    /// Repetitions of each calibration measurement.
    pub calibration_reps: usize,
}

impl Default for Config {
    fn default() -> Self {
        Self {
            frames: 100,
            levels: PAPER_LEVELS,
            methods: Method::ALL.to_vec(),
            threads: 1,
            seed: 1,
            mesh: None,
            central: CentralVertex::RestCentroid,
            sim: SimConfig::default(),
            timing_reps: 5,
            calibration_frames: 10,
            calibration_reps: 7,
        }
    }
}

impl Config {
    /// The hierarchy options of every measured hierarchy, refitted as `refit` says.
    fn options(&self, refit: Refit) -> Options {
        Options {
            refit,
            central: self.central,
            ..Options::paper()
        }
    }

    /// What the measure phase replays: every method with lazy refit (calibrated, in the
    /// report's per-method tables), then, when DH is among them, the refit study's eager
    /// DH variants.
    fn variants(&self) -> Vec<(Method, Refit)> {
        let mut v: Vec<(Method, Refit)> = self.methods.iter().map(|&m| (m, Refit::Lazy)).collect();
        if self.methods.contains(&Method::Dh) {
            v.extend(RefitStudy::REFITS.map(|r| (Method::Dh, r)));
        }
        v
    }

    /// The parallelism of the queries (checked by [`Par::threads`]).
    pub fn par(&self) -> Result<Par, Error> {
        Par::threads(self.threads)
    }

    fn check(&self) -> Result<(), ExperimentError> {
        // Threads: 0 is all cores; `Par::threads` checks the range.
        let counts = [
            ("frames", self.frames),
            ("timing_reps", self.timing_reps),
            ("calibration_reps", self.calibration_reps),
            ("calibration_frames", self.calibration_frames),
        ];
        if let Some((name, _)) = counts.into_iter().find(|&(_, n)| n == 0) {
            return Err(ExperimentError::ZeroCount(name));
        }
        self.par()?;
        if self.methods.is_empty() {
            return Err(ExperimentError::NoMethods);
        }
        for (k, &m) in self.methods.iter().enumerate() {
            if self.methods[..k].contains(&m) {
                return Err(ExperimentError::DuplicateMethod(m));
            }
        }
        Ok(())
    }
}

/// The phases of [`run`], for progress reports.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[non_exhaustive]
pub enum Phase {
    Simulate,
    /// Measurement, with the calibration interleaved.
    Measure,
}

impl Phase {
    pub fn name(self) -> &'static str {
        match self {
            Phase::Simulate => "simulate",
            Phase::Measure => "measure",
        }
    }
}

/// The scene as run.
#[derive(Clone, Debug, PartialEq)]
pub struct SceneInfo {
    /// `"pawn"` or the user mesh's description.
    pub mesh: String,
    pub objects: usize,
    /// Triangles of all objects.
    pub triangles: usize,
    /// Vertices of all objects.
    pub vertices: usize,
    pub triangles_per_object: usize,
    pub vertices_per_object: usize,
    /// Nodes of one object's region tree (the same for the three methods).
    pub nodes_per_hierarchy: usize,
    pub frames: usize,
    pub levels: usize,
    /// The DH central vertex.
    pub central: CentralVertex,
    /// Threads the queries actually ran on.
    pub threads: usize,
    pub seed: u64,
    /// Object pairs queried per step.
    pub object_pairs: usize,
}

/// One step of one method.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Step {
    /// `N_V`, `N_P`, `N_U`, contacts, summed over all object pairs.
    pub counters: Counters,
    /// `update_positions` of every object (least over replays).
    pub update_ns: f64,
    /// An eager refit of every object between update and query (least over replays; the
    /// refit study's variants), 0 with lazy refit (which happens inside the query).
    pub refit_ns: f64,
    /// All object-pair queries, lazy refit included (least over replays).
    pub query_ns: f64,
    /// Cost model `N_V*C_V + N_P*C_P + N_U*C_U` (calibrated constants).
    pub predicted_ns: f64,
}

impl Step {
    /// Measured step time: update + refit + query.
    pub fn time_ns(&self) -> f64 {
        self.update_ns + self.refit_ns + self.query_ns
    }
}

/// Everything measured for one method.
#[derive(Clone, Debug, PartialEq)]
pub struct MethodReport {
    pub method: Method,
    pub bytes_per_node: usize,
    /// Node records of one object's hierarchy.
    pub bytes_per_hierarchy: usize,
    /// Node records of all objects' hierarchies.
    pub bytes_all_hierarchies: usize,
    pub costs: Costs,
    pub steps: Vec<Step>,
}

/// Sums over the steps of one measured variant: a method ([`MethodReport`]) or a row of the
/// refit study ([`RefitRow`]).
pub trait StepTotals {
    fn steps(&self) -> &[Step];

    fn totals(&self) -> Counters {
        self.steps().iter().map(|s| s.counters).sum()
    }
    fn total_time_ns(&self) -> f64 {
        self.steps().iter().map(Step::time_ns).sum()
    }
    fn total_update_ns(&self) -> f64 {
        self.steps().iter().map(|s| s.update_ns).sum()
    }
    fn total_refit_ns(&self) -> f64 {
        self.steps().iter().map(|s| s.refit_ns).sum()
    }
    fn total_query_ns(&self) -> f64 {
        self.steps().iter().map(|s| s.query_ns).sum()
    }
}

impl StepTotals for MethodReport {
    fn steps(&self) -> &[Step] {
        &self.steps
    }
}

impl StepTotals for RefitRow {
    fn steps(&self) -> &[Step] {
        &self.steps
    }
}

impl MethodReport {
    /// Sum of the three-term model over all steps.
    pub fn total_predicted_ns(&self) -> f64 {
        self.steps.iter().map(|s| s.predicted_ns).sum()
    }
    /// The fixed cost of one step (calibrated position copy of every object), not in the
    /// paper's model.
    pub fn fixed_ns(&self) -> f64 {
        self.costs.fixed_ns.value
    }
    /// Model plus the fixed term, summed over all steps.
    pub fn total_predicted_with_fixed_ns(&self) -> f64 {
        self.total_predicted_ns() + self.fixed_ns() * self.steps.len() as f64
    }
    /// `(predicted - measured) / measured` over the whole run, three-term model vs update + query.
    pub fn model_error(&self) -> f64 {
        rel_err(self.total_predicted_ns(), self.total_time_ns())
    }
    /// Same, with the fixed term added to the prediction.
    pub fn model_with_fixed_error(&self) -> f64 {
        rel_err(self.total_predicted_with_fixed_ns(), self.total_time_ns())
    }
    /// Three-term model vs query time alone (where the lazy refit happens).
    pub fn model_vs_query_error(&self) -> f64 {
        rel_err(self.total_predicted_ns(), self.total_query_ns())
    }
}

/// The DH refit study: on the frames the methods replay, DH with every radius refitted
/// eagerly (all nodes, before the query, timed apart), exactly and as the bottom-up bound.
/// The default (exact, lazy) is the DH row of [`Report::methods`].
#[derive(Clone, Debug, PartialEq)]
pub struct RefitStudy {
    /// One row per mode of [`RefitStudy::REFITS`], in that order.
    pub rows: Vec<RefitRow>,
    /// Bottom-up radius / exact radius over the internal nodes of every object at the last
    /// step (leaves are fitted exactly by both).
    pub looseness: Looseness,
}

impl RefitStudy {
    /// The eager modes compared with the default lazy exact refit.
    pub const REFITS: [Refit; 2] = [Refit::Eager, Refit::EagerBottomUp];
}

/// One eager refit mode of the study.
#[derive(Clone, Debug, PartialEq)]
pub struct RefitRow {
    pub refit: Refit,
    pub steps: Vec<Step>,
}

/// How much larger the bottom-up radii are than the exact ones (ratios, deterministic).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Looseness {
    /// Internal nodes compared (all objects).
    pub nodes: usize,
    pub mean: f64,
    pub max: f64,
    /// Mean over the objects' roots (when they are internal).
    pub root_mean: f64,
}

/// Relative error `(predicted - measured) / measured` (0 when nothing was measured).
pub fn rel_err(predicted: f64, measured: f64) -> f64 {
    if measured > 0.0 {
        (predicted - measured) / measured
    } else {
        0.0
    }
}

/// The scene at one step, for the picture (the paper's Figure 1).
#[derive(Clone, Debug, PartialEq)]
pub struct Snapshot {
    pub step: usize,
    pub positions: Vec<Vec<[f32; 3]>>,
    pub triangles: Vec<Vec<[u32; 3]>>,
    /// Per object, the triangles in contact with another object (sorted, unique).
    pub contact_triangles: Vec<Vec<u32>>,
}

/// The result of [`run`].
#[derive(Clone, Debug, PartialEq)]
pub struct Report {
    pub scene: SceneInfo,
    pub methods: Vec<MethodReport>,
    /// The DH refit study (when DH is measured).
    pub refit_study: Option<RefitStudy>,
    /// The step with the most contacts (the first one if there are none).
    pub snapshot: Snapshot,
    /// Wall time of the phases (seconds; calibration is interleaved with measurement).
    pub simulate_s: f64,
    pub measure_s: f64,
    pub calibrate_s: f64,
}

impl Report {
    pub fn method(&self, m: Method) -> Option<&MethodReport> {
        self.methods.iter().find(|r| r.method == m)
    }
}

/// Frames simulated once: positions per frame per object, and each frame's contacts per
/// object pair (DH).
struct Frames {
    positions: Vec<Vec<Vec<[f32; 3]>>>,
    contacts: Vec<Vec<Vec<[u32; 2]>>>,
}

/// The object pairs `(i, j)`, `i < j`, in order.
fn object_pairs(n: usize) -> Vec<(usize, usize)> {
    (0..n)
        .flat_map(|i| (i + 1..n).map(move |j| (i, j)))
        .collect()
}

/// Two distinct elements of a slice, mutably.
pub(crate) fn two_mut<T>(v: &mut [T], i: usize, j: usize) -> (&mut T, &mut T) {
    assert!(i < j);
    let (lo, hi) = v.split_at_mut(j);
    (&mut lo[i], &mut hi[0])
}

/// Runs the experiment; `progress(phase, done, total)` is called as work completes.
pub fn run(
    config: &Config,
    progress: &mut dyn FnMut(Phase, usize, usize),
) -> Result<Report, ExperimentError> {
    config.check()?;
    let sim_config = SimConfig {
        seed: config.seed,
        ..config.sim.clone()
    };
    let (mesh_name, sim) = match &config.mesh {
        Some(m) => (
            format!(
                "user mesh ({} triangles, {} vertices)",
                m.triangle_count(),
                m.vertex_count()
            ),
            scene_with_mesh(m.clone(), &sim_config)?,
        ),
        None => ("pawn".to_string(), pawn_scene(&sim_config)?),
    };
    let n = sim.object_count();
    let meshes: Vec<Mesh> = (0..n)
        .map(|o| Mesh::new(sim.positions(o).to_vec(), sim.triangles(o).to_vec()))
        .collect::<Result<_, _>>()?;
    let trees: Vec<Arc<RegionTree>> = meshes
        .iter()
        .map(|m| RegionTree::build(m, TreeShape::Levels(config.levels)).map(Arc::new))
        .collect::<Result<_, _>>()?;
    let pairs = object_pairs(n);

    let t = Instant::now();
    let frames = simulate(sim, &meshes, &trees, &pairs, config, progress)?;
    let simulate_s = t.elapsed().as_secs_f64();

    // Every variant is built lazy: the study's eager refits are called (and timed) apart.
    let variants = config.variants();
    let mut hierarchies: Vec<Vec<AnyHierarchy>> = variants
        .iter()
        .map(|&(m, _)| {
            meshes
                .iter()
                .zip(&trees)
                .map(|(mesh, tree)| {
                    AnyHierarchy::with_tree(m, Arc::clone(tree), mesh, config.options(Refit::Lazy))
                })
                .collect::<Result<Vec<_>, _>>()
        })
        .collect::<Result<_, _>>()?;

    let t = Instant::now();
    let calib_frames = cost::calibration_frames(config.frames, config.calibration_frames);
    let (mut steps, samples, calibrate_s) = measure(
        &mut hierarchies,
        &variants,
        &frames,
        &pairs,
        &calib_frames,
        config,
        progress,
    )?;
    let measure_s = t.elapsed().as_secs_f64() - calibrate_s;

    let study_steps = steps.split_off(config.methods.len());
    let refit_study = (!study_steps.is_empty()).then(|| RefitStudy {
        looseness: looseness(&hierarchies[config.methods.len()..]),
        rows: RefitStudy::REFITS
            .into_iter()
            .zip(study_steps)
            .map(|(refit, steps)| RefitRow { refit, steps })
            .collect(),
    });
    let mut methods = Vec::with_capacity(config.methods.len());
    for (k, ((hs, mut steps), samples)) in hierarchies.iter().zip(steps).zip(samples).enumerate() {
        let costs = cost::combine(&samples);
        for s in &mut steps {
            s.predicted_ns = costs.predict(&s.counters);
        }
        methods.push(MethodReport {
            method: config.methods[k],
            bytes_per_node: hs[0].bytes_per_node(),
            bytes_per_hierarchy: hs[0].bv_bytes(),
            bytes_all_hierarchies: hs.iter().map(AnyHierarchy::bv_bytes).sum(),
            costs,
            steps,
        });
    }

    let snapshot = snapshot(&frames, &meshes, &pairs);
    let scene = SceneInfo {
        mesh: mesh_name,
        objects: n,
        triangles: meshes.iter().map(Mesh::triangle_count).sum(),
        vertices: meshes.iter().map(Mesh::vertex_count).sum(),
        triangles_per_object: meshes[0].triangle_count(),
        vertices_per_object: meshes[0].vertex_count(),
        nodes_per_hierarchy: trees[0].node_count(),
        frames: config.frames,
        levels: config.levels,
        central: config.central,
        threads: config.par()?.thread_count(),
        seed: config.seed,
        object_pairs: pairs.len(),
    };
    Ok(Report {
        scene,
        methods,
        refit_study,
        snapshot,
        simulate_s,
        measure_s,
        calibrate_s,
    })
}

/// Phase 1: the frames, with DH contacts feeding the simulation.
fn simulate(
    mut sim: Simulation,
    meshes: &[Mesh],
    trees: &[Arc<RegionTree>],
    pairs: &[(usize, usize)],
    config: &Config,
    progress: &mut dyn FnMut(Phase, usize, usize),
) -> Result<Frames, ExperimentError> {
    let par = config.par()?;
    let mut dh: Vec<AnyHierarchy> = meshes
        .iter()
        .zip(trees)
        .map(|(m, t)| {
            AnyHierarchy::with_tree(Method::Dh, Arc::clone(t), m, config.options(Refit::Lazy))
        })
        .collect::<Result<_, _>>()?;
    let mut ws = Workspace::default();
    let mut frames = Frames {
        positions: Vec::with_capacity(config.frames),
        contacts: Vec::with_capacity(config.frames),
    };
    for f in 0..config.frames {
        progress(Phase::Simulate, f, config.frames);
        let positions: Vec<Vec<[f32; 3]>> =
            (0..dh.len()).map(|o| sim.positions(o).to_vec()).collect();
        for (h, p) in dh.iter_mut().zip(&positions) {
            h.update_positions(p)?;
        }
        let mut per_pair = Vec::with_capacity(pairs.len());
        let mut contacts = Vec::new();
        for &(i, j) in pairs {
            let (a, b) = two_mut(&mut dh, i, j);
            let c = a.collide(b, &mut ws, par)?;
            contacts.extend(c.pairs.iter().map(|&[ta, tb]| ObjectContact {
                object_a: i as u32,
                triangle_a: ta,
                object_b: j as u32,
                triangle_b: tb,
            }));
            per_pair.push(c.pairs);
        }
        frames.positions.push(positions);
        frames.contacts.push(per_pair);
        if f + 1 < config.frames {
            sim.step(&contacts);
        }
    }
    progress(Phase::Simulate, config.frames, config.frames);
    Ok(frames)
}

/// Per variant: the measured steps (prediction still 0); per method: the calibration
/// samples; and the seconds spent calibrating.
type Measured = (Vec<Vec<Step>>, Vec<Vec<cost::FrameSamples>>, f64);

/// Phase 2: every variant (`(method, refit)`, [`Config::variants`]; `hierarchies` holds
/// one list per variant) on every frame, calibrating the lazy ones (the methods) at the
/// calibration frames.
fn measure(
    hierarchies: &mut [Vec<AnyHierarchy>],
    variants: &[(Method, Refit)],
    frames: &Frames,
    pairs: &[(usize, usize)],
    calib_frames: &[usize],
    config: &Config,
    progress: &mut dyn FnMut(Phase, usize, usize),
) -> Result<Measured, ExperimentError> {
    let par = config.par()?;
    let methods = &config.methods;
    let mut ws = Workspace::default();
    let mut steps: Vec<Vec<Step>> = vec![Vec::with_capacity(config.frames); variants.len()];
    let mut samples: Vec<Vec<cost::FrameSamples>> = vec![Vec::new(); methods.len()];
    let mut calibrate_s = 0.0;
    let mut update_t = vec![0.0; config.timing_reps];
    let mut refit_t = vec![0.0; config.timing_reps];
    let mut query_t = vec![0.0; config.timing_reps];
    for (s, positions) in frames.positions.iter().enumerate() {
        progress(Phase::Measure, s, config.frames);
        for r in 0..variants.len() {
            let k = (r + s) % variants.len();
            let (method, refit) = variants[k];
            let hs = &mut hierarchies[k];
            let mut counters = Counters::default();
            for rep in 0..config.timing_reps {
                let t0 = Instant::now();
                for (h, p) in hs.iter_mut().zip(positions) {
                    h.update_positions(p)?;
                }
                let t1 = Instant::now();
                // The study's eager refit, timed apart (lazy: none, inside the query).
                let mut sum = Counters::default();
                let t1r = match refit {
                    Refit::Eager => {
                        sum.bv_updates = hs.iter_mut().map(AnyHierarchy::refit_all).sum();
                        Instant::now()
                    }
                    Refit::EagerBottomUp => {
                        sum.bv_updates = hs.iter_mut().map(AnyHierarchy::refit_bottom_up).sum();
                        Instant::now()
                    }
                    _ => t1,
                };
                for (q, &(i, j)) in pairs.iter().enumerate() {
                    let (a, b) = two_mut(hs, i, j);
                    let c = a.collide(b, &mut ws, par)?;
                    sum += c.counters;
                    if rep == 0 && c.pairs != frames.contacts[s][q] {
                        return Err(ExperimentError::ContactMismatch {
                            step: s,
                            object_a: i,
                            object_b: j,
                            method_a: Method::Dh.name(),
                            count_a: frames.contacts[s][q].len(),
                            method_b: method.name(),
                            count_b: c.pairs.len(),
                        });
                    }
                }
                let t2 = Instant::now();
                update_t[rep] = (t1 - t0).as_nanos() as f64;
                refit_t[rep] = (t1r - t1).as_nanos() as f64;
                query_t[rep] = (t2 - t1r).as_nanos() as f64;
                debug_assert!(
                    rep == 0 || sum == counters,
                    "replayed step counted differently"
                );
                counters = sum;
            }
            steps[k].push(Step {
                counters,
                update_ns: cost::least(&update_t),
                refit_ns: cost::least(&refit_t),
                query_ns: cost::least(&query_t),
                predicted_ns: 0.0,
            });
            if k < methods.len() && calib_frames.contains(&s) {
                let t = Instant::now();
                samples[k].push(cost::calibrate_frame(
                    hs,
                    positions,
                    s,
                    pairs,
                    config.calibration_reps,
                    par,
                )?);
                calibrate_s += t.elapsed().as_secs_f64();
            }
        }
    }
    progress(Phase::Measure, config.frames, config.frames);
    Ok((steps, samples, calibrate_s))
}

/// Bottom-up over exact radii of the internal nodes, from the study's hierarchies (exact
/// first, then bottom-up; both fitted to the last frame by the last replay).
fn looseness(study: &[Vec<AnyHierarchy>]) -> Looseness {
    let [exact, bottom_up] = study else {
        return Looseness::default();
    };
    let mut l = Looseness::default();
    let (mut sum, mut roots, mut root_count) = (0.0, 0.0, 0);
    for (e, b) in exact.iter().zip(bottom_up) {
        let (AnyHierarchy::Dh(e), AnyHierarchy::Dh(b)) = (e, b) else {
            continue;
        };
        for n in (0..e.node_count()).filter(|&n| !e.tree().is_leaf(n)) {
            let (Some(re), Some(rb)) = (e.record(n), b.record(n)) else {
                continue;
            };
            let ratio = rb.radius as f64 / re.radius as f64;
            sum += ratio;
            l.max = l.max.max(ratio);
            l.nodes += 1;
            if n == 0 {
                roots += ratio;
                root_count += 1;
            }
        }
    }
    if l.nodes > 0 {
        l.mean = sum / l.nodes as f64;
        l.root_mean = roots / root_count as f64;
    }
    l
}

/// The step with the most contacts, with its contact triangles per object.
fn snapshot(frames: &Frames, meshes: &[Mesh], pairs: &[(usize, usize)]) -> Snapshot {
    let count = |s: usize| frames.contacts[s].iter().map(Vec::len).sum::<usize>();
    let step = (0..frames.positions.len())
        .max_by_key(|&s| (count(s), std::cmp::Reverse(s)))
        .unwrap_or(0);
    let mut contact_triangles = vec![Vec::new(); meshes.len()];
    for (q, &(i, j)) in pairs.iter().enumerate() {
        for &[ta, tb] in &frames.contacts[step][q] {
            contact_triangles[i].push(ta);
            contact_triangles[j].push(tb);
        }
    }
    for c in &mut contact_triangles {
        c.sort_unstable();
        c.dedup();
    }
    Snapshot {
        step,
        positions: frames.positions[step].clone(),
        triangles: meshes.iter().map(|m| m.triangles().to_vec()).collect(),
        contact_triangles,
    }
}
