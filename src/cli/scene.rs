//! `dhcd scene MESH... [--method dh|sphere|aabb] [--levels N] [--self-collision] [--json]`

use std::path::PathBuf;

use dhcd::scene::Scene;
use dhcd::{Method, Options};
use serde_json::json;

use super::collide::contacts_json;

#[derive(clap::Args, Debug)]
pub struct SceneArgs {
    /// The meshes (OBJ, STL or PLY), numbered 0, 1, ... in argument order.
    #[arg(required = true)]
    meshes: Vec<PathBuf>,
    /// Bounding-volume hierarchy: dh, sphere or aabb.
    #[arg(long, default_value = "dh")]
    method: Method,
    /// Levels of the region tree (root = level 0).
    #[arg(long, default_value_t = dhcd::tree::DEFAULT_LEVELS)]
    levels: usize,
    /// Also report each object's self-contacts (as `[k, ti, k, tj]`).
    #[arg(long)]
    self_collision: bool,
    /// Threads (1: the calling thread; 0: all cores). The output does not depend on it.
    #[arg(long, default_value_t = 1)]
    threads: usize,
    /// Print one JSON object instead of text.
    #[arg(long)]
    json: bool,
}

pub fn run(args: SceneArgs) -> dhcd::Result<()> {
    let options = Options {
        levels: args.levels,
        ..Options::default()
    };
    let mut scene = Scene::new(args.method, options);
    for path in &args.meshes {
        let mesh = dhcd::io::load(path)?;
        let id = scene.add(&mesh)?;
        scene.set_self_collision(id, args.self_collision)?;
    }
    let par = match args.threads {
        1 => dhcd::Par::Seq,
        n => dhcd::Par::Rayon(n),
    };
    let contacts = scene.contacts(par);
    if args.json {
        println!(
            "{}",
            contacts_json(
                args.method,
                args.levels,
                json!(contacts.pairs),
                contacts.counters
            )
        );
    } else {
        let c = contacts.counters;
        println!(
            "{} contacts between {} objects ({} object pairs past the broad phase; {} levels, {} bytes per node): {} BV pairs tested, {} triangle pairs tested, {} BV updates",
            contacts.pairs.len(),
            scene.len(),
            contacts.per_pair.len(),
            args.levels,
            args.method.bytes_per_node(),
            c.bv_tests,
            c.prim_tests,
            c.bv_updates
        );
        for [oa, ta, ob, tb] in &contacts.pairs {
            println!("{oa} {ta} {ob} {tb}");
        }
    }
    Ok(())
}
