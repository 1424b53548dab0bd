//! The collision-free step size: planted cases with known answers, equal to a brute force
//! over every feature pair (each tested by exact CCD at its own gap), never past the earliest
//! impact, the same for every method and thread count, typed errors for bad options.

use dhcd::bv::BoundingVolume;
use dhcd::ccd::{self, CcdOptions, TOI_TOLERANCE};
use dhcd::contact::{collision_free_stepsize, collision_free_stepsize_with, StepOptions};
use dhcd::distance::{edge_edge_distance_sq, point_triangle_distance_sq};
use dhcd::scene::Scene;
use dhcd::shapes::{fold_x, grid, jitter};
use dhcd::{
    for_each_method, self_ccd, CcdQuery, Error, Hierarchy, Mesh, Motion, Options, Par, Workspace,
};

fn f64s(p: &[[f32; 3]]) -> Vec<[f64; 3]> {
    p.iter().map(|q| q.map(f64::from)).collect()
}

/// A triangle at z = 0 and a vertex falling from z = 1 to z = -1 (through its middle).
fn falling_vertex() -> (Mesh, Vec<[f64; 3]>, Vec<[f64; 3]>) {
    let x0 = vec![
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [0.25, 0.25, 1.0],
        [5.0, 5.0, 5.0],
        [6.0, 5.0, 5.0],
    ];
    let mut x1 = x0.clone();
    x1[3][2] = -1.0;
    // A second triangle far away keeps the vertex in a triangle of its own.
    let m = Mesh::new_f64(x0.clone(), vec![[0, 1, 2], [3, 4, 5]]).unwrap();
    (m, x0, x1)
}

#[test]
fn a_falling_vertex_stops_at_its_gap() {
    let (m, x0, x1) = falling_vertex();
    for_each_method!(K => {
        let h = Hierarchy::<K>::new(&m, Options::default()).unwrap();
        let motion = Motion::new(&x0, &x1);
        // Gap 0.2 (of d0 = 1): reached at z = 0.2, t = 0.4.
        let s = collision_free_stepsize(&h, motion, &StepOptions::default()).unwrap();
        assert!(s.step <= 0.4 && 0.4 - s.step <= 2.0 * TOI_TOLERANCE, "{}", s.step);
        assert_eq!(s.limiting.vertex_face.len(), 1);
        assert_eq!(s.limiting.vertex_face[0].vertex, 3);
        // min distance 0.1: gap 0.1 + 0.2 * 0.9 = 0.28, at t = 0.36.
        let o = StepOptions { min_distance: 0.1, rescaling: 0.8 };
        let s = collision_free_stepsize(&h, motion, &o).unwrap();
        assert!(s.step <= 0.36 && 0.36 - s.step <= 2.0 * TOI_TOLERANCE, "{}", s.step);
        // rescaling 1: the impact itself, t = 0.5.
        let o = StepOptions { min_distance: 0.0, rescaling: 1.0 };
        let s = collision_free_stepsize(&h, motion, &o).unwrap();
        assert!(s.step <= 0.5 && 0.5 - s.step <= 2.0 * TOI_TOLERANCE, "{}", s.step);
        // Nothing comes near: 1.
        let still = Motion::new(&x0, &x0);
        let s = collision_free_stepsize(&h, still, &StepOptions::default()).unwrap();
        assert_eq!(s.step, 1.0);
        assert!(s.limiting.vertex_face.is_empty() && s.limiting.edge_edge.is_empty());
    });
}

/// Every vertex-triangle and edge-edge pair of the mesh, each by exact CCD at its own gap.
pub fn brute_force_step(m: &Mesh, x0: &[[f64; 3]], x1: &[[f64; 3]], o: &StepOptions) -> f64 {
    brute_force_step_of(m, x0, x1, o, &|_| true)
}

