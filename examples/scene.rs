//! A scene of several deforming objects: add meshes, move them every step, read the
//! contacts between every pair of objects (a root-box sweep-and-prune first, then the
//! object pairs in parallel).
//!
//! `cargo run --release --example scene`

use dhcd::shapes::{icosphere, wave};
use dhcd::{Method, Options, Par, Scene};

fn main() -> dhcd::Result<()> {
    let mut scene = Scene::new(Method::Dh, Options::default());
    // Five spheres in a row, each overlapping its neighbours a little.
    let meshes: Vec<_> = (0..5)
        .map(|k| icosphere(3, 0.55, [k as f32, 0.0, 0.0]))
        .collect();
    let ids = meshes
        .iter()
        .map(|m| scene.add(m))
        .collect::<dhcd::Result<Vec<_>>>()?;
    for step in 0..5 {
        let t = step as f32 * 0.4;
        let poses: Vec<Vec<[f32; 3]>> = meshes
            .iter()
            .enumerate()
            .map(|(k, m)| wave(m.positions(), t + k as f32, 0.08, [0.0, 0.05 * t, 0.0]))
            .collect();
        let updates: Vec<_> = ids
            .iter()
            .zip(&poses)
            .map(|(&id, p)| (id, &p[..]))
            .collect();
        let contacts = scene.step(&updates, Par::Rayon(2))?;
        println!(
            "step {step}: {} contacts between {} object pairs ({} root boxes compared)",
            contacts.pairs.len(),
            contacts.per_pair.len(),
            contacts.broad_phase_tests
        );
    }
    Ok(())
}
