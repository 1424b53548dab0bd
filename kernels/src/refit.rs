//! Refit reductions over a node's vertices: a contiguous run of points, or points named by
//! an index list (a gather). The caller combines the two for nodes whose vertex set is a run
//! plus a few vertices owned elsewhere.

use crate::Soa3;

/// Scalar reference of [`max_dist_sq`].
pub fn max_dist_sq_scalar(p: Soa3, c: [f32; 3]) -> f32 {
    let mut m = 0.0f32;
    for i in 0..p.len() {
        let dx = p.x[i] - c[0];
        let dy = p.y[i] - c[1];
        let dz = p.z[i] - c[2];
        m = m.max(dx * dx + dy * dy + dz * dz);
    }
    m
}

/// Largest squared distance from `c` to the points of `p` (0 for no points).
pub fn max_dist_sq(p: Soa3, c: [f32; 3]) -> f32 {
    max_dist_sq_scalar(p, c)
}

/// Scalar reference of [`max_dist_sq_indexed`].
pub fn max_dist_sq_indexed_scalar(p: Soa3, idx: &[u32], c: [f32; 3]) -> f32 {
    let mut m = 0.0f32;
    for &i in idx {
        let i = i as usize;
        let dx = p.x[i] - c[0];
        let dy = p.y[i] - c[1];
        let dz = p.z[i] - c[2];
        m = m.max(dx * dx + dy * dy + dz * dz);
    }
    m
}

/// Largest squared distance from `c` to the points `p[idx[k]]` (0 for no points).
pub fn max_dist_sq_indexed(p: Soa3, idx: &[u32], c: [f32; 3]) -> f32 {
    max_dist_sq_indexed_scalar(p, idx, c)
}

/// Scalar reference of [`sum`].
pub fn sum_scalar(p: Soa3) -> [f32; 3] {
    let mut s = [0.0f32; 3];
    for i in 0..p.len() {
        s[0] += p.x[i];
        s[1] += p.y[i];
        s[2] += p.z[i];
    }
    s
}

/// Component-wise sum of the points (for the sphere centre, the mean).
pub fn sum(p: Soa3) -> [f32; 3] {
    sum_scalar(p)
}

/// Scalar reference of [`sum_indexed`].
pub fn sum_indexed_scalar(p: Soa3, idx: &[u32]) -> [f32; 3] {
    let mut s = [0.0f32; 3];
    for &i in idx {
        let i = i as usize;
        s[0] += p.x[i];
        s[1] += p.y[i];
        s[2] += p.z[i];
    }
    s
}

/// Component-wise sum of the points `p[idx[k]]`.
pub fn sum_indexed(p: Soa3, idx: &[u32]) -> [f32; 3] {
    sum_indexed_scalar(p, idx)
}

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

/// Scalar reference of [`bounds`].
pub fn bounds_scalar(p: Soa3) -> ([f32; 3], [f32; 3]) {
    let (mut lo, mut hi) = EMPTY_BOUNDS;
    for i in 0..p.len() {
        lo[0] = lo[0].min(p.x[i]);
        lo[1] = lo[1].min(p.y[i]);
        lo[2] = lo[2].min(p.z[i]);
        hi[0] = hi[0].max(p.x[i]);
        hi[1] = hi[1].max(p.y[i]);
        hi[2] = hi[2].max(p.z[i]);
    }
    (lo, hi)
}

/// Axis-aligned bounds `(min, max)` of the points ([`EMPTY_BOUNDS`] for no points).
pub fn bounds(p: Soa3) -> ([f32; 3], [f32; 3]) {
    bounds_scalar(p)
}

/// Scalar reference of [`bounds_indexed`].
pub fn bounds_indexed_scalar(p: Soa3, idx: &[u32]) -> ([f32; 3], [f32; 3]) {
    let (mut lo, mut hi) = EMPTY_BOUNDS;
    for &i in idx {
        let i = i as usize;
        lo[0] = lo[0].min(p.x[i]);
        lo[1] = lo[1].min(p.y[i]);
        lo[2] = lo[2].min(p.z[i]);
        hi[0] = hi[0].max(p.x[i]);
        hi[1] = hi[1].max(p.y[i]);
        hi[2] = hi[2].max(p.z[i]);
    }
    (lo, hi)
}

/// Axis-aligned bounds of the points `p[idx[k]]`.
pub fn bounds_indexed(p: Soa3, idx: &[u32]) -> ([f32; 3], [f32; 3]) {
    bounds_indexed_scalar(p, idx)
}
