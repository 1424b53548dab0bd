//! Self-collision against the brute-force oracle: folded and crumpled meshes, many poses,
//! every method and refit mode, parallel == sequential.

use dhcd::bv::{Aabb, BoundingVolume, Dh, Sphere};
use dhcd::calibration::Calibration;
use dhcd::narrow::brute_force_self_pairs;
use dhcd::shapes::{grid, icosphere, wave};
use dhcd::{
    for_each_method, self_collide, self_collide_with, CentralVertex, Hierarchy, Mesh, Options, Par,
    Refit, Workspace,
};

fn with_positions(mesh: &Mesh, positions: Vec<[f32; 3]>) -> Mesh {
    Mesh::new(positions, mesh.triangles().to_vec()).unwrap()
}

/// A `2n x n` grid folded over itself at x = 1 (the right half lies back over the flat left
/// one, rippled so that it crosses it along many lines), then waved.
fn folded_grid(n: u32, t: f32, amplitude: f32) -> (Mesh, Vec<[f32; 3]>) {
    let cell = 1.0 / n as f32;
    let flat = grid(2 * n, n, cell, [0.0; 3]);
    let folded: Vec<[f32; 3]> = flat
        .positions()
        .iter()
        .map(|&[x, y, z]| {
            if x > 1.0 {
                [2.0 - x, y, z + 0.12 * (7.0 * y + 3.0 * (x - 1.0)).sin()]
            } else {
                [x, y, z]
            }
        })
        .collect();
    let posed = wave(&folded, t, amplitude, [0.0; 3]);
    (flat, posed)
}

fn crumpled_sphere(subdivisions: u32, t: f32, amplitude: f32) -> (Mesh, Vec<[f32; 3]>) {
    let s = icosphere(subdivisions, 1.0, [0.0; 3]);
    let posed = wave(s.positions(), t, amplitude, [0.0; 3]);
    (s, posed)
}

/// Self-contacts of `posed` (a pose of `rest`) with method `K` equal brute force, after a
/// build on the rest pose and a lazy (or eager) update; invariants hold.
fn check<K: BoundingVolume>(rest: &Mesh, posed: &[[f32; 3]], options: Options) -> Vec<[u32; 2]> {
    let expected = brute_force_self_pairs(&with_positions(rest, posed.to_vec()));
    let mut h = Hierarchy::<K>::new(rest, options).unwrap();
    h.update_positions(posed).unwrap();
    let c = self_collide(&h);
    h.validate().unwrap();
    assert_eq!(c.pairs, expected, "{:?} {:?}", K::METHOD, options);
    assert_eq!(c.counters.contacts as usize, c.pairs.len());
    assert!(c.pairs.iter().all(|p| p[0] < p[1]));
    // A second query in the same pose refits nothing and finds the same.
    let again = self_collide(&h);
    assert_eq!(again.pairs, expected);
    assert_eq!(again.counters.bv_updates, 0);
    expected
}

fn check_all(rest: &Mesh, posed: &[[f32; 3]], levels: usize) -> usize {
    let mut found = 0;
    for refit in [Refit::Lazy, Refit::Eager, Refit::EagerBottomUp] {
        for central in CentralVertex::ALL {
            let options = Options {
                levels: Some(levels),
                refit,
                central,
                ..Options::default()
            };
            for_each_method!(K => found = check::<K>(rest, posed, options).len());
        }
    }
    found
}

#[test]
fn folded_grid_equals_brute_force() {
    let mut total = 0;
    for step in 0..6 {
        let (rest, posed) = folded_grid(8, step as f32 * 0.7, 0.04);
        for levels in [1, 3, 5] {
            total += check_all(&rest, &posed, levels);
        }
    }
    assert!(total > 0, "the folded layers must cross somewhere");
}

#[test]
fn crumpled_sphere_equals_brute_force() {
    let mut total = 0;
    for step in 0..5 {
        let (rest, posed) = crumpled_sphere(3, step as f32 * 0.9, 0.6);
        for levels in [2, 5] {
            total += check_all(&rest, &posed, levels);
        }
    }
    assert!(total > 0, "a strongly crumpled sphere intersects itself");
}

#[test]
fn smooth_sphere_has_no_self_contacts() {
    let s = icosphere(3, 1.0, [0.0; 3]);
    let h = Hierarchy::<Dh>::new(&s, Options::default()).unwrap();
    let c = self_collide(&h);
    assert!(c.pairs.is_empty());
    assert!(c.counters.bv_tests > 0);
    assert!(c.counters.prim_tests > 0, "neighbouring leaves are tested");
}

