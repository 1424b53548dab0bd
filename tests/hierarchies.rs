//! The hierarchies against the exact brute-force oracle: every method, many poses, deforming
//! sequences, all refit modes, bad input.

use dhcd::bv::{Aabb, BoundingVolume, Dh, Sphere};
use dhcd::calibration::Calibration;
use dhcd::narrow::brute_force_pairs;
use dhcd::shapes::{grid, icosphere, translated, wave};
use dhcd::{
    collide, for_each_method, CentralVertex, Error, Hierarchy, Mesh, Method, Options, Refit,
    RegionTree,
};
use proptest::prelude::*;

const MODES: [Refit; 3] = [Refit::Lazy, Refit::Eager, Refit::EagerBottomUp];

fn with_positions(mesh: &Mesh, positions: Vec<[f32; 3]>) -> Mesh {
    Mesh::new(positions, mesh.triangles().to_vec()).unwrap()
}

/// Collides `a` and `b` (rest poses) with method `K`, checks invariants, returns the pairs.
fn pairs_of<K: BoundingVolume>(a: &Mesh, b: &Mesh, options: Options) -> Vec<[u32; 2]> {
    let ha = Hierarchy::<K>::new(a, options).unwrap();
    let hb = Hierarchy::<K>::new(b, options).unwrap();
    ha.tree().check_topology(a).unwrap();
    ha.validate().unwrap();
    hb.validate().unwrap();
    let c = collide(&ha, &hb);
    ha.validate().unwrap();
    hb.validate().unwrap();
    assert_eq!(c.counters.contacts as usize, c.pairs.len());
    assert!(
        c.pairs.windows(2).all(|w| w[0] < w[1]),
        "pairs sorted, unique"
    );
    c.pairs
}

/// Every method returns exactly the brute-force set.
fn assert_exact(a: &Mesh, b: &Mesh, levels: usize) -> Vec<[u32; 2]> {
    let expected = brute_force_pairs(a, b);
    let options = Options {
        levels: Some(levels),
        ..Options::default()
    };
    for_each_method!(K => assert_eq!(
        pairs_of::<K>(a, b, options),
        expected,
        "{}, levels {levels}",
        K::METHOD
    ));
    expected
}

#[test]
fn overlapping_spheres_equal_brute_force() {
    let a = icosphere(2, 1.0, [0.0, 0.0, 0.0]);
    for (dx, dy) in [(1.3, 0.0), (1.0, 0.5), (0.2, 0.1), (1.85, 0.0)] {
        let b = icosphere(2, 1.0, [dx, dy, 0.1]);
        for levels in [1, 2, 5, 7] {
            let pairs = assert_exact(&a, &b, levels);
            assert!(!pairs.is_empty(), "offset ({dx}, {dy}) must intersect");
        }
    }
}

#[test]
fn far_apart_and_nested_have_no_contacts() {
    let a = icosphere(2, 1.0, [0.0, 0.0, 0.0]);
    assert!(assert_exact(&a, &icosphere(2, 1.0, [5.0, 0.0, 0.0]), 5).is_empty());
    // Nested: every BV of the inner sphere lies inside the outer's root, none touch.
    assert!(assert_exact(&a, &icosphere(2, 0.5, [0.1, 0.0, 0.0]), 5).is_empty());
}

#[test]
fn coincident_copies() {
    let a = icosphere(1, 1.0, [0.0, 0.0, 0.0]);
    let pairs = assert_exact(&a, &a.clone(), 5);
    // Every triangle meets itself and its neighbours.
    for t in 0..a.triangle_count() as u32 {
        assert!(pairs.binary_search(&[t, t]).is_ok());
    }
}

#[test]
fn touching_grids() {
    // Two grids in the same plane sharing one edge line x = 4 exactly.
    let a = grid(4, 4, 1.0, [0.0, 0.0, 0.0]);
    let b = grid(4, 4, 1.0, [4.0, 0.0, 0.0]);
    assert!(!assert_exact(&a, &b, 5).is_empty());
    // Perpendicular grid touching a along one line.
    let c = Mesh::new(
        a.positions().iter().map(|p| [p[0], 2.0, p[1]]).collect(),
        a.triangles().to_vec(),
    )
    .unwrap();
    assert!(!assert_exact(&a, &c, 5).is_empty());
    // A grid just above: no contact; exactly on: contact.
    let up = with_positions(&a, translated(a.positions(), [0.5, 0.5, 1e-6]));
    assert!(assert_exact(&a, &up, 5).is_empty());
    let on = with_positions(&a, translated(a.positions(), [0.5, 0.5, 0.0]));
    assert!(!assert_exact(&a, &on, 5).is_empty());
}

