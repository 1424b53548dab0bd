//! Front filters of the exact narrow phase: one triangle (the *probe*) against a contiguous
//! *row* of triangles (another leaf's run), each answer a bit mask (bit `j` for row triangle
//! `j`). A row's slices hold at most [`MAX_ROW`] entries of which the first `n` are tested;
//! the rest is padding, computed and masked off (see [`crate::overlap`] on padding):
//!
//! - [`box_row`]: the closed boxes overlap (comparisons only: exact);
//! - [`share_row`]: the triangles share a vertex index (self-collision skips those pairs);
//! - [`plane_row`]: the pair is *not* proven disjoint by a separating plane: neither
//!   triangle has all three corners strictly on one side of the other's plane, as certified
//!   by a semi-static floating-point filter (below). A pair it drops is certainly disjoint;
//!   every other pair goes to the exact test, so contacts are unchanged.
//!
//! The plane filter evaluates, in `f64` (every `f32` input converts exactly),
//! `s = det[u, v, e]` with `u = b - a`, `v = c - a` (the plane triangle's edges from corner
//! `a`) and `e = d - a` (the tested corner), as `(e_x N_x + e_y N_y) + e_z N_z` with
//! `N = u x v`, and the permanent `P = (|e_x| M_x + |e_y| M_y) + |e_z| M_z` with
//! `M_x = |u_y v_z| + |u_z v_y|` (and cyclically), from the same rounded products. That is
//! Shewchuk's `orient3d` arithmetic (a Laplace expansion of the same determinant, each term a
//! rounded difference times a rounded 2x2 minor of rounded differences), whose error is at
//! most `(7 + 56 eps) eps P` (eps = 2^-53); we certify a sign only when `|s| > 8 eps P`. No
//! `f64` product of `f32` differences can underflow or overflow, so the bound always holds.
//! A degenerate plane triangle has `N = M = 0` and certifies nothing. NaN certifies nothing.
//!
//! Results are bit-identical to the `*_scalar` references on every backend (same operation
//! order, no fused multiply-add).

use crate::lanes::{load_prefix, load_prefix_f64, load_prefix_u32, mask_bits, mask_bits64};
use crate::overlap::AabbSoa;
use pulp::{Simd, WithSimd};

/// Largest row: the bits of the `u64` mask.
pub const MAX_ROW: usize = 64;

/// The certification factor of the plane filter: `8 eps`, `eps = 2^-53`.
pub const PLANE_ERR: f64 = 8.0 * (f64::EPSILON / 2.0);

/// The row's slice length, checking `n <= len <= MAX_ROW`.
#[inline(always)]
fn row_len(len: usize, n: usize) -> usize {
    assert!(len <= MAX_ROW, "a row holds at most {MAX_ROW} triangles");
    assert!(n <= len, "more entries tested than the row holds");
    len
}

/// The low `n` bits set (`n <= 64`).
#[inline(always)]
fn low_bits64(n: usize) -> u64 {
    if n >= 64 {
        u64::MAX
    } else {
        (1u64 << n) - 1
    }
}

// ---------------------------------------------------------------------------------------
// box_row

/// Scalar reference of [`box_row`].
pub fn box_row_scalar(lo: [f32; 3], hi: [f32; 3], row: AabbSoa, n: usize) -> u64 {
    row_len(row.len(), n);
    let mut bits = 0;
    for j in 0..n {
        bits |= (crate::overlap::aabbs_overlap((lo, hi), row.get(j)) as u64) << j;
    }
    bits
}

/// Box `(lo, hi)` against the first `n` boxes of `row`: bit `j` set iff they overlap
/// (closed; NaN never overlaps).
pub fn box_row(lo: [f32; 3], hi: [f32; 3], row: AabbSoa, n: usize) -> u64 {
    crate::arch().dispatch(BoxRow { lo, hi, row, n })
}

struct BoxRow<'a> {
    lo: [f32; 3],
    hi: [f32; 3],
    row: AabbSoa<'a>,
    n: usize,
}

impl WithSimd for BoxRow<'_> {
    type Output = u64;
    #[inline(always)]
    fn with_simd<S: Simd>(self, simd: S) -> u64 {
        box_row_with(simd, self.lo, self.hi, self.row, self.n)
    }
}

