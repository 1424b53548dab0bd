//! Tests of `dhcd_cli::sim`: the pawn mesh, the simulator's stability, determinism and contact
//! response, and the eight-object scene.

use std::collections::HashMap;

use dhcd::Mesh;
use dhcd_cli::sim::{
    pawn_mesh, pawn_mesh_with, pawn_scene, scene_with_mesh, ObjectContact, SimConfig, Simulation,
};
use glam::DVec3;

fn v(p: [f32; 3]) -> DVec3 {
    DVec3::new(f64::from(p[0]), f64::from(p[1]), f64::from(p[2]))
}

fn signed_volume(positions: &[[f32; 3]], triangles: &[[u32; 3]]) -> f64 {
    triangles
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|i| v(positions[i as usize]));
            a.dot(b.cross(c)) / 6.0
        })
        .sum()
}

/// Every undirected edge is used by exactly two triangles, once in each direction
/// (closed, consistently oriented 2-manifold).
fn assert_closed_oriented(mesh: &Mesh) {
    let mut directed: HashMap<(u32, u32), usize> = HashMap::new();
    for t in mesh.triangles() {
        for k in 0..3 {
            *directed.entry((t[k], t[(k + 1) % 3])).or_default() += 1;
        }
    }
    for (&(a, b), &count) in &directed {
        assert_eq!(count, 1, "directed edge {a}->{b} used {count} times");
        assert_eq!(
            directed.get(&(b, a)),
            Some(&1),
            "edge {a}-{b} is not shared by exactly two oppositely wound triangles"
        );
    }
}

/// Triangle pairs of different objects that may intersect: bounding boxes overlap and
/// neither triangle's plane strictly separates the other. A superset of the exact
/// intersections, good enough to drive the simulator in tests without the narrow phase.
fn approx_contacts(sim: &Simulation) -> Vec<ObjectContact> {
    let cell = 0.05 * sim.scale();
    let mut grid: HashMap<[i64; 3], Vec<(u32, u32)>> = HashMap::new();
    let mut boxes: Vec<Vec<(DVec3, DVec3)>> = Vec::new();
    for o in 0..sim.object_count() {
        let pos = sim.positions(o);
        let mut object_boxes = Vec::new();
        for (t, tri) in sim.triangles(o).iter().enumerate() {
            let [a, b, c] = tri.map(|i| v(pos[i as usize]));
            let (lo, hi) = (a.min(b).min(c), a.max(b).max(c));
            object_boxes.push((lo, hi));
            // A torn triangle would flood the grid; such a scene fails elsewhere anyway.
            assert!(
                (hi - lo).max_element() < 0.5 * sim.scale(),
                "triangle {t} torn"
            );
            let (l, h) = ((lo / cell).floor(), (hi / cell).floor());
            for x in l.x as i64..=h.x as i64 {
                for y in l.y as i64..=h.y as i64 {
                    for z in l.z as i64..=h.z as i64 {
                        grid.entry([x, y, z])
                            .or_default()
                            .push((o as u32, t as u32));
                    }
                }
            }
        }
        boxes.push(object_boxes);
    }
    let separated = |p: &[DVec3; 3], q: &[DVec3; 3]| {
        let n = (p[1] - p[0]).cross(p[2] - p[0]);
        let d: Vec<f64> = q.iter().map(|x| (*x - p[0]).dot(n)).collect();
        d.iter().all(|&s| s > 0.0) || d.iter().all(|&s| s < 0.0)
    };
    let tri = |o: u32, t: u32| {
        let pos = sim.positions(o as usize);
        sim.triangles(o as usize)[t as usize].map(|i| v(pos[i as usize]))
    };
    let mut out = Vec::new();
    for items in grid.values() {
        for (i, &(oa, ta)) in items.iter().enumerate() {
            for &(ob, tb) in &items[i + 1..] {
                if oa == ob {
                    continue;
                }
                let (la, ha) = boxes[oa as usize][ta as usize];
                let (lb, hb) = boxes[ob as usize][tb as usize];
                if la.cmpgt(hb).any() || lb.cmpgt(ha).any() {
                    continue;
                }
                let (p, q) = (tri(oa, ta), tri(ob, tb));
                if separated(&p, &q) || separated(&q, &p) {
                    continue;
                }
                let c = if oa < ob {
                    ObjectContact {
                        object_a: oa,
                        triangle_a: ta,
                        object_b: ob,
                        triangle_b: tb,
                    }
                } else {
                    ObjectContact {
                        object_a: ob,
                        triangle_a: tb,
                        object_b: oa,
                        triangle_b: ta,
                    }
                };
                out.push(c);
            }
        }
    }
    out.sort_unstable();
    out.dedup();
    out
}

fn all_finite(sim: &Simulation) -> bool {
    (0..sim.object_count()).all(|o| sim.positions(o).iter().flatten().all(|x| x.is_finite()))
}

fn centroid(points: &[[f32; 3]]) -> DVec3 {
    points.iter().map(|&p| v(p)).sum::<DVec3>() / points.len() as f64
}

