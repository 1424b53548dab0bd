//! Wide node tests: one bounding volume (the *probe*) against a contiguous *block* of
//! bounding volumes, typically the children of one node stored side by side in
//! structure-of-arrays buffers (Embree's collider pattern). The answer is a bit mask: bit `k`
//! is set iff the probe and block entry `k` overlap (closed volumes: touching counts). The
//! caller walks the set bits, so a pair that fails never costs more than its lane.
//!
//! A block's slices hold at most [`MAX_BLOCK`] entries (the bits of the `u32` mask), of
//! which the first `n` are tested; the others are padding whose lanes are computed and
//! masked off. Padding a block to a multiple of the lane count lets every load be a full
//! vector load (pulp's partial loads are out-of-line calls on x86-v3); a tail shorter than
//! the lane count is read with a partial load, so nothing outside the slices is ever read.
//!
//! Exactness: comparisons and a fixed operation order without fused multiply-add, so masks
//! are bit-identical to the `*_scalar` references on every backend. NaN policy: a NaN in the
//! probe or an entry makes the pair not overlap, on every backend.

use crate::lanes::{load_prefix, mask_bits};
use crate::Tile;
use pulp::{Simd, WithSimd};

/// Largest block: the bits of the mask.
pub const MAX_BLOCK: usize = 32;

/// Spheres (the SBV hierarchy; DH nodes with their staged centres): a [`Tile`] of four
/// fields, centre x, y, z and radius.
#[derive(Clone, Copy, Debug)]
pub struct SphereSoa<'a> {
    tile: Tile<'a>,
}

impl<'a> SphereSoa<'a> {
    /// Panics unless `tile` has four fields.
    #[inline]
    pub fn new(tile: Tile<'a>) -> Self {
        assert!(tile.has_fields(4), "SphereSoa: cx, cy, cz, r");
        Self { tile }
    }

    #[inline(always)]
    pub fn cx(&self) -> &'a [f32] {
        self.tile.field(0)
    }
    #[inline(always)]
    pub fn cy(&self) -> &'a [f32] {
        self.tile.field(1)
    }
    #[inline(always)]
    pub fn cz(&self) -> &'a [f32] {
        self.tile.field(2)
    }
    #[inline(always)]
    pub fn r(&self) -> &'a [f32] {
        self.tile.field(3)
    }

    /// Entries per field.
    #[inline(always)]
    pub fn len(&self) -> usize {
        self.tile.stride()
    }

    #[inline(always)]
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Entry `k` as `(centre, radius)`.
    #[inline(always)]
    pub fn get(&self, k: usize) -> ([f32; 3], f32) {
        ([self.cx()[k], self.cy()[k], self.cz()[k]], self.r()[k])
    }
}

/// Axis-aligned boxes: a [`Tile`] of six fields, min x, y, z and max x, y, z.
#[derive(Clone, Copy, Debug)]
pub struct AabbSoa<'a> {
    tile: Tile<'a>,
}

impl<'a> AabbSoa<'a> {
    /// Panics unless `tile` has six fields.
    #[inline]
    pub fn new(tile: Tile<'a>) -> Self {
        assert!(tile.has_fields(6), "AabbSoa: min xyz, max xyz");
        Self { tile }
    }

    /// Min (`k` = 0, 1, 2) of every box.
    #[inline(always)]
    pub fn min(&self, k: usize) -> &'a [f32] {
        self.tile.field(k)
    }
    /// Max (`k` = 0, 1, 2) of every box.
    #[inline(always)]
    pub fn max(&self, k: usize) -> &'a [f32] {
        self.tile.field(3 + k)
    }

    /// Entries per field.
    #[inline(always)]
    pub fn len(&self) -> usize {
        self.tile.stride()
    }

    #[inline(always)]
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Entry `k` as `(min, max)`.
    #[inline(always)]
    pub fn get(&self, k: usize) -> ([f32; 3], [f32; 3]) {
        (
            [self.min(0)[k], self.min(1)[k], self.min(2)[k]],
            [self.max(0)[k], self.max(1)[k], self.max(2)[k]],
        )
    }
}

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

/// The block's slice length, checking `n <= len <= MAX_BLOCK`.
#[inline(always)]
fn block_len(len: usize, n: usize) -> usize {
    assert!(
        len <= MAX_BLOCK,
        "a block holds at most {MAX_BLOCK} entries"
    );
    assert!(n <= len, "more entries tested than the block holds");
    len
}

