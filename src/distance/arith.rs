//! Arithmetic shared by the distance primitives.
//!
//! Every polynomial the primitives test is written once, generic over [`Ring`], and evaluated
//! in `f64` by the float filter and in big integers by the exact fallback, so the two cannot
//! disagree on what they compute. A third ring, `Count` (tests only), evaluates the same code
//! symbolically and checks the filter's declared error bounds ([`Bound`]) against the real
//! shape of each formula.

use num_bigint::{BigInt, BigUint};
use num_integer::Integer;
use num_traits::{ToPrimitive, Zero};

/// The unit roundoff of `f64`, `2^-53`.
pub(crate) const EPS: f64 = f64::EPSILON / 2.0;

/// A commutative ring: what the polynomials need.
pub(crate) trait Ring: Clone {
    fn add(&self, o: &Self) -> Self;
    fn sub(&self, o: &Self) -> Self;
    fn mul(&self, o: &Self) -> Self;
}

impl Ring for f64 {
    #[inline(always)]
    fn add(&self, o: &f64) -> f64 {
        self + o
    }
    #[inline(always)]
    fn sub(&self, o: &f64) -> f64 {
        self - o
    }
    #[inline(always)]
    fn mul(&self, o: &f64) -> f64 {
        self * o
    }
}

impl Ring for BigInt {
    fn add(&self, o: &BigInt) -> BigInt {
        self + o
    }
    fn sub(&self, o: &BigInt) -> BigInt {
        self - o
    }
    fn mul(&self, o: &BigInt) -> BigInt {
        self * o
    }
}

// ---------------------------------------------------------------------------------------------
// Error-free transformations, and the checked float ring.

/// `a + b = s + e` exactly (Knuth's two-sum), for any finite `a`, `b` whose sum does not
/// overflow.
#[inline(always)]
pub(crate) fn two_sum(a: f64, b: f64) -> (f64, f64) {
    let s = a + b;
    let bb = s - a;
    let e = (a - (s - bb)) + (b - bb);
    (s, e)
}

/// Dekker's split of `a` into two halves of at most 26 significant bits each.
#[inline(always)]
fn split(a: f64) -> (f64, f64) {
    let c = 134_217_729.0 * a; // 2^27 + 1
    let hi = c - (c - a);
    (hi, a - hi)
}

/// `a b = p + e` exactly (Dekker's two-product), when `|a|, |b| < 2^996` and the partial
/// products do not underflow (the lowest set bits of `a` and `b` sum to `-1074` or more).
#[inline(always)]
pub(crate) fn two_product(a: f64, b: f64) -> (f64, f64) {
    let p = a * b;
    let (ah, al) = split(a);
    let (bh, bl) = split(b);
    let e = ((ah * bh - p) + ah * bl + al * bh) + al * bl;
    (p, e)
}

/// A float with whether it is exactly the value of the formula that computed it: the ring
/// tried before big integers on the signs the filter leaves open. Near-ties are mostly exact
/// ties whose values are exact in floats: features on a common grid (procedural sheets,
/// meshes lying on a coordinate plane), coincident points (a zero difference makes every
/// product with it an exact zero, whatever the other factor). Each operation checks that it
/// rounded nothing (the error term of Knuth's two-sum or Dekker's two-product is zero); a
/// value whose `exact` flag holds is the real value, so its sign is exact.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Checked {
    pub(crate) v: f64,
    pub(crate) exact: bool,
}

impl Checked {
    /// A value not computed: inexact, so a formula that reads it by mistake falls to the
    /// big integers rather than giving a wrong sign.
    pub(crate) const UNKNOWN: Self = Self {
        v: f64::NAN,
        exact: false,
    };

    /// An input (exact by definition).
    #[inline(always)]
    pub(crate) fn input(v: f64) -> Self {
        Self { v, exact: true }
    }

    /// The exact sign, when the value is exact.
    #[inline(always)]
    pub(crate) fn sign(self) -> Option<i8> {
        let sign = if self.v > 0.0 {
            1
        } else if self.v < 0.0 {
            -1
        } else {
            0
        };
        self.exact.then_some(sign)
    }

    #[inline(always)]
    fn is_exact_zero(self) -> bool {
        self.exact && self.v == 0.0
    }
}

/// Factors at most this large (`2^995`): Dekker's split does not overflow.
const CHECKED_FACTOR_MAX: f64 = 3.348_464_397_457_085_4e299; // 2^995
/// Products at least this large (`2^-860`, or zero from a zero factor): Dekker's partial
/// products do not underflow (their lowest bits lie above `2^-970`).
const CHECKED_PRODUCT_MIN: f64 = 1.300_779_634_956_185_9e-259; // 2^-860

