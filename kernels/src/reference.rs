//! Scalar references of every kernel, for tests and benchmarks: one pair (or one point) at a
//! time, in the kernel's operation order, so that each kernel can be checked against its
//! reference on every backend.
//!
//! - Overlap ([`crate::overlap`]): [`sphere_block_scalar`], [`aabb_block_scalar`],
//!   [`boxes_meet_scalar`] and [`moving_sphere_block_scalar`], built on the pair tests
//!   [`spheres_overlap`], [`aabbs_overlap`] and [`moving_spheres_meet`]. Their masks equal the
//!   kernels' bit for bit on every backend.
//! - Narrow phase ([`crate::narrow`]): [`leaf_contacts_scalar`] and
//!   [`leaf_candidates_rounded_scalar`], built on the pair tests [`pair_verdict`] and
//!   [`plane_separated`]; bit-identical rows on every backend.
//! - Refit ([`crate::refit`]): `*_scalar_lanes(.., lanes)` reduce in the order of a
//!   `lanes`-wide SIMD body (equal bit for bit to `*_with` on a backend of `lanes` lanes);
//!   `lanes = 1` is the sequential order. [`f32_lanes`] is the lane count of the
//!   dispatched backend, the one [`crate::refit::bounds`] runs on.

use crate::lanes::{fold_max, fold_min, fold_sum};
use crate::narrow::{self, Pairing, Row, TriSoa};
use crate::overlap::{self, AabbSoa, BoxRows, MovingSphere, MovingSphereSoa, SphereSoa};
use crate::Soa3;
use pulp::{Simd, WithSimd};

struct F32Lanes;

impl WithSimd for F32Lanes {
    type Output = usize;
    #[inline(always)]
    fn with_simd<S: Simd>(self, _simd: S) -> usize {
        S::F32_LANES
    }
}

/// The `f32` lane count of the dispatched backend ([`crate::arch`]): the `lanes` argument for
/// which the `*_scalar_lanes` references reproduce a reduction run on that backend exactly.
pub fn f32_lanes() -> usize {
    crate::arch().dispatch(F32Lanes)
}

// ---------------------------------------------------------------------------------------
// overlap

/// Closed sphere test in the kernels' operation order:
/// `(dx*dx + dy*dy) + dz*dz <= (ra + rb)*(ra + rb)`. Symmetric: swapping the spheres gives
/// the same bits (negated differences square alike; addition commutes).
#[inline(always)]
pub fn spheres_overlap(a: [f32; 3], ra: f32, b: [f32; 3], rb: f32) -> bool {
    let dx = a[0] - b[0];
    let dy = a[1] - b[1];
    let dz = a[2] - b[2];
    let d2 = dx * dx + dy * dy + dz * dz;
    let rs = ra + rb;
    d2 <= rs * rs
}

/// Closed box test (comparisons only).
#[inline(always)]
pub fn aabbs_overlap(a: ([f32; 3], [f32; 3]), b: ([f32; 3], [f32; 3])) -> bool {
    a.0[0] <= b.1[0]
        && b.0[0] <= a.1[0]
        && a.0[1] <= b.1[1]
        && b.0[1] <= a.1[1]
        && a.0[2] <= b.1[2]
        && b.0[2] <= a.1[2]
}

/// Scalar reference of [`overlap::sphere_block_with`] (one pair at a time).
pub fn sphere_block_scalar(c: [f32; 3], r: f32, b: SphereSoa, n: usize) -> u32 {
    overlap::block_len(b.len(), n);
    let mut bits = 0;
    for k in 0..n {
        let (bc, br) = b.get(k);
        bits |= (spheres_overlap(c, r, bc, br) as u32) << k;
    }
    bits
}

/// Scalar reference of [`overlap::aabb_block_with`] (one pair at a time, early exit per axis).
pub fn aabb_block_scalar(lo: [f32; 3], hi: [f32; 3], b: AabbSoa, n: usize) -> u32 {
    overlap::block_len(b.len(), n);
    let mut bits = 0;
    for k in 0..n {
        bits |= (aabbs_overlap((lo, hi), b.get(k)) as u32) << k;
    }
    bits
}

