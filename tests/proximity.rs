//! Proximity queries: every vertex-triangle and edge-edge pair within a distance, exact,
//! equal to the brute force for every method and thread count, `f64` included.

use dhcd::bv::BoundingVolume;
use dhcd::narrow::{brute_force_proximity, brute_force_self_proximity};
use dhcd::shapes::{grid, icosphere, jitter, wave};
use dhcd::{
    for_each_method, proximity_with, self_proximity_with, Error, Hierarchy, Mesh, Options, Par,
    Proximity, Workspace,
};

fn with_positions(m: &Mesh, p: Vec<[f32; 3]>) -> Mesh {
    Mesh::new(p, m.triangles().to_vec()).unwrap()
}

/// The query's result equals the brute force's (pairs, distances, types), and every count
/// adds up.
fn assert_same(got: &Proximity, want: &Proximity, what: &str) {
    assert_eq!(got.vertex_face, want.vertex_face, "{what}: vertex-face");
    assert_eq!(got.face_vertex, want.face_vertex, "{what}: face-vertex");
    assert_eq!(got.edge_edge, want.edge_edge, "{what}: edge-edge");
    assert_eq!(got.counters.contacts, want.counters.contacts, "{what}");
    assert!(got.counters.prim_tests >= got.counters.contacts, "{what}");
}

fn pair_for<K: BoundingVolume>(a: &Mesh, b: &Mesh, distances: &[f64], what: &str) {
    let (ha, hb) = (
        Hierarchy::<K>::new(a, Options::default()).unwrap(),
        Hierarchy::<K>::new(b, Options::default()).unwrap(),
    );
    for &d in distances {
        let want = brute_force_proximity(a, b, d);
        for par in [Par::Seq, Par::Rayon(2)] {
            let got = proximity_with(&ha, &hb, d, &mut Workspace::default(), par).unwrap();
            assert_same(
                &got,
                &want,
                &format!("{what} {:?} d={d} {par:?}", K::METHOD),
            );
        }
    }
}

fn self_for<K: BoundingVolume>(m: &Mesh, distances: &[f64], what: &str) {
    let h = Hierarchy::<K>::new(m, Options::default()).unwrap();
    for &d in distances {
        let want = brute_force_self_proximity(m, d);
        for par in [Par::Seq, Par::Rayon(2)] {
            let got = self_proximity_with(&h, d, &mut Workspace::default(), par).unwrap();
            assert_same(
                &got,
                &want,
                &format!("{what} {:?} d={d} {par:?}", K::METHOD),
            );
        }
    }
}

#[test]
fn two_deformed_spheres_every_kind() {
    let a = icosphere(2, 1.0, [0.0; 3]);
    let b = icosphere(2, 0.8, [1.75, 0.1, 0.0]);
    let a = with_positions(&a, wave(a.positions(), 0.4, 0.05, [0.0; 3]));
    let b = with_positions(&b, jitter(b.positions(), [0.01; 3], 3));
    let ds = [0.0, 0.02, 0.1, 0.3];
    for_each_method!(K => pair_for::<K>(&a, &b, &ds, "spheres"));
}

/// A folded, jittered sheet: its layers come within the distance of each other, and every
/// neighbour (sharing a vertex) is excluded.
#[test]
fn folded_sheet_self_proximity_every_kind() {
    let g = grid(12, 12, 0.1, [0.0; 3]);
    let folded: Vec<[f32; 3]> = g
        .positions()
        .iter()
        .map(|p| {
            if p[0] > 0.6 {
                [1.2 - p[0], p[1], 0.05 + 0.02 * (p[1] * 9.0).sin()]
            } else {
                *p
            }
        })
        .collect();
    let m = with_positions(&g, jitter(&folded, [0.003; 3], 9));
    let ds = [0.0, 0.03, 0.08, 0.15];
    for_each_method!(K => self_for::<K>(&m, &ds, "folded sheet"));
}

/// Parallel grids `0.25` apart (exact in binary): at `d = 0.25` every vertex above a
/// triangle and every pair of overlapping parallel edges is within, at the `f64` just
/// below it none is.
#[test]
fn distance_equal_to_d_to_the_last_bit() {
    let a = grid(4, 4, 0.5, [0.0, 0.0, 0.0]);
    let b = grid(4, 4, 0.5, [0.0, 0.0, 0.25]);
    let at = 0.25f64;
    for_each_method!(K => {
        let (ha, hb) = (
            Hierarchy::<K>::new(&a, Options::default()).unwrap(),
            Hierarchy::<K>::new(&b, Options::default()).unwrap(),
        );
        let within = proximity_with(&ha, &hb, at, &mut Workspace::default(), Par::Seq).unwrap();
        assert_same(&within, &brute_force_proximity(&a, &b, at), "at d");
        assert!(!within.vertex_face.is_empty() && !within.edge_edge.is_empty());
        assert!(within.vertex_face.iter().all(|x| x.distance_sq == at * at));
        let below = proximity_with(&ha, &hb, at.next_down(), &mut Workspace::default(), Par::Seq)
            .unwrap();
        assert_eq!(below.counters.contacts, 0, "{:?}", K::METHOD);
    });
}

