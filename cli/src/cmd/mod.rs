//! Command-line front end. Every failure is one line on stderr and a non-zero exit code.

mod collide;
mod experiment;
mod query;
mod scene;
mod self_cmd;

use clap::{Parser, Subcommand};

#[derive(Parser, Debug)]
#[command(
    name = "dhcd",
    version,
    about = "Collision detection between deformable triangle meshes (Distance Hierarchy, sphere and AABB hierarchies)"
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
    /// The paper's experiment (eight deforming pawns) and the cost-model report.
    Experiment(experiment::ExperimentArgs),
}

/// Parses the arguments, runs the command, returns the process exit code.
pub fn run() -> i32 {
    let cli = match Cli::try_parse() {
        Ok(cli) => cli,
        // Usage errors: clap's first line only (one line on stderr, like every failure).
        Err(e) if e.use_stderr() => {
            let text = e.render().to_string();
            let line = text.lines().next().unwrap_or("error: invalid arguments");
            warn(&format!("dhcd: {line}"));
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
        Command::Experiment(args) => experiment::run(args),
    };
    match result {
        Ok(()) => 0,
        Err(e) => {
            warn(&format!("dhcd: error: {e}"));
            1
        }
    }
}

/// Parses a hierarchy kind: the names (and aliases) of the library's table of kinds, which
/// `--help` lists.
pub fn method_parser() -> impl clap::builder::TypedValueParser<Value = dhcd::Method> {
    use clap::builder::{PossibleValue, PossibleValuesParser, TypedValueParser};
    let values = dhcd::Method::ALL.map(|m| PossibleValue::new(m.name()).aliases(m.aliases()));
    PossibleValuesParser::new(values).try_map(|name| name.parse::<dhcd::Method>())
}

/// Writes `text` to standard output. A reader that went away (broken pipe, as in
/// `dhcd collide a.obj b.obj | head`) is not an error: there is nobody left to tell.
pub fn emit(text: &str) -> dhcd::Result<()> {
    use std::io::Write;
    let mut out = std::io::stdout().lock();
    match out.write_all(text.as_bytes()).and_then(|()| out.flush()) {
        Err(e) if e.kind() != std::io::ErrorKind::BrokenPipe => Err(dhcd::Error::Io {
            path: "<standard output>".into(),
            message: e.to_string(),
        }),
        _ => Ok(()),
    }
}

/// One line on standard error; never panics (unlike `eprintln!` on a closed stderr).
fn warn(line: &str) {
    use std::io::Write;
    let _ = writeln!(std::io::stderr().lock(), "{line}");
}
