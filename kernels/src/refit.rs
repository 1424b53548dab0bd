//! Refit reductions over a node's vertices: a contiguous run of points, or points named by
//! an index list (a gather). The caller combines the two for nodes whose vertex set is a run
//! plus a few vertices owned elsewhere.
//!
//! SIMD and exactness: the SIMD bodies keep one accumulator per lane; point `k` of the run
//! (or of the index list) goes to lane `k % lanes`, and the lanes are folded in order at the
//! end. The references in [`crate::reference`], `*_scalar_lanes(.., lanes)`, do exactly
//! that, so `x_with(simd, ..)` equals `x_scalar_lanes(.., S::F32_LANES)` bit for bit, and the
//! one dispatching entry, [`bounds`] (for callers outside a dispatched body), equals
//! `bounds_scalar_lanes(.., reference::f32_lanes())`. `*_scalar_lanes(.., 1)` is the sequential
//! order. For max/min only ties between `+0` and `-0` can tell orders apart; for sums
//! rounding can.
//!
//! Max/min policy: a value replaces the accumulator only if it is strictly greater (max) or
//! strictly smaller (min). So NaN values are skipped (a point with a NaN coordinate does not
//! widen the box on that axis; a NaN squared distance is ignored), and among `+0`/`-0` ties the
//! first in lane order stays. Squared distances are never `-0`, so [`max_dist_sq_with`] has no
//! sign ambiguity. `±inf` coordinates are ordinary values (`inf - inf` is NaN and skipped).
//! Sums follow IEEE addition: NaN propagates, `inf + -inf` is NaN (NaN payloads and signs
//! are unspecified and may differ between backends). Sums start at `+0`; tail lanes are
//! padded with `-0`, which leaves any sum unchanged bit for bit.

use crate::lanes::{f32_array, fold_max_simd, fold_min_simd, fold_sum, load};
use crate::{Soa3, MAX_LANES};
use pulp::{Simd, WithSimd};

/// Gathers `p[idx[l]]` for the `idx.len() <= S::F32_LANES` indices into lane-width vectors;
/// lanes past `idx.len()` hold `pad`.
#[inline(always)]
fn gather3<S: Simd>(p: Soa3, idx: &[u32], pad: f32) -> [S::f32s; 3] {
    let mut buf = [[pad; MAX_LANES]; 3];
    for (l, &i) in idx.iter().enumerate() {
        let i = i as usize;
        buf[0][l] = p.x[i];
        buf[1][l] = p.y[i];
        buf[2][l] = p.z[i];
    }
    [load::<S>(&buf[0]), load::<S>(&buf[1]), load::<S>(&buf[2])]
}

/// Copies the tail run `x, y, z` (shorter than a vector) into lane-width vectors; lanes past
/// the tail hold `pad`.
#[inline(always)]
fn tail3<S: Simd>(x: &[f32], y: &[f32], z: &[f32], pad: f32) -> [S::f32s; 3] {
    let mut buf = [[pad; MAX_LANES]; 3];
    buf[0][..x.len()].copy_from_slice(x);
    buf[1][..y.len()].copy_from_slice(y);
    buf[2][..z.len()].copy_from_slice(z);
    [load::<S>(&buf[0]), load::<S>(&buf[1]), load::<S>(&buf[2])]
}

/// One lane-wise reduction step. A trait rather than closures: closures do not inherit the
/// target features of the dispatched body and may be compiled out of line, turning every
/// intrinsic into a call (measured: several times slower than scalar).
trait Reduce<S: Simd> {
    /// Padding for tail lanes that leaves the reduction unchanged.
    const PAD: f32;
    fn step(&mut self, simd: S, q: [S::f32s; 3]);
}

/// Feeds the points of `p` to `r` a vector at a time; the tail is padded with `R::PAD`.
#[inline(always)]
fn reduce_run<S: Simd, R: Reduce<S>>(simd: S, p: Soa3, r: &mut R) {
    let (xs, xt) = S::as_simd_f32s(p.x);
    let (ys, yt) = S::as_simd_f32s(p.y);
    let (zs, zt) = S::as_simd_f32s(p.z);
    for ((&x, &y), &z) in xs.iter().zip(ys).zip(zs) {
        r.step(simd, [x, y, z]);
    }
    if !xt.is_empty() {
        r.step(simd, tail3::<S>(xt, yt, zt, R::PAD));
    }
}

/// Feeds the points `p[idx[k]]` to `r` a vector at a time (staged gather); the tail is padded
/// with `R::PAD`.
#[inline(always)]
fn reduce_indexed<S: Simd, R: Reduce<S>>(simd: S, p: Soa3, idx: &[u32], r: &mut R) {
    assert!(S::F32_LANES <= MAX_LANES);
    for block in idx.chunks(S::F32_LANES) {
        r.step(simd, gather3::<S>(p, block, R::PAD));
    }
}

