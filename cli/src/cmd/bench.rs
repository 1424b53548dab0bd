//! `dhcd bench self FRAME...`, `dhcd bench collide --a FRAME... --b FRAME...`,
//! `dhcd bench proximity FRAME... (--distance D | --relative R)` and
//! `dhcd bench ccd FRAME...`: the microbenchmark users run on their own meshes. Builds once
//! on the first frame, then cycles `update_positions` through the frames, timing each step
//! (update + query; for CCD, the query over the step from each frame to the next); reports
//! the build time, the median and least step time over all steps and per frame (frames of
//! different work make the overall median fall between them), and each frame's contacts and
//! counters.

use dhcd::calibration::Calibration;
use std::path::PathBuf;
use std::time::Instant;

use dhcd::error::escaped_path;
use dhcd::{
    AnyHierarchy, CcdMode, CcdQuery, CentralVertex, Counters, Mesh, Method, Motion, Options, Par,
    Workspace,
};
use serde_json::json;

use super::ccd::{ccd_query, f64_positions};
use super::input::{update, InputArgs};

/// Most passes over the frames (`--repeat`): a typo must not start a day-long run.
const MAX_REPEAT: usize = 10_000;

#[derive(clap::Args, Debug)]
#[command(subcommand_required = true, arg_required_else_help = false)]
pub struct BenchArgs {
    #[command(subcommand)]
    what: What,
}

#[derive(clap::Subcommand, Debug)]
enum What {
    /// Self-collision of one deforming mesh; FRAME... are its poses (the same triangles,
    /// new vertex positions).
    #[command(name = "self")]
    SelfCollide {
        /// The poses (OBJ, STL or PLY), in order.
        #[arg(required = true)]
        frames: Vec<PathBuf>,
        #[command(flatten)]
        opts: Opts,
    },
    /// Self-proximity of one deforming mesh: every vertex-triangle and edge-edge pair within
    /// a distance (`--distance`, or `--relative` times the first frame's bounding-box
    /// diagonal); FRAME... are its poses.
    #[command(group(clap::ArgGroup::new("how_far").required(true).args(["distance", "relative"])))]
    Proximity {
        /// The poses (OBJ, STL or PLY), in order.
        #[arg(required = true)]
        frames: Vec<PathBuf>,
        /// The distance.
        #[arg(long, allow_hyphen_values = true)]
        distance: Option<f64>,
        /// The distance as a fraction of the first frame's bounding-box diagonal (IPC's
        /// default contact distance is 1e-3).
        #[arg(long, allow_hyphen_values = true)]
        relative: Option<f64>,
        #[command(flatten)]
        opts: Opts,
    },
    /// Continuous collision detection of one deforming mesh: step k goes from frame k to
    /// frame k + 1 (coordinates read in f64; at least two frames).
    Ccd {
        /// The poses (OBJ, STL or PLY), in order.
        #[arg(required = true, num_args = 2..)]
        frames: Vec<PathBuf>,
        /// Pairs collide when they come within this distance.
        #[arg(long, default_value_t = 0.0, allow_hyphen_values = true)]
        min_distance: f64,
        /// Only the earliest time of impact of each step.
        #[arg(long)]
        earliest: bool,
        #[command(flatten)]
        opts: Opts,
    },
    /// Contacts between two deforming meshes: the i-th step uses `--a` frame i and `--b`
    /// frame i (each list cycles).
    Collide {
        /// Poses of the first mesh.
        #[arg(long, num_args = 1.., required = true)]
        a: Vec<PathBuf>,
        /// Poses of the second mesh.
        #[arg(long, num_args = 1.., required = true)]
        b: Vec<PathBuf>,
        #[command(flatten)]
        opts: Opts,
    },
}

