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
//! are bit-identical to the `*_scalar` references ([`crate::reference`]) on every backend.
//! NaN policy: a NaN in the probe or an entry makes the pair not overlap, on every backend.

use crate::lanes::{load_prefix, mask_bits, mask_bits_f64};
use crate::Tile;
use pulp::Simd;

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

    /// Centre x of every sphere.
    #[inline(always)]
    pub fn cx(&self) -> &'a [f32] {
        self.tile.field(0)
    }
    /// Centre y of every sphere.
    #[inline(always)]
    pub fn cy(&self) -> &'a [f32] {
        self.tile.field(1)
    }
    /// Centre z of every sphere.
    #[inline(always)]
    pub fn cz(&self) -> &'a [f32] {
        self.tile.field(2)
    }
    /// Radius of every sphere.
    #[inline(always)]
    pub fn r(&self) -> &'a [f32] {
        self.tile.field(3)
    }

    /// Entries per field.
    #[inline(always)]
    pub fn len(&self) -> usize {
        self.tile.stride()
    }

    /// Whether there are no entries.
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

    /// Whether there are no entries.
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

/// The block's slice length, checking `n <= len <= MAX_BLOCK`.
#[inline(always)]
pub(crate) fn block_len(len: usize, n: usize) -> usize {
    assert!(
        len <= MAX_BLOCK,
        "a block holds at most {MAX_BLOCK} entries"
    );
    assert!(n <= len, "more entries tested than the block holds");
    len
}

// ---------------------------------------------------------------------------------------
// sphere_block

/// Sphere `(c, r)` against the first `n` entries of the block `b` (four slices of equal
/// length, at most [`MAX_BLOCK`], at least `n`): bit `k` set iff they overlap. On the backend
/// `simd`, inlined into the caller's dispatched body: call it from inside a `pulp::WithSimd`
/// so a whole traversal dispatches once.
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

/// Box `(lo, hi)` against the first `n` entries of the block `b` (six slices of equal
/// length, at most [`MAX_BLOCK`], at least `n`): bit `k` set iff they overlap. On the backend
/// `simd` (see [`sphere_block_with`]).
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
/// fields per 16-lane vector gave 2.4x and 2.7x: docs/notes/performance-history.md, section
/// "wide node tests on 8 lanes").
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

#[inline]
pub(crate) fn box_rows_len(rows: &BoxRows, n: usize) -> usize {
    assert!(n <= MAX_BOX_ROW, "at most {MAX_BOX_ROW} boxes a call");
    rows_len_at_least(rows, n)
}

/// The rows' common length, checked to be at least `n`.
#[inline(always)]
fn rows_len_at_least(rows: &BoxRows, n: usize) -> usize {
    let len = rows[0].len();
    assert!(
        rows.iter().all(|r| r.len() == len) && n <= len,
        "six rows of one length, at least n"
    );
    len
}

/// The box `(lo, hi)` against the first `n <= 64` boxes of `rows`: bit `k` set iff they
/// meet (closed boxes; a NaN bound never meets). Comparisons only, so the mask is the
/// same on every backend as [`crate::reference::boxes_meet_scalar`].
#[inline(always)]
pub fn boxes_meet_with<S: Simd>(
    simd: S,
    lo: [f32; 3],
    hi: [f32; 3],
    rows: BoxRows,
    n: usize,
) -> u64 {
    assert!(n <= MAX_BOX_ROW, "at most {MAX_BOX_ROW} boxes a call");
    boxes_meet_from(simd, lo, hi, &rows, 0, n)
}

