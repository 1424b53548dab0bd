//! Scenes of many deforming objects against brute force: every object pair, self-collision,
//! add/remove/update, ids, broad-phase culling, parallel == sequential, contact segments.

use dhcd::narrow::{brute_force_pairs, brute_force_self_pairs, intersection_segment};
use dhcd::scene::{ObjectId, Scene, SceneContacts};
use dhcd::shapes::{grid, icosphere, wave};
use dhcd::{Error, Mesh, Method, Options, Par};

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

#[test]
fn a_ring_of_touching_objects_runs_in_two_batches() {
    let m = icosphere(1, 1.0, [0.0; 3]);
    let mut scene = Scene::new(Method::Dh, Options::default());
    let n = 8;
    for k in 0..n {
        let id = scene.add(&m).unwrap();
        let a = k as f32 / n as f32 * std::f32::consts::TAU;
        let offset = [2.4 * a.cos(), 2.4 * a.sin(), 0.0];
        scene
            .update_positions(id, &dhcd::shapes::translated(m.positions(), offset))
            .unwrap();
    }
    let c = scene.contacts(Par::Rayon(2));
    assert_eq!(c.per_pair.len(), n, "neighbours only");
    assert_eq!(
        c.batches, 2,
        "first fit colours an even ring with two colours"
    );
    assert!(!c.pairs.is_empty());
}
