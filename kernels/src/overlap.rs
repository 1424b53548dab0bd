//! Batch overlap tests for the three bounding-volume kinds, over pairs of node indices.
//!
//! Each entry tests pairs `(ia[k], ib[k])` for `k in 0..ia.len()`, writes `out[k] = 1` when
//! the two volumes overlap (closed volumes: touching counts) and `0` otherwise, and returns
//! the number of overlapping pairs. Node data is read by index (a gather).
//!
//! SIMD: pulp's portable `Simd` has no gather, so each block of `F32_LANES` pairs is staged:
//! the gathered fields are copied into small stack arrays (one per field, lane width) and
//! loaded as vectors; the test itself, the 0/1 mask store and the hit count are vector code.
//! Tail lanes are staged as NaN, which never overlaps, and are neither stored nor counted.
//! Masks are bit-identical to the `*_scalar` references on every backend (no fma, same
//! operation order).
//!
//! PERF (measured, `benches/kernels.rs`, AMD EPYC Zen 4, AVX-512, random pairs over 4,096
//! nodes): the pair kernels run at about the speed of their scalar references (0.5-1.0x), far
//! from the 4x of the contiguous kernels. Per pair they still do every gathered load
//! (8 for spheres/DH, plus 2 vertex indices for DH, 12 for boxes) and add the staging stores;
//! only ~10 flops per pair are vectorised. The scalar box test also short-circuits after the
//! first failing axis, which the lane-wise test cannot. AVX-512 hardware gathers (feature
//! `hw-gather`) measured no faster than staging on this CPU. The way to a real speedup is
//! layout, not instructions: test a node against a contiguous run of nodes (children are
//! contiguous), as [`crate::narrow::tri_aabb_overlap_row`] does for boxes (6-7x).

use crate::lanes::{load, store_u32, u32_array};
use crate::MAX_LANES;
use pulp::{Simd, WithSimd};

/// Sphere nodes (the SBV hierarchy) in SoA form.
#[derive(Clone, Copy, Debug)]
pub struct SphereSoa<'a> {
    pub cx: &'a [f32],
    pub cy: &'a [f32],
    pub cz: &'a [f32],
    pub r: &'a [f32],
}

/// Distance-hierarchy nodes in SoA form: the centre is the live position of vertex
/// `vertex[n]` in `points`.
#[derive(Clone, Copy, Debug)]
pub struct DhSoa<'a> {
    pub vertex: &'a [u32],
    pub r: &'a [f32],
    pub points: crate::Soa3<'a>,
}

/// Axis-aligned boxes in SoA form.
#[derive(Clone, Copy, Debug)]
pub struct AabbSoa<'a> {
    pub min_x: &'a [f32],
    pub min_y: &'a [f32],
    pub min_z: &'a [f32],
    pub max_x: &'a [f32],
    pub max_y: &'a [f32],
    pub max_z: &'a [f32],
}

#[inline(always)]
fn spheres_overlap(a: [f32; 3], ra: f32, b: [f32; 3], rb: f32) -> bool {
    let dx = a[0] - b[0];
    let dy = a[1] - b[1];
    let dz = a[2] - b[2];
    let d2 = dx * dx + dy * dy + dz * dz;
    let rs = ra + rb;
    d2 <= rs * rs
}

pub(crate) fn check_lengths(ia: &[u32], ib: &[u32], out: &[u32]) {
    assert_eq!(ia.len(), ib.len(), "overlap: ia and ib differ in length");
    assert!(
        out.len() >= ia.len(),
        "overlap: out is shorter than the pair list"
    );
}

/// Scalar reference of [`sphere_pairs`].
pub fn sphere_pairs_scalar(
    a: SphereSoa,
    b: SphereSoa,
    ia: &[u32],
    ib: &[u32],
    out: &mut [u32],
) -> usize {
    check_lengths(ia, ib, out);
    let mut hits = 0;
    for k in 0..ia.len() {
        let (i, j) = (ia[k] as usize, ib[k] as usize);
        let hit = spheres_overlap(
            [a.cx[i], a.cy[i], a.cz[i]],
            a.r[i],
            [b.cx[j], b.cy[j], b.cz[j]],
            b.r[j],
        );
        out[k] = hit as u32;
        hits += hit as usize;
    }
    hits
}

