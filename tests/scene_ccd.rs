//! CCD over a scene ([`Scene::ccd`]): objects that tunnel through others within a step
//! (no discrete contact at t0 or t1), broad-phase culling on the boxes over the step,
//! self-CCD on and off, still objects (`f32` and `f64`) at their stored pose, the result
//! equal to the direct `ccd_pair` / `self_ccd` calls, both modes, 1 and 2 threads, and every
//! input error leaving the scene as it was.

use dhcd::narrow::earliest_of;
use dhcd::scene::{ObjectId, Scene, SceneImpacts};
use dhcd::shapes::{grid, icosphere, jitter, translated};
use dhcd::{
    AnyHierarchy, CcdMode, CcdQuery, Error, Impacts, Mesh, Method, Motion, Options, Par, Positions,
    Workspace,
};

fn f64s(p: &[[f32; 3]]) -> Vec<[f64; 3]> {
    p.iter().map(|q| q.map(f64::from)).collect()
}

/// One object of the test scene: its rest mesh (added as is), its motion over the step
/// (`None`: still), self-collision.
struct Body {
    mesh: Mesh,
    x0: Vec<[f64; 3]>,
    x1: Option<Vec<[f64; 3]>>,
    self_collision: bool,
}

fn moving(mesh: Mesh, offset: [f32; 3]) -> Body {
    let x0 = f64s(mesh.positions());
    let x1 = Some(f64s(&translated(mesh.positions(), offset)));
    Body {
        mesh,
        x0,
        x1,
        self_collision: false,
    }
}

fn still(mesh: Mesh) -> Body {
    let x0 = match mesh.positions_f64() {
        Some(p) => p.to_vec(),
        None => f64s(mesh.positions()),
    };
    Body {
        mesh,
        x0,
        x1: None,
        self_collision: false,
    }
}

/// The bodies, by object index: 0 a ball (still) that 1 (a small ball) tunnels through
/// along x; 2 an `f64` ball (still, positions off the `f32` grid) that 3 tunnels through
/// along z; 4 a jittered sheet folding through itself (self-collision on); 5 a far ball
/// (still). Only (0, 1), (2, 3) and (4, 4) meet over the step.
fn bodies() -> Vec<Body> {
    let wall = icosphere(2, 1.0, [0.0; 3]);
    let bullet = icosphere(1, 0.3, [-3.0, 0.0, 0.0]);
    let b64 = icosphere(1, 0.4, [0.0, 0.0, 3.0]);
    let b64 = Mesh::new_f64(
        b64.positions()
            .iter()
            .map(|p| p.map(|c| f64::from(c) + 1e-9))
            .collect(),
        b64.triangles().to_vec(),
    )
    .unwrap();
    let dropper = icosphere(1, 0.3, [0.0, 0.0, 4.5]);
    let sheet = grid(8, 8, 0.1, [0.0, 10.0, 0.0]);
    let sheet = Mesh::new(
        jitter(sheet.positions(), [0.002; 3], 5),
        sheet.triangles().to_vec(),
    )
    .unwrap();
    let x0 = f64s(sheet.positions());
    // The right half folded over x = 0.45 and pushed through the left half.
    let x1 = crate::fixtures::folded_through(&x0, 1.0);
    let sheet = Body {
        mesh: sheet,
        x0,
        x1: Some(x1),
        self_collision: true,
    };
    vec![
        still(wall),
        moving(bullet, [6.0, 0.0, 0.0]),
        still(b64),
        moving(dropper, [0.0, 0.0, -3.0]),
        sheet,
        still(icosphere(1, 0.5, [50.0, 0.0, 0.0])),
    ]
}

fn scene_of(method: Method, bodies: &[Body]) -> (Scene, Vec<ObjectId>) {
    let mut scene = Scene::new(method, Options::default());
    let ids = bodies
        .iter()
        .map(|b| {
            let id = scene.add(&b.mesh).unwrap();
            scene.set_self_collision(id, b.self_collision).unwrap();
            id
        })
        .collect();
    (scene, ids)
}

fn motions<'a>(bodies: &'a [Body], ids: &[ObjectId]) -> Vec<(ObjectId, Motion<'a>)> {
    bodies
        .iter()
        .zip(ids)
        .filter_map(|(b, &id)| b.x1.as_ref().map(|x1| (id, Motion::new(&b.x0, x1))))
        .collect()
}

fn pairs_of(i: &Impacts) -> usize {
    i.vertex_face.len() + i.face_vertex.len() + i.edge_edge.len()
}

