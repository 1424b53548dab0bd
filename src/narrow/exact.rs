//! Exact orientations of `f64` points, whatever their magnitudes.
//!
//! Shewchuk's adaptive predicates (the `robust` crate) are exact when no intermediate
//! quantity underflows or overflows. When every coordinate is zero or of magnitude in
//! `[2^-200, 2^200]`, every coordinate is an integer multiple of `2^-252`, so every exact
//! quantity of the predicate (a polynomial of degree at most 3 in the coordinates, with
//! integer coefficients) and every component of its expansions is a multiple of `2^-756`,
//! far above the underflow threshold, and below `2^700`: the predicate is exact there. Other
//! inputs (tiny nonzero coordinates next to ordinary ones) are decided in big integers on the
//! points' common binary grid: slower, never wrong.

use num_bigint::BigInt;
use robust::{Coord, Coord3D};

/// Whether `robust` is exact for a coordinate (module doc).
#[inline]
fn safe(x: f64) -> bool {
    const LO: f64 = f64::from_bits((1023 - 200) << 52);
    const HI: f64 = f64::from_bits((1023 + 200) << 52);
    let a = x.abs();
    x == 0.0 || (LO..=HI).contains(&a)
}

/// The sign of `orient3d(a, b, c, d)` as `robust::orient3d` defines it (positive when `d`
/// lies below the plane through `a, b, c` seen with `a, b, c` counterclockwise), exactly: the
/// adaptive predicate's value where it is exact, else `-1.0`, `0.0` or `1.0`.
pub(crate) fn orient3d(a: &[f64; 3], b: &[f64; 3], c: &[f64; 3], d: &[f64; 3]) -> f64 {
    if [a, b, c, d].iter().all(|p| p.iter().all(|&x| safe(x))) {
        let p = |v: &[f64; 3]| Coord3D {
            x: v[0],
            y: v[1],
            z: v[2],
        };
        return robust::orient3d(p(a), p(b), p(c), p(d));
    }
    let [a, b, c, d] = grid([*a, *b, *c, *d].as_flattened())
        .chunks(3)
        .map(|p| [p[0].clone(), p[1].clone(), p[2].clone()])
        .collect::<Vec<_>>()
        .try_into()
        .unwrap_or_else(|_| unreachable!("four points"));
    let sub = |p: &[BigInt; 3], q: &[BigInt; 3]| [&p[0] - &q[0], &p[1] - &q[1], &p[2] - &q[2]];
    let (ad, bd, cd) = (sub(&a, &d), sub(&b, &d), sub(&c, &d));
    let minor = |p: &[BigInt; 3], q: &[BigInt; 3]| &p[0] * &q[1] - &p[1] * &q[0];
    let det = &ad[2] * minor(&bd, &cd) + &bd[2] * minor(&cd, &ad) + &cd[2] * minor(&ad, &bd);
    signum(&det)
}

/// The sign of `orient2d(a, b, c)` as `robust::orient2d` defines it (positive when `a, b, c`
/// turn counterclockwise), exactly, as [`orient3d`].
pub(crate) fn orient2d(a: [f64; 2], b: [f64; 2], c: [f64; 2]) -> f64 {
    if [a, b, c].iter().all(|p| p.iter().all(|&x| safe(x))) {
        let p = |v: [f64; 2]| Coord { x: v[0], y: v[1] };
        return robust::orient2d(p(a), p(b), p(c));
    }
    let g = grid(&[a[0], a[1], b[0], b[1], c[0], c[1]]);
    let (acx, acy) = (&g[0] - &g[4], &g[1] - &g[5]);
    let (bcx, bcy) = (&g[2] - &g[4], &g[3] - &g[5]);
    signum(&(acx * bcy - acy * bcx))
}

fn signum(x: &BigInt) -> f64 {
    match x.sign() {
        num_bigint::Sign::Minus => -1.0,
        num_bigint::Sign::NoSign => 0.0,
        num_bigint::Sign::Plus => 1.0,
    }
}

