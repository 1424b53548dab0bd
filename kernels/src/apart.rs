//! Feature pairs certainly farther apart than a distance: batch filters in `f64` in front of
//! an exact distance decision, for segment pairs ([`segments_apart_with`]) and point-triangle
//! pairs ([`point_triangles_apart_with`]). A pair a filter marks is farther than `d`, for
//! every input; a pair it leaves unmarked may be either, and the caller decides it exactly.
//!
//! **The certificate.** For closed convex sets `A`, `B` and any nonzero direction `w`, the
//! gap `g = min_{a in A} a.w - max_{b in B} b.w` bounds their distance: `dist(A, B) >= g /
//! |w|`. For segments and triangles the extremes are at corners, so with every point taken
//! relative to one corner `o` of `B` (three differences `x_i = c_i - o` of the other
//! corners, rounded once each), `g` is a `min` over `A`'s corners minus a `max` over `B`'s
//! (`o` projecting to `0`):
//!
//! - segments `[a0, a1]`, `[b0, b1]`, `o = b0`: `g = min(r.w, s.w) - max(0, v.w)` with
//!   `r = a0 - b0`, `s = a1 - b0`, `v = b1 - b0`;
//! - a point `p` and a triangle `[t0, t1, t2]`, `o = t0`: `g = r.w - max(0, e0.w, e1.w)` with
//!   `r = p - t0`, `e0 = t1 - t0`, `e1 = t2 - t0`;
//!
//! and `g > d |w|`, i.e. `g > 0` and `g^2 > d^2 (w.w)`, proves the pair farther than `d`.
//!
//! Any `w` gives a valid certificate, so `w` needs no care: it is the direction between the
//! closest points as the usual clamped formulas give them in floats (Ericson, *Real-Time
//! Collision Detection*, 5.1.9 for segments; for a triangle, the projection into its plane
//! when inside, else the nearest of the three edges), which makes `g / |w|` the distance up to
//! rounding for every pair not within rounding of `d`. A parallel or degenerate pair may give
//! a poor or non-finite `w`: ordered comparisons make a NaN certify nothing.
//!
//! **The error bound.** The three differences are rounded once each (relative error
//! `eps = 2^-53`), and each projection is a three-term dot product (error `gamma_3`), so each
//! of the three computed projections is within `4.01 eps m |w|_1` of the exact one, `m` the
//! largest computed component of the differences; `min`, `max` are exact, and the final
//! difference adds `eps |g|`, with `|g| <= 2 m |w|_1`. So the exact gap is at least
//! `g~ - 10.1 eps m |w|_1`; the filter subtracts `E = 12 eps m |w|_1` (its own rounding
//! covered by the margin) and certifies `L = g~ - E` when `L > 0` and
//! `L^2 > (d^2 (w.w)) (1 + 16 eps)`, which covers the rounding of both sides (`L^2` within
//! `3.01 eps`, `d^2 (w.w)` within `6.02 eps`).
//!
//! The bounds are relative, so they hold only without underflow or overflow: the filter
//! certifies nothing when `m` is outside `[2^-200, 2^200]`, `w.w < 2^-500`, or `d` (`> 0`) is
//! outside `[2^-200, 2^200]`. Within those ranges every rounded product stays normal or its
//! absolute error (`2^-1074`) is far inside the margin, and nothing overflows. `d = 0`
//! certifies `L > 0` alone (`L^2 > 0`).
//!
//! The kernels use no fused multiply-add, so they give the same bits on every pulp backend as
//! [`crate::reference::segments_apart_scalar`] and
//! [`crate::reference::point_triangles_apart_scalar`] on finite input whose directions are
//! finite (a NaN in a clamp may resolve differently by backend: a different, equally sound,
//! direction).

use pulp::Simd;

use crate::lanes::mask_bits_f64;
use crate::narrow::low_bits;

/// The largest batch: one bit of the result per pair.
pub const MAX_PAIRS: usize = 64;

/// Twelve rows of [`MAX_PAIRS`] coordinates: row `3 i + k` holds coordinate `k` of point `i`
/// of each pair.
pub type PointRows = [[f64; MAX_PAIRS]; 12];

/// Up to [`MAX_PAIRS`] feature pairs of four points each as twelve rows of coordinates: rows
/// `3 i + k` hold coordinate `k` of point `i`. Segment pairs are `[a0, a1, b0, b1]`,
/// point-triangle pairs `[p, t0, t1, t2]`.
#[derive(Clone, Debug)]
pub struct FourPoints {
    /// The coordinate rows.
    pub rows: PointRows,
}

impl Default for FourPoints {
    fn default() -> Self {
        Self {
            rows: [[0.0; MAX_PAIRS]; 12],
        }
    }
}

impl FourPoints {
    /// Stores pair `i`.
    #[inline(always)]
    pub fn set(&mut self, i: usize, points: [[f64; 3]; 4]) {
        for (e, p) in points.iter().enumerate() {
            for k in 0..3 {
                self.rows[3 * e + k][i] = p[k];
            }
        }
    }

