//! Free points: vertices that no triangle uses (particles, markers a simulator adds to a
//! mesh) are points to the feature queries. Proximity and CCD pair each with every triangle
//! (self, pair and scene queries, every method, 1 and 2 threads), equal to the brute force,
//! and the region tree's bounds hold them.

use dhcd::bv::BoundingVolume;
use dhcd::narrow::{
    brute_force_ccd, brute_force_proximity, brute_force_self_ccd, brute_force_self_proximity,
};
use dhcd::scene::Scene;
use dhcd::shapes::{grid, jitter, wave};
use dhcd::{
    ccd_pair_with, for_each_method, proximity_with, self_ccd_with, self_proximity_with, CcdQuery,
    Hierarchy, Mesh, Method, Motion, Options, Par, Workspace,
};

/// One triangle and a vertex 0.5 above it that no triangle uses.
fn triangle_and_point(z: f64) -> Mesh {
    Mesh::new_f64(
        vec![
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [0.25, 0.25, z],
        ],
        vec![[0, 1, 2]],
    )
    .unwrap()
}

/// The red team's case: a free vertex 0.5 above the only triangle, falling through it. It is
/// within 1.0 of the triangle (distance 0.5) and crosses it at t = 1/2.
#[test]
fn a_free_vertex_falling_through_the_only_triangle() {
    let m = triangle_and_point(0.5);
    let x0 = m.positions_f64().unwrap().to_vec();
    let mut x1 = x0.clone();
    x1[3][2] = -0.5;
    for_each_method!(K => {
        let h = Hierarchy::<K>::new(&m, Options::default()).unwrap();
        h.validate().unwrap();
        for par in [Par::Seq, Par::Rayon(2)] {
            let ws = &mut Workspace::default();
            let p = self_proximity_with(&h, 1.0, ws, par).unwrap();
            assert_eq!(p.vertex_face.len(), 1, "{:?}", K::METHOD);
            assert_eq!((p.vertex_face[0].vertex, p.vertex_face[0].triangle), (3, 0));
            assert_eq!(p.vertex_face[0].distance_sq, 0.25);
            for query in [CcdQuery::all(), CcdQuery::earliest()] {
                let c = self_ccd_with(&h, Motion::new(&x0, &x1), &query, ws, par).unwrap();
                assert_eq!(c.vertex_face.len(), 1, "{:?} {query:?}", K::METHOD);
                assert_eq!((c.vertex_face[0].vertex, c.vertex_face[0].triangle), (3, 0));
                let toi = c.toi.unwrap();
                assert!(toi <= 0.5 && 0.5 - toi <= dhcd::ccd::TOI_TOLERANCE, "{toi}");
            }
        }
    });
}

/// A wavy sheet with free points scattered above, below, inside its box and far away, some
/// of them sharing the index range of the triangles' vertices.
fn sheet_with_points() -> Mesh {
    let g = grid(6, 6, 0.2, [0.0; 3]);
    let wavy = wave(g.positions(), 0.3, 0.05, [0.0; 3]);
    let mut p = jitter(&wavy, [0.01; 3], 5);
    let n = p.len() as u32;
    // Free points: every third one between the sheet's vertices (the triangles are
    // renumbered around them), the rest after.
    let extra: Vec<[f32; 3]> = (0..24)
        .map(|k| {
            let k = k as f32;
            match k as usize % 4 {
                0 => [0.1 + 0.05 * k, 0.6, 0.04],
                1 => [0.5, 0.1 + 0.04 * k, -0.03],
                2 => [0.3 + 0.01 * k, 0.3, 0.2],
                _ => [40.0 + k, -7.0, 3.0],
            }
        })
        .collect();
    let mut tris: Vec<[u32; 3]> = g.triangles().to_vec();
    for (k, q) in extra.into_iter().enumerate() {
        if k % 3 == 0 {
            // Insert before vertex `at`: shift the triangles' indices at or above it.
            let at = (k as u32 * 5) % n;
            p.insert(at as usize, q);
            for t in &mut tris {
                for v in t.iter_mut() {
                    if *v >= at {
                        *v += 1;
                    }
                }
            }
        } else {
            p.push(q);
        }
    }
    Mesh::new(p, tris).unwrap()
}

fn moved(m: &Mesh, by: impl Fn(usize, [f64; 3]) -> [f64; 3]) -> Vec<[f64; 3]> {
    m.positions()
        .iter()
        .enumerate()
        .map(|(i, p)| by(i, p.map(f64::from)))
        .collect()
}