/// Sphere-sphere overlap `|c_a - c_b|^2 <= (r_a + r_b)^2` for each pair
/// (computed as `(dx*dx + dy*dy) + dz*dz <= (ra + rb)*(ra + rb)`, no fma).
pub fn sphere_pairs(a: SphereSoa, b: SphereSoa, ia: &[u32], ib: &[u32], out: &mut [u32]) -> usize {
    crate::arch().dispatch(SpherePairs { a, b, ia, ib, out })
}

/// [`sphere_pairs`] on the backend `simd`.
pub fn sphere_pairs_with<S: Simd>(
    simd: S,
    a: SphereSoa,
    b: SphereSoa,
    ia: &[u32],
    ib: &[u32],
    out: &mut [u32],
) -> usize {
    simd.vectorize(SpherePairs { a, b, ia, ib, out })
}

struct SpherePairs<'a> {
    a: SphereSoa<'a>,
    b: SphereSoa<'a>,
    ia: &'a [u32],
    ib: &'a [u32],
    out: &'a mut [u32],
}

impl WithSimd for SpherePairs<'_> {
    type Output = usize;
    #[inline(always)]
    fn with_simd<S: Simd>(self, simd: S) -> usize {
        sphere_pairs_simd(simd, self.a, self.b, self.ia, self.ib, self.out)
    }
}

#[inline(always)]
fn sphere_pairs_simd<S: Simd>(
    simd: S,
    a: SphereSoa,
    b: SphereSoa,
    ia: &[u32],
    ib: &[u32],
    out: &mut [u32],
) -> usize {
    check_lengths(ia, ib, out);
    pairs_simd(simd, &SphereStage { a, b, ia, ib }, out)
}

struct SphereStage<'a> {
    a: SphereSoa<'a>,
    b: SphereSoa<'a>,
    ia: &'a [u32],
    ib: &'a [u32],
}

impl PairStage<8> for SphereStage<'_> {
    #[inline(always)]
    fn len(&self) -> usize {
        self.ia.len()
    }

    #[inline(always)]
    fn stage(&self, k: usize) -> [f32; 8] {
        let (a, b) = (&self.a, &self.b);
        let (i, j) = (self.ia[k] as usize, self.ib[k] as usize);
        [
            a.cx[i], a.cy[i], a.cz[i], a.r[i], b.cx[j], b.cy[j], b.cz[j], b.r[j],
        ]
    }

    #[inline(always)]
    fn test<S: Simd>(simd: S, v: &[S::f32s; 8]) -> S::m32s {
        spheres_overlap_simd(simd, v)
    }

    #[cfg(all(target_arch = "x86_64", feature = "hw-gather"))]
    #[inline(always)]
    fn gather16(&self, v4: pulp::x86::V4, k: usize) -> [pulp::f32x16; 8] {
        use gather_v4::{gather, load_idx};
        let (a, b) = (&self.a, &self.b);
        let (i, j) = (load_idx(v4, self.ia, k), load_idx(v4, self.ib, k));
        [
            gather(v4, i, a.cx),
            gather(v4, i, a.cy),
            gather(v4, i, a.cz),
            gather(v4, i, a.r),
            gather(v4, j, b.cx),
            gather(v4, j, b.cy),
            gather(v4, j, b.cz),
            gather(v4, j, b.r),
        ]
    }
}

/// The lane-wise [`spheres_overlap`]: `v = [ax, ay, az, ar, bx, by, bz, br]`.
#[inline(always)]
fn spheres_overlap_simd<S: Simd>(simd: S, v: &[S::f32s; 8]) -> S::m32s {
    let dx = simd.sub_f32s(v[0], v[4]);
    let dy = simd.sub_f32s(v[1], v[5]);
    let dz = simd.sub_f32s(v[2], v[6]);
    let d2 = simd.add_f32s(
        simd.add_f32s(simd.mul_f32s(dx, dx), simd.mul_f32s(dy, dy)),
        simd.mul_f32s(dz, dz),
    );
    let rs = simd.add_f32s(v[3], v[7]);
    simd.less_than_or_equal_f32s(d2, simd.mul_f32s(rs, rs))
}

/// The lane-wise box test: `v = [a.min xyz, a.max xyz, b.min xyz, b.max xyz]`.
#[inline(always)]
pub(crate) fn aabbs_overlap_simd<S: Simd>(simd: S, v: &[S::f32s; 12]) -> S::m32s {
    let mut m = simd.less_than_or_equal_f32s(v[0], v[9]);
    m = simd.and_m32s(m, simd.less_than_or_equal_f32s(v[6], v[3]));
    m = simd.and_m32s(m, simd.less_than_or_equal_f32s(v[1], v[10]));
    m = simd.and_m32s(m, simd.less_than_or_equal_f32s(v[7], v[4]));
    m = simd.and_m32s(m, simd.less_than_or_equal_f32s(v[2], v[11]));
    simd.and_m32s(m, simd.less_than_or_equal_f32s(v[8], v[5]))
}

