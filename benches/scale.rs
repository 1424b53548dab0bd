//! Step time against size: a noisy grid folded onto itself and deforming, self-collided at
//! 10K, 100K and 1M triangles. One step = `update_positions` to the next frame (two frames,
//! alternating) + self-collision, one thread, default options.
//!
//! Ids: `scale/<triangles>/<impl>`, `impl` in `dhcd-aabb`, `dhcd-dh`, `parry3d` (see
//! `common/mod.rs`). The scene: a `2a x b` grid of cells `1/b` (`4ab` triangles), folded at
//! its middle so the two halves lie on each other (`shapes::fold_x`), z-noise of half a cell
//! on every vertex (`shapes::jitter`) so the layers cross everywhere, then a travelling wave
//! (`shapes::wave`) that moves both layers. The noise scales with the cell, so the contacts
//! grow linearly with the triangles (the setup prints them per size, and asserts that every
//! implementation finds the same pairs).
//!
//! `cargo bench --bench scale -- scale/10000/`

mod common;

use common::{bench_steps, Impl, Sequence};
use criterion::{criterion_group, criterion_main, Criterion};
use dhcd::shapes::{fold_x, grid, jitter, wave};
use dhcd::Method;

/// `(a, b)`: `4ab` triangles.
const SIZES: [(u32, u32); 3] = [(50, 50), (125, 200), (500, 500)];

/// Frames of the cycle (few: the setup steps every implementation through each).
const FRAMES: usize = 2;

fn folded(a: u32, b: u32) -> Sequence {
    let cell = 1.0 / b as f32;
    let rest = grid(2 * a, b, cell, [0.0; 3]);
    let layers = jitter(
        &fold_x(rest.positions(), a as f32 * cell),
        [0.0, 0.0, 0.5 * cell],
        11,
    );
    let frames = (0..FRAMES)
        .map(|f| wave(&layers, 0.5 * f as f32, 0.02, [0.0; 3]))
        .collect();
    Sequence { rest, frames }
}

fn scale(c: &mut Criterion) {
    let impls = [
        Impl::Dhcd(Method::Aabb),
        Impl::Dhcd(Method::Dh),
        Impl::Parry,
    ];
    for (a, b) in SIZES {
        let n = 4 * a * b;
        bench_steps(c, "scale", &n.to_string(), &impls, || folded(a, b));
    }
}

criterion_group! {
    name = benches;
    // A 1M-triangle step takes seconds: ten samples.
    config = Criterion::default().sample_size(10);
    targets = scale
}
criterion_main!(benches);
