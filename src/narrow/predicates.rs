//! Exact geometric primitives on `f32` or `f64` points ([`Coordinate`]).
//!
//! Every sign here is exact. `f32 -> f64` is exact and Shewchuk's adaptive predicates (the
//! `robust` crate) are exact for any `f64` input whose products neither overflow nor
//! underflow, which holds for all finite `f32` coordinates (a degree-3 product of `f32`
//! differences stays far inside the `f64` exponent range). Comparisons are exact.
//! Orientations the floating-point filter leaves open are computed in integers when the
//! points' exponents allow (`orient3d_fixed`, `f32`), or by the adaptive predicate; for `f64`
//! points whose magnitudes could underflow in it, in big integers (`super::exact`).

use robust::{Coord, Coord3D};

/// A point.
pub(crate) type P3<C = f32> = [C; 3];
/// A triangle (possibly degenerate).
pub(crate) type Tri<C = f32> = [P3<C>; 3];

/// A coordinate type of the exact tests: `f32` (the library's default precision) or `f64`.
pub(crate) trait Coordinate:
    Copy + PartialOrd + Into<f64> + std::fmt::Debug + 'static
{
    /// The absolute term of the `f64` filters' bounds: 0 for `f32` inputs (no product of
    /// their differences underflows), `2^-900` for `f64` inputs, far above any underflow
    /// error of a degree-3 product of coordinates below `2^128` (each rounding of an
    /// underflowing product is at most `2^-1075`).
    const TINY: f64;
    /// Whether a zero permanent proves an exact zero (no product of nonzero differences can
    /// underflow to zero).
    const ZERO_IS_EXACT: bool;
    /// The exact `orient3d(a, b, c, d)` (its sign exact; same convention as `robust`).
    fn orient3d_exact(a: &P3<Self>, b: &P3<Self>, c: &P3<Self>, d: &P3<Self>) -> f64;
    /// The sign of [`Coordinate::orient3d_exact`].
    fn orient3d_sign_exact(a: &P3<Self>, b: &P3<Self>, c: &P3<Self>, d: &P3<Self>) -> i32;
    /// The exact 2D orientation of three points given as `f64` pairs (exact values of
    /// `Self`).
    fn orient2d_exact(a: [f64; 2], b: [f64; 2], c: [f64; 2]) -> f64;
}

impl Coordinate for f32 {
    const TINY: f64 = 0.0;
    const ZERO_IS_EXACT: bool = true;

    #[cold]
    #[inline(never)]
    fn orient3d_exact(a: &P3, b: &P3, c: &P3, d: &P3) -> f64 {
        match orient3d_fixed(a, b, c, d) {
            Some(fixed) => fixed.value(),
            None => robust::orient3d(c3(a), c3(b), c3(c), c3(d)),
        }
    }

    /// PERF: without converting the integer determinant to `f64`, a library call that was a
    /// quarter of the integer path.
    #[cold]
    #[inline(never)]
    fn orient3d_sign_exact(a: &P3, b: &P3, c: &P3, d: &P3) -> i32 {
        match orient3d_fixed(a, b, c, d) {
            Some(Fixed { det, .. }) => det.signum() as i32,
            None => sign(robust::orient3d(c3(a), c3(b), c3(c), c3(d))),
        }
    }

    #[inline]
    fn orient2d_exact(a: [f64; 2], b: [f64; 2], c: [f64; 2]) -> f64 {
        let p = |v: [f64; 2]| Coord { x: v[0], y: v[1] };
        robust::orient2d(p(a), p(b), p(c))
    }
}

impl Coordinate for f64 {
    const TINY: f64 = f64::from_bits((1023 - 900) << 52); // 2^-900
    const ZERO_IS_EXACT: bool = false;

    #[cold]
    #[inline(never)]
    fn orient3d_exact(a: &P3<f64>, b: &P3<f64>, c: &P3<f64>, d: &P3<f64>) -> f64 {
        super::exact::orient3d(a, b, c, d)
    }

    #[cold]
    #[inline(never)]
    fn orient3d_sign_exact(a: &P3<f64>, b: &P3<f64>, c: &P3<f64>, d: &P3<f64>) -> i32 {
        sign(super::exact::orient3d(a, b, c, d))
    }

