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
//! **Search.** First the start: within at t = 0 (tested where the float distance there is
//! at most `delta (1 + 2^-21)`) means a contact at 0. Then pieces of
//! `[0, t_max]` are visited earliest first, skipped when apart and split otherwise, down to
//! width `2^-46`. Each piece is first tested the cheap way: the features' closest direction
//! at the piece's end, in plain floats, is used as a fixed separating axis over the piece
//! (`axis.rs`: the gap along a fixed axis is concave in t, so its values at the two ends
//! bound it, with no margin for the motion). A piece whose end is nearer than `delta` by
//! that float estimate holds the contact: it is split without trying the certificates that
//! could not succeed: once per query (at the first such piece whose start is farther than
//! `delta` in floats) at the float estimate `t` of the contact time (regula falsi on the
//! float distance), `2^-41` before it, so that the piece before is apart by what the
//! features close in `2^-41` and one piece of each side replaces the ~46 halvings down to
//! the contact; otherwise halved. The Lipschitz tests above come next.
//!
//! **Answer.** When every time before `lo` is apart (the piece after the estimate's split,
//! or the first leaf `[lo, hi]` that is not apart) and the distance is within `delta` at
//! one of the points `lo + k 2^-44`, `k = 1..16`, the earliest contact lies in
//! `[lo, lo + 2^-40]` and `lo` is returned (at most `2^-40` early, the exact path's
//! tolerance); after an estimate, `t - 2^-44` instead when the piece up to it is apart too
//! (the probes are tried once at the estimate's split).
//! Otherwise (the distance touches `delta` without crossing it, or crosses it too slowly
//! for floats to place within `2^-40`), the query is left to the exact path.
//!
//! **Relative corners.** Every test and estimate sees the corners relative to the first
//! one as it moves (`x_i(t) - x_0(t)`, the same distances, still moving on straight lines):
//! their rounding is a few ulps of the features' extent (each corner's distance from the
//! first), not of the coordinates. A feature a hundredth of the mesh's size approaching at a
//! few `delta` per step is then placed within `2^-40`; enclosed at the coordinates'
//! magnitude it was not, and took the exact path. The fixed-axis test (`axis.rs`) reads the
//! relative poses in plain floats too, each coordinate within `8.03 u R` of the exact one
//! (`R` the extent, [`Relative::extent`]), inside the error its bound allows at magnitude
//! `R`. What still bounds how close before a slow crossing a piece can be certified is the
//! axis itself: the float closest direction's angle error spreads each feature's
//! projection by about its length times that error, which a pair closing at a small
//! fraction of its corners' relative speed does not clear [`ESTIMATE_LEAD`] before the
//! crossing; the piece up to the estimate is then halved down to the leaves (~90 pieces,
//! most of the time of a contact step at `delta > 0` on cloth resting on a body).
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
use super::filter::Verdict;
use super::interval::Iv;
use super::pieces::{earliest_first, Piece};
use super::ring::{self, Ring, V3};

/// Bound on the pieces visited per query: where the distance stays near `delta` for a long
/// time the bisection would split many pieces; past this many the query is left to the exact
/// path (~2 us a piece).
const MAX_PIECES: u32 = 4096;

/// Width of the narrowest pieces.
const LEAF_WIDTH: f64 = 1.0 / (1u64 << 46) as f64;
/// Spacing and number of the probes after the first leaf not apart, or after the split at
/// the estimate: up to `2^-40`.
const PROBE_STEP: f64 = 1.0 / (1u64 << 44) as f64;
const PROBES: u32 = 16;

/// The corners relative to the first one as it moves, `y_i(t) = x_i(t) - x_0(t) = (x0_i -
/// x0_0) + t u_i`: every distance is the same, and the enclosures are as wide as a few
/// ulps of the features' extent instead of the coordinates' magnitude. Far from the
/// origin (a mesh of unit size, a `delta` and features a hundredth of it) that is what lets
/// a slow approach be placed within `2^-40`.
struct Relative {
    y0: [V3<Iv>; 4],
    u: [V3<Iv>; 4],
    /// The same in plain floats: for the estimates that steer the search, and the poses of
    /// the fixed-axis test ([`Relative::estimate_at`]).
    y0_float: [P3; 4],
    u_float: [P3; 4],
    /// At least every exact relative coordinate at both ends, `|x_i - x_0|` per axis at t0
    /// and at t1 (so at every time between), rounded up: the magnitude the fixed-axis test's
    /// rounding is bounded at.
    extent: f64,
}