/// Scalar reference of [`overlap::boxes_meet_with`].
pub fn boxes_meet_scalar(lo: [f32; 3], hi: [f32; 3], rows: BoxRows, n: usize) -> u64 {
    overlap::box_rows_len(&rows, n);
    let mut bits = 0;
    for k in 0..n {
        let b = (
            [rows[0][k], rows[1][k], rows[2][k]],
            [rows[3][k], rows[4][k], rows[5][k]],
        );
        bits |= u64::from(aabbs_overlap((lo, hi), b)) << k;
    }
    bits
}

/// Whether two moving spheres meet at some `t` in `[0, 1]`, conservatively: always when they
/// do, and when they come within rounding of doing so. With `D(t) = D0 + t E` the centres'
/// difference and `R(t) = R0 + t F` the radii's sum, they meet iff `h(t) = |D|^2 - R^2 <= 0`
/// somewhere: `h(0) = C <= 0`, `h(1) <= 0`, or the minimum of the quadratic
/// `h = A t^2 + 2 B t + C` is interior (`A > 0`, `-A < B < 0`) and `A C - B^2 <= 0`
/// (`C - |B| <= 0` is implied, and tested too: it stops near-still pairs that are apart).
/// Evaluated in `f64` (centres and radii are `f32` values, exact in `f64`), every comparison
/// widened by its rounding bound (`MOVING_K2`, `MOVING_K4` in `overlap.rs`). A NaN makes the
/// pair not meet. In the operation order of [`overlap::moving_sphere_block_with`].
#[inline(always)]
pub fn moving_spheres_meet(a: &MovingSphere, b: &MovingSphere) -> bool {
    let d0 = [a.c0[0] - b.c0[0], a.c0[1] - b.c0[1], a.c0[2] - b.c0[2]];
    let d1 = [a.c1[0] - b.c1[0], a.c1[1] - b.c1[1], a.c1[2] - b.c1[2]];
    let e = [d1[0] - d0[0], d1[1] - d0[1], d1[2] - d0[2]];
    let (r0, r1) = (a.r0 + b.r0, a.r1 + b.r1);
    let f = r1 - r0;
    let dot = |x: [f64; 3], y: [f64; 3]| (x[0] * y[0] + x[1] * y[1]) + x[2] * y[2];
    let c = dot(d0, d0) - r0 * r0;
    let h1 = dot(d1, d1) - r1 * r1;
    let aa = dot(e, e) - f * f;
    let bb = dot(d0, e) - r0 * f;
    let abs = |x: f64| if x < 0.0 { 0.0 - x } else { x };
    let mut m = r0;
    for x in [d0[0], d0[1], d0[2], d1[0], d1[1], d1[2], r1] {
        let x = abs(x);
        m = if x > m { x } else { m };
    }
    let m2 = m * m;
    let s2 = overlap::MOVING_K2 * m2 + overlap::MOVING_TINY;
    let s4 = overlap::MOVING_K4 * (m2 * m2) + overlap::MOVING_TINY;
    let two_s2 = s2 + s2;
    let interior = aa > 0.0 - s2
        && bb < s2
        && bb > (0.0 - aa) - two_s2
        && c - abs(bb) <= two_s2
        && aa * c - bb * bb <= s4;
    c <= s2 || h1 <= s2 || interior
}

/// Scalar reference of [`overlap::moving_sphere_block_with`].
pub fn moving_sphere_block_scalar(p: &MovingSphere, b: MovingSphereSoa, n: usize) -> u32 {
    overlap::block_len(b.len(), n);
    let mut bits = 0;
    for k in 0..n {
        bits |= u32::from(moving_spheres_meet(p, &b.get(k))) << k;
    }
    bits
}

// ---------------------------------------------------------------------------------------
// narrow