/// The gathered inputs and the lane-wise test of one pair kernel. A trait rather than
/// closures: closures do not inherit the target features of the dispatched body and may be
/// compiled out of line, turning every intrinsic into a call (measured: 4x slower than scalar).
pub(crate) trait PairStage<const N: usize> {
    /// Number of pairs.
    fn len(&self) -> usize;
    /// The `N` fields of pair `k` (the gather).
    fn stage(&self, k: usize) -> [f32; N];
    /// The lane-wise overlap test on the staged fields.
    fn test<S: Simd>(simd: S, v: &[S::f32s; N]) -> S::m32s;
    /// The fields of the 16 pairs `k..k + 16` by hardware gather (AVX-512F only).
    #[cfg(all(target_arch = "x86_64", feature = "hw-gather"))]
    fn gather16(&self, v4: pulp::x86::V4, k: usize) -> [pulp::f32x16; N];
}

/// The shared driver of the pair kernels: for each block of `S::F32_LANES` pairs, stages the
/// `N` gathered fields of every pair into lane-width stack arrays, loads them, runs the test,
/// stores the 0/1 mask into `out` and counts the hits. Tail lanes hold NaN (never a hit) and
/// are not stored.
#[inline(always)]
pub(crate) fn pairs_simd<S: Simd, const N: usize, P: PairStage<N>>(
    simd: S,
    pairs: &P,
    out: &mut [u32],
) -> usize {
    let n = pairs.len();
    let lanes = S::F32_LANES;
    assert!(lanes <= MAX_LANES);
    let one = simd.splat_u32s(1);
    let zero = simd.splat_u32s(0);
    let mut count = zero;
    let mut buf = [[0.0f32; MAX_LANES]; N];
    let full = n - n % lanes;
    let mut k = 0;
    let mut total = 0;
    // PERF: with the `hw-gather` feature, the full blocks on AVX-512 use hardware gathers
    // (`vgatherdps`) instead of staging through the stack; the tail stays staged. Off by
    // default: on the AMD EPYC (Zen 4) development machine it measured no faster than staging
    // (both bound by the random loads; see the crate README / bench notes).
    #[cfg(all(target_arch = "x86_64", feature = "hw-gather"))]
    if let Some(&v4) = (&simd as &dyn core::any::Any).downcast_ref::<pulp::x86::V4>() {
        (k, total) = gather_v4::pairs(v4, pairs, out);
    }
    while k < full {
        for l in 0..lanes {
            let vals = pairs.stage(k + l);
            for f in 0..N {
                buf[f][l] = vals[f];
            }
        }
        let hit = simd.select_u32s(P::test(simd, &load_rows::<S, N>(&buf)), one, zero);
        store_u32::<S>(&mut out[k..k + lanes], hit);
        count = simd.add_u32s(count, hit);
        k += lanes;
    }
    if k < n {
        buf = [[f32::NAN; MAX_LANES]; N];
        for l in 0..n - k {
            let vals = pairs.stage(k + l);
            for f in 0..N {
                buf[f][l] = vals[f];
            }
        }
        let hit = simd.select_u32s(P::test(simd, &load_rows::<S, N>(&buf)), one, zero);
        simd.partial_store_u32s(&mut out[k..n], hit);
        count = simd.add_u32s(count, hit);
    }
    for &c in u32_array::<S>(&count) {
        total += c as usize;
    }
    total
}

/// Loads row `f` of `buf` into vector `f`.
#[inline(always)]
pub(crate) fn load_rows<S: Simd, const N: usize>(buf: &[[f32; MAX_LANES]; N]) -> [S::f32s; N] {
    let mut v = [load::<S>(&buf[0]); N];
    for f in 1..N {
        v[f] = load::<S>(&buf[f]);
    }
    v
}

/// Scalar reference of [`dh_pairs`].
pub fn dh_pairs_scalar(a: DhSoa, b: DhSoa, ia: &[u32], ib: &[u32], out: &mut [u32]) -> usize {
    check_lengths(ia, ib, out);
    let mut hits = 0;
    for k in 0..ia.len() {
        let (i, j) = (ia[k] as usize, ib[k] as usize);
        let ca = a.points.get(a.vertex[i] as usize);
        let cb = b.points.get(b.vertex[j] as usize);
        let hit = spheres_overlap(ca, a.r[i], cb, b.r[j]);
        out[k] = hit as u32;
        hits += hit as usize;
    }
    hits
}