impl Relative {
    fn new(x0: &[[f64; 3]; 4], x1: &[[f64; 3]; 4]) -> Self {
        let y0: [V3<Iv>; 4] = std::array::from_fn(|i| {
            std::array::from_fn(|k| {
                if i == 0 {
                    Iv::point(0.0)
                } else {
                    Iv::diff(x0[i][k], x0[0][k])
                }
            })
        });
        let u = std::array::from_fn(|i| {
            std::array::from_fn(|k| {
                if i == 0 {
                    Iv::point(0.0)
                } else {
                    Iv::diff(x1[i][k], x1[0][k]).sub(&y0[i][k])
                }
            })
        });
        let y0_float = std::array::from_fn(|i| std::array::from_fn(|k| x0[i][k] - x0[0][k]));
        let u_float = std::array::from_fn(|i| {
            std::array::from_fn(|k| (x1[i][k] - x1[0][k]) - (x0[i][k] - x0[0][k]))
        });
        // Each difference is correctly rounded, so within a factor `1 + 2^-53` of the exact
        // one: `1 + 2^-50` covers it.
        let largest = (1..4)
            .flat_map(|i| (0..3).map(move |k| (i, k)))
            .map(|(i, k)| y0_float[i][k].abs().max((x1[i][k] - x1[0][k]).abs()))
            .fold(0.0f64, f64::max);
        let extent = (largest * (1.0 + 4.0 * f64::EPSILON)).next_up();
        Relative {
            y0,
            u,
            y0_float,
            u_float,
            extent,
        }
    }

    /// The corners at `t` in `[0, 1]` in plain floats: the poses the estimates steer by,
    /// and those of the fixed-axis test, which relies on their bound: each coordinate within
    /// `8.03 u R` of the exact one (`u = 2^-53`, `R` the [`Relative::extent`]). The
    /// differences `A = x0_i - x0_0` and `B = x1_i - x1_0` are each within `u R`, `fl(B) -
    /// fl(A)` within `4.01 u R` of `B - A` after its own rounding, its product by `t` within
    /// `6.02 u R` of `t (B - A)`, and the sum within `7.02 u R` before its last rounding
    /// (`1.01 u R`). `axis::apart_between` allows for that at magnitude `R`.
    #[inline(always)]
    fn estimate_at(&self, t: f64) -> [P3; 4] {
        std::array::from_fn(|i| {
            std::array::from_fn(|k| self.y0_float[i][k] + t * self.u_float[i][k])
        })
    }

