//! The deforming-step loop: build a hierarchy once, then every step hand it the new
//! positions and ask for the self-contacts. Uses the real simulation frames of
//! `../shared/data/real-frames` when they are there (rod-twist 3036 and 3037, f64), else a
//! procedural waving sphere. Prints each step's contacts and the cost-model counters
//! (`N_V` node pairs tested, `N_P` triangle pairs tested, `N_U` nodes refitted).
//!
//! `cargo run --release --example deforming_step`

use std::path::Path;

use dhcd::bv::Dh;
use dhcd::io::{load_as, Limits};
use dhcd::shapes::{icosphere, wave};
use dhcd::{self_collide, Hierarchy, Mesh, Options, Precision};

fn main() -> dhcd::Result<()> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../shared/data/real-frames");
    let (mesh, poses): (Mesh, Vec<Vec<[f64; 3]>>) = if dir.is_dir() {
        let load = |f: &str| load_as(&dir.join(f), &Limits::default(), Precision::F64);
        let (a, b) = (load("rod-twist-3036.ply")?, load("rod-twist-3037.ply")?);
        let poses = [&a, &b].map(|m| m.positions_f64().expect("f64").to_vec());
        (a, poses.to_vec())
    } else {
        let m = icosphere(4, 1.0, [0.0; 3]);
        let poses = (0..4)
            .map(|k| {
                let p = wave(m.positions(), k as f32 * 0.5, 0.3, [0.0; 3]);
                p.iter().map(|q| q.map(f64::from)).collect()
            })
            .collect();
        let m = Mesh::new_f64(
            m.positions().iter().map(|q| q.map(f64::from)).collect(),
            m.triangles().to_vec(),
        )?;
        (m, poses)
    };
    // Built once, at the first pose; bounds are refitted lazily, only where a query looks.
    let mut h = Hierarchy::<Dh>::new(&mesh, Options::default())?;
    println!(
        "{} triangles, {} nodes",
        mesh.triangle_count(),
        h.node_count()
    );
    for (step, pose) in poses.iter().cycle().take(2 * poses.len()).enumerate() {
        h.update_positions_f64(pose)?;
        let contacts = self_collide(&h);
        let c = contacts.counters;
        println!(
            "step {step}: {} self-contacts; N_V {} node pairs, N_P {} triangle pairs, N_U {} refits",
            contacts.pairs.len(),
            c.bv_tests,
            c.prim_tests,
            c.bv_updates
        );
    }
    Ok(())
}
