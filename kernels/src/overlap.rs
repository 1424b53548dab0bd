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

use crate::lanes::{load, load_prefix, mask_bits, swap_halves, IOTA};
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

    /// The four fields side by side.
    #[inline(always)]
    fn data(&self) -> &'a [f32] {
        self.tile.data()
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

    /// The six fields side by side.
    #[inline(always)]
    fn data(&self) -> &'a [f32] {
        self.tile.data()
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
    if 2 * len == S::F32_LANES {
        return sphere_block_paired(simd, c, r, b.data(), n);
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

/// [`sphere_block_with`] for a block of half a vector (an octree's 8 children on 16 lanes):
/// two fields per vector, `[cx | cy]` and `[cz | r]` (`t`: the four fields side by side),
/// the halves combined by one lane swap each, in the reference's operation order
/// (`kernels/sphere_block` 2.2x -> 2.4x its scalar reference, Zen 4).
#[inline(always)]
fn sphere_block_paired<S: Simd>(simd: S, c: [f32; 3], r: f32, t: &[f32], n: usize) -> u32 {
    let half = S::F32_LANES / 2;
    let (v0, v1) = (load::<S>(t), load::<S>(&t[2 * half..]));
    let upper = upper_half::<S>(simd);
    // `[c_x - cx | c_y - cy]`, squared, and each lane plus its other half: `dx^2 + dy^2`.
    let d = simd.sub_f32s(
        simd.select_f32s(upper, simd.splat_f32s(c[1]), simd.splat_f32s(c[0])),
        v0,
    );
    let sq = simd.mul_f32s(d, d);
    let xy = simd.add_f32s(sq, swap_halves(simd, sq));
    // `[c_z - cz | r + rb]` (the lower half as `c_z + (-cz)`: the same value), squared.
    let sign = simd.select_f32s(upper, simd.splat_f32s(1.0), simd.splat_f32s(-1.0));
    let w = simd.add_f32s(
        simd.select_f32s(upper, simd.splat_f32s(r), simd.splat_f32s(c[2])),
        simd.mul_f32s(sign, v1),
    );
    let w2 = simd.mul_f32s(w, w);
    let hit = simd.less_than_or_equal_f32s(simd.add_f32s(xy, w2), swap_halves(simd, w2));
    mask_bits(simd, hit) & low_bits(n)
}

/// The mask of the upper half of the lanes.
#[inline(always)]
fn upper_half<S: Simd>(simd: S) -> S::m32s {
    simd.less_than_or_equal_f32s(simd.splat_f32s((S::F32_LANES / 2) as f32), load::<S>(&IOTA))
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
    if 2 * len == S::F32_LANES {
        return aabb_block_paired(simd, lo, hi, b.data(), n);
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

/// [`aabb_block_with`] for a block of half a vector (an octree's 8 children on 16 lanes):
/// two fields per vector, so the six fields are three full loads instead of six half-empty
/// ones (`kernels/aabb_block` 1.7x -> 2.7x its scalar reference, Zen 4). `t` holds the six fields side by side (`3 * S::F32_LANES` entries): vectors
/// `[min x | min y]`, `[min z | max x]`, `[max y | max z]`.
#[inline(always)]
fn aabb_block_paired<S: Simd>(simd: S, lo: [f32; 3], hi: [f32; 3], t: &[f32], n: usize) -> u32 {
    let half = S::F32_LANES / 2;
    let low = low_bits(half);
    let v = [
        load::<S>(t),
        load::<S>(&t[2 * half..]),
        load::<S>(&t[4 * half..]),
    ];
    let upper = upper_half::<S>(simd);
    let m0 = mask_bits(
        simd,
        simd.less_than_or_equal_f32s(
            v[0],
            simd.select_f32s(upper, simd.splat_f32s(hi[1]), simd.splat_f32s(hi[0])),
        ),
    );
    // `[min z | max x]`: the lower half against the probe's max z, the upper its min x.
    let m1 = (mask_bits(
        simd,
        simd.less_than_or_equal_f32s(v[1], simd.splat_f32s(hi[2])),
    ) & low)
        | (mask_bits(
            simd,
            simd.less_than_or_equal_f32s(simd.splat_f32s(lo[0]), v[1]),
        ) & !low);
    let m2 = mask_bits(
        simd,
        simd.less_than_or_equal_f32s(
            simd.select_f32s(upper, simd.splat_f32s(lo[2]), simd.splat_f32s(lo[1])),
            v[2],
        ),
    );
    let m = m0 & m1 & m2;
    m & (m >> half) & low_bits(n)
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
