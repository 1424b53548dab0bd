//! Edge-edge (segment-segment): the closest sub-features, the exact decision and the value.
//!
//! With `u = a1 - a0`, `v = b1 - b0`, `r = a0 - b0` and the five dot products
//! `uu, vv, uv, ru = r.u, rv = r.v`, the four corner differences are `r`, `r01 = a0 - b1 =
//! r - v`, `r10 = a1 - b0 = r + u`, `r11 = a1 - b1`, and their dot products with `u` and `v`
//! are sums of the five (`r01.u = ru - uv`, `r10.v = rv + uv`, ...). A pair of points
//! `(x, y)` of the segments is closest iff `(x - y)` meets the optimality conditions of the
//! convex problem at both ends, which gives, in [`EdgeEdge`]'s order:
//!
//! | closest pair | iff |
//! |---|---|
//! | `(a0, b0)` | `ru >= 0`, `rv <= 0` |
//! | `(a0, b1)` | `r01.u >= 0`, `r01.v >= 0` |
//! | `(a1, b0)` | `r10.u <= 0`, `r10.v <= 0` |
//! | `(a1, b1)` | `r11.u <= 0`, `r11.v >= 0` |
//! | (open `A`, `b0`) | `ru < 0 < r10.u` (the foot of `b0` inside `A`), `uu rv - uv ru <= 0` |
//! | (open `A`, `b1`) | `r01.u < 0 < r11.u`, `uu r01.v - uv r01.u >= 0` |
//! | (`a0`, open `B`) | `rv > 0 > r01.v`, `vv ru - uv rv >= 0` |
//! | (`a1`, open `B`) | `r10.v > 0 > r11.v`, `vv r10.u - uv r10.v <= 0` |
//! | (open `A`, open `B`) | none of the above |
//!
//! The first row that holds is the type, so ties go to the least total dimension, then to the
//! earlier type. Parallel segments always have a closest pair with an end point, so the last
//! row implies `u x v != 0`. The decision then compares the feature pair's distance with `d`:
//! `|r_ij|^2 <= d^2`, `|e x w|^2 <= d^2 |e|^2` (a corner and a line),
//! `(r.n)^2 <= d^2 |n|^2` with `n = u x v` (two lines).

use num_bigint::BigInt;

use super::arith::{
    across, apart_along, certified, checked_ratio, cross, dot, exact_ratio, float_value,
    gap_exceeds, hmax, lagrange, ldexp, line_parts, max3, min3, plane_parts, plane_q, point_parts,
    ratio_to_f64, scale_of, sign_of, sub3, to_grid, Bound, Checked, CheckedDots, Parts, Powers,
    Ring, DOT, DOT2, DOT3, LAGRANGE, LAGRANGE2, LINE, PLANE, POINT, V,
};
use super::EdgeEdge as Ee;

/// A sign the classification or the decision needs.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Q {
    Ru,
    Rv,
    R01u,
    R01v,
    R10u,
    R10v,
    R11u,
    R11v,
    /// `uu rv - uv ru`
    L0,
    /// `uu r01.v - uv r01.u`
    L1,
    /// `vv ru - uv rv`
    M0,
    /// `vv r10.u - uv r10.v`
    M1,
    /// The distance between the type's features minus `d` (squared, divided out).
    Dist(Ee),
}

/// The filter bound of each quantity (checked against the formulas by a test).
#[inline(always)]
fn bound(q: Q) -> Bound {
    match q {
        Q::Ru | Q::Rv => DOT,
        Q::R01u | Q::R01v | Q::R10u | Q::R10v => DOT2,
        Q::R11u | Q::R11v => DOT3,
        Q::L0 | Q::M0 => LAGRANGE,
        Q::L1 | Q::M1 => LAGRANGE2,
        Q::Dist(Ee::Ea0Eb0 | Ee::Ea0Eb1 | Ee::Ea1Eb0 | Ee::Ea1Eb1) => POINT,
        Q::Dist(Ee::EaEb0 | Ee::EaEb1 | Ee::Ea0Eb | Ee::Ea1Eb) => LINE,
        Q::Dist(Ee::EaEb) => PLANE,
    }
}

/// The differences every quantity is a polynomial in.
#[derive(Clone)]
pub(crate) struct Leaves<R> {
    u: V<R>,
    v: V<R>,
    r: V<R>,
    r01: V<R>,
    r10: V<R>,
    r11: V<R>,
}