    /// Encloses the corners at every time of `t`.
    #[inline(always)]
    fn at(&self, t: Iv) -> [V3<Iv>; 4] {
        std::array::from_fn(|i| std::array::from_fn(|k| self.y0[i][k].add(&t.mul(&self.u[i][k]))))
    }
}

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
/// during `[0, t_max]`: `Miss`, `Hit(t)` with the earliest contact in `[t, t + 2^-40]`, or
/// `Unknown`.
pub(crate) fn decide(
    vf: bool,
    x0: &[[f64; 3]; 4],
    x1: &[[f64; 3]; 4],
    t_max: f64,
    delta: f64,
) -> Verdict {
    let relative = Relative::new(x0, x1);
    let at = |t: f64| relative.at(Iv::point(t));
    // Within at the start, tried only where the float distance is not clearly above delta.
    // A contact at 0 skipped by a float error larger than that (large features against a
    // tiny delta, nearly parallel edges) is still never missed: no piece holding 0 is
    // certified apart, so the first leaf answers `Hit(0)` or leaves it to the exact path.
    let start = ring_len2(&closest_direction(vf, &relative.estimate_at(0.0)));
    if start <= delta * delta * NEAR_START && within(vf, &at(0.0), delta) {
        return Verdict::Hit(0.0);
    }
    let speed = max_relative_speed(vf, x0, x1);
    // `[lo, hi]` certainly apart, `c` the features' closest direction at `hi` (plain
    // floats): along `c` as a fixed axis; by the Lipschitz bound from `mid`; or with the
    // corners enclosed over the whole piece, sharper where they slide past each other fast
    // at a nearly constant distance (then the speed is large and the margin wide).
    let apart_over = |lo: f64, hi: f64, c: &P3| {
        let poses = (&relative.estimate_at(lo), &relative.estimate_at(hi));
        if axis::apart_between(vf, poses, c, delta, relative.extent) {
            return true;
        }
        let mid = 0.5 * (lo + hi);
        // The largest distance from mid to an end, rounded up, times the speed.
        let reach = (mid - lo).max(hi - mid).next_up();
        let margin = (speed * reach).next_up();
        apart(vf, &at(mid), (delta + margin).next_up())
            || apart(vf, &relative.at(Iv { lo, hi }), delta)
    };
    // The float estimate of the contact time, and the end of the piece split off before it
    // (one estimate per query); `probed`: its probes were tried.
    let mut estimate: Option<(f64, f64)> = None;
    let mut probed = false;
    earliest_first(t_max, MAX_PIECES, |lo, hi, last| {
        if let (Some((t, a)), false) = (estimate, probed) {
            // Every time before `a` is apart: within at a probe after it puts the contact
            // in [a, a + 2^-40]; closer when the piece up to one probe step before the
            // estimate is apart too (the probe that was within is less than 2^-40 after
            // that). Otherwise the piece is searched as any other (its first halves start
            // at `a` too: the probes are not tried again).
            if a == lo {
                probed = true;
                if within_soon(vf, &at, lo, t_max, delta) {
                    let closer = t - PROBE_STEP;
                    let c = closest_direction(vf, &relative.estimate_at(closer));
                    let from = if closer > lo && apart_over(lo, closer, &c) {
                        closer
                    } else {
                        lo
                    };
                    return Piece::Decided(Verdict::Hit(from));
                }
            }
        }
        // The features' closest direction at the piece's end: the separating axis of a
        // piece before the contact; and, with the features nearer than delta there, the
        // sign that this piece holds the contact, so the certificates, which could not
        // succeed, are skipped: the piece is split at the float estimate of the contact
        // time (once per query), or halved.
        let c = closest_direction(vf, &relative.estimate_at(hi));
        let splittable = hi - lo > LEAF_WIDTH && !last;
        if splittable && ring_len2(&c) < delta * delta {
            if estimate.is_none() {
                if let Some(t) = crossing_estimate(vf, &relative, (lo, hi), delta) {
                    let a = t - ESTIMATE_LEAD;
                    estimate = Some((t, a));
                    return Piece::SplitAt(a);
                }
            }
            return Piece::Split;
        }
        if apart_over(lo, hi, &c) {
            return Piece::Apart;
        }
        if splittable {
            return Piece::Split;
        }
        // Everything before lo is apart: within at a probe puts the contact in
        // [lo, lo + 2^-40].
        Piece::Decided(
            if within_soon(vf, &at, lo, t_max, delta) || touches_by(vf, x0, x1, t_max, lo) {
                Verdict::Hit(lo)
            } else {
                Verdict::Unknown
            },
        )
    })
}

/// The features certainly within `delta` at one of the probes `lo + k 2^-44`, `k = 1..16`
/// (clamped to `t_max`), the latest first: past a contact the distance falls below
/// `delta` by more the later the probe, so the latest is the likeliest to certify. `at`:
/// the enclosure of the corners at a time.
fn within_soon(
    vf: bool,
    at: &impl Fn(f64) -> [V3<Iv>; 4],
    lo: f64,
    t_max: f64,
    delta: f64,
) -> bool {
    (1..=PROBES).rev().any(|k| {
        let t = (lo + k as f64 * PROBE_STEP).min(t_max);
        within(vf, &at(t), delta)
    })
}

/// How far before the estimated contact time the piece searched first ends: the probes
/// after it reach `2^-41` past the estimate, and the piece before it is apart by the
/// distance the features close in `2^-41`, well above the axis test's rounding bound for
/// all but the slowest approaches.
const ESTIMATE_LEAD: f64 = 1.0 / (1u64 << 41) as f64;