impl Ring for Checked {
    #[inline(always)]
    fn add(&self, o: &Self) -> Self {
        let (v, e) = two_sum(self.v, o.v);
        Self {
            v,
            exact: self.exact & o.exact & (e == 0.0) & v.is_finite(),
        }
    }
    #[inline(always)]
    fn sub(&self, o: &Self) -> Self {
        self.add(&Self {
            v: -o.v,
            exact: o.exact,
        })
    }
    #[inline(always)]
    fn mul(&self, o: &Self) -> Self {
        if self.is_exact_zero() || o.is_exact_zero() {
            return Self::input(0.0);
        }
        let in_range = (self.v.abs() <= CHECKED_FACTOR_MAX) & (o.v.abs() <= CHECKED_FACTOR_MAX);
        let (v, e) = two_product(self.v, o.v);
        Self {
            v,
            exact: self.exact
                & o.exact
                & in_range
                & (v.abs() >= CHECKED_PRODUCT_MIN)
                & (e == 0.0)
                & v.is_finite(),
        }
    }
}

/// Dot products in the checked ring computed on demand: a sign computes only those its
/// formula reads. The others stay [`Checked::UNKNOWN`], so a formula that reads one it did
/// not ask for falls to big integers instead of giving a wrong sign.
pub(crate) struct CheckedDots<const N: usize> {
    d: [Checked; N],
    /// Bit `k` for `d[k]` computed.
    have: u8,
}

impl<const N: usize> CheckedDots<N> {
    pub(crate) fn new() -> Self {
        Self {
            d: [Checked::UNKNOWN; N],
            have: 0,
        }
    }

    /// The dot products, with every one of `need` (bit `k` for the `k`-th) computed by
    /// `dot(k)` if it was not yet.
    pub(crate) fn with(&mut self, need: u8, dot: impl Fn(usize) -> Checked) -> &[Checked; N] {
        let missing = need & !self.have;
        for (k, d) in self.d.iter_mut().enumerate() {
            if missing >> k & 1 == 1 {
                *d = dot(k);
            }
        }
        self.have |= missing;
        &self.d
    }
}

/// The squared distance `num / den` of checked parts, correctly rounded, when both are exact
/// (IEEE division rounds the exact quotient once).
pub(crate) fn checked_ratio(parts: Parts<Checked>) -> Option<f64> {
    let (num, den) = match parts {
        Parts::Point(r2) => (r2, Checked::input(1.0)),
        Parts::Line(n, e) => (n, e),
        Parts::Plane(s, nn) => (s.mul(&s), nn),
    };
    (num.exact & den.exact & (den.v > 0.0)).then(|| num.v / den.v)
}

/// A 3-vector.
pub(crate) type V<R> = [R; 3];

/// `a - b` componentwise (the leaves: differences of input points).
#[inline(always)]
pub(crate) fn sub3<R: Ring>(a: &V<R>, b: &V<R>) -> V<R> {
    [a[0].sub(&b[0]), a[1].sub(&b[1]), a[2].sub(&b[2])]
}

/// `(a0 b0 + a1 b1) + a2 b2`.
#[inline(always)]
pub(crate) fn dot<R: Ring>(a: &V<R>, b: &V<R>) -> R {
    a[0].mul(&b[0]).add(&a[1].mul(&b[1])).add(&a[2].mul(&b[2]))
}

/// `a x b`.
#[inline(always)]
pub(crate) fn cross<R: Ring>(a: &V<R>, b: &V<R>) -> V<R> {
    [
        a[1].mul(&b[2]).sub(&a[2].mul(&b[1])),
        a[2].mul(&b[0]).sub(&a[0].mul(&b[2])),
        a[0].mul(&b[1]).sub(&a[1].mul(&b[0])),
    ]
}

/// `a b - c d` (a Lagrange identity `(x x y).(z x w)` written on dot products).
#[inline(always)]
pub(crate) fn lagrange<R: Ring>(a: &R, b: &R, c: &R, d: &R) -> R {
    a.mul(b).sub(&c.mul(d))
}

/// A squared distance as the parts its decision and value are computed from.
#[derive(Clone, Debug)]
pub(crate) enum Parts<R> {
    /// `|r|^2`, from a point to a corner.
    Point(R),
    /// `(N, E)`, `D = N / E`, from a point to a line.
    Line(R, R),
    /// `(s, nn)`, `D = s^2 / nn`, from a point to a plane.
    Plane(R, R),
}

impl<R: Ring> Parts<R> {
    /// `num - dd den`: nonpositive iff the distance is at most `d` (`den > 0`).
    #[inline(always)]
    pub(crate) fn q(&self, dd: &R) -> R {
        match self {
            Parts::Point(r2) => r2.sub(dd),
            Parts::Line(n, e) => n.sub(&dd.mul(e)),
            Parts::Plane(s, nn) => s.mul(s).sub(&dd.mul(nn)),
        }
    }
}