/// [`box_row`] on the backend `simd` (inlined into the caller's dispatched body).
#[inline(always)]
pub fn box_row_with<S: Simd>(simd: S, lo: [f32; 3], hi: [f32; 3], row: AabbSoa, n: usize) -> u64 {
    let len = row_len(row.len(), n);
    let mins = [&row.min_x[..len], &row.min_y[..len], &row.min_z[..len]];
    let maxs = [&row.max_x[..len], &row.max_y[..len], &row.max_z[..len]];
    // No closures in SIMD bodies (see `overlap::aabb_block_with`).
    let plo = [
        simd.splat_f32s(lo[0]),
        simd.splat_f32s(lo[1]),
        simd.splat_f32s(lo[2]),
    ];
    let phi = [
        simd.splat_f32s(hi[0]),
        simd.splat_f32s(hi[1]),
        simd.splat_f32s(hi[2]),
    ];
    let mut bits = 0u64;
    let mut base = 0;
    while base < n {
        let end = (base + S::F32_LANES).min(len);
        let mut hit = simd.less_than_or_equal_f32s(plo[0], load_prefix(simd, &maxs[0][base..end]));
        hit = simd.and_m32s(
            hit,
            simd.less_than_or_equal_f32s(load_prefix(simd, &mins[0][base..end]), phi[0]),
        );
        for k in 1..3 {
            hit = simd.and_m32s(
                hit,
                simd.less_than_or_equal_f32s(plo[k], load_prefix(simd, &maxs[k][base..end])),
            );
            hit = simd.and_m32s(
                hit,
                simd.less_than_or_equal_f32s(load_prefix(simd, &mins[k][base..end]), phi[k]),
            );
        }
        bits |= (u64::from(mask_bits(simd, hit)) & low_bits64(n - base)) << base;
        base = end;
    }
    bits
}

// ---------------------------------------------------------------------------------------
// share_row

/// Scalar reference of [`share_row`].
pub fn share_row_scalar(v: [u32; 3], row: [&[u32]; 3], n: usize) -> u64 {
    row_len(row[0].len(), n);
    let mut bits = 0;
    for j in 0..n {
        let shares = (0..3).any(|c| v.contains(&row[c][j]));
        bits |= (shares as u64) << j;
    }
    bits
}

/// The probe's corner indices `v` against the first `n` of the row's (`row[c][j]`: corner
/// `c` of triangle `j`, three slices of equal length): bit `j` set iff they share an index.
pub fn share_row(v: [u32; 3], row: [&[u32]; 3], n: usize) -> u64 {
    crate::arch().dispatch(ShareRow { v, row, n })
}

struct ShareRow<'a> {
    v: [u32; 3],
    row: [&'a [u32]; 3],
    n: usize,
}

impl WithSimd for ShareRow<'_> {
    type Output = u64;
    #[inline(always)]
    fn with_simd<S: Simd>(self, simd: S) -> u64 {
        share_row_with(simd, self.v, self.row, self.n)
    }
}

/// [`share_row`] on the backend `simd`.
#[inline(always)]
pub fn share_row_with<S: Simd>(simd: S, v: [u32; 3], row: [&[u32]; 3], n: usize) -> u64 {
    let len = row_len(row[0].len(), n);
    let cols = [&row[0][..len], &row[1][..len], &row[2][..len]];
    let pv = [
        simd.splat_u32s(v[0]),
        simd.splat_u32s(v[1]),
        simd.splat_u32s(v[2]),
    ];
    let mut bits = 0u64;
    let mut base = 0;
    while base < n {
        let end = (base + S::U32_LANES).min(len);
        let mut hit = simd.equal_u32s(pv[0], load_prefix_u32(simd, &cols[0][base..end]));
        for c in 0..3 {
            let w = load_prefix_u32(simd, &cols[c][base..end]);
            for (k, &p) in pv.iter().enumerate() {
                if c == 0 && k == 0 {
                    continue;
                }
                hit = simd.or_m32s(hit, simd.equal_u32s(p, w));
            }
        }
        bits |= (u64::from(mask_bits(simd, hit)) & low_bits64(n - base)) << base;
        base = end;
    }
    bits
}

// ---------------------------------------------------------------------------------------
// plane_row

/// A triangle prepared as the probe of [`plane_row`]: its corners in `f64`, and its plane
/// (`N`, `M` of the module doc) from corner 0.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PlaneProbe {
    pub corners: [[f64; 3]; 3],
    pub normal: [f64; 3],
    pub magnitude: [f64; 3],
}

impl PlaneProbe {
    #[inline(always)]
    pub fn new(tri: &[[f32; 3]; 3]) -> Self {
        let corners = tri.map(|p| p.map(f64::from));
        let (normal, magnitude) = plane(&corners);
        Self {
            corners,
            normal,
            magnitude,
        }
    }
}

