//! The contact set: every pair of features within `dhat` once, with the IPC Toolkit's types,
//! equal to a brute force that applies the IPC Toolkit's rules to every feature pair (an
//! exact rational mollifier test of its own), for every method, thread count, self and pair
//! query; weights that reproduce the distances; derivatives against finite differences.

use std::collections::BTreeMap;

use dhcd::bv::BoundingVolume;
use dhcd::contact::{
    self, contact_set_with, self_contact_set_with, ContactSet, ContactType, MOLLIFIER_FACTOR, NONE,
};
use dhcd::distance::{
    edge_edge_within, point_line_distance_sq, point_triangle_within, EdgeEdge, PointTriangle,
};
use dhcd::shapes::{fold_x, grid, jitter, wave};
use dhcd::{for_each_method, Error, Hierarchy, Mesh, Options, Par, Workspace};
use num_rational::BigRational;

/// What the oracle and the library must agree on, per contact.
type Key = (u8, [u32; 4]);
#[derive(Debug, PartialEq)]
struct Row {
    edges: [u32; 2],
    mollified: bool,
    closest: Option<EdgeEdge>,
    distance_sq: f64,
}

fn exact(x: f64) -> BigRational {
    BigRational::from_float(x).expect("finite")
}

/// `|(a1 - a0) x (b1 - b0)|^2 < t`, over the rationals.
fn cross_sq_below(x: [[f64; 3]; 4], t: f64) -> bool {
    let d = |i: usize, j: usize| -> [BigRational; 3] {
        std::array::from_fn(|c| exact(x[j][c]) - exact(x[i][c]))
    };
    let (a, b) = (d(0, 1), d(2, 3));
    let c = [
        &a[1] * &b[2] - &a[2] * &b[1],
        &a[2] * &b[0] - &a[0] * &b[2],
        &a[0] * &b[1] - &a[1] * &b[0],
    ];
    let n = &c[0] * &c[0] + &c[1] * &c[1] + &c[2] * &c[2];
    n < exact(t)
}

/// One object of the oracle: positions, rest, triangles, and offsets.
struct Obj {
    x: Vec<[f64; 3]>,
    rest: Vec<[f64; 3]>,
    tris: Vec<[u32; 3]>,
    edges: Vec<[u32; 2]>,
    vo: u32,
    eo: u32,
}

impl Obj {
    fn new(m: &Mesh, rest: &Mesh, vo: u32, eo: u32) -> Self {
        let f64s = |m: &Mesh| -> Vec<[f64; 3]> {
            m.positions_f64().map_or_else(
                || m.positions().iter().map(|p| p.map(f64::from)).collect(),
                <[_]>::to_vec,
            )
        };
        let mut edges: Vec<[u32; 2]> = m
            .triangles()
            .iter()
            .flat_map(|t| (0..3).map(move |k| [t[k].min(t[(k + 1) % 3]), t[k].max(t[(k + 1) % 3])]))
            .collect();
        edges.sort_unstable();
        edges.dedup();
        Self {
            x: f64s(m),
            rest: f64s(rest),
            tris: m.triangles().to_vec(),
            edges,
            vo,
            eo,
        }
    }
    fn edge(&self, u: u32, v: u32) -> u32 {
        self.eo + self.edges.binary_search(&[u.min(v), u.max(v)]).unwrap() as u32
    }
    fn len_sq(&self, u: u32, v: u32) -> f64 {
        let (p, q) = (self.rest[u as usize], self.rest[v as usize]);
        (0..3).map(|c| (p[c] - q[c]) * (p[c] - q[c])).sum()
    }
}

/// A point-edge contact's value: the corner-edge formula from the edge's first vertex,
/// whichever pair found it.
fn point_edge_value(p: [f64; 3], e0: [f64; 3], e1: [f64; 3]) -> f64 {
    point_line_distance_sq(p, e0, e1)
}

fn insert(set: &mut BTreeMap<Key, Row>, key: Key, row: Row) {
    match set.get_mut(&key) {
        Some(old) if old.distance_sq <= row.distance_sq => {}
        Some(old) => *old = row,
        None => {
            set.insert(key, row);
        }
    }
}

