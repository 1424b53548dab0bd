//! Point-triangle: the closest sub-feature, the exact decision and the value.
//!
//! With `ab = t1 - t0`, `ac = t2 - t0`, `bc = t2 - t1`, `ap = p - t0`, `bp = p - t1`,
//! `cp = p - t2` (the leaves) and the six dot products
//! `d1 = ab.ap, d2 = ac.ap, d3 = ab.bp, d4 = ac.bp, d5 = ab.cp, d6 = ac.cp`
//! (Ericson, *Real-Time Collision Detection*, 5.1.5), the closest point `c` of the closed
//! triangle to `p` is characterised by signs (each an optimality condition of the convex
//! problem, so exact for any triangle, degenerate or not):
//!
//! | `c` is | iff |
//! |---|---|
//! | `t0` | `d1 <= 0` and `d2 <= 0` |
//! | `t1` | `d3 >= 0` and `d4 - d3 <= 0` (`d4 - d3 = bc.bp`) |
//! | `t2` | `d6 >= 0` and `d5 - d6 <= 0` (`d5 - d6 = (t1 - t2).cp`) |
//! | in the open edge `t0 t1` | `d1 > 0`, `d3 < 0`, `vc = d1 d4 - d3 d2 <= 0` |
//! | in the open edge `t1 t2` | `d4 - d3 > 0`, `d5 - d6 > 0`, `va = d3 d6 - d5 d4 <= 0` |
//! | in the open edge `t2 t0` | `d2 > 0`, `d6 < 0`, `vb = d5 d2 - d1 d6 <= 0` |
//! | in the open face | none of the above |
//!
//! (`vc = n.(ab x ap)` with `n = ab x ac` by the Lagrange identity: `p` is on the far side of
//! the edge's line from the triangle, or on it; `va`, `vb` likewise.) The table is tested in
//! this order, so at a tie (coincident corners, a corner inside an edge of a collinear
//! triangle) the first type in [`PointTriangle`]'s order wins. `p` is then within `d` iff the
//! distance to that feature is: `|p - ti|^2 <= d^2`, `|e x w|^2 <= d^2 |e|^2` for the
//! edge's line, `(n.ap)^2 <= d^2 |n|^2` for the face's plane.

use num_bigint::BigInt;

use super::arith::{
    across, apart_along, certified, checked_ratio, cross, dot, exact_ratio, float_value,
    gap_exceeds, hmax, lagrange, ldexp, line_parts, max3, min3, plane_parts, plane_q, point_parts,
    ratio_to_f64, scale_of, sign_of, sub3, to_grid, Bound, Checked, CheckedDots, Parts, Powers,
    Ring, DOT, DOT2, LAGRANGE, LINE, PLANE, POINT, V,
};
use super::PointTriangle as Pt;

/// A sign the classification or the decision needs.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Q {
    D1,
    D2,
    D3,
    D6,
    /// `d4 - d3`
    D43,
    /// `d5 - d6`
    D56,
    Va,
    Vb,
    Vc,
    /// The distance to the type's feature minus `d` (in the squared, divided-out form).
    Dist(Pt),
}

/// The filter bound of each quantity (checked against the formulas by a test).
#[inline(always)]
fn bound(q: Q) -> Bound {
    match q {
        Q::D1 | Q::D2 | Q::D3 | Q::D6 => DOT,
        Q::D43 | Q::D56 => DOT2,
        Q::Va | Q::Vb | Q::Vc => LAGRANGE,
        Q::Dist(Pt::Vertex0 | Pt::Vertex1 | Pt::Vertex2) => POINT,
        Q::Dist(Pt::Edge0 | Pt::Edge1 | Pt::Edge2) => LINE,
        Q::Dist(Pt::Face) => PLANE,
    }
}

/// The differences every quantity is a polynomial in.
#[derive(Clone)]
pub(crate) struct Leaves<R> {
    ab: V<R>,
    ac: V<R>,
    bc: V<R>,
    ap: V<R>,
    bp: V<R>,
    cp: V<R>,
}

impl<R: Ring> Leaves<R> {
    #[inline(always)]
    fn new(p: &V<R>, t: &[V<R>; 3]) -> Self {
        Self {
            ab: sub3(&t[1], &t[0]),
            ac: sub3(&t[2], &t[0]),
            bc: sub3(&t[2], &t[1]),
            ap: sub3(p, &t[0]),
            bp: sub3(p, &t[1]),
            cp: sub3(p, &t[2]),
        }
    }

