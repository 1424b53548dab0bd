//! The float filter for a minimum distance `delta > 0`: decides whether the two features come
//! within `delta` during `[0, t_max]`, and when, in interval arithmetic, or says it cannot.
//!
//! The step is cut into time pieces, earliest first (depth-first bisection). On each piece the
//! positions are enclosed by intervals ([`moving`]) and the piece is classified:
//! - **apart**: the distance is certainly `> delta` at every t of the piece;
//! - **within**: certainly `<= delta` at every t of the piece;
//! - **unknown**: the piece is split, down to width `2^-44`.
//!
//! Pieces are visited in time order and the search stops at the first unknown leaf, so when a
//! piece `[lo, hi]` is found within, or the first unknown leaf `[lo, hi]` is within at one of
//! the points `lo + k 2^-44`, `k = 1..16`, every time before `lo` is certified apart: the
//! earliest contact `t*` lies in `[lo, lo + 2^-40]`, and `lo` is returned (at most `2^-40`
//! early, the exact path's tolerance). Probing past the leaf is needed because near `t*` the
//! distance differs from `delta` by less than the float noise of a piece that narrow. Where
//! no probe is within (the distance touches `delta` without crossing it, or crosses it too
//! slowly for floats to see within `2^-40`), the query is left to the exact path.
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
//!   endpoint-to-segment distances all apart do.
//!
//! A foot or a line is only used where its squared length factor is certainly `> 0`
//! (degenerate triangles and zero-length edges fall back to their corners).

use super::filter::{moving, Verdict, ROOT_WIDTH};
use super::interval::Iv;
use super::ring::{self, Ring, V3};

/// What a piece of the step certainly is.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Piece {
    Apart,
    Within,
    Unknown,
}

/// Bound on the pieces classified per query: pieces the interval arithmetic over-estimates
/// are split until they are narrow enough, which a near-tangent pair could repeat at many
/// places; past this many the query is left to the exact path.
const MAX_PIECES: u32 = 4096;

/// Width of the narrowest pieces, a sixteenth of the tolerance; [`PROBES`] points after the
/// first unknown one are probed, up to the tolerance.
const LEAF_WIDTH: f64 = ROOT_WIDTH / 16.0;
const PROBES: u32 = 16;

/// Depth bound of the bisection (a piece of `[0, 1]` narrower than `2^-44` needs 45 halvings;
/// the midpoints of float endpoints are exact or rounded between them).
const MAX_DEPTH: usize = 64;

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
    let dd = Iv::point(delta).mul(&Iv::point(delta));
    let classify = |lo: f64, hi: f64| classify(vf, &moving(x0, x1, Iv { lo, hi }), dd, delta);
    let mut stack = [(0.0f64, 0.0f64); MAX_DEPTH + 1];
    stack[0] = (0.0, t_max);
    let (mut n, mut pieces) = (1usize, 0u32);
    while n > 0 {
        n -= 1;
        let (lo, hi) = stack[n];
        pieces += 1;
        if pieces > MAX_PIECES {
            return Verdict::Unknown;
        }
        match classify(lo, hi) {
            Piece::Apart => continue,
            Piece::Within => return Verdict::Hit(lo),
            Piece::Unknown => {}
        }
        let mid = 0.5 * (lo + hi);
        if hi - lo <= LEAF_WIDTH || n + 2 > MAX_DEPTH || !(lo < mid && mid < hi) {
            // Everything before lo is apart. Near the contact the distance differs from
            // delta by less than the float noise of a piece, so within is looked for at
            // points after lo, up to the tolerance: within at one puts the contact in
            // [lo, lo + 2^-40].
            let within = (1..=PROBES).any(|k| {
                let t = (lo + k as f64 * LEAF_WIDTH).min(t_max);
                classify(t, t) == Piece::Within
            });
            return if within {
                Verdict::Hit(lo)
            } else {
                Verdict::Unknown
            };
        }
        stack[n] = (mid, hi);
        stack[n + 1] = (lo, mid);
        n += 2;
    }
    Verdict::Miss
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

