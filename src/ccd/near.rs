//! The float filter for a minimum distance `delta > 0`: decides whether the two features come
//! within `delta` during `[0, t_max]`, and when, in interval arithmetic, or says it cannot.
//!
//! **Lipschitz pieces.** The distance between the two features changes at most as fast as
//! their fastest relative motion: a point of either feature is a convex combination of its
//! corners, so for fixed weights the distance between two such points moves at speed
//! `|sum l_i a_i' - sum m_j b_j'| <= max_ij |a_i' - b_j'| = L` (each corner moves at the
//! constant velocity `x1 - x0`), and a minimum of `L`-Lipschitz functions is `L`-Lipschitz.
//! So a time piece `[lo, hi]` is apart (distance `> delta` at every t of it) when the distance
//! at one point `m` of it exceeds `delta + L max(m - lo, hi - m)`. That test is evaluated at a
//! single time, where the interval enclosure of the positions is a few ulps wide, so it stays
//! sharp however close the piece is to the contact time. Where it fails, the piece is also
//! tested with every corner enclosed over the whole piece, which is sharper for features
//! sliding past each other fast at a nearly constant distance (large `L`).
//!
//! **Search.** First the start: within at t = 0 means a contact at 0. Then pieces of
//! `[0, t_max]` are visited earliest first (depth-first bisection), skipped when apart and
//! split otherwise, down to width `2^-46`. Each piece is first tested the cheap way: the
//! features' closest direction at the piece's end, in plain floats, is used as a fixed
//! separating axis over the piece (`axis.rs`: the gap along a fixed axis is concave in t,
//! so its values at the two ends bound it, with no margin for the motion); and a piece
//! whose end is nearer than `delta` by that float estimate holds the contact, so it is split
//! without trying the certificates that could not succeed. The Lipschitz tests above come
//! next. At the first leaf `[lo, hi]` that is not apart, every time before `lo` is apart; if
//! the distance is within `delta` at one of the points `lo + k 2^-44`, `k = 1..16`, the
//! earliest contact lies in `[lo, lo + 2^-40]` and `lo` is returned (at most `2^-40` early,
//! the exact path's tolerance). Otherwise (the distance touches `delta` without crossing it,
//! or crosses it too slowly for floats to place within `2^-40`), the query is left to the
//! exact path.
//!
//! Every test compares squared distances times a positive squared length with `delta^2`, so no
//! division or square root is needed, and uses only these facts:
//! - a plane, a line, or the lines of two edges are never farther than the feature itself, so
//!   `dist(plane) > delta` (resp. line) certifies apart;
//! - the distance to a point of a feature bounds the feature's distance from above: a corner,
//!   the foot of the perpendicular on a segment when it certainly lies on the segment, the
//!   foot on the triangle's plane when it certainly lies in the triangle, the closest points of
//!   two lines when both certainly lie on their segments. Any of them within certifies within;
//! - the closest point of a triangle is the foot on its plane or a point of its boundary, and
//!   the closest pair of two segments is the pair of the lines' closest points or involves an
//!   endpoint (minimising a convex function over a square): so with the foot certainly outside
//!   the triangle (a barycentric numerator `< 0`), the three edges all apart certify apart,
//!   and with the lines' closest points certainly not both on the segments, the four
//!   endpoint-to-segment distances all apart do;
//! - for nearly parallel edges, a separating axis: along `n = u x (u x (b0 - a0))`
//!   (perpendicular to edge a, in the plane of its line and `b0`) all of edge a projects to one
//!   value, so both ends of edge b beyond delta on the same side separate the edges.
//!
//! A foot or a line is only used where its squared length factor is certainly `> 0`
//! (degenerate triangles and zero-length edges fall back to their corners).

use super::axis;
use super::filter::{moving, Verdict};
use super::interval::Iv;
use super::pieces::{earliest_first, Piece};
use super::ring::{self, Ring, V3};

/// Bound on the pieces visited per query: where the distance stays near `delta` for a long
/// time the bisection would split many pieces; past this many the query is left to the exact
/// path (~2 us a piece).
const MAX_PIECES: u32 = 4096;