/// The IPC Toolkit's rules on every vertex-triangle pair of `p` against `f` and every edge
/// pair of `a` against `b` (`same`: one object, so skip shared vertices and take `a < b`).
fn oracle(a: &Obj, b: &Obj, same: bool, dhat: f64) -> BTreeMap<Key, Row> {
    let mut set = BTreeMap::new();
    let sides: &[(&Obj, &Obj)] = if same { &[(a, a)] } else { &[(a, b), (b, a)] };
    for &(p, f) in sides {
        for v in 0..p.x.len() as u32 {
            for t in &f.tris {
                if same && t.contains(&v) {
                    continue;
                }
                let corners = t.map(|w| f.x[w as usize]);
                let Some((d, kind)) = point_triangle_within(p.x[v as usize], corners, dhat) else {
                    continue;
                };
                let gv = v + p.vo;
                let g = t.map(|w| w + f.vo);
                let k = kind as usize;
                let (key, edges) = match kind {
                    PointTriangle::Vertex0 | PointTriangle::Vertex1 | PointTriangle::Vertex2 => {
                        ((0, [gv.min(g[k]), gv.max(g[k]), NONE, NONE]), [NONE; 2])
                    }
                    PointTriangle::Face => ((2, [gv, g[0], g[1], g[2]]), [NONE; 2]),
                    _ => {
                        let (i, j) = (k - 3, (k - 2) % 3);
                        let (i, j) = if g[i] < g[j] { (i, j) } else { (j, i) };
                        ((1, [gv, g[i], g[j], NONE]), [f.edge(t[i], t[j]), NONE])
                    }
                };
                let d = match key.0 {
                    1 => {
                        let (i, j) = (key.1[1] - f.vo, key.1[2] - f.vo);
                        point_edge_value(p.x[v as usize], f.x[i as usize], f.x[j as usize])
                    }
                    _ => d,
                };
                let row = Row {
                    edges,
                    mollified: false,
                    closest: None,
                    distance_sq: d,
                };
                insert(&mut set, key, row);
            }
        }
    }
    for (i, ea) in a.edges.iter().enumerate() {
        for (j, eb) in b.edges.iter().enumerate() {
            if same && (j <= i || ea.iter().any(|v| eb.contains(v))) {
                continue;
            }
            let x = [
                a.x[ea[0] as usize],
                a.x[ea[1] as usize],
                b.x[eb[0] as usize],
                b.x[eb[1] as usize],
            ];
            let Some((d, kind)) = edge_edge_within(x[0], x[1], x[2], x[3], dhat) else {
                continue;
            };
            let g = [ea[0] + a.vo, ea[1] + a.vo, eb[0] + b.vo, eb[1] + b.vo];
            let (ida, idb) = (a.edge(ea[0], ea[1]), b.edge(eb[0], eb[1]));
            let eps = MOLLIFIER_FACTOR * a.len_sq(ea[0], ea[1]) * b.len_sq(eb[0], eb[1]);
            let mollified = cross_sq_below(x, eps);
            let pp = |i: usize, j: usize| (0u8, [g[i].min(g[j]), g[i].max(g[j]), NONE, NONE]);
            let (key, edges, closest) = if mollified || kind == EdgeEdge::EaEb {
                ((3, g), [ida, idb], Some(kind))
            } else {
                match kind {
                    EdgeEdge::Ea0Eb0 => (pp(0, 2), [NONE; 2], None),
                    EdgeEdge::Ea0Eb1 => (pp(0, 3), [NONE; 2], None),
                    EdgeEdge::Ea1Eb0 => (pp(1, 2), [NONE; 2], None),
                    EdgeEdge::Ea1Eb1 => (pp(1, 3), [NONE; 2], None),
                    EdgeEdge::EaEb0 => ((1, [g[2], g[0], g[1], NONE]), [ida, NONE], None),
                    EdgeEdge::EaEb1 => ((1, [g[3], g[0], g[1], NONE]), [ida, NONE], None),
                    EdgeEdge::Ea0Eb => ((1, [g[0], g[2], g[3], NONE]), [idb, NONE], None),
                    EdgeEdge::Ea1Eb => ((1, [g[1], g[2], g[3], NONE]), [idb, NONE], None),
                    EdgeEdge::EaEb => unreachable!(),
                }
            };
            let at = |v: u32| {
                x[g.iter()
                    .position(|&w| w == v)
                    .expect("a vertex of the pair")]
            };
            let d = match key {
                (1, [v, e0, e1, _]) => point_edge_value(at(v), at(e0), at(e1)),
                _ => d,
            };
            let row = Row {
                edges,
                mollified,
                closest,
                distance_sq: d,
            };
            insert(&mut set, key, row);
        }
    }
    set
}

