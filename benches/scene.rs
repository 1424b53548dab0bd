//! A scene step (update every object, then all contacts) with the scene's parallel schedule
//! (every object pair at once on rayon over the shared hierarchies, each query splitting its
//! own frontier),
//! against the sequential step and against the alternative of running the same object
//! pairs one after the other, each query parallel inside only; and the sequential step with
//! front tracking (`Scene::set_front_tracking`: each pair starts from its last front).
//!
//! `cargo bench --bench scene`

use criterion::{criterion_group, criterion_main, Criterion};
use dhcd::bv::Dh;
use dhcd::scene::Scene;
use dhcd::shapes::{icosphere, wave};
use dhcd::{collide_with, Hierarchy, Method, ObjectId, Options, Par, Workspace};

const OBJECTS: usize = 8;
const POSES: usize = 4;

/// Ring of overlapping, deforming balls: `poses[p][k]` is object `k` in pose `p`.
fn poses() -> (dhcd::Mesh, Vec<Vec<Vec<[f32; 3]>>>) {
    let ball = icosphere(4, 1.0, [0.0; 3]);
    let poses = (0..POSES)
        .map(|p| {
            (0..OBJECTS)
                .map(|k| {
                    let a = k as f32 / OBJECTS as f32 * std::f32::consts::TAU;
                    let r = 2.4;
                    wave(
                        ball.positions(),
                        p as f32 * 0.5 + k as f32,
                        0.1,
                        [r * a.cos(), r * a.sin(), 0.0],
                    )
                })
                .collect()
        })
        .collect();
    (ball, poses)
}

fn bench(c: &mut Criterion) {
    let (ball, poses) = poses();
    let mut g = c.benchmark_group("scene_step_8_balls_5120_tris");
    g.sample_size(20);
    for (name, par) in [("scene_seq", Par::Seq), ("scene_rayon2", Par::Rayon(2))] {
        let mut scene = Scene::new(Method::Dh, Options::default());
        for _ in 0..OBJECTS {
            scene.add(&ball).unwrap();
        }
        let mut frame = 0;
        g.bench_function(name, |b| {
            b.iter(|| {
                frame = (frame + 1) % POSES;
                let updates: Vec<(ObjectId, &[[f32; 3]])> = poses[frame]
                    .iter()
                    .enumerate()
                    .map(|(k, pos)| (ObjectId(k as u64), &pos[..]))
                    .collect();
                scene.step(&updates, par).unwrap().pairs.len()
            })
        });
    }
    // The alternative: the same object pairs in sequence, parallel inside each query.
    let mut scene = Scene::new(Method::Dh, Options::default());
    for (k, pos) in poses[0].iter().enumerate() {
        scene.add(&ball).unwrap();
        scene.update_positions(ObjectId(k as u64), pos).unwrap();
    }
    let pairs: Vec<(usize, usize)> = scene
        .contacts(Par::Seq)
        .per_pair
        .iter()
        .map(|p| (p.a.0 as usize, p.b.0 as usize))
        .collect();
    let mut hs: Vec<Hierarchy<Dh>> = (0..OBJECTS)
        .map(|_| Hierarchy::new(&ball, Options::default()).unwrap())
        .collect();
    let mut ws = Workspace::default();
    let mut frame = 0;
    g.bench_function("pairs_in_sequence_inner_rayon2", |b| {
        b.iter(|| {
            frame = (frame + 1) % POSES;
            for (h, pos) in hs.iter_mut().zip(&poses[frame]) {
                h.update_positions(pos).unwrap();
            }
            let mut n = 0;
            for &(i, j) in &pairs {
                let (lo, hi) = hs.split_at_mut(j);
                n += collide_with(&lo[i], &hi[0], &mut ws, Par::Rayon(2))
                    .pairs
                    .len();
            }
            n
        })
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
