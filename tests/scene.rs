//! Scenes of many deforming objects against brute force: every object pair, self-collision,
//! add/remove/update, ids, broad-phase culling, parallel == sequential, contact segments.

use dhcd::calibration::Calibration;
use dhcd::narrow::{brute_force_pairs, brute_force_self_pairs, intersection_segment};
use dhcd::scene::{ObjectId, Scene, SceneContacts};
use dhcd::shapes::{grid, icosphere, wave};
use dhcd::Positions;
use dhcd::{AnyHierarchy, Counters, Error, Mesh, Method, Options, Par, Refit, Workspace};

/// The brute-force contacts of objects `(id, mesh in its current pose, self-collision)`.
fn expected(objects: &[(ObjectId, Mesh, bool)]) -> Vec<[u64; 4]> {
    let mut out = Vec::new();
    for (i, (ia, ma, sa)) in objects.iter().enumerate() {
        if *sa {
            for [x, y] in brute_force_self_pairs(ma) {
                out.push([ia.0, x as u64, ia.0, y as u64]);
            }
        }
        for (ib, mb, _) in &objects[i + 1..] {
            for [x, y] in brute_force_pairs(ma, mb) {
                out.push([ia.0, x as u64, ib.0, y as u64]);
            }
        }
    }
    out.sort_unstable();
    out
}

fn posed(mesh: &Mesh, t: f32, amplitude: f32, offset: [f32; 3]) -> Mesh {
    Mesh::new(
        wave(mesh.positions(), t, amplitude, offset),
        mesh.triangles().to_vec(),
    )
    .unwrap()
}

fn check(c: &SceneContacts) {
    assert!(c.pairs.windows(2).all(|w| w[0] < w[1]), "sorted, unique");
    assert!(c
        .pairs
        .iter()
        .all(|p| p[0] < p[2] || (p[0] == p[2] && p[1] < p[3])));
    let sum: dhcd::Counters = c.per_pair.iter().map(|p| p.counters).sum();
    assert_eq!(sum, c.counters);
    assert_eq!(c.counters.contacts as usize, c.pairs.len());
    assert!(c
        .per_pair
        .windows(2)
        .all(|w| (w[0].a, w[0].b) < (w[1].a, w[1].b)));
}

/// A deforming sequence of a cluster of objects, with add and remove between steps;
/// checked against brute force at every step; returns every step's result.
fn sequence(method: Method, par: Par, levels: usize) -> Vec<SceneContacts> {
    let ball = icosphere(2, 1.0, [0.0; 3]);
    let small = icosphere(1, 0.6, [0.0; 3]);
    let sheet = grid(6, 6, 0.5, [-1.5, -1.5, 0.0]);
    let mut scene = Scene::new(
        method,
        Options {
            levels: Some(levels),
            ..Options::default()
        },
    );
    // (id, rest mesh, centre, self-collision)
    let mut objs: Vec<(ObjectId, Mesh, [f32; 3], bool)> = Vec::new();
    for (k, (mesh, centre, selfc)) in [
        (&ball, [0.0, 0.0, 0.0], true),
        (&ball, [1.6, 0.3, 0.0], false),
        (&small, [0.5, 1.2, 0.4], true),
        (&sheet, [0.0, 0.0, 0.2], true),
        (&ball, [30.0, 0.0, 0.0], false),
    ]
    .into_iter()
    .enumerate()
    {
        let id = scene.add(mesh).unwrap();
        assert_eq!(id, ObjectId(k as u64));
        scene.set_self_collision(id, selfc).unwrap();
        objs.push((id, mesh.clone(), centre, selfc));
    }
    let mut results = Vec::new();
    for step in 0..6 {
        if step == 3 {
            // Remove object 1; add a new one (id 5, never 1 again).
            scene.remove(ObjectId(1)).unwrap();
            objs.retain(|o| o.0 != ObjectId(1));
            let id = scene.add(&small).unwrap();
            assert_eq!(id, ObjectId(5));
            objs.push((id, small.clone(), [-0.8, -0.5, 0.3], false));
        }
        let t = step as f32 * 0.6;
        let mut current = Vec::new();
        for (k, (id, rest, centre, selfc)) in objs.iter().enumerate() {
            let amp = if k % 2 == 0 { 0.45 } else { 0.15 };
            let m = posed(rest, t + k as f32, amp, *centre);
            scene.update_positions(*id, m.positions()).unwrap();
            current.push((*id, m, *selfc));
        }
        let c = scene.contacts(par);
        check(&c);
        assert_eq!(c.pairs, expected(&current), "{method}, step {step}");
        // The far object is culled by the broad phase while it exists.
        assert!(c
            .per_pair
            .iter()
            .all(|p| p.a != ObjectId(4) || p.b == ObjectId(4)));
        // Contact detail: the segments of the current pose.
        let segs = scene.contact_segments(&c).unwrap();
        assert_eq!(segs.len(), c.pairs.len());
        for (p, s) in c.pairs.iter().zip(&segs) {
            let mesh = |id: u64| &current.iter().find(|o| o.0 .0 == id).unwrap().1;
            let (ma, mb) = (mesh(p[0]), mesh(p[2]));
            let e = intersection_segment(&ma.corners(p[1] as usize), &mb.corners(p[3] as usize));
            assert_eq!(Some(*s), e);
        }
        results.push(c);
    }
    assert!(results.iter().any(|c| c.pairs.iter().any(|p| p[0] != p[2])));
    assert!(results.iter().any(|c| c.pairs.iter().any(|p| p[0] == p[2])));
    results
}