/// Equal maps, or a panic listing the first differences (not both maps).
fn assert_same(got: &BTreeMap<Key, Row>, want: &BTreeMap<Key, Row>, what: &str) {
    let mut diffs = Vec::new();
    for (k, v) in got {
        match want.get(k) {
            None => diffs.push(format!("extra {k:?} {v:?}")),
            Some(w) if w != v => diffs.push(format!("{k:?}: got {v:?}, want {w:?}")),
            _ => {}
        }
    }
    for (k, w) in want {
        if !got.contains_key(k) {
            diffs.push(format!("missing {k:?} {w:?}"));
        }
    }
    let n = diffs.len();
    diffs.truncate(8);
    assert!(n == 0, "{what}: {n} differences, first: {diffs:#?}");
}

fn as_map(set: &ContactSet) -> BTreeMap<Key, Row> {
    set.contacts
        .iter()
        .map(|c| {
            (
                (c.kind as u8, c.vertices),
                Row {
                    edges: c.edges,
                    mollified: c.mollified,
                    closest: c.closest,
                    distance_sq: c.distance_sq,
                },
            )
        })
        .collect()
}

/// The weights give back the distance, and the formula's value is the row's distance.
fn check_geometry(set: &ContactSet, what: &str) {
    assert_eq!(set.contacts.len(), set.positions.len());
    let formula = set.distances_sq();
    for ((c, x), f) in set.contacts.iter().zip(&set.positions).zip(formula) {
        let v: [f64; 3] =
            std::array::from_fn(|k| (0..4).map(|i| c.weights[i] * x[i][k]).sum::<f64>());
        let d = v[0] * v[0] + v[1] * v[1] + v[2] * v[2];
        let scale = x
            .iter()
            .take(c.kind.vertex_count())
            .flatten()
            .fold(0.0f64, |m, &q| m.max(q.abs()));
        let tol = 1e-9 * scale * scale + 1e-12 * c.distance_sq;
        assert!(
            (d - c.distance_sq).abs() <= tol,
            "{what} {c:?}: weights give {d}"
        );
        assert!(
            (f - c.distance_sq).abs() <= tol,
            "{what} {c:?}: formula gives {f}"
        );
        for (i, &w) in c.weights.iter().enumerate() {
            assert_eq!(
                c.vertices[i] == NONE,
                w == 0.0 && c.vertices[i] == NONE,
                "{what}"
            );
            if c.vertices[i] == NONE {
                assert_eq!(x[i], [0.0; 3], "{what}");
            }
        }
    }
}

fn check_self<K: BoundingVolume>(m: &Mesh, rest: &Mesh, dhat: f64, what: &str) -> usize {
    let h = Hierarchy::<K>::new(rest, Options::default()).unwrap();
    let mut h = h;
    match m.positions_f64() {
        Some(p) => h.update_positions_f64(p).unwrap(),
        None => h.update_positions(m.positions()).unwrap(),
    };
    let want = oracle(
        &Obj::new(m, rest, 0, 0),
        &Obj::new(m, rest, 0, 0),
        true,
        dhat,
    );
    for par in [Par::Seq, Par::Rayon(2)] {
        let got = self_contact_set_with(&h, dhat, None, &mut Workspace::default(), par).unwrap();
        let what = format!("{what} {:?} dhat={dhat} {par:?}", K::METHOD);
        assert_same(&as_map(&got), &want, &what);
        assert_eq!(got.counters.contacts, want.len() as u64, "{what}");
        check_geometry(&got, &what);
        // Sorted by (type, vertices), one row per contact.
        let keys: Vec<Key> = got
            .contacts
            .iter()
            .map(|c| (c.kind as u8, c.vertices))
            .collect();
        assert!(keys.windows(2).all(|w| w[0] < w[1]), "{what}");
    }
    want.len()
}

