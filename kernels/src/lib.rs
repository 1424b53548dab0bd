//! Pure batch kernels of `dhcd`: wide bounding-volume tests (one volume against a block of
//! volumes, [`overlap`]), narrow-phase row filters (one triangle against a row of triangles,
//! [`narrow`]) and refit reductions ([`refit`]) over structure-of-arrays slices. No tree
//! knowledge lives here: slices in, bit masks and values out.
//!
//! Every kernel has a scalar reference (`*_scalar`; `*_scalar_lanes` for the refit
//! reductions) with the same operation order, in
//! [`mod@reference`]: the oracles of the tests and the baselines of the benchmarks.
//!
//! The kernels are SIMD bodies generic over a pulp backend, public as `*_with(simd, ..)`
//! and `#[inline(always)]`: a caller runs a whole traversal inside one `pulp::WithSimd`
//! dispatched on the cached [`arch`] (dispatching once, never per node) and the kernels
//! inline under its target features. The one dispatching entry is [`refit::bounds`], for
//! callers outside such a body. Tests run the bodies on `pulp::Scalar`, `Scalar128b`,
//! `Scalar256b`, `Scalar512b` and the native backends against the references.
//!
//! Exactness: the SIMD bodies use no fused multiply-add. pulp's `mul_add_e_f32s` is fused on
//! the vector backends but unfused on `pulp::Scalar`, so fusing would make results depend on
//! the backend. Overlap and filter kernels therefore give bit-identical masks on every
//! backend; reductions ([`refit`]) are exact against `reference::*_scalar_lanes(.., lanes)`
//! for the backend's lane count.
//!
//! NaN policy: overlap tests use ordered comparisons only, so a NaN anywhere in a pair makes
//! the pair *not* overlap, on every backend. Reductions skip NaN values (see [`refit`]).
//! (The `dhcd` crate rejects non-finite input before it reaches a kernel, so this only
//! matters to direct users of this crate.)
#![deny(unsafe_op_in_unsafe_fn)]
#![warn(missing_docs)]
// Kernels index several parallel arrays (lanes x fields, axes) with one counter; the
// iterator forms clippy suggests hide that layout.
#![allow(clippy::needless_range_loop)]

pub mod apart;
pub mod lazy;
pub mod narrow;
pub mod overlap;
pub mod reference;
pub mod refit;

pub use pulp;

use std::sync::OnceLock;

/// The widest lane count of any pulp backend for `f32` (AVX-512: 16). Staging buffers for
/// gathers have this size.
pub(crate) const MAX_LANES: usize = 16;

/// The cached runtime-detected backend: the one to dispatch a traversal (and so its
/// `*_with` kernels) on.
#[inline]
pub fn arch() -> pulp::Arch {
    static ARCH: OnceLock<pulp::Arch> = OnceLock::new();
    *ARCH.get_or_init(pulp::Arch::new)
}

/// Lane-width helpers shared by the kernels. pulp's vector types are `Pod` with the alignment
/// of their element, so a slice of `F32_LANES` elements reinterprets in place; the only
/// `unsafe` is the x86 masked load of a short slice and the backend-token casts.
pub(crate) mod lanes {
    use pulp::Simd;

    /// Loads `v` (at most `S::F32_LANES` values; missing lanes are zero), reading nothing
    /// past `v`: one full load when `v` fills a register, else one masked load on x86
    /// ([`masked_load`]), else pulp's partial load.
    #[inline(always)]
    pub fn load_prefix<S: Simd>(simd: S, v: &[f32]) -> S::f32s {
        if v.len() == S::F32_LANES {
            return S::as_simd_f32s(v).0[0];
        }
        #[cfg(target_arch = "x86_64")]
        if let Some(x) = masked_load(simd, bytemuck::cast_slice(v)) {
            return bytemuck::cast(x);
        }
        simd.partial_load_f32s(v)
    }