    #[inline]
    fn orient2d_exact(a: [f64; 2], b: [f64; 2], c: [f64; 2]) -> f64 {
        super::exact::orient2d(a, b, c)
    }
}

#[inline(always)]
fn c3<C: Coordinate>(p: &P3<C>) -> Coord3D<f64> {
    Coord3D {
        x: p[0].into(),
        y: p[1].into(),
        z: p[2].into(),
    }
}

/// Shewchuk's static error bound for the floating-point `orient3d` (same constant as
/// `robust`): `(7 + 56 eps) eps`, `eps = 2^-53`.
const O3D_ERRBOUND_A: f64 = (7.0 + 56.0 * EPS) * EPS;
const EPS: f64 = f64::EPSILON / 2.0;

/// Sign-exact orientation of `d` against the plane through `a, b, c` (zero iff coplanar);
/// same sign convention as `robust::orient3d`.
///
/// PERF: `robust::orient3d` is not inlined across the crate boundary and the call costs
/// as much as the arithmetic; this is its floating-point stage (Shewchuk's filter, same
/// formula and bound) inlined here, falling back to `robust::orient3d` (whose adaptive
/// stages are exact) only when the filter cannot certify the sign.
#[inline(always)]
pub(crate) fn orient3d<C: Coordinate>(a: &P3<C>, b: &P3<C>, c: &P3<C>, d: &P3<C>) -> f64 {
    let f = |x: C| -> f64 { x.into() };
    let (adx, bdx, cdx) = (f(a[0]) - f(d[0]), f(b[0]) - f(d[0]), f(c[0]) - f(d[0]));
    let (ady, bdy, cdy) = (f(a[1]) - f(d[1]), f(b[1]) - f(d[1]), f(c[1]) - f(d[1]));
    let (adz, bdz, cdz) = (f(a[2]) - f(d[2]), f(b[2]) - f(d[2]), f(c[2]) - f(d[2]));
    let (bdxcdy, cdxbdy) = (bdx * cdy, cdx * bdy);
    let (cdxady, adxcdy) = (cdx * ady, adx * cdy);
    let (adxbdy, bdxady) = (adx * bdy, bdx * ady);
    let det = adz * (bdxcdy - cdxbdy) + bdz * (cdxady - adxcdy) + cdz * (adxbdy - bdxady);
    let permanent = (bdxcdy.abs() + cdxbdy.abs()) * adz.abs()
        + (cdxady.abs() + adxcdy.abs()) * bdz.abs()
        + (adxbdy.abs() + bdxady.abs()) * cdz.abs();
    let errbound = O3D_ERRBOUND_A * permanent + C::TINY;
    if det > errbound || -det > errbound {
        return det;
    }
    C::orient3d_exact(a, b, c, d)
}

/// A triangle's plane, prepared for many orientation queries: [`Plane::side`]`(d)` is the
/// exact sign of `orient3d(d, t0, t1, t2)`.
///
/// PERF: the normal `N = (t0 - t2) x (t1 - t2)` and the magnitudes `M` of its products are
/// computed once; each query is then `e = d - t2`, `s = e . N` and the permanent
/// `P = |e| . M`, Shewchuk's orient3d arithmetic in another association (a Laplace expansion
/// of the same determinant along `e`), so its first-stage error bound `(7 + 56 eps) eps P`
/// holds; a sign is certified when `|s| > 8 eps P` (`f32` inputs cannot underflow or
/// overflow in `f64`), else the adaptive exact predicate decides.
pub(crate) struct Plane<'a, C: Coordinate = f32> {
    t: &'a Tri<C>,
    origin: [f64; 3],
    normal: [f64; 3],
    magnitude: [f64; 3],
}

impl<'a, C: Coordinate> Plane<'a, C> {
    #[inline(always)]
    pub(crate) fn new(t: &'a Tri<C>) -> Self {
        let f = |p: &P3<C>| p.map(|x| -> f64 { x.into() });
        let (a, b, o) = (f(&t[0]), f(&t[1]), f(&t[2]));
        let u = [a[0] - o[0], a[1] - o[1], a[2] - o[2]];
        let v = [b[0] - o[0], b[1] - o[1], b[2] - o[2]];
        let (yz, zy) = (u[1] * v[2], u[2] * v[1]);
        let (zx, xz) = (u[2] * v[0], u[0] * v[2]);
        let (xy, yx) = (u[0] * v[1], u[1] * v[0]);
        Self {
            t,
            origin: o,
            normal: [yz - zy, zx - xz, xy - yx],
            magnitude: [
                yz.abs() + zy.abs(),
                zx.abs() + xz.abs(),
                xy.abs() + yx.abs(),
            ],
        }
    }

