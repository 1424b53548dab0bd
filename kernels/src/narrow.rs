//! Front filters of the exact narrow phase: per-triangle bounding boxes, and box-box tests
//! for batches of triangle pairs, so the exact triangle-triangle test only runs on pairs whose
//! boxes overlap.
//!
//! Typical use for a leaf pair: [`triangle_bounds`] for the triangles of each leaf (into
//! caller-owned scratch), then [`tri_aabb_overlap_row`] for each triangle of one leaf against
//! all triangles of the other (contiguous, no gather), or [`tri_aabb_overlap_pairs`] for an
//! arbitrary list of candidate pairs.
//!
//! Boxes are closed (touching counts) and NaN never overlaps, exactly like
//! [`crate::overlap::aabb_pairs`]; results are bit-identical to the `*_scalar` references on
//! every backend.

use crate::lanes::{load, store_f32, store_u32, u32_array};
use crate::overlap::{aabbs_overlap_simd, AabbPairs, AabbSoa};
use crate::refit::widen_simd;
use crate::{Soa3, MAX_LANES};
use pulp::{Simd, WithSimd};

/// Writable axis-aligned boxes in SoA form (the output of [`triangle_bounds`]).
#[derive(Debug)]
pub struct AabbSoaMut<'a> {
    pub min_x: &'a mut [f32],
    pub min_y: &'a mut [f32],
    pub min_z: &'a mut [f32],
    pub max_x: &'a mut [f32],
    pub max_y: &'a mut [f32],
    pub max_z: &'a mut [f32],
}

impl AabbSoaMut<'_> {
    /// The shortest of the six arrays.
    pub fn len(&self) -> usize {
        [
            self.min_x.len(),
            self.min_y.len(),
            self.min_z.len(),
            self.max_x.len(),
            self.max_y.len(),
            self.max_z.len(),
        ]
        .into_iter()
        .min()
        .unwrap_or(0)
    }

    /// True if any array is empty.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// A read-only view.
    pub fn as_soa(&self) -> AabbSoa<'_> {
        AabbSoa {
            min_x: self.min_x,
            min_y: self.min_y,
            min_z: self.min_z,
            max_x: self.max_x,
            max_y: self.max_y,
            max_z: self.max_z,
        }
    }
}

// ---------------------------------------------------------------------------------------
// triangle_bounds

/// Scalar reference of [`triangle_bounds`].
pub fn triangle_bounds_scalar(points: Soa3, tris: &[[u32; 3]], out: AabbSoaMut) {
    assert!(
        out.len() >= tris.len(),
        "triangle_bounds: out is shorter than tris"
    );
    for (t, tri) in tris.iter().enumerate() {
        let (mut lo, mut hi) = crate::refit::EMPTY_BOUNDS;
        for &v in tri {
            let q = points.get(v as usize);
            for a in 0..3 {
                if q[a] < lo[a] {
                    lo[a] = q[a];
                }
                if q[a] > hi[a] {
                    hi[a] = q[a];
                }
            }
        }
        out.min_x[t] = lo[0];
        out.min_y[t] = lo[1];
        out.min_z[t] = lo[2];
        out.max_x[t] = hi[0];
        out.max_y[t] = hi[1];
        out.max_z[t] = hi[2];
    }
}

/// Axis-aligned box of each triangle: `out.*[t]` for `t in 0..tris.len()` is the box of the
/// vertices `points[tris[t][0..3]]`. Entries of `out` past `tris.len()` are untouched.
///
/// Same policy as [`crate::refit::bounds`]: starting from the empty box, a coordinate widens
/// the box only if strictly outside it, so NaN coordinates are skipped (an axis whose three
/// coordinates are NaN stays empty, `+inf..-inf`, and never overlaps).
///
/// Panics if `out` is shorter than `tris` or a vertex index is out of range.
pub fn triangle_bounds(points: Soa3, tris: &[[u32; 3]], out: AabbSoaMut) {
    crate::arch().dispatch(TriangleBounds { points, tris, out })
}

/// [`triangle_bounds`] on the backend `simd`.
pub fn triangle_bounds_with<S: Simd>(simd: S, points: Soa3, tris: &[[u32; 3]], out: AabbSoaMut) {
    simd.vectorize(TriangleBounds { points, tris, out })
}

