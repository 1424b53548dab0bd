//! `f64` meshes: construction, range and precision checks, and the loaders at full precision.

use dhcd::calibration::Calibration;
use std::path::Path;

use dhcd::io::{self, Format, Limits};
use dhcd::{Error, Mesh, Precision};

fn tri() -> Vec<[u32; 3]> {
    vec![[0, 1, 2]]
}

#[test]
fn an_f64_mesh_keeps_its_values_and_rounds_its_f32_view_to_nearest() {
    let p = vec![
        [0.1, 0.2, 0.3],
        [1.0 + 2f64.powi(-40), 0.0, 0.0],
        [0.0, 1.0, -1e-30],
    ];
    let m = Mesh::new_f64(p.clone(), tri()).unwrap();
    assert_eq!(m.precision(), Precision::F64);
    assert_eq!(m.positions_f64(), Some(&p[..]));
    assert_eq!(m.to_f64_positions(), p);
    for (r, e) in m.positions().iter().zip(&p) {
        assert_eq!(*r, e.map(|x| x as f32));
    }
    let f = Mesh::new(
        vec![[0.5, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]],
        tri(),
    )
    .unwrap();
    assert_eq!(f.precision(), Precision::F32);
    assert_eq!(f.positions_f64(), None);
    assert_eq!(f.to_f64_positions()[0], [0.5, 0.0, 0.0]);
}

/// The largest accepted magnitude rounds to `f32::MAX`; the next `f64` up would round to
/// infinity and is refused, as are NaN and infinities.
#[test]
fn f64_coordinates_must_round_to_finite_f32() {
    let edge = |x: f64| Mesh::new_f64(vec![[x, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]], tri());
    let max = f32::MAX as f64;
    let midpoint = max + 2f64.powi(103);
    let below = f64::from_bits(midpoint.to_bits() - 1);
    let m = edge(below).unwrap();
    assert_eq!(m.positions()[0][0], f32::MAX);
    assert_eq!(edge(-below).unwrap().positions()[0][0], -f32::MAX);
    assert!(matches!(
        edge(midpoint),
        Err(Error::OutOfRange { vertex: 0, .. })
    ));
    assert!(matches!(
        edge(-1e300),
        Err(Error::OutOfRange { vertex: 0, .. })
    ));
    assert!(matches!(
        edge(f64::NAN),
        Err(Error::NonFinite { vertex: 0, .. })
    ));
    assert!(matches!(
        edge(f64::INFINITY),
        Err(Error::NonFinite { vertex: 0, .. })
    ));
    // Tiny values are fine: they round to zero or a subnormal f32.
    assert_eq!(edge(1e-300).unwrap().positions()[0][0], 0.0);
}

#[test]
fn positions_of_the_other_precision_are_refused() {
    let mut m = Mesh::new_f64(vec![[0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]], tri()).unwrap();
    let before = m.clone();
    assert!(matches!(
        m.set_positions(&[[0.0; 3]; 3]),
        Err(Error::PrecisionMismatch {
            expected: Precision::F64,
            got: Precision::F32
        })
    ));
    assert_eq!(m, before);
    m.set_positions_f64(&[[0.1; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]])
        .unwrap();
    assert_eq!(m.positions_f64().unwrap()[0], [0.1; 3]);
    assert_eq!(m.positions()[0], [0.1f32; 3]);
    let mut f = Mesh::new(vec![[0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]], tri()).unwrap();
    assert!(matches!(
        f.set_positions_f64(&[[0.0; 3]; 3]),
        Err(Error::PrecisionMismatch {
            expected: Precision::F32,
            got: Precision::F64
        })
    ));
}

#[test]
fn precision_names_parse_and_print() {
    for p in Precision::ALL {
        assert_eq!(p.name().parse::<Precision>().unwrap(), p);
        assert_eq!(p.to_string(), p.name());
    }
    assert!(matches!(
        "f16".parse::<Precision>(),
        Err(Error::UnknownPrecision(_))
    ));
}