    /// Whether the triangle certainly spans a plane (is not degenerate): some component of
    /// the normal exceeds its rounding error (the differences, the products and the component
    /// each round once: at most about `3 eps M_k + eps |N_k|`, below `8 eps M_k`).
    #[inline(always)]
    pub(crate) fn spans(&self) -> bool {
        (0..3).any(|k| self.normal[k].abs() > PLANE_ERRBOUND * self.magnitude[k] + C::TINY)
    }

    /// The exact sign of `orient3d(d, t0, t1, t2)`.
    #[inline(always)]
    pub(crate) fn side(&self, d: &P3<C>) -> i32 {
        let (o, n, m) = (&self.origin, &self.normal, &self.magnitude);
        let f = |x: C| -> f64 { x.into() };
        let e = [f(d[0]) - o[0], f(d[1]) - o[1], f(d[2]) - o[2]];
        let s = e[0] * n[0] + e[1] * n[1] + e[2] * n[2];
        let p = e[0].abs() * m[0] + e[1].abs() * m[1] + e[2].abs() * m[2];
        let bound = PLANE_ERRBOUND * p + C::TINY;
        if s > bound {
            1
        } else if s < -bound {
            -1
        } else if C::ZERO_IS_EXACT && p == 0.0 {
            // Exactly zero (PERF: a corner on an axis-aligned plane, flat cloth or the cap of
            // an axis-aligned cylinder, skips the exact predicate). The terms of `P` are
            // nonnegative, so each is zero: `e_k = 0` or both products of `M_k` are zero. A
            // computed difference is zero only for equal inputs, and a product of two nonzero
            // differences of `f32` values cannot underflow in `f64`, so each zero is exact,
            // and so is `s = sum e_k N_k` with `|N_k| <= M_k`.
            0
        } else {
            C::orient3d_sign_exact(d, &self.t[0], &self.t[1], &self.t[2])
        }
    }
}

/// The certification factor of [`Plane::side`]: `8 eps`, above Shewchuk's
/// `(7 + 56 eps) eps`.
const PLANE_ERRBOUND: f64 = 8.0 * EPS;

/// Largest spread of the (nonzero) coordinates' binary exponents that [`orient3d_fixed`]
/// takes: the coordinates on the grid of the smallest one's last bit then hold at most
/// `24 + 16 = 40` bits, their differences 41, a 2x2 minor 83, the determinant
/// `3 * 2^124 < 2^126`: inside `i128`.
const FIXED_SPREAD: u32 = 16;

/// `orient3d(a, b, c, d)` on the common binary grid of `f32` coordinates: the determinant
/// `det * 2^(3 (lo - 150))`, `det` exact in `i128`.
struct Fixed {
    det: i128,
    lo: u32,
}

impl Fixed {
    /// The determinant rounded to `f64` (its sign exact, and so a zero). `det * 2^(3 (lo -
    /// 150))` is at least 2^-447 and at most 2^(126 + 312) in magnitude when nonzero, so the
    /// scaling neither underflows nor overflows (a normal f64 power of two, built from its
    /// bits).
    fn value(&self) -> f64 {
        let scale = f64::from_bits(((1023 + 3 * (i64::from(self.lo) - 150)) as u64) << 52);
        self.det as f64 * scale
    }
}