#[test]
fn pawn_has_paper_counts() {
    let pawn = pawn_mesh();
    assert_eq!(pawn.vertex_count(), 3490);
    assert_eq!(pawn.triangle_count(), 6976);
}

#[test]
fn pawn_is_closed_and_consistently_wound() {
    assert_closed_oriented(&pawn_mesh());
    assert_closed_oriented(&pawn_mesh_with(5, 7, 2.0).unwrap());
}

#[test]
fn pawn_faces_outward_and_has_pawn_proportions() {
    let pawn = pawn_mesh();
    let volume = signed_volume(pawn.positions(), pawn.triangles());
    assert!(volume > 0.0, "signed volume {volume} must be positive");
    let (mut lo, mut hi) = (DVec3::splat(f64::MAX), DVec3::splat(f64::MIN));
    for &p in pawn.positions() {
        lo = lo.min(v(p));
        hi = hi.max(v(p));
    }
    assert!((hi.y - lo.y - 1.0).abs() < 1e-6, "height {}", hi.y - lo.y);
    assert!(lo.y.abs() < 1e-6);
    // Wider base than head, and a volume well inside the bounding cylinder.
    let width = hi.x - lo.x;
    assert!(width > 0.5 && width < 0.8, "width {width}");
    let cylinder = std::f64::consts::PI * (width / 2.0).powi(2);
    assert!(
        volume < 0.6 * cylinder && volume > 0.1 * cylinder,
        "volume {volume}"
    );
}

#[test]
fn pawn_has_no_degenerate_triangles() {
    let pawn = pawn_mesh();
    let p = pawn.positions();
    let min_area = pawn
        .triangles()
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|i| v(p[i as usize]));
            0.5 * (b - a).cross(c - a).length()
        })
        .fold(f64::MAX, f64::min);
    assert!(min_area > 1e-6, "smallest triangle area {min_area}");
}

#[test]
fn pawn_parameters_are_validated() {
    assert!(pawn_mesh_with(1, 10, 1.0).is_err());
    assert!(pawn_mesh_with(10, 2, 1.0).is_err());
    assert!(pawn_mesh_with(10, 10, 0.0).is_err());
    assert!(pawn_mesh_with(10, 10, f32::NAN).is_err());
    let small = pawn_mesh_with(4, 6, 1.0).unwrap();
    assert_eq!(small.vertex_count(), 4 * 6 + 2);
    assert_eq!(small.triangle_count(), 2 * 4 * 6);
}

#[test]
fn pawn_scene_has_eight_separated_pawns() {
    let sim = pawn_scene(&SimConfig::default()).unwrap();
    assert_eq!(sim.object_count(), 8);
    for o in 0..8 {
        assert_eq!(sim.positions(o).len(), 3490);
        assert_eq!(sim.triangles(o).len(), 6976);
    }
    assert!(approx_contacts(&sim).is_empty(), "pawns start apart");
}

#[test]
fn config_is_validated() {
    let bad = [
        SimConfig {
            frame_dt: 0.0,
            ..SimConfig::default()
        },
        SimConfig {
            substeps: 0,
            ..SimConfig::default()
        },
        SimConfig {
            drag: f64::NAN,
            ..SimConfig::default()
        },
        SimConfig {
            shape_stiffness: 1e9,
            ..SimConfig::default()
        },
    ];
    for config in bad {
        assert!(Simulation::new(vec![pawn_mesh()], config).is_err());
    }
    assert!(Simulation::new(Vec::new(), SimConfig::default()).is_err());
}

/// A coarse pawn keeps the long runs fast while exercising the same code.
fn coarse_scene(config: &SimConfig) -> Simulation {
    scene_with_mesh(pawn_mesh_with(12, 24, 1.0).unwrap(), config).unwrap()
}

#[test]
fn thousand_frames_stay_finite_and_bounded() {
    let config = SimConfig::default();
    let mut sim = coarse_scene(&config);
    let vertices: usize = (0..sim.object_count())
        .map(|o| sim.positions(o).len())
        .sum();
    let mut contacts = Vec::new();
    let mut max_kinetic: f64 = 0.0;
    let mut max_potential: f64 = 0.0;
    let mut touching_frames = 0;
    for _ in 0..1000 {
        sim.step(&contacts);
        contacts = approx_contacts(&sim);
        touching_frames += usize::from(!contacts.is_empty());
        assert!(all_finite(&sim));
        max_kinetic = max_kinetic.max(sim.kinetic_energy());
        max_potential = max_potential.max(sim.potential_energy());
    }
    // Speeds are clamped to max_speed (3 heights/s); bound the kinetic energy by half of
    // that per unit of vertex mass, and the elastic energy generously.
    let kinetic_bound = 0.5 * vertices as f64 * 1.5 * 1.5;
    assert!(
        max_kinetic.is_finite() && max_kinetic < kinetic_bound,
        "kinetic {max_kinetic} >= {kinetic_bound}"
    );
    assert!(
        max_potential.is_finite() && max_potential < 50.0 * vertices as f64,
        "potential {max_potential}"
    );
    assert!(
        touching_frames > 800,
        "touching in only {touching_frames} frames"
    );
    // Objects never fly apart: every centroid stays within two scene widths of the origin.
    for o in 0..sim.object_count() {
        let c = centroid(sim.positions(o));
        assert!(c.length() < 8.0, "object {o} drifted to {c}");
    }
}