#[test]
fn scene_equals_brute_force_every_kind() {
    for method in Method::ALL {
        sequence(method, Par::Seq, 4);
    }
}

#[test]
fn scene_parallel_equals_sequential() {
    for method in Method::ALL {
        let seq = sequence(method, Par::Seq, 3);
        for threads in [0, 2, 3] {
            assert_eq!(
                sequence(method, Par::Rayon(threads), 3),
                seq,
                "{method} {threads}"
            );
        }
    }
}

#[test]
fn ids_are_never_reused_and_unknown_ids_are_errors() {
    let m = icosphere(0, 1.0, [0.0; 3]);
    let mut scene = Scene::new(Method::Aabb, Options::default());
    assert!(scene.is_empty());
    let a = scene.add(&m).unwrap();
    let b = scene.add(&m).unwrap();
    scene.remove(a).unwrap();
    let c = scene.add(&m).unwrap();
    assert_eq!((a, b, c), (ObjectId(0), ObjectId(1), ObjectId(2)));
    assert_eq!(scene.ids(), vec![b, c]);
    assert!(!scene.contains(a));
    assert_eq!(scene.remove(a), Err(Error::UnknownObject(0)));
    assert_eq!(
        scene.update_positions(ObjectId(7), m.positions()),
        Err(Error::UnknownObject(7))
    );
    assert_eq!(
        scene.set_self_collision(a, true),
        Err(Error::UnknownObject(0))
    );
    assert_eq!(scene.bounds(a), Err(Error::UnknownObject(0)));
    // A bad update is an error and changes nothing.
    let before = scene.bounds(b).unwrap();
    assert!(matches!(
        scene.update_positions(b, &m.positions()[1..]),
        Err(Error::WrongVertexCount { .. })
    ));
    let mut nan = m.positions().to_vec();
    nan[0][1] = f32::NAN;
    assert!(matches!(
        scene.update_positions(b, &nan),
        Err(Error::NonFinite { .. })
    ));
    assert_eq!(scene.bounds(b).unwrap(), before);
    // A bad mesh is an error and uses no id.
    assert!(Scene::new(
        Method::Dh,
        Options {
            levels: Some(0),
            ..Options::default()
        }
    )
    .add(&m)
    .is_err());
    // Coincident objects: contacts with the other, none with the removed one.
    let c2 = scene.contacts(Par::Seq);
    assert!(!c2.pairs.is_empty());
    assert!(c2.pairs.iter().all(|p| p[0] == b.0 && p[2] == c.0));
}