/// Squared distance from a point to a corner: `|r|^2`.
#[inline(always)]
pub(crate) fn point_parts<R: Ring>(r: &V<R>) -> Parts<R> {
    Parts::Point(dot(r, r))
}

/// [`point_parts`]`(r).q(dd)` = `|r|^2 - dd` (the filter's bound is checked on it).
#[cfg(test)]
pub(crate) fn point_q<R: Ring>(r: &V<R>, dd: &R) -> R {
    point_parts(r).q(dd)
}

/// The squared distance from a point to a line as `N / E`: `N = |e x w|^2`, `E = |e|^2`,
/// for the line through `o` with direction `e` and `w = x - o`.
#[inline(always)]
pub(crate) fn line_parts<R: Ring>(e: &V<R>, w: &V<R>) -> Parts<R> {
    let c = cross(e, w);
    Parts::Line(dot(&c, &c), dot(e, e))
}

/// `N - dd E`: nonpositive iff the line is within `d` (`E > 0`).
#[cfg(test)]
pub(crate) fn line_q<R: Ring>(e: &V<R>, w: &V<R>, dd: &R) -> R {
    line_parts(e, w).q(dd)
}

/// The squared distance from a point to a plane as `s^2 / nn`: `s = n . w`, `nn = |n|^2`,
/// for the plane through `o` with normal `n` and `w = x - o`.
#[inline(always)]
pub(crate) fn plane_parts<R: Ring>(n: &V<R>, w: &V<R>) -> Parts<R> {
    Parts::Plane(dot(n, w), dot(n, n))
}

/// `s^2 - dd nn`: nonpositive iff the plane is within `d` (`nn > 0`).
#[inline(always)]
pub(crate) fn plane_q<R: Ring>(n: &V<R>, w: &V<R>, dd: &R) -> R {
    plane_parts(n, w).q(dd)
}

/// The exact squared distance `num / den` of exact parts.
pub(crate) fn exact_ratio(parts: Parts<BigInt>) -> (BigInt, BigInt) {
    match parts {
        Parts::Point(r2) => (r2, BigInt::from(1)),
        Parts::Line(n, e) => (n, e),
        Parts::Plane(s, nn) => (s.mul(&s), nn),
    }
}

// ---------------------------------------------------------------------------------------------
// The float filter.

/// The shape of a polynomial as its code evaluates it, from which the filter's error bound
/// follows: `degree` in the leaves, `terms` monomials once expanded (with multiplicity, each
/// with coefficient +-1), and `depth` roundings on the longest path from a leaf (an input
/// difference, itself one rounding; `d` enters unrounded) to the result.
///
/// Lemma (the filter's bound). Let every leaf be at most `M` in magnitude (exactly). Evaluated
/// in `f64` without overflow or underflow, the computed value `v` of such a polynomial `Q`
/// satisfies `|v - Q| <= gamma_depth * P`, with `P` the sum of the magnitudes of the
/// expanded monomials (the standard bound of a sum-of-products tree, Higham, *Accuracy and
/// Stability of Numerical Algorithms*, 3.1-3.5: each monomial carries a factor
/// `(1 + theta_depth)`, `|theta_k| <= gamma_k = k eps / (1 - k eps)`), and `P <= terms *
/// M^degree`. [`Bound::factor`] is `((depth + 1) terms + 1) eps`, above `gamma_depth terms`
/// with room for the roundings of `M^degree` and of the product, and for the `M` being the
/// rounded extent (`M >= M_exact (1 - eps)`). Overflow and underflow: the filter runs only
/// with `2^-60 <= M <= 2^61` (after an exact scaling, see [`scale_of`]) and every leaf at most
/// `M`, so no value overflows (degree <= 6: below `48 * 2^366`), and a product that
/// underflows adds at most `2^-1075` absolute, which the rest of a formula multiplies by at
/// most about `2^260`: below `2^-800` in all, while the constant's slack (the `+ 1` and the
/// `depth + 1`) is at least `eps M^degree >= 2^-413`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct Bound {
    pub(crate) degree: u32,
    pub(crate) terms: u32,
    pub(crate) depth: u32,
}

impl Bound {
    /// The relative factor `c` of the bound `c M^degree`.
    #[inline(always)]
    pub(crate) const fn factor(self) -> f64 {
        ((self.depth + 1) * self.terms + 1) as f64 * EPS
    }
}