impl<R: Ring> Leaves<R> {
    #[inline(always)]
    fn new(a0: &V<R>, a1: &V<R>, b0: &V<R>, b1: &V<R>) -> Self {
        Self {
            u: sub3(a1, a0),
            v: sub3(b1, b0),
            r: sub3(a0, b0),
            r01: sub3(a0, b1),
            r10: sub3(a1, b0),
            r11: sub3(a1, b1),
        }
    }

    /// `[uu, vv, uv, ru, rv]`.
    #[inline(always)]
    fn dots(&self) -> [R; 5] {
        std::array::from_fn(|k| self.dot(k))
    }

    /// The `k`-th of `[uu, vv, uv, ru, rv]`.
    #[inline(always)]
    fn dot(&self, k: usize) -> R {
        let (x, y) = match k {
            0 => (&self.u, &self.u),
            1 => (&self.v, &self.v),
            2 => (&self.u, &self.v),
            3 => (&self.r, &self.u),
            _ => (&self.r, &self.v),
        };
        dot(x, y)
    }

    /// The corner difference of a vertex-vertex type.
    #[inline(always)]
    fn corners(&self, ty: Ee) -> &V<R> {
        match ty {
            Ee::Ea0Eb0 => &self.r,
            Ee::Ea0Eb1 => &self.r01,
            Ee::Ea1Eb0 => &self.r10,
            _ => &self.r11,
        }
    }

    /// `(e, w)` of a vertex-edge type: the edge's direction, the corner relative to the
    /// edge's first end (up to sign).
    #[inline(always)]
    fn corner_edge(&self, ty: Ee) -> (&V<R>, &V<R>) {
        match ty {
            Ee::EaEb0 => (&self.u, &self.r),
            Ee::EaEb1 => (&self.u, &self.r01),
            Ee::Ea0Eb => (&self.v, &self.r),
            _ => (&self.v, &self.r10),
        }
    }
}

/// The dot products `quantity(q)` reads (bit `k` for the `k`-th of `[uu, vv, uv, ru,
/// rv]`); `Q::Dist` reads the leaves only.
#[inline(always)]
fn dots_of(q: Q) -> u8 {
    match q {
        Q::Ru => 0b1000,
        Q::Rv => 0b1_0000,
        Q::R01u => 0b1100,
        Q::R01v => 0b1_0010,
        Q::R10u => 0b1001,
        Q::R10v => 0b1_0100,
        Q::R11u => 0b1101,
        Q::R11v => 0b1_0110,
        Q::L0 => 0b1_1101,
        Q::M0 => 0b1_1110,
        Q::L1 | Q::M1 => 0b1_1111,
        Q::Dist(_) => 0,
    }
}

/// Every quantity, from the dots and leaves.
#[inline(always)]
fn quantity<R: Ring>(l: &Leaves<R>, d: &[R; 5], dd: &R, q: Q) -> R {
    let [uu, vv, uv, ru, rv] = d;
    match q {
        Q::Ru => ru.clone(),
        Q::Rv => rv.clone(),
        Q::R01u => ru.sub(uv),
        Q::R01v => rv.sub(vv),
        Q::R10u => ru.add(uu),
        Q::R10v => rv.add(uv),
        Q::R11u => ru.add(uu).sub(uv),
        Q::R11v => rv.add(uv).sub(vv),
        Q::L0 => lagrange(uu, rv, uv, ru),
        Q::L1 => lagrange(uu, &rv.sub(vv), uv, &ru.sub(uv)),
        Q::M0 => lagrange(vv, ru, uv, rv),
        Q::M1 => lagrange(vv, &ru.add(uu), uv, &rv.add(uv)),
        Q::Dist(ty) => parts(l, ty).q(dd),
    }
}

/// The squared distance between the features of `ty` as [`Parts`] (see the point-triangle
/// twin).
#[inline(always)]
fn parts<R: Ring>(l: &Leaves<R>, ty: Ee) -> Parts<R> {
    match ty {
        Ee::Ea0Eb0 | Ee::Ea0Eb1 | Ee::Ea1Eb0 | Ee::Ea1Eb1 => point_parts(l.corners(ty)),
        Ee::EaEb0 | Ee::EaEb1 | Ee::Ea0Eb | Ee::Ea1Eb => {
            let (e, w) = l.corner_edge(ty);
            line_parts(e, w)
        }
        Ee::EaEb => plane_parts(&cross(&l.u, &l.v), &l.r),
    }
}