/// Whether a separating plane of `a` or `b` is certified (the plane filter on one pair,
/// boxes from the corners).
pub fn plane_separated(a: &[[f32; 3]; 3], b: &[[f32; 3]; 3]) -> bool {
    let (sa, sb) = narrow::filter_signs(
        a,
        b,
        &narrow::union_extents(&narrow::corner_box(a), &narrow::corner_box(b)),
        0.0,
    );
    narrow::one_side(sa) || narrow::one_side(sb)
}

pub use crate::narrow::Verdict;

/// The verdict of the plane filter and the certified canonical form on one pair (the
/// [`narrow`] module doc), in the kernel's arithmetic, boxes from the corners.
pub fn pair_verdict(a: &[[f32; 3]; 3], b: &[[f32; 3]; 3]) -> Verdict {
    narrow::verdict_within(
        a,
        b,
        &narrow::union_extents(&narrow::corner_box(a), &narrow::corner_box(b)),
    )
}

/// Scalar reference of [`narrow::leaf_contacts_with`] (one pair at a time).
pub fn leaf_contacts_scalar(
    a: TriSoa,
    na: usize,
    b: TriSoa,
    nb: usize,
    pairing: Pairing,
    out: &mut [Row],
) {
    rows_scalar::<false>(a, na, b, nb, pairing, out)
}

/// Scalar reference of [`narrow::leaf_candidates_rounded_with`] (one pair at a time).
pub fn leaf_candidates_rounded_scalar(
    a: TriSoa,
    na: usize,
    b: TriSoa,
    nb: usize,
    pairing: Pairing,
    out: &mut [Row],
) {
    rows_scalar::<true>(a, na, b, nb, pairing, out)
}

fn rows_scalar<const ROUNDED: bool>(
    a: TriSoa,
    na: usize,
    b: TriSoa,
    nb: usize,
    pairing: Pairing,
    out: &mut [Row],
) {
    narrow::check(&a, na, &b, nb, out);
    for i in 0..na {
        let ta = a.corners(i);
        let va = [a.vertex(0)[i], a.vertex(1)[i], a.vertex(2)[i]];
        let mut row = Row::default();
        for j in 0..nb {
            if pairing == Pairing::NoSharedVertexUpper && j <= i {
                continue;
            }
            if pairing != Pairing::All && (0..3).any(|c| va.contains(&b.vertex(c)[j])) {
                continue;
            }
            let boxes = (0..3).all(|k| a.lo(k)[i] <= b.hi(k)[j] && b.lo(k)[j] <= a.hi(k)[i]);
            if !boxes {
                continue;
            }
            let stored = |t: &TriSoa, i: usize| {
                (
                    [t.lo(0)[i], t.lo(1)[i], t.lo(2)[i]],
                    [t.hi(0)[i], t.hi(1)[i], t.hi(2)[i]],
                )
            };
            let (sa, sb) = (stored(&a, i), stored(&b, j));
            let ext = narrow::union_extents(&sa, &sb);
            if ROUNDED {
                let slack = narrow::rounding_slack(&ext, narrow::union_magnitude(&sa, &sb));
                let (s1, s2) = narrow::filter_signs(&ta, &b.corners(j), &ext, slack);
                if !(narrow::one_side(s1) || narrow::one_side(s2)) {
                    row.undecided |= 1 << j;
                }
                continue;
            }
            match narrow::verdict_within(&ta, &b.corners(j), &ext) {
                Verdict::Apart => {}
                Verdict::Contact => row.contact |= 1 << j,
                Verdict::Undecided => row.undecided |= 1 << j,
            }
        }
        out[i] = row;
    }
}

// ---------------------------------------------------------------------------------------
// refit

/// The largest `lanes` the `*_scalar_lanes` references accept.
pub const MAX_REFERENCE_LANES: usize = 64;

fn check_ref_lanes(lanes: usize) {
    assert!(
        (1..=MAX_REFERENCE_LANES).contains(&lanes),
        "lanes must be in 1..={MAX_REFERENCE_LANES}"
    );
}