/// Width of the narrowest pieces.
const LEAF_WIDTH: f64 = 1.0 / (1u64 << 46) as f64;
/// Spacing and number of the probes after the first leaf not apart: up to `2^-40`.
const PROBE_STEP: f64 = 1.0 / (1u64 << 44) as f64;
const PROBES: u32 = 16;

/// An upper bound on the speed at which the features' distance can change (see the module
/// docs): the largest `|a_i' - b_j'|` over the corners of the two features.
fn max_relative_speed(vf: bool, x0: &[[f64; 3]; 4], x1: &[[f64; 3]; 4]) -> f64 {
    let velocity = |i: usize| -> V3<Iv> { std::array::from_fn(|k| Iv::diff(x1[i][k], x0[i][k])) };
    let split = if vf { 1 } else { 2 };
    let mut most = 0.0f64;
    for i in 0..split {
        for j in split..4 {
            let d = ring::sub3(&velocity(i), &velocity(j));
            most = most.max(ring::dot(&d, &d).hi);
        }
    }
    // sqrt is correctly rounded; a NaN (overflow) makes every margin NaN, which certifies
    // nothing.
    most.sqrt().next_up()
}

/// The verdict for the pair (`vf`: vertex-face, else edge-edge) coming within `delta > 0`
/// during `[0, t_max]`: `Miss`, `Hit(lo)` with the earliest contact in `[lo, lo + 2^-40]`, or
/// `Unknown`.
pub(crate) fn decide(
    vf: bool,
    x0: &[[f64; 3]; 4],
    x1: &[[f64; 3]; 4],
    t_max: f64,
    delta: f64,
) -> Verdict {
    let at = |t: f64| moving(x0, x1, Iv::point(t));
    if within(vf, &at(0.0), delta) {
        return Verdict::Hit(0.0);
    }
    let speed = max_relative_speed(vf, x0, x1);
    let magnitude = x0
        .iter()
        .chain(x1)
        .flatten()
        .fold(0.0f64, |m, x| m.max(x.abs()));
    earliest_first(t_max, MAX_PIECES, |lo, hi, last| {
        // The features' closest direction at the piece's end, in plain floats: the
        // separating axis of a piece before the contact; and, with the features nearer
        // than delta there, the sign that this piece holds the contact, so the certificates
        // below, which could not succeed, are skipped.
        let (start, end) = (
            axis::positions_at(x0, x1, lo),
            axis::positions_at(x0, x1, hi),
        );
        let c = closest_direction(vf, &end);
        let splittable = hi - lo > LEAF_WIDTH && !last;
        if splittable && ring_len2(&c) < delta * delta {
            return Piece::Split;
        }
        if axis::apart_between(vf, (&start, &end), &c, delta, magnitude) {
            return Piece::Apart;
        }
        let mid = 0.5 * (lo + hi);
        // The largest distance from mid to an end, rounded up, times the speed.
        let reach = (mid - lo).max(hi - mid).next_up();
        let margin = (speed * reach).next_up();
        if apart(vf, &at(mid), (delta + margin).next_up()) {
            return Piece::Apart;
        }
        // The features enclosed over the whole piece: sharper where they slide past each
        // other fast at a nearly constant distance (then L is large and the margin wide).
        if apart(vf, &moving(x0, x1, Iv { lo, hi }), delta) {
            return Piece::Apart;
        }
        if splittable {
            return Piece::Split;
        }
        // Everything before lo is apart: within at a probe puts the contact in
        // [lo, lo + 2^-40].
        let within = (1..=PROBES).any(|k| {
            let t = (lo + k as f64 * PROBE_STEP).min(t_max);
            within(vf, &at(t), delta)
        });
        Piece::Decided(
            if within || touches_by(vf, x0, x1, t_max, lo + TOUCH_SLACK) {
                Verdict::Hit(lo)
            } else {
                Verdict::Unknown
            },
        )
    })
}

type P3 = [f64; 3];