// ---------------------------------------------------------------------------------------
// sphere_block

/// Scalar reference of [`sphere_block`] (one pair at a time).
pub fn sphere_block_scalar(c: [f32; 3], r: f32, b: SphereSoa, n: usize) -> u32 {
    block_len(b.len(), n);
    let mut bits = 0;
    for k in 0..n {
        let (bc, br) = b.get(k);
        bits |= (spheres_overlap(c, r, bc, br) as u32) << k;
    }
    bits
}

/// Sphere `(c, r)` against the first `n` entries of the block `b` (four slices of equal
/// length, at most [`MAX_BLOCK`], at least `n`): bit `k` set iff they overlap.
pub fn sphere_block(c: [f32; 3], r: f32, b: SphereSoa, n: usize) -> u32 {
    crate::arch().dispatch(SphereBlock { c, r, b, n })
}

struct SphereBlock<'a> {
    c: [f32; 3],
    r: f32,
    b: SphereSoa<'a>,
    n: usize,
}

impl WithSimd for SphereBlock<'_> {
    type Output = u32;
    #[inline(always)]
    fn with_simd<S: Simd>(self, simd: S) -> u32 {
        sphere_block_with(simd, self.c, self.r, self.b, self.n)
    }
}

/// [`sphere_block`] on the backend `simd` (inlined into the caller's dispatched body: call
/// it from inside a `pulp::WithSimd` so a whole traversal dispatches once).
#[inline(always)]
pub fn sphere_block_with<S: Simd>(simd: S, c: [f32; 3], r: f32, b: SphereSoa, n: usize) -> u32 {
    let len = block_len(b.len(), n);
    #[cfg(target_arch = "x86_64")]
    if let Some(v3) = half_width(simd, len) {
        return sphere_block_with(v3, c, r, b, n);
    }
    let (cx, cy, cz, rr) = (b.cx(), b.cy(), b.cz(), b.r());
    let (px, py, pz, pr) = (
        simd.splat_f32s(c[0]),
        simd.splat_f32s(c[1]),
        simd.splat_f32s(c[2]),
        simd.splat_f32s(r),
    );
    let mut bits = 0;
    let mut base = 0;
    while base < n {
        let end = (base + S::F32_LANES).min(len);
        let dx = simd.sub_f32s(px, load_prefix(simd, &cx[base..end]));
        let dy = simd.sub_f32s(py, load_prefix(simd, &cy[base..end]));
        let dz = simd.sub_f32s(pz, load_prefix(simd, &cz[base..end]));
        let d2 = simd.add_f32s(
            simd.add_f32s(simd.mul_f32s(dx, dx), simd.mul_f32s(dy, dy)),
            simd.mul_f32s(dz, dz),
        );
        let rs = simd.add_f32s(pr, load_prefix(simd, &rr[base..end]));
        let hit = simd.less_than_or_equal_f32s(d2, simd.mul_f32s(rs, rs));
        bits |= (mask_bits(simd, hit) & low_bits(n - base)) << base;
        base = end;
    }
    bits
}

// ---------------------------------------------------------------------------------------
// aabb_block

/// Scalar reference of [`aabb_block`] (one pair at a time, early exit per axis).
pub fn aabb_block_scalar(lo: [f32; 3], hi: [f32; 3], b: AabbSoa, n: usize) -> u32 {
    block_len(b.len(), n);
    let mut bits = 0;
    for k in 0..n {
        bits |= (aabbs_overlap((lo, hi), b.get(k)) as u32) << k;
    }
    bits
}

/// Box `(lo, hi)` against the first `n` entries of the block `b` (six slices of equal
/// length, at most [`MAX_BLOCK`], at least `n`): bit `k` set iff they overlap.
pub fn aabb_block(lo: [f32; 3], hi: [f32; 3], b: AabbSoa, n: usize) -> u32 {
    crate::arch().dispatch(AabbBlock { lo, hi, b, n })
}

struct AabbBlock<'a> {
    lo: [f32; 3],
    hi: [f32; 3],
    b: AabbSoa<'a>,
    n: usize,
}

impl WithSimd for AabbBlock<'_> {
    type Output = u32;
    #[inline(always)]
    fn with_simd<S: Simd>(self, simd: S) -> u32 {
        aabb_block_with(simd, self.lo, self.hi, self.b, self.n)
    }
}