fn f64_mesh(m: &Mesh, p: Vec<[f32; 3]>) -> Mesh {
    Mesh::new_f64(
        p.iter().map(|q| q.map(f64::from)).collect(),
        m.triangles().to_vec(),
    )
    .unwrap()
}

/// A folded, jittered sheet: every type, near-parallel layers (mollified edge pairs).
#[test]
fn folded_sheet_equals_the_ipc_rules() {
    let rest = grid(9, 9, 0.1, [0.0, 0.0, 0.0]);
    let folded = fold_x(rest.positions(), 0.45);
    let m = f64_mesh(&rest, jitter(&folded, [0.004; 3], 7));
    let rest64 = f64_mesh(&rest, rest.positions().to_vec());
    let mut kinds = [0usize; 4];
    let mut mollified = 0;
    for dhat in [0.02, 0.06, 0.12] {
        let mut n = 0;
        for_each_method!(K => n += check_self::<K>(&m, &rest64, dhat, "folded sheet"));
        assert!(n > 0);
        let h = Hierarchy::<dhcd::bv::Dh>::new(&m, Options::default()).unwrap();
        let set = contact::self_contact_set(&h, dhat).unwrap();
        for c in &set.contacts {
            kinds[c.kind as usize] += 1;
            mollified += c.mollified as usize;
        }
    }
    assert!(kinds.iter().all(|&k| k > 0), "every type occurs: {kinds:?}");
    assert!(mollified > 0, "near-parallel edge pairs occur");
}

/// A wavy sheet, in f32: rest positions given separately decide the mollifier.
#[test]
fn wavy_sheet_in_f32_with_rest_positions() {
    let rest = grid(8, 8, 0.1, [0.0, 0.0, 0.0]);
    let m = Mesh::new(
        wave(rest.positions(), 0.3, 0.05, [0.0; 3]),
        rest.triangles().to_vec(),
    )
    .unwrap();
    for_each_method!(K => assert!(check_self::<K>(&m, &rest, 0.11, "wavy sheet") > 0));
    // Rest positions given explicitly: the same as the build's.
    let h = Hierarchy::<dhcd::bv::Aabb>::new(&m, Options::default()).unwrap();
    let rest64: Vec<[f64; 3]> = m.positions().iter().map(|p| p.map(f64::from)).collect();
    let a = self_contact_set_with(&h, 0.11, None, &mut Workspace::default(), Par::Seq).unwrap();
    let b = self_contact_set_with(&h, 0.11, Some(&rest64), &mut Workspace::default(), Par::Seq)
        .unwrap();
    assert_eq!(a, b);
    // Rest positions of the wrong length or not finite are typed errors.
    let e = self_contact_set_with(
        &h,
        0.11,
        Some(&rest64[1..]),
        &mut Workspace::default(),
        Par::Seq,
    )
    .unwrap_err();
    assert!(matches!(e, Error::WrongVertexCount { .. }), "{e}");
    let mut bad = rest64.clone();
    bad[3][1] = f64::NAN;
    let e = self_contact_set_with(&h, 0.11, Some(&bad), &mut Workspace::default(), Par::Seq)
        .unwrap_err();
    assert!(matches!(e, Error::NonFinite { .. }), "{e}");
    for dhat in [-1.0, f64::NAN, f64::INFINITY] {
        let e = contact::self_contact_set(&h, dhat).unwrap_err();
        assert!(matches!(e, Error::InvalidDistance(_)), "{e}");
    }
}

fn check_pair<K: BoundingVolume>(a: &Mesh, b: &Mesh, dhat: f64) {
    let (ha, hb) = (
        Hierarchy::<K>::new(a, Options::default()).unwrap(),
        Hierarchy::<K>::new(b, Options::default()).unwrap(),
    );
    let na = a.vertex_count() as u32;
    let oa = Obj::new(a, a, 0, 0);
    let ob = Obj::new(b, b, na, oa.edges.len() as u32);
    let want = oracle(&oa, &ob, false, dhat);
    assert!(!want.is_empty());
    for par in [Par::Seq, Par::Rayon(2)] {
        let got =
            contact_set_with(&ha, &hb, dhat, [None, None], &mut Workspace::default(), par).unwrap();
        assert_same(&as_map(&got), &want, &format!("{:?} {par:?}", K::METHOD));
        check_geometry(&got, "pair");
    }
}