fn classify(vf: bool, pts: &[V3<Iv>; 4], dd: Iv, delta: f64) -> Piece {
    if boxes_apart(vf, pts, delta) {
        return Piece::Apart;
    }
    if vf {
        vertex_face(pts, dd)
    } else {
        edge_edge(pts, dd)
    }
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

/// A point and a closed segment `[a, b]`.
struct Seg {
    apart: bool,
    within: bool,
}

fn point_segment(p: &V3<Iv>, a: &V3<Iv>, b: &V3<Iv>, dd: Iv) -> Seg {
    let e = ring::sub3(b, a);
    let w = ring::sub3(p, a);
    let len2 = ring::dot(&e, &e);
    // The foot's parameter times |e|^2, and the squared distances to the corners.
    let s = ring::dot(&w, &e);
    let to_a = ring::dot(&w, &w).sub(&dd);
    let wb = ring::sub3(p, b);
    let to_b = ring::dot(&wb, &wb).sub(&dd);
    let c = ring::cross(&w, &e);
    // |w x e|^2 - dd |e|^2: the line's distance against delta, times |e|^2.
    let line = ring::dot(&c, &c).sub(&dd.mul(&len2));
    let foot_on = len2.pos() && nonnegative(s) && nonnegative(len2.sub(&s));
    let foot_off = s.neg() || len2.sub(&s).neg();
    Seg {
        apart: (len2.pos() && line.pos()) || (to_a.pos() && to_b.pos() && foot_off),
        within: nonpositive(to_a) || nonpositive(to_b) || (foot_on && nonpositive(line)),
    }
}

fn vertex_face(pts: &[V3<Iv>; 4], dd: Iv) -> Piece {
    let [p, a, b, c] = pts;
    let face = ring::vf_face(p, a, b, c);
    let n2 = ring::dot(&face.n, &face.n);
    // f = (a - p) . n: the plane's distance is |f| / |n|.
    let plane = excess(face.f, n2, dd);
    if n2.pos() && plane.pos() {
        return Piece::Apart;
    }
    let foot_in = n2.pos() && face.d.iter().all(|&d| nonnegative(d));
    if foot_in && nonpositive(plane) {
        return Piece::Within;
    }
    let edges = [
        point_segment(p, a, b, dd),
        point_segment(p, b, c, dd),
        point_segment(p, c, a, dd),
    ];
    if edges.iter().any(|e| e.within) {
        return Piece::Within;
    }
    // The foot certainly outside, or the triangle degenerate (then it is its edges).
    let foot_out = face.d.iter().any(|d| d.neg()) || nonpositive(n2);
    if foot_out && edges.iter().all(|e| e.apart) {
        return Piece::Apart;
    }
    Piece::Unknown
}

fn edge_edge(pts: &[V3<Iv>; 4], dd: Iv) -> Piece {
    let [a0, a1, b0, b1] = pts;
    let u = ring::sub3(a1, a0);
    let v = ring::sub3(b1, b0);
    let w = ring::cross(&u, &v);
    let w2 = ring::dot(&w, &w);
    let r = ring::sub3(b0, a0);
    // The lines' distance is |r . w| / |w|.
    let lines = excess(ring::dot(&r, &w), w2, dd);
    if w2.pos() && lines.pos() {
        return Piece::Apart;
    }
    // The lines' closest points a0 + s u, b0 + t v, times |w|^2.
    let s = ring::dot(&ring::cross(&r, &v), &w);
    let t = ring::dot(&ring::cross(&r, &u), &w);
    let on = |x: Iv| nonnegative(x) && nonnegative(w2.sub(&x));
    let off = |x: Iv| x.neg() || w2.sub(&x).neg();
    if w2.pos() && on(s) && on(t) && nonpositive(lines) {
        return Piece::Within;
    }
    let ends = [
        point_segment(a0, b0, b1, dd),
        point_segment(a1, b0, b1, dd),
        point_segment(b0, a0, a1, dd),
        point_segment(b1, a0, a1, dd),
    ];
    if ends.iter().any(|e| e.within) {
        return Piece::Within;
    }
    if w2.pos() && (off(s) || off(t)) && ends.iter().all(|e| e.apart) {
        return Piece::Apart;
    }
    Piece::Unknown
}