/// Exact signs of the quantities.
pub(crate) trait Signs {
    fn sign(&mut self, q: Q) -> i8;
}

/// The closest sub-features (exact, given exact signs).
#[inline(always)]
pub(crate) fn classify<S: Signs>(s: &mut S) -> Ee {
    if s.sign(Q::Ru) >= 0 && s.sign(Q::Rv) <= 0 {
        return Ee::Ea0Eb0;
    }
    if s.sign(Q::R01u) >= 0 && s.sign(Q::R01v) >= 0 {
        return Ee::Ea0Eb1;
    }
    if s.sign(Q::R10u) <= 0 && s.sign(Q::R10v) <= 0 {
        return Ee::Ea1Eb0;
    }
    if s.sign(Q::R11u) <= 0 && s.sign(Q::R11v) >= 0 {
        return Ee::Ea1Eb1;
    }
    if s.sign(Q::Ru) < 0 && s.sign(Q::R10u) > 0 && s.sign(Q::L0) <= 0 {
        return Ee::EaEb0;
    }
    if s.sign(Q::R01u) < 0 && s.sign(Q::R11u) > 0 && s.sign(Q::L1) >= 0 {
        return Ee::EaEb1;
    }
    if s.sign(Q::Rv) > 0 && s.sign(Q::R01v) < 0 && s.sign(Q::M0) >= 0 {
        return Ee::Ea0Eb;
    }
    if s.sign(Q::R10v) > 0 && s.sign(Q::R11v) < 0 && s.sign(Q::M1) <= 0 {
        return Ee::Ea1Eb;
    }
    Ee::EaEb
}

// ---------------------------------------------------------------------------------------------
// Exact.

/// Everything in integers on the inputs' common grid.
pub(crate) struct Exact {
    l: Leaves<BigInt>,
    d: [BigInt; 5],
    dd: BigInt,
    /// The grid's unit is `2^unit`.
    unit: i32,
}

impl Exact {
    /// From finite inputs (`d` is only used by `Q::Dist`).
    pub(crate) fn new(a0: &[f64; 3], a1: &[f64; 3], b0: &[f64; 3], b1: &[f64; 3], d: f64) -> Self {
        let xs = [
            a0[0], a0[1], a0[2], a1[0], a1[1], a1[2], b0[0], b0[1], b0[2], b1[0], b1[1], b1[2], d,
        ];
        let (g, unit) = to_grid(&xs);
        let [x0, x1, x2, y0, y1, y2, z0, z1, z2, w0, w1, w2, d] = g;
        let l = Leaves::new(&[x0, x1, x2], &[y0, y1, y2], &[z0, z1, z2], &[w0, w1, w2]);
        let dots = l.dots();
        Self {
            dd: d.mul(&d),
            d: dots,
            l,
            unit,
        }
    }

    /// The squared distance between the features of `ty` (the closest ones), correctly
    /// rounded.
    pub(crate) fn distance(&self, ty: Ee) -> f64 {
        let (num, den) = exact_ratio(parts(&self.l, ty));
        ratio_to_f64(&num, &den, 2 * i64::from(self.unit))
    }
}

impl Signs for Exact {
    fn sign(&mut self, q: Q) -> i8 {
        match q {
            Q::Ru => sign_of(&self.d[3]),
            Q::Rv => sign_of(&self.d[4]),
            _ => sign_of(&quantity(&self.l, &self.d, &self.dd, q)),
        }
    }
}

/// The inputs in the checked float ring ([`Checked`]): exact signs and values of exact ties
/// without big integers, where every operation of their formula rounds nothing.
struct CheckedFloats {
    l: Leaves<Checked>,
    /// Computed as the signs read them ([`dots_of`]).
    d: CheckedDots<5>,
    dd: Checked,
}

impl CheckedFloats {
    fn new(e: &[[f64; 3]; 4], d: f64) -> Self {
        let [a0, a1, b0, b1] = e.map(|p| p.map(Checked::input));
        let l = Leaves::new(&a0, &a1, &b0, &b1);
        let d = Checked::input(d);
        Self {
            d: CheckedDots::new(),
            dd: d.mul(&d),
            l,
        }
    }