/// `a . b` of two leaves.
pub(crate) const DOT: Bound = Bound {
    degree: 2,
    terms: 3,
    depth: 4,
};
/// A sum or difference of two dot products of leaves.
pub(crate) const DOT2: Bound = Bound {
    degree: 2,
    terms: 6,
    depth: 5,
};
/// `(x + y) - z` of three dot products of leaves.
pub(crate) const DOT3: Bound = Bound {
    degree: 2,
    terms: 9,
    depth: 6,
};
/// [`lagrange`] of four dot products.
pub(crate) const LAGRANGE: Bound = Bound {
    degree: 4,
    terms: 18,
    depth: 6,
};
/// [`lagrange`] of two dot products and two [`DOT2`]s.
pub(crate) const LAGRANGE2: Bound = Bound {
    degree: 4,
    terms: 36,
    depth: 7,
};
/// [`point_q`].
pub(crate) const POINT: Bound = Bound {
    degree: 2,
    terms: 4,
    depth: 5,
};
/// [`line_q`].
pub(crate) const LINE: Bound = Bound {
    degree: 4,
    terms: 15,
    depth: 7,
};
/// [`plane_q`] with `n` a [`cross`] of two leaves.
pub(crate) const PLANE: Bound = Bound {
    degree: 6,
    terms: 48,
    depth: 8,
};

/// Powers of the leaves' bound `M`, to turn a [`Bound`] into an absolute error bound.
#[derive(Clone, Copy)]
pub(crate) struct Powers {
    m2: f64,
    m4: f64,
    m6: f64,
}

impl Powers {
    #[inline(always)]
    pub(crate) fn new(m: f64) -> Self {
        let m2 = m * m;
        let m4 = m2 * m2;
        Self {
            m2,
            m4,
            m6: m4 * m2,
        }
    }

    /// The absolute error bound of a polynomial of shape `b`.
    #[inline(always)]
    pub(crate) fn of(self, b: Bound) -> f64 {
        let p = match b.degree {
            2 => self.m2,
            4 => self.m4,
            _ => self.m6,
        };
        b.factor() * p
    }
}

/// The sign of `v` certified against the error bound `e` (`|v - exact| <= e`): `Some(-1, 0
/// or 1)`, or `None` when `|v| <= e` (also for NaN).
#[inline(always)]
pub(crate) fn certified(v: f64, e: f64) -> Option<i8> {
    if v > e {
        Some(1)
    } else if v < -e {
        Some(-1)
    } else {
        None
    }
}

/// The smallest extent the filter takes unscaled, `2^-60`: smaller configurations are scaled
/// up by a power of two first (exact).
pub(crate) const TINY: f64 = 1.0 / (1u64 << 60) as f64;
/// The largest extent the filter takes, `2^60` (about `1.15e18`); larger ones (and
/// non-finite input) go to the exact path.
pub(crate) const HUGE: f64 = (1u64 << 60) as f64;
/// A leaf component below this (and nonzero) may underflow in the value formulas: the value
/// is then computed exactly.
pub(crate) const VALUE_TINY: f64 = 6.223_015_277_861_142e-61; // 2^-200

/// What the filter does with a configuration of extent `m` (the largest side of the box of
/// its points): `Some(k)`, scale the leaves by `2^k` (`k >= 0`, `0` when `m` is in range),
/// or `None`, use the exact path (`m` above [`HUGE`], or not finite). `m > 0`.
#[inline(always)]
pub(crate) fn scale_of(m: f64) -> Option<i32> {
    if (TINY..=HUGE).contains(&m) {
        Some(0)
    } else if m > 0.0 && m < TINY {
        // m * 2^k in [1, 2).
        Some(-floor_log2(m))
    } else {
        None
    }
}

/// `floor(log2(x))` of a positive finite `x` (subnormals included).
pub(crate) fn floor_log2(x: f64) -> i32 {
    let bits = x.to_bits();
    let e = ((bits >> 52) & 0x7ff) as i32;
    if e == 0 {
        // Subnormal: x = frac 2^-1074.
        let frac = bits & ((1 << 52) - 1);
        -1074 + 63 - frac.leading_zeros() as i32
    } else {
        e - 1023
    }
}

/// `2^e` for `-1074 <= e <= 1023`.
pub(crate) fn pow2(e: i32) -> f64 {
    debug_assert!((-1074..=1023).contains(&e));
    if e >= -1022 {
        f64::from_bits(((e + 1023) as u64) << 52)
    } else {
        f64::from_bits(1u64 << (e + 1074))
    }
}

/// `x 2^e` (exact when the result is a normal number; a subnormal result may be rounded
/// twice: an error below `2^-1073`).
pub(crate) fn ldexp(mut x: f64, mut e: i32) -> f64 {
    while e > 1000 {
        x *= pow2(1000);
        e -= 1000;
    }
    while e < -1000 {
        x *= pow2(-1000);
        e += 1000;
    }
    x * pow2(e)
}