#[test]
fn degenerate_triangles_at_build() {
    // A fan with a collinear (zero-area) triangle and a point-like triangle.
    let positions = vec![
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [2.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [0.5, 0.5, 0.0],
        [0.5, 0.5, 0.0],
        [0.5, 0.5, 0.0],
    ];
    let a = Mesh::new(positions, vec![[0, 1, 2], [0, 1, 3], [4, 5, 6]]).unwrap();
    let b = grid(2, 2, 0.75, [-0.25, -0.25, 0.0]);
    let pairs = assert_exact(&a, &b, 3);
    assert!(
        pairs.iter().any(|p| p[0] == 0),
        "the segment triangle touches the grid"
    );
    assert!(
        pairs.iter().any(|p| p[0] == 2),
        "the point triangle touches the grid"
    );
}

/// A deforming sequence: two spheres wobble through each other for `steps` steps; every step
/// compares every method and refit mode with brute force and checks invariants after refit.
fn deforming_sequence<K: BoundingVolume>(
    refit: Refit,
    central: CentralVertex,
    steps: usize,
) -> Vec<Vec<[u32; 2]>> {
    let a = icosphere(2, 1.0, [0.0, 0.0, 0.0]);
    let b = icosphere(2, 0.8, [0.0, 0.0, 0.0]);
    let options = Options {
        levels: Some(5),
        refit,
        central,
        ..Options::default()
    };
    let mut ha = Hierarchy::<K>::new(&a, options).unwrap();
    let mut hb = Hierarchy::<K>::new(&b, options).unwrap();
    let mut all = Vec::new();
    for step in 0..steps {
        let t = step as f32 * 0.3;
        let pa = wave(a.positions(), t, 0.15, [0.0, 0.0, 0.0]);
        let pb = wave(b.positions(), -t, 0.2, [2.2 - 0.08 * step as f32, 0.1, 0.0]);
        ha.update_positions(&pa).unwrap();
        hb.update_positions(&pb).unwrap();
        if refit != Refit::Lazy {
            assert_eq!(
                ha.validate().unwrap(),
                ha.node_count(),
                "eager refit fits all"
            );
        }
        let c = collide(&ha, &hb);
        ha.validate().unwrap();
        hb.validate().unwrap();
        let expected = brute_force_pairs(&with_positions(&a, pa), &with_positions(&b, pb));
        assert_eq!(c.pairs, expected, "{:?} {refit:?} step {step}", K::METHOD);
        if refit == Refit::Lazy {
            assert!(
                c.counters.bv_updates > 0 && c.counters.bv_updates <= 2 * ha.node_count() as u64
            );
        }
        all.push(c.pairs);
    }
    all
}

#[test]
fn deforming_sequences_all_kinds_all_refit_modes() {
    for refit in MODES {
        let dh = deforming_sequence::<Dh>(refit, CentralVertex::default(), 24);
        assert!(
            dh.iter().filter(|p| !p.is_empty()).count() > 10,
            "the spheres must meet"
        );
        for central in CentralVertex::ALL {
            for_each_method!(K => if K::METHOD != Method::Dh || central != CentralVertex::default() {
                assert_eq!(dh, deforming_sequence::<K>(refit, central, 24));
            });
        }
    }
}

#[test]
fn collapse_to_degenerate_during_deformation() {
    let a = grid(3, 3, 1.0, [0.0, 0.0, 0.0]);
    let b = grid(3, 3, 1.0, [0.5, 0.5, 0.0]);
    let mut hb = Hierarchy::<Dh>::new(&b, Options::default()).unwrap();
    let ha = Hierarchy::<Dh>::new(&a, Options::default()).unwrap();
    // Flatten b onto a line (every triangle becomes a segment), lifted so it crosses a.
    let flat: Vec<[f32; 3]> = b
        .positions()
        .iter()
        .map(|p| [p[0], 1.25, p[1] - 1.5])
        .collect();
    hb.update_positions(&flat).unwrap();
    let c = collide(&ha, &hb);
    hb.validate().unwrap();
    assert_eq!(c.pairs, brute_force_pairs(&a, &with_positions(&b, flat)));
    assert!(!c.pairs.is_empty());
}

#[test]
fn record_sizes_and_memory() {
    assert_eq!(std::mem::size_of::<dhcd::bv::DhNode>(), 8);
    assert_eq!(std::mem::size_of::<dhcd::bv::SphereNode>(), 16);
    assert_eq!(std::mem::size_of::<dhcd::bv::AabbNode>(), 24);
    let m = icosphere(3, 1.0, [0.0; 3]);
    let dh = Hierarchy::<Dh>::new(&m, Options::paper()).unwrap();
    let sp = Hierarchy::<Sphere>::new(&m, Options::paper()).unwrap();
    let bx = Hierarchy::<Aabb>::new(&m, Options::paper()).unwrap();
    assert_eq!(dh.bv_bytes(), 8 * dh.node_count());
    assert_eq!(sp.bv_bytes(), 16 * dh.node_count());
    assert_eq!(bx.bv_bytes(), 24 * dh.node_count());
    assert_eq!(Method::Dh.bytes_per_node(), 8);
    assert_eq!(dh.tree().depth_count(), 5);
}

#[test]
fn shared_tree_gives_identical_regions() {
    let m = icosphere(2, 1.0, [0.0; 3]);
    let tree =
        std::sync::Arc::new(RegionTree::build(&m, dhcd::tree::TreeShape::Levels(4)).unwrap());
    let dh = Hierarchy::<Dh>::with_tree(tree.clone(), &m, Options::default()).unwrap();
    let bx = Hierarchy::<Aabb>::with_tree(tree.clone(), &m, Options::default()).unwrap();
    assert!(std::sync::Arc::ptr_eq(dh.tree(), bx.tree()));
    let other = icosphere(1, 1.0, [0.0; 3]);
    assert!(matches!(
        Hierarchy::<Dh>::with_tree(tree, &other, Options::default()),
        Err(Error::TreeMismatch { .. })
    ));
}

#[test]
fn dh_central_vertex_is_closest_to_region_centroid() {
    let m = icosphere(2, 1.0, [0.0; 3]);
    let h = Hierarchy::<Dh>::new(&m, Options::default()).unwrap();
    let tree = h.tree();
    let p = h.points();
    for n in 0..h.node_count() {
        let verts: Vec<u32> = tree.region_vertices(n).collect();
        let mean: [f64; 3] = std::array::from_fn(|k| {
            verts
                .iter()
                .map(|&v| p.get(v as usize)[k] as f64)
                .sum::<f64>()
                / verts.len() as f64
        });
        let d = |v: u32| -> f64 {
            (0..3)
                .map(|k| (p.get(v as usize)[k] as f64 - mean[k]).powi(2))
                .sum()
        };
        let c = h.record(n).unwrap().vertex;
        assert!(verts.contains(&c));
        assert!(verts.iter().all(|&v| d(c) <= d(v)), "node {n}");
    }
}

#[test]
fn lazy_refit_updates_only_tested_nodes() {
    let a = icosphere(3, 1.0, [0.0; 3]);
    let b = icosphere(3, 1.0, [10.0, 0.0, 0.0]);
    let mut ha = Hierarchy::<Dh>::new(&a, Options::default()).unwrap();
    let mut hb = Hierarchy::<Dh>::new(&b, Options::default()).unwrap();
    ha.update_positions(&wave(a.positions(), 1.0, 0.1, [0.0; 3]))
        .unwrap();
    hb.update_positions(&wave(b.positions(), 1.0, 0.1, [0.0; 3]))
        .unwrap();
    let c = collide(&ha, &hb);
    // Far apart: only the roots are tested, so only the roots are refitted.
    assert_eq!(c.counters.bv_tests, 1);
    assert_eq!(c.counters.bv_updates, 2);
    assert_eq!(ha.validate().unwrap(), 1);
    // A second query in the same step refits nothing.
    assert_eq!(collide(&ha, &hb).counters.bv_updates, 0);
}

#[test]
fn bad_mesh_input_is_a_typed_error() {
    let p = vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
    assert_eq!(Mesh::new(vec![], vec![[0, 1, 2]]), Err(Error::NoVertices));
    assert_eq!(Mesh::new(p.clone(), vec![]), Err(Error::NoTriangles));
    assert!(matches!(
        Mesh::new(p.clone(), vec![[0, 1, 3]]),
        Err(Error::IndexOutOfRange {
            triangle: 0,
            index: 3,
            vertex_count: 3
        })
    ));
    assert!(matches!(
        Mesh::new(p.clone(), vec![[0, 1, 1]]),
        Err(Error::RepeatedIndex { .. })
    ));
    for bad in [f32::NAN, f32::INFINITY, f32::NEG_INFINITY] {
        let mut q = p.clone();
        q[1][2] = bad;
        assert!(matches!(
            Mesh::new(q, vec![[0, 1, 2]]),
            Err(Error::NonFinite { vertex: 1, .. })
        ));
    }
    let m = Mesh::new(p, vec![[0, 1, 2]]).unwrap();
    for levels in [0, 17] {
        assert_eq!(
            Hierarchy::<Dh>::new(
                &m,
                Options {
                    levels: Some(levels),
                    ..Options::default()
                }
            )
            .err(),
            Some(Error::InvalidLevels {
                got: levels,
                max: dhcd::tree::MAX_LEVELS
            })
        );
    }
    // Messages are one clear line.
    let msg = Error::IndexOutOfRange {
        triangle: 4,
        index: 9,
        vertex_count: 3,
    }
    .to_string();
    assert!(msg.contains("triangle 4") && msg.contains('9') && !msg.contains('\n'));
}

/// Every non-finite coordinate is found, wherever it is (the check folds chunks of
/// coordinates without a branch per vertex): first, last, across a chunk boundary, each axis,
/// NaN and both infinities; the first culprit is the one reported.
#[test]
fn every_non_finite_coordinate_is_found() {
    let mesh = icosphere(4, 1.0, [0.0; 3]);
    let n = mesh.vertex_count();
    assert!(3 * n > 2 * 1024, "several chunks");
    let mut h = Hierarchy::<Aabb>::new(&mesh, Options::default()).unwrap();
    for bad in [f32::NAN, f32::INFINITY, f32::NEG_INFINITY] {
        for vertex in [0, 1, 340, 341, 342, 682, 683, n / 2, n - 1] {
            for axis in 0..3 {
                let mut p = mesh.positions().to_vec();
                p[vertex][axis] = bad;
                let got = h.update_positions(&p);
                assert!(
                    matches!(got, Err(Error::NonFinite { vertex: v, .. }) if v == vertex),
                    "{bad} at vertex {vertex} axis {axis}: {got:?}"
                );
                // A later culprit too: the first is reported.
                p[n - 1][2] = f32::NAN;
                let got = h.update_positions(&p);
                assert!(
                    matches!(got, Err(Error::NonFinite { vertex: v, .. }) if v == vertex),
                    "{bad} at vertex {vertex} axis {axis}, NaN last: {got:?}"
                );
            }
        }
    }
    h.update_positions(mesh.positions()).unwrap();
    h.validate().unwrap();
}

#[test]
fn bad_update_is_an_error_and_changes_nothing() {
    let a = icosphere(2, 1.0, [0.0; 3]);
    let b = icosphere(2, 1.0, [1.5, 0.0, 0.0]);
    for method in Method::ALL {
        let mut ha = dhcd::AnyHierarchy::new(method, &a, Options::default()).unwrap();
        let hb = dhcd::AnyHierarchy::new(method, &b, Options::default()).unwrap();
        let mut ws = dhcd::Workspace::default();
        let before = ha.collide(&hb, &mut ws, dhcd::Par::Seq).unwrap().pairs;
        let n = a.vertex_count();
        assert_eq!(
            ha.update_positions(&a.positions()[..n - 1]),
            Err(Error::WrongVertexCount {
                expected: n,
                got: n - 1,
                of: dhcd::Positions::Update,
                object: None,
            })
        );
        let mut nan = a.positions().to_vec();
        nan[7][0] = f32::NAN;
        assert!(matches!(
            ha.update_positions(&nan),
            Err(Error::NonFinite { vertex: 7, .. })
        ));
        let mut inf = a.positions().to_vec();
        inf[3][1] = f32::INFINITY;
        assert!(matches!(
            ha.update_positions(&inf),
            Err(Error::NonFinite { vertex: 3, .. })
        ));
        assert_eq!(
            ha.collide(&hb, &mut ws, dhcd::Par::Seq).unwrap().pairs,
            before
        );
        ha.validate().unwrap();
        let other = dhcd::AnyHierarchy::new(
            Method::ALL[(method as usize + 1) % 3],
            &b,
            Options::default(),
        )
        .unwrap();
        assert!(ha.collide(&other, &mut ws, dhcd::Par::Seq).is_err());
    }
}

#[test]
fn method_names_parse() {
    for m in Method::ALL {
        assert_eq!(m.name().parse::<Method>().unwrap(), m);
    }
    assert!("obb".parse::<Method>().is_err());
}

/// Random triangle soups on a coarse grid (so touching and coplanar cases are frequent).
fn soup(max_tris: usize) -> impl Strategy<Value = Mesh> {
    let coord = (-4i32..=4).prop_map(|c| c as f32 * 0.5);
    let point = [coord.clone(), coord.clone(), coord];
    prop::collection::vec(prop::collection::vec(point, 3), 1..max_tris).prop_map(|tris| {
        let positions: Vec<[f32; 3]> = tris.iter().flatten().copied().collect();
        let triangles = (0..tris.len() as u32)
            .map(|t| [3 * t, 3 * t + 1, 3 * t + 2])
            .collect();
        Mesh::new(positions, triangles).unwrap()
    })
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    #[test]
    fn random_soups_equal_brute_force(a in soup(40), b in soup(40), levels in 1usize..7) {
        assert_exact(&a, &b, levels);
    }

    #[test]
    fn random_poses_of_spheres(dx in -2.0f32..2.0, dy in -2.0f32..2.0, dz in -2.0f32..2.0, t in 0.0f32..6.0, amp in 0.0f32..0.4) {
        let a = icosphere(1, 1.0, [0.0; 3]);
        let b = with_positions(&a, wave(a.positions(), t, amp, [dx, dy, dz]));
        assert_exact(&a, &b, 4);
    }
}

/// Runs a deforming sequence with the given parallelism and grain; returns every step's
/// contacts and counters.
fn sequence_with<K: BoundingVolume>(par: dhcd::Par, grain: usize) -> Vec<dhcd::Contacts> {
    let a = icosphere(3, 1.0, [0.0, 0.0, 0.0]);
    let b = icosphere(3, 0.9, [0.0, 0.0, 0.0]);
    let mut ha = Hierarchy::<K>::new(&a, Options::default()).unwrap();
    let mut hb = Hierarchy::<K>::new(&b, Options::default()).unwrap();
    let mut ws = dhcd::Workspace::with_grain(grain);
    (0..8)
        .map(|step| {
            let t = step as f32 * 0.4;
            ha.update_positions(&wave(a.positions(), t, 0.1, [0.0; 3]))
                .unwrap();
            hb.update_positions(&wave(
                b.positions(),
                -t,
                0.1,
                [1.7 - 0.05 * step as f32, 0.2, 0.0],
            ))
            .unwrap();
            let c = dhcd::collide_with(&ha, &hb, &mut ws, par);
            ha.validate().unwrap();
            hb.validate().unwrap();
            c
        })
        .collect()
}

fn parallel_equals_sequential_for<K: BoundingVolume>() {
    let seq = sequence_with::<K>(dhcd::Par::Seq, 1024);
    assert!(seq.iter().any(|c| !c.pairs.is_empty()));
    for threads in [1, 2, 3] {
        // Grain 1 splits every frontier and every leaf pair list into single-pair tasks.
        for grain in [1, 5, 64, 1024] {
            let par = sequence_with::<K>(dhcd::Par::Rayon(threads), grain);
            assert_eq!(
                par,
                seq,
                "{:?}: {threads} threads, grain {grain}",
                K::METHOD
            );
        }
    }
    assert_eq!(sequence_with::<K>(dhcd::Par::Ambient, 3), seq);
}

#[test]
fn parallel_equals_sequential_every_kind() {
    for_each_method!(K => parallel_equals_sequential_for::<K>());
}

#[test]
fn broad_then_narrow_phase_equals_collide() {
    let a = icosphere(3, 1.0, [0.0; 3]);
    let b = icosphere(3, 1.0, [1.4, 0.3, 0.0]);
    let mut ha = Hierarchy::<Dh>::new(&a, Options::default()).unwrap();
    let mut hb = Hierarchy::<Dh>::new(&b, Options::default()).unwrap();
    ha.update_positions(&wave(a.positions(), 0.5, 0.1, [0.0; 3]))
        .unwrap();
    hb.update_positions(&wave(b.positions(), 0.5, 0.1, [1.4, 0.3, 0.0]))
        .unwrap();
    let whole = collide(&ha.clone(), &hb.clone());
    let mut ws = dhcd::Workspace::default();
    let broad = ha.broad_phase(&hb, &mut ws, dhcd::Par::Seq).unwrap();
    let narrow = ha
        .narrow_phase(&hb, &broad.leaf_pairs, dhcd::Par::Rayon(2))
        .unwrap();
    assert_eq!(narrow.pairs, whole.pairs);
    assert_eq!(broad.counters.bv_tests, whole.counters.bv_tests);
    assert_eq!(broad.counters.bv_updates, whole.counters.bv_updates);
    assert_eq!(broad.counters.prim_tests, whole.counters.prim_tests);
    assert_eq!(narrow.counters.prim_tests, whole.counters.prim_tests);
    // Replaying the step's refit: invalidate, then refit exactly the nodes the query fitted.
    let fitted = ha.fitted_nodes();
    assert_eq!(
        fitted.len() + hb.fitted_nodes().len(),
        whole.counters.bv_updates as usize
    );
    ha.invalidate();
    assert_eq!(ha.validate().unwrap(), 0);
    assert_eq!(
        ha.refit_nodes(&fitted, dhcd::Par::Rayon(2)).unwrap(),
        fitted.len() as u64
    );
    assert_eq!(ha.validate().unwrap(), fitted.len());
    // Node ids from elsewhere are errors, not panics.
    let n = ha.node_count() as u32;
    assert_eq!(
        ha.refit_nodes(&[0, n], dhcd::Par::Seq),
        Err(Error::NodeOutOfRange {
            node: n,
            node_count: n as usize
        })
    );
    assert!(matches!(
        ha.narrow_phase(&hb, &[[n, 0]], dhcd::Par::Seq),
        Err(Error::NodeOutOfRange { node, .. }) if node == n
    ));
    assert_eq!(
        ha.narrow_phase(&hb, &[[0, 0]], dhcd::Par::Seq)
            .map(|c| c.pairs),
        Err(Error::NotALeaf { node: 0 }),
        "root is no leaf"
    );
}

fn scaled(mesh: &Mesh, s: f32, offset: [f32; 3]) -> Mesh {
    with_positions(
        mesh,
        mesh.positions()
            .iter()
            .map(|p| {
                [
                    p[0] * s + offset[0],
                    p[1] * s + offset[1],
                    p[2] * s + offset[2],
                ]
            })
            .collect(),
    )
}

#[test]
fn extreme_magnitudes_stay_exact() {
    // Squared distances overflow (1e25^2) or underflow (1e-25^2) in f32: the bounds must stay
    // conservative, and touching triangles must still be found.
    let a = grid(3, 3, 1.0, [0.0; 3]);
    let b = Mesh::new(
        a.positions()
            .iter()
            .map(|p| [p[0], 1.5, p[1] - 1.0])
            .collect(),
        a.triangles().to_vec(),
    )
    .unwrap();
    for s in [1e25f32, 1e18, 1e-18, 1e-25, 1e-38] {
        let (sa, sb) = (scaled(&a, s, [0.0; 3]), scaled(&b, s, [0.0; 3]));
        assert!(!assert_exact(&sa, &sb, 3).is_empty(), "scale {s}");
    }
    // Far from the origin: large common offset, small features.
    let (fa, fb) = (
        scaled(&a, 1.0, [3e6, -2e6, 1e6]),
        scaled(&b, 1.0, [3e6, -2e6, 1e6]),
    );
    assert!(!assert_exact(&fa, &fb, 3).is_empty());
}

/// Vertices no triangle uses (free points) change no contact (contacts are triangle pairs),
/// and the bounds hold them: proximity and CCD pair them with triangles as points
/// (`tests/free_points.rs`).
#[test]
fn free_points_are_in_the_bounds_and_change_no_contact() {
    let mut positions = vec![[100.0, 100.0, 100.0]];
    positions.extend_from_slice(icosphere(1, 1.0, [0.0; 3]).positions());
    positions.push([-50.0, 0.0, 0.0]);
    let tris = icosphere(1, 1.0, [0.0; 3])
        .triangles()
        .iter()
        .map(|t| t.map(|v| v + 1))
        .collect();
    let a = Mesh::new(positions, tris).unwrap();
    let b = icosphere(1, 1.0, [0.5, 0.0, 0.0]);
    assert!(!assert_exact(&a, &b, 4).is_empty());
    let mut h = Hierarchy::<Aabb>::new(&a, Options::default()).unwrap();
    h.refit_all();
    h.validate().unwrap();
    let root = h.record(0).unwrap();
    assert!(root.max[0] >= 100.0 && root.min[0] <= -50.0);
}