    /// The sign of `q` when its value is exact in floats.
    fn sign(&mut self, q: Q) -> Option<i8> {
        let l = &self.l;
        let d = self.d.with(dots_of(q), |k| l.dot(k));
        quantity(l, d, &self.dd, q).sign()
    }

    /// The squared distance between the features of `ty`, correctly rounded, when its parts
    /// are exact in floats.
    fn distance(&self, ty: Ee) -> Option<f64> {
        checked_ratio(parts(&self.l, ty))
    }
}

/// The exact contexts, built on the first sign the filter cannot certify: checked floats,
/// then big integers for a sign they leave open.
struct Lazy {
    e: [[f64; 3]; 4],
    d: f64,
    checked: Option<CheckedFloats>,
    ex: Option<Box<Exact>>,
}

impl Lazy {
    fn new(e: [[f64; 3]; 4], d: f64) -> Self {
        Self {
            e,
            d,
            checked: None,
            ex: None,
        }
    }

    #[cold]
    #[inline(never)]
    fn sign(&mut self, q: Q) -> i8 {
        let (e, d) = (self.e, self.d);
        let checked = self
            .checked
            .get_or_insert_with(|| CheckedFloats::new(&e, d));
        match checked.sign(q) {
            Some(s) => s,
            None => self.get().sign(q),
        }
    }

    #[cold]
    fn get(&mut self) -> &mut Exact {
        let ([a0, a1, b0, b1], d) = (self.e, self.d);
        self.ex
            .get_or_insert_with(|| Box::new(Exact::new(&a0, &a1, &b0, &b1, d)))
    }
}

// ---------------------------------------------------------------------------------------------
// Float.

/// The float classification of the uncertain case: each sign certified by its bound, else
/// exact.
struct Fast {
    l: Leaves<f64>,
    d: [f64; 5],
    pw: Powers,
    lazy: Lazy,
}

impl Signs for Fast {
    #[inline(always)]
    fn sign(&mut self, q: Q) -> i8 {
        // Classification only (no `Q::Dist`): `dd` is not used.
        let v = quantity(&self.l, &self.d, &0.0, q);
        match certified(v, self.pw.of(bound(q))) {
            Some(s) => s,
            None => self.lazy.sign(q),
        }
    }
}

/// The float value of the squared distance between the features of `ty`, from its parts,
/// or `None` when the formula's accuracy is not assured (see [`float_value`]).
#[inline(always)]
fn value(l: &Leaves<f64>, parts: &Parts<f64>, ty: Ee) -> Option<f64> {
    match ty {
        Ee::Ea0Eb0 | Ee::Ea0Eb1 | Ee::Ea1Eb0 | Ee::Ea1Eb1 => float_value(parts, [], None),
        Ee::EaEb0 | Ee::EaEb1 | Ee::Ea0Eb | Ee::Ea1Eb => {
            let (e, w) = l.corner_edge(ty);
            float_value(parts, [e, w], None)
        }
        Ee::EaEb => float_value(parts, [&l.u, &l.v, &l.r], Some((&l.u, &l.v))),
    }
}

/// The largest side of the box of the four points, and whether the segments' boxes are
/// farther apart than `d` along an axis (exact: rounding is monotone and `d` is a float).
/// PERF: plain comparisons, as in the point-triangle twin.
#[inline(always)]
fn extent(e: [[f64; 3]; 4], d: f64) -> (f64, bool) {
    let [a0, a1, b0, b1] = e;
    let (alo, ahi) = (min3(&a0, &a1), max3(&a0, &a1));
    let (blo, bhi) = (min3(&b0, &b1), max3(&b0, &b1));
    let far = gap_exceeds(&blo, &ahi, d) | gap_exceeds(&alo, &bhi, d);
    let m = hmax(&sub3(&max3(&ahi, &bhi), &min3(&alo, &blo)));
    (m, far)
}