#[derive(clap::Args, Debug)]
struct Opts {
    /// Bounding-volume hierarchy: dh, sphere, aabb, or all (one result each).
    #[arg(long, default_value = "dh")]
    method: String,
    /// A fixed depth for the region tree (the paper uses 5). Default: an adaptive tree.
    #[arg(long)]
    levels: Option<usize>,
    /// Largest number of triangles per leaf of the adaptive tree.
    #[arg(long, default_value_t = dhcd::tree::DEFAULT_LEAF_SIZE)]
    leaf_size: usize,
    /// The DH central vertex: rest-centroid (the paper's) or min-radius. Other methods
    /// ignore it.
    #[arg(long, default_value_t = CentralVertex::RestCentroid, value_parser = super::central_parser())]
    central: CentralVertex,
    /// Threads of each query (1: the calling thread). Results do not depend on it.
    #[arg(long, default_value_t = 1)]
    threads: usize,
    /// Time the broad phase alone: update, lazy refit and traversal down to the overlapping
    /// leaf pairs, no triangle tested (contacts are 0; the triangle pairs counted are those
    /// the narrow phase would test). A full step's time minus this one is the narrow phase's.
    #[arg(long)]
    broad_only: bool,
    /// Passes over the frames (each pass times one step per frame).
    #[arg(long, default_value_t = 5)]
    repeat: usize,
    /// Print JSON (an object, or an array of objects with `--method all`).
    #[arg(long)]
    json: bool,
    #[command(flatten)]
    input: InputArgs,
}

/// One method's measurement.
struct Run {
    method: Method,
    build_ms: f64,
    /// Pass by pass, one step per frame: frame `k`'s steps are `k, k + frames, ...`.
    steps_ms: Vec<f64>,
    /// Per frame: contacts and counters (of the last pass; every pass gives the same).
    frames: Vec<Counters>,
}

