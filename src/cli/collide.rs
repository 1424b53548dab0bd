//! `dhcd collide A B [--method dh|sphere|aabb] [--levels N] [--json]`

use std::path::PathBuf;

use dhcd::{AnyHierarchy, Method, Options, Workspace};
use serde_json::json;

#[derive(clap::Args, Debug)]
pub struct CollideArgs {
    /// First mesh (OBJ, STL or PLY).
    a: PathBuf,
    /// Second mesh.
    b: PathBuf,
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

pub fn run(args: CollideArgs) -> dhcd::Result<()> {
    let options = Options {
        levels: args.levels,
        ..Options::default()
    };
    let mesh_a = dhcd::io::load(&args.a)?;
    let mesh_b = dhcd::io::load(&args.b)?;
    let mut a = AnyHierarchy::new(args.method, &mesh_a, options)?;
    let mut b = AnyHierarchy::new(args.method, &mesh_b, options)?;
    let contacts = a.collide(&mut b, &mut Workspace::default(), dhcd::Par::Seq)?;
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
            "{} contacts ({} levels, {} bytes per node): {} BV pairs tested, {} triangle pairs tested, {} BV updates",
            contacts.pairs.len(),
            args.levels,
            args.method.bytes_per_node(),
            c.bv_tests,
            c.prim_tests,
            c.bv_updates
        );
        for [ta, tb] in &contacts.pairs {
            println!("{ta} {tb}");
        }
    }
    Ok(())
}

/// The JSON object printed by `collide --json` (also used by `self` and `scene`).
pub fn contacts_json(
    method: Method,
    levels: usize,
    pairs: serde_json::Value,
    counters: dhcd::Counters,
) -> serde_json::Value {
    json!({
        "method": method.name(),
        "levels": levels,
        "bytes_per_node": method.bytes_per_node(),
        "pairs": pairs,
        "counters": {
            "bv_tests": counters.bv_tests,
            "prim_tests": counters.prim_tests,
            "bv_updates": counters.bv_updates,
            "contacts": counters.contacts,
        },
    })
}
