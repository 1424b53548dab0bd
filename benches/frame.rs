//! Whole-frame benchmarks against parry3d: one step = new positions -> refit -> traverse ->
//! exact contacts, on identical meshes, deformations and frames for every implementation.
//!
//! Ids:
//! - `frame/<scene>/<impl>`: a whole step, `impl` in `dhcd-dh`, `dhcd-sphere`, `dhcd-aabb`,
//!   `parry3d`, plus `dhcd-dh-t1` / `dhcd-dh-t2` on `pawns8` (the `Scene` API, one `Scene::step` a frame: object pairs in parallel, `Par::Rayon(1)` / `Rayon(2)`),
//! - `hier/<scene>/<impl>`: refit + traversal down to leaf pairs only (no triangle tests;
//!   for dhcd `broad_phase`, which also refreshes the leaves' cached triangle boxes);
//! - `narrow/<scene>/dhcd-dh`: the exact narrow phase alone on the leaf pairs of a frame
//!   (divide by the printed `N_P` per frame for the cost per triangle pair).
//!
//! Scenes: `icospheres` (two overlapping 5,120-triangle icospheres, deformed by
//! `dhcd::shapes::wave`) and `pawns8` (`dhcd_cli::sim::pawn_scene`: eight 6,976-triangle pawns
//! pushed into each other by the mass-spring simulator, all 28 pairs per frame; simulated
//! once in the setup, with dhcd's contacts fed back, and frames `PAWN_WARMUP..` kept). A
//! cycle of `FRAMES` frames is computed once and each iteration applies the next one (lazy
//! refit has real work every iteration).
//!
//! The setup asserts that dhcd's contacts (all three methods) equal the exact brute force on a
//! few frames, and prints how parry's GJK contacts compare (not exact; not asserted).
use dhcd::calibration::Calibration;
use std::collections::BTreeSet;
use std::hint::black_box;
use std::time::{Duration, Instant};

use criterion::{criterion_group, criterion_main, Criterion};
use dhcd::bv::{Aabb, BoundingVolume, Dh, Sphere};
use dhcd::{collide_with, Counters, Hierarchy, Mesh, Method, ObjectId, Options, Par, Workspace};
use parry3d::bounding_volume::Aabb as PAabb;
use parry3d::math::{Pose, Vector};
use parry3d::partitioning::{Bvh, BvhBuildStrategy};
use parry3d::shape::Triangle;

const FRAMES: usize = 16;
/// Pawn frames simulated before the kept cycle (the pawns touch after about ten).
const PAWN_WARMUP: usize = 24;

/// Rest meshes, the frame cycle (`frames[f][object]` = positions) and the object pairs.
struct Scene {
    name: &'static str,
    meshes: Vec<Mesh>,
    frames: Vec<Vec<Vec<[f32; 3]>>>,
    pairs: Vec<(usize, usize)>,
}

impl Scene {
    fn new(name: &'static str, centers: &[[f32; 3]]) -> Self {
        let meshes: Vec<Mesh> = centers
            .iter()
            .map(|&c| dhcd::shapes::icosphere(4, 1.0, c))
            .collect();
        let frames = (0..FRAMES)
            .map(|f| {
                let t = f as f32 * std::f32::consts::TAU / FRAMES as f32;
                meshes
                    .iter()
                    .enumerate()
                    .map(|(o, m)| {
                        let phase = t + o as f32 * 0.7;
                        let sway = 0.05 * phase.sin();
                        dhcd::shapes::wave(m.positions(), phase, 0.04, [sway, -sway, 0.5 * sway])
                    })
                    .collect()
            })
            .collect();
        let n = meshes.len();
        let pairs = (0..n)
            .flat_map(|i| (i + 1..n).map(move |j| (i, j)))
            .collect();
        Self {
            name,
            meshes,
            frames,
            pairs,
        }
    }

    fn mesh_at(&self, f: usize, o: usize) -> Mesh {
        Mesh::new(
            self.frames[f][o].clone(),
            self.meshes[o].triangles().to_vec(),
        )
        .expect("deformed mesh is valid")
    }
}