struct TriangleBounds<'a> {
    points: Soa3<'a>,
    tris: &'a [[u32; 3]],
    out: AabbSoaMut<'a>,
}

impl WithSimd for TriangleBounds<'_> {
    type Output = ();
    #[inline(always)]
    fn with_simd<S: Simd>(self, simd: S) {
        triangle_bounds_simd(simd, self.points, self.tris, self.out)
    }
}

#[inline(always)]
fn triangle_bounds_simd<S: Simd>(simd: S, p: Soa3, tris: &[[u32; 3]], out: AabbSoaMut) {
    assert!(
        out.len() >= tris.len(),
        "triangle_bounds: out is shorter than tris"
    );
    let lanes = S::F32_LANES;
    assert!(lanes <= MAX_LANES);
    let n = tris.len();
    let outs = [
        out.min_x, out.min_y, out.min_z, out.max_x, out.max_y, out.max_z,
    ];
    let mut k = 0;
    while k < n {
        let m = lanes.min(n - k);
        // buf[3 * corner + axis][lane]; padding lanes are NaN (their box stays empty and is
        // not stored).
        let mut buf = [[f32::NAN; MAX_LANES]; 9];
        for (l, tri) in tris[k..k + m].iter().enumerate() {
            for (c, &v) in tri.iter().enumerate() {
                let v = v as usize;
                buf[3 * c][l] = p.x[v];
                buf[3 * c + 1][l] = p.y[v];
                buf[3 * c + 2][l] = p.z[v];
            }
        }
        for a in 0..3 {
            let mut lo = simd.splat_f32s(f32::INFINITY);
            let mut hi = simd.splat_f32s(f32::NEG_INFINITY);
            for c in 0..3 {
                widen_simd(simd, &mut lo, &mut hi, load::<S>(&buf[3 * c + a]));
            }
            if m == lanes {
                store_f32::<S>(&mut outs[a][k..k + m], lo);
                store_f32::<S>(&mut outs[3 + a][k..k + m], hi);
            } else {
                simd.partial_store_f32s(&mut outs[a][k..k + m], lo);
                simd.partial_store_f32s(&mut outs[3 + a][k..k + m], hi);
            }
        }
        k += m;
    }
}

// ---------------------------------------------------------------------------------------
// tri_aabb_overlap_pairs

/// Scalar reference of [`tri_aabb_overlap_pairs`].
pub fn tri_aabb_overlap_pairs_scalar(
    a: AabbSoa,
    b: AabbSoa,
    ta: &[u32],
    tb: &[u32],
    out: &mut [u32],
) -> usize {
    crate::overlap::aabb_pairs_scalar(a, b, ta, tb, out)
}

/// Triangle-box filter for a batch of candidate triangle pairs `(ta[k], tb[k])`: `a` and `b`
/// hold triangle boxes (e.g. from [`triangle_bounds`]); `out[k] = 1` when the closed boxes
/// overlap, else `0`; returns the number of overlapping pairs. The same test and kernel as
/// [`crate::overlap::aabb_pairs`], named for the narrow phase.
pub fn tri_aabb_overlap_pairs(
    a: AabbSoa,
    b: AabbSoa,
    ta: &[u32],
    tb: &[u32],
    out: &mut [u32],
) -> usize {
    crate::overlap::aabb_pairs(a, b, ta, tb, out)
}

/// [`tri_aabb_overlap_pairs`] on the backend `simd`.
pub fn tri_aabb_overlap_pairs_with<S: Simd>(
    simd: S,
    a: AabbSoa,
    b: AabbSoa,
    ta: &[u32],
    tb: &[u32],
    out: &mut [u32],
) -> usize {
    simd.vectorize(AabbPairs {
        a,
        b,
        ia: ta,
        ib: tb,
        out,
    })
}

// ---------------------------------------------------------------------------------------
// tri_aabb_overlap_row