#[inline(always)]
fn reduce<S: Simd, R: Reduce<S>>(simd: S, p: Soa3, idx: Option<&[u32]>, r: &mut R) {
    match idx {
        None => reduce_run(simd, p, r),
        Some(idx) => reduce_indexed(simd, p, idx, r),
    }
}

// ---------------------------------------------------------------------------------------
// max_dist_sq

struct MaxDistSqAcc<S: Simd> {
    c: [S::f32s; 3],
    acc: S::f32s,
}

impl<S: Simd> Reduce<S> for MaxDistSqAcc<S> {
    /// NaN coordinates give a NaN distance, which never replaces the maximum.
    const PAD: f32 = f32::NAN;

    #[inline(always)]
    fn step(&mut self, simd: S, q: [S::f32s; 3]) {
        let c = self.c;
        let dx = simd.sub_f32s(q[0], c[0]);
        let dy = simd.sub_f32s(q[1], c[1]);
        let dz = simd.sub_f32s(q[2], c[2]);
        let d2 = simd.add_f32s(
            simd.add_f32s(simd.mul_f32s(dx, dx), simd.mul_f32s(dy, dy)),
            simd.mul_f32s(dz, dz),
        );
        self.acc = simd.select_f32s(simd.greater_than_f32s(d2, self.acc), d2, self.acc);
    }
}

#[inline(always)]
fn max_dist_sq_simd<S: Simd>(simd: S, p: Soa3, idx: Option<&[u32]>, c: [f32; 3]) -> f32 {
    let mut r = MaxDistSqAcc::<S> {
        c: [
            simd.splat_f32s(c[0]),
            simd.splat_f32s(c[1]),
            simd.splat_f32s(c[2]),
        ],
        acc: simd.splat_f32s(0.0),
    };
    reduce(simd, p, idx, &mut r);
    // The accumulator starts at 0 and NaN never replaces: no NaN lane.
    fold_max_simd(simd, r.acc)
}

struct MaxDistSq<'a> {
    p: Soa3<'a>,
    idx: Option<&'a [u32]>,
    c: [f32; 3],
}

impl WithSimd for MaxDistSq<'_> {
    type Output = f32;
    #[inline(always)]
    fn with_simd<S: Simd>(self, simd: S) -> f32 {
        max_dist_sq_simd(simd, self.p, self.idx, self.c)
    }
}
/// Largest squared distance `(dx*dx + dy*dy) + dz*dz` from `c` to the points of `p` (0 for
/// no points; NaN distances are skipped), on the backend `simd`.
pub fn max_dist_sq_with<S: Simd>(simd: S, p: Soa3, c: [f32; 3]) -> f32 {
    simd.vectorize(MaxDistSq { p, idx: None, c })
}

/// Largest squared distance from `c` to the points `p[idx[k]]` (0 for no points), on the
/// backend `simd`.
pub fn max_dist_sq_indexed_with<S: Simd>(simd: S, p: Soa3, idx: &[u32], c: [f32; 3]) -> f32 {
    simd.vectorize(MaxDistSq {
        p,
        idx: Some(idx),
        c,
    })
}

// ---------------------------------------------------------------------------------------
// sum

/// Padding that leaves a sum unchanged bit for bit (`x + -0.0 == x`, also for `x = -0.0`).
const SUM_PAD: f32 = -0.0;

struct SumAcc<S: Simd> {
    acc: [S::f32s; 3],
}

impl<S: Simd> Reduce<S> for SumAcc<S> {
    const PAD: f32 = SUM_PAD;

    #[inline(always)]
    fn step(&mut self, simd: S, q: [S::f32s; 3]) {
        for a in 0..3 {
            self.acc[a] = simd.add_f32s(self.acc[a], q[a]);
        }
    }
}

#[inline(always)]
fn sum_simd<S: Simd>(simd: S, p: Soa3, idx: Option<&[u32]>) -> [f32; 3] {
    let mut r = SumAcc::<S> {
        acc: [simd.splat_f32s(0.0); 3],
    };
    reduce(simd, p, idx, &mut r);
    let mut s = [0.0f32; 3];
    for a in 0..3 {
        s[a] = fold_sum(f32_array::<S>(&r.acc[a]));
    }
    s
}

struct Sum<'a> {
    p: Soa3<'a>,
    idx: Option<&'a [u32]>,
}

impl WithSimd for Sum<'_> {
    type Output = [f32; 3];
    #[inline(always)]
    fn with_simd<S: Simd>(self, simd: S) -> [f32; 3] {
        sum_simd(simd, self.p, self.idx)
    }
}