/// Two sheets, one above the other and slightly rotated: vertex numbering `a` then `b`.
#[test]
fn two_sheets_number_vertices_and_edges_a_then_b() {
    let a = grid(6, 6, 0.1, [0.0, 0.0, 0.0]);
    let b0 = grid(5, 7, 0.11, [0.03, -0.02, 0.0]);
    let b = f64_mesh(&b0, jitter(b0.positions(), [0.0, 0.0, 0.03], 3));
    let a = f64_mesh(&a, a.positions().to_vec());
    for_each_method!(K => check_pair::<K>(&a, &b, 0.05));
}

/// One workspace carried through contact sets of different meshes, distances and threads,
/// self and pair queries (its scratch holds the previous query's rows, larger or smaller):
/// each set is the one a fresh workspace gives.
#[test]
fn a_reused_workspace_gives_the_sets_of_a_fresh_one() {
    let rest = grid(9, 9, 0.1, [0.0, 0.0, 0.0]);
    let folded = f64_mesh(
        &rest,
        jitter(&fold_x(rest.positions(), 0.45), [0.004; 3], 7),
    );
    let small = grid(5, 7, 0.11, [0.03, -0.02, 0.0]);
    let lifted = f64_mesh(&small, jitter(small.positions(), [0.0, 0.0, 0.03], 3));
    let (hf, hl) = (
        Hierarchy::<dhcd::bv::Dh>::new(&folded, Options::default()).unwrap(),
        Hierarchy::<dhcd::bv::Dh>::new(&lifted, Options::default()).unwrap(),
    );
    let mut ws = Workspace::default();
    let mut sizes = Vec::new();
    for (dhat, par) in [(0.12, Par::Seq), (0.02, Par::Rayon(2)), (0.06, Par::Seq)] {
        for self_query in [true, false] {
            let run = |ws: &mut Workspace| {
                if self_query {
                    self_contact_set_with(&hf, dhat, None, ws, par).unwrap()
                } else {
                    contact_set_with(&hf, &hl, dhat, [None, None], ws, par).unwrap()
                }
            };
            let (reused, fresh) = (run(&mut ws), run(&mut Workspace::default()));
            assert_eq!(reused, fresh, "dhat {dhat} {par:?} self {self_query}");
            sizes.push(reused.len());
        }
    }
    // The scratch is exercised both ways: a set smaller, then larger, than the one before.
    assert!(sizes.windows(2).any(|w| w[0] > w[1]), "{sizes:?}");
    assert!(sizes.windows(2).any(|w| w[0] < w[1]), "{sizes:?}");
}

/// A vertex above the middle of a shared edge is one point-edge contact, not one per
/// triangle (and not again from the edges at its ends).
#[test]
fn a_vertex_near_a_shared_edge_is_one_contact() {
    let m = Mesh::new_f64(
        vec![
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [1.0, 1.0, 0.0],
            [0.5, 0.5, 0.05],
            [0.5, 0.5, 2.0],
            [0.6, 0.5, 2.0],
        ],
        vec![[0, 1, 2], [1, 3, 2], [4, 5, 6]],
    )
    .unwrap();
    let h = Hierarchy::<dhcd::bv::Dh>::new(&m, Options::default()).unwrap();
    let set = contact::self_contact_set(&h, 0.1).unwrap();
    let pe: Vec<_> = set.contacts.iter().filter(|c| c.vertices[0] == 4).collect();
    assert_eq!(pe.len(), 1, "{:?}", set.contacts);
    assert_eq!(pe[0].kind, ContactType::PointEdge);
    assert_eq!(pe[0].vertices, [4, 1, 2, NONE]);
    assert_eq!(h.tree().edges()[pe[0].edges[0] as usize], [1, 2]);
    assert!((pe[0].distance_sq - 0.0025).abs() < 1e-15);
    assert_eq!(pe[0].weights, [1.0, -0.5, -0.5, 0.0]);
    let raw = dhcd::self_proximity(&h, 0.1).unwrap();
    assert!(
        raw.vertex_face.len() + raw.edge_edge.len() > 1,
        "several raw rows"
    );
}