fn every_query_equals_the_brute_force<K: BoundingVolume>(m: &Mesh, other: &Mesh) {
    let method = K::METHOD;
    let h = Hierarchy::<K>::new(m, Options::default()).unwrap();
    let ho = Hierarchy::<K>::new(other, Options::default()).unwrap();
    h.validate().unwrap();
    let x0 = moved(m, |_, p| p);
    // Free points move down through the sheet, the sheet a little up.
    let x1 = moved(m, |i, p| {
        let free = !m.triangles().iter().any(|t| t.contains(&(i as u32)));
        if free {
            [p[0] + 0.02, p[1], p[2] - 0.3]
        } else {
            [p[0], p[1], p[2] + 0.02]
        }
    });
    let o0 = moved(other, |_, p| p);
    let o1 = moved(other, |_, p| [p[0], p[1], p[2] + 0.25]);
    for par in [Par::Seq, Par::Rayon(2)] {
        let ws = &mut Workspace::default();
        for d in [0.0, 0.03, 0.1] {
            let got = self_proximity_with(&h, d, ws, par).unwrap();
            let want = brute_force_self_proximity(m, d);
            assert_eq!(
                got.vertex_face, want.vertex_face,
                "{method:?} d={d} {par:?}"
            );
            assert_eq!(got.edge_edge, want.edge_edge, "{method:?} d={d} {par:?}");
            let got = proximity_with(&h, &ho, d, ws, par).unwrap();
            let want = brute_force_proximity(m, other, d);
            assert_eq!(
                got.vertex_face, want.vertex_face,
                "{method:?} d={d} {par:?}"
            );
            assert_eq!(
                got.face_vertex, want.face_vertex,
                "{method:?} d={d} {par:?}"
            );
            assert_eq!(got.edge_edge, want.edge_edge, "{method:?} d={d} {par:?}");
        }
        let query = CcdQuery::all();
        let got = self_ccd_with(&h, Motion::new(&x0, &x1), &query, ws, par).unwrap();
        let want = brute_force_self_ccd(m, Motion::new(&x0, &x1), &query.options);
        assert!(got.vertex_face.iter().any(|x| x.vertex as usize >= 36));
        assert_eq!(got.vertex_face, want.vertex_face, "{method:?} {par:?}");
        assert_eq!(got.edge_edge, want.edge_edge, "{method:?} {par:?}");
        let (m0, m1) = (Motion::new(&x0, &x1), Motion::new(&o0, &o1));
        let got = ccd_pair_with(&h, m0, &ho, m1, &query, ws, par).unwrap();
        let want = brute_force_ccd(m, m0, other, m1, &query.options);
        assert_eq!(got.vertex_face, want.vertex_face, "{method:?} {par:?}");
        assert_eq!(got.face_vertex, want.face_vertex, "{method:?} {par:?}");
        assert_eq!(got.edge_edge, want.edge_edge, "{method:?} {par:?}");
    }
}

#[test]
fn free_points_equal_the_brute_force_every_method() {
    let m = sheet_with_points();
    // The other object: a sheet just below, with a free point of its own above `m`.
    let g = grid(4, 4, 0.3, [0.05, 0.05, -0.12]);
    let mut p = g.positions().to_vec();
    p.push([0.5, 0.5, 0.08]);
    let other = Mesh::new(p, g.triangles().to_vec()).unwrap();
    for_each_method!(K => every_query_equals_the_brute_force::<K>(&m, &other));
}

/// Every levels setting and leaf size: the tree puts each free point in exactly one leaf, the
/// bounds hold it after refits, and self-proximity still equals the brute force.
#[test]
fn free_points_in_every_tree_shape() {
    let m = sheet_with_points();
    for options in [
        Options::paper(),
        Options {
            leaf_size: 1,
            ..Options::default()
        },
        Options {
            leaf_size: 7,
            ..Options::default()
        },
    ] {
        for_each_method!(K => {
            let mut h = Hierarchy::<K>::new(&m, options).unwrap();
            h.tree().check_topology(&m).unwrap();
            let moved: Vec<[f32; 3]> = m.positions().iter().map(|p| [p[0], p[1] + 0.1, -p[2]]).collect();
            h.update_positions(&moved).unwrap();
            h.validate().unwrap();
            let want = brute_force_self_proximity(&Mesh::new(moved.clone(), m.triangles().to_vec()).unwrap(), 0.05);
            let got = self_proximity_with(&h, 0.05, &mut Workspace::default(), Par::Seq).unwrap();
            assert_eq!(got.vertex_face, want.vertex_face, "{:?} {options:?}", K::METHOD);
        });
    }
}

/// A scene: the free vertex of one object falls through another object's triangle; scene
/// proximity and CCD report it, equal to the pair query.
#[test]
fn scene_queries_see_free_points() {
    let point_only = triangle_and_point(0.5);
    // The first object's triangle far away; its free point above the second's triangle.
    let a = Mesh::new_f64(
        vec![
            [9.0, 9.0, 9.0],
            [10.0, 9.0, 9.0],
            [9.0, 10.0, 9.0],
            [0.25, 0.25, 0.3],
        ],
        vec![[0, 1, 2]],
    )
    .unwrap();
    let b = point_only;
    for method in Method::ALL {
        let mut scene = Scene::new(method, Options::default());
        let (ia, ib) = (scene.add(&a).unwrap(), scene.add(&b).unwrap());
        let p = scene.proximity(0.31, Par::Seq).unwrap();
        let pair = p
            .per_pair
            .iter()
            .find(|x| (x.a, x.b) == (ia, ib))
            .expect("the pair is within the distance");
        assert!(pair
            .proximity
            .vertex_face
            .iter()
            .any(|x| (x.vertex, x.triangle) == (3, 0)));
        let x0 = a.positions_f64().unwrap().to_vec();
        let mut x1 = x0.clone();
        x1[3][2] = -0.3;
        let hits = scene
            .ccd(
                &[(ia, Motion::new(&x0, &x1))],
                &CcdQuery::all(),
                Par::Rayon(2),
            )
            .unwrap();
        let pair = hits
            .per_pair
            .iter()
            .find(|x| (x.a, x.b) == (ia, ib))
            .expect("the free point crosses the triangle");
        assert_eq!(
            pair.impacts
                .vertex_face
                .iter()
                .map(|x| (x.vertex, x.triangle))
                .collect::<Vec<_>>(),
            [(3, 0)],
            "{method}"
        );
    }
}