/// The pawn scene: simulated once, contacts from dhcd (DH) fed back every frame.
fn pawns() -> Scene {
    use dhcd_cli::sim::{pawn_scene, ObjectContact, SimConfig};
    let mut sim = pawn_scene(&SimConfig::default()).expect("pawn scene");
    let n = sim.object_count();
    let meshes: Vec<Mesh> = (0..n).map(|o| sim.mesh(o)).collect();
    let pairs: Vec<(usize, usize)> = (0..n)
        .flat_map(|i| (i + 1..n).map(move |j| (i, j)))
        .collect();
    let mut hs: Vec<Hierarchy<Dh>> = meshes
        .iter()
        .map(|m| Hierarchy::new(m, Options::default()).expect("hierarchy"))
        .collect();
    let mut frames = Vec::new();
    for f in 0..PAWN_WARMUP + FRAMES {
        for (o, h) in hs.iter_mut().enumerate() {
            h.update_positions(sim.positions(o))
                .expect("valid positions");
        }
        let mut contacts = Vec::new();
        for &(i, j) in &pairs {
            let (a, b) = two_mut(&mut hs, i, j);
            for [ta, tb] in dhcd::collide(a, b).pairs {
                contacts.push(ObjectContact {
                    object_a: i as u32,
                    triangle_a: ta,
                    object_b: j as u32,
                    triangle_b: tb,
                });
            }
        }
        if f >= PAWN_WARMUP {
            frames.push((0..n).map(|o| sim.positions(o).to_vec()).collect());
        }
        sim.step(&contacts);
    }
    Scene {
        name: "pawns8",
        meshes,
        frames,
        pairs,
    }
}

fn scenes() -> Vec<Scene> {
    vec![
        Scene::new("icospheres", &[[0.0, 0.0, 0.0], [1.5, 0.2, 0.1]]),
        pawns(),
    ]
}

/// `(&mut v[i], &mut v[j])` for `i < j`.
fn two_mut<T>(v: &mut [T], i: usize, j: usize) -> (&mut T, &mut T) {
    let (lo, hi) = v.split_at_mut(j);
    (&mut lo[i], &mut hi[0])
}

struct DhcdWorld<K: BoundingVolume> {
    hs: Vec<Hierarchy<K>>,
    ws: Workspace,
    /// Each pair's overlapping leaf pairs of the last [`DhcdWorld::hier`].
    leaves: Vec<Vec<[u32; 2]>>,
}

impl<K: BoundingVolume> DhcdWorld<K> {
    fn new(scene: &Scene) -> Self {
        let hs = scene
            .meshes
            .iter()
            .map(|m| Hierarchy::<K>::new(m, Options::default()).expect("hierarchy"))
            .collect();
        Self {
            hs,
            ws: Workspace::default(),
            leaves: vec![Vec::new(); scene.pairs.len()],
        }
    }

    fn apply(&mut self, scene: &Scene, f: usize) {
        for (h, p) in self.hs.iter_mut().zip(&scene.frames[f]) {
            h.update_positions(p).expect("valid positions");
        }
    }

    /// One whole step; calls `sink` with each pair's contacts.
    fn step(
        &mut self,
        scene: &Scene,
        f: usize,
        par: Par,
        mut sink: impl FnMut(usize, &dhcd::Contacts),
    ) {
        self.apply(scene, f);
        for (k, &(i, j)) in scene.pairs.iter().enumerate() {
            let c = collide_with(&self.hs[i], &self.hs[j], &mut self.ws, par);
            sink(k, &c);
        }
    }

    /// Refit + traversal only; returns the triangle pairs the narrow phase would test.
    fn hier(&mut self, scene: &Scene, f: usize) -> u64 {
        self.apply(scene, f);
        let mut n = 0;
        for (k, &(i, j)) in scene.pairs.iter().enumerate() {
            let b = self.hs[i]
                .broad_phase(&self.hs[j], &mut self.ws, Par::Seq)
                .expect("one method");
            n += b.counters.prim_tests;
            self.leaves[k] = b.leaf_pairs;
        }
        n
    }
}

fn tri_aabb(p: &[[f32; 3]], t: [u32; 3]) -> PAabb {
    let c = t.map(|v| Vector::from(p[v as usize]));
    PAabb::new(c[0].min(c[1]).min(c[2]), c[0].max(c[1]).max(c[2]))
}

/// What a parry3d user writes: one `Bvh` per object, one leaf per triangle.
struct ParryWorld {
    bvhs: Vec<Bvh>,
    tris: Vec<Vec<[u32; 3]>>,
}

impl ParryWorld {
    fn new(scene: &Scene) -> Self {
        let tris: Vec<Vec<[u32; 3]>> = scene
            .meshes
            .iter()
            .map(|m| m.triangles().to_vec())
            .collect();
        let bvhs = scene
            .meshes
            .iter()
            .zip(&tris)
            .map(|(m, t)| {
                let leaves: Vec<PAabb> = t.iter().map(|&t| tri_aabb(m.positions(), t)).collect();
                Bvh::from_leaves(BvhBuildStrategy::default(), &leaves)
            })
            .collect();
        Self { bvhs, tris }
    }