    /// `[d1, .., d6]`.
    #[inline(always)]
    fn dots(&self) -> [R; 6] {
        std::array::from_fn(|k| self.dot(k))
    }

    /// `d(k + 1)`: `ab` or `ac` (even or odd `k`) dotted with `ap`, `bp` or `cp`.
    #[inline(always)]
    fn dot(&self, k: usize) -> R {
        let edge = if k.is_multiple_of(2) {
            &self.ab
        } else {
            &self.ac
        };
        let point = match k / 2 {
            0 => &self.ap,
            1 => &self.bp,
            _ => &self.cp,
        };
        dot(edge, point)
    }

    /// The feature's line or plane (or corner) as `(e, w)`: an edge's direction and the
    /// point relative to its first end.
    #[inline(always)]
    fn edge(&self, ty: Pt) -> (&V<R>, &V<R>) {
        match ty {
            Pt::Edge0 => (&self.ab, &self.ap),
            Pt::Edge1 => (&self.bc, &self.bp),
            _ => (&self.ac, &self.cp),
        }
    }

    /// The point relative to a corner.
    #[inline(always)]
    fn corner(&self, ty: Pt) -> &V<R> {
        match ty {
            Pt::Vertex0 => &self.ap,
            Pt::Vertex1 => &self.bp,
            _ => &self.cp,
        }
    }
}

/// The dot products `quantity(q)` reads (bit `k` for `d(k + 1)`); `Q::Dist` reads the
/// leaves only.
#[inline(always)]
fn dots_of(q: Q) -> u8 {
    match q {
        Q::D1 => 0b1,
        Q::D2 => 0b10,
        Q::D3 => 0b100,
        Q::D6 => 0b10_0000,
        Q::D43 => 0b1100,
        Q::D56 => 0b11_0000,
        Q::Va => 0b11_1100,
        Q::Vb => 0b11_0011,
        Q::Vc => 0b1111,
        Q::Dist(_) => 0,
    }
}

/// The quantities other than the six dot products, from the dots and leaves.
#[inline(always)]
fn quantity<R: Ring>(l: &Leaves<R>, d: &[R; 6], dd: &R, q: Q) -> R {
    let [d1, d2, d3, d4, d5, d6] = d;
    match q {
        Q::D1 => d1.clone(),
        Q::D2 => d2.clone(),
        Q::D3 => d3.clone(),
        Q::D6 => d6.clone(),
        Q::D43 => d4.sub(d3),
        Q::D56 => d5.sub(d6),
        Q::Va => lagrange(d3, d6, d5, d4),
        Q::Vb => lagrange(d5, d2, d1, d6),
        Q::Vc => lagrange(d1, d4, d3, d2),
        Q::Dist(ty) => parts(l, ty).q(dd),
    }
}

/// The squared distance to the feature `ty` as [`Parts`] (a [`point_parts`], [`line_parts`]
/// or [`plane_parts`]: their `q` is [`point_q`], [`line_q`], [`plane_q`]).
#[inline(always)]
fn parts<R: Ring>(l: &Leaves<R>, ty: Pt) -> Parts<R> {
    match ty {
        Pt::Vertex0 | Pt::Vertex1 | Pt::Vertex2 => point_parts(l.corner(ty)),
        Pt::Edge0 | Pt::Edge1 | Pt::Edge2 => {
            let (e, w) = l.edge(ty);
            line_parts(e, w)
        }
        Pt::Face => plane_parts(&cross(&l.ab, &l.ac), &l.ap),
    }
}

/// Exact signs of the quantities.
pub(crate) trait Signs {
    fn sign(&mut self, q: Q) -> i8;
}