#[test]
fn obj_decimals_are_read_at_full_precision_when_asked() {
    let text = b"v 0.1 0.2 0.3\nv 1.0000000000001 0 0\nv 0 1 0\nf 1 2 3\n";
    let path = Path::new("m.obj");
    let m64 = io::parse_as(text, Format::Obj, path, Precision::F64).unwrap();
    assert_eq!(m64.positions_f64().unwrap()[0], [0.1, 0.2, 0.3]);
    assert_eq!(m64.positions_f64().unwrap()[1][0], 1.0000000000001);
    let m32 = io::parse(text, Format::Obj, path).unwrap();
    assert_eq!(m32.precision(), Precision::F32);
    assert_eq!(m32.positions()[0], [0.1f32, 0.2, 0.3]);
    assert_eq!(m32.positions()[1][0], 1.0);
    // Out of f64 range is a parse error naming the line, in either precision.
    let bad = b"v 1e400 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
    for p in Precision::ALL {
        let e = io::parse_as(bad, Format::Obj, path, p).unwrap_err();
        assert!(matches!(e, Error::Parse { line: 1, .. }), "{e}");
    }
    // In f64 range but beyond f32's: an f64 mesh refuses it as well (bounds are f32).
    let big = b"v 1e39 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
    let e = io::parse_as(big, Format::Obj, path, Precision::F64).unwrap_err();
    assert!(e.to_string().contains("f32 range"), "{e}");
}

/// The real frames hold `f64` (armadillo, rod) and `f32` (cloth, n-body) coordinates: read as
/// `f64`, the doubles come out unrounded and the floats exactly.
#[test]
fn real_frames_read_as_f64_keep_their_doubles() {
    let Some(dir) = crate::support::shared_data(
        "precision::real_frames_read_as_f64_keep_their_doubles",
        "real-frames",
    ) else {
        return;
    };
    let limits = Limits::default();
    let arm = dir.join("armadillo-rollers-326.ply");
    let m64 = io::load_as(&arm, &limits, Precision::F64).unwrap();
    let m32 = io::load(&arm).unwrap();
    assert_eq!(m64.triangles(), m32.triangles());
    let exact = m64.positions_f64().unwrap();
    assert_eq!(m64.positions(), m32.positions());
    let unrounded = exact
        .iter()
        .flatten()
        .filter(|&&x| f64::from(x as f32) != x)
        .count();
    assert!(
        unrounded > exact.len(),
        "the armadillo's doubles need f64: {unrounded}"
    );
    let cloth = io::load_as(&dir.join("cloth-ball-92.ply"), &limits, Precision::F64).unwrap();
    let cloth32 = io::load(&dir.join("cloth-ball-92.ply")).unwrap();
    for (e, r) in cloth
        .positions_f64()
        .unwrap()
        .iter()
        .zip(cloth32.positions())
    {
        assert_eq!(*e, r.map(f64::from));
    }
}

// ---------------------------------------------------------------------------------------------
// f64 hierarchies: bounds enclose the exact points, contacts are exact for the f64 input
// ---------------------------------------------------------------------------------------------

use dhcd::bv::BoundingVolume;
use dhcd::narrow::{brute_force_pairs, brute_force_self_pairs};
use dhcd::shapes::splitmix64;
use dhcd::{
    collide_with, for_each_method, self_collide_with, Hierarchy, Options, Par, Refit, Workspace,
};

fn unit(state: &mut u64) -> f64 {
    (splitmix64(state) >> 11) as f64 / (1u64 << 53) as f64
}

