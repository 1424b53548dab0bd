//! `dhcd collide A B [--method dh|sphere|aabb] [--levels N] [--json] [--max-file-bytes N]`

use std::path::PathBuf;

use dhcd::{AnyHierarchy, Par, Workspace};

use super::input::InputArgs;
use super::query::QueryArgs;

#[derive(clap::Args, Debug)]
pub struct CollideArgs {
    /// First mesh (OBJ, STL or PLY).
    a: PathBuf,
    /// Second mesh.
    b: PathBuf,
    #[command(flatten)]
    query: QueryArgs,
    #[command(flatten)]
    input: InputArgs,
}

pub fn run(args: CollideArgs) -> dhcd::Result<()> {
    let q = &args.query;
    let mesh_a = args.input.load(&args.a)?;
    let mesh_b = args.input.load(&args.b)?;
    let a = AnyHierarchy::new(q.method, &mesh_a, q.options())?;
    let b = AnyHierarchy::new(q.method, &mesh_b, q.options())?;
    let contacts = a.collide(&b, &mut Workspace::default(), Par::Seq)?;
    let levels = a.tree().levels().max(b.tree().levels());
    q.report(
        "contacts",
        args.input.precision(),
        levels,
        &contacts.pairs,
        contacts.counters,
    )
}