/// [`aabb_block`] on the backend `simd` (see [`sphere_block_with`]).
#[inline(always)]
pub fn aabb_block_with<S: Simd>(simd: S, lo: [f32; 3], hi: [f32; 3], b: AabbSoa, n: usize) -> u32 {
    let len = block_len(b.len(), n);
    #[cfg(target_arch = "x86_64")]
    if let Some(v3) = half_width(simd, len) {
        return aabb_block_with(v3, lo, hi, b, n);
    }
    let mins = [b.min(0), b.min(1), b.min(2)];
    let maxs = [b.max(0), b.max(1), b.max(2)];
    // No closures in SIMD bodies: they may be compiled without the dispatched target
    // features and turn every intrinsic into a call.
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
    let mut bits = 0;
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
        bits |= (mask_bits(simd, hit) & low_bits(n - base)) << base;
        base = end;
    }
    bits
}

/// The x86-v3 (8-lane) token for a block of at most 8 entries on x86-v4: an octree's 8
/// children fill half of a 16-lane vector, and Zen 4 runs a 512-bit operation as two
/// 256-bit halves, so the empty half costs as much as the full one (`kernels/sphere_block`
/// 2.2x -> 3.4-3.6x its scalar reference, `aabb_block` 1.7x -> 2.7-2.8x; packing two
/// fields per 16-lane vector gave 2.4x and 2.7x: docs/PERFORMANCE.md, sixteenth sitting).
/// Every x86-v4 CPU has x86-v3.
#[cfg(target_arch = "x86_64")]
#[inline(always)]
fn half_width<S: Simd>(simd: S, len: usize) -> Option<pulp::x86::V3> {
    let v4 = crate::lanes::as_v4(simd)?;
    (2 * len <= S::F32_LANES).then_some(*v4)
}

/// The low `n` bits set (`n <= 32`).
#[inline(always)]
pub(crate) fn low_bits(n: usize) -> u32 {
    if n >= 32 {
        u32::MAX
    } else {
        (1u32 << n) - 1
    }
}

// ---------------------------------------------------------------------------------------
// boxes_meet

/// Closed boxes as six rows of one length: minima x, y, z, then maxima x, y, z (a leaf's
/// triangle or edge boxes). Rows longer than the entries tested are allowed (padding).
pub type BoxRows<'a> = [&'a [f32]; 6];

/// The longest block [`boxes_meet_with`] tests: the bits of a `u64`.
pub const MAX_BOX_ROW: usize = 64;

/// Scalar reference of [`boxes_meet_with`].
pub fn boxes_meet_scalar(lo: [f32; 3], hi: [f32; 3], rows: BoxRows, n: usize) -> u64 {
    box_rows_len(&rows, n);
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

fn box_rows_len(rows: &BoxRows, n: usize) -> usize {
    assert!(n <= MAX_BOX_ROW, "at most {MAX_BOX_ROW} boxes a call");
    let len = rows[0].len();
    assert!(
        rows.iter().all(|r| r.len() == len) && n <= len,
        "six rows of one length, at least n"
    );
    len
}

/// The box `(lo, hi)` against the first `n <= 64` boxes of `rows`: bit `k` set iff they
/// meet (closed boxes; a NaN bound never meets). Comparisons only, so the mask is the
/// same on every backend as [`boxes_meet_scalar`].
#[inline(always)]
pub fn boxes_meet_with<S: Simd>(
    simd: S,
    lo: [f32; 3],
    hi: [f32; 3],
    rows: BoxRows,
    n: usize,
) -> u64 {
    let len = box_rows_len(&rows, n);
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
        let mut hit = simd.less_than_or_equal_f32s(plo[0], load_prefix(simd, &rows[3][base..end]));
        hit = simd.and_m32s(
            hit,
            simd.less_than_or_equal_f32s(load_prefix(simd, &rows[0][base..end]), phi[0]),
        );
        for k in 1..3 {
            hit = simd.and_m32s(
                hit,
                simd.less_than_or_equal_f32s(plo[k], load_prefix(simd, &rows[3 + k][base..end])),
            );
            hit = simd.and_m32s(
                hit,
                simd.less_than_or_equal_f32s(load_prefix(simd, &rows[k][base..end]), phi[k]),
            );
        }
        let valid = if n - base >= 64 {
            u64::MAX
        } else {
            (1u64 << (n - base)) - 1
        };
        bits |= (u64::from(mask_bits(simd, hit)) & valid) << base;
        base = end;
    }
    bits
}
