//! `f64` meshes: construction, range and precision checks, and the loaders at full precision.

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
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../shared/data/real-frames");
    let limits = Limits::default();
    let arm = dir.join("armadillo-rollers-326.ply");
    if !arm.exists() {
        eprintln!("skipping: {} not found", arm.display());
        return;
    }
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
