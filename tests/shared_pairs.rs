//! The vertex-sharing pairs of each leaf pair, which the region tree tabulates at build so
//! that a self query neither tests nor counts them: the table against a direct count on
//! every leaf pair, `N_P` against its definition, and a mesh over the table's build budget
//! (a fan around one vertex) answered exactly without it.

use dhcd::bv::{Aabb, Dh, Sphere};
use dhcd::narrow::brute_force_self_pairs;
use dhcd::shapes::{grid, icosphere, jitter};
use dhcd::tree::TreeShape;
use dhcd::{self_collide, Error, Hierarchy, Mesh, Options, RegionTree};

/// Pairs of triangles `t` of leaf `x` and `u` of leaf `y` with a common corner index
/// (`t < u` when `x == y`), straight from the definition.
fn direct(tree: &RegionTree, x: usize, y: usize) -> u64 {
    let tris = tree.triangles();
    let mut n = 0;
    for t in tree.tri_range(x) {
        for u in tree.tri_range(y) {
            n += ((x != y || t < u) && tris[t].iter().any(|v| tris[u].contains(v))) as u64;
        }
    }
    n
}

/// Unordered pairs of distinct triangles of the mesh sharing a corner index.
fn sharing_pairs(mesh: &Mesh) -> u64 {
    let t = mesh.triangles();
    let mut n = 0;
    for i in 0..t.len() {
        for j in i + 1..t.len() {
            n += t[i].iter().any(|v| t[j].contains(v)) as u64;
        }
    }
    n
}

/// A grid with a duplicated triangle (sharing all three corners) and a long one joining
/// three far-apart vertices (sharing one with triangles of many leaves).
fn with_duplicates() -> Mesh {
    let g = grid(6, 5, 0.2, [0.0; 3]);
    let mut triangles = g.triangles().to_vec();
    triangles.push(triangles[3]);
    triangles.push([0, 20, 41]);
    Mesh::new(g.positions().to_vec(), triangles).unwrap()
}

fn meshes() -> Vec<(&'static str, Mesh)> {
    vec![
        ("icosphere", icosphere(2, 1.0, [0.0; 3])),
        ("jittered grid", {
            let g = grid(12, 9, 0.1, [0.0; 3]);
            Mesh::new(jitter(g.positions(), [0.02; 3], 3), g.triangles().to_vec()).unwrap()
        }),
        ("duplicates", with_duplicates()),
    ]
}

#[test]
fn the_table_equals_a_direct_count_on_every_leaf_pair() {
    for (name, mesh) in meshes() {
        for shape in [
            TreeShape::Adaptive { leaf_size: 4 },
            TreeShape::default(),
            TreeShape::Levels(3),
            TreeShape::Levels(1),
        ] {
            let tree = RegionTree::build(&mesh, shape).unwrap();
            tree.check_topology(&mesh).unwrap();
            let leaves: Vec<usize> = tree.leaves().collect();
            let mut total = 0;
            for (i, &x) in leaves.iter().enumerate() {
                for &y in &leaves {
                    let want = direct(&tree, x, y);
                    assert_eq!(
                        tree.shared_pairs(x, y).unwrap(),
                        want,
                        "{name} {shape:?} {x} {y}"
                    );
                    total += if y >= leaves[i] { want } else { 0 };
                }
            }
            assert_eq!(total, sharing_pairs(&mesh), "{name} {shape:?}");
            // Bad node ids are typed errors.
            let n = tree.node_count();
            assert!(matches!(
                tree.shared_pairs(n, leaves[0]),
                Err(Error::NodeOutOfRange { .. })
            ));
            if !tree.is_leaf(0) {
                assert!(matches!(
                    tree.shared_pairs(leaves[0], 0),
                    Err(Error::NotALeaf { node: 0 })
                ));
            }
        }
    }
}

/// One leaf holding every triangle: `N_P` is every unordered pair minus the sharing ones.
#[test]
fn one_leaf_counts_every_pair_that_shares_no_vertex() {
    for (name, mesh) in meshes() {
        let n = mesh.triangle_count() as u64;
        let options = Options {
            levels: Some(1),
            ..Options::default()
        };
        let want = n * (n - 1) / 2 - sharing_pairs(&mesh);
        let c = self_collide(&Hierarchy::<Aabb>::new(&mesh, options).unwrap());
        assert_eq!(c.counters.prim_tests, want, "{name}");
        assert_eq!(c.pairs, brute_force_self_pairs(&mesh), "{name}");
    }
}

/// A fan of 2,000 triangles around one vertex (wound twice around it, so it overlaps
/// itself) and a strip crossing it: over the table's budget, so shared pairs are counted
/// directly; contacts equal brute force.
#[test]
fn a_mesh_over_the_table_budget_is_answered_without_it() {
    let fan = 2000u32;
    let mut positions = vec![[0.0f32, 0.0, 0.0]];
    for k in 0..=fan {
        let angle = 4.0 * std::f32::consts::PI * k as f32 / fan as f32;
        let z = 0.05 * (k as f32 / fan as f32);
        positions.push([angle.cos(), angle.sin(), z]);
    }
    let mut triangles: Vec<[u32; 3]> = (1..=fan).map(|k| [0, k, k + 1]).collect();
    let v = positions.len() as u32;
    positions.extend([
        [0.5, -0.1, -1.0],
        [0.5, 0.1, -1.0],
        [0.5, -0.1, 1.0],
        [0.5, 0.1, 1.0],
    ]);
    triangles.extend([[v, v + 1, v + 2], [v + 1, v + 3, v + 2]]);
    let mesh = Mesh::new(positions, triangles).unwrap();
    let expected = brute_force_self_pairs(&mesh);
    assert!(!expected.is_empty());
    let h = Hierarchy::<Dh>::new(&mesh, Options::default()).unwrap();
    let tree = h.tree().clone();
    tree.check_topology(&mesh).unwrap();
    let leaves: Vec<usize> = tree.leaves().collect();
    for &x in leaves.iter().step_by(7) {
        for &y in leaves.iter().step_by(5) {
            assert_eq!(tree.shared_pairs(x, y).unwrap(), direct(&tree, x, y));
        }
    }
    assert_eq!(self_collide(&h).pairs, expected);
    let s = Hierarchy::<Sphere>::with_tree(tree, &mesh, Options::default()).unwrap();
    assert_eq!(self_collide(&s).pairs, expected);
}