    /// Pair `i`.
    pub fn get(&self, i: usize) -> [[f64; 3]; 4] {
        std::array::from_fn(|e| std::array::from_fn(|k| self.rows[3 * e + k][i]))
    }
}

/// `12 eps`: the gap's error per unit of `m |w|_1`.
pub(crate) const GAP_ERROR: f64 = 12.0 * (f64::EPSILON / 2.0);
/// `1 + 16 eps`: the margin on `d^2 (w.w)`.
pub(crate) const SQUARE_MARGIN: f64 = 1.0 + 16.0 * (f64::EPSILON / 2.0);
/// The range of `m` (and of a positive `d`) the bound holds in: `[2^-200, 2^200]`.
pub(crate) const SCALE_LOW: f64 = power_of_two(-200);
pub(crate) const SCALE_HIGH: f64 = power_of_two(200);
/// The least `w.w` the bound holds for, `2^-500`.
pub(crate) const DIRECTION_LOW: f64 = power_of_two(-500);

/// `2^e` for a normal power.
const fn power_of_two(e: i32) -> f64 {
    f64::from_bits(((1023 + e) as u64) << 52)
}

/// Whether the filter can certify anything at distance `d`.
#[inline(always)]
pub(crate) fn distance_in_range(d: f64) -> bool {
    d == 0.0 || (SCALE_LOW..=SCALE_HIGH).contains(&d)
}

/// The bits of the first `n` segment pairs of `pairs` (`n <= MAX_PAIRS`) that are certainly
/// farther apart than `d` (bit `i` for pair `i`); `0` for a `d` out of range (module doc).
#[inline(always)]
pub fn segments_apart_with<S: Simd>(simd: S, pairs: &FourPoints, n: usize, d: f64) -> u64 {
    apart_with::<S, Segments>(simd, pairs, n, d)
}

/// The bits of the first `n` point-triangle pairs of `pairs` (`n <= MAX_PAIRS`) that are
/// certainly farther apart than `d`; `0` for a `d` out of range (module doc).
#[inline(always)]
pub fn point_triangles_apart_with<S: Simd>(simd: S, pairs: &FourPoints, n: usize, d: f64) -> u64 {
    apart_with::<S, PointTriangles>(simd, pairs, n, d)
}

/// A kind of feature pair: the verdicts of one lane group, lanes `base..base + F64_LANES`.
// PERF: a trait, not a closure or `fn` pointer: those may be compiled without the backend's
// target features (every SIMD operation then a call).
trait Pairs {
    fn lanes<S: Simd>(simd: S, c: &Constants<S::f64s>, pairs: &PointRows, base: usize) -> S::m64s;
}

/// Segment pairs `[a0, a1, b0, b1]`.
struct Segments;

impl Pairs for Segments {
    #[inline(always)]
    fn lanes<S: Simd>(simd: S, c: &Constants<S::f64s>, pairs: &PointRows, base: usize) -> S::m64s {
        segments_apart_lanes(simd, c, pairs, base)
    }
}

/// Point-triangle pairs `[p, t0, t1, t2]`.
struct PointTriangles;

impl Pairs for PointTriangles {
    #[inline(always)]
    fn lanes<S: Simd>(simd: S, c: &Constants<S::f64s>, pairs: &PointRows, base: usize) -> S::m64s {
        point_triangles_apart_lanes(simd, c, pairs, base)
    }
}

/// The batch loop of both filters.
#[inline(always)]
fn apart_with<S: Simd, P: Pairs>(simd: S, pairs: &FourPoints, n: usize, d: f64) -> u64 {
    assert!(n <= MAX_PAIRS, "at most MAX_PAIRS pairs");
    if !distance_in_range(d) {
        return 0;
    }
    let c = Constants::new(simd, d * d);
    let mut bits = 0u64;
    let mut base = 0;
    while base < n {
        let hit = P::lanes(simd, &c, &pairs.rows, base);
        bits |= (u64::from(mask_bits_f64(simd, hit)) & low_bits(n - base)) << base;
        base += S::F64_LANES;
    }
    bits
}

/// The splatted constants of one batch (`dd`: the distance's square, per lane).
#[derive(Clone, Copy)]
struct Constants<V> {
    zero: V,
    one: V,
    dd: V,
    gap_error: V,
    margin: V,
    low: V,
    high: V,
    direction_low: V,
}

impl<V: Copy> Constants<V> {
    #[inline(always)]
    fn new<S: Simd<f64s = V>>(simd: S, dd: f64) -> Self {
        Constants {
            zero: simd.splat_f64s(0.0),
            one: simd.splat_f64s(1.0),
            dd: simd.splat_f64s(dd),
            gap_error: simd.splat_f64s(GAP_ERROR),
            margin: simd.splat_f64s(SQUARE_MARGIN),
            low: simd.splat_f64s(SCALE_LOW),
            high: simd.splat_f64s(SCALE_HIGH),
            direction_low: simd.splat_f64s(DIRECTION_LOW),
        }
    }
}