/// The same pairs, times and reported count (work counters aside).
fn assert_same_impacts(got: &Impacts, want: &Impacts, what: &str) {
    assert_eq!(got.vertex_face, want.vertex_face, "{what}: vertex-face");
    assert_eq!(got.face_vertex, want.face_vertex, "{what}: face-vertex");
    assert_eq!(got.edge_edge, want.edge_edge, "{what}: edge-edge");
    assert_eq!(got.toi, want.toi, "{what}: toi");
    assert_eq!(got.counters.contacts, want.counters.contacts, "{what}");
}

fn check_shape(r: &SceneImpacts) {
    assert!(r
        .per_pair
        .windows(2)
        .all(|w| (w[0].a, w[0].b) < (w[1].a, w[1].b)));
    assert!(r.per_pair.iter().all(|p| p.a <= p.b));
    let sum: dhcd::Counters = r.per_pair.iter().map(|p| p.impacts.counters).sum();
    assert_eq!(sum, r.counters);
    let least = r
        .per_pair
        .iter()
        .filter_map(|p| p.impacts.toi)
        .reduce(f64::min);
    assert_eq!(r.toi, least);
}

/// The small balls pass right through the others within the step: no discrete contact at
/// t0 or at t1, but CCD finds them, at the time the geometry says; the far ball is culled.
#[test]
fn tunnelling_is_found_and_far_objects_are_culled() {
    let bodies = bodies();
    for method in Method::ALL {
        let (mut scene, ids) = scene_of(method, &bodies);
        // Discrete contacts between objects (the sheet's own are not the point here).
        scene.set_self_collision(ids[4], false).unwrap();
        assert!(scene.contacts(Par::Seq).pairs.is_empty(), "{method:?} t0");
        let mut end = scene.clone();
        for (i, b) in bodies.iter().enumerate().take(4) {
            if let Some(x1) = &b.x1 {
                let x1: Vec<[f32; 3]> = x1.iter().map(|p| p.map(|c| c as f32)).collect();
                end.update_positions(ids[i], &x1).unwrap();
            }
        }
        assert!(end.contacts(Par::Seq).pairs.is_empty(), "{method:?} t1");
        scene.set_self_collision(ids[4], true).unwrap();

        let m = motions(&bodies, &ids);
        let r = scene.ccd(&m, &CcdQuery::all(), Par::Seq).unwrap();
        check_shape(&r);
        let jobs: Vec<_> = r.per_pair.iter().map(|p| (p.a, p.b)).collect();
        assert_eq!(
            jobs,
            [(ids[0], ids[1]), (ids[2], ids[3]), (ids[4], ids[4])],
            "{method:?}: the far ball and the apart pairs culled"
        );
        // 6 objects: 15 box pairs at most; sweep-and-prune along x compares fewer.
        assert!(r.broad_phase_tests > 0 && r.broad_phase_tests < 15);
        for p in &r.per_pair {
            assert!(pairs_of(&p.impacts) > 0, "{method:?} {:?}", (p.a, p.b));
            assert_eq!(p.impacts.counters.contacts as usize, pairs_of(&p.impacts));
        }
        // The bullet (radius 0.3, from x = -3, 6 per step) meets the ball of radius 1 when
        // its centre is near x = -1.3: t near 1.7 / 6 = 0.283 (later by the polyhedra's
        // flat faces); the dropper (from z = 4.5, -3 per step) meets the ball of radius 0.4
        // at z = 3 near t = 0.8 / 3 = 0.267.
        let bullet = r.per_pair[0].impacts.toi.unwrap();
        assert!((0.283..0.30).contains(&bullet), "{method:?} {bullet}");
        let dropper = r.per_pair[1].impacts.toi.unwrap();
        assert!((0.266..0.29).contains(&dropper), "{method:?} {dropper}");
        // Pairs of the bullet: vertices of the ball first (object 0 < object 1).
        let vf = &r.per_pair[0].impacts.vertex_face;
        let ball_vertices = bodies[0].mesh.positions().len() as u32;
        assert!(vf.iter().all(|x| x.vertex < ball_vertices));
        assert!(
            r.per_pair[2].impacts.face_vertex.is_empty(),
            "self: no face-vertex"
        );
        assert!(r.toi.unwrap() <= dropper.min(bullet));
    }
}