/// The float value of a face or line-line type is used when `|n|^2 > SLIVER |x|^2 |y|^2`
/// for `n = x cross y` (`sigma = |x| |y| / |n| < 2^20`): then the computed normal's error is
/// a tiny fraction of `|n|` and the first-order error analysis holds; thinner slivers and
/// nearly parallel edges take the exact value.
pub(crate) const SLIVER: f64 = 1.0 / (1u64 << 40) as f64;

/// The float value of a squared distance from its parts: `|r|^2`, `N / E`, `s (s / nn)`
/// (not `s^2 / nn`, so that `s^2` cannot underflow); `None` when the formula's accuracy is
/// not assured: a leaf too small ([`has_tiny`]) among `leaves` (the ones the parts are made
/// of), or for a plane a configuration too thin ([`SLIVER`]; `x, y` the two vectors whose
/// cross product is the normal).
#[inline(always)]
pub(crate) fn float_value<const N: usize>(
    parts: &Parts<f64>,
    leaves: [&V<f64>; N],
    sliver: Option<(&V<f64>, &V<f64>)>,
) -> Option<f64> {
    match *parts {
        Parts::Point(r2) => Some(r2),
        Parts::Line(n, e) => (!has_tiny(leaves)).then(|| n / e),
        Parts::Plane(s, nn) => {
            if has_tiny(leaves) {
                return None;
            }
            if let Some((x, y)) = sliver {
                if nn.is_nan() || nn <= SLIVER * (dot(x, x) * dot(y, y)) {
                    return None;
                }
            }
            Some(s * (s / nn))
        }
    }
}

/// Whether a value formula over these leaf components could underflow (some component is
/// nonzero and below [`VALUE_TINY`]). PERF: integer compares on the magnitudes' bits, no
/// iterator.
#[inline(always)]
pub(crate) fn has_tiny<const N: usize>(vs: [&V<f64>; N]) -> bool {
    const ABS: u64 = !(1 << 63);
    let limit = VALUE_TINY.to_bits() - 1;
    let mut any = false;
    for v in vs {
        for x in v {
            // 0 < |x| < VALUE_TINY  <=>  |x|'s bits - 1 < VALUE_TINY's bits - 1 (wrapping).
            any |= (x.to_bits() & ABS).wrapping_sub(1) < limit;
        }
    }
    any
}

/// Elementwise minimum (plain comparisons: `minsd`/`minpd`).
#[inline(always)]
pub(crate) fn min3(a: &V<f64>, b: &V<f64>) -> V<f64> {
    let m = |x: f64, y: f64| if x < y { x } else { y };
    [m(a[0], b[0]), m(a[1], b[1]), m(a[2], b[2])]
}

/// Elementwise maximum.
#[inline(always)]
pub(crate) fn max3(a: &V<f64>, b: &V<f64>) -> V<f64> {
    let m = |x: f64, y: f64| if x > y { x } else { y };
    [m(a[0], b[0]), m(a[1], b[1]), m(a[2], b[2])]
}

/// The largest component.
#[inline(always)]
pub(crate) fn hmax(a: &V<f64>) -> f64 {
    let m = |x: f64, y: f64| if x > y { x } else { y };
    m(m(a[0], a[1]), a[2])
}

/// Whether two point sets are certainly farther than `d` apart along `w` (any nonzero float
/// vector): projection onto `w / |w|` shortens no distance, so a gap between the sets'
/// projections above `d |w|` separates them by more than `d`. The points are given relative
/// to a common origin as computed differences (each coordinate within half an ulp of the
/// exact difference and at most `m` in size; the origin itself is `[0; 3]`); every rounding
/// of the projections is bounded by `16 EPSILON m |w|_1`, and the test is certain.
#[inline(always)]
pub(crate) fn apart_along(w: &V<f64>, first: &[V<f64>], second: &[V<f64>], d: f64, m: f64) -> bool {
    let w1 = w[0].abs() + w[1].abs() + w[2].abs();
    if w1.is_nan() || w1 <= 0.0 {
        return false;
    }
    let err = 16.0 * f64::EPSILON * m * w1;
    let span = |pts: &[V<f64>]| {
        pts.iter()
            .map(|p| dot(p, w))
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), s| {
                (lo.min(s), hi.max(s))
            })
    };
    let ((lo_a, hi_a), (lo_b, hi_b)) = (span(first), span(second));
    let gap = (lo_b - hi_a).max(lo_a - hi_b) - 3.0 * err;
    let norm = dot(w, w).sqrt() * (1.0 + 8.0 * f64::EPSILON);
    gap > 0.0 && gap > d * norm * (1.0 + 8.0 * f64::EPSILON)
}