/// [`brute_force_step`] over the pairs whose four vertices `counts`.
fn brute_force_step_of(
    m: &Mesh,
    x0: &[[f64; 3]],
    x1: &[[f64; 3]],
    o: &StepOptions,
    counts: &dyn Fn([u32; 4]) -> bool,
) -> f64 {
    let gap = |d0_sq: f64| {
        let g = o.min_distance + (1.0 - o.rescaling) * (d0_sq.sqrt() - o.min_distance);
        (g * (1.0 + 16.0 * f64::EPSILON)).max(0.0)
    };
    let mut best = 1.0f64;
    let tris = m.triangles();
    for v in 0..x0.len() as u32 {
        for t in tris {
            if t.contains(&v) || !counts([v, t[0], t[1], t[2]]) {
                continue;
            }
            let p0 = [
                x0[v as usize],
                x0[t[0] as usize],
                x0[t[1] as usize],
                x0[t[2] as usize],
            ];
            let p1 = [
                x1[v as usize],
                x1[t[0] as usize],
                x1[t[1] as usize],
                x1[t[2] as usize],
            ];
            let g = gap(point_triangle_distance_sq(p0[0], [p0[1], p0[2], p0[3]]).0);
            let c = CcdOptions {
                t_max: 1.0,
                min_distance: g,
            };
            if let Some(toi) = ccd::vertex_face(&p0, &p1, &c) {
                best = best.min(toi);
            }
        }
    }
    let mut edges: Vec<[u32; 2]> = tris
        .iter()
        .flat_map(|t| (0..3).map(move |k| [t[k].min(t[(k + 1) % 3]), t[k].max(t[(k + 1) % 3])]))
        .collect();
    edges.sort_unstable();
    edges.dedup();
    for (i, a) in edges.iter().enumerate() {
        for b in &edges[i + 1..] {
            if a.iter().any(|v| b.contains(v)) || !counts([a[0], a[1], b[0], b[1]]) {
                continue;
            }
            let q = |x: &[[f64; 3]]| {
                [
                    x[a[0] as usize],
                    x[a[1] as usize],
                    x[b[0] as usize],
                    x[b[1] as usize],
                ]
            };
            let (p0, p1) = (q(x0), q(x1));
            let g = gap(edge_edge_distance_sq(p0[0], p0[1], p0[2], p0[3]).0);
            let c = CcdOptions {
                t_max: 1.0,
                min_distance: g,
            };
            if let Some(toi) = ccd::edge_edge(&p0, &p1, &c) {
                best = best.min(toi);
            }
        }
    }
    best
}

/// The step size equals `want` (the brute force's) within the tolerance, on 1 and 2
/// threads, and is never past the earliest impact at the minimum distance.
pub fn check<K: BoundingVolume>(
    m: &Mesh,
    x0: &[[f64; 3]],
    x1: &[[f64; 3]],
    o: &StepOptions,
    want: f64,
) {
    let h = Hierarchy::<K>::new(m, Options::default()).unwrap();
    let motion = Motion::new(x0, x1);
    for par in [Par::Seq, Par::Rayon(2)] {
        let s =
            collision_free_stepsize_with(&h, motion, o, &mut Workspace::default(), par).unwrap();
        // The walk finds the limiting pair; its time may be from any pair within the
        // tolerance of the brute force's least.
        assert!(
            (s.step - want).abs() <= TOI_TOLERANCE,
            "{:?} {par:?} {o:?}: {} vs brute force {want}",
            K::METHOD,
            s.step
        );
        // Never past the earliest impact at the minimum distance.
        let q = CcdQuery::earliest().with_min_distance(o.min_distance);
        if let Some(t) = self_ccd(&h, motion, &q).unwrap().toi {
            assert!(
                s.step <= t + TOI_TOLERANCE,
                "{} past the impact {t}",
                s.step
            );
        }
    }
}

/// A sheet folding onto itself over the step, jittered: the brute force over every pair.
#[test]
fn a_folding_sheet_equals_the_brute_force() {
    let rest = grid(6, 6, 0.1, [0.0, 0.0, 0.0]);
    let x0 = f64s(&jitter(&fold_x(rest.positions(), 0.28), [0.01; 3], 5));
    let x1 = f64s(&jitter(&fold_x(rest.positions(), 0.3), [0.02; 3], 6));
    let m = Mesh::new_f64(x0.clone(), rest.triangles().to_vec()).unwrap();
    for o in [
        StepOptions::default(),
        StepOptions {
            min_distance: 0.005,
            rescaling: 0.8,
        },
        StepOptions {
            min_distance: 0.0,
            rescaling: 0.5,
        },
        StepOptions {
            min_distance: 0.001,
            rescaling: 1.0,
        },
    ] {
        let want = brute_force_step(&m, &x0, &x1, &o);
        assert!(want < 1.0, "the planted motion limits the step ({o:?})");
        for_each_method!(K => check::<K>(&m, &x0, &x1, &o, want));
    }
}