#[test]
fn empty_and_single_object_scenes() {
    let mut scene = Scene::new(Method::Dh, Options::default());
    assert_eq!(scene.contacts(Par::Seq), SceneContacts::default());
    let m = icosphere(1, 1.0, [0.0; 3]);
    let id = scene.add(&m).unwrap();
    let c = scene.contacts(Par::Rayon(2));
    assert!(c.pairs.is_empty() && c.per_pair.is_empty());
    scene.set_self_collision(id, true).unwrap();
    let c = scene.contacts(Par::Seq);
    assert_eq!(c.per_pair.len(), 1);
    assert!(c.pairs.is_empty());
}

#[test]
fn far_apart_objects_cost_no_bv_work() {
    let m = icosphere(2, 1.0, [0.0; 3]);
    let mut scene = Scene::new(Method::Dh, Options::default());
    for k in 0..20 {
        let id = scene.add(&m).unwrap();
        scene
            .update_positions(
                id,
                &dhcd::shapes::translated(m.positions(), [3.0 * k as f32, 0.0, 0.0]),
            )
            .unwrap();
    }
    let c = scene.contacts(Par::Seq);
    assert!(c.pairs.is_empty());
    assert!(c.per_pair.is_empty());
    assert_eq!(c.counters, dhcd::Counters::default());
    assert!(
        c.broad_phase_tests < 20 * 19 / 2,
        "sweep-and-prune prunes along x"
    );
    // Touching boxes (closed intervals) are kept.
    scene
        .update_positions(
            ObjectId(1),
            &dhcd::shapes::translated(m.positions(), [2.0, 0.0, 0.0]),
        )
        .unwrap();
    let c = scene.contacts(Par::Seq);
    assert_eq!(c.per_pair.len(), 1);
    assert_eq!(
        c.pairs,
        expected(&[
            (ObjectId(0), m.clone(), false),
            (
                ObjectId(1),
                Mesh::new(
                    dhcd::shapes::translated(m.positions(), [2.0, 0.0, 0.0]),
                    m.triangles().to_vec()
                )
                .unwrap(),
                false
            ),
        ])
    );
}

#[test]
fn stale_contacts_are_an_error_for_segments() {
    let m = icosphere(1, 1.0, [0.0; 3]);
    let mut scene = Scene::new(Method::Sphere, Options::default());
    let a = scene.add(&m).unwrap();
    let b = scene.add(&m).unwrap();
    scene
        .update_positions(b, &dhcd::shapes::translated(m.positions(), [1.0, 0.0, 0.0]))
        .unwrap();
    let c = scene.contacts(Par::Seq);
    assert!(!c.pairs.is_empty());
    scene
        .update_positions(b, &dhcd::shapes::translated(m.positions(), [9.0, 0.0, 0.0]))
        .unwrap();
    assert!(matches!(
        scene.contact_segments(&c),
        Err(Error::StaleContact { .. })
    ));
    // Triangle indices the mesh does not have, within u32 and beyond it.
    for t in [m.triangle_count() as u64, u64::MAX] {
        let mut bad = c.clone();
        bad.pairs[0][1] = t;
        assert_eq!(
            scene.contact_segments(&bad),
            Err(Error::TriangleOutOfRange {
                triangle: t,
                triangle_count: m.triangle_count()
            })
        );
    }
    scene.remove(a).unwrap();
    assert_eq!(scene.contact_segments(&c), Err(Error::UnknownObject(0)));
}