#[test]
fn simulation_is_deterministic() {
    let config = SimConfig::default();
    let run = || {
        let mut sim = coarse_scene(&config);
        let mut contacts = Vec::new();
        for _ in 0..60 {
            sim.step(&contacts);
            contacts = approx_contacts(&sim);
            // A kernel may report contacts in any order; the frames must not depend on it.
            contacts.reverse();
        }
        (0..sim.object_count())
            .map(|o| sim.positions(o).to_vec())
            .collect::<Vec<_>>()
    };
    let first = run();
    let in_pool = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .unwrap()
        .install(run);
    assert_eq!(first, in_pool);
    assert_eq!(first, run());
}

#[test]
fn contacts_push_objects_apart() {
    // Two coarse pawns side by side, no drive: fabricated contacts between their facing
    // triangles must push them apart compared with a run without contacts.
    let config = SimConfig {
        drive_strength: 0.0,
        wobble: 0.0,
        ..SimConfig::default()
    };
    let pawn = pawn_mesh_with(12, 24, 1.0).unwrap();
    let shifted = |dx: f32| {
        let p = pawn
            .positions()
            .iter()
            .map(|p| [p[0] + dx, p[1], p[2]])
            .collect();
        Mesh::new(p, pawn.triangles().to_vec()).unwrap()
    };
    let make = || Simulation::new(vec![shifted(-0.35), shifted(0.35)], config.clone()).unwrap();
    // Triangles of object 0 facing +x and of object 1 facing -x, paired up.
    let facing = |sim: &Simulation, o: usize, sign: f64| -> Vec<u32> {
        let p = sim.positions(o);
        let c = centroid(p);
        sim.triangles(o)
            .iter()
            .enumerate()
            .filter(|(_, t)| {
                let m = t.iter().map(|&i| v(p[i as usize])).sum::<DVec3>() / 3.0;
                (m.x - c.x) * sign > 0.25
            })
            .map(|(i, _)| i as u32)
            .collect()
    };
    let mut with = make();
    let mut without = make();
    let (left, right) = (facing(&with, 0, 1.0), facing(&with, 1, -1.0));
    assert!(!left.is_empty() && !right.is_empty());
    let contacts: Vec<ObjectContact> = left
        .iter()
        .zip(right.iter().cycle())
        .map(|(&a, &b)| ObjectContact {
            object_a: 0,
            triangle_a: a,
            object_b: 1,
            triangle_b: b,
        })
        .collect();
    for _ in 0..10 {
        with.step(&contacts);
        without.step(&[]);
    }
    let gap = |sim: &Simulation| centroid(sim.positions(1)).x - centroid(sim.positions(0)).x;
    assert!(
        gap(&with) > gap(&without) + 1e-3,
        "with contacts {} vs without {}",
        gap(&with),
        gap(&without)
    );
    assert!((gap(&without) - 0.7).abs() < 1e-6, "no forces, no motion");
    // Contacts naming missing objects or triangles are ignored, not a panic.
    without.step(&[ObjectContact {
        object_a: 0,
        triangle_a: u32::MAX,
        object_b: 7,
        triangle_b: 0,
    }]);
    assert!(all_finite(&without));
}

/// Tuning report for the full scene (run with `--ignored --nocapture` in release).
#[test]
#[ignore]
fn pawn_scene_report() {
    let config = SimConfig::default();
    let mut sim = pawn_scene(&config).unwrap();
    let rest: Vec<Vec<[f32; 3]>> = (0..8).map(|o| sim.positions(o).to_vec()).collect();
    let mut contacts = Vec::new();
    let mut sim_time = std::time::Duration::ZERO;
    for frame in 0..100 {
        let start = std::time::Instant::now();
        sim.step(&contacts);
        sim_time += start.elapsed();
        contacts = approx_contacts(&sim);
        if frame % 5 == 4 || frame < 5 {
            // Dent: largest vertex displacement relative to the object's mean displacement.
            let mut dent: f64 = 0.0;
            for (o, rest) in rest.iter().enumerate() {
                let p = sim.positions(o);
                let shift = centroid(p) - centroid(rest);
                for (a, b) in p.iter().zip(rest) {
                    dent = dent.max((v(*a) - v(*b) - shift).length());
                }
            }
            println!(
                "frame {:3} contacts {:5} dent {:.4} ke {:.2} pe {:.2}",
                frame + 1,
                contacts.len(),
                dent,
                sim.kinetic_energy(),
                sim.potential_energy()
            );
        }
    }
    println!("simulation time for 100 frames: {sim_time:?}");
}