/// `orient3d(a, b, c, d)` exactly, by integer arithmetic on the `f32` inputs' common binary
/// grid; `None` when the nonzero coordinates' exponents span more than [`FIXED_SPREAD`]
/// binades, or one is not finite.
///
/// PERF: the pairs the filter leaves are mostly exactly coplanar (flat parts of a mesh, and
/// corners exactly on a neighbour's plane), where Shewchuk's adaptive predicate runs its
/// expansion arithmetic to the end: that was a third of a step on the armadillo frames.
/// This is a few dozen integer operations.
fn orient3d_fixed(a: &P3, b: &P3, c: &P3, d: &P3) -> Option<Fixed> {
    // A finite f32 is `m 2^(e - 150)`, `m < 2^24` (subnormals: biased exponent 0 taken as 1).
    let bits = [a, b, c, d].map(|p| p.map(f32::to_bits));
    let exponent = |x: u32| ((x >> 23) & 0xff).max(1);
    let (mut lo, mut hi) = (u32::MAX, 0);
    for &x in bits.as_flattened() {
        if x & 0x7fff_ffff != 0 {
            (lo, hi) = (lo.min(exponent(x)), hi.max(exponent(x)));
        }
    }
    if lo == u32::MAX {
        return Some(Fixed { det: 0, lo: 1 });
    }
    if hi == 0xff || hi - lo > FIXED_SPREAD {
        return None;
    }
    // Each coordinate as an integer multiple of 2^(lo - 150) (zero: 0).
    let mut fixed = [[0i64; 3]; 4];
    for (f, p) in fixed.iter_mut().zip(&bits) {
        for (v, &x) in f.iter_mut().zip(p) {
            let implicit = if x & 0x7f80_0000 == 0 { 0 } else { 0x80_0000 };
            let m = i64::from((x & 0x7f_ffff) | implicit) << exponent(x).saturating_sub(lo);
            *v = if x >> 31 == 0 { m } else { -m };
        }
    }
    let [fa, fb, fc, fd] = fixed;
    let [ad, bd, cd] = [fa, fb, fc].map(|p| [p[0] - fd[0], p[1] - fd[1], p[2] - fd[2]]);
    // Differences of 41 bits: each 2x2 minor from two widening 64 x 64 -> 128 products.
    let minor = |a: i64, b: i64, c: i64, d: i64| {
        i128::from(a) * i128::from(b) - i128::from(c) * i128::from(d)
    };
    let det = i128::from(ad[2]) * minor(bd[0], cd[1], cd[0], bd[1])
        + i128::from(bd[2]) * minor(cd[0], ad[1], ad[0], cd[1])
        + i128::from(cd[2]) * minor(ad[0], bd[1], bd[0], ad[1]);
    Some(Fixed { det, lo })
}

/// The two axes kept when projecting along axis `k` (cyclic, so orientation is consistent).
const KEEP: [(usize, usize); 3] = [(1, 2), (2, 0), (0, 1)];

/// The two axes kept when projecting along axis `k`.
#[inline(always)]
pub(crate) fn keep(k: usize) -> (usize, usize) {
    KEEP[k]
}

/// Sign-exact 2D orientation of `a, b, c` projected along axis `k` (zero iff the
/// projections are collinear).
#[inline]
pub(crate) fn orient2d<C: Coordinate>(k: usize, a: &P3<C>, b: &P3<C>, c: &P3<C>) -> f64 {
    let (i, j) = KEEP[k];
    let p = |v: &P3<C>| -> [f64; 2] { [v[i].into(), v[j].into()] };
    C::orient2d_exact(p(a), p(b), p(c))
}

/// The projection axis `k` that keeps the triangle `a, b, c` most non-degenerate (largest
/// `|orient2d|`, i.e. the dominant normal component), or `None` when the corners are
/// collinear in 3D (all three projections are then collinear, exactly).
#[inline]
pub(crate) fn projection_axis<C: Coordinate>(a: &P3<C>, b: &P3<C>, c: &P3<C>) -> Option<usize> {
    let mut best = None;
    let mut best_abs = 0.0;
    for k in 0..3 {
        let o = orient2d(k, a, b, c).abs();
        if o > best_abs {
            best_abs = o;
            best = Some(k);
        }
    }
    best
}

/// Strict sign of `x` as -1, 0 or 1.
#[inline(always)]
pub(crate) fn sign(x: f64) -> i32 {
    i32::from(x > 0.0) - i32::from(x < 0.0)
}

/// Lexicographic `a <= b`. On any line, lexicographic order is a linear order compatible
/// with the line's parametrisation, so it decides betweenness of collinear points exactly.
#[inline]
pub(crate) fn lex_le<C: PartialOrd>(a: &[C], b: &[C]) -> bool {
    for (x, y) in a.iter().zip(b) {
        if x < y {
            return true;
        }
        if x > y {
            return false;
        }
    }
    true
}