/// A vertex sweeping past a triangle's edge (0.1 above it at its closest, 1.0 away at t0)
/// reaches its gap (0.2 of its distance) at t ~ 0.05 and never touches; another vertex
/// falls onto a triangle at t = 0.1, the first impact. The passing pair limits the step,
/// though at the first impact it is far from its triangle again: the gap rule must test it
/// although the first impact's walk, fitted up to that impact, need not meet it.
#[test]
fn a_pair_passing_by_limits_the_step_before_the_first_impact() {
    let x0 = vec![
        // The triangle the vertex passes by, and the passing vertex with its companions.
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [-1.0, 0.0, 0.1],
        [-1.0, -3.0, 0.1],
        [-2.0, -3.0, 0.1],
        // The triangle the falling vertex meets, and the falling vertex with its companions.
        [5.0, 5.0, 5.0],
        [6.0, 5.0, 5.0],
        [5.0, 6.0, 5.0],
        [5.25, 5.25, 5.1],
        [5.25, 8.0, 5.1],
        [6.25, 8.0, 5.1],
    ];
    let mut x1 = x0.clone();
    for p in &mut x1[3..6] {
        p[0] += 16.5;
    }
    for p in &mut x1[9..12] {
        p[2] -= 1.0;
    }
    let tris = vec![[0, 1, 2], [3, 4, 5], [6, 7, 8], [9, 10, 11]];
    let m = Mesh::new_f64(x0.clone(), tris).unwrap();
    let o = StepOptions::default();
    let want = brute_force_step(&m, &x0, &x1, &o);
    assert!(want < 0.08, "the passing pair limits the step: {want}");
    for_each_method!(K => {
        check::<K>(&m, &x0, &x1, &o, want);
        let h = Hierarchy::<K>::new(&m, Options::default()).unwrap();
        let s = collision_free_stepsize(&h, Motion::new(&x0, &x1), &o).unwrap();
        // The passing vertex against the triangle (tied with the features at the corner).
        let passing = |x: &dhcd::query::VertexImpact| x.vertex == 3 && x.triangle == 0;
        assert!(s.limiting.vertex_face.iter().any(passing), "{:?}", s.limiting);
    });
}

/// Two coincident sheets in one mesh, the second sliding over the first: pairs touching at
/// t0 keep a gap of 0 under the rule with `min_distance = 0` (the step is 0), and with a
/// minimum distance they are already inside it.
#[test]
fn sheets_resting_on_each_other_allow_no_step() {
    let (m, x0, x1) = crate::fixtures::resting_sheets();
    for o in [
        StepOptions::default(),
        StepOptions {
            min_distance: 0.01,
            rescaling: 0.8,
        },
    ] {
        let want = brute_force_step(&m, &x0, &x1, &o);
        assert_eq!(want, 0.0, "{o:?}");
        for_each_method!(K => check::<K>(&m, &x0, &x1, &o, want));
    }
}