pub fn run(args: BenchArgs) -> Result<(), String> {
    let opts = match &args.what {
        What::SelfCollide { opts, .. }
        | What::Collide { opts, .. }
        | What::Proximity { opts, .. }
        | What::Ccd { opts, .. } => opts,
    };
    let methods: Vec<Method> = if opts.method.eq_ignore_ascii_case("all") {
        Method::ALL.to_vec()
    } else {
        vec![opts.method.parse::<Method>().map_err(|e| e.to_string())?]
    };
    if opts.repeat == 0 || opts.repeat > MAX_REPEAT {
        return Err(format!(
            "--repeat must be between 1 and {MAX_REPEAT}, got {}",
            opts.repeat
        ));
    }
    let par = Par::threads(opts.threads).map_err(|e| e.to_string())?;
    let threads = par.thread_count();
    // Options are checked above, before any file is read.
    if let What::Proximity {
        distance, relative, ..
    } = &args.what
    {
        let (name, x) = match (distance, relative) {
            (Some(d), _) => ("--distance", *d),
            (_, Some(r)) => ("--relative", *r),
            _ => unreachable!("clap requires one"),
        };
        if !(x.is_finite() && x >= 0.0) {
            return Err(format!("{name} must be a finite number >= 0, got {x:?}"));
        }
    }
    // CCD: its options, f64 input, and no broad-phase-only mode.
    let ccd = match &args.what {
        What::Ccd {
            min_distance,
            earliest,
            ..
        } => {
            if opts.broad_only {
                return Err("--broad-only is not available for ccd".into());
            }
            let q = ccd_query(*min_distance, *earliest).map_err(|e| e.to_string())?;
            Some(q)
        }
        _ => None,
    };
    let input = match ccd {
        Some(_) => opts.input.f64_only("dhcd bench ccd")?,
        None => opts.input.clone(),
    };
    let (a, b) = match &args.what {
        What::SelfCollide { frames, .. }
        | What::Proximity { frames, .. }
        | What::Ccd { frames, .. } => (load_frames(&input, frames)?, None),
        What::Collide { a, b, .. } => (load_frames(&input, a)?, Some(load_frames(&input, b)?)),
    };
    // The proximity distance, in the units of the mesh.
    let distance = match &args.what {
        What::Proximity {
            distance: Some(d), ..
        } => Some(*d),
        What::Proximity {
            relative: Some(r), ..
        } => {
            let diag = diagonal(&a[0]);
            let d = r * diag;
            if !d.is_finite() {
                return Err(format!(
                    "--relative {r:?} times the first frame's bounding-box diagonal {diag:?} \
                     overflows to {d:?}; give a smaller --relative or --distance"
                ));
            }
            Some(d)
        }
        _ => None,
    };
    let options = Options {
        levels: opts.levels,
        leaf_size: opts.leaf_size,
        central: opts.central,
        ..Options::default()
    };
    let steps = match ccd {
        Some(_) => a.len() - 1,
        None => a.len().max(b.as_ref().map_or(0, Vec::len)),
    };
    let mut runs = Vec::new();
    for &method in &methods {
        let t = Instant::now();
        let mut ha = AnyHierarchy::new(method, &a[0], options).map_err(|e| e.to_string())?;
        let mut hb = match &b {
            Some(b) => Some(AnyHierarchy::new(method, &b[0], options).map_err(|e| e.to_string())?),
            None => None,
        };
        let build_ms = t.elapsed().as_secs_f64() * 1e3;
        let mut ws = Workspace::default();
        let mut steps_ms = Vec::with_capacity(opts.repeat * steps);
        let mut frames = vec![Counters::default(); steps];
        for _ in 0..opts.repeat {
            for (k, counters) in frames.iter_mut().enumerate() {
                let t = Instant::now();
                if let Some(q) = &ccd {
                    let motion = Motion::new(f64_positions(&a[k]), f64_positions(&a[k + 1]));
                    *counters = ha
                        .self_ccd(motion, q, &mut ws, par)
                        .map_err(|e| e.to_string())?
                        .counters;
                    steps_ms.push(t.elapsed().as_secs_f64() * 1e3);
                    continue;
                }
                update(&mut ha, &a[k % a.len()]).map_err(|e| e.to_string())?;
                *counters = match (&mut hb, &b) {
                    (Some(hb), Some(b)) => {
                        update(hb, &b[k % b.len()]).map_err(|e| e.to_string())?;
                        if opts.broad_only {
                            ha.broad_phase(hb, &mut ws, par).map(|b| b.counters)
                        } else {
                            ha.collide(hb, &mut ws, par).map(|c| c.counters)
                        }
                        .map_err(|e| e.to_string())?
                    }
                    _ if opts.broad_only => ha.self_broad_phase(&mut ws, par).counters,
                    _ => match distance {
                        Some(d) => {
                            ha.self_proximity(d, &mut ws, par)
                                .map_err(|e| e.to_string())?
                                .counters
                        }
                        None => ha.self_collide(&mut ws, par).counters,
                    },
                };
                steps_ms.push(t.elapsed().as_secs_f64() * 1e3);
            }
        }
        runs.push(Run {
            method,
            build_ms,
            steps_ms,
            frames,
        });
    }
    let out = if opts.json {
        let values: Vec<serde_json::Value> = runs
            .iter()
            .map(|r| to_json(r, threads, opts, &input, distance, ccd.as_ref()))
            .collect();
        let v = if methods.len() == 1 {
            values.into_iter().next().unwrap_or_default()
        } else {
            serde_json::Value::Array(values)
        };
        format!("{v}\n")
    } else {
        text(
            &runs,
            opts,
            threads,
            &a,
            b.as_deref(),
            distance,
            ccd.as_ref(),
        )
    };
    super::emit(&out).map_err(|e| e.to_string())
}

/// Loads the poses; every one must have the first one's triangles.
fn load_frames(input: &InputArgs, paths: &[PathBuf]) -> Result<Vec<Mesh>, String> {
    let mut frames: Vec<Mesh> = Vec::new();
    for path in paths {
        let m = input.load(path).map_err(|e| e.to_string())?;
        if let Some(first) = frames.first() {
            if m.vertex_count() != first.vertex_count() || m.triangles() != first.triangles() {
                return Err(format!(
                    "{}: not a pose of {} (a frame must have the first frame's vertices and triangles)",
                    escaped_path(path),
                    escaped_path(&paths[0])
                ));
            }
        }
        frames.push(m);
    }
    Ok(frames)
}