/// Lanes `base..base + F64_LANES` of row `k`.
#[inline(always)]
fn row<S: Simd>(pairs: &PointRows, k: usize, base: usize) -> S::f64s {
    let (head, _) = S::as_simd_f64s(&pairs[k][base..base + S::F64_LANES]);
    head[0]
}

/// The four points of the pairs in lanes `base..`.
#[inline(always)]
fn points<S: Simd>(pairs: &PointRows, base: usize) -> [[S::f64s; 3]; 4] {
    [
        point::<S>(pairs, 0, base),
        point::<S>(pairs, 1, base),
        point::<S>(pairs, 2, base),
        point::<S>(pairs, 3, base),
    ]
}

/// Point `e` (0..4) of the pairs in lanes `base..`.
#[inline(always)]
fn point<S: Simd>(pairs: &PointRows, e: usize, base: usize) -> [S::f64s; 3] {
    [
        row::<S>(pairs, 3 * e, base),
        row::<S>(pairs, 3 * e + 1, base),
        row::<S>(pairs, 3 * e + 2, base),
    ]
}

#[inline(always)]
fn sub3<S: Simd>(simd: S, x: &[S::f64s; 3], y: &[S::f64s; 3]) -> [S::f64s; 3] {
    [
        simd.sub_f64s(x[0], y[0]),
        simd.sub_f64s(x[1], y[1]),
        simd.sub_f64s(x[2], y[2]),
    ]
}

/// `(x0 y0 + x1 y1) + x2 y2`.
#[inline(always)]
fn dot3<S: Simd>(simd: S, x: &[S::f64s; 3], y: &[S::f64s; 3]) -> S::f64s {
    simd.add_f64s(
        simd.add_f64s(simd.mul_f64s(x[0], y[0]), simd.mul_f64s(x[1], y[1])),
        simd.mul_f64s(x[2], y[2]),
    )
}

/// `x` clamped to `[0, 1]` (a NaN becomes one of the bounds or stays NaN: either is fine,
/// any direction certifies soundly).
#[inline(always)]
fn unit<S: Simd>(simd: S, c: &Constants<S::f64s>, x: S::f64s) -> S::f64s {
    simd.min_f64s(simd.max_f64s(x, c.zero), c.one)
}

/// The verdicts of segment pairs `[a0, a1, b0, b1]` in lanes `base..base + F64_LANES`.
#[inline(always)]
fn segments_apart_lanes<S: Simd>(
    simd: S,
    c: &Constants<S::f64s>,
    pairs: &PointRows,
    base: usize,
) -> S::m64s {
    let [a0, a1, b0, b1] = points::<S>(pairs, base);
    // The certified part reads r, s, v (module doc); u only steers the direction.
    let r = sub3(simd, &a0, &b0);
    let s = sub3(simd, &a1, &b0);
    let v = sub3(simd, &b1, &b0);
    let u = sub3(simd, &a1, &a0);
    // The closest parameters: a0 + p u against b0 + q v.
    let (uu, vv, uv) = (dot3(simd, &u, &u), dot3(simd, &v, &v), dot3(simd, &u, &v));
    let (ru, rv) = (dot3(simd, &r, &u), dot3(simd, &r, &v));
    let den = simd.sub_f64s(simd.mul_f64s(uu, vv), simd.mul_f64s(uv, uv));
    let p = unit(
        simd,
        c,
        simd.div_f64s(
            simd.sub_f64s(simd.mul_f64s(uv, rv), simd.mul_f64s(ru, vv)),
            den,
        ),
    );
    let q = unit(
        simd,
        c,
        simd.div_f64s(simd.add_f64s(simd.mul_f64s(uv, p), rv), vv),
    );
    let p = unit(
        simd,
        c,
        simd.div_f64s(simd.sub_f64s(simd.mul_f64s(uv, q), ru), uu),
    );
    // w = (r + p u) - q v, from the closest point of b to that of a.
    let w = along(
        simd,
        &[
            simd.add_f64s(r[0], simd.mul_f64s(p, u[0])),
            simd.add_f64s(r[1], simd.mul_f64s(p, u[1])),
            simd.add_f64s(r[2], simd.mul_f64s(p, u[2])),
        ],
        q,
        &v,
    );
    let (pr, ps, pv) = (dot3(simd, &r, &w), dot3(simd, &s, &w), dot3(simd, &v, &w));
    let gap = simd.sub_f64s(simd.min_f64s(pr, ps), simd.max_f64s(c.zero, pv));
    certified(simd, c, gap, [&r, &s, &v], &w)
}