    fn refit(&mut self, scene: &Scene, f: usize) {
        for ((bvh, tris), p) in self.bvhs.iter_mut().zip(&self.tris).zip(&scene.frames[f]) {
            for (i, &t) in tris.iter().enumerate() {
                bvh.insert_or_update_partially(tri_aabb(p, t), i as u32, 0.0);
            }
            bvh.refit_without_opt();
        }
    }

    /// One whole step; calls `sink(pair, ta, tb)` for every GJK-intersecting triangle pair.
    fn step(&mut self, scene: &Scene, f: usize, mut sink: impl FnMut(usize, u32, u32)) {
        self.refit(scene, f);
        let id = Pose::identity();
        for (k, &(i, j)) in scene.pairs.iter().enumerate() {
            let (pa, pb) = (&scene.frames[f][i], &scene.frames[f][j]);
            let (ta, tb) = (&self.tris[i], &self.tris[j]);
            let corners = |p: &[[f32; 3]], t: [u32; 3]| {
                let c = t.map(|v| Vector::from(p[v as usize]));
                Triangle::new(c[0], c[1], c[2])
            };
            for (la, lb) in self.bvhs[i].leaf_pairs(&self.bvhs[j], |x, y| x.intersects(y)) {
                let (x, y) = (corners(pa, ta[la as usize]), corners(pb, tb[lb as usize]));
                let hit = parry3d::query::intersection_test(&id, &x, &id, &y)
                    .expect("triangles are supported")
                    .intersecting;
                if hit {
                    sink(k, la, lb);
                }
            }
        }
    }

    /// Refit + traversal only; returns the number of leaf (triangle) pairs.
    fn hier(&mut self, scene: &Scene, f: usize) -> u64 {
        self.refit(scene, f);
        let mut n = 0;
        for &(i, j) in &scene.pairs {
            n += self.bvhs[i]
                .leaf_pairs(&self.bvhs[j], |x, y| x.intersects(y))
                .count() as u64;
        }
        n
    }
}

/// Asserts dhcd == brute force on a few frames, prints the counters of the whole cycle and
/// how parry's GJK contacts compare.
fn check(scene: &Scene) {
    let check_frames: &[usize] = if scene.pairs.len() > 1 {
        &[0, 9]
    } else {
        &[0, 5, 11]
    };
    let mut dh = DhcdWorld::<Dh>::new(scene);
    let mut sp = DhcdWorld::<Sphere>::new(scene);
    let mut bx = DhcdWorld::<Aabb>::new(scene);
    let mut parry = ParryWorld::new(scene);
    let mut totals = [Counters::default(); 3];
    let mut parry_total = 0u64;
    for f in 0..FRAMES {
        let mut got: Vec<Vec<Vec<[u32; 2]>>> = vec![vec![Vec::new(); scene.pairs.len()]; 3];
        dh.step(scene, f, Par::Seq, |k, c| {
            got[0][k] = c.pairs.clone();
            totals[0] += c.counters;
        });
        sp.step(scene, f, Par::Seq, |k, c| {
            got[1][k] = c.pairs.clone();
            totals[1] += c.counters;
        });
        bx.step(scene, f, Par::Seq, |k, c| {
            got[2][k] = c.pairs.clone();
            totals[2] += c.counters;
        });
        // Threads give the same contacts and counters.
        let mut dh2 = DhcdWorld::<Dh>::new(scene);
        dh2.step(scene, f, Par::Rayon(2), |k, c| {
            assert_eq!(c.pairs, got[0][k])
        });
        let mut gjk: Vec<BTreeSet<[u32; 2]>> = vec![BTreeSet::new(); scene.pairs.len()];
        parry.step(scene, f, |k, a, b| {
            gjk[k].insert([a, b]);
        });
        parry_total += gjk.iter().map(|s| s.len() as u64).sum::<u64>();
        assert_eq!(got[0], got[1], "{}: dh != sphere, frame {f}", scene.name);
        assert_eq!(got[0], got[2], "{}: dh != aabb, frame {f}", scene.name);
        if check_frames.contains(&f) {
            let (mut missed, mut extra) = (0, 0);
            for (k, &(i, j)) in scene.pairs.iter().enumerate() {
                let exact =
                    dhcd::narrow::brute_force_pairs(&scene.mesh_at(f, i), &scene.mesh_at(f, j));
                assert_eq!(
                    got[0][k], exact,
                    "{}: dh != brute force, frame {f}, pair {k}",
                    scene.name
                );
                let exact: BTreeSet<[u32; 2]> = exact.into_iter().collect();
                missed += exact.difference(&gjk[k]).count();
                extra += gjk[k].difference(&exact).count();
            }
            let n: usize = got[0].iter().map(Vec::len).sum();
            eprintln!(
                "[{}] frame {f}: exact contacts {n} (== brute force, all 3 methods); parry GJK {} (missed {missed}, extra {extra})",
                scene.name,
                gjk.iter().map(BTreeSet::len).sum::<usize>()
            );
        }
    }
    for (m, t) in ["dh", "sphere", "aabb"].iter().zip(&totals) {
        eprintln!(
            "[{}] {m:6} over {FRAMES} frames: N_V {} N_P {} N_U {} contacts {} (per frame N_P {:.0})",
            scene.name,
            t.bv_tests,
            t.prim_tests,
            t.bv_updates,
            t.contacts,
            t.prim_tests as f64 / FRAMES as f64
        );
    }
    eprintln!(
        "[{}] parry GJK contacts over {FRAMES} frames: {parry_total}",
        scene.name
    );
}