/// `c` without its part along `dir` (`None` when `dir` is zero): the direction across a
/// segment or edge `dir` towards `c`.
#[inline(always)]
pub(crate) fn across(dir: &V<f64>, c: &V<f64>) -> Option<V<f64>> {
    let dd = dot(dir, dir);
    if dd.is_nan() || dd <= 0.0 {
        return None;
    }
    let f = dot(c, dir) / dd;
    Some(std::array::from_fn(|k| c[k] - f * dir[k]))
}

/// Whether some component of `a - b` exceeds `d` (exact: rounding is monotone and `d` is a
/// float, so `fl(a - b) > d` iff `a - b > d`).
#[inline(always)]
pub(crate) fn gap_exceeds(a: &V<f64>, b: &V<f64>, d: f64) -> bool {
    (a[0] - b[0] > d) | (a[1] - b[1] > d) | (a[2] - b[2] > d)
}

// ---------------------------------------------------------------------------------------------
// The exact path.

/// `x = m 2^e` exactly (`m` an integer, `|m| < 2^53`, `e >= -1074`) for a finite `x`.
#[inline]
pub(crate) fn decompose(x: f64) -> (i64, i32) {
    let bits = x.to_bits();
    let e = ((bits >> 52) & 0x7ff) as i32;
    let frac = (bits & ((1 << 52) - 1)) as i64;
    let (m, e) = if e == 0 {
        (frac, -1074)
    } else {
        (frac | (1 << 52), e - 1075)
    };
    (if x.is_sign_negative() { -m } else { m }, e)
}

/// Finite `f64` values as integers on their common binary grid: `xs[i] = out[i] 2^unit`,
/// with `unit` the exponent of the smallest last bit among the nonzero values. Every
/// polynomial the primitives compare is homogeneous, so signs on the grid are the signs of
/// the real values.
pub(crate) fn to_grid<const N: usize>(xs: &[f64; N]) -> ([BigInt; N], i32) {
    let parts = xs.map(decompose);
    let unit = parts
        .iter()
        .filter(|(m, _)| *m != 0)
        .map(|&(_, e)| e)
        .min()
        .unwrap_or(0);
    let ints = parts.map(|(m, e)| {
        if m == 0 {
            BigInt::zero()
        } else {
            BigInt::from(m) << (e - unit) as usize
        }
    });
    (ints, unit)
}

/// The sign of an integer as -1, 0 or 1.
pub(crate) fn sign_of(x: &BigInt) -> i8 {
    match x.sign() {
        num_bigint::Sign::Minus => -1,
        num_bigint::Sign::NoSign => 0,
        num_bigint::Sign::Plus => 1,
    }
}

/// `num / den * 2^e` correctly rounded to `f64` (round to nearest, ties to even; `+inf`
/// beyond the largest finite value), for `num >= 0`, `den > 0`.
pub(crate) fn ratio_to_f64(num: &BigInt, den: &BigInt, e: i64) -> f64 {
    debug_assert!(num.sign() != num_bigint::Sign::Minus && den.sign() == num_bigint::Sign::Plus);
    let (num, den) = (num.magnitude(), den.magnitude());
    if num.is_zero() {
        return 0.0;
    }
    // q = floor(num 2^s / den) has 55 or 56 bits: num / den lies in [2^(t - 1), 2^(t + 1)).
    let t = num.bits() as i64 - den.bits() as i64;
    let s = 55 - t;
    let (n2, d2): (BigUint, BigUint) = if s >= 0 {
        (num << s as usize, den.clone())
    } else {
        (num.clone(), den << (-s) as usize)
    };
    let (q, r) = n2.div_rem(&d2);
    let sticky = !r.is_zero();
    let q = q.to_u64().expect("55 or 56 bits");
    // The value is (q + f) 2^x, 0 <= f < 1 (f > 0 iff sticky).
    let x = e - s;
    let qbits = 64 - i64::from(q.leading_zeros());
    let lead = x + qbits - 1;
    if lead > 1023 {
        return f64::INFINITY;
    }
    // The last bit kept: 53 significant bits, or the subnormal grid 2^-1074.
    let ulp = (lead - 52).max(-1074);
    let drop = ulp - x; // >= 2 since qbits >= 55
    if drop >= 64 {
        // Below 2^(ulp - 8): rounds to zero.
        return 0.0;
    }
    let mut mant = q >> drop;
    let rem = q & ((1u64 << drop) - 1);
    let half = 1u64 << (drop - 1);
    if rem > half || (rem == half && (sticky || mant & 1 == 1)) {
        mant += 1;
    }
    // mant <= 2^53 and mant 2^ulp is representable (or overflows to inf): exact product.
    let ulp = ulp as i32;
    if ulp > 1023 - 53 {
        // mant 2^ulp = (mant 2^(ulp - 100)) 2^100, both steps exact or overflowing.
        (mant as f64 * pow2(ulp - 100)) * pow2(100)
    } else {
        mant as f64 * pow2(ulp)
    }
}