/// The verdicts of point-triangle pairs `[p, t0, t1, t2]` in lanes `base..base + F64_LANES`.
#[inline(always)]
fn point_triangles_apart_lanes<S: Simd>(
    simd: S,
    c: &Constants<S::f64s>,
    pairs: &PointRows,
    base: usize,
) -> S::m64s {
    let [p, t0, t1, t2] = points::<S>(pairs, base);
    // The certified part reads r, e0, e1 (module doc); f only steers the direction.
    let r = sub3(simd, &p, &t0);
    let e0 = sub3(simd, &t1, &t0);
    let e1 = sub3(simd, &t2, &t0);
    let f = sub3(simd, &t2, &t1);
    let rf = sub3(simd, &p, &t1);
    let (d00, d01, d11) = (
        dot3(simd, &e0, &e0),
        dot3(simd, &e0, &e1),
        dot3(simd, &e1, &e1),
    );
    let (d20, d21) = (dot3(simd, &r, &e0), dot3(simd, &r, &e1));
    // The foot in the plane, in barycentric coordinates (beta on e0, gamma on e1).
    let den = simd.sub_f64s(simd.mul_f64s(d00, d11), simd.mul_f64s(d01, d01));
    let beta = simd.div_f64s(
        simd.sub_f64s(simd.mul_f64s(d11, d20), simd.mul_f64s(d01, d21)),
        den,
    );
    let gamma = simd.div_f64s(
        simd.sub_f64s(simd.mul_f64s(d00, d21), simd.mul_f64s(d01, d20)),
        den,
    );
    let inside = simd.and_m64s(
        simd.and_m64s(
            simd.greater_than_or_equal_f64s(beta, c.zero),
            simd.greater_than_or_equal_f64s(gamma, c.zero),
        ),
        simd.less_than_or_equal_f64s(simd.add_f64s(beta, gamma), c.one),
    );
    let w_in = along2(simd, &r, beta, &e0, gamma, &e1);
    // Else the nearest point of the three edges.
    let w0 = along(simd, &r, unit(simd, c, simd.div_f64s(d20, d00)), &e0);
    let w1 = along(simd, &r, unit(simd, c, simd.div_f64s(d21, d11)), &e1);
    let w2 = along(
        simd,
        &rf,
        unit(
            simd,
            c,
            simd.div_f64s(dot3(simd, &rf, &f), dot3(simd, &f, &f)),
        ),
        &f,
    );
    let (n0, n1, n2) = (
        dot3(simd, &w0, &w0),
        dot3(simd, &w1, &w1),
        dot3(simd, &w2, &w2),
    );
    let first = simd.less_than_or_equal_f64s(n0, n1);
    let w01 = select3(simd, first, &w0, &w1);
    let n01 = simd.select_f64s(first, n0, n1);
    let w_out = select3(simd, simd.less_than_or_equal_f64s(n01, n2), &w01, &w2);
    let w = select3(simd, inside, &w_in, &w_out);
    let pr = dot3(simd, &r, &w);
    let (p0, p1) = (dot3(simd, &e0, &w), dot3(simd, &e1, &w));
    let gap = simd.sub_f64s(pr, simd.max_f64s(simd.max_f64s(c.zero, p0), p1));
    certified(simd, c, gap, [&r, &e0, &e1], &w)
}

/// `r - t e`.
#[inline(always)]
fn along<S: Simd>(simd: S, r: &[S::f64s; 3], t: S::f64s, e: &[S::f64s; 3]) -> [S::f64s; 3] {
    [
        simd.sub_f64s(r[0], simd.mul_f64s(t, e[0])),
        simd.sub_f64s(r[1], simd.mul_f64s(t, e[1])),
        simd.sub_f64s(r[2], simd.mul_f64s(t, e[2])),
    ]
}

/// `(r - b e) - g f`.
#[inline(always)]
fn along2<S: Simd>(
    simd: S,
    r: &[S::f64s; 3],
    b: S::f64s,
    e: &[S::f64s; 3],
    g: S::f64s,
    f: &[S::f64s; 3],
) -> [S::f64s; 3] {
    along(simd, &along(simd, r, b, e), g, f)
}

/// `x` where `m`, else `y`, per lane.
#[inline(always)]
fn select3<S: Simd>(simd: S, m: S::m64s, x: &[S::f64s; 3], y: &[S::f64s; 3]) -> [S::f64s; 3] {
    [
        simd.select_f64s(m, x[0], y[0]),
        simd.select_f64s(m, x[1], y[1]),
        simd.select_f64s(m, x[2], y[2]),
    ]
}