/// Distance-hierarchy overlap: the sphere test with centres read from the live vertex
/// positions, `|P_a[c_a] - P_b[c_b]|^2 <= (r_a + r_b)^2`.
pub fn dh_pairs(a: DhSoa, b: DhSoa, ia: &[u32], ib: &[u32], out: &mut [u32]) -> usize {
    crate::arch().dispatch(DhPairs { a, b, ia, ib, out })
}

/// [`dh_pairs`] on the backend `simd`.
pub fn dh_pairs_with<S: Simd>(
    simd: S,
    a: DhSoa,
    b: DhSoa,
    ia: &[u32],
    ib: &[u32],
    out: &mut [u32],
) -> usize {
    simd.vectorize(DhPairs { a, b, ia, ib, out })
}

struct DhPairs<'a> {
    a: DhSoa<'a>,
    b: DhSoa<'a>,
    ia: &'a [u32],
    ib: &'a [u32],
    out: &'a mut [u32],
}

impl WithSimd for DhPairs<'_> {
    type Output = usize;
    #[inline(always)]
    fn with_simd<S: Simd>(self, simd: S) -> usize {
        dh_pairs_simd(simd, self.a, self.b, self.ia, self.ib, self.out)
    }
}

#[inline(always)]
fn dh_pairs_simd<S: Simd>(
    simd: S,
    a: DhSoa,
    b: DhSoa,
    ia: &[u32],
    ib: &[u32],
    out: &mut [u32],
) -> usize {
    check_lengths(ia, ib, out);
    pairs_simd(simd, &DhStage { a, b, ia, ib }, out)
}

struct DhStage<'a> {
    a: DhSoa<'a>,
    b: DhSoa<'a>,
    ia: &'a [u32],
    ib: &'a [u32],
}

impl PairStage<8> for DhStage<'_> {
    #[inline(always)]
    fn len(&self) -> usize {
        self.ia.len()
    }

    #[inline(always)]
    fn stage(&self, k: usize) -> [f32; 8] {
        let (a, b) = (&self.a, &self.b);
        let (pa, pb) = (&a.points, &b.points);
        let (i, j) = (self.ia[k] as usize, self.ib[k] as usize);
        let (va, vb) = (a.vertex[i] as usize, b.vertex[j] as usize);
        [
            pa.x[va], pa.y[va], pa.z[va], a.r[i], pb.x[vb], pb.y[vb], pb.z[vb], b.r[j],
        ]
    }

    #[inline(always)]
    fn test<S: Simd>(simd: S, v: &[S::f32s; 8]) -> S::m32s {
        spheres_overlap_simd(simd, v)
    }

    #[cfg(all(target_arch = "x86_64", feature = "hw-gather"))]
    #[inline(always)]
    fn gather16(&self, v4: pulp::x86::V4, k: usize) -> [pulp::f32x16; 8] {
        use gather_v4::{gather, gather_u32, load_idx};
        let (a, b) = (&self.a, &self.b);
        let (i, j) = (load_idx(v4, self.ia, k), load_idx(v4, self.ib, k));
        let (va, vb) = (gather_u32(v4, i, a.vertex), gather_u32(v4, j, b.vertex));
        let (pa, pb) = (&a.points, &b.points);
        [
            gather(v4, va, pa.x),
            gather(v4, va, pa.y),
            gather(v4, va, pa.z),
            gather(v4, i, a.r),
            gather(v4, vb, pb.x),
            gather(v4, vb, pb.y),
            gather(v4, vb, pb.z),
            gather(v4, j, b.r),
        ]
    }
}

/// Scalar reference of [`aabb_pairs`].
pub fn aabb_pairs_scalar(a: AabbSoa, b: AabbSoa, ia: &[u32], ib: &[u32], out: &mut [u32]) -> usize {
    check_lengths(ia, ib, out);
    let mut hits = 0;
    for k in 0..ia.len() {
        let (i, j) = (ia[k] as usize, ib[k] as usize);
        let hit = a.min_x[i] <= b.max_x[j]
            && b.min_x[j] <= a.max_x[i]
            && a.min_y[i] <= b.max_y[j]
            && b.min_y[j] <= a.max_y[i]
            && a.min_z[i] <= b.max_z[j]
            && b.min_z[j] <= a.max_z[i];
        out[k] = hit as u32;
        hits += hit as usize;
    }
    hits
}