/// [`boxes_meet_with`] on the boxes `from..min(from + 64, n)` of the first `n` of `rows`
/// (`from <= n`): bit `k` for box `from + k`. The rows are read in place, so a caller
/// walking a long row in blocks of 64 does not build six new slices for each block.
#[inline(always)]
pub fn boxes_meet_from<S: Simd>(
    simd: S,
    lo: [f32; 3],
    hi: [f32; 3],
    rows: &BoxRows,
    from: usize,
    n: usize,
) -> u64 {
    let len = rows_len_at_least(rows, n);
    assert!(from <= n, "the first box tested is at most n");
    let n = (n - from).min(MAX_BOX_ROW);
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
    let row =
        |k: usize, base: usize, end: usize| load_prefix(simd, &rows[k][from + base..from + end]);
    let mut bits = 0u64;
    let mut base = 0;
    while base < n {
        // Within the rows (padding past `n` included), at most one vector.
        let end = (base + S::F32_LANES).min(len - from);
        let mut hit = simd.less_than_or_equal_f32s(plo[0], row(3, base, end));
        hit = simd.and_m32s(hit, simd.less_than_or_equal_f32s(row(0, base, end), phi[0]));
        for k in 1..3 {
            hit = simd.and_m32s(
                hit,
                simd.less_than_or_equal_f32s(plo[k], row(3 + k, base, end)),
            );
            hit = simd.and_m32s(hit, simd.less_than_or_equal_f32s(row(k, base, end), phi[k]));
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

// ---------------------------------------------------------------------------------------
// moving spheres (swept bounds over a step)

/// A sphere moving over a step: centre `c0 + t (c1 - c0)`, radius `(1 - t) r0 + t r1`,
/// `t` in `[0, 1]`. It bounds a region over the whole step when both end spheres bound the
/// region at their end and the region's points and the centre move linearly (the triangle
/// inequality on `(1 - t)(v0 - c0) + t (v1 - c1)`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MovingSphere {
    /// Centre at `t = 0`.
    pub c0: [f64; 3],
    /// Radius at `t = 0`.
    pub r0: f64,
    /// Centre at `t = 1`.
    pub c1: [f64; 3],
    /// Radius at `t = 1`.
    pub r1: f64,
}

/// Fields of a [`MovingSphereSoa`]: `c0` x, y, z, `r0`, `c1` x, y, z, `r1`.
pub const MOVING_SPHERE_FIELDS: usize = 8;

/// Moving spheres in structure-of-arrays form: eight `f64` fields of `stride` entries each,
/// side by side ([`MOVING_SPHERE_FIELDS`]).
#[derive(Clone, Copy, Debug)]
pub struct MovingSphereSoa<'a> {
    data: &'a [f64],
    stride: usize,
}

impl<'a> MovingSphereSoa<'a> {
    /// Panics unless `data` holds eight fields of `stride` entries.
    #[inline]
    pub fn new(data: &'a [f64], stride: usize) -> Self {
        assert_eq!(
            data.len(),
            MOVING_SPHERE_FIELDS * stride,
            "MovingSphereSoa: c0 xyz, r0, c1 xyz, r1"
        );
        Self { data, stride }
    }

    /// Field `f` of every entry.
    #[inline(always)]
    pub fn field(&self, f: usize) -> &'a [f64] {
        &self.data[f * self.stride..(f + 1) * self.stride]
    }

    /// Entries per field.
    #[inline(always)]
    pub fn len(&self) -> usize {
        self.stride
    }

    /// Whether there are no entries.
    #[inline(always)]
    pub fn is_empty(&self) -> bool {
        self.stride == 0
    }

    /// Entry `k`.
    #[inline(always)]
    pub fn get(&self, k: usize) -> MovingSphere {
        let f = |i: usize| self.field(i)[k];
        MovingSphere {
            c0: [f(0), f(1), f(2)],
            r0: f(3),
            c1: [f(4), f(5), f(6)],
            r1: f(7),
        }
    }
}

/// The relative error bound of the quadratic's coefficients: `2^-44 M^2` (their rounding is
/// below `2^-46 M^2`, `M` the largest magnitude of the centre differences and radius sums).
pub(crate) const MOVING_K2: f64 = 1.0 / (1u64 << 44) as f64;
/// The error bound of `A C - B^2`: `2^-36 M^4` (below `2^-39 M^4`).
pub(crate) const MOVING_K4: f64 = 1.0 / (1u64 << 36) as f64;
/// An absolute term for underflow: far above any underflowing rounding (`2^-1075` each,
/// times magnitudes below `2^130`).
pub(crate) const MOVING_TINY: f64 = f64::from_bits((1023 - 900) << 52);

