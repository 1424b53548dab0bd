//! `dhcd self MESH [--method dh|sphere|aabb] [--levels N] [--json]`

use std::path::PathBuf;

use dhcd::{AnyHierarchy, Method, Options, Workspace};
use serde_json::json;

use super::collide::contacts_json;

#[derive(clap::Args, Debug)]
pub struct SelfArgs {
    /// The mesh (OBJ, STL or PLY).
    mesh: PathBuf,
    /// Bounding-volume hierarchy: dh, sphere or aabb.
    #[arg(long, default_value = "dh")]
    method: Method,
    /// Levels of the region tree (root = level 0).
    #[arg(long, default_value_t = dhcd::tree::DEFAULT_LEVELS)]
    levels: usize,
    /// Print one JSON object instead of text.
    #[arg(long)]
    json: bool,
}

pub fn run(args: SelfArgs) -> dhcd::Result<()> {
    let options = Options {
        levels: args.levels,
        ..Options::default()
    };
    let mesh = dhcd::io::load(&args.mesh)?;
    let mut h = AnyHierarchy::new(args.method, &mesh, options)?;
    let contacts = h.self_collide(&mut Workspace::default(), dhcd::Par::Seq);
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
            "{} self-contacts ({} levels, {} bytes per node): {} BV pairs tested, {} triangle pairs tested, {} BV updates",
            contacts.pairs.len(),
            args.levels,
            args.method.bytes_per_node(),
            c.bv_tests,
            c.prim_tests,
            c.bv_updates
        );
        for [ti, tj] in &contacts.pairs {
            println!("{ti} {tj}");
        }
    }
    Ok(())
}
