//! Every labelled query of `tests/data/ccd-sample-queries` (Wang et al. 2021; ground
//! truth from Mathematica): the CCD result equals the label, through the filtered entry and
//! through the exact path alone, and the two times of impact agree within the tolerance.

use std::path::{Path, PathBuf};

use dhcd::ccd::{self, CcdOptions};
use num_bigint::BigInt;
use num_rational::BigRational;
use num_traits::{One, Signed, ToPrimitive, Zero};

pub type Query = ([[f64; 3]; 4], [[f64; 3]; 4], bool);

/// The sample queries, which travel with the repository (`tests/data/README.md`).
pub fn samples_root() -> PathBuf {
    crate::support::repo_data("ccd-sample-queries")
}

/// The f64 equal to `num/den`; panics unless the rational is exactly an f64.
pub fn exact_f64(num: &str, den: &str) -> f64 {
    let q = BigRational::new(
        num.parse::<BigInt>().unwrap(),
        den.parse::<BigInt>().unwrap(),
    );
    if q.is_zero() {
        return 0.0;
    }
    // Reduced: the denominator must be a power of two, the numerator at most 53 bits.
    let d = q.denom();
    assert!(
        (d & (d - BigInt::one())).is_zero(),
        "{num}/{den} is not dyadic"
    );
    let k = d.bits() as i32 - 1;
    let n = q.numer().clone();
    let tz = n.abs().trailing_zeros().unwrap_or(0);
    let m = &n >> tz;
    assert!(m.abs().bits() <= 53, "{num}/{den} needs more than 53 bits");
    let mut x = m.to_f64().unwrap();
    let mut e = tz as i32 - k;
    while e > 0 {
        let s = e.min(1000);
        x *= 2f64.powi(s);
        e -= s;
    }
    while e < 0 {
        let s = (-e).min(1000);
        x *= 2f64.powi(-s);
        e += s;
    }
    assert_eq!(
        BigRational::from_float(x).unwrap(),
        q,
        "{num}/{den} is not an f64"
    );
    x
}

/// The queries of one CSV file.
pub fn load(path: &Path) -> Vec<Query> {
    let text = std::fs::read_to_string(path).unwrap();
    let rows: Vec<Vec<&str>> = text
        .lines()
        .filter(|l| !l.trim().is_empty())
        .map(|l| l.trim().split(',').collect())
        .collect();
    assert_eq!(rows.len() % 8, 0, "{}", path.display());
    rows.chunks(8)
        .map(|q| {
            let pt = |r: &Vec<&str>| -> [f64; 3] {
                assert_eq!(r.len(), 7);
                [
                    exact_f64(r[0], r[1]),
                    exact_f64(r[2], r[3]),
                    exact_f64(r[4], r[5]),
                ]
            };
            let truth = q[0][6].trim() == "1";
            assert!(q.iter().all(|r| r[6].trim() == q[0][6].trim()));
            (
                std::array::from_fn(|i| pt(&q[i])),
                std::array::from_fn(|i| pt(&q[4 + i])),
                truth,
            )
        })
        .collect()
}

/// Every (folder, kind (vertex-face or edge-edge), queries) of the sample set.
pub fn all_samples() -> Vec<(String, &'static str, Vec<Query>)> {
    let root = samples_root();
    let mut folders: Vec<_> = std::fs::read_dir(&root)
        .unwrap()
        .filter_map(|e| e.ok())
        .filter(|e| e.path().is_dir())
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .collect();
    folders.sort();
    let mut out = Vec::new();
    for f in folders {
        for kind in ["vertex-face", "edge-edge"] {
            let dir = root.join(&f).join(kind);
            let Ok(rd) = std::fs::read_dir(&dir) else {
                continue;
            };
            let mut files: Vec<_> = rd.filter_map(|e| e.ok()).map(|e| e.path()).collect();
            files.sort();
            let qs: Vec<Query> = files.iter().flat_map(|p| load(p)).collect();
            out.push((f.clone(), kind, qs));
        }
    }
    out
}

#[test]
fn rationals_convert_exactly() {
    assert_eq!(exact_f64("-1", "8388608"), -1.0 / 8388608.0);
    assert_eq!(exact_f64("3", "6"), 0.5);
    assert_eq!(exact_f64("0", "5"), 0.0);
}

#[test]
fn sample_queries_match_ground_truth() {
    let opts = CcdOptions::default();
    let (mut total, mut wrong, mut colliding) = (0, Vec::new(), 0);
    for (folder, kind, qs) in all_samples() {
        assert!(!qs.is_empty());
        for (i, (x0, x1, truth)) in qs.iter().enumerate() {
            let (fast, exact) = if kind == "vertex-face" {
                (
                    ccd::vertex_face(x0, x1, &opts),
                    ccd::vertex_face_exact(x0, x1, &opts),
                )
            } else {
                (
                    ccd::edge_edge(x0, x1, &opts),
                    ccd::edge_edge_exact(x0, x1, &opts),
                )
            };
            total += 1;
            colliding += *truth as usize;
            if fast.is_some() != *truth || exact.is_some() != *truth {
                wrong.push(format!(
                    "{folder}/{kind} #{i}: truth {truth}, got {fast:?} / exact {exact:?}"
                ));
            }
            if let (Some(a), Some(b)) = (fast, exact) {
                assert!(
                    (a - b).abs() <= ccd::TOI_TOLERANCE,
                    "{folder}/{kind} #{i}: toi {a} vs exact {b}"
                );
                assert!((0.0..=1.0).contains(&a));
            }
        }
    }
    println!(
        "sample queries: {} matched of {total} ({colliding} colliding)",
        total - wrong.len()
    );
    assert!(
        wrong.is_empty(),
        "{} mismatches:\n{}",
        wrong.len(),
        wrong.join("\n")
    );
    assert_eq!(total, 5279);
}