/// Every job equals the direct call on the same objects (a still object moves from its
/// stored pose to itself), and every object pair the broad phase culled has no impact;
/// with self-collision off the sheet's self job is gone. Both modes, 1 and 2 threads,
/// minimum distances 0 and 0.01.
#[test]
fn scene_equals_direct_calls_every_method_mode_and_thread_count() {
    let bodies = bodies();
    for method in Method::ALL {
        let (mut scene, ids) = scene_of(method, &bodies);
        let hs: Vec<AnyHierarchy> = bodies
            .iter()
            .map(|b| AnyHierarchy::new(method, &b.mesh, Options::default()).unwrap())
            .collect();
        let motion = |i: usize| {
            Motion::new(
                &bodies[i].x0,
                bodies[i].x1.as_ref().unwrap_or(&bodies[i].x0),
            )
        };
        for (b, &id) in bodies.iter().zip(&ids) {
            assert_eq!(
                scene.positions_f64(id).unwrap(),
                b.x0,
                "stored pose, exactly"
            );
        }
        let m = motions(&bodies, &ids);
        for d in [0.0, 0.01] {
            let all = CcdQuery::all().with_min_distance(d);
            let mut ws = Workspace::default();
            let direct = |a: usize, b: usize, ws: &mut Workspace| {
                if a == b {
                    hs[a].self_ccd(motion(a), &all, ws, Par::Seq).unwrap()
                } else {
                    hs[a]
                        .ccd_pair(motion(a), &hs[b], motion(b), &all, ws, Par::Seq)
                        .unwrap()
                }
            };
            for self_on in [true, false] {
                scene.set_self_collision(ids[4], self_on).unwrap();
                let what = format!("{method:?} d={d} self={self_on}");
                let r = scene.ccd(&m, &all, Par::Seq).unwrap();
                check_shape(&r);
                assert_eq!(
                    r,
                    scene.ccd(&m, &all, Par::Rayon(2)).unwrap(),
                    "{what}: Seq == Rayon(2)"
                );
                assert_eq!(
                    r.per_pair.iter().any(|p| p.a == p.b),
                    self_on,
                    "{what}: the self job"
                );
                for i in 0..bodies.len() {
                    for j in i..bodies.len() {
                        if i == j && !(self_on && bodies[i].self_collision) {
                            continue;
                        }
                        let want = direct(i, j, &mut ws);
                        match r.per_pair.iter().find(|p| (p.a, p.b) == (ids[i], ids[j])) {
                            Some(p) => {
                                let what = format!("{what} ({i}, {j})");
                                assert_same_impacts(&p.impacts, &want, &what);
                                assert_eq!(p.impacts.counters.bv_tests, want.counters.bv_tests);
                                assert_eq!(p.impacts.counters.prim_tests, want.counters.prim_tests);
                            }
                            None => assert_eq!(pairs_of(&want), 0, "{what}: culled ({i}, {j})"),
                        }
                    }
                }
                let least = r.toi;
                assert!(least.is_some());
                let earliest = CcdQuery {
                    mode: CcdMode::Earliest,
                    ..all
                };
                let e = scene.ccd(&m, &earliest, Par::Seq).unwrap();
                let e2 = scene.ccd(&m, &earliest, Par::Rayon(2)).unwrap();
                assert_eq!(e.toi, least, "{what}: earliest = least of all mode");
                assert_eq!(e2.toi, least, "{what}: earliest, Rayon(2)");
                assert_eq!(e.per_pair.len(), r.per_pair.len());
                for ((p, q), pall) in e.per_pair.iter().zip(&e2.per_pair).zip(&r.per_pair) {
                    assert_eq!((p.a, p.b), (pall.a, pall.b));
                    assert_eq!((q.a, q.b), (pall.a, pall.b));
                    let want = earliest_of(&pall.impacts, least);
                    assert_same_impacts(&p.impacts, &want, &format!("{what} earliest Seq"));
                    assert_same_impacts(&q.impacts, &want, &format!("{what} earliest Rayon(2)"));
                }
                assert!(e.per_pair.iter().any(|p| pairs_of(&p.impacts) > 0));
            }
        }
    }
}