/// The closest sub-feature (exact, given exact signs).
#[inline(always)]
pub(crate) fn classify<S: Signs>(s: &mut S) -> Pt {
    if s.sign(Q::D1) <= 0 && s.sign(Q::D2) <= 0 {
        return Pt::Vertex0;
    }
    if s.sign(Q::D3) >= 0 && s.sign(Q::D43) <= 0 {
        return Pt::Vertex1;
    }
    if s.sign(Q::D6) >= 0 && s.sign(Q::D56) <= 0 {
        return Pt::Vertex2;
    }
    if s.sign(Q::D1) > 0 && s.sign(Q::D3) < 0 && s.sign(Q::Vc) <= 0 {
        return Pt::Edge0;
    }
    if s.sign(Q::D43) > 0 && s.sign(Q::D56) > 0 && s.sign(Q::Va) <= 0 {
        return Pt::Edge1;
    }
    if s.sign(Q::D2) > 0 && s.sign(Q::D6) < 0 && s.sign(Q::Vb) <= 0 {
        return Pt::Edge2;
    }
    Pt::Face
}

// ---------------------------------------------------------------------------------------------
// Exact.

/// Everything in integers on the inputs' common grid.
pub(crate) struct Exact {
    l: Leaves<BigInt>,
    d: [BigInt; 6],
    dd: BigInt,
    /// The grid's unit is `2^unit`.
    unit: i32,
}

impl Exact {
    /// From finite inputs (`d` is only used by `Q::Dist`).
    pub(crate) fn new(p: &[f64; 3], t: &[[f64; 3]; 3], d: f64) -> Self {
        let xs = [
            p[0], p[1], p[2], t[0][0], t[0][1], t[0][2], t[1][0], t[1][1], t[1][2], t[2][0],
            t[2][1], t[2][2], d,
        ];
        let (g, unit) = to_grid(&xs);
        let [p0, p1, p2, a0, a1, a2, b0, b1, b2, c0, c1, c2, d] = g;
        let l = Leaves::new(&[p0, p1, p2], &[[a0, a1, a2], [b0, b1, b2], [c0, c1, c2]]);
        let dots = l.dots();
        Self {
            dd: d.mul(&d),
            d: dots,
            l,
            unit,
        }
    }

    /// The squared distance to the feature `ty` (the closest one), correctly rounded.
    pub(crate) fn distance(&self, ty: Pt) -> f64 {
        let (num, den) = exact_ratio(parts(&self.l, ty));
        ratio_to_f64(&num, &den, 2 * i64::from(self.unit))
    }
}

impl Signs for Exact {
    fn sign(&mut self, q: Q) -> i8 {
        match q {
            Q::D1 => sign_of(&self.d[0]),
            Q::D2 => sign_of(&self.d[1]),
            Q::D3 => sign_of(&self.d[2]),
            Q::D6 => sign_of(&self.d[5]),
            _ => sign_of(&quantity(&self.l, &self.d, &self.dd, q)),
        }
    }
}

/// The inputs in the checked float ring ([`Checked`]): exact signs and values of exact ties
/// without big integers, where every operation of their formula rounds nothing.
struct CheckedFloats {
    l: Leaves<Checked>,
    /// Computed as the signs read them ([`dots_of`]).
    d: CheckedDots<6>,
    dd: Checked,
}

impl CheckedFloats {
    fn new(p: &[f64; 3], t: &[[f64; 3]; 3], d: f64) -> Self {
        let l = Leaves::new(&p.map(Checked::input), &t.map(|c| c.map(Checked::input)));
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

    /// The squared distance to the feature `ty`, correctly rounded, when its parts are exact
    /// in floats.
    fn distance(&self, ty: Pt) -> Option<f64> {
        checked_ratio(parts(&self.l, ty))
    }
}

/// The exact contexts, built on the first sign the filter cannot certify: checked floats,
/// then big integers for a sign they leave open.
struct Lazy {
    p: [f64; 3],
    t: [[f64; 3]; 3],
    d: f64,
    checked: Option<CheckedFloats>,
    ex: Option<Box<Exact>>,
}

impl Lazy {
    fn new(p: [f64; 3], t: [[f64; 3]; 3], d: f64) -> Self {
        Self {
            p,
            t,
            d,
            checked: None,
            ex: None,
        }
    }

    #[cold]
    #[inline(never)]
    fn sign(&mut self, q: Q) -> i8 {
        let (p, t, d) = (self.p, self.t, self.d);
        let checked = self
            .checked
            .get_or_insert_with(|| CheckedFloats::new(&p, &t, d));
        match checked.sign(q) {
            Some(s) => s,
            None => self.get().sign(q),
        }
    }