/// `N = u x v` and `M` (see the module doc) of the triangle `t`.
#[inline(always)]
fn plane(t: &[[f64; 3]; 3]) -> ([f64; 3], [f64; 3]) {
    let u = [t[1][0] - t[0][0], t[1][1] - t[0][1], t[1][2] - t[0][2]];
    let v = [t[2][0] - t[0][0], t[2][1] - t[0][1], t[2][2] - t[0][2]];
    let (yz, zy) = (u[1] * v[2], u[2] * v[1]);
    let (zx, xz) = (u[2] * v[0], u[0] * v[2]);
    let (xy, yx) = (u[0] * v[1], u[1] * v[0]);
    (
        [yz - zy, zx - xz, xy - yx],
        [
            yz.abs() + zy.abs(),
            zx.abs() + xz.abs(),
            xy.abs() + yx.abs(),
        ],
    )
}

/// Side of `d` against the plane `(a, n, m)`: `1` certainly positive, `-1` certainly
/// negative, `0` unknown (or on the plane).
#[inline(always)]
fn side(a: &[f64; 3], n: &[f64; 3], m: &[f64; 3], d: &[f64; 3]) -> i32 {
    let e = [d[0] - a[0], d[1] - a[1], d[2] - a[2]];
    let s = e[0] * n[0] + e[1] * n[1] + e[2] * n[2];
    let p = e[0].abs() * m[0] + e[1].abs() * m[1] + e[2].abs() * m[2];
    let bound = PLANE_ERR * p;
    i32::from(s > bound) - i32::from(s < -bound)
}

/// Whether the triangle `d` lies certainly strictly on one side of the plane `(a, n, m)`.
#[inline(always)]
fn separated(a: &[f64; 3], n: &[f64; 3], m: &[f64; 3], d: &[[f64; 3]; 3]) -> bool {
    let s = d.map(|p| side(a, n, m, &p));
    (s[0] == 1 && s[1] == 1 && s[2] == 1) || (s[0] == -1 && s[1] == -1 && s[2] == -1)
}

/// Scalar reference of [`plane_row`].
pub fn plane_row_scalar(probe: &PlaneProbe, row: [[&[f32]; 3]; 3], candidates: u64) -> u64 {
    let n = row_len(row[0][0].len(), 0);
    let mut keep = 0;
    for j in 0..n {
        if candidates >> j & 1 == 0 {
            continue;
        }
        let t: [[f64; 3]; 3] =
            std::array::from_fn(|c| std::array::from_fn(|k| f64::from(row[c][k][j])));
        let p = &probe.corners;
        let (tn, tm) = plane(&t);
        let sep =
            separated(&p[0], &probe.normal, &probe.magnitude, &t) || separated(&t[0], &tn, &tm, p);
        keep |= (!sep as u64) << j;
    }
    keep
}

/// Of the `candidates` (bits of row triangles), those not proven disjoint from the probe by a
/// separating plane (the probe's plane, or the row triangle's). `row[c][k][j]` is coordinate
/// `k` of corner `c` of row triangle `j` (nine slices of equal length, at most
/// [`MAX_ROW`]); candidate bits past the row are dropped. Only lane blocks holding a
/// candidate are evaluated.
pub fn plane_row(probe: &PlaneProbe, row: [[&[f32]; 3]; 3], candidates: u64) -> u64 {
    crate::arch().dispatch(PlaneRow {
        probe,
        row,
        candidates,
    })
}

struct PlaneRow<'a> {
    probe: &'a PlaneProbe,
    row: [[&'a [f32]; 3]; 3],
    candidates: u64,
}

impl WithSimd for PlaneRow<'_> {
    type Output = u64;
    #[inline(always)]
    fn with_simd<S: Simd>(self, simd: S) -> u64 {
        plane_row_with(simd, self.probe, self.row, self.candidates)
    }
}

/// Lanes of `f64` the staging buffers hold (AVX-512: 8).
const MAX_F64_LANES: usize = 8;

