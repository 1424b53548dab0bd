//! `dhcd scene MESH... [--method dh|sphere|aabb] [--levels N] [--self-collision] [--threads N]
//! [--json] [--max-file-bytes N]`

use std::path::PathBuf;

use dhcd::scene::Scene;
use dhcd::Par;

use super::input::InputArgs;
use super::query::QueryArgs;

#[derive(clap::Args, Debug)]
pub struct SceneArgs {
    /// The meshes (OBJ, STL or PLY), numbered 0, 1, ... in argument order.
    #[arg(required = true)]
    meshes: Vec<PathBuf>,
    #[command(flatten)]
    query: QueryArgs,
    /// Also report each object's self-contacts (as `[k, ti, k, tj]`).
    #[arg(long)]
    self_collision: bool,
    /// Threads (1: the calling thread; 0: all cores; at most 1024, and never more than the
    /// machine has). The output does not depend on it.
    #[arg(long, default_value_t = 1)]
    threads: usize,
    #[command(flatten)]
    input: InputArgs,
}

pub fn run(args: SceneArgs) -> dhcd::Result<()> {
    let q = &args.query;
    let par = Par::threads(args.threads)?;
    let mut scene = Scene::new(q.method, q.options());
    for path in &args.meshes {
        let mesh = args.input.load(path)?;
        let id = scene.add(&mesh)?;
        scene.set_self_collision(id, args.self_collision)?;
    }
    let contacts = scene.contacts(par);
    let what = format!(
        "contacts between {} objects ({} object pairs past the broad phase)",
        scene.len(),
        contacts.per_pair.len()
    );
    let mut levels = 0;
    for id in scene.ids() {
        levels = levels.max(scene.tree(id)?.levels());
    }
    q.report(
        &what,
        args.input.precision(),
        levels,
        &contacts.pairs,
        contacts.counters,
    )
}
