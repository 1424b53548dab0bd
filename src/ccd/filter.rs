//! The float filter: decides a query in f64 arithmetic with rigorous error bounds, or says
//! it cannot. Stages:
//!
//! 0. Swept boxes: the two features' boxes over their positions at t = 0 and t = 1 (they
//!    move linearly, so each lies in its box all step); disjoint on an axis means no
//!    contact. Comparisons only: exact.
//! 1. The coplanarity cubic `f(t)` (zero at every contact) in Bernstein form on [0, 1]:
//!    its four coefficients are sums of the eight determinants `det(P_i, Q_j, R_k)` of the
//!    three difference vectors at t = 0 / 1 (the determinant is trilinear and each vector
//!    is linear in t). All certainly of one sign means `f` has no root: no contact.
//! 2. Isolation of the roots of `f` in [0, t_max] by subdivision of interval Bernstein
//!    coefficients, each root narrowed to an interval of width <= 2^-40 by bisection, and
//!    at each root interval (in increasing order) the in-triangle / crossing signs
//!    evaluated in interval arithmetic over that interval. A root of `f` where the
//!    features miss each other is first ruled out more cheaply, by separation along an
//!    in-plane normal of one feature's edge over the root's interval ([`apart_over`]).
//!
//! Anything not certain (a root at an endpoint, a double root, a sign straddling 0, an
//! edge or vertex contact, huge coordinates) is `Unknown` and goes to the exact path.

use super::axis;
use super::interval::Iv;
use super::ring::{self, Ring, V3};

/// What the filter concluded.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum Verdict {
    Miss,
    /// Contact; the value is a lower bound of the earliest contact time, at most 2^-40 below.
    Hit(f64),
    /// Contact at the only root of f in (lo, hi), a simple root where f changes sign; the
    /// time is to be narrowed exactly.
    Refine(f64, f64),
    Unknown,
}

/// Largest coordinate difference the filter accepts (keeps degree-4 terms far from
/// overflow).
const MAX_MAGNITUDE: f64 = 1.606_938_044_258_990_3e60; // 2^200
/// Root intervals are narrowed to this width.
pub(crate) const ROOT_WIDTH: f64 = 9.094_947_017_729_282e-13; // 2^-40
/// Subdivision depth of the root isolation before giving up.
const MAX_DEPTH: u32 = 12;

#[inline(always)]
fn min4(a: f64, b: f64, c: f64, d: f64) -> f64 {
    a.min(b).min(c.min(d))
}
#[inline(always)]
fn max4(a: f64, b: f64, c: f64, d: f64) -> f64 {
    a.max(b).max(c.max(d))
}

/// Stage 0 for vertex-face: the vertex's swept interval against the triangle's swept box,
/// per axis, separated by more than `gap` (certainly).
#[inline(always)]
pub(crate) fn vf_boxes_apart(x0: &[[f64; 3]; 4], x1: &[[f64; 3]; 4], gap: f64) -> bool {
    (0..3).any(|k| {
        let pmin = x0[0][k].min(x1[0][k]);
        let pmax = x0[0][k].max(x1[0][k]);
        let tmin = min4(x0[1][k], x0[2][k], x0[3][k], x1[1][k]).min(x1[2][k].min(x1[3][k]));
        let tmax = max4(x0[1][k], x0[2][k], x0[3][k], x1[1][k]).max(x1[2][k].max(x1[3][k]));
        apart(pmin, pmax, tmin, tmax, gap)
    })
}

/// Stage 0 for edge-edge.
#[inline(always)]
pub(crate) fn ee_boxes_apart(x0: &[[f64; 3]; 4], x1: &[[f64; 3]; 4], gap: f64) -> bool {
    (0..3).any(|k| {
        let amin = min4(x0[0][k], x0[1][k], x1[0][k], x1[1][k]);
        let amax = max4(x0[0][k], x0[1][k], x1[0][k], x1[1][k]);
        let bmin = min4(x0[2][k], x0[3][k], x1[2][k], x1[3][k]);
        let bmax = max4(x0[2][k], x0[3][k], x1[2][k], x1[3][k]);
        apart(amin, amax, bmin, bmax, gap)
    })
}