/// The type from the float signs when every sign [`classify`] may read is certified (all
/// nonzero then), branch-free; `None` otherwise (see the point-triangle twin).
#[inline(always)]
fn classify_certified(l: &Leaves<f64>, d: &[f64; 5], pw: &Powers) -> Option<Ee> {
    let q = |q: Q| quantity(l, d, &0.0, q);
    let (ru, rv) = (d[3], d[4]);
    let (r01u, r01v, r10u, r10v) = (q(Q::R01u), q(Q::R01v), q(Q::R10u), q(Q::R10v));
    let (r11u, r11v) = (q(Q::R11u), q(Q::R11v));
    let (l0, l1, m0, m1) = (q(Q::L0), q(Q::L1), q(Q::M0), q(Q::M1));
    let (b1, b2, b3) = (pw.of(DOT), pw.of(DOT2), pw.of(DOT3));
    let (b4, b5) = (pw.of(LAGRANGE), pw.of(LAGRANGE2));
    let sure = (ru.abs() > b1)
        & (rv.abs() > b1)
        & (r01u.abs() > b2)
        & (r01v.abs() > b2)
        & (r10u.abs() > b2)
        & (r10v.abs() > b2)
        & (r11u.abs() > b3)
        & (r11v.abs() > b3)
        & (l0.abs() > b4)
        & (m0.abs() > b4)
        & (l1.abs() > b5)
        & (m1.abs() > b5);
    if !sure {
        return None;
    }
    let pos = |x: f64| x > 0.0;
    let (pru, prv) = (pos(ru), pos(rv));
    let (p01u, p01v, p10u, p10v) = (pos(r01u), pos(r01v), pos(r10u), pos(r10v));
    let (p11u, p11v) = (pos(r11u), pos(r11v));
    let mask = u32::from(pru & !prv)
        | u32::from(p01u & p01v) << 1
        | u32::from(!p10u & !p10v) << 2
        | u32::from(!p11u & p11v) << 3
        | u32::from(!pru & p10u & !pos(l0)) << 4
        | u32::from(!p01u & p11u & pos(l1)) << 5
        | u32::from(prv & !p01v & pos(m0)) << 6
        | u32::from(p10v & !p11v & !pos(m1)) << 7
        | 1 << 8;
    Some(Ee::ALL[mask.trailing_zeros() as usize])
}

/// The float path for extents in the filter's range (see the point-triangle twin).
#[inline(always)]
fn fast(e: [[f64; 3]; 4], d: f64, m: f64, k: i32, decide: bool) -> Option<(f64, Ee)> {
    let [a0, a1, b0, b1] = e;
    // Scaling up by a power of two is exact.
    let sc = |v: V<f64>| if k == 0 { v } else { v.map(|x| ldexp(x, k)) };
    let (ds, ms) = if k == 0 {
        (d, m)
    } else {
        (ldexp(d, k), ldexp(m, k))
    };
    let dd = ds * ds;
    let pw = Powers::new(if decide { ms.max(ds) } else { ms });
    let u = sc(sub3(&a1, &a0));
    let v = sc(sub3(&b1, &b0));
    let r = sc(sub3(&a0, &b0));
    let n = cross(&u, &v);
    let lines = if decide {
        // Early exit: the lines are farther apart than `d`.
        let q = plane_q(&n, &r, &dd);
        if q > pw.of(PLANE) {
            return None;
        }
        q
    } else {
        f64::NAN
    };
    let l = Leaves {
        u,
        v,
        r,
        r01: sc(sub3(&a0, &b1)),
        r10: sc(sub3(&a1, &b0)),
        r11: sc(sub3(&a1, &b1)),
    };
    let dots = l.dots();
    // A non-finite input makes `uu` or `vv` non-finite (u and v hold every input).
    if !(dots[0] + dots[1]).is_finite() {
        return None;
    }
    let ty = match classify_certified(&l, &dots, &pw) {
        Some(ty) => ty,
        // Parallel or touching lines leave the type uncertain; a pair certainly farther
        // than `d` apart is decided without it.
        None if decide && apart_across(&l, ds, ms) => return None,
        None => classify_uncertain(&l, &dots, pw, e),
    };
    let parts = parts(&l, ty);
    if decide {
        let q = Q::Dist(ty);
        let v = match ty {
            Ee::EaEb => lines,
            _ => parts.q(&dd),
        };
        let s = match certified(v, pw.of(bound(q))) {
            Some(s) => s,
            None if apart_across(&l, ds, ms) => 1,
            None => exact_sign(e, d, q),
        };
        if s > 0 {
            return None;
        }
    }
    let v = match value(&l, &parts, ty) {
        Some(v) if k == 0 => v,
        Some(v) => ldexp(v, -2 * k),
        None => exact_distance(e, ty),
    };
    Some((v, ty))
}

