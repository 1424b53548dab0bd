//! `dhcd experiment [--frames N] [--levels N] [--methods dh,sphere,aabb] [--central C]
//! [--threads N] [--seed S] [--out DIR] [--mesh FILE] [--max-file-bytes N]`: the paper's
//! experiment and the cost-model report.

use std::path::PathBuf;
use std::time::Instant;

use dhcd::{CentralVertex, Method, Par};
use dhcd_cli::experiment::{self, output, Config, Phase};
use indicatif::{ProgressBar, ProgressStyle};

use super::input::InputArgs;

#[derive(clap::Args, Debug)]
pub struct ExperimentArgs {
    /// Time steps simulated and processed by every method.
    #[arg(long, default_value_t = 100, value_parser = clap::value_parser!(u64).range(1..=100_000))]
    frames: u64,
    /// Levels of the region trees (root = level 0).
    #[arg(long, default_value_t = dhcd::tree::PAPER_LEVELS)]
    levels: usize,
    /// Methods to compare, comma-separated.
    #[arg(long, value_delimiter = ',', default_values_t = Method::ALL, value_parser = super::method_parser(), ignore_case = true)]
    methods: Vec<Method>,
    /// The DH central vertex: rest-centroid (the paper's) or min-radius.
    #[arg(long, default_value_t = CentralVertex::RestCentroid, value_parser = super::central_parser())]
    central: CentralVertex,
    /// Threads of each query (1: sequential; 0: all cores; at most 1024, and never more than
    /// the machine has). Counters and contacts do not depend on it.
    #[arg(long, default_value_t = 1)]
    threads: usize,
    /// Seed of the scene.
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Output directory (report.json, report.md, SVG figures).
    #[arg(long, default_value = "results")]
    out: PathBuf,
    /// Use eight copies of this mesh (OBJ, STL or PLY) instead of the pawn.
    #[arg(long)]
    mesh: Option<PathBuf>,
    /// No progress bar.
    #[arg(long)]
    quiet: bool,
    #[command(flatten)]
    input: InputArgs,
}

pub fn run(args: ExperimentArgs) -> Result<(), String> {
    let start = Instant::now();
    // Bad options before any file is read.
    Par::threads(args.threads).map_err(|e| e.to_string())?;
    let mesh = match &args.mesh {
        Some(p) => Some(args.input.load(p).map_err(|e| e.to_string())?),
        None => None,
    };
    let config = Config {
        frames: args.frames as usize,
        levels: args.levels,
        methods: args.methods.clone(),
        central: args.central,
        threads: args.threads,
        seed: args.seed,
        mesh,
        ..Config::default()
    };
    let bar = if args.quiet {
        ProgressBar::hidden()
    } else {
        ProgressBar::new(0)
    };
    bar.set_style(
        ProgressStyle::with_template("{prefix:>9} [{bar:40}] {pos}/{len} {elapsed}")
            .unwrap_or_else(|_| ProgressStyle::default_bar())
            .progress_chars("=> "),
    );
    let mut phase = None;
    let report = experiment::run(&config, &mut |p: Phase, done, total| {
        if phase != Some(p) {
            phase = Some(p);
            bar.set_prefix(p.name());
            bar.set_length(total as u64);
        }
        bar.set_position(done as u64);
    })
    .map_err(|e| e.to_string());
    bar.finish_and_clear();
    let report = report?;
    output::write_all(&report, &args.out).map_err(|e| e.to_string())?;
    let s = &report.scene;
    let text = format!(
        "{} objects x {} triangles, {} frames, {} levels, DH central vertex {}, {} thread(s), seed {}\n{}\
         contacts identical across methods at every step; report in {} ({:.1} s)\n",
        s.objects,
        s.triangles_per_object,
        s.frames,
        s.levels,
        s.central,
        s.threads,
        s.seed,
        output::summary_table(&report),
        args.out.display(),
        start.elapsed().as_secs_f64()
    );
    super::emit(&text).map_err(|e| e.to_string())
}