/// `n` pairs of nearly touching triangles far from the origin (at x = 1000 + 3i, where an
/// f32 ulp is 6e-5): `A_i` a random triangle, `B_i` a triangle with one corner at a signed
/// distance of `+-1e-7`, `+-1e-9` or 0 from `A_i`'s plane, above `A_i`'s interior, and its
/// other corners well on one side. Rounding to f32 moves every corner by up to 3e-5, so it
/// decides many of these pairs differently from the f64 values.
fn near_touching(n: usize, seed: u64) -> (Mesh, Mesh) {
    let mut s = seed;
    let (mut pa, mut pb) = (Vec::new(), Vec::new());
    let sub = |p: [f64; 3], q: [f64; 3]| [p[0] - q[0], p[1] - q[1], p[2] - q[2]];
    let cross = |u: [f64; 3], v: [f64; 3]| {
        [
            u[1] * v[2] - u[2] * v[1],
            u[2] * v[0] - u[0] * v[2],
            u[0] * v[1] - u[1] * v[0],
        ]
    };
    for i in 0..n {
        let o = [1000.0 + 3.0 * i as f64, 0.25, -0.5];
        let mut r = || unit(&mut s) - 0.5;
        let a: [[f64; 3]; 3] = [
            [o[0] + r(), o[1] + r(), o[2] + 0.3 * r()],
            [o[0] + 1.0 + r(), o[1] + r(), o[2] + 0.3 * r()],
            [o[0] + r(), o[1] + 1.0 + r(), o[2] + 0.3 * r()],
        ];
        let nrm = cross(sub(a[1], a[0]), sub(a[2], a[0]));
        let len = (nrm[0] * nrm[0] + nrm[1] * nrm[1] + nrm[2] * nrm[2]).sqrt();
        let nrm = nrm.map(|x| x / len);
        // A point inside A (barycentric), moved off its plane by a tiny signed distance.
        let (u, v) = (0.2 + 0.3 * (r() + 0.5), 0.2 + 0.3 * (r() + 0.5));
        let inside: [f64; 3] =
            std::array::from_fn(|k| a[0][k] + u * (a[1][k] - a[0][k]) + v * (a[2][k] - a[0][k]));
        let off = [1e-7, -1e-7, 1e-9, -1e-9, 0.0][i % 5];
        let p: [f64; 3] = std::array::from_fn(|k| inside[k] + off * nrm[k]);
        // The other corners on the positive side.
        let q: [f64; 3] = std::array::from_fn(|k| p[k] + 0.5 * nrm[k] + 0.3 * r());
        let w: [f64; 3] = std::array::from_fn(|k| p[k] + 0.6 * nrm[k] - 0.3 * r());
        pa.extend_from_slice(&a);
        pb.extend_from_slice(&[p, q, w]);
    }
    let tris: Vec<[u32; 3]> = (0..n as u32)
        .map(|i| [3 * i, 3 * i + 1, 3 * i + 2])
        .collect();
    (
        Mesh::new_f64(pa, tris.clone()).unwrap(),
        Mesh::new_f64(pb, tris).unwrap(),
    )
}

fn rounded(m: &Mesh) -> Mesh {
    Mesh::new(m.positions().to_vec(), m.triangles().to_vec()).unwrap()
}

/// The meshes are meaningful: rounding to f32 changes the exact answer both ways.
#[test]
fn rounding_to_f32_changes_near_touching_answers() {
    let (a, b) = near_touching(200, 7);
    let exact = brute_force_pairs(&a, &b);
    let f32_answer = brute_force_pairs(&rounded(&a), &rounded(&b));
    let only64 = exact.iter().filter(|p| !f32_answer.contains(p)).count();
    let only32 = f32_answer.iter().filter(|p| !exact.contains(p)).count();
    assert!(
        only64 > 0 && only32 > 0,
        "f64-only {only64}, f32-only {only32}"
    );
    // Every designed pair is decided by its offset's sign in f64.
    assert!(exact.iter().all(|p| p[0] == p[1]));
}