/// The falling vertex stopping short of the triangle (z from 1 to 0.1: it never touches, but
/// passes its gap 0.2 at t = 8/9) while the whole mesh drifts far: the drift dwarfs the
/// pair's approach, so only the relative motion bounds which pairs the gap walk must test.
/// Alone the mesh drifts as one; in a scene beside a still copy of the triangle, the still
/// object's zero displacement makes the drift itself relative motion.
#[test]
fn a_drifting_mesh_stops_at_its_gap_alone_and_beside_a_still_object() {
    let (m, x0, mut x1) = falling_vertex();
    x1[3][2] = 0.1;
    let want = 0.8 / 0.9;
    let drift = [40.0, -25.0, 10.0];
    let drifted: Vec<[f64; 3]> = x1
        .iter()
        .map(|p| [p[0] + drift[0], p[1] + drift[1], p[2] + drift[2]])
        .collect();
    let close = |step: f64, want: f64| step <= want && want - step <= 2.0 * TOI_TOLERANCE;
    for_each_method!(K => {
        let h = Hierarchy::<K>::new(&m, Options::default()).unwrap();
        for par in [Par::Seq, Par::Rayon(2)] {
            let motion = Motion::new(&x0, &drifted);
            let mut ws = Workspace::default();
            let s = collision_free_stepsize_with(&h, motion, &StepOptions::default(), &mut ws, par)
                .unwrap();
            assert!(close(s.step, want), "{:?} {par:?}: {}", K::METHOD, s.step);
            assert_eq!(s.limiting.vertex_face.len(), 1);
        }
    });
    // A still triangle under the drifting vertex's path: the vertex (alone in its object,
    // with a far triangle) drifts across it from above, while staying above it.
    let wall = Mesh::new_f64(
        vec![
            [-100.0, -100.0, 0.0],
            [100.0, -100.0, 0.0],
            [0.0, 100.0, 0.0],
        ],
        vec![[0, 1, 2]],
    )
    .unwrap();
    let p0 = vec![[0.0, 0.0, 1.0], [5.0, 5.0, 5.0], [6.0, 5.0, 5.0]];
    let p1: Vec<[f64; 3]> = p0
        .iter()
        .map(|p| [p[0] + 3.0, p[1] + 2.0, p[2] - 0.9])
        .collect();
    let falling = Mesh::new_f64(p0.clone(), vec![[0, 1, 2]]).unwrap();
    for method in dhcd::Method::ALL {
        let mut scene = Scene::new(method, Options::default());
        let _still = scene.add(&wall).unwrap();
        let moving = scene.add(&falling).unwrap();
        let motions = [(moving, Motion::new(&p0, &p1))];
        for par in [Par::Seq, Par::Rayon(2)] {
            let s = scene
                .collision_free_stepsize(&motions, &StepOptions::default(), par)
                .unwrap();
            assert!(close(s.step, want), "{method:?} {par:?}: {}", s.step);
        }
    }
}

#[test]
fn bad_options_are_typed_errors() {
    let (m, x0, x1) = falling_vertex();
    let h = Hierarchy::<dhcd::bv::Dh>::new(&m, Options::default()).unwrap();
    let motion = Motion::new(&x0, &x1);
    for r in [0.0, -0.5, 1.5, f64::NAN, f64::INFINITY] {
        let o = StepOptions {
            min_distance: 0.0,
            rescaling: r,
        };
        let e = collision_free_stepsize(&h, motion, &o).unwrap_err();
        assert!(matches!(e, Error::InvalidRescaling(_)), "{e}");
    }
    for d in [-1.0, f64::NAN, f64::INFINITY] {
        let o = StepOptions {
            min_distance: d,
            rescaling: 0.8,
        };
        let e = collision_free_stepsize(&h, motion, &o).unwrap_err();
        assert!(matches!(e, Error::InvalidMinDistance(_)), "{e}");
    }
    let e = collision_free_stepsize(&h, Motion::new(&x0[1..], &x1), &StepOptions::default())
        .unwrap_err();
    assert!(matches!(e, Error::WrongVertexCount { .. }), "{e}");
}