/// Whether the segments are certainly farther than `d` apart, seen along a direction across
/// one of them: the part of the vector from its start to the other's midpoint perpendicular
/// to it ([`apart_along`]); each side's direction is tried. This decides the pairs whose type
/// or distance the float filter leaves uncertain (parallel segments, as a flat grid's
/// parallel diagonals) when they are far, without the exact path.
#[cold]
#[inline(never)]
fn apart_across(l: &Leaves<f64>, d: f64, m: f64) -> bool {
    let neg = |p: &V<f64>| p.map(|x| -x);
    let mid = |p: &V<f64>, q: &V<f64>| std::array::from_fn(|k| 0.5 * (p[k] + q[k]));
    // Relative to a0: a's ends 0 and u, b's -r and -r01. Relative to b0: b's ends 0 and v,
    // a's r and r10.
    let (b0, b1) = (neg(&l.r), neg(&l.r01));
    let o = [0.0; 3];
    across(&l.u, &mid(&b0, &b1)).is_some_and(|w| apart_along(&w, &[o, l.u], &[b0, b1], d, m))
        || across(&l.v, &mid(&l.r, &l.r10))
            .is_some_and(|w| apart_along(&w, &[o, l.v], &[l.r, l.r10], d, m))
}

/// [`classify`] with the float signs, exact where uncertain (cold: a near-tie).
#[cold]
#[inline(never)]
fn classify_uncertain(l: &Leaves<f64>, dots: &[f64; 5], pw: Powers, e: [[f64; 3]; 4]) -> Ee {
    classify(&mut Fast {
        l: l.clone(),
        d: *dots,
        pw,
        lazy: Lazy::new(e, 0.0),
    })
}

/// The correctly rounded squared distance between the features of `ty` (cold).
#[cold]
#[inline(never)]
fn exact_distance(e: [[f64; 3]; 4], ty: Ee) -> f64 {
    CheckedFloats::new(&e, 0.0).distance(ty).unwrap_or_else(|| {
        let [a0, a1, b0, b1] = e;
        Exact::new(&a0, &a1, &b0, &b1, 0.0).distance(ty)
    })
}

/// The exact sign of one quantity (cold: a near-tie).
#[cold]
#[inline(never)]
fn exact_sign(e: [[f64; 3]; 4], d: f64, q: Q) -> i8 {
    Lazy::new(e, d).sign(q)
}

/// The exact path: extents beyond the filter's range, and non-finite input (`None`).
#[cold]
#[inline(never)]
fn slow(e: [[f64; 3]; 4], d: Option<f64>) -> Option<(f64, Ee)> {
    let finite = e.iter().flat_map(|p| p.iter()).all(|x| x.is_finite());
    if !finite || d.is_some_and(|d| !d.is_finite()) {
        return None;
    }
    let [a0, a1, b0, b1] = e;
    let mut ex = Exact::new(&a0, &a1, &b0, &b1, d.unwrap_or(0.0));
    let ty = classify(&mut ex);
    if d.is_some() && ex.sign(Q::Dist(ty)) > 0 {
        return None;
    }
    Some((ex.distance(ty), ty))
}

/// See [`super::edge_edge_within`].
#[inline]
pub(crate) fn within(e: [[f64; 3]; 4], d: f64) -> Option<(f64, Ee)> {
    if d.is_nan() || d < 0.0 {
        return None;
    }
    let (m, far) = extent(e, d);
    if far {
        return None;
    }
    // The distance is at most |a0 - b0| <= sqrt(3) m_exact < 2 m.
    let decide = d < 2.0 * m;
    match scale_of(m) {
        Some(k) => fast(e, d, m, k, decide),
        None => slow(e, decide.then_some(d)),
    }
}