fn f64_contacts_for<K: BoundingVolume>() {
    let (a, b) = near_touching(200, 11);
    let exact = brute_force_pairs(&a, &b);
    for refit in [Refit::Lazy, Refit::Eager, Refit::EagerBottomUp] {
        let options = Options {
            refit,
            ..Options::default()
        };
        let ha = Hierarchy::<K>::new(&a, options).unwrap();
        let hb = Hierarchy::<K>::new(&b, options).unwrap();
        assert_eq!(ha.validate().unwrap(), ha.node_count());
        for par in [Par::Seq, Par::Rayon(2)] {
            let c = collide_with(&ha, &hb, &mut Workspace::default(), par);
            assert_eq!(c.pairs, exact, "{:?} {refit:?} {par:?}", K::METHOD);
        }
        // One mesh holding both: self-collision, exact for f64.
        let both: Vec<[f64; 3]> = a
            .positions_f64()
            .unwrap()
            .iter()
            .chain(b.positions_f64().unwrap())
            .copied()
            .collect();
        let n = a.vertex_count() as u32;
        let tris: Vec<[u32; 3]> = a
            .triangles()
            .iter()
            .copied()
            .chain(b.triangles().iter().map(|t| t.map(|v| v + n)))
            .collect();
        let m = Mesh::new_f64(both, tris).unwrap();
        let want = brute_force_self_pairs(&m);
        assert_eq!(want.len(), exact.len());
        let mut h = Hierarchy::<K>::new(&m, options).unwrap();
        for par in [Par::Seq, Par::Rayon(2)] {
            let c = self_collide_with(&h, &mut Workspace::default(), par);
            assert_eq!(c.pairs, want, "self {:?} {refit:?} {par:?}", K::METHOD);
        }
        // Moved by an update: the bounds still enclose the exact points, contacts follow.
        let moved: Vec<[f64; 3]> = m
            .positions_f64()
            .unwrap()
            .iter()
            .map(|p| [p[0] + 1e-3, p[1] - 2e6, p[2]])
            .collect();
        h.update_positions_f64(&moved).unwrap();
        let c = self_collide_with(&h, &mut Workspace::default(), Par::Seq);
        let all: Vec<u32> = (0..h.node_count() as u32).collect();
        h.refit_nodes(&all, Par::Seq).unwrap();
        assert_eq!(h.validate().unwrap(), h.node_count());
        let mut mm = m.clone();
        mm.set_positions_f64(&moved).unwrap();
        assert_eq!(
            c.pairs,
            brute_force_self_pairs(&mm),
            "{:?} moved",
            K::METHOD
        );
        assert!(matches!(
            h.update_positions(m.positions()),
            Err(Error::PrecisionMismatch { .. })
        ));
    }
}

#[test]
fn f64_contacts_are_exact_for_every_kind() {
    for_each_method!(K => f64_contacts_for::<K>());
}

/// The real rod frames (f64): contacts of an f64 hierarchy equal the exact f64 brute force on
/// a slab of the rod (the whole frame would take minutes of brute force), for every method.
#[test]
fn f64_hierarchy_bounds_hold_on_a_real_frame() {
    let Some(dir) = crate::support::shared_data(
        "precision::f64_hierarchy_bounds_hold_on_a_real_frame",
        "real-frames",
    ) else {
        return;
    };
    let path = dir.join("rod-twist-3036.ply");
    let m = io::load_as(&path, &Limits::default(), Precision::F64).unwrap();
    let next = io::load_as(
        &dir.join("rod-twist-3037.ply"),
        &Limits::default(),
        Precision::F64,
    )
    .unwrap();
    for_each_method!(K => {
        let mut h = Hierarchy::<K>::new(&m, Options::default()).unwrap();
        assert_eq!(h.validate().unwrap(), h.node_count());
        let c = self_collide_with(&h, &mut Workspace::default(), Par::Rayon(2));
        assert!(c.pairs.is_empty(), "the rod frames do not intersect");
        h.update_positions_f64(next.positions_f64().unwrap()).unwrap();
        let all: Vec<u32> = (0..h.node_count() as u32).collect();
        h.refit_nodes(&all, Par::Seq).unwrap();
        assert_eq!(h.validate().unwrap(), h.node_count());
    });
}