/// `1 + 2^-20`: a squared float distance at t = 0 above `delta^2` times this skips the
/// interval test for a contact at 0 (wider than the float error of features not far larger
/// than `delta`; where it is not, the contact is still found, at the first leaf).
const NEAR_START: f64 = 1.000_000_953_674_316_4;

/// Most evaluations of the distance by [`crossing_estimate`].
const ESTIMATE_STEPS: u32 = 48;

/// The last time of `[lo, hi]` at which the features' distance, computed in plain floats,
/// is still above `delta`, when it is at `lo` and below at `hi` (no guarantee: the
/// estimate only places the pieces the certificates then test). Regula falsi with the
/// Illinois halving on `|c(t)|^2 - delta^2`, `c` the closest direction, down to a bracket
/// of a few ulps of `hi`.
fn crossing_estimate(
    vf: bool,
    relative: &Relative,
    (mut lo, mut hi): (f64, f64),
    delta: f64,
) -> Option<f64> {
    let dd = delta * delta;
    let g = |t: f64| ring_len2(&closest_direction(vf, &relative.estimate_at(t))) - dd;
    let (mut g_lo, mut g_hi) = (g(lo), g(hi));
    if !(g_lo > 0.0 && g_hi <= 0.0) {
        return None;
    }
    // The side kept twice in a row has its value halved (Illinois), so the bracket shrinks
    // at both ends.
    let mut kept = 0i8;
    for _ in 0..ESTIMATE_STEPS {
        if hi - lo <= 4.0 * f64::EPSILON * hi {
            break;
        }
        let secant = hi - g_hi * (hi - lo) / (g_hi - g_lo);
        let t = if secant > lo && secant < hi {
            secant
        } else {
            0.5 * (lo + hi)
        };
        let value = g(t);
        if value > 0.0 {
            (lo, g_lo) = (t, value);
            if kept == -1 {
                g_hi *= 0.5;
            }
            kept = -1;
        } else {
            (hi, g_hi) = (t, value);
            if kept == 1 {
                g_lo *= 0.5;
            }
            kept = 1;
        }
    }
    Some(lo)
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

/// The features certainly touch (distance 0, so within any `delta`) at some time `<= by +
/// 2^-40`: the delta-0 float filter finds a contact at a time it places at most `2^-40`
/// before the true one, and no later than `by`. A `delta` too small to certify "within" in
/// floats (`5e-324` next to unit coordinates) is then decided by the contact itself; called
/// with `by` = the first piece not apart (`lo`), the earliest time within `delta` lies in
/// `[lo, lo + 2^-40]`, the module's contract.
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

#[cfg(test)]
mod tests {
    //! Slow approaches far from the origin are decided in floats, at the exact path's time:
    //! queries of a real frame step that reached the exact path while the corners were
    //! enclosed at the coordinates' magnitude, and random ones built the same way.
    use super::*;
    use crate::ccd::exact::{self, Kind};
    use crate::ccd::TOI_TOLERANCE;

    type Q = [[f64; 3]; 4];

    /// The filter's verdict is a decision, the exact path's (`Miss` for none), within the
    /// tolerance of its time.
    fn decided_as_exact(vf: bool, x0: &Q, x1: &Q, t_max: f64, delta: f64) -> Verdict {
        let verdict = decide(vf, x0, x1, t_max, delta);
        let kind = if vf { Kind::VertexFace } else { Kind::EdgeEdge };
        let exact = exact::solve(kind, x0, x1, t_max, delta, &|| false).expect("not stopped");
        let what = format!("vf {vf} delta {delta} t_max {t_max}: {x0:?} -> {x1:?}");
        match (verdict, exact) {
            (Verdict::Miss, None) => {}
            (Verdict::Hit(t), Some(e)) => {
                assert!((t - e).abs() <= TOI_TOLERANCE, "{what}: {t} vs exact {e}")
            }
            (v, e) => panic!("{what}: filter {v:?}, exact {e:?}"),
        }
        verdict
    }

    #[test]
    fn slow_approaches_of_a_real_frame_are_decided_in_floats() {
        // armadillo-rollers 326 -> 327 at min distance 1e-3, scaled to unit magnitude (as the
        // filter sees them): the distance crosses delta at about 2 delta per step.
        let cases: [(bool, f64, Q, Q); 3] = [
            (
                false,
                2e-3,
                [
                    [0.618414463888342, 0.990193255021748, 0.24726471886623],
                    [0.412274366990376, 1.082475830582516, 0.1556668167611716],
                    [0.516725481266468, 1.055608282793246, 0.1760532661702556],
                    [0.507544081271968, 1.035855010456678, 0.1989701828255146],
                ],
                [
                    [0.618414319459444, 0.98124775341931, 0.261300787881548],
                    [0.412273470324424, 1.068846034870276, 0.1652127900679392],
                    [0.393683607516584, 1.090360793156924, 0.151214894076181],
                    [0.39025670508451, 1.064779035203344, 0.1676679903703326],
                ],
            ),
            (
                false,
                2e-3,
                [
                    [0.24289080134961, 1.0576164263263, 0.16694273984902],
                    [0.217983405700336, 1.08235341026487, 0.1123143124984568],
                    [0.239724438607748, 1.086195082542274, 0.1339795230738196],
                    [0.223306300369366, 1.06032300778678, 0.134644539200551],
                ],
                [
                    [0.1146578226791426, 1.052457500932024, 0.1617257502746522],
                    [0.088922647501674, 1.04879612342285, 0.131286870971811],
                    [0.1157995885678746, 1.10670571835424, 0.1048487273593944],
                    [0.1028152455496084, 1.08655606827778, 0.113789020547906],
                ],
            ),
            (
                true,
                4e-3,
                [
                    [0.419404090990108, 1.607707679191556, 0.95917875347616],
                    [0.3883508897377236, 1.6098943862948, 0.90556578848246],
                    [0.3920529777873988, 1.623343066441316, 0.888245224295756],
                    [0.468144096882672, 1.627085217561644, 1.021063642434184],
                ],
                [
                    [0.499205258002508, 1.661709273550812, 1.053515209469012],
                    [0.448035998612544, 1.636296830757752, 1.017332260588852],
                    [0.42453075663212, 1.63997274307486, 0.983507830176852],
                    [0.546465536564676, 1.691746623376804, 1.098291825581668],
                ],
            ),
        ];
        for (vf, delta, x0, x1) in &cases {
            let verdict = decided_as_exact(*vf, x0, x1, 1.0, *delta);
            assert!(matches!(verdict, Verdict::Hit(t) if t > 0.0), "{verdict:?}");
        }
    }

    #[test]
    fn slow_random_approaches_far_from_the_origin_are_decided_in_floats() {
        // Features a ten-thousandth of the coordinates' magnitude, the second one starting
        // `2.5-4.5 delta` from the first along a random direction and closing in at a few
        // delta per step (with a slight random drift): the distance crosses delta inside
        // the step, slowly next to the coordinates' rounding.
        let mut state = 7u64;
        let mut unit =
            || (crate::shapes::splitmix64(&mut state) >> 11) as f64 / (1u64 << 53) as f64;
        let (mut hits, mut total) = (0, 0);
        for n in 0..64 {
            let vf = n % 2 == 0;
            let delta = 4e-5;
            let origin = [1.3 + 0.3 * unit(), 1.1 + 0.5 * unit(), 0.6 + 0.3 * unit()];
            let mut dir = [unit() - 0.5, unit() - 0.5, unit() - 0.5];
            let len = (dir[0] * dir[0] + dir[1] * dir[1] + dir[2] * dir[2]).sqrt();
            dir = dir.map(|d| d / len);
            let gap = (2.5 + 2.0 * unit()) * delta;
            let close = (3.0 + 2.0 * unit()) * delta;
            let split = if vf { 1 } else { 2 };
            let mut x0: Q = [[0.0; 3]; 4];
            let mut x1: Q = [[0.0; 3]; 4];
            for (i, (p, q)) in x0.iter_mut().zip(x1.iter_mut()).enumerate() {
                // The first feature around the origin (a point, or an edge across `dir`),
                // the second beyond the gap (a triangle, or an edge), both small.
                let jitter: [f64; 3] = std::array::from_fn(|_| 2e-4 * (unit() - 0.5));
                let jitter = if vf && i < split { [0.0; 3] } else { jitter };
                let along = |k: usize| {
                    // Project the jitter off `dir` so the features face each other.
                    let j: f64 = (0..3).map(|c| jitter[c] * dir[c]).sum();
                    jitter[k] - j * dir[k]
                };
                let offset = if i < split { 0.0 } else { gap };
                let drift: [f64; 3] = std::array::from_fn(|_| 1e-5 * (unit() - 0.5));
                for k in 0..3 {
                    p[k] = origin[k] + along(k) + offset * dir[k];
                    q[k] = p[k] + drift[k] - if i < split { 0.0 } else { close * dir[k] };
                }
            }
            total += 1;
            if matches!(decided_as_exact(vf, &x0, &x1, 1.0, delta), Verdict::Hit(t) if t > 0.0) {
                hits += 1;
            }
        }
        // Most come within delta inside the step (the rest never do, or start within it).
        assert!(hits * 2 > total, "{hits} of {total}");
    }

    /// Edge pairs of cloth-ball 92 -> 93 at min distance 1e-3, scaled to unit magnitude (as
    /// the filter sees them): cloth resting on the ball, the edges closing at a small
    /// fraction of their corners' relative speed, so the piece up to the estimate cannot be
    /// certified in one and is halved down to the leaves. Still decided in floats, at the
    /// exact path's time.
    #[test]
    fn slow_crossings_of_cloth_on_a_body_are_decided_at_the_exact_time() {
        let cases: [(f64, Q, Q); 3] = [
            (
                0.000125,
                [
                    [0.31500986218452454, 1.0018688440322876, 0.5700922608375549],
                    [0.31031137704849243, 0.9655402302742004, 0.5494006276130676],
                    [0.33802250027656555, 0.9691216349601746, 0.5384153723716736],
                    [0.30778101086616516, 0.9696661233901978, 0.5540878772735596],
                ],
                [
                    [0.36078113317489624, 1.005311131477356, 0.5447271466255188],
                    [0.3570365011692047, 0.9673414826393127, 0.5208415985107422],
                    [0.3827912509441376, 0.9708395004272461, 0.5041888952255249],
                    [0.3561403751373291, 0.9723827242851257, 0.5232808589935303],
                ],
            ),
            (
                0.00025,
                [
                    [1.0884745121002197, 0.9406185150146484, 0.2342892438173294],
                    [1.0868264436721802, 0.8939495086669922, 0.26079151034355164],
                    [1.0429060459136963, 0.8931862711906433, 0.27221348881721497],
                    [1.0905817747116089, 0.9065985083580017, 0.25620025396347046],
                ],
                [
                    [1.1147245168685913, 0.9471560120582581, 0.13657300174236298],
                    [1.117666482925415, 0.9008902311325073, 0.15845650434494019],
                    [1.0781562328338623, 0.893862247467041, 0.17393074929714203],
                    [1.117993950843811, 0.9086407423019409, 0.1482515037059784],
                ],
            ),
            (
                0.00025,
                [
                    [1.0666261911392212, 0.9302307367324829, 0.27342474460601807],
                    [1.0905817747116089, 0.9065985083580017, 0.25620025396347046],
                    [1.0884745121002197, 0.9406185150146484, 0.2342892438173294],
                    [1.0868264436721802, 0.8939495086669922, 0.26079151034355164],
                ],
                [
                    [1.1001527309417725, 0.9321942329406738, 0.17490075528621674],
                    [1.117993950843811, 0.9086407423019409, 0.1482515037059784],
                    [1.1147245168685913, 0.9471560120582581, 0.13657300174236298],
                    [1.117666482925415, 0.9008902311325073, 0.15845650434494019],
                ],
            ),
        ];
        for (delta, x0, x1) in &cases {
            let verdict = decided_as_exact(false, x0, x1, 1.0, *delta);
            assert!(matches!(verdict, Verdict::Hit(t) if t > 0.0), "{verdict:?}");
        }
    }
}