/// Three objects: the folding sheet (self-collision on), a small sheet falling through it
/// (self-collision off) and a far still one (self-collision on). The scene's step equals
/// the brute force over the pairs the scene covers, for every method and thread count, and
/// is never past the scene's earliest impact.
#[test]
fn a_scene_equals_the_brute_force_over_its_pairs() {
    let rest = grid(6, 6, 0.1, [0.0, 0.0, 0.0]);
    let fold0 = f64s(&jitter(&fold_x(rest.positions(), 0.28), [0.01; 3], 5));
    let fold1 = f64s(&jitter(&fold_x(rest.positions(), 0.3), [0.02; 3], 6));
    let small = grid(2, 2, 0.1, [0.05, 0.15, 0.25]);
    let fall0 = f64s(small.positions());
    let fall1: Vec<[f64; 3]> = fall0.iter().map(|p| [p[0], p[1], p[2] - 30.0]).collect();
    let far = grid(2, 2, 0.1, [10.0, 0.0, 0.0]);
    let far0 = f64s(far.positions());
    // The three objects as one mesh, vertices in scene order.
    let (na, nb) = (fold0.len() as u32, fall0.len() as u32);
    let shift = |m: &Mesh, by: u32| -> Vec<[u32; 3]> {
        m.triangles().iter().map(|t| t.map(|v| v + by)).collect()
    };
    let mut tris = shift(&rest, 0);
    tris.extend(shift(&small, na));
    tris.extend(shift(&far, na + nb));
    let x0: Vec<[f64; 3]> = [&fold0[..], &fall0, &far0].concat();
    let x1: Vec<[f64; 3]> = [&fold1[..], &fall1, &far0].concat();
    let all = Mesh::new_f64(x0.clone(), tris).unwrap();
    let falling = |v: u32| (na..na + nb).contains(&v);
    // The falling sheet's self pairs are not the scene's.
    let scene_pairs = |q: [u32; 4]| !q.iter().all(|&v| falling(v));
    let only_fold = |q: [u32; 4]| q.iter().all(|&v| v < na);
    for o in [
        StepOptions::default(),
        StepOptions {
            min_distance: 0.0,
            rescaling: 0.5,
        },
        StepOptions {
            min_distance: 1e-6,
            rescaling: 0.9,
        },
    ] {
        let want = brute_force_step_of(&all, &x0, &x1, &o, &scene_pairs);
        let fold_alone = brute_force_step_of(&all, &x0, &x1, &o, &only_fold);
        assert!(
            want < fold_alone,
            "the falling sheet limits the step ({o:?}: {want} vs {fold_alone})"
        );
        for method in dhcd::Method::ALL {
            let mut scene = Scene::new(method, Options::default());
            let meshes = [
                Mesh::new_f64(fold0.clone(), rest.triangles().to_vec()).unwrap(),
                Mesh::new_f64(fall0.clone(), small.triangles().to_vec()).unwrap(),
                Mesh::new_f64(far0.clone(), far.triangles().to_vec()).unwrap(),
            ];
            let ids: Vec<_> = meshes.iter().map(|m| scene.add(m).unwrap()).collect();
            scene.set_self_collision(ids[0], true).unwrap();
            scene.set_self_collision(ids[2], true).unwrap();
            let motions = [
                (ids[0], Motion::new(&fold0, &fold1)),
                (ids[1], Motion::new(&fall0, &fall1)),
            ];
            for par in [Par::Seq, Par::Rayon(2)] {
                let s = scene.collision_free_stepsize(&motions, &o, par).unwrap();
                assert!(
                    (s.step - want).abs() <= TOI_TOLERANCE,
                    "{method:?} {par:?} {o:?}: {} vs brute force {want}",
                    s.step
                );
                assert_eq!(s.limiting.toi.map_or(1.0, |t| t.clamp(0.0, 1.0)), s.step);
                let q = CcdQuery::earliest().with_min_distance(o.min_distance);
                if let Some(t) = scene.ccd(&motions, &q, par).unwrap().toi {
                    assert!(
                        s.step <= t + TOI_TOLERANCE,
                        "{} past the impact {t}",
                        s.step
                    );
                }
            }
            // Bad input: typed errors before any work.
            let e = scene
                .collision_free_stepsize(&[motions[0], motions[0]], &o, Par::Seq)
                .unwrap_err();
            assert!(matches!(e, Error::RepeatedObject(_)), "{e}");
            let bad = StepOptions {
                rescaling: 0.0,
                ..o
            };
            let e = scene
                .collision_free_stepsize(&motions, &bad, Par::Seq)
                .unwrap_err();
            assert!(matches!(e, Error::InvalidRescaling(_)), "{e}");
            let e = scene
                .collision_free_stepsize(&[(dhcd::ObjectId(99), motions[0].1)], &o, Par::Seq)
                .unwrap_err();
            assert!(matches!(e, Error::UnknownObject(99)), "{e}");
        }
    }
}
