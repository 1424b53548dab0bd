//! `dhcd self MESH [--method dh|sphere|aabb] [--levels N] [--json]`

use std::path::PathBuf;

use dhcd::{AnyHierarchy, Par, Workspace};

use super::query::QueryArgs;

#[derive(clap::Args, Debug)]
pub struct SelfArgs {
    /// The mesh (OBJ, STL or PLY).
    mesh: PathBuf,
    #[command(flatten)]
    query: QueryArgs,
}

pub fn run(args: SelfArgs) -> dhcd::Result<()> {
    let q = &args.query;
    let mesh = dhcd::io::load(&args.mesh)?;
    let mut h = AnyHierarchy::new(q.method, &mesh, q.options())?;
    let contacts = h.self_collide(&mut Workspace::default(), Par::Seq);
    q.report(
        "self-contacts",
        h.tree().levels(),
        &contacts.pairs,
        contacts.counters,
    )
}