#[cfg(test)]
pub(crate) mod count {
    //! The symbolic ring that checks the filter's bounds.

    use super::{Bound, Ring};

    /// A polynomial's shape (see [`Bound`]); `terms` as `f64` only to avoid overflow checks.
    #[derive(Clone, Debug)]
    pub(crate) struct Count {
        pub(crate) degree: u32,
        pub(crate) terms: u64,
        pub(crate) depth: u32,
    }

    impl Count {
        /// A leaf that is a rounded difference of inputs.
        pub(crate) fn diff() -> Self {
            Self {
                degree: 1,
                terms: 1,
                depth: 1,
            }
        }
        /// The distance `d`, exact.
        pub(crate) fn input() -> Self {
            Self {
                degree: 1,
                terms: 1,
                depth: 0,
            }
        }
        pub(crate) fn diffs() -> [Self; 3] {
            [Self::diff(), Self::diff(), Self::diff()]
        }
        /// Whether `b` bounds this shape.
        pub(crate) fn fits(&self, b: Bound) -> bool {
            self.degree == b.degree && self.terms <= u64::from(b.terms) && self.depth <= b.depth
        }
    }

    impl Ring for Count {
        fn add(&self, o: &Self) -> Self {
            assert_eq!(self.degree, o.degree, "inhomogeneous sum");
            Self {
                degree: self.degree,
                terms: self.terms + o.terms,
                depth: self.depth.max(o.depth) + 1,
            }
        }
        fn sub(&self, o: &Self) -> Self {
            self.add(o)
        }
        fn mul(&self, o: &Self) -> Self {
            Self {
                degree: self.degree + o.degree,
                terms: self.terms * o.terms,
                depth: self.depth.max(o.depth) + 1,
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::count::Count;
    use super::*;
    use num_traits::Signed;
    use proptest::prelude::*;

    #[test]
    fn shared_bounds_fit_their_formulas() {
        let l = Count::diffs;
        let dd = Count::input().mul(&Count::input());
        let dt = dot(&l(), &l());
        assert!(dt.fits(DOT), "{dt:?}");
        let d2 = dt.add(&dt);
        assert!(d2.fits(DOT2), "{d2:?}");
        let d3 = d2.sub(&dt);
        assert!(d3.fits(DOT3), "{d3:?}");
        let lg = lagrange(&dt, &dt, &dt, &dt);
        assert!(lg.fits(LAGRANGE), "{lg:?}");
        let lg2 = lagrange(&dt, &d2, &dt, &d2);
        assert!(lg2.fits(LAGRANGE2), "{lg2:?}");
        assert!(point_q(&l(), &dd).fits(POINT));
        let lq = line_q(&l(), &l(), &dd);
        assert!(lq.fits(LINE), "{lq:?}");
        let pq = plane_q(&cross(&l(), &l()), &l(), &dd);
        assert!(pq.fits(PLANE), "{pq:?}");
    }

    #[test]
    fn powers_of_two_and_logs() {
        for e in -1074..=1023 {
            let x = pow2(e);
            assert_eq!(floor_log2(x), e);
            assert_eq!(
                x,
                2f64.powi(e.max(-1022)) * if e < -1022 { 2f64.powi(e + 1022) } else { 1.0 }
            );
        }
        assert_eq!(floor_log2(3.0), 1);
        assert_eq!(floor_log2(f64::from_bits(3)), -1073);
        assert_eq!(ldexp(3.0, -1074), f64::from_bits(3));
        assert_eq!(ldexp(3.0, -1075), f64::from_bits(2)); // 1.5 ulp: ties to even
        assert_eq!(ldexp(1.0, 2000), f64::INFINITY);
        assert_eq!(ldexp(f64::MIN_POSITIVE, 1100), pow2(78));
    }

    #[test]
    fn grid_is_exact() {
        let xs = [
            0.0,
            -0.0,
            1.5,
            -3.25e-300,
            f64::from_bits(1),
            f64::MAX,
            -1.0,
        ];
        let (ints, unit) = to_grid(&xs);
        assert_eq!(unit, -1074);
        for (x, i) in xs.iter().zip(&ints) {
            assert_eq!(
                ratio_to_f64(&i.abs(), &BigInt::from(1), i64::from(unit)),
                x.abs()
            );
            assert_eq!(i.sign() == num_bigint::Sign::Minus, *x < 0.0);
        }
    }

    fn big(x: f64) -> (BigInt, i64) {
        let (m, e) = decompose(x);
        (BigInt::from(m), i64::from(e))
    }

    /// `x 2^ex == y 2^ey`.
    fn same((x, ex): (BigInt, i64), (y, ey): (BigInt, i64)) -> bool {
        let e = ex.min(ey);
        (x << (ex - e) as usize) == (y << (ey - e) as usize)
    }

    #[test]
    fn checked_float_limits_are_the_powers_of_two_they_claim() {
        assert_eq!(CHECKED_FACTOR_MAX, pow2(995));
        assert_eq!(CHECKED_PRODUCT_MIN, pow2(-860));
    }

    #[test]
    fn checked_floats_flag_what_they_cannot_vouch_for() {
        let inexact = Checked::input(0.1).mul(&Checked::input(0.1));
        assert!(!inexact.exact);
        // An exact zero times anything finite is an exact zero.
        assert_eq!(Checked::input(0.0).mul(&inexact).sign(), Some(0));
        assert_eq!(inexact.mul(&Checked::input(-0.0)).sign(), Some(0));
        // A zero from an inexact value is not.
        assert_eq!(inexact.sub(&inexact).mul(&Checked::input(1.0)).sign(), None);
        // Underflow, overflow, and a product too small for Dekker's partial products.
        let tiny = Checked::input(1e-200);
        assert!(!tiny.mul(&tiny).exact);
        assert!(
            !Checked::input(2f64.powi(-1074))
                .mul(&Checked::input(1.0))
                .exact
        );
        let huge = Checked::input(1e300);
        assert!(!huge.mul(&Checked::input(1e10)).exact);
        assert!(!huge.mul(&huge).exact);
        assert!(
            !Checked::input(f64::MAX)
                .add(&Checked::input(f64::MAX))
                .exact
        );
        assert!(!Checked::input(f64::NAN).add(&Checked::input(0.0)).exact);
        // Exact sums and products stay exact.
        let third = Checked::input(3.0)
            .mul(&Checked::input(0.125))
            .sub(&Checked::input(0.375));
        assert_eq!(third.sign(), Some(0));
        assert_eq!(
            checked_ratio(Parts::Line(Checked::input(1.0), Checked::input(3.0))),
            Some(1.0 / 3.0)
        );
        assert_eq!(
            checked_ratio(Parts::Line(inexact, Checked::input(3.0))),
            None
        );
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(4000))]

        /// A checked sum or product of any two floats (every binade, subnormals included) that
        /// claims to be exact is the exact value.
        #[test]
        fn checked_floats_are_exact_when_they_say_so(
            a in any::<u64>(),
            b in any::<u64>(),
            (za, zb) in (0u32..53, 0u32..53),
        ) {
            // Mantissas cut short at random (exact products and sums are then common).
            let cut = |x: u64, z: u32| f64::from_bits(x & !((1u64 << z) - 1));
            let (a, b) = (cut(a, za), cut(b, zb));
            prop_assume!(a.is_finite() && b.is_finite());
            let (ca, cb) = (Checked::input(a), Checked::input(b));
            let (ba, bb) = (big(a), big(b));
            let p = ca.mul(&cb);
            if p.exact {
                prop_assert!(same(big(p.v), (&ba.0 * &bb.0, ba.1 + bb.1)), "{} * {}", a, b);
            }
            let s = ca.add(&cb);
            if s.exact {
                let e = ba.1.min(bb.1);
                let sum = (&ba.0 << (ba.1 - e) as usize) + (&bb.0 << (bb.1 - e) as usize);
                prop_assert!(same(big(s.v), (sum, e)), "{} + {}", a, b);
            }
        }

        /// Exact values come back unchanged; midpoints of neighbours round to even; a third
        /// rounds to nearest.
        #[test]
        fn ratio_rounds_correctly(bits in 1u64..0x7fef_ffff_ffff_ffff) {
            let x = f64::from_bits(bits);
            let y = x.next_up();
            let (mx, ex) = big(x);
            let (my, ey) = big(y);
            let one = BigInt::from(1);
            prop_assert_eq!(ratio_to_f64(&mx, &one, ex), x);
            // Midpoint (x + y) / 2 on the finer grid.
            let e = ex.min(ey);
            let sx = &mx << (ex - e) as usize;
            let sy = &my << (ey - e) as usize;
            let mid = ratio_to_f64(&(&sx + &sy), &BigInt::from(2), e);
            let even = if bits & 1 == 0 { x } else { y };
            prop_assert_eq!(mid, even);
            // Just above and below the midpoint.
            let above = ratio_to_f64(&(BigInt::from(2) * (&sx + &sy) + 1), &BigInt::from(4), e);
            prop_assert_eq!(above, y);
            let below = ratio_to_f64(&(BigInt::from(2) * (&sx + &sy) - 1), &BigInt::from(4), e);
            prop_assert_eq!(below, x);
            // x / 3 against the (correctly rounded) f64 division, where it is exact-rounded:
            // both are the correctly rounded quotient.
            prop_assert_eq!(ratio_to_f64(&mx, &BigInt::from(3), ex), x / 3.0);
        }
    }
}