/// Scalar reference of [`tri_aabb_overlap_row`].
pub fn tri_aabb_overlap_row_scalar(a: ([f32; 3], [f32; 3]), b: AabbSoa, out: &mut [u32]) -> usize {
    let n = row_len(b, out);
    let (lo, hi) = a;
    let mut hits = 0;
    for j in 0..n {
        let hit = lo[0] <= b.max_x[j]
            && b.min_x[j] <= hi[0]
            && lo[1] <= b.max_y[j]
            && b.min_y[j] <= hi[1]
            && lo[2] <= b.max_z[j]
            && b.min_z[j] <= hi[2];
        out[j] = hit as u32;
        hits += hit as usize;
    }
    hits
}

fn row_len(b: AabbSoa, out: &[u32]) -> usize {
    let n = b.min_x.len();
    assert!(
        [
            b.min_y.len(),
            b.min_z.len(),
            b.max_x.len(),
            b.max_y.len(),
            b.max_z.len()
        ]
        .iter()
        .all(|&l| l == n),
        "tri_aabb_overlap_row: ragged box arrays"
    );
    assert!(
        out.len() >= n,
        "tri_aabb_overlap_row: out is shorter than b"
    );
    n
}

/// One box `a = (min, max)` against every box of `b` (all six arrays of equal length `n`):
/// `out[j] = 1` when `a` and `b[j]` overlap (closed, NaN never overlaps), else `0`, for
/// `j in 0..n`; returns the number of overlaps. Contiguous loads, no gather: the fast path of
/// the narrow-phase filter (one triangle of one leaf against the triangle run of another).
pub fn tri_aabb_overlap_row(a: ([f32; 3], [f32; 3]), b: AabbSoa, out: &mut [u32]) -> usize {
    crate::arch().dispatch(TriAabbRow { a, b, out })
}

/// [`tri_aabb_overlap_row`] on the backend `simd`.
pub fn tri_aabb_overlap_row_with<S: Simd>(
    simd: S,
    a: ([f32; 3], [f32; 3]),
    b: AabbSoa,
    out: &mut [u32],
) -> usize {
    simd.vectorize(TriAabbRow { a, b, out })
}

struct TriAabbRow<'a> {
    a: ([f32; 3], [f32; 3]),
    b: AabbSoa<'a>,
    out: &'a mut [u32],
}

impl WithSimd for TriAabbRow<'_> {
    type Output = usize;
    #[inline(always)]
    fn with_simd<S: Simd>(self, simd: S) -> usize {
        tri_aabb_overlap_row_simd(simd, self.a, self.b, self.out)
    }
}

#[inline(always)]
fn tri_aabb_overlap_row_simd<S: Simd>(
    simd: S,
    a: ([f32; 3], [f32; 3]),
    b: AabbSoa,
    out: &mut [u32],
) -> usize {
    let n = row_len(b, out);
    let lanes = S::F32_LANES;
    let mut v = [simd.splat_f32s(0.0); 12];
    for f in 0..3 {
        v[f] = simd.splat_f32s(a.0[f]);
        v[3 + f] = simd.splat_f32s(a.1[f]);
    }
    let (one, zero) = (simd.splat_u32s(1), simd.splat_u32s(0));
    let cols = [b.min_x, b.min_y, b.min_z, b.max_x, b.max_y, b.max_z];
    let mut count = zero;
    let full = n - n % lanes;
    let mut k = 0;
    while k < full {
        for f in 0..6 {
            v[6 + f] = load::<S>(&cols[f][k..]);
        }
        let hit = simd.select_u32s(aabbs_overlap_simd(simd, &v), one, zero);
        store_u32::<S>(&mut out[k..k + lanes], hit);
        count = simd.add_u32s(count, hit);
        k += lanes;
    }
    if k < n {
        let mut buf = [[f32::NAN; MAX_LANES]; 6];
        for f in 0..6 {
            buf[f][..n - k].copy_from_slice(&cols[f][k..n]);
            v[6 + f] = load::<S>(&buf[f]);
        }
        let hit = simd.select_u32s(aabbs_overlap_simd(simd, &v), one, zero);
        simd.partial_store_u32s(&mut out[k..n], hit);
        count = simd.add_u32s(count, hit);
    }
    let mut total = 0;
    for &c in u32_array::<S>(&count) {
        total += c as usize;
    }
    total
}