/// Component-wise sum of the points (for the sphere centre, the mean), on the backend
/// `simd`: `S::F32_LANES` interleaved partial sums, so it may differ from the sequential
/// [`crate::reference::sum_scalar_lanes`] with one lane by rounding.
pub fn sum_with<S: Simd>(simd: S, p: Soa3) -> [f32; 3] {
    simd.vectorize(Sum { p, idx: None })
}

/// Component-wise sum of the points `p[idx[k]]`, on the backend `simd`.
pub fn sum_indexed_with<S: Simd>(simd: S, p: Soa3, idx: &[u32]) -> [f32; 3] {
    simd.vectorize(Sum { p, idx: Some(idx) })
}

// ---------------------------------------------------------------------------------------
// bounds

/// An empty box: `min = +inf`, `max = -inf`, so it never overlaps and is the identity of
/// [`merge_bounds`].
pub const EMPTY_BOUNDS: ([f32; 3], [f32; 3]) = ([f32::INFINITY; 3], [f32::NEG_INFINITY; 3]);

/// Union of two boxes.
#[inline]
pub fn merge_bounds(a: ([f32; 3], [f32; 3]), b: ([f32; 3], [f32; 3])) -> ([f32; 3], [f32; 3]) {
    (
        [a.0[0].min(b.0[0]), a.0[1].min(b.0[1]), a.0[2].min(b.0[2])],
        [a.1[0].max(b.1[0]), a.1[1].max(b.1[1]), a.1[2].max(b.1[2])],
    )
}

/// Lane-wise `if v < lo { lo = v }` and `if v > hi { hi = v }` (NaN never replaces).
#[inline(always)]
pub(crate) fn widen_simd<S: Simd>(simd: S, lo: &mut S::f32s, hi: &mut S::f32s, v: S::f32s) {
    *lo = simd.select_f32s(simd.less_than_f32s(v, *lo), v, *lo);
    *hi = simd.select_f32s(simd.greater_than_f32s(v, *hi), v, *hi);
}

struct BoundsAcc<S: Simd> {
    lo: [S::f32s; 3],
    hi: [S::f32s; 3],
}

impl<S: Simd> Reduce<S> for BoundsAcc<S> {
    /// NaN never widens a box.
    const PAD: f32 = f32::NAN;

    #[inline(always)]
    fn step(&mut self, simd: S, q: [S::f32s; 3]) {
        for a in 0..3 {
            widen_simd(simd, &mut self.lo[a], &mut self.hi[a], q[a]);
        }
    }
}

#[inline(always)]
fn bounds_simd<S: Simd>(simd: S, p: Soa3, idx: Option<&[u32]>) -> ([f32; 3], [f32; 3]) {
    let mut r = BoundsAcc::<S> {
        lo: [simd.splat_f32s(f32::INFINITY); 3],
        hi: [simd.splat_f32s(f32::NEG_INFINITY); 3],
    };
    reduce(simd, p, idx, &mut r);
    let (mut lo, mut hi) = EMPTY_BOUNDS;
    for a in 0..3 {
        // The accumulators start at +-inf and NaN never replaces: no NaN lane.
        lo[a] = fold_min_simd(simd, r.lo[a]);
        hi[a] = fold_max_simd(simd, r.hi[a]);
    }
    (lo, hi)
}

struct Bounds<'a> {
    p: Soa3<'a>,
    idx: Option<&'a [u32]>,
}

impl WithSimd for Bounds<'_> {
    type Output = ([f32; 3], [f32; 3]);
    #[inline(always)]
    fn with_simd<S: Simd>(self, simd: S) -> Self::Output {
        bounds_simd(simd, self.p, self.idx)
    }
}

/// Axis-aligned bounds `(min, max)` of the points ([`EMPTY_BOUNDS`] for no points; NaN
/// coordinates are skipped, so an axis with only NaN stays empty).
pub fn bounds(p: Soa3) -> ([f32; 3], [f32; 3]) {
    crate::arch().dispatch(Bounds { p, idx: None })
}

/// [`bounds`] on the backend `simd`: the form to call inside a dispatched body.
pub fn bounds_with<S: Simd>(simd: S, p: Soa3) -> ([f32; 3], [f32; 3]) {
    simd.vectorize(Bounds { p, idx: None })
}

/// Axis-aligned bounds of the points `p[idx[k]]`, on the backend `simd`.
pub fn bounds_indexed_with<S: Simd>(simd: S, p: Soa3, idx: &[u32]) -> ([f32; 3], [f32; 3]) {
    simd.vectorize(Bounds { p, idx: Some(idx) })
}