/// Box-box overlap: six interval comparisons per pair.
///
/// PERF: runs the scalar body. The test is gather-bound (12 indexed loads per pair) and the
/// scalar version stops at the first separating axis, so it beats the lane-wise SIMD body
/// (`aabb_pairs_with`) by 2.3-2.5x on this machine (`cargo bench --bench kernels --
/// aabb_pairs`, docs/PERFORMANCE.md). The results are identical.
pub fn aabb_pairs(a: AabbSoa, b: AabbSoa, ia: &[u32], ib: &[u32], out: &mut [u32]) -> usize {
    aabb_pairs_scalar(a, b, ia, ib, out)
}

/// The runtime-dispatched SIMD body of [`aabb_pairs`] (kept for benchmarks and for machines
/// where gathers are cheap; same results).
pub fn aabb_pairs_vectorized(
    a: AabbSoa,
    b: AabbSoa,
    ia: &[u32],
    ib: &[u32],
    out: &mut [u32],
) -> usize {
    crate::arch().dispatch(AabbPairs { a, b, ia, ib, out })
}

/// [`aabb_pairs`] on the backend `simd`.
pub fn aabb_pairs_with<S: Simd>(
    simd: S,
    a: AabbSoa,
    b: AabbSoa,
    ia: &[u32],
    ib: &[u32],
    out: &mut [u32],
) -> usize {
    simd.vectorize(AabbPairs { a, b, ia, ib, out })
}

pub(crate) struct AabbPairs<'a> {
    pub(crate) a: AabbSoa<'a>,
    pub(crate) b: AabbSoa<'a>,
    pub(crate) ia: &'a [u32],
    pub(crate) ib: &'a [u32],
    pub(crate) out: &'a mut [u32],
}

impl WithSimd for AabbPairs<'_> {
    type Output = usize;
    #[inline(always)]
    fn with_simd<S: Simd>(self, simd: S) -> usize {
        aabb_pairs_simd(simd, self.a, self.b, self.ia, self.ib, self.out)
    }
}

#[inline(always)]
fn aabb_pairs_simd<S: Simd>(
    simd: S,
    a: AabbSoa,
    b: AabbSoa,
    ia: &[u32],
    ib: &[u32],
    out: &mut [u32],
) -> usize {
    check_lengths(ia, ib, out);
    pairs_simd(simd, &AabbStage { a, b, ia, ib }, out)
}

struct AabbStage<'a> {
    a: AabbSoa<'a>,
    b: AabbSoa<'a>,
    ia: &'a [u32],
    ib: &'a [u32],
}

impl PairStage<12> for AabbStage<'_> {
    #[inline(always)]
    fn len(&self) -> usize {
        self.ia.len()
    }

    #[inline(always)]
    fn stage(&self, k: usize) -> [f32; 12] {
        let (a, b) = (&self.a, &self.b);
        let (i, j) = (self.ia[k] as usize, self.ib[k] as usize);
        [
            a.min_x[i], a.min_y[i], a.min_z[i], a.max_x[i], a.max_y[i], a.max_z[i], b.min_x[j],
            b.min_y[j], b.min_z[j], b.max_x[j], b.max_y[j], b.max_z[j],
        ]
    }

    #[inline(always)]
    fn test<S: Simd>(simd: S, v: &[S::f32s; 12]) -> S::m32s {
        aabbs_overlap_simd(simd, v)
    }

    #[cfg(all(target_arch = "x86_64", feature = "hw-gather"))]
    #[inline(always)]
    fn gather16(&self, v4: pulp::x86::V4, k: usize) -> [pulp::f32x16; 12] {
        use gather_v4::{gather, load_idx};
        let (a, b) = (&self.a, &self.b);
        let (i, j) = (load_idx(v4, self.ia, k), load_idx(v4, self.ib, k));
        [
            gather(v4, i, a.min_x),
            gather(v4, i, a.min_y),
            gather(v4, i, a.min_z),
            gather(v4, i, a.max_x),
            gather(v4, i, a.max_y),
            gather(v4, i, a.max_z),
            gather(v4, j, b.min_x),
            gather(v4, j, b.min_y),
            gather(v4, j, b.min_z),
            gather(v4, j, b.max_x),
            gather(v4, j, b.max_y),
            gather(v4, j, b.max_z),
        ]
    }
}

