//! CCD of single pairs whose coordinates span the whole `f64` exponent range: a query and the
//! same query scaled by a power of two have the same answer; a contact with a minimum
//! distance too small to certify in floats (`5e-324`) is decided by the contact itself,
//! equal to the exact path; and a query that takes the exact path for seconds stops within
//! one step when asked.

use std::cell::Cell;

use dhcd::ccd::{self, CcdOptions, TOI_TOLERANCE};
use dhcd::Error;

/// `x * 2^k` if exact (and finite), else `None`.
fn scaled(x: f64, k: i32) -> Option<f64> {
    let s = 2f64.powi(k / 2) * 2f64.powi(k - k / 2);
    let y = x * s;
    (y.is_finite() && y / s == x && (y != 0.0 || x == 0.0)).then_some(y)
}

/// One CCD query: the four points at t = 0 and at t = 1.
type Query = ([[f64; 3]; 4], [[f64; 3]; 4]);

fn scale_query(q: &Query, k: i32) -> Option<Query> {
    let mut out = *q;
    for p in out.0.iter_mut().chain(out.1.iter_mut()) {
        for x in p.iter_mut() {
            *x = scaled(*x, k)?;
        }
    }
    Some(out)
}

/// Every sample query scaled by `2^k` (where that is exact), for `k` from `-1000` to `900`:
/// the same hits, and times within the tolerance of each other (both are within it of the
/// true time, which scaling does not move).
#[test]
fn a_query_scaled_by_a_power_of_two_has_the_same_answer() {
    let o = CcdOptions::default();
    let mut checked = 0;
    for (folder, kind, qs) in crate::ccd_samples::all_samples() {
        let test = if kind == "vertex-face" {
            ccd::vertex_face
        } else {
            ccd::edge_edge
        };
        for (x0, x1, truth) in qs.iter().step_by(7) {
            let want = test(x0, x1, &o);
            assert_eq!(want.is_some(), *truth, "{folder}/{kind}");
            for k in [-1000, -600, -90, 70, 500, 900] {
                let Some((y0, y1)) = scale_query(&(*x0, *x1), k) else {
                    continue;
                };
                let got = test(&y0, &y1, &o);
                assert_eq!(
                    got.is_some(),
                    *truth,
                    "{folder}/{kind} scaled 2^{k}: {x0:?} {x1:?}"
                );
                if let (Some(a), Some(b)) = (got, want) {
                    assert!(
                        (a - b).abs() <= TOI_TOLERANCE,
                        "{folder}/{kind} 2^{k}: {a} {b}"
                    );
                }
                checked += 1;
            }
        }
    }
    assert!(checked > 3000, "{checked}");
}

/// A vertex falling through a unit triangle's interior at `t = 1/2`, with coordinates of
/// every magnitude in the other axes' noise, and a minimum distance of `5e-324` (no float
/// test can certify "within 5e-324"): the answer is the exact path's.
#[test]
fn a_contact_decides_a_minimum_distance_too_small_for_floats() {
    let x0 = [
        [0.25, 0.25, 1.0],
        [0.0, 0.0, 1e-300],
        [1.0, 5e-324, 0.0],
        [0.0, 1.0, -1e-300],
    ];
    let mut x1 = x0;
    x1[0][2] = -1.0;
    for delta in [5e-324, 1e-300, 1e-200] {
        let o = CcdOptions::new(1.0, delta).unwrap();
        let got = ccd::vertex_face(&x0, &x1, &o).expect("the vertex crosses the triangle");
        let exact = ccd::vertex_face_exact(&x0, &x1, &o).unwrap();
        assert!(got <= 0.5 && 0.5 - got <= TOI_TOLERANCE, "{got}");
        assert!((got - exact).abs() <= TOI_TOLERANCE, "{got} {exact}");
    }
}

/// One of the adversarial gadgets (coordinates 0, `5e-324`, `1e-300`, 1 and `3e38` with random
/// signs, minimum distance `5e-324`) that only the exact path decides, over many seconds: a
/// stop function that says stop at its fourth call ends it with `Cancelled`, and the
/// single-pair entry without a stop still answers the same as before.
#[test]
fn a_long_exact_query_stops_when_asked() {
    let x0 = [
        [1e-300, 3e38, 1.0],
        [-1.0, -5e-324, -1e-300],
        [-0.0, -3e38, -3e38],
        [5e-324, -0.0, 1.0],
    ];
    let x1 = [
        [-5e-324, -5e-324, 3e38],
        [0.0, 1.0, 1.0],
        [0.0, 0.0, 3e38],
        [-3e38, 3e38, -1e-300],
    ];
    let o = CcdOptions::new(1.0, 5e-324).unwrap();
    let calls = Cell::new(0);
    let stop = || {
        calls.set(calls.get() + 1);
        calls.get() > 3
    };
    assert_eq!(
        ccd::vertex_face_until(&x0, &x1, &o, &stop),
        Err(Error::Cancelled)
    );
    assert_eq!(calls.get(), 4);
    // A stop that never fires changes nothing on a quick query.
    let quick = crate::ccd_samples::all_samples()
        .into_iter()
        .find(|(_, kind, _)| *kind == "vertex-face")
        .unwrap()
        .2[0];
    let d = CcdOptions::default();
    assert_eq!(
        ccd::vertex_face_until(&quick.0, &quick.1, &d, &|| false),
        Ok(ccd::vertex_face(&quick.0, &quick.1, &d))
    );
}