/// A ring of touching, deforming objects, some with self-collision: every pair's BV tests,
/// triangle pairs and contacts are those of the same queries run one after the other in job
/// order ((a, a) before (a, b), pairs ascending) on hierarchies of their own, for every
/// thread count; each object's refits (the nodes fitted in the pose, lazily or eagerly) go to
/// its first job.
#[test]
fn per_pair_counters_are_those_of_sequential_queries_in_job_order() {
    let m = icosphere(2, 1.0, [0.0; 3]);
    let n = 8;
    for method in Method::ALL {
        for refit in [Refit::Lazy, Refit::Eager] {
            let options = Options {
                refit,
                ..Options::default()
            };
            for par in [Par::Seq, Par::Rayon(2), Par::Rayon(3)] {
                let mut scene = Scene::new(method, options);
                let ids: Vec<ObjectId> = (0..n).map(|_| scene.add(&m).unwrap()).collect();
                for &id in &ids[..3] {
                    scene.set_self_collision(id, true).unwrap();
                }
                for step in 0..3 {
                    let poses: Vec<Mesh> = (0..n)
                        .map(|k| {
                            let a = k as f32 / n as f32 * std::f32::consts::TAU;
                            let at = [2.3 * a.cos(), 2.3 * a.sin(), 0.0];
                            posed(&m, step as f32 + k as f32, 0.35, at)
                        })
                        .collect();
                    for (&id, p) in ids.iter().zip(&poses) {
                        scene.update_positions(id, p.positions()).unwrap();
                    }
                    let c = scene.contacts(par);
                    check(&c);
                    let current: Vec<(ObjectId, Mesh, bool)> = ids
                        .iter()
                        .zip(&poses)
                        .enumerate()
                        .map(|(k, (&id, p))| (id, p.clone(), k < 3))
                        .collect();
                    assert_eq!(c.pairs, expected(&current));
                    // The reference: fresh hierarchies with the same history of poses (a
                    // lazy hierarchy refits on demand, so only the last pose matters).
                    let mut hs: Vec<AnyHierarchy> = (0..n)
                        .map(|_| AnyHierarchy::new(method, &m, options).unwrap())
                        .collect();
                    for (h, p) in hs.iter_mut().zip(&poses) {
                        h.update_positions(p.positions()).unwrap();
                    }
                    let mut reference = Vec::new();
                    let mut first_job = vec![None; n];
                    for (k, pc) in c.per_pair.iter().enumerate() {
                        let (i, j) = (pc.a.0 as usize, pc.b.0 as usize);
                        let r = if i == j {
                            hs[i].self_collide(&mut Workspace::default(), Par::Seq)
                        } else {
                            hs[i]
                                .collide(&hs[j], &mut Workspace::default(), Par::Seq)
                                .unwrap()
                        };
                        first_job[i].get_or_insert(k);
                        first_job[j].get_or_insert(k);
                        reference.push(Counters {
                            bv_updates: 0,
                            ..r.counters
                        });
                    }
                    // Every object is in a job here, so every pose's refits are credited.
                    for (h, first) in hs.iter().zip(&first_job) {
                        reference[first.expect("every object touches")].bv_updates +=
                            h.fitted_nodes().len() as u64;
                    }
                    let got: Vec<Counters> = c.per_pair.iter().map(|p| p.counters).collect();
                    assert_eq!(got, reference, "{method} {refit:?} {par:?} step {step}");
                    assert!(c.per_pair.iter().any(|p| p.a != p.b), "the ring touches");
                }
            }
        }
    }
}