/// Hardware gathers for the AVX-512 backend (`pulp::x86::V4`). pulp's portable `Simd` has no
/// gather; these helpers are only reached from bodies dispatched on `V4`, whose token proves
/// AVX-512F is available and whose `vectorize` enables it for the inlined body.
#[cfg(all(target_arch = "x86_64", feature = "hw-gather"))]
mod gather_v4 {
    use super::PairStage;
    use core::arch::x86_64::{
        __m512, __m512i, _mm512_cmpge_epu32_mask, _mm512_i32gather_epi32, _mm512_i32gather_ps,
        _mm512_set1_epi32,
    };
    use pulp::x86::V4;
    use pulp::{f32x16, u32x16, Simd};

    /// The full 16-pair blocks of `pairs` with gathered fields; returns the first pair not
    /// done and the number of hits.
    #[inline(always)]
    pub(super) fn pairs<const N: usize, P: PairStage<N>>(
        v4: V4,
        pairs: &P,
        out: &mut [u32],
    ) -> (usize, usize) {
        let n = pairs.len();
        let full = n - n % 16;
        let (one, zero) = (v4.splat_u32s(1), v4.splat_u32s(0));
        let mut count = zero;
        let mut k = 0;
        while k < full {
            let v = pairs.gather16(v4, k);
            let hit = v4.select_u32s(P::test(v4, &v), one, zero);
            V4::as_mut_simd_u32s(&mut out[k..k + 16]).0[0] = hit;
            count = v4.add_u32s(count, hit);
            k += 16;
        }
        let c: [u32; 16] = bytemuck::cast(count);
        (k, c.iter().map(|&c| c as usize).sum())
    }

    /// The 16 indices `idx[k..k + 16]`.
    #[inline(always)]
    pub(super) fn load_idx(_v4: V4, idx: &[u32], k: usize) -> u32x16 {
        V4::as_simd_u32s(&idx[k..k + 16]).0[0]
    }

    fn to_m512i(v: u32x16) -> __m512i {
        // SAFETY: both are 64 bytes of plain integer data; every bit pattern is valid.
        unsafe { core::mem::transmute::<u32x16, __m512i>(v) }
    }

    /// Panics (like slice indexing) unless every lane of `idx` is `< len`; returns the
    /// indices as a vector register. Requires `len <= i32::MAX` (gather offsets are signed).
    #[inline(always)]
    fn checked(_v4: V4, idx: u32x16, len: usize) -> __m512i {
        debug_assert!(len <= i32::MAX as usize);
        let idx = to_m512i(idx);
        // SAFETY: AVX-512F is available: the `V4` token exists only if it was detected.
        let oob = unsafe { _mm512_cmpge_epu32_mask(idx, _mm512_set1_epi32(len as i32)) };
        assert!(oob == 0, "overlap: index out of range");
        idx
    }

    /// `data[idx[l]]` for the 16 lanes.
    #[inline(always)]
    pub(super) fn gather(v4: V4, idx: u32x16, data: &[f32]) -> f32x16 {
        if data.len() > i32::MAX as usize {
            let i: [u32; 16] = bytemuck::cast(idx);
            return bytemuck::cast(i.map(|i| data[i as usize]));
        }
        let idx = checked(v4, idx, data.len());
        // SAFETY: AVX-512F is available (the `V4` token), and `checked` proved every lane
        // index is `< data.len() <= i32::MAX`, so all 16 addresses `data.as_ptr() + 4 * idx`
        // lie inside `data`.
        let g: __m512 = unsafe { _mm512_i32gather_ps::<4>(idx, data.as_ptr()) };
        // SAFETY: both are 64 bytes of 16 `f32`; every bit pattern is valid.
        unsafe { core::mem::transmute::<__m512, f32x16>(g) }
    }

    /// `data[idx[l]]` for the 16 lanes.
    #[inline(always)]
    pub(super) fn gather_u32(v4: V4, idx: u32x16, data: &[u32]) -> u32x16 {
        if data.len() > i32::MAX as usize {
            let i: [u32; 16] = bytemuck::cast(idx);
            return bytemuck::cast(i.map(|i| data[i as usize]));
        }
        let idx = checked(v4, idx, data.len());
        // SAFETY: as in `gather`: AVX-512F is available and every lane index is in bounds.
        let g: __m512i = unsafe { _mm512_i32gather_epi32::<4>(idx, data.as_ptr().cast()) };
        // SAFETY: both are 64 bytes of plain integer data; every bit pattern is valid.
        unsafe { core::mem::transmute::<__m512i, u32x16>(g) }
    }
}