#[inline(always)]
fn dist_sq(q: [f32; 3], c: [f32; 3]) -> f32 {
    let dx = q[0] - c[0];
    let dy = q[1] - c[1];
    let dz = q[2] - c[2];
    dx * dx + dy * dy + dz * dz
}

fn max_dist_sq_ref(points: impl Iterator<Item = [f32; 3]>, c: [f32; 3], lanes: usize) -> f32 {
    check_ref_lanes(lanes);
    let mut acc = [0.0f32; MAX_REFERENCE_LANES];
    for (k, q) in points.enumerate() {
        let d2 = dist_sq(q, c);
        let l = k % lanes;
        if d2 > acc[l] {
            acc[l] = d2;
        }
    }
    fold_max(&acc[..lanes])
}

fn sum_ref(points: impl Iterator<Item = [f32; 3]>, lanes: usize) -> [f32; 3] {
    check_ref_lanes(lanes);
    let mut acc = [[0.0f32; MAX_REFERENCE_LANES]; 3];
    for (k, q) in points.enumerate() {
        let l = k % lanes;
        for a in 0..3 {
            acc[a][l] += q[a];
        }
    }
    core::array::from_fn(|a| fold_sum(&acc[a][..lanes]))
}

fn bounds_ref(points: impl Iterator<Item = [f32; 3]>, lanes: usize) -> ([f32; 3], [f32; 3]) {
    check_ref_lanes(lanes);
    let mut lo = [[f32::INFINITY; MAX_REFERENCE_LANES]; 3];
    let mut hi = [[f32::NEG_INFINITY; MAX_REFERENCE_LANES]; 3];
    for (k, q) in points.enumerate() {
        let l = k % lanes;
        for a in 0..3 {
            if q[a] < lo[a][l] {
                lo[a][l] = q[a];
            }
            if q[a] > hi[a][l] {
                hi[a][l] = q[a];
            }
        }
    }
    (
        core::array::from_fn(|a| fold_min(&lo[a][..lanes])),
        core::array::from_fn(|a| fold_max(&hi[a][..lanes])),
    )
}