/// See [`super::edge_edge_distance_sq`].
#[inline]
pub(crate) fn distance(e: [[f64; 3]; 4]) -> (f64, Ee) {
    let (m, _) = extent(e, f64::INFINITY);
    match scale_of(m) {
        Some(k) => fast(e, 0.0, m, k, false),
        None => slow(e, None),
    }
    .unwrap_or((f64::NAN, Ee::Ea0Eb0))
}
/// The squared distance from `p` to the line through `e0` and `e1` by the corner-edge
/// formula `|e x w|^2 / |e|^2` (`e = e1 - e0`, `w = p - e0`: the value of type `Ea0Eb` for the
/// segments `[p, p]` and `[e0, e1]`), within that type's bound, and correctly rounded where
/// the formula's analysis does not hold; `NaN` for non-finite input or `e0 == e1`.
pub(crate) fn point_line_distance_sq(p: [f64; 3], e0: [f64; 3], e1: [f64; 3]) -> f64 {
    let (e, w) = (sub3(&e1, &e0), sub3(&p, &e0));
    let m = hmax(&sub3(
        &max3(&max3(&e0, &e1), &p),
        &min3(&min3(&e0, &e1), &p),
    ));
    if !m.is_finite() || e == [0.0; 3] {
        return f64::NAN;
    }
    if scale_of(m) == Some(0) {
        if let Some(v) = float_value(&line_parts(&e, &w), [&e, &w], None) {
            return v;
        }
    }
    Exact::new(&p, &p, &e0, &e1, 0.0).distance(Ee::Ea0Eb)
}

#[cfg(test)]
mod tests {
    use super::super::arith::count::Count;
    use super::*;
    use proptest::prelude::*;

    #[test]
    fn bounds_fit_every_quantity() {
        let c = Count::diffs;
        let l = Leaves {
            u: c(),
            v: c(),
            r: c(),
            r01: c(),
            r10: c(),
            r11: c(),
        };
        let d = l.dots();
        let dd = Count::input().mul(&Count::input());
        let mut all = vec![
            Q::Ru,
            Q::Rv,
            Q::R01u,
            Q::R01v,
            Q::R10u,
            Q::R10v,
            Q::R11u,
            Q::R11v,
            Q::L0,
            Q::L1,
            Q::M0,
            Q::M1,
        ];
        all.extend(Ee::ALL.map(Q::Dist));
        for q in all {
            let shape = quantity(&l, &d, &dd, q);
            assert!(shape.fits(bound(q)), "{q:?}: {shape:?} vs {:?}", bound(q));
        }
    }