/// Stage 0 over `[0, t_max]`: the features' boxes over that time are certainly more than
/// `gap` apart. A point's box over `[0, t_max]` spans `x0` and `x0 + t_max (x1 - x0)`; the
/// latter is computed in floats and widened by a bound on its rounding (three operations,
/// each within `u = 2^-53` of `|x0| + |x1 - x0|`: `2^-50` of it, plus an absolute term for
/// underflow).
#[inline(always)]
pub(crate) fn boxes_apart_until(
    kind: super::exact::Kind,
    x0: &[[f64; 3]; 4],
    x1: &[[f64; 3]; 4],
    t_max: f64,
    gap: f64,
) -> bool {
    let mut lo = [[0.0f64; 3]; 4];
    let mut hi = [[0.0f64; 3]; 4];
    for i in 0..4 {
        for k in 0..3 {
            let (a, d) = (x0[i][k], x1[i][k] - x0[i][k]);
            let end = a + t_max * d;
            let err = (a.abs() + d.abs()) * 2f64.powi(-50) + 2f64.powi(-1000);
            lo[i][k] = a.min(end - err);
            hi[i][k] = a.max(end + err);
        }
    }
    let vf = matches!(kind, super::exact::Kind::VertexFace);
    (0..3).any(|k| {
        let (first, second) = if vf { (1, 3) } else { (2, 2) };
        let amin = lo[..first].iter().fold(f64::INFINITY, |m, p| m.min(p[k]));
        let amax = hi[..first]
            .iter()
            .fold(f64::NEG_INFINITY, |m, p| m.max(p[k]));
        let bmin = lo[4 - second..]
            .iter()
            .fold(f64::INFINITY, |m, p| m.min(p[k]));
        let bmax = hi[4 - second..]
            .iter()
            .fold(f64::NEG_INFINITY, |m, p| m.max(p[k]));
        apart(amin, amax, bmin, bmax, gap)
    })
}

/// Intervals [a0, a1] and [b0, b1] certainly more than `gap` apart. With gap = 0 a plain
/// comparison; otherwise the rounded difference stepped down one ulp (a lower bound of the
/// exact difference) must exceed the gap.
#[inline(always)]
fn apart(a0: f64, a1: f64, b0: f64, b1: f64, gap: f64) -> bool {
    if gap == 0.0 {
        a1 < b0 || b1 < a0
    } else {
        (b0 - a1).next_down() > gap || (a0 - b1).next_down() > gap
    }
}

/// The three difference vectors of `f` at t = 0 and t = 1, `[[P0, Q0, R0], [P1, Q1, R1]]`,
/// each rounded to nearest.
type Diffs = [[[f64; 3]; 3]; 2];