/// `f64` meshes: grids `1e-9` apart at `z = 1000`, where an `f32` ulp is `6e-5`: within
/// `1e-9` in `f64` (all of them), and the `f32` roundings would put them on one plane.
#[test]
fn f64_proximity_is_exact_for_the_f64_input() {
    let g = grid(5, 5, 0.5, [0.0, 0.0, 1000.0]);
    let pa: Vec<[f64; 3]> = g.positions().iter().map(|p| p.map(f64::from)).collect();
    let pb: Vec<[f64; 3]> = pa.iter().map(|p| [p[0], p[1], p[2] + 1e-9]).collect();
    let a = Mesh::new_f64(pa, g.triangles().to_vec()).unwrap();
    let b = Mesh::new_f64(pb, g.triangles().to_vec()).unwrap();
    assert_eq!(a.positions(), b.positions(), "the f32 roundings coincide");
    for_each_method!(K => {
        let (ha, hb) = (
            Hierarchy::<K>::new(&a, Options::default()).unwrap(),
            Hierarchy::<K>::new(&b, Options::default()).unwrap(),
        );
        for d in [1e-9, 0.9999e-9, 0.3] {
            let want = brute_force_proximity(&a, &b, d);
            let got = proximity_with(&ha, &hb, d, &mut Workspace::default(), Par::Rayon(2)).unwrap();
            assert_same(&got, &want, &format!("f64 {:?} d={d}", K::METHOD));
            assert_eq!(got.vertex_face.is_empty(), d < 1e-9, "d={d}");
        }
    });
}

#[test]
fn all_kinds_give_the_same_pairs() {
    let m = icosphere(3, 1.0, [0.0; 3]);
    let m = with_positions(&m, wave(m.positions(), 1.3, 0.4, [0.0; 3]));
    let mut results = Vec::new();
    for_each_method!(K => {
        let h = Hierarchy::<K>::new(&m, Options::default()).unwrap();
        let mut p = self_proximity_with(&h, 0.05, &mut Workspace::default(), Par::Rayon(2)).unwrap();
        p.counters = Default::default();
        results.push(p);
    });
    assert!(results.windows(2).all(|w| w[0] == w[1]));
    assert!(!results[0].vertex_face.is_empty());
}

#[test]
fn bad_distances_are_typed_errors() {
    let m = icosphere(1, 1.0, [0.0; 3]);
    let h = Hierarchy::<dhcd::bv::Dh>::new(&m, Options::default()).unwrap();
    for d in [
        -1.0,
        (-0.0f64).next_down(),
        f64::NAN,
        f64::INFINITY,
        f64::NEG_INFINITY,
    ] {
        let e = dhcd::self_proximity(&h, d).unwrap_err();
        assert!(matches!(e, Error::InvalidDistance(_)), "{d}: {e}");
        assert!(dhcd::proximity(&h, &h, d).is_err());
    }
    assert!(dhcd::self_proximity(&h, 0.0).is_ok());
    assert!(dhcd::self_proximity(&h, -0.0).is_ok());
}

/// A scene's proximity: the pairs of every object pair within the distance and of the
/// objects with self-collision on, each equal to the two-object (or self) query, for every
/// thread count; far objects cost one box test; refits credited to each object's first job.
#[test]
fn scene_proximity_equals_pair_queries() {
    use dhcd::scene::Scene;
    use dhcd::Method;
    let ball = icosphere(2, 1.0, [0.0; 3]);
    let at = |o: [f32; 3]| with_positions(&ball, wave(ball.positions(), o[0], 0.05, o));
    let meshes = [at([0.0; 3]), at([2.06, 0.0, 0.0]), at([50.0, 0.0, 0.0])];
    let d = 0.1;
    for method in Method::ALL {
        let mut firsts = None;
        for par in [Par::Seq, Par::Rayon(2)] {
            let mut scene = Scene::new(method, Options::default());
            let ids: Vec<_> = meshes.iter().map(|m| scene.add(m).unwrap()).collect();
            scene.set_self_collision(ids[0], true).unwrap();
            let p = scene.proximity(d, par).unwrap();
            let keys: Vec<_> = p.per_pair.iter().map(|x| (x.a, x.b)).collect();
            assert_eq!(keys, [(ids[0], ids[0]), (ids[0], ids[1])], "{method}");
            let self_want = brute_force_self_proximity(&meshes[0], d);
            let pair_want = brute_force_proximity(&meshes[0], &meshes[1], d);
            assert_same(&p.per_pair[0].proximity, &self_want, "scene self");
            assert_same(&p.per_pair[1].proximity, &pair_want, "scene pair");
            assert!(!pair_want.vertex_face.is_empty());
            let sum: dhcd::Counters = p.per_pair.iter().map(|x| x.proximity.counters).sum();
            assert_eq!(sum, p.counters);
            match &firsts {
                None => firsts = Some(p),
                Some(f) => assert_eq!(f, &p, "{method}: threads change nothing"),
            }
        }
        let mut scene = Scene::new(method, Options::default());
        scene.add(&meshes[0]).unwrap();
        assert!(matches!(
            scene.proximity(f64::NAN, Par::Seq),
            Err(Error::InvalidDistance(_))
        ));
    }
}