/// [`plane_row`] on the backend `simd`.
#[inline(always)]
pub fn plane_row_with<S: Simd>(
    simd: S,
    probe: &PlaneProbe,
    row: [[&[f32]; 3]; 3],
    candidates: u64,
) -> u64 {
    let n = row_len(row[0][0].len(), 0);
    let lanes = S::F64_LANES;
    assert!(lanes <= MAX_F64_LANES);
    // No closures in SIMD bodies (see `overlap::aabb_block_with`).
    let pc = [
        splat3(simd, probe.corners[0]),
        splat3(simd, probe.corners[1]),
        splat3(simd, probe.corners[2]),
    ];
    let (pn, pm) = (splat3(simd, probe.normal), splat3(simd, probe.magnitude));
    let err = simd.splat_f64s(PLANE_ERR);
    let mut keep = 0u64;
    let mut base = 0;
    while base < n {
        let end = (base + lanes).min(n);
        let chunk = candidates >> base & low_bits64(end - base);
        if chunk != 0 {
            // PERF: pulp has no f32 -> f64 conversion; a plain loop into a small buffer is
            // compiled to the backend's convert instruction.
            let mut buf = [[[0.0f64; MAX_F64_LANES]; 3]; 3];
            for c in 0..3 {
                for k in 0..3 {
                    let src = &row[c][k][base..end];
                    if src.len() == lanes {
                        // The common case (rows padded to whole vectors): a fixed-length
                        // loop, one convert instruction.
                        for l in 0..lanes {
                            buf[c][k][l] = f64::from(src[l]);
                        }
                    } else {
                        for (dst, &s) in buf[c][k].iter_mut().zip(src) {
                            *dst = f64::from(s);
                        }
                    }
                }
            }
            let zero = simd.splat_f64s(0.0);
            let mut t = [[zero; 3]; 3];
            for c in 0..3 {
                for k in 0..3 {
                    t[c][k] = load_prefix_f64(simd, &buf[c][k][..end - base]);
                }
            }
            // The row triangles' corners against the probe's plane.
            let sep_a = separated_simd(simd, err, &pc[0], &pn, &pm, &t);
            // The probe's corners against the row triangles' planes.
            let (tn, tm) = plane_simd(simd, &t);
            let sep_b = separated_simd(simd, err, &t[0], &tn, &tm, &pc);
            let sep = mask_bits64(simd, simd.or_m64s(sep_a, sep_b));
            keep |= (chunk & !u64::from(sep)) << base;
        }
        base = end;
    }
    keep
}

#[inline(always)]
fn splat3<S: Simd>(simd: S, v: [f64; 3]) -> [S::f64s; 3] {
    [
        simd.splat_f64s(v[0]),
        simd.splat_f64s(v[1]),
        simd.splat_f64s(v[2]),
    ]
}

/// The lane-wise [`plane`].
#[inline(always)]
fn plane_simd<S: Simd>(simd: S, t: &[[S::f64s; 3]; 3]) -> ([S::f64s; 3], [S::f64s; 3]) {
    let mut u = t[0];
    let mut v = t[0];
    for k in 0..3 {
        u[k] = simd.sub_f64s(t[1][k], t[0][k]);
        v[k] = simd.sub_f64s(t[2][k], t[0][k]);
    }
    let (yz, zy) = (simd.mul_f64s(u[1], v[2]), simd.mul_f64s(u[2], v[1]));
    let (zx, xz) = (simd.mul_f64s(u[2], v[0]), simd.mul_f64s(u[0], v[2]));
    let (xy, yx) = (simd.mul_f64s(u[0], v[1]), simd.mul_f64s(u[1], v[0]));
    (
        [
            simd.sub_f64s(yz, zy),
            simd.sub_f64s(zx, xz),
            simd.sub_f64s(xy, yx),
        ],
        [
            abs_sum(simd, yz, zy),
            abs_sum(simd, zx, xz),
            abs_sum(simd, xy, yx),
        ],
    )
}

#[inline(always)]
fn abs_sum<S: Simd>(simd: S, a: S::f64s, b: S::f64s) -> S::f64s {
    simd.add_f64s(simd.abs_f64s(a), simd.abs_f64s(b))
}

/// The lane-wise [`separated`]: whether the three points `d` are certainly strictly on one
/// side of the plane `(a, n, m)`.
#[inline(always)]
fn separated_simd<S: Simd>(
    simd: S,
    err: S::f64s,
    a: &[S::f64s; 3],
    n: &[S::f64s; 3],
    m: &[S::f64s; 3],
    d: &[[S::f64s; 3]; 3],
) -> S::m64s {
    let mut pos = simd.greater_than_f64s(err, simd.splat_f64s(0.0)); // all true
    let mut neg = pos;
    for p in d {
        let e = [
            simd.sub_f64s(p[0], a[0]),
            simd.sub_f64s(p[1], a[1]),
            simd.sub_f64s(p[2], a[2]),
        ];
        let s = simd.add_f64s(
            simd.add_f64s(simd.mul_f64s(e[0], n[0]), simd.mul_f64s(e[1], n[1])),
            simd.mul_f64s(e[2], n[2]),
        );
        let perm = simd.add_f64s(
            simd.add_f64s(
                simd.mul_f64s(simd.abs_f64s(e[0]), m[0]),
                simd.mul_f64s(simd.abs_f64s(e[1]), m[1]),
            ),
            simd.mul_f64s(simd.abs_f64s(e[2]), m[2]),
        );
        let bound = simd.mul_f64s(err, perm);
        let is_pos = simd.greater_than_f64s(s, bound);
        let is_neg = simd.less_than_f64s(s, simd.sub_f64s(simd.splat_f64s(0.0), bound));
        pos = simd.and_m64s(pos, is_pos);
        neg = simd.and_m64s(neg, is_neg);
    }
    simd.or_m64s(pos, neg)
}
