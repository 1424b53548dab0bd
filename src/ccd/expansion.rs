//! Exact signs of small sums of products of f64 differences, by error-free transformations
//! (Knuth's two-sum, Dekker's two-product) and Shewchuk's expansion growth: no big
//! integers, no allocation.
//!
//! Exact when no operation overflows or underflows. Callers keep every input inside
//! [`Exactly`]'s range: magnitudes at most `2^400` and the lowest set bit of every nonzero
//! input at `2^-480` or above. Then every difference of two inputs is a multiple of
//! `2^-480` below `2^401`, every product of two differences (and each of Dekker's partial
//! products) a multiple of `2^-960` below `2^802`, and every intermediate sum of them is
//! exact in f64 or has an exact error term: nothing is lost.

use crate::distance::decompose;
pub(crate) use crate::distance::{two_product, two_sum};

/// The exponent of the lowest set bit of a nonzero finite `x` (`x` is a multiple of
/// `2^lowest_bit(x)`); `i32::MAX` for zero.
#[inline(always)]
pub(crate) fn lowest_bit(x: f64) -> i32 {
    let (m, e) = decompose(x);
    if m == 0 {
        i32::MAX
    } else {
        e + m.trailing_zeros() as i32
    }
}

/// Values in the range where [`sign_of_sum`] over their differences' products is exact.
pub(crate) struct Exactly;

impl Exactly {
    /// Largest magnitude accepted.
    pub(crate) const MAX: f64 = 2.582_249_878_086_908_6e120; // 2^400
    /// Lowest set bit accepted.
    pub(crate) const LOWEST_BIT: i32 = -480;

    /// `x` is zero, or at most [`Exactly::MAX`] in magnitude with its lowest set bit at
    /// [`Exactly::LOWEST_BIT`] or above.
    #[inline(always)]
    pub(crate) fn holds(x: f64) -> bool {
        x == 0.0 || (x.abs() <= Self::MAX && lowest_bit(x) >= Self::LOWEST_BIT)
    }
}

/// The exact sign of the sum of `terms` (each a float; the sum is taken exactly, without
/// rounding), when no two-sum among them overflows: the terms are grown into a
/// nonoverlapping expansion (zero components dropped), whose largest component carries
/// the sign of the sum.
#[inline]
pub(crate) fn sign_of_sum(terms: &[f64]) -> i8 {
    const CAPACITY: usize = 32;
    debug_assert!(terms.len() <= CAPACITY);
    let mut e = [0.0f64; CAPACITY];
    let mut n = 0usize;
    for &x in terms {
        if x == 0.0 {
            continue;
        }
        let mut q = x;
        let mut m = 0usize;
        for i in 0..n {
            let (s, err) = two_sum(q, e[i]);
            if err != 0.0 {
                e[m] = err;
                m += 1;
            }
            q = s;
        }
        if q != 0.0 {
            e[m] = q;
            m += 1;
        }
        n = m;
    }
    if n == 0 {
        0
    } else if e[n - 1] > 0.0 {
        1
    } else {
        -1
    }
}

/// The difference `a - b` as an exact pair `hi + lo`.
#[inline(always)]
pub(crate) fn difference(a: f64, b: f64) -> [f64; 2] {
    let (hi, lo) = two_sum(a, -b);
    [hi, lo]
}

/// The exact sign of `a0 b0 + sign (a1 b1)` for exact pairs (`hi + lo`), `sign` = 1 or -1:
/// a 2D dot product (`+1`) or cross product (`a0 b1 - a1 b0`, called with the factors
/// swapped and `-1`).
#[inline]
pub(crate) fn sign_of_two_products(
    a0: [f64; 2],
    b0: [f64; 2],
    a1: [f64; 2],
    b1: [f64; 2],
    sign: f64,
) -> i8 {
    let mut terms = [0.0f64; 16];
    let mut n = 0;
    for (a, b, s) in [(a0, b0, 1.0), (a1, b1, sign)] {
        for x in a {
            for y in b {
                if x != 0.0 && y != 0.0 {
                    let (p, e) = two_product(x, y);
                    terms[n] = s * p;
                    terms[n + 1] = s * e;
                    n += 2;
                }
            }
        }
    }
    sign_of_sum(&terms[..n])
}

#[cfg(test)]
mod tests {
    use super::super::testing::Rng;
    use super::*;
    use num_bigint::BigInt;
    use num_traits::{Signed, Zero};

    /// `x` as an integer multiple of `2^-1100` (exact for every f64 of the tested range).
    fn big(x: f64) -> BigInt {
        let (m, e) = decompose(x);
        BigInt::from(m) << ((e + 1100) as usize)
    }

    fn sign(x: &BigInt) -> i8 {
        if x.is_zero() {
            0
        } else if x.is_positive() {
            1
        } else {
            -1
        }
    }

    #[test]
    fn lowest_bit_of_normal_subnormal_and_zero() {
        assert_eq!(lowest_bit(1.0), 0);
        assert_eq!(lowest_bit(0.75), -2);
        assert_eq!(lowest_bit(-6.0), 1);
        assert_eq!(lowest_bit(f64::from_bits(1)), -1074);
        assert_eq!(lowest_bit(0.1), -55); // 0x3FB999999999999A: one trailing zero
        assert_eq!(lowest_bit(0.0), i32::MAX);
        assert!(Exactly::holds(0.1) && Exactly::holds(0.0) && !Exactly::holds(1e-150));
        assert!(!Exactly::holds(1e121) && Exactly::holds(-1e120));
    }

    #[test]
    fn two_sum_and_two_product_are_exact() {
        let mut rng = Rng(0x1234_5678_9abc_def1);
        for _ in 0..20_000 {
            let (a, b) = (rng.wide(), rng.wide());
            let (s, e) = two_sum(a, b);
            assert_eq!(big(s) + big(e), big(a) + big(b), "{a} + {b}");
            let (p, e) = two_product(a, b);
            assert_eq!((big(p) + big(e)) << 1100usize, big(a) * big(b), "{a} * {b}");
        }
    }

    #[test]
    fn signs_of_products_of_differences_are_exact() {
        let mut rng = Rng(0x0bad_cafe_f00d_d00d);
        let mut zeros = 0;
        for n in 0..20_000 {
            // Points on a coarse grid (many exact zeros and ties) or anywhere in range.
            let p: [f64; 8] = std::array::from_fn(|_| {
                if n % 2 == 0 {
                    rng.below(5) as f64 * 0.375 - 0.75
                } else {
                    rng.wide()
                }
            });
            let d = |i: usize, j: usize| difference(p[i], p[j]);
            let bd = |i: usize, j: usize| big(p[i]) - big(p[j]);
            for sg in [1.0, -1.0] {
                let got = sign_of_two_products(d(0, 1), d(2, 3), d(4, 5), d(6, 7), sg);
                let second = bd(4, 5) * bd(6, 7);
                let exact = bd(0, 1) * bd(2, 3) + if sg > 0.0 { second } else { -second };
                assert_eq!(got, sign(&exact), "{p:?} {sg}");
                zeros += (got == 0) as u32;
            }
        }
        assert!(zeros > 1000, "{zeros}");
    }
}
