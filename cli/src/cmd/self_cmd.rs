//! `dhcd self MESH [--method dh|sphere|aabb] [--levels N] [--json] [--max-file-bytes N]`

use std::path::PathBuf;

use dhcd::{AnyHierarchy, Par, Workspace};

use super::input::InputArgs;
use super::query::QueryArgs;

#[derive(clap::Args, Debug)]
pub struct SelfArgs {
    /// The mesh (OBJ, STL or PLY).
    mesh: PathBuf,
    #[command(flatten)]
    query: QueryArgs,
    #[command(flatten)]
    input: InputArgs,
}

pub fn run(args: SelfArgs) -> dhcd::Result<()> {
    let q = &args.query;
    let mesh = args.input.load(&args.mesh)?;
    let h = AnyHierarchy::new(q.method, &mesh, q.options())?;
    let contacts = h.self_collide(&mut Workspace::default(), Par::Seq);
    q.report(
        "self-contacts",
        args.input.precision(),
        h.tree().levels(),
        &contacts.pairs,
        contacts.counters,
    )
}