    /// [`load_prefix`] for `u32`.
    #[inline(always)]
    pub fn load_prefix_u32<S: Simd>(simd: S, v: &[u32]) -> S::u32s {
        if v.len() == S::U32_LANES {
            return S::as_simd_u32s(v).0[0];
        }
        #[cfg(target_arch = "x86_64")]
        if let Some(x) = masked_load(simd, v) {
            return x;
        }
        simd.partial_load_u32s(v)
    }

    /// The `v.len() < S::U32_LANES` values of `v` and zeros above, in one masked load, when
    /// `simd` is x86-v4 or x86-v3 (`None` on other backends).
    ///
    /// PERF: pulp's partial loads jump through a table to a stub per length: an indirect
    /// branch per load, mispredicted whenever consecutive leaves or sibling groups differ in
    /// length (the norm on adaptive trees), and every vector field of a short block is such a
    /// load. A masked load costs about a plain load.
    #[cfg(target_arch = "x86_64")]
    #[inline(always)]
    fn masked_load<S: Simd>(simd: S, v: &[u32]) -> Option<S::u32s> {
        use core::arch::x86_64::{__m256i, __m512i};
        let n = v.len();
        debug_assert!(n < S::U32_LANES);
        if let Some(v4) = as_v4(simd) {
            let k = ((1u32 << n) - 1) as u16;
            // SAFETY: lane `i < n` reads `v[i]`; AVX-512 masked loads read nothing, and do not
            // fault, in the masked-off lanes.
            let x = unsafe { v4.avx512f._mm512_maskz_loadu_epi32(k, v.as_ptr().cast()) };
            // SAFETY: `__m512i` and `u32x16` are 64 bytes of plain integers.
            let x: pulp::u32x16 = unsafe { core::mem::transmute::<__m512i, pulp::u32x16>(x) };
            return Some(bytemuck::cast(x));
        }
        if let Some(v3) = as_v3(simd) {
            let iota = v3.avx._mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7);
            let mask = v3
                .avx2
                ._mm256_cmpgt_epi32(v3.avx._mm256_set1_epi32(n as i32), iota);
            // SAFETY: lane `i < n` reads `v[i]`; AVX masked loads read nothing, and do not
            // fault, in the lanes whose mask sign bit is clear.
            let x = unsafe { v3.avx2._mm256_maskload_epi32(v.as_ptr().cast(), mask) };
            // SAFETY: `__m256i` and `u32x8` are 32 bytes of plain integers.
            let x: pulp::u32x8 = unsafe { core::mem::transmute::<__m256i, pulp::u32x8>(x) };
            return Some(bytemuck::cast(x));
        }
        None
    }

    /// The lanes of a comparison mask as bits (lane `k` -> bit `k`). pulp's masks are either
    /// a vector of all-ones/all-zeros lanes (x86-v3, NEON, the emulated backends), a bit
    /// mask register (AVX-512), or a `bool` (the one-lane scalar backend).
    #[inline(always)]
    pub fn mask_bits<S: Simd>(simd: S, m: S::m32s) -> u32 {
        use core::mem::size_of;
        #[cfg(target_arch = "x86_64")]
        if let Some(v3) = as_v3(simd) {
            // PERF: one `vmovmskps`; the generic lane loop below is not recognised as one.
            let v: pulp::f32x8 = bytemuck::cast(m);
            return v3.avx._mm256_movemask_ps(bytemuck::cast(v)) as u32;
        }
        let _ = simd;
        if size_of::<S::m32s>() == size_of::<S::u32s>() && S::U32_LANES > 1 {
            let v: S::u32s = bytemuck::cast(m);
            let mut bits = 0;
            for (k, &x) in u32_array::<S>(&v).iter().enumerate() {
                bits |= (x >> 31) << k;
            }
            bits
        } else if size_of::<S::m32s>() == 2 {
            let v: u16 = bytemuck::cast(m);
            v as u32
        } else if size_of::<S::m32s>() == 1 {
            let v: u8 = bytemuck::cast(m);
            v as u32
        } else {
            let v: S::u32s = bytemuck::cast(m);
            u32_array::<S>(&v)[0] & 1
        }
    }

    /// [`mask_bits`] for a 64-bit comparison mask (lane `k` -> bit `k`), for the same three
    /// mask layouts.
    #[inline(always)]
    pub fn mask_bits_f64<S: Simd>(_simd: S, m: S::m64s) -> u32 {
        use core::mem::size_of;
        if size_of::<S::m64s>() == size_of::<S::u64s>() && S::F64_LANES > 1 {
            let v: S::u64s = bytemuck::cast(m);
            let lanes: &[u64] = bytemuck::cast_slice(core::slice::from_ref(&v));
            let mut bits = 0;
            for (k, &x) in lanes.iter().enumerate() {
                bits |= ((x >> 63) as u32) << k;
            }
            bits
        } else if size_of::<S::m64s>() == 1 {
            let v: u8 = bytemuck::cast(m);
            u32::from(v)
        } else if size_of::<S::m64s>() == 2 {
            let v: u16 = bytemuck::cast(m);
            u32::from(v)
        } else {
            let v: S::u64s = bytemuck::cast(m);
            let lanes: &[u64] = bytemuck::cast_slice(core::slice::from_ref(&v));
            u32::from(lanes[0] & 1 != 0)
        }
    }

    /// `simd` as pulp's x86-v3 token when that is its type.
    #[cfg(target_arch = "x86_64")]
    #[inline(always)]
    fn as_v3<S: Simd>(simd: S) -> Option<pulp::x86::V3> {
        as_backend(simd)
    }

    /// `simd` as pulp's x86-v4 token when that is its type.
    #[cfg(target_arch = "x86_64")]
    #[inline(always)]
    pub(crate) fn as_v4<S: Simd>(simd: S) -> Option<pulp::x86::V4> {
        as_backend(simd)
    }

    /// `simd` as the backend token `T` when `S` is `T`.
    #[inline(always)]
    fn as_backend<S: Simd, T: Simd>(simd: S) -> Option<T> {
        if core::any::TypeId::of::<S>() == core::any::TypeId::of::<T>() {
            // SAFETY: `S` is `T`, so this copies the token the caller holds (pulp's tokens
            // are zero-sized and exist only on CPUs with their features).
            Some(unsafe { core::mem::transmute_copy::<S, T>(&simd) })
        } else {
            None
        }
    }

    /// Loads the first `S::F32_LANES` values of `v`.
    #[inline(always)]
    pub fn load<S: Simd>(v: &[f32]) -> S::f32s {
        S::as_simd_f32s(&v[..S::F32_LANES]).0[0]
    }

    /// The lanes of `v`, lane 0 first.
    #[inline(always)]
    pub fn f32_array<S: Simd>(v: &S::f32s) -> &[f32] {
        bytemuck::cast_slice(core::slice::from_ref(v))
    }

    /// The lanes of `v`, lane 0 first.
    #[inline(always)]
    pub fn u32_array<S: Simd>(v: &S::u32s) -> &[u32] {
        bytemuck::cast_slice(core::slice::from_ref(v))
    }

    /// `m[0]`, then `if v > m { m = v }` for the other values in order: the lane fold of the
    /// max reductions (NaN never replaces; among equal values the first one stays).
    #[inline(always)]
    pub fn fold_max(v: &[f32]) -> f32 {
        let mut m = v[0];
        for &x in &v[1..] {
            if x > m {
                m = x;
            }
        }
        m
    }

    /// Like [`fold_max`] with `<`.
    #[inline(always)]
    pub fn fold_min(v: &[f32]) -> f32 {
        let mut m = v[0];
        for &x in &v[1..] {
            if x < m {
                m = x;
            }
        }
        m
    }

    /// [`fold_min`] of the lanes of `v`, none of which may be NaN, by a SIMD reduction. The
    /// value is the minimum in any order; only a zero's sign could depend on it, and the fold
    /// keeps the first zero lane, which is looked up then. (The sequential fold was half of a
    /// leaf's box fit: a chain of compares and mispredicted branches over every lane.)
    #[inline(always)]
    pub fn fold_min_simd<S: Simd>(simd: S, v: S::f32s) -> f32 {
        first_zero_or(simd, v, simd.reduce_min_f32s(v))
    }

    /// [`fold_max`] of the lanes of `v` (no NaN), like [`fold_min_simd`].
    #[inline(always)]
    pub fn fold_max_simd<S: Simd>(simd: S, v: S::f32s) -> f32 {
        first_zero_or(simd, v, simd.reduce_max_f32s(v))
    }

    /// `m`, or when `m` is zero the first zero lane of `v` (`+0` or `-0`).
    #[inline(always)]
    fn first_zero_or<S: Simd>(simd: S, v: S::f32s, m: f32) -> f32 {
        debug_assert!(f32_array::<S>(&v).iter().all(|x| !x.is_nan()), "NaN lane");
        if m != 0.0 {
            return m;
        }
        let zeros = mask_bits(simd, simd.equal_f32s(v, simd.splat_f32s(0.0)));
        f32_array::<S>(&v)[zeros.trailing_zeros() as usize]
    }

    /// `v[0] + v[1] + ...`, sequentially.
    #[inline(always)]
    pub fn fold_sum(v: &[f32]) -> f32 {
        let mut s = v[0];
        for &x in &v[1..] {
            s += x;
        }
        s
    }
}