fn sub(a: &P3, b: &P3) -> P3 {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

fn dot(a: &P3, b: &P3) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

fn ring_len2(a: &P3) -> f64 {
    dot(a, a)
}

fn cross(a: &P3, b: &P3) -> P3 {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

/// `a + s (b - a)`.
fn lerp(a: &P3, b: &P3, s: f64) -> P3 {
    [
        a[0] + s * (b[0] - a[0]),
        a[1] + s * (b[1] - a[1]),
        a[2] + s * (b[2] - a[2]),
    ]
}

/// The point of segment `[a, b]` nearest `p`, approximately (plain floats).
fn nearest_on_segment(p: &P3, a: &P3, b: &P3) -> P3 {
    let e = sub(b, a);
    let len2 = dot(&e, &e);
    let s = if len2 > 0.0 {
        (dot(&sub(p, a), &e) / len2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    lerp(a, b, s)
}

/// From the first feature's nearest point to the second's, approximately (plain floats, no
/// guarantee: any direction is a valid separating axis, and the distance it gives only
/// steers the search). `x`: the vertex and the triangle's corners, or two edges' ends.
fn closest_direction(vf: bool, x: &[P3; 4]) -> P3 {
    let nearest = |candidates: &[(P3, P3)]| -> P3 {
        candidates
            .iter()
            .map(|(a, b)| sub(b, a))
            .min_by(|u, v| dot(u, u).total_cmp(&dot(v, v)))
            .unwrap_or([0.0; 3])
    };
    if vf {
        let [p, a, b, c] = x;
        let n = cross(&sub(b, a), &sub(c, a));
        let n2 = dot(&n, &n);
        if n2 > 0.0 {
            let foot = lerp(
                p,
                &[p[0] + n[0], p[1] + n[1], p[2] + n[2]],
                dot(&sub(a, p), &n) / n2,
            );
            let inside = [(a, b), (b, c), (c, a)]
                .iter()
                .all(|(u, v)| dot(&cross(&sub(v, u), &sub(&foot, u)), &n) >= 0.0);
            if inside {
                return sub(&foot, p);
            }
        }
        nearest(&[
            (*p, nearest_on_segment(p, a, b)),
            (*p, nearest_on_segment(p, b, c)),
            (*p, nearest_on_segment(p, c, a)),
        ])
    } else {
        let [a0, a1, b0, b1] = x;
        let (u, v, r) = (sub(a1, a0), sub(b1, b0), sub(b0, a0));
        let w = cross(&u, &v);
        let w2 = dot(&w, &w);
        if w2 > 0.0 {
            // The lines' closest points, when both lie on the segments.
            let s = dot(&cross(&r, &v), &w) / w2;
            let t = dot(&cross(&r, &u), &w) / w2;
            if (0.0..=1.0).contains(&s) && (0.0..=1.0).contains(&t) {
                return sub(&lerp(b0, b1, t), &lerp(a0, a1, s));
            }
        }
        nearest(&[
            (*a0, nearest_on_segment(a0, b0, b1)),
            (*a1, nearest_on_segment(a1, b0, b1)),
            (nearest_on_segment(b0, a0, a1), *b0),
            (nearest_on_segment(b1, a0, a1), *b1),
        ])
    }
}

/// How far after the first piece not apart (`lo`) the delta-0 filter's contact time may lie
/// for [`touches_by`] to place the earliest time within `delta` in `[lo, lo + 2^-40 +
/// 2^-44]` (below [`super::TOI_TOLERANCE`]).
const TOUCH_SLACK: f64 = 1.0 / (1u64 << 44) as f64;

/// The features certainly touch (distance 0, so within any `delta`) at some time `<= by +
/// 2^-40`: the delta-0 float filter finds a contact at a time it places at most `2^-40`
/// before the true one, and no later than `by`. A `delta` too small to certify "within" in
/// floats (`5e-324` next to unit coordinates) is then decided by the contact itself.
fn touches_by(vf: bool, x0: &[[f64; 3]; 4], x1: &[[f64; 3]; 4], t_max: f64, by: f64) -> bool {
    let verdict = if vf {
        super::filter::vertex_face(x0, x1, t_max)
    } else {
        super::filter::edge_edge(x0, x1, t_max)
    };
    match verdict {
        Verdict::Hit(t) => t <= by,
        // A contact somewhere in (lo, hi).
        Verdict::Refine(_, hi) => hi <= by + super::filter::ROOT_WIDTH,
        _ => false,
    }
}

/// The boxes of the two features (vertex | triangle, or edge | edge) over the piece, more
/// than `delta` apart on an axis.
fn boxes_apart(vf: bool, pts: &[V3<Iv>; 4], delta: f64) -> bool {
    let (first, second) = pts.split_at(if vf { 1 } else { 2 });
    let boxed = |ps: &[V3<Iv>], k: usize| {
        ps.iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), p| {
                (l.min(p[k].lo), h.max(p[k].hi))
            })
    };
    (0..3).any(|k| {
        let (l1, h1) = boxed(first, k);
        let (l2, h2) = boxed(second, k);
        (l2 - h1).next_down() > delta || (l1 - h2).next_down() > delta
    })
}

/// The features at `pts` (enclosures of their corners over a time or a piece) certainly
/// farther apart than `delta`. Cheapest tests first, each skipped once one succeeds.
fn apart(vf: bool, pts: &[V3<Iv>; 4], delta: f64) -> bool {
    if boxes_apart(vf, pts, delta) {
        return true;
    }
    let dd = square(delta);
    if vf {
        let [p, a, b, c] = pts;
        let face = ring::vf_face(p, a, b, c);
        let n2 = ring::dot(&face.n, &face.n);
        // f = (a - p) . n: the plane's distance is |f| / |n|.
        if n2.pos() && excess(face.f, n2, dd).pos() {
            return true;
        }
        // The foot certainly outside, or the triangle degenerate (then it is its edges).
        let foot_out = face.d.iter().any(|d| d.neg()) || nonpositive(n2);
        foot_out
            && segment_apart(p, a, b, dd)
            && segment_apart(p, b, c, dd)
            && segment_apart(p, c, a, dd)
    } else {
        let [a0, a1, b0, b1] = pts;
        let EdgeLines { u, v, w, w2, r } = EdgeLines::new(pts);
        // The lines' distance is |r . w| / |w|.
        if w2.pos() && excess(ring::dot(&r, &w), w2, dd).pos() {
            return true;
        }
        // Parallel or nearly parallel edges: the axis across one edge's line towards the
        // other edge, on which the first edge is one point.
        if beside(a0, &u, b0, b1, dd) || beside(b0, &v, a0, a1, dd) {
            return true;
        }
        // The lines' closest points a0 + s u, b0 + t v (times |w|^2) not both on the
        // segments: then the closest pair involves an endpoint.
        let (s, t) = lines_closest(&r, &u, &v, &w);
        let off = |x: Iv| x.neg() || w2.sub(&x).neg();
        w2.pos()
            && (off(s) || off(t))
            && segment_apart(a0, b0, b1, dd)
            && segment_apart(a1, b0, b1, dd)
            && segment_apart(b0, a0, a1, dd)
            && segment_apart(b1, a0, a1, dd)
    }
}

/// The features at `pts` certainly within `delta` of each other: the distance to one point of
/// the other feature is.
fn within(vf: bool, pts: &[V3<Iv>; 4], delta: f64) -> bool {
    let dd = square(delta);
    if vf {
        let [p, a, b, c] = pts;
        let face = ring::vf_face(p, a, b, c);
        let n2 = ring::dot(&face.n, &face.n);
        let foot_in = n2.pos() && face.d.iter().all(|&d| nonnegative(d));
        (foot_in && nonpositive(excess(face.f, n2, dd)))
            || segment_within(p, a, b, dd)
            || segment_within(p, b, c, dd)
            || segment_within(p, c, a, dd)
    } else {
        let [a0, a1, b0, b1] = pts;
        let EdgeLines { u, v, w, w2, r } = EdgeLines::new(pts);
        let (s, t) = lines_closest(&r, &u, &v, &w);
        let on = |x: Iv| nonnegative(x) && nonnegative(w2.sub(&x));
        (w2.pos() && on(s) && on(t) && nonpositive(excess(ring::dot(&r, &w), w2, dd)))
            || segment_within(a0, b0, b1, dd)
            || segment_within(a1, b0, b1, dd)
            || segment_within(b0, a0, a1, dd)
            || segment_within(b1, a0, a1, dd)
    }
}

fn square(x: f64) -> Iv {
    Iv::point(x).mul(&Iv::point(x))
}

/// `x <= 0` for every value of the interval.
#[inline(always)]
fn nonpositive(x: Iv) -> bool {
    x.hi <= 0.0
}

/// `x >= 0` for every value of the interval.
#[inline(always)]
fn nonnegative(x: Iv) -> bool {
    x.lo >= 0.0
}

/// `q^2 - dd * len2`: positive iff `|q| / sqrt(len2) > delta` (for `len2 > 0`).
#[inline(always)]
fn excess(q: Iv, len2: Iv, dd: Iv) -> Iv {
    q.mul(&q).sub(&dd.mul(&len2))
}

/// The lines of edges `[a0, a1]` and `[b0, b1]`: directions `u = a1 - a0`, `v = b1 - b0`,
/// their cross product `w` and `|w|^2`, and `r = b0 - a0`.
struct EdgeLines {
    u: V3<Iv>,
    v: V3<Iv>,
    w: V3<Iv>,
    w2: Iv,
    r: V3<Iv>,
}

impl EdgeLines {
    fn new([a0, a1, b0, b1]: &[V3<Iv>; 4]) -> Self {
        let (u, v) = (ring::sub3(a1, a0), ring::sub3(b1, b0));
        let w = ring::cross(&u, &v);
        let w2 = ring::dot(&w, &w);
        let r = ring::sub3(b0, a0);
        EdgeLines { u, v, w, w2, r }
    }
}

/// The parameters of the closest points `a0 + s u`, `b0 + t v` of two lines (`r = b0 - a0`,
/// `w = u x v`), times `|w|^2`.
fn lines_closest(r: &V3<Iv>, u: &V3<Iv>, v: &V3<Iv>, w: &V3<Iv>) -> (Iv, Iv) {
    (
        ring::dot(&ring::cross(r, v), w),
        ring::dot(&ring::cross(r, u), w),
    )
}

/// Point `p` farther than delta from the closed segment `[a, b]`: from its line, or from both
/// ends with the foot of the perpendicular off the segment.
fn segment_apart(p: &V3<Iv>, a: &V3<Iv>, b: &V3<Iv>, dd: Iv) -> bool {
    let e = ring::sub3(b, a);
    let w = ring::sub3(p, a);
    let len2 = ring::dot(&e, &e);
    let c = ring::cross(&w, &e);
    // |w x e|^2 - dd |e|^2: the line's distance against delta, times |e|^2.
    if len2.pos() && ring::dot(&c, &c).sub(&dd.mul(&len2)).pos() {
        return true;
    }
    let s = ring::dot(&w, &e);
    let foot_off = s.neg() || len2.sub(&s).neg();
    let wb = ring::sub3(p, b);
    foot_off && ring::dot(&w, &w).sub(&dd).pos() && ring::dot(&wb, &wb).sub(&dd).pos()
}

/// Point `p` within delta of the closed segment `[a, b]`: of an end, or of the foot of the
/// perpendicular when it certainly lies on the segment.
fn segment_within(p: &V3<Iv>, a: &V3<Iv>, b: &V3<Iv>, dd: Iv) -> bool {
    let w = ring::sub3(p, a);
    let wb = ring::sub3(p, b);
    if nonpositive(ring::dot(&w, &w).sub(&dd)) || nonpositive(ring::dot(&wb, &wb).sub(&dd)) {
        return true;
    }
    let e = ring::sub3(b, a);
    let len2 = ring::dot(&e, &e);
    let s = ring::dot(&w, &e);
    let c = ring::cross(&w, &e);
    len2.pos()
        && nonnegative(s)
        && nonnegative(len2.sub(&s))
        && nonpositive(ring::dot(&c, &c).sub(&dd.mul(&len2)))
}

/// Both `q0` and `q1` farther than delta, on the same side, from the line through `p` along
/// `u`, measured along `n = u x (u x (q0 - p))`, the direction in the plane of the line and
/// `q0` perpendicular to the line (the whole line projects onto one value along `n`).
fn beside(p: &V3<Iv>, u: &V3<Iv>, q0: &V3<Iv>, q1: &V3<Iv>, dd: Iv) -> bool {
    let r0 = ring::sub3(q0, p);
    let r1 = ring::sub3(q1, p);
    let n = ring::cross(u, &ring::cross(u, &r0));
    let n2 = ring::dot(&n, &n);
    let (h0, h1) = (ring::dot(&r0, &n), ring::dot(&r1, &n));
    let same_side = (h0.neg() && h1.neg()) || (h0.pos() && h1.pos());
    same_side && excess(h0, n2, dd).pos() && excess(h1, n2, dd).pos()
}