fn bench_method<K: BoundingVolume>(c: &mut Criterion, scene: &Scene, id: &str, par: Par) {
    let mut w = DhcdWorld::<K>::new(scene);
    let mut f = 0;
    c.bench_function(&format!("frame/{}/{id}", scene.name), |b| {
        b.iter(|| {
            f = (f + 1) % FRAMES;
            let mut n = 0;
            w.step(scene, f, par, |_, c| n += c.pairs.len());
            black_box(n)
        })
    });
}

fn bench_scene(c: &mut Criterion, scene: &Scene, id: &str, par: Par) {
    let mut world = dhcd::scene::Scene::new(Method::Dh, Options::default());
    let ids: Vec<_> = scene
        .meshes
        .iter()
        .map(|m| world.add(m).expect("valid mesh"))
        .collect();
    let mut f = 0;
    c.bench_function(&format!("frame/{}/{id}", scene.name), |b| {
        b.iter(|| {
            f = (f + 1) % FRAMES;
            let updates: Vec<(ObjectId, &[[f32; 3]])> = ids
                .iter()
                .zip(&scene.frames[f])
                .map(|(&id, p)| (id, &p[..]))
                .collect();
            let contacts = world.step(&updates, par).expect("valid positions");
            black_box(contacts.pairs.len())
        })
    });
}

fn frame(c: &mut Criterion) {
    // DHCD_BENCH_NO_CHECK=1 skips the brute-force checks (profiling runs only).
    let checks = std::env::var_os("DHCD_BENCH_NO_CHECK").is_none();
    for scene in &scenes() {
        if checks {
            check(scene);
        }
        bench_method::<Dh>(c, scene, "dhcd-dh", Par::Seq);
        bench_method::<Sphere>(c, scene, "dhcd-sphere", Par::Seq);
        bench_method::<Aabb>(c, scene, "dhcd-aabb", Par::Seq);
        let mut p = ParryWorld::new(scene);
        let mut f = 0;
        c.bench_function(&format!("frame/{}/parry3d", scene.name), |b| {
            b.iter(|| {
                f = (f + 1) % FRAMES;
                let mut n = 0;
                p.step(scene, f, |_, _, _| n += 1);
                black_box(n)
            })
        });
        if scene.pairs.len() > 1 {
            // Many objects: the Scene API runs the object pairs in parallel (all at once, on
            // the shared hierarchies), the way a user with eight objects would.
            bench_scene(c, scene, "dhcd-dh-t1", Par::Rayon(1));
            bench_scene(c, scene, "dhcd-dh-t2", Par::Rayon(2));
        }

        let mut w = DhcdWorld::<Dh>::new(scene);
        c.bench_function(&format!("hier/{}/dhcd-dh", scene.name), |b| {
            b.iter(|| {
                f = (f + 1) % FRAMES;
                black_box(w.hier(scene, f))
            })
        });
        c.bench_function(&format!("hier/{}/parry3d", scene.name), |b| {
            b.iter(|| {
                f = (f + 1) % FRAMES;
                black_box(p.hier(scene, f))
            })
        });
        c.bench_function(&format!("narrow/{}/dhcd-dh", scene.name), |b| {
            b.iter_custom(|iters| {
                let mut t = Duration::ZERO;
                for _ in 0..iters {
                    f = (f + 1) % FRAMES;
                    w.hier(scene, f);
                    let start = Instant::now();
                    for (k, &(i, j)) in scene.pairs.iter().enumerate() {
                        let r = w.hs[i]
                            .narrow_phase(&w.hs[j], &w.leaves[k], Par::Seq)
                            .expect("leaf pairs of this frame");
                        black_box(r);
                    }
                    t += start.elapsed();
                }
                t
            })
        });
    }
}

criterion_group! {
    name = benches;
    config = Criterion::default().sample_size(20);
    targets = frame
}
criterion_main!(benches);