/// The diagonal of the bounding box of `m`'s positions (exact values, `f64`).
fn diagonal(m: &Mesh) -> f64 {
    let p = m.to_f64_positions();
    let (mut lo, mut hi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
    for q in &p {
        for k in 0..3 {
            lo[k] = lo[k].min(q[k]);
            hi[k] = hi[k].max(q[k]);
        }
    }
    (0..3).map(|k| (hi[k] - lo[k]).powi(2)).sum::<f64>().sqrt()
}

/// Median and least of `xs` (non-empty).
fn median_min(xs: &[f64]) -> (f64, f64) {
    let mut s = xs.to_vec();
    s.sort_by(f64::total_cmp);
    (s[s.len() / 2], s[0])
}

impl Run {
    /// Median and least of frame `k`'s steps (one per pass).
    fn frame_median_min(&self, k: usize) -> (f64, f64) {
        let steps: Vec<f64> = self
            .steps_ms
            .iter()
            .skip(k)
            .step_by(self.frames.len())
            .copied()
            .collect();
        median_min(&steps)
    }
}

fn counters_json(c: &Counters) -> serde_json::Value {
    json!({
        "bv_tests": c.bv_tests,
        "prim_tests": c.prim_tests,
        "bv_updates": c.bv_updates,
        "contacts": c.contacts,
    })
}

/// `{"method", "precision", "threads", "broad_only", ("distance",) "build_ms", "step_ms":
/// {"median", "min"}, "frames": [{"contacts", "counters", "step_ms": {"median", "min"}}...]}`
/// (`distance` for proximity; its `contacts` are the pairs within it).
fn to_json(
    r: &Run,
    threads: usize,
    opts: &Opts,
    input: &InputArgs,
    distance: Option<f64>,
    ccd: Option<&CcdQuery>,
) -> serde_json::Value {
    let (median, min) = median_min(&r.steps_ms);
    let mut v = json!({
        "method": r.method.name(),
        "precision": input.precision().name(),
        "threads": threads,
        "broad_only": opts.broad_only,
        "build_ms": r.build_ms,
        "step_ms": { "median": median, "min": min },
        "frames": r.frames.iter().enumerate().map(|(k, c)| {
            let (median, min) = r.frame_median_min(k);
            json!({
                "contacts": c.contacts,
                "counters": counters_json(c),
                "step_ms": { "median": median, "min": min },
            })
        }).collect::<Vec<_>>(),
    });
    if let (Some(d), Some(o)) = (distance, v.as_object_mut()) {
        o.insert("distance".into(), d.into());
    }
    if let (Some(q), Some(o)) = (ccd, v.as_object_mut()) {
        o.insert("min_distance".into(), q.options.min_distance.into());
        o.insert("earliest".into(), (q.mode == CcdMode::Earliest).into());
    }
    v
}

fn text(
    runs: &[Run],
    opts: &Opts,
    threads: usize,
    a: &[Mesh],
    b: Option<&[Mesh]>,
    distance: Option<f64>,
    ccd: Option<&CcdQuery>,
) -> String {
    use std::fmt::Write;
    let mut s = String::new();
    let what = match (b, distance) {
        _ if ccd.is_some() => format!(
            "continuous collision detection{} of {} triangles (f64)",
            if ccd.is_some_and(|q| q.mode == CcdMode::Earliest) {
                " (earliest time)"
            } else {
                ""
            },
            a[0].triangle_count()
        ),
        (None, Some(d)) => format!(
            "self-proximity within {d} of {} triangles ({})",
            a[0].triangle_count(),
            opts.input.precision()
        ),
        (None, None) => format!(
            "self-collision of {} triangles ({})",
            a[0].triangle_count(),
            opts.input.precision()
        ),
        (Some(b), _) => format!(
            "{} against {} triangles ({})",
            a[0].triangle_count(),
            b[0].triangle_count(),
            opts.input.precision()
        ),
    };
    let _ = writeln!(
        s,
        "{what}{}, {} steps per pass, {} passes, {} thread(s)",
        if opts.broad_only {
            " (broad phase only)"
        } else {
            ""
        },
        runs.first().map_or(0, |r| r.frames.len()),
        opts.repeat,
        threads
    );
    for r in runs {
        let (median, min) = median_min(&r.steps_ms);
        let _ = writeln!(
            s,
            "{}: build {:.2} ms; step median {:.3} ms, min {:.3} ms",
            r.method, r.build_ms, median, min
        );
        for (k, c) in r.frames.iter().enumerate() {
            let (median, min) = r.frame_median_min(k);
            let _ = writeln!(
                s,
                "  step {k}: median {median:.3} ms, min {min:.3} ms; {} contacts; {} BV tests, \
                 {} triangle pairs, {} BV updates",
                c.contacts, c.bv_tests, c.prim_tests, c.bv_updates
            );
        }
    }
    s
}