/// The moving sphere `p` against the first `n` entries of the block `b` (at most
/// [`MAX_BLOCK`]): bit `k` set iff they meet during the step
/// ([`crate::reference::moving_spheres_meet`], the same bits on every backend).
#[inline(always)]
pub fn moving_sphere_block_with<S: Simd>(
    simd: S,
    p: &MovingSphere,
    b: MovingSphereSoa,
    n: usize,
) -> u32 {
    let len = block_len(b.len(), n);
    // No closures in SIMD bodies (see `aabb_block_with`).
    let pc0 = [
        simd.splat_f64s(p.c0[0]),
        simd.splat_f64s(p.c0[1]),
        simd.splat_f64s(p.c0[2]),
    ];
    let pc1 = [
        simd.splat_f64s(p.c1[0]),
        simd.splat_f64s(p.c1[1]),
        simd.splat_f64s(p.c1[2]),
    ];
    let (pr0, pr1) = (simd.splat_f64s(p.r0), simd.splat_f64s(p.r1));
    let zero = simd.splat_f64s(0.0);
    let k2 = simd.splat_f64s(MOVING_K2);
    let k4 = simd.splat_f64s(MOVING_K4);
    let tiny = simd.splat_f64s(MOVING_TINY);
    let mut bits = 0u32;
    let mut base = 0;
    while base < n {
        let end = (base + S::F64_LANES).min(len);
        let d0 = [
            simd.sub_f64s(pc0[0], load_field(simd, &b, 0, base, end)),
            simd.sub_f64s(pc0[1], load_field(simd, &b, 1, base, end)),
            simd.sub_f64s(pc0[2], load_field(simd, &b, 2, base, end)),
        ];
        let d1 = [
            simd.sub_f64s(pc1[0], load_field(simd, &b, 4, base, end)),
            simd.sub_f64s(pc1[1], load_field(simd, &b, 5, base, end)),
            simd.sub_f64s(pc1[2], load_field(simd, &b, 6, base, end)),
        ];
        let e = [
            simd.sub_f64s(d1[0], d0[0]),
            simd.sub_f64s(d1[1], d0[1]),
            simd.sub_f64s(d1[2], d0[2]),
        ];
        let r0 = simd.add_f64s(pr0, load_field(simd, &b, 3, base, end));
        let r1 = simd.add_f64s(pr1, load_field(simd, &b, 7, base, end));
        let f = simd.sub_f64s(r1, r0);
        let c = simd.sub_f64s(dot3_f64(simd, &d0, &d0), simd.mul_f64s(r0, r0));
        let h1 = simd.sub_f64s(dot3_f64(simd, &d1, &d1), simd.mul_f64s(r1, r1));
        let aa = simd.sub_f64s(dot3_f64(simd, &e, &e), simd.mul_f64s(f, f));
        let bb = simd.sub_f64s(dot3_f64(simd, &d0, &e), simd.mul_f64s(r0, f));
        let mut m = r0;
        for x in [d0[0], d0[1], d0[2], d1[0], d1[1], d1[2], r1] {
            let x = abs_f64(simd, x, zero);
            m = simd.select_f64s(simd.greater_than_f64s(x, m), x, m);
        }
        let m2 = simd.mul_f64s(m, m);
        let s2 = simd.add_f64s(simd.mul_f64s(k2, m2), tiny);
        let s4 = simd.add_f64s(simd.mul_f64s(k4, simd.mul_f64s(m2, m2)), tiny);
        let two_s2 = simd.add_f64s(s2, s2);
        let mut interior = simd.greater_than_f64s(aa, simd.sub_f64s(zero, s2));
        interior = simd.and_m64s(interior, simd.less_than_f64s(bb, s2));
        interior = simd.and_m64s(
            interior,
            simd.greater_than_f64s(bb, simd.sub_f64s(simd.sub_f64s(zero, aa), two_s2)),
        );
        interior = simd.and_m64s(
            interior,
            simd.less_than_or_equal_f64s(simd.sub_f64s(c, abs_f64(simd, bb, zero)), two_s2),
        );
        interior = simd.and_m64s(
            interior,
            simd.less_than_or_equal_f64s(
                simd.sub_f64s(simd.mul_f64s(aa, c), simd.mul_f64s(bb, bb)),
                s4,
            ),
        );
        let hit = simd.or_m64s(
            simd.or_m64s(
                simd.less_than_or_equal_f64s(c, s2),
                simd.less_than_or_equal_f64s(h1, s2),
            ),
            interior,
        );
        bits |= (mask_bits_f64(simd, hit) & low_bits(n - base)) << base;
        base = end;
    }
    bits
}

/// Entries `base..end` of field `f` of `b`.
#[inline(always)]
fn load_field<S: Simd>(simd: S, b: &MovingSphereSoa, f: usize, base: usize, end: usize) -> S::f64s {
    load_prefix_f64(simd, &b.field(f)[base..end])
}

/// `(x0 y0 + x1 y1) + x2 y2`, lane-wise.
#[inline(always)]
fn dot3_f64<S: Simd>(simd: S, x: &[S::f64s; 3], y: &[S::f64s; 3]) -> S::f64s {
    simd.add_f64s(
        simd.add_f64s(simd.mul_f64s(x[0], y[0]), simd.mul_f64s(x[1], y[1])),
        simd.mul_f64s(x[2], y[2]),
    )
}

/// `|x|` as a select (`x < 0 ? 0 - x : x`; NaN stays NaN), the scalar reference's form.
#[inline(always)]
fn abs_f64<S: Simd>(simd: S, x: S::f64s, zero: S::f64s) -> S::f64s {
    simd.select_f64s(simd.less_than_f64s(x, zero), simd.sub_f64s(zero, x), x)
}

/// Loads `v` (at most `S::F64_LANES` values; missing lanes are zero).
#[inline(always)]
fn load_prefix_f64<S: Simd>(simd: S, v: &[f64]) -> S::f64s {
    if v.len() == S::F64_LANES {
        return S::as_simd_f64s(v).0[0];
    }
    simd.partial_load_f64s(v)
}