    #[cold]
    fn get(&mut self) -> &mut Exact {
        let (p, t, d) = (self.p, self.t, self.d);
        self.ex
            .get_or_insert_with(|| Box::new(Exact::new(&p, &t, d)))
    }
}

// ---------------------------------------------------------------------------------------------
// Float.

/// The float classification of the uncertain case: each sign certified by its bound, else
/// exact.
struct Fast {
    l: Leaves<f64>,
    d: [f64; 6],
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

/// The float value of the squared distance to the feature `ty`, from its parts (unscaled
/// by the caller), or `None` when the formula's accuracy is not assured (see
/// [`float_value`]).
#[inline(always)]
fn value(l: &Leaves<f64>, parts: &Parts<f64>, ty: Pt) -> Option<f64> {
    match ty {
        Pt::Vertex0 | Pt::Vertex1 | Pt::Vertex2 => float_value(parts, [], None),
        Pt::Edge0 | Pt::Edge1 | Pt::Edge2 => {
            let (e, w) = l.edge(ty);
            float_value(parts, [e, w], None)
        }
        Pt::Face => float_value(parts, [&l.ab, &l.ac, &l.ap], Some((&l.ab, &l.ac))),
    }
}

/// The largest side of the box of the points (exact extents, rounded once), and whether a
/// coordinate gap already exceeds `d` (`far`: decided exactly, since rounding is monotone and
/// `d` is a float). PERF: plain comparisons (`minsd`), not `f64::min`'s NaN handling, in
/// whole vectors; a NaN input is caught later (see [`fast`]).
#[inline(always)]
fn extent(p: [f64; 3], t: [[f64; 3]; 3], d: f64) -> (f64, bool) {
    let lo = min3(&min3(&t[0], &t[1]), &t[2]);
    let hi = max3(&max3(&t[0], &t[1]), &t[2]);
    let far = gap_exceeds(&lo, &p, d) | gap_exceeds(&p, &hi, d);
    let m = hmax(&sub3(&max3(&hi, &p), &min3(&lo, &p)));
    (m, far)
}

/// The type from the float signs when every sign [`classify`] may read is certified (all
/// nonzero then), branch-free; `None` otherwise. PERF: the types of neighbouring candidates
/// are unpredictable, and the branchy [`classify`] paid a misprediction per test.
#[inline(always)]
fn classify_certified(l: &Leaves<f64>, d: &[f64; 6], pw: &Powers) -> Option<Pt> {
    let q = |q: Q| quantity(l, d, &0.0, q);
    let (d1, d2, d3, d6) = (d[0], d[1], d[2], d[5]);
    let (d43, d56) = (q(Q::D43), q(Q::D56));
    let (va, vb, vc) = (q(Q::Va), q(Q::Vb), q(Q::Vc));
    let (b2, b2d, b4) = (pw.of(DOT), pw.of(DOT2), pw.of(LAGRANGE));
    let sure = (d1.abs() > b2)
        & (d2.abs() > b2)
        & (d3.abs() > b2)
        & (d6.abs() > b2)
        & (d43.abs() > b2d)
        & (d56.abs() > b2d)
        & (va.abs() > b4)
        & (vb.abs() > b4)
        & (vc.abs() > b4);
    if !sure {
        return None;
    }
    let (p1, p2, p3, p6) = (d1 > 0.0, d2 > 0.0, d3 > 0.0, d6 > 0.0);
    let (p43, p56) = (d43 > 0.0, d56 > 0.0);
    let mask = u32::from(!p1 & !p2)
        | u32::from(p3 & !p43) << 1
        | u32::from(p6 & !p56) << 2
        | u32::from(p1 & !p3 & (vc < 0.0)) << 3
        | u32::from(p43 & p56 & (va < 0.0)) << 4
        | u32::from(p2 & !p6 & (vb < 0.0)) << 5
        | 1 << 6;
    Some(Pt::ALL[mask.trailing_zeros() as usize])
}

/// The float path for extents in the filter's range (`k`: the leaves' scaling exponent).
/// `decide`: test the distance against `d` (else only classify and measure). `None`: not
/// within `d`, or an input is not finite.
#[inline(always)]
fn fast(p: [f64; 3], t: [[f64; 3]; 3], d: f64, m: f64, k: i32, decide: bool) -> Option<(f64, Pt)> {
    // Scaling up by a power of two is exact.
    let sc = |v: V<f64>| if k == 0 { v } else { v.map(|x| ldexp(x, k)) };
    let (ds, ms) = if k == 0 {
        (d, m)
    } else {
        (ldexp(d, k), ldexp(m, k))
    };
    let dd = ds * ds;
    let pw = Powers::new(if decide { ms.max(ds) } else { ms });
    // The plane test's leaves first (PERF: most far pairs leave there).
    let ab = sc(sub3(&t[1], &t[0]));
    let ac = sc(sub3(&t[2], &t[0]));
    let ap = sc(sub3(&p, &t[0]));
    let n = cross(&ab, &ac);
    let plane = if decide {
        // Early exit: farther than `d` from the triangle's plane.
        let q = plane_q(&n, &ap, &dd);
        if q > pw.of(PLANE) {
            return None;
        }
        q
    } else {
        f64::NAN
    };
    let l = Leaves {
        ab,
        ac,
        bc: sc(sub3(&t[2], &t[1])),
        ap,
        bp: sc(sub3(&p, &t[1])),
        cp: sc(sub3(&p, &t[2])),
    };
    let dots = l.dots();
    // A non-finite input makes some dot product non-finite (every input is in one).
    if !(dots[0] + dots[1] + dots[2] + dots[3] + dots[4] + dots[5]).is_finite() {
        return None;
    }
    let ty = match classify_certified(&l, &dots, &pw) {
        Some(ty) => ty,
        // A point in or near the triangle's plane leaves the type uncertain; a pair
        // certainly farther than `d` apart is decided without it.
        None if decide && apart_beside(&l, ds, ms) => return None,
        None => classify_uncertain(&l, &dots, pw, p, t),
    };
    let parts = parts(&l, ty);
    if decide {
        let q = Q::Dist(ty);
        let v = match ty {
            Pt::Face => plane,
            _ => parts.q(&dd),
        };
        let s = match certified(v, pw.of(bound(q))) {
            Some(s) => s,
            None if apart_beside(&l, ds, ms) => 1,
            None => exact_sign(p, t, d, q),
        };
        if s > 0 {
            return None;
        }
    }
    let v = match value(&l, &parts, ty) {
        Some(v) if k == 0 => v,
        Some(v) => ldexp(v, -2 * k),
        None => exact_distance(p, t, ty),
    };
    Some((v, ty))
}

/// Whether the point is certainly farther than `d` from the triangle, seen across one of
/// its edges: the part of the vector from the edge's start to the point perpendicular to
/// the edge ([`apart_along`]; a point outside the triangle in its plane lies beyond some
/// edge's line). Decides the pairs whose type or distance the float filter leaves
/// uncertain (a point in the triangle's plane, as on a flat sheet) when they are far,
/// without the exact path.
#[cold]
#[inline(never)]
fn apart_beside(l: &Leaves<f64>, d: f64, m: f64) -> bool {
    let neg = |p: &V<f64>| p.map(|x| -x);
    let o = [0.0; 3];
    // Each edge from its start: the edge, the third corner and the point, relative to it.
    let edges = [
        (l.ab, l.ac, l.ap),
        (l.bc, neg(&l.ab), l.bp),
        (neg(&l.ac), neg(&l.bc), l.cp),
    ];
    edges
        .iter()
        .any(|(e, z, q)| across(e, q).is_some_and(|w| apart_along(&w, &[o, *e, *z], &[*q], d, m)))
}

/// [`classify`] with the float signs, exact where uncertain (cold: a near-tie).
#[cold]
#[inline(never)]
fn classify_uncertain(
    l: &Leaves<f64>,
    dots: &[f64; 6],
    pw: Powers,
    p: [f64; 3],
    t: [[f64; 3]; 3],
) -> Pt {
    classify(&mut Fast {
        l: l.clone(),
        d: *dots,
        pw,
        lazy: Lazy::new(p, t, 0.0),
    })
}

/// The correctly rounded squared distance to the feature `ty` (cold).
#[cold]
#[inline(never)]
fn exact_distance(p: [f64; 3], t: [[f64; 3]; 3], ty: Pt) -> f64 {
    CheckedFloats::new(&p, &t, 0.0)
        .distance(ty)
        .unwrap_or_else(|| Exact::new(&p, &t, 0.0).distance(ty))
}

/// The exact sign of one quantity (cold: a near-tie).
#[cold]
#[inline(never)]
fn exact_sign(p: [f64; 3], t: [[f64; 3]; 3], d: f64, q: Q) -> i8 {
    Lazy::new(p, t, d).sign(q)
}

/// The exact path: extents beyond the filter's range, and non-finite input (`None`).
#[cold]
#[inline(never)]
fn slow(p: [f64; 3], t: [[f64; 3]; 3], d: Option<f64>) -> Option<(f64, Pt)> {
    let finite = p.iter().chain(t.as_flattened()).all(|x| x.is_finite());
    if !finite || d.is_some_and(|d| !d.is_finite()) {
        return None;
    }
    let mut ex = Exact::new(&p, &t, d.unwrap_or(0.0));
    let ty = classify(&mut ex);
    if d.is_some() && ex.sign(Q::Dist(ty)) > 0 {
        return None;
    }
    Some((ex.distance(ty), ty))
}

/// See [`super::point_triangle_within`].
#[inline]
pub(crate) fn within(p: [f64; 3], t: [[f64; 3]; 3], d: f64) -> Option<(f64, Pt)> {
    if d.is_nan() || d < 0.0 {
        return None;
    }
    let (m, far) = extent(p, t, d);
    if far {
        return None;
    }
    // The distance is at most |p - t0| <= sqrt(3) m_exact < 2 m: within when d >= 2 m.
    let decide = d < 2.0 * m;
    match scale_of(m) {
        Some(k) => fast(p, t, d, m, k, decide),
        None => slow(p, t, decide.then_some(d)),
    }
}

/// See [`super::point_triangle_distance_sq`].
#[inline]
pub(crate) fn distance(p: [f64; 3], t: [[f64; 3]; 3]) -> (f64, Pt) {
    let (m, _) = extent(p, t, f64::INFINITY);
    match scale_of(m) {
        Some(k) => fast(p, t, 0.0, m, k, false),
        None => slow(p, t, None),
    }
    .unwrap_or((f64::NAN, Pt::Vertex0))
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
            ab: c(),
            ac: c(),
            bc: c(),
            ap: c(),
            bp: c(),
            cp: c(),
        };
        let d = l.dots();
        let dd = Count::input().mul(&Count::input());
        let mut all = vec![
            Q::D1,
            Q::D2,
            Q::D3,
            Q::D6,
            Q::D43,
            Q::D56,
            Q::Va,
            Q::Vb,
            Q::Vc,
        ];
        all.extend(Pt::ALL.map(Q::Dist));
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
        fn certified_signs_are_exact((pts, unit) in nearly_tied(), d in 0.0f64..6.0) {
            let [p, t0, t1, t2] = pts;
            let d = d * unit;
            let t = [t0, t1, t2];
            let (m, _) = extent(p, t, d);
            prop_assume!(m > 0.0 && scale_of(m) == Some(0));
            let l = Leaves::new(&p, &t);
            let dots = l.dots();
            let dd = d * d;
            let pw = Powers::new(m.max(d));
            let mut ex = Exact::new(&p, &t, d);
            let mut all = vec![Q::D1, Q::D2, Q::D3, Q::D6, Q::D43, Q::D56, Q::Va, Q::Vb, Q::Vc];
            all.extend(Pt::ALL.map(Q::Dist));
            let mut checked = CheckedFloats::new(&p, &t, d);
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
            prop_assert_eq!(classify_uncertain(&l, &dots, pw, p, t), exact);
            let within = ex.sign(Q::Dist(exact)) <= 0;
            prop_assert_eq!(super::within(p, t, d).map(|r| r.1), within.then_some(exact));
            // The separation across an edge is certain whenever it is claimed.
            if apart_beside(&l, d, m) {
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
            let [p, t0, t1, t2] = pts.map(|p| p.map(|x| f64::from(x) * unit));
            let t = [t0, t1, t2];
            let d = f64::from(d) * unit;
            let mut ex = Exact::new(&p, &t, d);
            let checked = CheckedFloats::new(&p, &t, d);
            let mut all = vec![Q::D1, Q::D2, Q::D3, Q::D6, Q::D43, Q::D56, Q::Va, Q::Vb, Q::Vc];
            all.extend(Pt::ALL.map(Q::Dist));
            for q in all {
                // A fresh context per sign: each computes only the dot products it reads.
                let mut fresh = CheckedFloats::new(&p, &t, d);
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
    }
}