    /// Inputs near every region boundary: small integers, nudged by an ulp, scaled.
    fn nearly_tied() -> impl Strategy<Value = ([[f64; 3]; 4], f64)> {
        (
            prop::array::uniform4(prop::array::uniform3(-4i32..=4)),
            prop::array::uniform4(prop::array::uniform3(-1i32..=1)),
            -40i32..40,
        )
            .prop_map(|(pts, nudge, e)| {
                let mut out = [[0.0; 3]; 4];
                for i in 0..4 {
                    for k in 0..3 {
                        let x = f64::from(pts[i][k]) * 2f64.powi(e);
                        out[i][k] = match nudge[i][k] {
                            1 => x.next_up(),
                            -1 => x.next_down(),
                            _ => x,
                        };
                    }
                }
                (out, 2f64.powi(e))
            })
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(20000))]

        /// Every sign the filter certifies is the exact sign; so is every type the branch-free
        /// classification returns, and every decision.
        #[test]
        fn certified_signs_are_exact((e, unit) in nearly_tied(), d in 0.0f64..6.0) {
            let [a0, a1, b0, b1] = e;
            let d = d * unit;
            let (m, _) = extent(e, d);
            prop_assume!(m > 0.0 && scale_of(m) == Some(0));
            let l = Leaves::new(&a0, &a1, &b0, &b1);
            let dots = l.dots();
            let dd = d * d;
            let pw = Powers::new(m.max(d));
            let mut ex = Exact::new(&a0, &a1, &b0, &b1, d);
            let mut all = vec![
                Q::Ru, Q::Rv, Q::R01u, Q::R01v, Q::R10u, Q::R10v, Q::R11u, Q::R11v, Q::L0, Q::L1,
                Q::M0, Q::M1,
            ];
            all.extend(Ee::ALL.map(Q::Dist));
            let mut checked = CheckedFloats::new(&e, d);
            for q in all {
                if let Some(s) = certified(quantity(&l, &dots, &dd, q), pw.of(bound(q))) {
                    prop_assert_eq!(s, ex.sign(q), "{:?}", q);
                }
                if let Some(s) = checked.sign(q) {
                    prop_assert_eq!(s, ex.sign(q), "checked {:?}", q);
                }
            }
            let exact = classify(&mut ex);
            if let Some(v) = checked.distance(exact) {
                prop_assert_eq!(v.to_bits(), ex.distance(exact).to_bits(), "checked {:?}", exact);
            }
            if let Some(ty) = classify_certified(&l, &dots, &pw) {
                prop_assert_eq!(ty, exact);
            }
            prop_assert_eq!(classify_uncertain(&l, &dots, pw, e), exact);
            let within = ex.sign(Q::Dist(exact)) <= 0;
            prop_assert_eq!(super::within(e, d).map(|r| r.1), within.then_some(exact));
            // The separation across a segment is certain whenever it is claimed.
            if apart_across(&l, d, m) {
                prop_assert!(!within, "claimed apart, within {}", d);
            }
        }

        /// Exact ties on a grid (no nudge: every difference and product is exact in floats)
        /// are decided by the checked floats alone, with the exact signs and values.
        #[test]
        fn ties_on_a_grid_are_exact_in_checked_floats(
            pts in prop::array::uniform4(prop::array::uniform3(-4i32..=4)),
            e in -40i32..40,
            d in 0i32..=6,
        ) {
            let unit = 2f64.powi(e);
            let e = pts.map(|p| p.map(|x| f64::from(x) * unit));
            let d = f64::from(d) * unit;
            let [a0, a1, b0, b1] = e;
            let mut ex = Exact::new(&a0, &a1, &b0, &b1, d);
            let checked = CheckedFloats::new(&e, d);
            let mut all = vec![
                Q::Ru, Q::Rv, Q::R01u, Q::R01v, Q::R10u, Q::R10v, Q::R11u, Q::R11v, Q::L0, Q::L1,
                Q::M0, Q::M1,
            ];
            all.extend(Ee::ALL.map(Q::Dist));
            for q in all {
                // A fresh context per sign: each computes only the dot products it reads.
                let mut fresh = CheckedFloats::new(&e, d);
                prop_assert_eq!(fresh.sign(q), Some(ex.sign(q)), "{:?}", q);
            }
            let ty = classify(&mut ex);
            prop_assert_eq!(
                checked.distance(ty).map(f64::to_bits),
                Some(ex.distance(ty).to_bits()),
                "{:?}",
                ty
            );
        }

        /// Parallel and nearly parallel segments (the case the separation across a segment
        /// decides): claimed apart only when the exact distance exceeds `d`.
        #[test]
        fn the_separation_across_a_segment_is_certain(
            (a0, along, off, shift) in (
                prop::array::uniform3(-8i32..=8),
                prop::array::uniform3(-3i32..=3),
                prop::array::uniform3(-3i32..=3),
                -4i32..=4,
            ),
            nudge in prop::array::uniform3(-1i32..=1),
            e in -30i32..30,
            d in 0.0f64..4.0,
        ) {
            let unit = 2f64.powi(e);
            let p = |v: [i32; 3]| v.map(|x| f64::from(x) * unit);
            let a0 = p(a0);
            let a1: V<f64> = std::array::from_fn(|k| a0[k] + f64::from(along[k]) * unit);
            // b: a's direction, shifted across by `off` and along by `shift`, one end nudged.
            let b0: V<f64> = std::array::from_fn(|k| {
                a0[k] + f64::from(off[k] + shift * along[k]) * unit
            });
            let mut b1: V<f64> = std::array::from_fn(|k| b0[k] + f64::from(along[k]) * unit);
            for k in 0..3 {
                b1[k] = match nudge[k] { 1 => b1[k].next_up(), -1 => b1[k].next_down(), _ => b1[k] };
            }
            let d = d * unit;
            let e = [a0, a1, b0, b1];
            let (m, _) = extent(e, d);
            prop_assume!(m > 0.0 && scale_of(m) == Some(0));
            let l = Leaves::new(&a0, &a1, &b0, &b1);
            if apart_across(&l, d, m) {
                let mut ex = Exact::new(&a0, &a1, &b0, &b1, d);
                let ty = classify(&mut ex);
                prop_assert!(ex.sign(Q::Dist(ty)) > 0, "{:?} claimed apart at {}", e, d);
            }
        }
    }
}