#[test]
fn single_triangle_and_shared_vertices() {
    let one = Mesh::new(
        vec![[0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]],
        vec![[0, 1, 2]],
    )
    .unwrap();
    let h = Hierarchy::<Aabb>::new(&one, Options::default()).unwrap();
    let c = self_collide(&h);
    assert!(c.pairs.is_empty());
    assert_eq!(c.counters.prim_tests, 0);
    // Two coplanar overlapping triangles that share vertex 0: excluded; a third crossing
    // both without sharing: reported with each.
    let m = Mesh::new(
        vec![
            [0.0, 0.0, 0.0],
            [2.0, 0.0, 0.0],
            [0.0, 2.0, 0.0],
            [2.0, 2.0, 0.0],
            [0.5, 0.5, -1.0],
            [0.6, 0.5, 1.0],
            [0.5, 0.6, 1.0],
        ],
        vec![[0, 1, 2], [0, 3, 2], [4, 5, 6]],
    )
    .unwrap();
    for levels in [1, 2, 3] {
        let options = Options {
            levels: Some(levels),
            ..Options::default()
        };
        let expected = brute_force_self_pairs(&m);
        assert_eq!(expected, vec![[0, 2], [1, 2]]);
        assert_eq!(
            self_collide(&Hierarchy::<Dh>::new(&m, options).unwrap()).pairs,
            expected
        );
        assert_eq!(
            self_collide(&Hierarchy::<Sphere>::new(&m, options).unwrap()).pairs,
            expected
        );
        assert_eq!(
            self_collide(&Hierarchy::<Aabb>::new(&m, options).unwrap()).pairs,
            expected
        );
    }
}

/// A deforming crumpling sequence with the given parallelism and grain.
fn sequence<K: BoundingVolume>(par: Par, grain: usize) -> Vec<dhcd::Contacts> {
    let s = icosphere(3, 1.0, [0.0; 3]);
    let mut h = Hierarchy::<K>::new(&s, Options::default()).unwrap();
    let mut ws = Workspace::with_grain(grain);
    (0..5)
        .map(|step| {
            h.update_positions(&wave(s.positions(), step as f32 * 0.8, 0.5, [0.0; 3]))
                .unwrap();
            let c = self_collide_with(&h, &mut ws, par);
            h.validate().unwrap();
            c
        })
        .collect()
}

fn parallel_equals_sequential_for<K: BoundingVolume>() {
    let seq = sequence::<K>(Par::Seq, 1024);
    assert!(seq.iter().any(|c| !c.pairs.is_empty()));
    for threads in [1, 2, 3] {
        for grain in [1, 7, 1024] {
            assert_eq!(
                sequence::<K>(Par::Rayon(threads), grain),
                seq,
                "{threads} threads, grain {grain}"
            );
        }
    }
    assert_eq!(sequence::<K>(Par::Ambient, 3), seq);
}

#[test]
fn parallel_equals_sequential_dh() {
    parallel_equals_sequential_for::<Dh>();
}

#[test]
fn parallel_equals_sequential_sphere() {
    parallel_equals_sequential_for::<Sphere>();
}

#[test]
fn parallel_equals_sequential_aabb() {
    parallel_equals_sequential_for::<Aabb>();
}

#[test]
fn any_hierarchy_self_collide_matches_generic() {
    let (rest, posed) = crumpled_sphere(2, 1.0, 0.6);
    let expected = brute_force_self_pairs(&with_positions(&rest, posed.clone()));
    for method in dhcd::Method::ALL {
        let mut h = dhcd::AnyHierarchy::new(method, &rest, Options::default()).unwrap();
        h.update_positions(&posed).unwrap();
        let c = h.self_collide(&mut Workspace::default(), Par::Seq);
        assert_eq!(c.pairs, expected, "{method}");
    }
}

/// The self broad phase is the self query without its triangle tests: the same node tests,
/// refits and counted triangle pairs, no contacts, leaf pairs `[x, y]` with `x <= y` (a leaf
/// with itself included), the same for every thread count.
fn self_broad_phase_matches_query_for<K: BoundingVolume>() {
    let (rest, _) = folded_grid(12, 0.0, 0.0);
    let mut found_pairs = false;
    for step in 0..3 {
        let (_, posed) = folded_grid(12, step as f32, 0.05);
        let mut whole = Hierarchy::<K>::new(&rest, Options::default()).unwrap();
        whole.update_positions(&posed).unwrap();
        let want = self_collide(&whole).counters;
        let mut first: Option<Vec<[u32; 2]>> = None;
        for par in [Par::Seq, Par::Rayon(2), Par::Rayon(3)] {
            let mut h = Hierarchy::<K>::new(&rest, Options::default()).unwrap();
            h.update_positions(&posed).unwrap();
            let mut ws = Workspace::default();
            let broad = h.self_broad_phase(&mut ws, par);
            let got = broad.counters;
            assert_eq!(got.bv_tests, want.bv_tests, "{:?} {par:?}", K::METHOD);
            assert_eq!(got.bv_updates, want.bv_updates, "{:?} {par:?}", K::METHOD);
            assert_eq!(got.prim_tests, want.prim_tests, "{:?} {par:?}", K::METHOD);
            assert_eq!(got.contacts, 0);
            // Sequential runs list them in walk order, parallel ones sorted.
            let mut leaves = broad.leaf_pairs.clone();
            leaves.sort_unstable();
            let tree = h.tree();
            assert!(leaves
                .iter()
                .all(|&[x, y]| x <= y && tree.is_leaf(x as usize) && tree.is_leaf(y as usize)));
            found_pairs |= leaves.iter().any(|&[x, y]| x != y);
            h.validate().unwrap();
            match &first {
                None => first = Some(leaves),
                Some(f) => assert_eq!(&leaves, f, "{:?} {par:?}", K::METHOD),
            }
        }
    }
    assert!(
        found_pairs,
        "the folded grid has distinct overlapping leaves"
    );
}

#[test]
fn self_broad_phase_matches_query() {
    self_broad_phase_matches_query_for::<Dh>();
    self_broad_phase_matches_query_for::<Sphere>();
    self_broad_phase_matches_query_for::<Aabb>();
}