/// The certificate of the module doc: `gap` (computed from the differences `x`, each rounded
/// once from the input) exceeds `d |w|` beyond its error bound, in the ranges the bound holds.
#[inline(always)]
fn certified<S: Simd>(
    simd: S,
    c: &Constants<S::f64s>,
    gap: S::f64s,
    x: [&[S::f64s; 3]; 3],
    w: &[S::f64s; 3],
) -> S::m64s {
    let mut m = simd.abs_f64s(x[0][0]);
    for v in x {
        for k in 0..3 {
            m = simd.max_f64s(m, simd.abs_f64s(v[k]));
        }
    }
    let w1 = simd.add_f64s(
        simd.add_f64s(simd.abs_f64s(w[0]), simd.abs_f64s(w[1])),
        simd.abs_f64s(w[2]),
    );
    let lower = simd.sub_f64s(gap, simd.mul_f64s(c.gap_error, simd.mul_f64s(m, w1)));
    let ww = dot3(simd, w, w);
    let mut ok = simd.greater_than_f64s(lower, c.zero);
    ok = simd.and_m64s(
        ok,
        simd.greater_than_f64s(
            simd.mul_f64s(lower, lower),
            simd.mul_f64s(simd.mul_f64s(c.dd, ww), c.margin),
        ),
    );
    ok = simd.and_m64s(ok, simd.greater_than_or_equal_f64s(ww, c.direction_low));
    ok = simd.and_m64s(ok, simd.greater_than_or_equal_f64s(m, c.low));
    simd.and_m64s(ok, simd.less_than_or_equal_f64s(m, c.high))
}

// ---------------------------------------------------------------------------------------
// Moving pairs: separation along the centroids' line over a time interval.

/// Up to [`MAX_PAIRS`] moving feature pairs: the four points of each at two poses (CCD's
/// layout: `[v, t0, t1, t2]` or `[a0, a1, b0, b1]`), as 24 rows: row `12 j + 3 i + k` holds
/// coordinate `k` of point `i` at pose `j`.
#[derive(Clone, Debug)]
pub struct MovingPoints {
    /// The coordinate rows.
    pub rows: [[f64; MAX_PAIRS]; 24],
}

impl Default for MovingPoints {
    fn default() -> Self {
        Self {
            rows: [[0.0; MAX_PAIRS]; 24],
        }
    }
}

impl MovingPoints {
    /// Stores pair `i` at its two poses.
    #[inline(always)]
    pub fn set(&mut self, i: usize, x0: &[[f64; 3]; 4], x1: &[[f64; 3]; 4]) {
        for (j, x) in [x0, x1].into_iter().enumerate() {
            for (e, p) in x.iter().enumerate() {
                for k in 0..3 {
                    self.rows[12 * j + 3 * e + k][i] = p[k];
                }
            }
        }
    }

    /// Pair `i` at its two poses.
    #[inline(always)]
    pub fn get(&self, i: usize) -> ([[f64; 3]; 4], [[f64; 3]; 4]) {
        let pose = |j: usize| {
            std::array::from_fn(|e| std::array::from_fn(|k| self.rows[12 * j + 3 * e + k][i]))
        };
        (pose(0), pose(1))
    }
}

/// `2^-48`: the relative part of a fixed-axis gap's error bound (per unit of `M |c|_1`).
pub(crate) const AXIS_REL: f64 = power_of_two(-48);
/// `2^-1000`: its absolute part.
pub(crate) const AXIS_ABS: f64 = power_of_two(-1000);
/// The magnitudes (`M`, and axes' 1-norms) the bound holds for: `[2^-400, 2^400]`.
pub(crate) const AXIS_LOW: f64 = power_of_two(-400);
pub(crate) const AXIS_HIGH: f64 = power_of_two(400);
/// `1 + 2^-46`: raises `|c|` computed from its rounded square (and the products and sums
/// that follow) above the exact `|c|`.
pub(crate) const LENGTH_UP: f64 = 1.0 + power_of_two(-46);

/// Whether the moving filter can certify anything for these inputs (the ranges of
/// [`centroids_apart_with`]).
#[inline(always)]
pub(crate) fn moving_in_range(delta: f64, m: f64, t_end: f64) -> bool {
    (AXIS_LOW..=AXIS_HIGH).contains(&m)
        && delta.is_finite()
        && delta >= 0.0
        && t_end > 0.0
        && t_end <= 1.0
}