/// The listed objects' stored poses are not read: a motion from elsewhere counts, and the
/// scene is the same after the query.
#[test]
fn stored_pose_of_moving_objects_is_not_read() {
    let bodies = bodies();
    let (mut scene, ids) = scene_of(Method::Dh, &bodies);
    let m = motions(&bodies, &ids);
    let want = scene.ccd(&m, &CcdQuery::all(), Par::Seq).unwrap();
    // Move the bullet and the dropper far away in the stored pose: same result.
    for i in [1, 3] {
        let p = translated(bodies[i].mesh.positions(), [0.0, 40.0, 0.0]);
        scene.update_positions(ids[i], &p).unwrap();
    }
    let got = scene.ccd(&m, &CcdQuery::all(), Par::Seq).unwrap();
    assert_eq!(got.per_pair, want.per_pair);
    assert_eq!(got.toi, want.toi);
    // Without their motions, they stay still far away: only the sheet's own job is left.
    let only_sheet: Vec<_> = m.iter().copied().filter(|(id, _)| *id == ids[4]).collect();
    let r = scene.ccd(&only_sheet, &CcdQuery::all(), Par::Seq).unwrap();
    let jobs: Vec<_> = r.per_pair.iter().map(|p| (p.a, p.b)).collect();
    assert_eq!(jobs, [(ids[4], ids[4])]);
    assert_eq!(r.per_pair[0].impacts, want.per_pair[2].impacts);
    // No motion at all: the sheet alone at rest touches nothing.
    let r = scene.ccd(&[], &CcdQuery::all(), Par::Rayon(2)).unwrap();
    assert_eq!(r.toi, None);
    assert_eq!(r.per_pair.len(), 1);
    assert_eq!(pairs_of(&r.per_pair[0].impacts), 0);
}

/// Every bad input is an error before any work, and the scene is as it was.
#[test]
fn errors_change_nothing() {
    let bodies = bodies();
    let (mut scene, ids) = scene_of(Method::Aabb, &bodies);
    let m = motions(&bodies, &ids);
    let x0 = &bodies[1].x0;
    let short = &x0[..x0.len() - 1];
    let mut nan = bodies[1].x1.clone().unwrap();
    nan[5][2] = f64::NAN;
    let mut huge = x0.clone();
    huge[2][0] = 1e300;
    let before = (
        scene.contacts(Par::Seq),
        ids.iter()
            .map(|&id| scene.positions_f64(id).unwrap())
            .collect::<Vec<_>>(),
        ids.iter()
            .map(|&id| scene.bounds(id).unwrap())
            .collect::<Vec<_>>(),
    );
    let want = scene.ccd(&m, &CcdQuery::all(), Par::Seq).unwrap();
    let all = CcdQuery::all();
    type Case<'a> = (Vec<(ObjectId, Motion<'a>)>, CcdQuery, Error);
    let still = Motion::new(x0, x0);
    let cases: Vec<Case> = vec![
        (
            vec![m[0], (ObjectId(99), still)],
            all,
            Error::UnknownObject(99),
        ),
        (vec![m[0], m[1], m[0]], all, Error::RepeatedObject(ids[1].0)),
        (
            vec![m[1], (ids[1], Motion::new(short, x0))],
            all,
            Error::WrongVertexCount {
                expected: x0.len(),
                got: x0.len() - 1,
                of: Positions::Start,
                object: Some(ids[1].0),
            },
        ),
        (
            vec![(ids[1], Motion::new(x0, short))],
            all,
            Error::WrongVertexCount {
                expected: x0.len(),
                got: x0.len() - 1,
                of: Positions::End,
                object: Some(ids[1].0),
            },
        ),
        (
            vec![(ids[1], Motion::new(x0, &nan))],
            all,
            Error::NonFinite {
                vertex: 5,
                position: nan[5],
                of: Positions::End,
                object: Some(ids[1].0),
            },
        ),
        (
            vec![(ids[1], Motion::new(&huge, x0))],
            all,
            Error::OutOfRange {
                vertex: 2,
                position: huge[2],
                of: Positions::Start,
                object: Some(ids[1].0),
            },
        ),
        (
            m.clone(),
            all.with_min_distance(-0.1),
            Error::InvalidMinDistance(-0.1),
        ),
        (
            m.clone(),
            all.with_min_distance(f64::NAN),
            Error::InvalidMinDistance(f64::NAN),
        ),
        (m.clone(), all.with_t_max(1.5), Error::InvalidTimeLimit(1.5)),
    ];
    for (motions, query, error) in cases {
        for par in [Par::Seq, Par::Rayon(2)] {
            let got = scene.ccd(&motions, &query, par).unwrap_err();
            // NaN != NaN: compare the messages.
            assert_eq!(got.to_string(), error.to_string(), "{par:?}");
        }
    }
    let after = (
        scene.contacts(Par::Seq),
        ids.iter()
            .map(|&id| scene.positions_f64(id).unwrap())
            .collect::<Vec<_>>(),
        ids.iter()
            .map(|&id| scene.bounds(id).unwrap())
            .collect::<Vec<_>>(),
    );
    assert_eq!(after, before);
    assert_eq!(scene.ccd(&m, &CcdQuery::all(), Par::Seq).unwrap(), want);
}