/// Finite `xs` as integers on their common binary grid: `xs[i] = out[i] 2^e` for one `e`.
fn grid(xs: &[f64]) -> Vec<BigInt> {
    // A finite f64 is m 2^(q - 1075), m < 2^53 (subnormals: biased exponent 0 taken as 1).
    let parts: Vec<(i64, i64)> = xs
        .iter()
        .map(|&x| {
            let bits = x.to_bits();
            let biased = ((bits >> 52) & 0x7ff) as i64;
            let frac = (bits & ((1 << 52) - 1)) as i64;
            let m = if biased == 0 { frac } else { frac | (1 << 52) };
            (if x < 0.0 { -m } else { m }, biased.max(1))
        })
        .collect();
    let lo = parts
        .iter()
        .filter(|p| p.0 != 0)
        .map(|p| p.1)
        .min()
        .unwrap_or(1);
    parts
        .iter()
        .map(|&(m, q)| BigInt::from(m) << (q - lo).max(0) as usize)
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn big3(a: &[f64; 3], b: &[f64; 3], c: &[f64; 3], d: &[f64; 3]) -> f64 {
        // The big-integer path, whatever the range.
        let g = grid([*a, *b, *c, *d].as_flattened());
        let p: Vec<[BigInt; 3]> = g
            .chunks(3)
            .map(|p| [p[0].clone(), p[1].clone(), p[2].clone()])
            .collect();
        let sub = |p: &[BigInt; 3], q: &[BigInt; 3]| [&p[0] - &q[0], &p[1] - &q[1], &p[2] - &q[2]];
        let (ad, bd, cd) = (sub(&p[0], &p[3]), sub(&p[1], &p[3]), sub(&p[2], &p[3]));
        let minor = |p: &[BigInt; 3], q: &[BigInt; 3]| &p[0] * &q[1] - &p[1] * &q[0];
        signum(&(&ad[2] * minor(&bd, &cd) + &bd[2] * minor(&cd, &ad) + &cd[2] * minor(&ad, &bd)))
    }

    /// Both paths agree in sign (and with `robust`) on ordinary points, and the big-integer
    /// path decides what underflow would hide.
    #[test]
    fn both_paths_agree_and_tiny_coordinates_stay_exact() {
        let pts = [
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [0.25, 0.25, 1e-9],
            [0.3, 0.1, -2.5],
            [0.1 + 1e-16, 0.2, 0.0],
        ];
        for a in &pts {
            for b in &pts {
                for c in &pts {
                    for d in &pts {
                        assert_eq!(orient3d(a, b, c, d).signum_or_zero(), big3(a, b, c, d));
                    }
                }
            }
        }
        // A point 1e-300 above the plane z = 0 (products of 1e-300 differences underflow).
        let (a, b, c) = ([0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]);
        let up = [0.5, 0.5, 1e-300];
        let down = [0.5, 0.5, -1e-300];
        assert_eq!(orient3d(&a, &b, &c, &up), -orient3d(&a, &b, &c, &down));
        assert_ne!(orient3d(&a, &b, &c, &up), 0.0);
        let tiny = [[1e-310, 0.0, 0.0], [0.0, 1e-310, 0.0], [0.0, 0.0, 1e-310]];
        assert_ne!(orient3d(&tiny[0], &tiny[1], &tiny[2], &[0.0; 3]), 0.0);
        assert_eq!(orient2d([0.0, 0.0], [1e-320, 0.0], [0.0, 1e-320]), 1.0);
        assert_eq!(orient2d([0.0, 0.0], [1e-320, 0.0], [2e-320, 0.0]), 0.0);
    }

    trait SignumOrZero {
        fn signum_or_zero(self) -> f64;
    }

    impl SignumOrZero for f64 {
        fn signum_or_zero(self) -> f64 {
            if self == 0.0 {
                0.0
            } else {
                self.signum()
            }
        }
    }
}