/// The bits of the first `n` moving pairs of `pairs` (`n <= MAX_PAIRS`; `vertex_face`: each
/// is a vertex and a triangle, else two edges) certainly farther than `delta` apart at every
/// time of `[0, t_end]` (`t_end` in `(0, 1]`; the pose at `t_end` interpolated as
/// `x0 + t_end (x1 - x0)` when below 1), by separation along the line between the features'
/// centroids at pose 0. `m` is at least every coordinate's magnitude at both poses.
///
/// Along a fixed direction `c` the gap between two linearly moving features is concave in
/// `t`, so gaps above `delta |c|` at both ends hold over the interval. This is the first
/// axis of `dhcd`'s CCD cull (`src/ccd/axis.rs`, which derives the error bound): a computed
/// gap is within `18.1 u M |c|_1 + 2^-1070` of the exact one (`u = 2^-53`), interpolated
/// poses included; the kernel certifies a gap above `delta (|c| (1 + 2^-46)) + 2^-48 M |c|_1 +
/// 2^-1000`, whose margins (`2^-48 = 32 u` against `18.1 u`, `2^-46` against about `6 u`)
/// cover the rounding of the bound itself. Nothing is certified when `m` or `|c|_1` is
/// outside `[2^-400, 2^400]`, `delta` is not finite and `>= 0`, or `t_end` is outside
/// `(0, 1]`.
#[inline(always)]
pub fn centroids_apart_with<S: Simd>(
    simd: S,
    pairs: &MovingPoints,
    n: usize,
    vertex_face: bool,
    delta: f64,
    m: f64,
    t_end: f64,
) -> u64 {
    assert!(n <= MAX_PAIRS, "at most MAX_PAIRS pairs");
    if !moving_in_range(delta, m, t_end) {
        return 0;
    }
    let c = AxisConstants {
        error: simd.splat_f64s(AXIS_REL * m),
        abs: simd.splat_f64s(AXIS_ABS),
        low: simd.splat_f64s(AXIS_LOW),
        high: simd.splat_f64s(AXIS_HIGH),
        delta: simd.splat_f64s(delta),
        length_up: simd.splat_f64s(LENGTH_UP),
        t: simd.splat_f64s(t_end),
        third: simd.splat_f64s(1.0 / 3.0),
        half: simd.splat_f64s(0.5),
    };
    let mut bits = 0u64;
    let mut base = 0;
    while base < n {
        let hit = if vertex_face {
            moving_lanes::<S, true>(simd, &c, pairs, base, t_end < 1.0, delta > 0.0)
        } else {
            moving_lanes::<S, false>(simd, &c, pairs, base, t_end < 1.0, delta > 0.0)
        };
        bits |= (u64::from(mask_bits_f64(simd, hit)) & low_bits(n - base)) << base;
        base += S::F64_LANES;
    }
    bits
}

/// The splatted constants of one moving batch (`error` is `2^-48 M`).
struct AxisConstants<V> {
    error: V,
    abs: V,
    low: V,
    high: V,
    delta: V,
    length_up: V,
    t: V,
    third: V,
    half: V,
}

/// Point `e` of pose `j` of the moving pairs in lanes `base..`.
#[inline(always)]
fn moving_point<S: Simd>(pairs: &MovingPoints, j: usize, e: usize, base: usize) -> [S::f64s; 3] {
    let rows = &pairs.rows[12 * j + 3 * e..12 * j + 3 * e + 3];
    [
        S::as_simd_f64s(&rows[0][base..base + S::F64_LANES]).0[0],
        S::as_simd_f64s(&rows[1][base..base + S::F64_LANES]).0[0],
        S::as_simd_f64s(&rows[2][base..base + S::F64_LANES]).0[0],
    ]
}

/// The gaps along `c` at the points `x`: the second feature (points `split..4`) above the
/// first, and below it.
#[inline(always)]
fn gaps_lanes<S: Simd, const VF: bool>(
    simd: S,
    x: &[[S::f64s; 3]; 4],
    c: &[S::f64s; 3],
) -> (S::f64s, S::f64s) {
    let p = [
        dot3(simd, &x[0], c),
        dot3(simd, &x[1], c),
        dot3(simd, &x[2], c),
        dot3(simd, &x[3], c),
    ];
    let (a_lo, a_hi, b_lo, b_hi) = if VF {
        (
            p[0],
            p[0],
            simd.min_f64s(simd.min_f64s(p[1], p[2]), p[3]),
            simd.max_f64s(simd.max_f64s(p[1], p[2]), p[3]),
        )
    } else {
        (
            simd.min_f64s(p[0], p[1]),
            simd.max_f64s(p[0], p[1]),
            simd.min_f64s(p[2], p[3]),
            simd.max_f64s(p[2], p[3]),
        )
    };
    (simd.sub_f64s(b_lo, a_hi), simd.sub_f64s(a_lo, b_hi))
}