/// `update_many` is one `update_positions` per object, for every thread count: same
/// contacts, same counters, same root boxes; and `step` is `update_many` then `contacts`
/// (every field of the result).
#[test]
fn update_many_equals_one_update_per_object() {
    let ball = icosphere(2, 1.0, [0.0; 3]);
    let n = 6;
    let build = || {
        let mut scene = Scene::new(Method::Dh, Options::default());
        let ids: Vec<ObjectId> = (0..n).map(|_| scene.add(&ball).unwrap()).collect();
        scene.set_self_collision(ids[0], true).unwrap();
        (scene, ids)
    };
    let (mut one_by_one, ids) = build();
    let mut batched: Vec<(Scene, Par)> = [Par::Seq, Par::Rayon(2), Par::Rayon(3)]
        .into_iter()
        .map(|par| (build().0, par))
        .collect();
    let mut stepped: Vec<Scene> = batched.iter().map(|_| build().0).collect();
    for step in 0..3 {
        let poses: Vec<Mesh> = (0..n)
            .map(|k| {
                posed(
                    &ball,
                    step as f32 + k as f32,
                    0.3,
                    [1.7 * k as f32, 0.0, 0.0],
                )
            })
            .collect();
        for (&id, p) in ids.iter().zip(&poses) {
            one_by_one.update_positions(id, p.positions()).unwrap();
        }
        let reference = one_by_one.contacts(Par::Seq);
        assert!(!reference.pairs.is_empty());
        // Every other step, only some objects move.
        let moved = if step == 1 { 0..3 } else { 0..n };
        for ((scene, par), stepping) in batched.iter_mut().zip(&mut stepped) {
            let updates: Vec<(ObjectId, &[[f32; 3]])> = moved
                .clone()
                .map(|k| (ids[k], poses[k].positions()))
                .collect();
            scene.update_many(&updates, *par).unwrap();
            if step == 1 {
                for k in 3..n {
                    scene
                        .update_positions(ids[k], poses[k].positions())
                        .unwrap();
                    stepping
                        .update_positions(ids[k], poses[k].positions())
                        .unwrap();
                }
            }
            for &id in &ids {
                assert_eq!(scene.bounds(id), one_by_one.bounds(id));
            }
            let contacts = scene.contacts(Par::Seq);
            assert_eq!(contacts.pairs, reference.pairs, "{par:?}");
            assert_eq!(stepping.step(&updates, *par).unwrap(), contacts, "{par:?}");
            for &id in &ids {
                assert_eq!(stepping.bounds(id), one_by_one.bounds(id));
            }
        }
    }
}

/// A bad entry anywhere in an `update_many` (or a `step`) is a typed error and no object
/// moves.
#[test]
fn update_many_checks_everything_before_changing_anything() {
    let ball = icosphere(1, 1.0, [0.0; 3]);
    let mut scene = Scene::new(Method::Aabb, Options::default());
    let a = scene.add(&ball).unwrap();
    let b = scene.add(&ball).unwrap();
    let moved = dhcd::shapes::translated(ball.positions(), [1.5, 0.0, 0.0]);
    let mut nan = moved.clone();
    nan[3][1] = f32::NAN;
    let short = &moved[..moved.len() - 1];
    let before = (scene.bounds(a).unwrap(), scene.bounds(b).unwrap());
    for par in [Par::Seq, Par::Rayon(2)] {
        type Update<'a> = (ObjectId, &'a [[f32; 3]]);
        let cases: [(&[Update], Error); 4] = [
            (
                &[(a, &moved), (ObjectId(9), &moved)],
                Error::UnknownObject(9),
            ),
            (
                &[(b, &moved), (a, &moved), (b, &moved)],
                Error::RepeatedObject(1),
            ),
            (
                &[(a, &moved), (b, short)],
                Error::WrongVertexCount {
                    expected: moved.len(),
                    got: moved.len() - 1,
                    of: Positions::Update,
                    object: Some(b.0),
                },
            ),
            (
                &[(a, &moved), (b, &nan)],
                Error::NonFinite {
                    vertex: 3,
                    position: nan[3].map(f64::from),
                    of: Positions::Update,
                    object: Some(b.0),
                },
            ),
        ];
        for (updates, error) in cases {
            let got = scene.update_many(updates, par).unwrap_err();
            if matches!(
                got,
                Error::NonFinite { .. } | Error::WrongVertexCount { .. }
            ) {
                assert!(
                    got.to_string().contains(&format!("of object {}", b.0)),
                    "{got}"
                );
            }
            // NaN != NaN: compare the messages.
            assert_eq!(got.to_string(), error.to_string(), "{par:?}");
            let got = scene.step(updates, par).unwrap_err();
            assert_eq!(got.to_string(), error.to_string(), "step, {par:?}");
            assert_eq!(
                (scene.bounds(a).unwrap(), scene.bounds(b).unwrap()),
                before,
                "nothing moved ({par:?}, {error})"
            );
        }
    }
    scene.update_many(&[(b, &moved)], Par::Rayon(2)).unwrap();
    assert_ne!(scene.bounds(b).unwrap(), before.1);
    assert!(!scene.contacts(Par::Seq).pairs.is_empty());
}