/// The batch functions: lengths checked, types from codes checked.
#[test]
fn batch_geometry_checks_its_input() {
    let x = [[
        [0.0, 0.0, 1.0],
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
    ]];
    let t = [ContactType::PointTriangle];
    assert_eq!(contact::distance_sq(&t, &x).unwrap(), vec![1.0]);
    let g = contact::distance_gradient(&t, &x).unwrap();
    assert_eq!(&g[0][..3], &[0.0, 0.0, 2.0]);
    let h = contact::distance_hessian(&t, &x).unwrap();
    assert_eq!(h[0][2][2], 2.0);
    assert!(matches!(
        contact::distance_sq(&t, &[]),
        Err(Error::LengthMismatch {
            expected: 1,
            got: 0,
            ..
        })
    ));
    assert!(matches!(
        ContactType::from_code(7),
        Err(Error::UnknownContactType(7))
    ));
}

/// A scene's contact set is the contact set of all its objects as one mesh (self-collision
/// on everywhere), in the global numbering: each object's vertices and edges after those of
/// the objects added before it.
#[test]
fn a_scene_numbers_its_objects_in_order() {
    use dhcd::scene::Scene;
    let rest = grid(7, 7, 0.1, [0.0, 0.0, 0.0]);
    let folded = f64_mesh(
        &rest,
        jitter(&fold_x(rest.positions(), 0.35), [0.003; 3], 4),
    );
    let below = f64_mesh(
        &grid(5, 5, 0.15, [0.0; 3]),
        jitter(
            grid(5, 5, 0.15, [-0.05, -0.05, -0.03]).positions(),
            [0.0, 0.0, 0.01],
            8,
        ),
    );
    let far = f64_mesh(
        &grid(2, 2, 0.1, [0.0; 3]),
        grid(2, 2, 0.1, [9.0, 9.0, 9.0]).positions().to_vec(),
    );
    let objects = [&folded, &below, &far];
    // One mesh of all three.
    let (mut p, mut t) = (Vec::new(), Vec::new());
    for m in objects {
        let o = p.len() as u32;
        t.extend(m.triangles().iter().map(|tri| tri.map(|v| v + o)));
        p.extend_from_slice(m.positions_f64().unwrap());
    }
    let all = Mesh::new_f64(p, t).unwrap();
    let dhat = 0.06;
    let h = Hierarchy::<dhcd::bv::Sphere>::new(&all, Options::default()).unwrap();
    let want = contact::self_contact_set(&h, dhat).unwrap();
    assert!(want.len() > 10);
    for par in [Par::Seq, Par::Rayon(2)] {
        let mut scene = Scene::new(dhcd::Method::Sphere, Options::default());
        let ids: Vec<_> = objects.iter().map(|m| scene.add(m).unwrap()).collect();
        for &id in &ids {
            scene.set_self_collision(id, true).unwrap();
        }
        let got = scene.contact_set(dhat, par).unwrap();
        assert_same(&as_map(&got), &as_map(&want), &format!("scene {par:?}"));
        assert_eq!(got.contacts, want.contacts);
        let offsets: Vec<u64> = ids
            .iter()
            .map(|&id| scene.vertex_offset(id).unwrap())
            .collect();
        assert_eq!(offsets, [0, 64, 100]);
        let e = scene.edge_offset(ids[2]).unwrap();
        let e1 = scene.edge_offset(ids[1]).unwrap();
        assert_eq!(e1, 7 * 8 * 2 + 7 * 7);
        assert!(e > e1);
        // Removing an object renumbers the ones after it.
        scene.remove(ids[0]).unwrap();
        assert_eq!(scene.vertex_offset(ids[1]).unwrap(), 0);
        assert!(scene.vertex_offset(ids[0]).is_err());
    }
}