/// The verdicts of the moving pairs in lanes `base..base + F64_LANES` (`VF`: vertex-face).
#[inline(always)]
fn moving_lanes<S: Simd, const VF: bool>(
    simd: S,
    c: &AxisConstants<S::f64s>,
    pairs: &MovingPoints,
    base: usize,
    interpolate: bool,
    with_delta: bool,
) -> S::m64s {
    let x0 = [
        moving_point::<S>(pairs, 0, 0, base),
        moving_point::<S>(pairs, 0, 1, base),
        moving_point::<S>(pairs, 0, 2, base),
        moving_point::<S>(pairs, 0, 3, base),
    ];
    let mut x1 = [
        moving_point::<S>(pairs, 1, 0, base),
        moving_point::<S>(pairs, 1, 1, base),
        moving_point::<S>(pairs, 1, 2, base),
        moving_point::<S>(pairs, 1, 3, base),
    ];
    if interpolate {
        // x0 + t (x1 - x0), as the scalar cull interpolates.
        for (e, p) in x1.iter_mut().enumerate() {
            for k in 0..3 {
                p[k] = simd.add_f64s(x0[e][k], simd.mul_f64s(c.t, simd.sub_f64s(p[k], x0[e][k])));
            }
        }
    }
    // The centroids' line at pose 0 (any direction is a valid axis).
    let mut axis = [x0[0][0], x0[0][1], x0[0][2]];
    for k in 0..3 {
        axis[k] = if VF {
            simd.sub_f64s(
                simd.mul_f64s(
                    simd.add_f64s(simd.add_f64s(x0[1][k], x0[2][k]), x0[3][k]),
                    c.third,
                ),
                x0[0][k],
            )
        } else {
            simd.mul_f64s(
                simd.sub_f64s(
                    simd.add_f64s(x0[2][k], x0[3][k]),
                    simd.add_f64s(x0[0][k], x0[1][k]),
                ),
                c.half,
            )
        };
    }
    let norm1 = simd.add_f64s(
        simd.add_f64s(simd.abs_f64s(axis[0]), simd.abs_f64s(axis[1])),
        simd.abs_f64s(axis[2]),
    );
    let mut bound = simd.add_f64s(simd.mul_f64s(c.error, norm1), c.abs);
    if with_delta {
        let length = simd.mul_f64s(simd.sqrt_f64s(dot3(simd, &axis, &axis)), c.length_up);
        bound = simd.add_f64s(simd.mul_f64s(c.delta, length), bound);
    }
    let (up0, down0) = gaps_lanes::<S, VF>(simd, &x0, &axis);
    let (up1, down1) = gaps_lanes::<S, VF>(simd, &x1, &axis);
    let up = simd.and_m64s(
        simd.greater_than_f64s(up0, bound),
        simd.greater_than_f64s(up1, bound),
    );
    let down = simd.and_m64s(
        simd.greater_than_f64s(down0, bound),
        simd.greater_than_f64s(down1, bound),
    );
    let in_range = simd.and_m64s(
        simd.greater_than_or_equal_f64s(norm1, c.low),
        simd.less_than_or_equal_f64s(norm1, c.high),
    );
    simd.and_m64s(in_range, simd.or_m64s(up, down))
}

// ---------------------------------------------------------------------------------------
// Moving pairs: apart at pose 0 by more than their relative motion can close.

/// `2^-46`: the absolute part of the motion bound, per unit of `M`.
pub(crate) const MOTION_ABS: f64 = power_of_two(-46);

/// The bits of the first `n` moving pairs of `pairs` (`n <= MAX_PAIRS`; `vertex_face`: each
/// is a vertex and a triangle, else two edges) farther apart at pose 0 than `delta` plus
/// `closing` times the most their relative motion can close by `t_end` (`t_end` in `(0, 1]`,
/// `closing >= 1`). With `closing = 1` such a pair stays farther than `delta` apart at every
/// time of `[0, t_end]`; with `closing = 1 / s` it cannot come within the step-size rule's
/// gap `delta + (1 - s)(d0 - delta)` by `t_end` (`d0 - A t > gap` iff `d0 > delta + A t / s`).
/// `m` is at least every coordinate's magnitude at both poses.
///
/// **The motion bound.** Translating both features by a common motion changes no distance.
/// Take the motion of the pair's first point `o` (the vertex, or `a0`): relative to it,
/// point `i` moves by `t D_i` at time `t`, `D_i = (x1_i - x1_o) - (x0_i - x0_o)`, and every
/// point of a feature, a convex combination of its corners, by at most `t` times the largest
/// `|D_i|` of its corners. So the distance at `t` is at least the distance at pose 0 minus
/// `t A`, `A = max_i |D_i|` over the triangle's corners (vertex-face), or `|D_a1| + max(|D_b0|,
/// |D_b1|)` (edge-edge). This is the separation-at-`t0` bound of additive CCD (Li et al.
/// 2021) used as a cull: it ends the neighbours of a sheet that slides or bends a little,
/// which no fixed axis separates over the step.
///
/// **Rounding** (`u = 2^-53`). Each `D_i` component is two differences of coordinates and
/// their difference: within `8 u M` of the exact one, so `|D_i|` is within `14 u M` of the
/// norm of the computed vector; its computed norm (three squares, two sums, a square root)
/// is within `2.6 u` of that norm, plus `2^-535` for squares that underflow. So `A <= s (1 +
/// 3.7 u) + 28 u M + 2^-534`, `s` the computed sum or maximum. The kernel takes `A' = s (1 +
/// 2^-46) + 2^-46 M` (each rounding at most `u`: `A' >= s (1 + 125 u) + 127 u M`, and `M >=
/// 2^-400` puts `99 u M` far above `2^-534`), `d = (delta + ((A' t_end) closing)(1 +
/// 2^-46))(1 + 2^-46)` (at least `delta + A t_end closing`: five roundings against the
/// margins), and certifies the pair when the static certificate of the module doc proves it
/// farther than `d` at pose 0. A `d` outside `[2^-200, 2^200]` certifies nothing; nor do the
/// ranges of [`centroids_apart_with`] (`m` in `[2^-400, 2^400]`, `delta` finite and `>= 0`,
/// `t_end` in `(0, 1]`), nor a `closing` not finite or below 1. A product that underflows
/// loses at most `2^-1074`, covered by the margin on a `d >= 2^-200`.
#[inline(always)]
#[allow(clippy::too_many_arguments)]
pub fn apart_beyond_motion_with<S: Simd>(
    simd: S,
    pairs: &MovingPoints,
    n: usize,
    vertex_face: bool,
    delta: f64,
    closing: f64,
    m: f64,
    t_end: f64,
) -> u64 {
    assert!(n <= MAX_PAIRS, "at most MAX_PAIRS pairs");
    if !motion_in_range(delta, closing, m, t_end) {
        return 0;
    }
    let start: &PointRows = pairs.rows[..12].try_into().expect("twelve rows of pose 0");
    let c = Constants::new(simd, 0.0);
    let motion = MotionConstants {
        up: simd.splat_f64s(LENGTH_UP),
        slack: simd.splat_f64s(MOTION_ABS * m),
        t: simd.splat_f64s(t_end),
        closing: simd.splat_f64s(closing),
        delta: simd.splat_f64s(delta),
    };
    let mut bits = 0u64;
    let mut base = 0;
    while base < n {
        let d = if vertex_face {
            motion_distance_lanes::<S, true>(simd, &motion, pairs, base)
        } else {
            motion_distance_lanes::<S, false>(simd, &motion, pairs, base)
        };
        let c = Constants {
            dd: simd.mul_f64s(d, d),
            ..c
        };
        let apart = if vertex_face {
            point_triangles_apart_lanes(simd, &c, start, base)
        } else {
            segments_apart_lanes(simd, &c, start, base)
        };
        let in_range = simd.and_m64s(
            simd.greater_than_or_equal_f64s(d, c.low),
            simd.less_than_or_equal_f64s(d, c.high),
        );
        let hit = simd.and_m64s(apart, in_range);
        bits |= (u64::from(mask_bits_f64(simd, hit)) & low_bits(n - base)) << base;
        base += S::F64_LANES;
    }
    bits
}