#[inline(always)]
fn d3(a: &[f64; 3], b: &[f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

#[inline(always)]
fn cross(a: &[f64; 3], b: &[f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

#[inline(always)]
fn dot(a: &[f64; 3], b: &[f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// Stage 1: the Bernstein coefficients of f on [0, 1] (the middle two times 3) and a bound
/// on the error of each, or None if the magnitudes are out of the filter's range.
///
/// Error bound, per coefficient. Each difference is rounded once (relative error <= u =
/// 2^-53); a determinant `p . (q x r)` is six products of three such differences with two
/// rounded multiplications each and five rounded additions, and a coefficient sums three
/// determinants. The standard forward bound is `gamma_k * P` with `P` the coefficient's
/// *permanent*, the same sums and products on absolute values (`|p| . (|q| x' |r|)` with the
/// cross product's subtraction made an addition), `k <= 3 + 2 + 5 + 2 = 12` roundings on
/// any term: `12.01 u P < 2^-49 P`. The permanent is computed in floats too (round to
/// nearest, same operation count), so it is itself within `gamma_12` of the true one; the
/// bound is taken with a relative slack of `2^-20`, which covers that. Underflow adds at
/// most `24 (m + 1) 2^-1074` absolute (an underflowed product, amplified by one factor
/// `<= m`, the largest difference), far below `(m + 1) 2^-1000`. A bound relative to each
/// coefficient's own terms (rather than to `m^3`) certifies the sign of coefficients whose
/// terms are far smaller than the largest coordinate cubed: coordinates of mixed magnitudes.
#[inline(always)]
fn bernstein(d: &Diffs) -> Option<([f64; 4], [f64; 4])> {
    let mut m = 0.0f64;
    for t in d {
        for v in t {
            for x in v {
                m = m.max(x.abs());
            }
        }
    }
    // `max` ignores NaN, so a NaN difference (inf - inf) is looked for on its own.
    if m > MAX_MAGNITUDE || d.iter().flatten().flatten().any(|x| x.is_nan()) {
        return None;
    }
    let [[p0, q0, r0], [p1, q1, r1]] = d;
    let qr00 = cross(q0, r0);
    let qr01 = cross(q0, r1);
    let qr10 = cross(q1, r0);
    let qr11 = cross(q1, r1);
    let d000 = dot(p0, &qr00);
    let d100 = dot(p1, &qr00);
    let d010 = dot(p0, &qr10);
    let d001 = dot(p0, &qr01);
    let d110 = dot(p1, &qr10);
    let d101 = dot(p1, &qr01);
    let d011 = dot(p0, &qr11);
    let d111 = dot(p1, &qr11);
    let b = [d000, d100 + d010 + d001, d110 + d101 + d011, d111];
    // The permanents, on absolute values.
    let [[p0, q0, r0], [p1, q1, r1]] = d.map(|t| t.map(|v| v.map(f64::abs)));
    let (ar00, ar01) = (abs_cross(&q0, &r0), abs_cross(&q0, &r1));
    let (ar10, ar11) = (abs_cross(&q1, &r0), abs_cross(&q1, &r1));
    let perm = [
        dot(&p0, &ar00),
        dot(&p1, &ar00) + dot(&p0, &ar10) + dot(&p0, &ar01),
        dot(&p1, &ar10) + dot(&p1, &ar01) + dot(&p0, &ar11),
        dot(&p1, &ar11),
    ];
    let tiny = (m + 1.0) * 2f64.powi(-1000);
    let e = perm.map(|p| p * (2f64.powi(-49) * (1.0 + 2f64.powi(-20))) + tiny);
    Some((b, e))
}

/// The cross product's pattern on absolute values: `|a| x' |b|` with every subtraction an
/// addition (the permanent's inner part).
#[inline(always)]
fn abs_cross(a: &[f64; 3], b: &[f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] + a[2] * b[1],
        a[2] * b[0] + a[0] * b[2],
        a[0] * b[1] + a[1] * b[0],
    ]
}

/// Interval Bernstein coefficients over a dyadic piece of [0, 1].
#[derive(Clone, Copy)]
struct Piece {
    s0: f64,
    s1: f64,
    c: [Iv; 4],
}

#[inline(always)]
fn half(a: Iv, b: Iv) -> Iv {
    a.add(&b).scale(0.5)
}

/// de Casteljau at 1/2: the two halves.
fn split(p: &Piece) -> (Piece, Piece) {
    let [c0, c1, c2, c3] = p.c;
    let c01 = half(c0, c1);
    let c12 = half(c1, c2);
    let c23 = half(c2, c3);
    let c012 = half(c01, c12);
    let c123 = half(c12, c23);
    let mid = half(c012, c123);
    let sm = 0.5 * (p.s0 + p.s1); // exact: both are multiples of 2^-MAX_DEPTH in [0, 1]
    (
        Piece {
            s0: p.s0,
            s1: sm,
            c: [c0, c01, c012, mid],
        },
        Piece {
            s0: sm,
            s1: p.s1,
            c: [mid, c123, c23, c3],
        },
    )
}

/// Enclosure of f(s) from the coefficients on [0, 1].
fn eval_at(c: &[Iv; 4], s: f64) -> Iv {
    let l = Iv::point(s);
    let m = Iv::diff(1.0, s);
    let lerp = |a: Iv, b: Iv| a.mul(&m).add(&b.mul(&l));
    let (a0, a1, a2) = (lerp(c[0], c[1]), lerp(c[1], c[2]), lerp(c[2], c[3]));
    let (b0, b1) = (lerp(a0, a1), lerp(a1, a2));
    lerp(b0, b1)
}

/// A root interval (s0, s1) of f and the sign of f at s0.
#[derive(Clone, Copy)]
struct RootIv {
    s0: f64,
    s1: f64,
    sign0: i8,
}

/// Isolates the roots of f in [0, 1] (in increasing order) or fails.
fn isolate(p: &Piece, depth: u32, out: &mut [RootIv; 3], n: &mut usize) -> bool {
    let [c0, c1, c2, c3] = p.c;
    if c0.pos() && c1.pos() && c2.pos() && c3.pos() || c0.neg() && c1.neg() && c2.neg() && c3.neg()
    {
        return true;
    }
    let (e0, e1, e2) = (c1.sub(&c0), c2.sub(&c1), c3.sub(&c2));
    let monotone = e0.pos() && e1.pos() && e2.pos() || e0.neg() && e1.neg() && e2.neg();
    if monotone {
        let (sa, sb) = (c0.sign(), c3.sign());
        if sa == 0 || sb == 0 {
            return false; // possibly a root at an end of the piece
        }
        if sa != sb {
            if *n == 3 {
                return false;
            }
            out[*n] = RootIv {
                s0: p.s0,
                s1: p.s1,
                sign0: sa,
            };
            *n += 1;
        }
        return true;
    }
    if depth == MAX_DEPTH {
        return false;
    }
    let (l, r) = split(p);
    isolate(&l, depth + 1, out, n) && isolate(&r, depth + 1, out, n)
}

/// The in-triangle or crossing test over a time interval: Some(true) contact at every
/// root of f in it, Some(false) none, None unknown.
type Static = fn(&[[f64; 3]; 4], &[[f64; 3]; 4], Iv) -> Option<bool>;

#[inline(always)]
pub(crate) fn moving(x0: &[[f64; 3]; 4], x1: &[[f64; 3]; 4], t: Iv) -> [V3<Iv>; 4] {
    let mut out = [[Iv::point(0.0); 3]; 4];
    for i in 0..4 {
        for k in 0..3 {
            out[i][k] = Iv::point(x0[i][k]).add(&t.mul(&Iv::diff(x1[i][k], x0[i][k])));
        }
    }
    out
}

fn vf_static(x0: &[[f64; 3]; 4], x1: &[[f64; 3]; 4], t: Iv) -> Option<bool> {
    let [p, a, b, c] = moving(x0, x1, t);
    let face = ring::vf_face(&p, &a, &b, &c);
    if face.d.iter().all(|d| d.pos()) {
        Some(true) // strictly inside the (coplanar) triangle
    } else if face.d.iter().any(|d| d.neg()) {
        Some(false) // a barycentric coordinate < 0: outside the closed triangle
    } else {
        None
    }
}

fn ee_static(x0: &[[f64; 3]; 4], x1: &[[f64; 3]; 4], t: Iv) -> Option<bool> {
    let [a0, a1, b0, b1] = moving(x0, x1, t);
    let x = ring::ee_cross(&a0, &a1, &b0, &b1);
    if x.cc.neg() && x.ee.neg() {
        Some(true) // a proper crossing of the coplanar segments
    } else if x.cc.pos() || x.ee.pos() {
        Some(false) // one segment strictly on one side of the other's line
    } else {
        None
    }
}

/// Stages 1 and 2 on the difference vectors.
#[inline(always)]
fn decide(
    vf: bool,
    x0: &[[f64; 3]; 4],
    x1: &[[f64; 3]; 4],
    d: &Diffs,
    t_max: f64,
    test: Static,
) -> Verdict {
    let Some((b, e)) = bernstein(d) else {
        return Verdict::Unknown;
    };
    if (0..4).all(|k| b[k] > e[k]) || (0..4).all(|k| b[k] < -e[k]) {
        return Verdict::Miss;
    }
    // Every coefficient may be 0 (f identically 0: coplanar motion): every piece of the
    // subdivision would have coefficients that may all be 0 too, so isolation cannot succeed.
    if (0..4).all(|k| b[k].abs() <= e[k]) {
        return Verdict::Unknown;
    }
    roots_and_test(vf, x0, x1, b, e, t_max, test)
}

/// f's Bernstein coefficients on [0, 1] as plain floats with one error bound, for the
/// bisection of a root: a point evaluation and its bound cost a fifth of the interval one.
struct PointCubic {
    c: [f64; 4],
    /// Bound on |f(s) - value at s| for every s in [0, 1]: the coefficients' largest error
    /// `e` (de Casteljau combinations are convex, so they do not grow it), their rounding (the
    /// division by 3) and the rounding of three levels of `a (1 - s) + b s` (each within
    /// `3u` of the largest magnitude `M`): `e + 2^-48 M` with an absolute `2^-1000` for
    /// underflow. `1 - s` is exact when `s` is a dyadic midpoint of at most 42 bits; after
    /// a root interval is clipped to a `t_max` that is not, it may round (within `u`), which
    /// adds at most `3u M` to the `9u M` above, far inside `2^-48 M = 32u M`.
    err: f64,
}

impl PointCubic {
    fn new(b: [f64; 4], e: [f64; 4]) -> Self {
        let e = e.iter().fold(0.0f64, |m, &x| m.max(x));
        let c = [b[0], b[1] / 3.0, b[2] / 3.0, b[3]];
        let m = c.iter().fold(0.0f64, |m, x| m.max(x.abs()));
        let err = (e + m * 2f64.powi(-48)) * (1.0 + 2f64.powi(-20)) + 2f64.powi(-1000);
        Self { c, err }
    }

    /// f's sign at `s` in [0, 1] if certain, else 0.
    #[inline(always)]
    fn sign_at(&self, s: f64) -> i8 {
        let t = 1.0 - s;
        let lerp = |a: f64, b: f64| a * t + b * s;
        let c = &self.c;
        let (a0, a1, a2) = (lerp(c[0], c[1]), lerp(c[1], c[2]), lerp(c[2], c[3]));
        let v = lerp(lerp(a0, a1), lerp(a1, a2));
        if v > self.err {
            1
        } else if v < -self.err {
            -1
        } else {
            0
        }
    }
}

/// Widths at which a root's interval is tested for separation ([`apart_over`]) before it is
/// narrowed to [`ROOT_WIDTH`]: on n-body-simulation 18 -> 19, 96% of these tests rule their
/// root out (the others are mostly contacts). The interval in-edge /
/// in-triangle test runs once, on the narrowed interval: run at the coarse widths too it
/// ruled out little that the separation had not, and cost a contact two more calls.
const COARSE_WIDTHS: [f64; 2] = [1.0 / 1024.0, 1.0 / (1u64 << 20) as f64];

/// Bisects the root interval `[s0, s1]` of the cubic with Bernstein coefficients `c` (sign
/// `sign0` at `s0`) down to `width` while f's sign at the midpoint is certain; false if it
/// stopped early on an uncertain sign.
#[inline(always)]
fn bisect(c: &PointCubic, sign0: i8, s0: &mut f64, s1: &mut f64, width: f64) -> bool {
    while *s1 - *s0 > width {
        let m = 0.5 * (*s0 + *s1);
        match c.sign_at(m) {
            0 => return false,
            s if s == sign0 => *s0 = m,
            _ => *s1 = m,
        }
    }
    true
}

/// The features certainly apart at every time of `[s0, s1]` (in `[0, 1]`), by separation
/// along a fixed direction between their poses at `s0` and `s1` ([`axis::apart_between`]:
/// the gap along a fixed direction is concave in time, and the poses are interpolated with
/// a bounded error). The directions are the ones that separate coplanar features that miss
/// each other, as they are at a root of f: a vertex outside a triangle lies beyond the line
/// of one of its edges within their plane, and of two segments that do not cross one lies
/// beyond the other's line. So each is an edge's normal within the plane, `n x e` (`n` the
/// triangle's normal, or the edges' cross product), at `s0`: each edge of the triangle, or
/// each of the two edges. Any direction is a valid axis, so nothing here needs to be
/// exact; a root the directions do not separate goes to the interval test.
#[inline(always)]
fn apart_over(vf: bool, x0: &[[f64; 3]; 4], x1: &[[f64; 3]; 4], s0: f64, s1: f64, m: f64) -> bool {
    let p0 = axis::positions_at(x0, x1, s0);
    let p1 = axis::positions_at(x0, x1, s1);
    let apart = |c: &[f64; 3]| axis::apart_between(vf, (&p0, &p1), c, 0.0, m);
    let edge = |from: usize, to: usize| d3(&p0[to], &p0[from]);
    if vf {
        let (e1, e2, e3) = (edge(1, 2), edge(2, 3), edge(3, 1));
        let n = cross(&e1, &e2);
        apart(&cross(&n, &e1)) || apart(&cross(&n, &e2)) || apart(&cross(&n, &e3))
    } else {
        let (u, v) = (edge(0, 1), edge(2, 3));
        let n = cross(&u, &v);
        apart(&cross(&n, &u)) || apart(&cross(&n, &v))
    }
}

#[inline(never)]
fn roots_and_test(
    vf: bool,
    x0: &[[f64; 3]; 4],
    x1: &[[f64; 3]; 4],
    b: [f64; 4],
    e: [f64; 4],
    t_max: f64,
    test: Static,
) -> Verdict {
    let c = [
        Iv::around(b[0], e[0]),
        Iv::around(b[1], e[1]).div3(),
        Iv::around(b[2], e[2]).div3(),
        Iv::around(b[3], e[3]),
    ];
    let mut found = [RootIv {
        s0: 0.0,
        s1: 0.0,
        sign0: 0,
    }; 3];
    let point = PointCubic::new(b, e);
    let mut n = 0;
    let m = super::max_magnitude(x0, x1);
    let whole = Piece {
        s0: 0.0,
        s1: 1.0,
        c,
    };
    if !isolate(&whole, 0, &mut found, &mut n) {
        return Verdict::Unknown;
    }
    for r in &found[..n] {
        let (mut s0, mut s1) = (r.s0, r.s1);
        if s0 >= t_max {
            break;
        }
        if s1 > t_max {
            match eval_at(&c, t_max).sign() {
                0 => return Verdict::Unknown,
                s if s == r.sign0 => break, // the root is beyond t_max
                _ => s1 = t_max,
            }
        }
        // Most roots of f are plane crossings away from the feature: separation in the
        // plane over the root's interval at 2^-10, then 2^-20, rules them out before the
        // narrowing to 2^-40 that only a contact's time needs.
        let mut narrow = true;
        let mut ruled_out = false;
        for width in COARSE_WIDTHS {
            narrow = bisect(&point, r.sign0, &mut s0, &mut s1, width);
            if apart_over(vf, x0, x1, s0, s1, m) {
                ruled_out = true;
                break;
            }
            if !narrow {
                break;
            }
        }
        if ruled_out {
            continue;
        }
        // Narrow the root while f's sign at the midpoint is certain. With small motions
        // f is flat and its float error (~u m^3) hides the sign before 2^-40: the interval
        // then stays wider, and a contact's time is narrowed exactly (`Refine`).
        if narrow {
            narrow = bisect(&point, r.sign0, &mut s0, &mut s1, ROOT_WIDTH);
        }
        match test(x0, x1, Iv { lo: s0, hi: s1 }) {
            Some(true) if narrow => return Verdict::Hit(s0),
            Some(true) => return Verdict::Refine(s0, s1),
            Some(false) => {}
            None => return Verdict::Unknown,
        }
    }
    Verdict::Miss
}

/// The vertex-face filter (stages 1-2; stage 0 is the caller's, which the walk's pairs skip:
/// see `ccd::pair_until`).
#[inline]
pub(crate) fn vertex_face(x0: &[[f64; 3]; 4], x1: &[[f64; 3]; 4], t_max: f64) -> Verdict {
    let at = |x: &[[f64; 3]; 4]| [d3(&x[1], &x[0]), d3(&x[2], &x[0]), d3(&x[3], &x[0])];
    decide(true, x0, x1, &[at(x0), at(x1)], t_max, vf_static)
}

/// The edge-edge filter (stages 1-2, as [`vertex_face`]).
#[inline]
pub(crate) fn edge_edge(x0: &[[f64; 3]; 4], x1: &[[f64; 3]; 4], t_max: f64) -> Verdict {
    let at = |x: &[[f64; 3]; 4]| [d3(&x[1], &x[0]), d3(&x[2], &x[0]), d3(&x[3], &x[0])];
    decide(false, x0, x1, &[at(x0), at(x1)], t_max, ee_static)
}

#[cfg(test)]
mod tests {
    //! The in-plane separation that rules out roots of f: every interval it calls apart
    //! holds no contact for the exact path, on motions built to be coplanar at some time
    //! (grid coordinates: a vertex or an edge crossing the plane of the other feature, at,
    //! beside or away from it), and it rules out a fair share of them, so the check is not
    //! vacuous.
    use super::super::exact::{solve, Kind};
    use super::super::testing::Rng;
    use super::*;

    type Points = [[f64; 3]; 4];

    /// The other feature in the plane z = 0 (still, or sliding in it) and the first crossing
    /// that plane during the step (vertex-face: the vertex; edge-edge: the first edge).
    fn crossing(rng: &mut Rng, vf: bool) -> (Points, Points) {
        let in_plane = |rng: &mut Rng| [rng.small(), rng.small(), 0.0];
        let mut x0: Points = std::array::from_fn(|_| in_plane(rng));
        let mut x1 = x0;
        if rng.below(2) == 0 {
            let slide = in_plane(rng).map(|c| c / 4.0);
            x1 = x0.map(|p| [p[0] + slide[0], p[1] + slide[1], 0.0]);
        }
        for i in 0..if vf { 1 } else { 2 } {
            let (z0, z1) = (rng.small().abs().max(0.25), -rng.small().abs().max(0.25));
            x0[i] = [rng.small(), rng.small(), z0];
            x1[i] = [rng.small(), rng.small(), z1];
        }
        (x0, x1)
    }

    #[test]
    fn every_interval_called_apart_holds_no_contact() {
        let mut rng = Rng(0x2545_f491_4f6c_dd1d);
        let (mut ruled_out, mut total) = (0u32, 0u32);
        for case in 0..6000 {
            let vf = case % 2 == 0;
            let (x0, x1) = crossing(&mut rng, vf);
            let kind = if vf { Kind::VertexFace } else { Kind::EdgeEdge };
            // From t = 0, whose pose is exact: no contact in [0, hi] at all.
            let hi = [1.0, 0.75, 0.5, 0.25][rng.below(4) as usize];
            total += 1;
            if apart_over(vf, &x0, &x1, 0.0, hi, super::super::max_magnitude(&x0, &x1)) {
                ruled_out += 1;
                let exact = solve(kind, &x0, &x1, hi, 0.0, &|| false).unwrap();
                assert_eq!(exact, None, "vf {vf} {x0:?} -> {x1:?} over [0, {hi}]");
            }
            // From an interpolated pose, over a whole tail of the step or over 2^-10 around
            // the time the first vertex crosses the plane (as the filter calls it, around a
            // root of f): the earliest contact, if any, is before the interval.
            let crossing = x0[0][2] / (x0[0][2] - x1[0][2]);
            let (lo, hi) = if rng.below(2) == 0 {
                ([0.125, 0.375, 0.5][rng.below(3) as usize], 1.0)
            } else {
                let w = 2f64.powi(-10);
                ((crossing - w).max(0.0), (crossing + w).min(1.0))
            };
            total += 1;
            if apart_over(vf, &x0, &x1, lo, hi, super::super::max_magnitude(&x0, &x1)) {
                ruled_out += 1;
                if let Some(t) = solve(kind, &x0, &x1, hi, 0.0, &|| false).unwrap() {
                    assert!(
                        t < lo,
                        "vf {vf} {x0:?} -> {x1:?}: contact at {t} in [{lo}, {hi}]"
                    );
                }
            }
        }
        assert!(ruled_out > total / 5, "{ruled_out} of {total}");
    }

    /// A vertex crossing a triangle's plane at t = 1/2, through the face, through an edge, or
    /// beside it: over an interval of 2^-10 around the crossing (and over the whole step)
    /// the last is ruled out, the others never.
    #[test]
    fn a_vertex_through_the_face_is_never_ruled_out() {
        let tri = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
        let pass = |x: f64, y: f64| {
            (
                [[x, y, 1.0], tri[0], tri[1], tri[2]],
                [[x, y, -1.0], tri[0], tri[1], tri[2]],
            )
        };
        let (lo, hi) = (0.5 - 2f64.powi(-10), 0.5 + 2f64.powi(-10));
        for (x, y) in [(0.25, 0.25), (0.5, 0.5), (0.0, 0.0)] {
            let (x0, x1) = pass(x, y);
            assert!(
                !apart_over(true, &x0, &x1, lo, hi, 1.0),
                "through ({x}, {y})"
            );
        }
        for (x, y) in [(0.75, 0.5), (-0.25, 0.5), (0.5, -0.001)] {
            let (x0, x1) = pass(x, y);
            assert!(apart_over(true, &x0, &x1, lo, hi, 1.0), "beside ({x}, {y})");
            // Straight down beside the face: apart over the whole step as well.
            assert!(
                apart_over(true, &x0, &x1, 0.0, 1.0, 1.0),
                "({x}, {y}), whole step"
            );
        }
    }
}
