//! Command-line front end. Every failure is one line on stderr and a non-zero exit code.

mod bench;
mod ccd;
mod collide;
mod experiment;
mod input;
mod proximity;
mod query;
mod scene;
mod self_cmd;

use std::ffi::OsString;

use clap::{Parser, Subcommand};
use dhcd::error::escaped;

#[derive(Parser, Debug)]
#[command(
    name = "dhcd",
    version,
    about = "Collision detection between deformable triangle meshes (Distance Hierarchy, sphere and AABB hierarchies)",
    // `dhcd` alone is an error naming the missing subcommand, not the help text.
    subcommand_required = true,
    arg_required_else_help = false
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand, Debug)]
enum Command {
    /// Contacts (intersecting triangle pairs) between two meshes.
    Collide(collide::CollideArgs),
    /// Self-contacts of one mesh: intersecting triangle pairs sharing no vertex.
    #[command(name = "self")]
    SelfCollide(self_cmd::SelfArgs),
    /// Contacts between every pair of several meshes.
    Scene(scene::SceneArgs),
    /// Every vertex-triangle and edge-edge pair within a distance, in one mesh or between two.
    Proximity(proximity::ProximityArgs),
    /// Continuous collision detection over a step: every vertex-triangle and edge-edge pair
    /// of one mesh that touches while it moves from pose T0 to pose T1, with its time of
    /// impact (f64, exact).
    Ccd(ccd::CcdArgs),
    /// The paper's experiment (eight deforming pawns) and the cost-model report.
    Experiment(experiment::ExperimentArgs),
    /// Time the steps of a deforming mesh (or pair) given as frames: build once, then
    /// update + query per frame.
    Bench(bench::BenchArgs),
}

/// Parses the arguments, runs the command, returns the process exit code.
pub fn run() -> i32 {
    let args: Vec<OsString> = std::env::args_os().collect();
    let cli = match Cli::try_parse_from(&args) {
        Ok(cli) => cli,
        Err(e) if e.use_stderr() => {
            warn(&format!("dhcd: {}", usage_error(e, &args)));
            return 2;
        }
        Err(e) => {
            let _ = e.print();
            return 0;
        }
    };
    let result = match cli.command {
        Command::Collide(args) => collide::run(args).map_err(|e| e.to_string()),
        Command::SelfCollide(args) => self_cmd::run(args).map_err(|e| e.to_string()),
        Command::Scene(args) => scene::run(args).map_err(|e| e.to_string()),
        Command::Proximity(args) => proximity::run(args).map_err(|e| e.to_string()),
        Command::Ccd(args) => ccd::run(args),
        Command::Experiment(args) => experiment::run(args),
        Command::Bench(args) => bench::run(args),
    };
    match result {
        Ok(()) => 0,
        Err(e) => {
            warn(&format!("dhcd: error: {e}"));
            1
        }
    }
}

/// Parses a method: the names (and aliases) of the library's table of methods, which
/// `--help` lists.
pub fn method_parser() -> impl clap::builder::TypedValueParser<Value = dhcd::Method> {
    use clap::builder::{PossibleValue, PossibleValuesParser, TypedValueParser};
    let values = dhcd::Method::ALL.map(|m| PossibleValue::new(m.name()).aliases(m.aliases()));
    PossibleValuesParser::new(values).try_map(|name| name.parse::<dhcd::Method>())
}

/// Parses a DH central vertex choice: `rest-centroid` (the paper's, the default) or
/// `min-radius`, which `--help` lists.
pub fn central_parser() -> impl clap::builder::TypedValueParser<Value = dhcd::CentralVertex> {
    use clap::builder::{PossibleValuesParser, TypedValueParser};
    PossibleValuesParser::new(dhcd::CentralVertex::ALL.map(dhcd::CentralVertex::name))
        .try_map(|name| name.parse::<dhcd::CentralVertex>())
}

/// Writes `text` to standard output (see [`emit_with`]).
pub fn emit(text: &str) -> dhcd::Result<()> {
    emit_with(|out| out.write_all(text.as_bytes()))
}

/// Writes to standard output through a buffer as `write` produces the output, so that a large
/// report is never held whole in memory. A reader that went away (broken pipe, as in
/// `dhcd collide a.obj b.obj | head`) is not an error: there is nobody left to tell.
pub fn emit_with(
    write: impl FnOnce(&mut dyn std::io::Write) -> std::io::Result<()>,
) -> dhcd::Result<()> {
    use std::io::Write;
    let mut out = std::io::BufWriter::with_capacity(1 << 16, std::io::stdout().lock());
    match write(&mut out).and_then(|()| out.flush()) {
        Err(e) if e.kind() != std::io::ErrorKind::BrokenPipe => Err(dhcd::Error::Io {
            path: "<standard output>".into(),
            message: e.to_string(),
        }),
        _ => Ok(()),
    }
}

/// A usage error as one printable line that names what is wrong: clap's message without its
/// usage section, its lines joined (clap lists missing arguments on lines of their own).
fn usage_error(e: clap::Error, args: &[OsString]) -> String {
    // clap echoes arguments as given; printable copies of them fail the same way, so their
    // message is the one to show (a path with a newline must not split the line).
    let shown: Vec<String> = args
        .iter()
        .map(|a| escaped(&a.to_string_lossy()).into_owned())
        .collect();
    let e = match Cli::try_parse_from(&shown) {
        Err(again) if again.kind() == e.kind() => again,
        _ => e,
    };
    let text = e.render().to_string();
    let message = text.split("\n\n").next().unwrap_or_default();
    let line: Vec<&str> = message
        .lines()
        .map(str::trim)
        .filter(|l| !l.is_empty())
        .collect();
    match line.join(" ") {
        l if l.is_empty() => "error: invalid arguments".to_string(),
        l => escaped(&l).into_owned(),
    }
}

/// One line on standard error; never panics (unlike `eprintln!` on a closed stderr).
fn warn(line: &str) {
    use std::io::Write;
    let _ = writeln!(std::io::stderr().lock(), "{line}");
}