fn run(p: Soa3<'_>) -> impl Iterator<Item = [f32; 3]> + '_ {
    (0..p.len()).map(move |i| p.get(i))
}

fn indexed<'a>(p: Soa3<'a>, idx: &'a [u32]) -> impl Iterator<Item = [f32; 3]> + 'a {
    idx.iter().map(move |&i| p.get(i as usize))
}

/// Reference of [`crate::refit::max_dist_sq_with`] in the order of a `lanes`-wide SIMD body (see
/// the [`crate::refit`] module doc).
pub fn max_dist_sq_scalar_lanes(p: Soa3, c: [f32; 3], lanes: usize) -> f32 {
    max_dist_sq_ref(run(p), c, lanes)
}

/// Reference of [`crate::refit::max_dist_sq_indexed_with`] in the order of a `lanes`-wide SIMD
/// body.
pub fn max_dist_sq_indexed_scalar_lanes(p: Soa3, idx: &[u32], c: [f32; 3], lanes: usize) -> f32 {
    max_dist_sq_ref(indexed(p, idx), c, lanes)
}

/// Reference of [`crate::refit::sum_with`] in the order of a `lanes`-wide SIMD body.
pub fn sum_scalar_lanes(p: Soa3, lanes: usize) -> [f32; 3] {
    sum_ref(run(p), lanes)
}

/// Reference of [`crate::refit::sum_indexed_with`] in the order of a `lanes`-wide SIMD body.
pub fn sum_indexed_scalar_lanes(p: Soa3, idx: &[u32], lanes: usize) -> [f32; 3] {
    sum_ref(indexed(p, idx), lanes)
}

/// Reference of [`crate::refit::bounds_with`] in the order of a `lanes`-wide SIMD body.
pub fn bounds_scalar_lanes(p: Soa3, lanes: usize) -> ([f32; 3], [f32; 3]) {
    bounds_ref(run(p), lanes)
}

/// Reference of [`crate::refit::bounds_indexed_with`] in the order of a `lanes`-wide SIMD body.
pub fn bounds_indexed_scalar_lanes(p: Soa3, idx: &[u32], lanes: usize) -> ([f32; 3], [f32; 3]) {
    bounds_ref(indexed(p, idx), lanes)
}

// ---------------------------------------------------------------------------------------
// apart

/// The arithmetic of the [`crate::apart`] filters on one pair, in the kernels' operation
/// order. Their clamps are `min(max(x, 0), 1)`; a NaN there may resolve differently by
/// backend, which only changes the direction (module doc).
mod apart_one {
    use crate::apart::{
        distance_in_range, DIRECTION_LOW, GAP_ERROR, SCALE_HIGH, SCALE_LOW, SQUARE_MARGIN,
    };

    pub(super) type P = [f64; 3];

    pub(super) fn sub(x: P, y: P) -> P {
        [x[0] - y[0], x[1] - y[1], x[2] - y[2]]
    }

    pub(super) fn dot(x: P, y: P) -> f64 {
        (x[0] * y[0] + x[1] * y[1]) + x[2] * y[2]
    }

    // The kernels' order of `max` then `min`: `clamp` differs on NaN.
    #[allow(clippy::manual_clamp)]
    pub(super) fn unit(x: f64) -> f64 {
        x.max(0.0).min(1.0)
    }

    /// `r - t e`.
    pub(super) fn along(r: P, t: f64, e: P) -> P {
        [r[0] - t * e[0], r[1] - t * e[1], r[2] - t * e[2]]
    }

    /// The certificate: `gap` from the differences `x` exceeds `d |w|` beyond its bound.
    pub(super) fn certified(gap: f64, x: [P; 3], w: P, d: f64) -> bool {
        if !distance_in_range(d) {
            return false;
        }
        let mut m = x[0][0].abs();
        for v in x {
            for c in v {
                m = m.max(c.abs());
            }
        }
        let w1 = (w[0].abs() + w[1].abs()) + w[2].abs();
        let lower = gap - GAP_ERROR * (m * w1);
        let ww = dot(w, w);
        lower > 0.0
            && lower * lower > ((d * d) * ww) * SQUARE_MARGIN
            && ww >= DIRECTION_LOW
            && (SCALE_LOW..=SCALE_HIGH).contains(&m)
    }
}

/// Whether one segment pair `[a0, a1, b0, b1]` is certainly farther apart than `d` (the
/// [`crate::apart`] filter on one pair).
pub fn segment_pair_apart(e: [[f64; 3]; 4], d: f64) -> bool {
    use apart_one::{along, certified, dot, sub, unit};
    let [a0, a1, b0, b1] = e;
    let (r, s, v, u) = (sub(a0, b0), sub(a1, b0), sub(b1, b0), sub(a1, a0));
    let (uu, vv, uv) = (dot(u, u), dot(v, v), dot(u, v));
    let (ru, rv) = (dot(r, u), dot(r, v));
    let den = uu * vv - uv * uv;
    let p = unit((uv * rv - ru * vv) / den);
    let q = unit((uv * p + rv) / vv);
    let p = unit((uv * q - ru) / uu);
    let w = along([r[0] + p * u[0], r[1] + p * u[1], r[2] + p * u[2]], q, v);
    let gap = dot(r, w).min(dot(s, w)) - 0f64.max(dot(v, w));
    certified(gap, [r, s, v], w, d)
}

/// Whether one point-triangle pair `[p, t0, t1, t2]` is certainly farther apart than `d`.
pub fn point_triangle_apart(e: [[f64; 3]; 4], d: f64) -> bool {
    use apart_one::{along, certified, dot, sub, unit};
    let [p, t0, t1, t2] = e;
    let (r, e0, e1, f, rf) = (
        sub(p, t0),
        sub(t1, t0),
        sub(t2, t0),
        sub(t2, t1),
        sub(p, t1),
    );
    let (d00, d01, d11) = (dot(e0, e0), dot(e0, e1), dot(e1, e1));
    let (d20, d21) = (dot(r, e0), dot(r, e1));
    let den = d00 * d11 - d01 * d01;
    let beta = (d11 * d20 - d01 * d21) / den;
    let gamma = (d00 * d21 - d01 * d20) / den;
    let inside = beta >= 0.0 && gamma >= 0.0 && beta + gamma <= 1.0;
    let w_in = along(along(r, beta, e0), gamma, e1);
    let w0 = along(r, unit(d20 / d00), e0);
    let w1 = along(r, unit(d21 / d11), e1);
    let w2 = along(rf, unit(dot(rf, f) / dot(f, f)), f);
    let (n0, n1, n2) = (dot(w0, w0), dot(w1, w1), dot(w2, w2));
    let (w01, n01) = if n0 <= n1 { (w0, n0) } else { (w1, n1) };
    let w_out = if n01 <= n2 { w01 } else { w2 };
    let w = if inside { w_in } else { w_out };
    let gap = dot(r, w) - 0f64.max(dot(e0, w)).max(dot(e1, w));
    certified(gap, [r, e0, e1], w, d)
}

/// Scalar reference of [`crate::apart::segments_apart_with`].
pub fn segments_apart_scalar(pairs: &crate::apart::FourPoints, n: usize, d: f64) -> u64 {
    assert!(n <= crate::apart::MAX_PAIRS, "at most MAX_PAIRS pairs");
    (0..n).fold(0, |bits, i| {
        bits | u64::from(segment_pair_apart(pairs.get(i), d)) << i
    })
}

/// Scalar reference of [`crate::apart::point_triangles_apart_with`].
pub fn point_triangles_apart_scalar(pairs: &crate::apart::FourPoints, n: usize, d: f64) -> u64 {
    assert!(n <= crate::apart::MAX_PAIRS, "at most MAX_PAIRS pairs");
    (0..n).fold(0, |bits, i| {
        bits | u64::from(point_triangle_apart(pairs.get(i), d)) << i
    })
}

/// Whether one moving pair (`vertex_face`: `[v, t0, t1, t2]`, else `[a0, a1, b0, b1]`, at
/// poses `x0` and `x1`) is certainly farther than `delta` apart over `[0, t_end]` along its
/// centroids' line at pose 0 (the [`crate::apart::centroids_apart_with`] test on one pair).
pub fn moving_centroids_apart(
    x0: &[[f64; 3]; 4],
    x1: &[[f64; 3]; 4],
    vertex_face: bool,
    delta: f64,
    m: f64,
    t_end: f64,
) -> bool {
    use crate::apart::{AXIS_ABS, AXIS_HIGH, AXIS_LOW, AXIS_REL, LENGTH_UP};
    if !crate::apart::moving_in_range(delta, m, t_end) {
        return false;
    }
    let end: [[f64; 3]; 4] = if t_end < 1.0 {
        std::array::from_fn(|e| std::array::from_fn(|k| x0[e][k] + t_end * (x1[e][k] - x0[e][k])))
    } else {
        *x1
    };
    let axis: [f64; 3] = std::array::from_fn(|k| {
        if vertex_face {
            ((x0[1][k] + x0[2][k]) + x0[3][k]) * (1.0 / 3.0) - x0[0][k]
        } else {
            ((x0[2][k] + x0[3][k]) - (x0[0][k] + x0[1][k])) * 0.5
        }
    });
    let dot = |x: [f64; 3]| (x[0] * axis[0] + x[1] * axis[1]) + x[2] * axis[2];
    let norm1 = (axis[0].abs() + axis[1].abs()) + axis[2].abs();
    let mut bound = (AXIS_REL * m) * norm1 + AXIS_ABS;
    if delta > 0.0 {
        bound += delta * (dot(axis).sqrt() * LENGTH_UP);
    }
    let gaps = |x: &[[f64; 3]; 4]| {
        let p = x.map(dot);
        let (a_lo, a_hi, b_lo, b_hi) = if vertex_face {
            (
                p[0],
                p[0],
                p[1].min(p[2]).min(p[3]),
                p[1].max(p[2]).max(p[3]),
            )
        } else {
            (
                p[0].min(p[1]),
                p[0].max(p[1]),
                p[2].min(p[3]),
                p[2].max(p[3]),
            )
        };
        (b_lo - a_hi, a_lo - b_hi)
    };
    let ((up0, down0), (up1, down1)) = (gaps(x0), gaps(&end));
    (AXIS_LOW..=AXIS_HIGH).contains(&norm1)
        && ((up0 > bound && up1 > bound) || (down0 > bound && down1 > bound))
}

/// Scalar reference of [`crate::apart::centroids_apart_with`].
pub fn centroids_apart_scalar(
    pairs: &crate::apart::MovingPoints,
    n: usize,
    vertex_face: bool,
    delta: f64,
    m: f64,
    t_end: f64,
) -> u64 {
    moving_bits(pairs, n, |x0, x1| {
        moving_centroids_apart(x0, x1, vertex_face, delta, m, t_end)
    })
}

/// The bits of the first `n` moving pairs of `pairs` (`n <= MAX_PAIRS`) that `test` passes
/// (bit `i` for pair `i`): the batch of a one-pair moving test.
fn moving_bits(
    pairs: &crate::apart::MovingPoints,
    n: usize,
    test: impl Fn(&[[f64; 3]; 4], &[[f64; 3]; 4]) -> bool,
) -> u64 {
    assert!(n <= crate::apart::MAX_PAIRS, "at most MAX_PAIRS pairs");
    (0..n).fold(0, |bits, i| {
        let (x0, x1) = pairs.get(i);
        bits | u64::from(test(&x0, &x1)) << i
    })
}

/// Whether one moving pair (`vertex_face`: `[v, t0, t1, t2]`, else `[a0, a1, b0, b1]`, at
/// poses `x0` and `x1`) is farther apart at pose 0 than `delta` plus `closing` times the most
/// its relative motion closes by `t_end` (the [`crate::apart::apart_beyond_motion_with`] test
/// on one pair, in its operation order).
pub fn moving_apart_beyond_motion(
    x0: &[[f64; 3]; 4],
    x1: &[[f64; 3]; 4],
    vertex_face: bool,
    delta: f64,
    closing: f64,
    m: f64,
    t_end: f64,
) -> bool {
    use crate::apart::{LENGTH_UP, MOTION_ABS, SCALE_HIGH, SCALE_LOW};
    if !crate::apart::motion_in_range(delta, closing, m, t_end) {
        return false;
    }
    let relative = |e: usize| {
        let d: [f64; 3] = std::array::from_fn(|k| (x1[e][k] - x1[0][k]) - (x0[e][k] - x0[0][k]));
        ((d[0] * d[0] + d[1] * d[1]) + d[2] * d[2]).sqrt()
    };
    let (n1, n2, n3) = (relative(1), relative(2), relative(3));
    let s = if vertex_face {
        n1.max(n2).max(n3)
    } else {
        n1 + n2.max(n3)
    };
    let a = s * LENGTH_UP + MOTION_ABS * m;
    let d = (delta + ((a * t_end) * closing) * LENGTH_UP) * LENGTH_UP;
    (SCALE_LOW..=SCALE_HIGH).contains(&d)
        && if vertex_face {
            point_triangle_apart(*x0, d)
        } else {
            segment_pair_apart(*x0, d)
        }
}

/// Scalar reference of [`crate::apart::apart_beyond_motion_with`].
pub fn apart_beyond_motion_scalar(
    pairs: &crate::apart::MovingPoints,
    n: usize,
    vertex_face: bool,
    delta: f64,
    closing: f64,
    m: f64,
    t_end: f64,
) -> u64 {
    moving_bits(pairs, n, |x0, x1| {
        moving_apart_beyond_motion(x0, x1, vertex_face, delta, closing, m, t_end)
    })
}