/// Fields stored side by side in one slice: field `f` is `data[f * stride..(f + 1) *
/// stride]`. The layout of every block the kernels read (a node's children, a leaf's
/// triangles): one contiguous tile, so a block is two words to pass and a few cache lines to
/// load.
#[derive(Clone, Copy, Debug)]
pub struct Tile<'a> {
    data: &'a [f32],
    stride: usize,
}

impl<'a> Tile<'a> {
    /// A tile of `data.len() / stride` fields. (The views built on tiles check their field
    /// count with [`Tile::has_fields`], a multiplication: this is on the hot path of every
    /// node test.)
    #[inline(always)]
    pub fn new(data: &'a [f32], stride: usize) -> Self {
        Self { data, stride }
    }

    /// Whether the tile holds exactly `fields` fields.
    #[inline(always)]
    pub fn has_fields(&self, fields: usize) -> bool {
        self.stride > 0 && self.data.len() == fields * self.stride
    }

    /// Entries per field.
    #[inline(always)]
    pub fn stride(&self) -> usize {
        self.stride
    }

    /// Field `f`.
    #[inline(always)]
    pub fn field(&self, f: usize) -> &'a [f32] {
        &self.data[f * self.stride..(f + 1) * self.stride]
    }
}

/// Points (or centres) in structure-of-arrays form: `x[i], y[i], z[i]` is point `i`.
#[derive(Clone, Copy, Debug)]
pub struct Soa3<'a> {
    /// The x coordinate of every point.
    pub x: &'a [f32],
    /// The y coordinate of every point.
    pub y: &'a [f32],
    /// The z coordinate of every point.
    pub z: &'a [f32],
}

impl<'a> Soa3<'a> {
    /// The points of the three coordinate arrays; panics unless they have the same length.
    #[inline]
    pub fn new(x: &'a [f32], y: &'a [f32], z: &'a [f32]) -> Self {
        assert!(
            x.len() == y.len() && y.len() == z.len(),
            "Soa3: ragged arrays"
        );
        Self { x, y, z }
    }

    /// Number of points.
    #[inline]
    pub fn len(&self) -> usize {
        self.x.len()
    }

    /// Whether there are no points.
    #[inline]
    pub fn is_empty(&self) -> bool {
        self.x.is_empty()
    }

    /// Point `i` as `[x, y, z]`; panics if `i >= len()`.
    #[inline]
    pub fn get(&self, i: usize) -> [f32; 3] {
        [self.x[i], self.y[i], self.z[i]]
    }

    /// The contiguous run `range` of these points.
    #[inline]
    pub fn slice(&self, range: core::ops::Range<usize>) -> Soa3<'a> {
        Soa3 {
            x: &self.x[range.clone()],
            y: &self.y[range.clone()],
            z: &self.z[range],
        }
    }
}