/// `p + t (q - p)` in `f64`, `t` clamped to `[0, 1]`; exact at `t = 0` and `t = 1`.
#[inline]
pub(crate) fn lerp<C: Coordinate>(p: &P3<C>, q: &P3<C>, t: f64) -> [f64; 3] {
    let t = t.clamp(0.0, 1.0);
    if t == 1.0 {
        return q.map(|x| -> f64 { x.into() });
    }
    let mut x = [0.0; 3];
    for i in 0..3 {
        let (a, b): (f64, f64) = (p[i].into(), q[i].into());
        x[i] = a + t * (b - a);
    }
    x
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    /// The integer path's value, as `orient3d_exact` returns it.
    fn fixed_value(a: &P3, b: &P3, c: &P3, d: &P3) -> Option<f64> {
        orient3d_fixed(a, b, c, d).map(|f| f.value())
    }

    fn robust_sign(a: &P3, b: &P3, c: &P3, d: &P3) -> i32 {
        sign(robust::orient3d(c3(a), c3(b), c3(c), c3(d)))
    }

    fn orient3d_sign_exact(a: &P3, b: &P3, c: &P3, d: &P3) -> i32 {
        <f32 as Coordinate>::orient3d_sign_exact(a, b, c, d)
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(5000))]

        /// `Plane::spans` only certifies triangles that are not degenerate, and certifies
        /// every one on a coarse grid (collinear and repeated corners are common there), also
        /// scaled to tiny and huge magnitudes.
        #[test]
        fn spans_certifies_exactly_the_proper_triangles(
            t in prop::array::uniform3(prop::array::uniform3(-3i32..=3)),
            exp in -140i32..120,
        ) {
            let unit = 2f32.powi(exp.max(-149));
            let t: Tri = t.map(|p| p.map(|c| c as f32 * unit));
            let proper = projection_axis(&t[0], &t[1], &t[2]).is_some();
            prop_assert!(!Plane::new(&t).spans() || proper);
            if exp > -120 {
                prop_assert_eq!(Plane::new(&t).spans(), proper);
            }
        }

        /// The inlined filter returns robust's sign, also for nearly coplanar `d` (an affine
        /// combination of `a, b, c` rounded to f32, nudged by a few ulps).
        #[test]
        fn inlined_orient3d_matches_robust(
            p in prop::array::uniform3(prop::array::uniform3(-1e3f32..1e3)),
            s in -2.0f64..3.0,
            t in -2.0f64..3.0,
            nudge in prop::array::uniform3(-2i32..=2),
        ) {
            let [a, b, c] = p;
            let mut d = [0.0f32; 3];
            for k in 0..3 {
                let (x, y, z) = (f64::from(a[k]), f64::from(b[k]), f64::from(c[k]));
                let mut v = (x + s * (y - x) + t * (z - x)) as f32;
                for _ in 0..nudge[k].unsigned_abs() {
                    v = if nudge[k] > 0 { v.next_up() } else { v.next_down() };
                }
                d[k] = v;
            }
            prop_assert_eq!(sign(orient3d(&a, &b, &c, &d)), robust_sign(&a, &b, &c, &d));
            prop_assert_eq!(sign(orient3d(&a, &b, &c, &c)), 0);
            // The prepared plane gives the same exact signs.
            let t = [a, b, c];
            let plane = Plane::new(&t);
            prop_assert_eq!(plane.side(&d), robust_sign(&d, &a, &b, &c));
            prop_assert_eq!(plane.side(&c), 0);
            prop_assert_eq!(plane.side(&a), 0);
            prop_assert_eq!(sign(orient3d(&d, &a, &b, &c)), -robust_sign(&a, &b, &c, &d));
        }

        /// The integer path gives robust's sign whenever it answers, on coplanar and nearly
        /// coplanar points, points on a coarse grid (exact zeros), coordinates of mixed
        /// magnitudes, and subnormals; and it answers when the exponents allow.
        #[test]
        fn fixed_orient3d_matches_robust(
            p in prop::array::uniform3(prop::array::uniform3(-64i32..64)),
            s in -4i32..5,
            t in -4i32..5,
            nudge in prop::array::uniform3(-1i32..=1),
            unit_exp in -140i32..100,
            spread in prop::array::uniform4(0i32..24),
        ) {
            // Integer points times a power of two: `d` an integer combination of `a, b, c`
            // is exactly coplanar, then nudged by an ulp.
            let unit = 2f32.powi(unit_exp.max(-126));
            let scale = |v: i32| v as f32 * unit;
            let [a, b, c] = p.map(|q| q.map(scale));
            let mut d = [0.0f32; 3];
            for k in 0..3 {
                let v = p[0][k] + s * (p[1][k] - p[0][k]) + t * (p[2][k] - p[0][k]);
                let mut x = scale(v);
                if nudge[k] > 0 { x = x.next_up() } else if nudge[k] < 0 { x = x.next_down() }
                d[k] = x;
            }
            let pts = [a, b, c, d];
            if let Some(det) = fixed_value(&a, &b, &c, &d) {
                prop_assert_eq!(sign(det), robust_sign(&a, &b, &c, &d));
            }
            if nudge == [0; 3] {
                // Integers below 2^11 times a normal power of two: within the spread, and
                // exactly coplanar.
                prop_assert_eq!(fixed_value(&a, &b, &c, &d), Some(0.0));
            }
            // The same points, each coordinate scaled by its own power of two (mixed
            // exponents, some beyond the spread).
            let mixed: Vec<P3> = pts
                .iter()
                .zip(spread)
                .map(|(q, e)| q.map(|x| x * 2f32.powi(e - 12)))
                .collect();
            let (a, b, c, d) = (&mixed[0], &mixed[1], &mixed[2], &mixed[3]);
            let got = fixed_value(a, b, c, d);
            if let Some(det) = got {
                prop_assert_eq!(sign(det), robust_sign(a, b, c, d));
            }
            prop_assert_eq!(sign(orient3d(a, b, c, d)), robust_sign(a, b, c, d));
            prop_assert_eq!(orient3d_sign_exact(a, b, c, d), robust_sign(a, b, c, d));
        }
    }

    #[test]
    fn fixed_orient3d_answers_within_its_spread_and_not_beyond() {
        let (a, b, c) = ([0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]);
        // Coplanar: exactly zero.
        assert_eq!(fixed_value(&a, &b, &c, &[0.25, 0.75, 0.0]), Some(0.0));
        // Exponents 2^-16 .. 2^0: answered, exact value (det of unit edges and height h).
        let h = 2f32.powi(-16);
        assert_eq!(fixed_value(&a, &b, &c, &[0.5, 0.5, h]), Some(-f64::from(h)));
        assert_eq!(
            sign(fixed_value(&a, &b, &c, &[0.5, 0.5, h]).unwrap()),
            sign(robust::orient3d(c3(&a), c3(&b), c3(&c), c3(&[0.5, 0.5, h])))
        );
        // One binade more: left to the adaptive predicate.
        assert_eq!(fixed_value(&a, &b, &c, &[0.5, 0.5, h / 2.0]), None);
        // Not finite: left to the adaptive predicate (whose answer is unspecified).
        assert_eq!(fixed_value(&a, &b, &c, &[0.5, 0.5, f32::INFINITY]), None);
        assert_eq!(fixed_value(&a, &b, &c, &[0.5, f32::NAN, 0.0]), None);
        // All zero.
        assert_eq!(fixed_value(&a, &a, &a, &a), Some(0.0));
        // Subnormals alone: exact.
        let s = f32::from_bits(1);
        let (sa, sb, sc) = ([0.0, 0.0, 0.0], [s, 0.0, 0.0], [0.0, s, 0.0]);
        let above = fixed_value(&sa, &sb, &sc, &[0.0, 0.0, s]).unwrap();
        assert_eq!(
            sign(above),
            sign(robust::orient3d(
                c3(&sa),
                c3(&sb),
                c3(&sc),
                c3(&[0.0, 0.0, s])
            ))
        );
        assert!(above != 0.0);
        // The largest magnitudes: no overflow.
        let m = f32::MAX;
        let (o, x, y, d) = ([0.0, 0.0, 0.0], [m, 0.0, 0.0], [0.0, m, 0.0], [-m, -m, m]);
        let big = fixed_value(&o, &x, &y, &d).expect("one binade");
        assert!(big.is_finite() && big != 0.0);
        assert_eq!(
            sign(big),
            sign(robust::orient3d(c3(&o), c3(&x), c3(&y), c3(&d)))
        );
    }
}