/// The splatted constants of the motion bound: `1 + 2^-46`, `2^-46 M`, `t_end`, `closing`,
/// `delta`.
struct MotionConstants<V> {
    up: V,
    slack: V,
    t: V,
    closing: V,
    delta: V,
}

/// Whether the motion filter can certify anything for these inputs (the ranges of
/// [`apart_beyond_motion_with`]).
#[inline(always)]
pub(crate) fn motion_in_range(delta: f64, closing: f64, m: f64, t_end: f64) -> bool {
    moving_in_range(delta, m, t_end) && closing.is_finite() && closing >= 1.0
}

/// The distance `d` of [`apart_beyond_motion_with`] for the moving pairs in lanes
/// `base..base + F64_LANES` (`VF`: vertex-face).
#[inline(always)]
fn motion_distance_lanes<S: Simd, const VF: bool>(
    simd: S,
    c: &MotionConstants<S::f64s>,
    pairs: &MovingPoints,
    base: usize,
) -> S::f64s {
    let o = [
        moving_point::<S>(pairs, 0, 0, base),
        moving_point::<S>(pairs, 1, 0, base),
    ];
    let (n1, n2, n3) = (
        relative_motion(simd, pairs, &o, 1, base),
        relative_motion(simd, pairs, &o, 2, base),
        relative_motion(simd, pairs, &o, 3, base),
    );
    let s = if VF {
        simd.max_f64s(simd.max_f64s(n1, n2), n3)
    } else {
        simd.add_f64s(n1, simd.max_f64s(n2, n3))
    };
    let a = simd.add_f64s(simd.mul_f64s(s, c.up), c.slack);
    let a_t = simd.mul_f64s(simd.mul_f64s(simd.mul_f64s(a, c.t), c.closing), c.up);
    simd.mul_f64s(simd.add_f64s(c.delta, a_t), c.up)
}

/// `|D_e|`: how far point `e` moves relative to the pair's first point `o` (`o[j]` at pose
/// `j`), `D_e = (x1_e - x1_o) - (x0_e - x0_o)`, in lanes `base..`.
// PERF: a function, not a closure: a closure may be compiled without the target features.
#[inline(always)]
fn relative_motion<S: Simd>(
    simd: S,
    pairs: &MovingPoints,
    o: &[[S::f64s; 3]; 2],
    e: usize,
    base: usize,
) -> S::f64s {
    let x0 = moving_point::<S>(pairs, 0, e, base);
    let x1 = moving_point::<S>(pairs, 1, e, base);
    let d = sub3(simd, &sub3(simd, &x1, &o[1]), &sub3(simd, &x0, &o[0]));
    simd.sqrt_f64s(dot3(simd, &d, &d))
}
