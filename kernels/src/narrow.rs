//! The narrow phase's front filter: the *candidate pairs* of two blocks of triangles (the
//! triangles of two leaves, in structure-of-arrays form), as one bit row per triangle of
//! the first block. A pair is a candidate when
//!
//! 1. the pairing allows it (self-collision excludes pairs sharing a vertex index, and pairs
//!    `j <= i` inside one leaf),
//! 2. the closed boxes overlap (comparisons only: exact), and
//! 3. no separating plane is certified: neither triangle has all three corners strictly on
//!    one side of the other's plane, by a semi-static floating-point filter (below).
//!
//! Every dropped pair certainly does not intersect, so running the exact test on the
//! candidates alone gives exactly the contacts of the exact test on every pair.
//!
//! **The plane filter.** In `f32`, `s = det[u, v, e]` with `u = b - a`, `v = c - a` (the
//! plane triangle's edges from corner `a`) and `e = d - a` (the tested corner), computed as
//! `(e_x N_x + e_y N_y) + e_z N_z` with `N = u x v`, next to the permanent
//! `P = (|e_x| M_x + |e_y| M_y) + |e_z| M_z`, `M_x = |u_y v_z| + |u_z v_y|` (cyclically),
//! from the same rounded products. That is Shewchuk's `orient3d` arithmetic (a Laplace
//! expansion of the same determinant: rounded differences times rounded 2x2 minors of rounded
//! differences), whose rounding error is at most `(7 + 56 eps) eps P` (eps = 2^-24) when
//! nothing underflows. Gradual underflow adds an absolute error of at most `2^-150` per
//! product, which the products by `e` scale: at most `(2 |e|_1 + 3) 2^-150` in all. A sign is
//! certified only when `|s| > 8 eps P + 2^-126 (|e|_1 + 2)`, which covers both with margin
//! (and the rounding of the bound itself). The absolute term is the smallest *normal* `f32`,
//! not the `2^-147` the underflow needs: a subnormal operand costs an FP assist of about a
//! hundred cycles on x86, and with a subnormal constant every bound paid six (measured: half
//! of a cloth self-collision step). It only gives up certifying determinants below about
//! `1e-38`, i.e. triangles of sides below about `1e-12`, which the exact test then decides.
//! Overflow gives an infinite `P` (so `|s|` can never exceed the bound: `|s| <= P` holds in
//! floating point by monotonic rounding); NaN compares false. So a certified sign is the exact sign of the determinant, for every `f32` input.
//! A degenerate triangle has `N = M = 0` and certifies nothing.
//!
//! Results are bit-identical to [`leaf_candidates_scalar`] on every backend (same operation
//! order, no fused multiply-add).

use crate::lanes::{load_prefix, load_prefix_u32, mask_bits};
use crate::Tile;
use pulp::{Simd, WithSimd};

/// Largest second block: the bits of one row.
pub const MAX_ROW: usize = 64;

/// The relative factor of the plane filter's certification bound: `8 eps`, `eps = 2^-24`.
pub const PLANE_ERR: f32 = 8.0 * (f32::EPSILON / 2.0);
/// The absolute factor for gradual underflow: `2^-126`, the smallest normal `f32` (a
/// subnormal factor would make every bound an FP assist; see the module doc).
pub const PLANE_TINY: f32 = f32::MIN_POSITIVE;

/// Triangles in structure-of-arrays form: a [`Tile`] of fifteen fields (coordinate `k` of
/// corner `c` is field `3c + k`, then the closed box: min x, y, z, max x, y, z) and a tile of
/// their three corner indices (used by the self pairings only), from entry `offset` on.
/// Padding past the tested count is allowed.
#[derive(Clone, Copy, Debug)]
pub struct TriSoa<'a> {
    tile: Tile<'a>,
    vertex: &'a [u32],
    offset: usize,
}

impl<'a> TriSoa<'a> {
    /// Panics unless `tile` has 15 fields and `vertex` 3 fields of the same stride.
    #[inline]
    pub fn new(tile: Tile<'a>, vertex: &'a [u32]) -> Self {
        assert!(
            tile.has_fields(15) && vertex.len() == 3 * tile.stride(),
            "TriSoa: 9 corner coordinates and 6 box bounds, 3 corner indices"
        );
        Self {
            tile,
            vertex,
            offset: 0,
        }
    }

    /// Coordinate `k` of corner `c`.
    #[inline(always)]
    pub fn corner(&self, c: usize, k: usize) -> &'a [f32] {
        &self.tile.field(3 * c + k)[self.offset..]
    }
    /// Box min along `k`.
    #[inline(always)]
    pub fn lo(&self, k: usize) -> &'a [f32] {
        &self.tile.field(9 + k)[self.offset..]
    }
    /// Box max along `k`.
    #[inline(always)]
    pub fn hi(&self, k: usize) -> &'a [f32] {
        &self.tile.field(12 + k)[self.offset..]
    }
    /// Corner `c`'s vertex index.
    #[inline(always)]
    pub fn vertex(&self, c: usize) -> &'a [u32] {
        let s = self.tile.stride();
        &self.vertex[c * s + self.offset..(c + 1) * s]
    }

    /// Entries from the offset on.
    #[inline(always)]
    pub fn len(&self) -> usize {
        self.tile.stride() - self.offset
    }

    #[inline(always)]
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Triangle `t`'s corners.
    #[inline(always)]
    pub fn corners(&self, t: usize) -> [[f32; 3]; 3] {
        let c = |c: usize, k: usize| self.corner(c, k)[t];
        [
            [c(0, 0), c(0, 1), c(0, 2)],
            [c(1, 0), c(1, 1), c(1, 2)],
            [c(2, 0), c(2, 1), c(2, 2)],
        ]
    }

    /// The first `n` entries of every field, sliced once (hot loops then index without
    /// re-slicing; `n` bounds every index).
    #[inline(always)]
    fn fields(&self, n: usize) -> Fields<'a> {
        let s = self.tile.stride();
        let o = self.offset;
        let f = |k: usize| -> &'a [f32] { &self.tile.field(k)[o..o + n] };
        Fields {
            corner: [[f(0), f(1), f(2)], [f(3), f(4), f(5)], [f(6), f(7), f(8)]],
            lo: [f(9), f(10), f(11)],
            hi: [f(12), f(13), f(14)],
            vertex: [
                &self.vertex[o..o + n],
                &self.vertex[s + o..s + o + n],
                &self.vertex[2 * s + o..2 * s + o + n],
            ],
        }
    }

    /// The triangles from `start` on.
    #[inline(always)]
    pub fn skip(&self, start: usize) -> TriSoa<'a> {
        assert!(start <= self.len());
        TriSoa {
            offset: self.offset + start,
            ..*self
        }
    }
}

/// The fields of `n` triangles of a [`TriSoa`], each sliced to `n`.
struct Fields<'a> {
    corner: [[&'a [f32]; 3]; 3],
    lo: [&'a [f32]; 3],
    hi: [&'a [f32]; 3],
    vertex: [&'a [u32]; 3],
}

impl Fields<'_> {
    #[inline(always)]
    fn corners(&self, t: usize) -> [[f32; 3]; 3] {
        let c = &self.corner;
        [
            [c[0][0][t], c[0][1][t], c[0][2][t]],
            [c[1][0][t], c[1][1][t], c[1][2][t]],
            [c[2][0][t], c[2][1][t], c[2][2][t]],
        ]
    }
}

/// Which pairs `(i, j)` of two blocks are allowed.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[non_exhaustive]
pub enum Pairing {
    /// Every pair (two objects).
    All,
    /// Pairs sharing no vertex index (two parts of one mesh).
    NoSharedVertex,
    /// Pairs `i < j` sharing no vertex index (one block with itself).
    NoSharedVertexUpper,
}

// ---------------------------------------------------------------------------------------
// scalar

/// A triangle's plane from corner 0: `N = u x v` and `M` (see the module doc).
#[inline(always)]
fn plane(t: &[[f32; 3]; 3]) -> ([f32; 3], [f32; 3]) {
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
fn side(a: &[f32; 3], n: &[f32; 3], m: &[f32; 3], d: &[f32; 3]) -> i32 {
    let e = [d[0] - a[0], d[1] - a[1], d[2] - a[2]];
    let s = e[0] * n[0] + e[1] * n[1] + e[2] * n[2];
    let p = e[0].abs() * m[0] + e[1].abs() * m[1] + e[2].abs() * m[2];
    let l = e[0].abs() + e[1].abs() + e[2].abs();
    let bound = PLANE_ERR * p + PLANE_TINY * (l + 2.0);
    i32::from(s > bound) - i32::from(s < 0.0 - bound)
}

/// Whether the triangle `d` lies certainly strictly on one side of `t`'s plane.
#[inline(always)]
fn separated(t: &[[f32; 3]; 3], d: &[[f32; 3]; 3]) -> bool {
    let (n, m) = plane(t);
    let s = d.map(|p| side(&t[0], &n, &m, &p));
    (s[0] == 1 && s[1] == 1 && s[2] == 1) || (s[0] == -1 && s[1] == -1 && s[2] == -1)
}

/// Whether a separating plane of `a` or `b` is certified (the plane filter on one pair).
pub fn plane_separated(a: &[[f32; 3]; 3], b: &[[f32; 3]; 3]) -> bool {
    separated(a, b) || separated(b, a)
}

fn check(a: &TriSoa, na: usize, b: &TriSoa, nb: usize, out: &[u64]) {
    assert!(
        nb <= MAX_ROW,
        "the second block holds at most {MAX_ROW} triangles"
    );
    assert!(
        na <= a.len() && nb <= b.len(),
        "more triangles tested than the blocks hold"
    );
    assert!(
        out.len() >= na,
        "one output row per triangle of the first block"
    );
}

/// Scalar reference of [`leaf_candidates`] (one pair at a time).
pub fn leaf_candidates_scalar(
    a: TriSoa,
    na: usize,
    b: TriSoa,
    nb: usize,
    pairing: Pairing,
    out: &mut [u64],
) {
    check(&a, na, &b, nb, out);
    for i in 0..na {
        let ta = a.corners(i);
        let va = [a.vertex(0)[i], a.vertex(1)[i], a.vertex(2)[i]];
        let mut row = 0;
        for j in 0..nb {
            if pairing == Pairing::NoSharedVertexUpper && j <= i {
                continue;
            }
            if pairing != Pairing::All && (0..3).any(|c| va.contains(&b.vertex(c)[j])) {
                continue;
            }
            let boxes = (0..3).all(|k| a.lo(k)[i] <= b.hi(k)[j] && b.lo(k)[j] <= a.hi(k)[i]);
            if boxes && !plane_separated(&ta, &b.corners(j)) {
                row |= 1 << j;
            }
        }
        out[i] = row;
    }
}

/// The candidate pairs of the first `na` triangles of `a` and the first `nb <= MAX_ROW` of
/// `b`: `out[i]` gets bit `j` set iff `(i, j)` is allowed by `pairing`, the boxes overlap and
/// no separating plane is certified. Panics if `nb > MAX_ROW`, a block is shorter than its
/// count, or `out` is shorter than `na`. (It does not count the allowed pairs, `N_P`: that
/// is a fact of the mesh's topology, which the caller tabulates once.)
pub fn leaf_candidates(
    a: TriSoa,
    na: usize,
    b: TriSoa,
    nb: usize,
    pairing: Pairing,
    out: &mut [u64],
) {
    crate::arch().dispatch(LeafCandidates {
        a,
        na,
        b,
        nb,
        pairing,
        out,
    })
}

struct LeafCandidates<'a> {
    a: TriSoa<'a>,
    na: usize,
    b: TriSoa<'a>,
    nb: usize,
    pairing: Pairing,
    out: &'a mut [u64],
}

impl WithSimd for LeafCandidates<'_> {
    type Output = ();
    #[inline(always)]
    fn with_simd<S: Simd>(self, simd: S) {
        leaf_candidates_with(
            simd,
            self.a,
            self.na,
            self.b,
            self.nb,
            self.pairing,
            self.out,
        )
    }
}

/// The low `n` bits set (`n <= 64`).
#[inline(always)]
fn low_bits(n: usize) -> u64 {
    if n >= 64 {
        u64::MAX
    } else {
        (1u64 << n) - 1
    }
}

#[inline(always)]
fn splat3<S: Simd>(simd: S, v: [f32; 3]) -> [S::f32s; 3] {
    [
        simd.splat_f32s(v[0]),
        simd.splat_f32s(v[1]),
        simd.splat_f32s(v[2]),
    ]
}

/// [`leaf_candidates`] on the backend `simd` (inlined into the caller's dispatched body).
///
/// PERF: the second block is loaded one vector of lanes at a time, with its planes, and
/// every triangle of the first block is tested against it from registers; the shared-vertex
/// mask only for rows with a box hit, the plane filter only for rows with a pair left after
/// both (most rows of neighbouring leaves have no hit: the mask was 15% of a cloth step when
/// every row built it to count `N_P`). No closures here: they may be compiled without the
/// dispatched target features.
#[inline(always)]
pub fn leaf_candidates_with<S: Simd>(
    simd: S,
    a: TriSoa,
    na: usize,
    b: TriSoa,
    nb: usize,
    pairing: Pairing,
    out: &mut [u64],
) {
    check(&a, na, &b, nb, out);
    for row in out[..na].iter_mut() {
        *row = 0;
    }
    // B is read in whole vectors: its fields over the lanes covering `nb` (padding allowed).
    let len = nb.next_multiple_of(S::F32_LANES).min(b.len());
    let (fa, fb) = (a.fields(na), b.fields(len));
    let (err, tiny, two, zero) = (
        simd.splat_f32s(PLANE_ERR),
        simd.splat_f32s(PLANE_TINY),
        simd.splat_f32s(2.0),
        simd.splat_f32s(0.0),
    );
    let mut base = 0;
    while base < nb {
        let end = (base + S::F32_LANES).min(len);
        let lanes_valid = low_bits((nb - base).min(S::F32_LANES));
        let mut blo = [zero; 3];
        let mut bhi = [zero; 3];
        let mut bc = [[zero; 3]; 3];
        for k in 0..3 {
            blo[k] = load_prefix(simd, &fb.lo[k][base..end]);
            bhi[k] = load_prefix(simd, &fb.hi[k][base..end]);
            for c in 0..3 {
                bc[c][k] = load_prefix(simd, &fb.corner[c][k][base..end]);
            }
        }
        let (bn, bm) = plane_simd(simd, &bc);
        let bv = if pairing == Pairing::All {
            None
        } else {
            Some([
                load_prefix_u32(simd, &fb.vertex[0][base..end]),
                load_prefix_u32(simd, &fb.vertex[1][base..end]),
                load_prefix_u32(simd, &fb.vertex[2][base..end]),
            ])
        };
        for i in 0..na {
            let mut valid = lanes_valid;
            if pairing == Pairing::NoSharedVertexUpper {
                // Only j > i.
                valid &= !low_bits((i + 1).saturating_sub(base));
            }
            if valid == 0 {
                continue;
            }
            let mut hit = simd.less_than_or_equal_f32s(simd.splat_f32s(fa.lo[0][i]), bhi[0]);
            hit = simd.and_m32s(
                hit,
                simd.less_than_or_equal_f32s(blo[0], simd.splat_f32s(fa.hi[0][i])),
            );
            for k in 1..3 {
                hit = simd.and_m32s(
                    hit,
                    simd.less_than_or_equal_f32s(simd.splat_f32s(fa.lo[k][i]), bhi[k]),
                );
                hit = simd.and_m32s(
                    hit,
                    simd.less_than_or_equal_f32s(blo[k], simd.splat_f32s(fa.hi[k][i])),
                );
            }
            let mut bits = u64::from(mask_bits(simd, hit)) & valid;
            if bits == 0 {
                continue;
            }
            if let Some(bv) = &bv {
                let mut share = simd.equal_u32s(simd.splat_u32s(fa.vertex[0][i]), bv[0]);
                for k in 0..3 {
                    let v = simd.splat_u32s(fa.vertex[k][i]);
                    for (c, w) in bv.iter().enumerate() {
                        if k != 0 || c != 0 {
                            share = simd.or_m32s(share, simd.equal_u32s(v, *w));
                        }
                    }
                }
                bits &= !u64::from(mask_bits(simd, share));
            }
            if bits == 0 {
                continue;
            }
            let ta = fa.corners(i);
            let (an, am) = plane(&ta);
            let pc = [
                splat3(simd, ta[0]),
                splat3(simd, ta[1]),
                splat3(simd, ta[2]),
            ];
            // The block's corners against triangle i's plane, then i's corners against the
            // block's planes.
            let sep_a = separated_simd(
                simd,
                [err, tiny, two, zero],
                &pc[0],
                &splat3(simd, an),
                &splat3(simd, am),
                &bc,
            );
            let sep_b = separated_simd(simd, [err, tiny, two, zero], &bc[0], &bn, &bm, &pc);
            bits &= !u64::from(mask_bits(simd, simd.or_m32s(sep_a, sep_b)));
            out[i] |= bits << base;
        }
        base += S::F32_LANES;
    }
}

/// The lane-wise [`plane`].
#[inline(always)]
fn plane_simd<S: Simd>(simd: S, t: &[[S::f32s; 3]; 3]) -> ([S::f32s; 3], [S::f32s; 3]) {
    let mut u = t[0];
    let mut v = t[0];
    for k in 0..3 {
        u[k] = simd.sub_f32s(t[1][k], t[0][k]);
        v[k] = simd.sub_f32s(t[2][k], t[0][k]);
    }
    let (yz, zy) = (simd.mul_f32s(u[1], v[2]), simd.mul_f32s(u[2], v[1]));
    let (zx, xz) = (simd.mul_f32s(u[2], v[0]), simd.mul_f32s(u[0], v[2]));
    let (xy, yx) = (simd.mul_f32s(u[0], v[1]), simd.mul_f32s(u[1], v[0]));
    (
        [
            simd.sub_f32s(yz, zy),
            simd.sub_f32s(zx, xz),
            simd.sub_f32s(xy, yx),
        ],
        [
            abs_sum(simd, yz, zy),
            abs_sum(simd, zx, xz),
            abs_sum(simd, xy, yx),
        ],
    )
}

#[inline(always)]
fn abs_sum<S: Simd>(simd: S, a: S::f32s, b: S::f32s) -> S::f32s {
    simd.add_f32s(simd.abs_f32s(a), simd.abs_f32s(b))
}

/// The lane-wise [`separated`] of the three points `d` against the plane `(a, n, m)`;
/// `c = [PLANE_ERR, PLANE_TINY, 2, 0]` splatted.
#[inline(always)]
fn separated_simd<S: Simd>(
    simd: S,
    c: [S::f32s; 4],
    a: &[S::f32s; 3],
    n: &[S::f32s; 3],
    m: &[S::f32s; 3],
    d: &[[S::f32s; 3]; 3],
) -> S::m32s {
    let [err, tiny, two, zero] = c;
    let mut pos = simd.less_than_or_equal_f32s(zero, two); // all lanes true
    let mut neg = pos;
    for p in d {
        let e = [
            simd.sub_f32s(p[0], a[0]),
            simd.sub_f32s(p[1], a[1]),
            simd.sub_f32s(p[2], a[2]),
        ];
        let s = simd.add_f32s(
            simd.add_f32s(simd.mul_f32s(e[0], n[0]), simd.mul_f32s(e[1], n[1])),
            simd.mul_f32s(e[2], n[2]),
        );
        let ae = [
            simd.abs_f32s(e[0]),
            simd.abs_f32s(e[1]),
            simd.abs_f32s(e[2]),
        ];
        let perm = simd.add_f32s(
            simd.add_f32s(simd.mul_f32s(ae[0], m[0]), simd.mul_f32s(ae[1], m[1])),
            simd.mul_f32s(ae[2], m[2]),
        );
        let l = simd.add_f32s(simd.add_f32s(ae[0], ae[1]), ae[2]);
        let bound = simd.add_f32s(
            simd.mul_f32s(err, perm),
            simd.mul_f32s(tiny, simd.add_f32s(l, two)),
        );
        pos = simd.and_m32s(pos, simd.greater_than_f32s(s, bound));
        neg = simd.and_m32s(neg, simd.less_than_f32s(s, simd.sub_f32s(zero, bound)));
    }
    simd.or_m32s(pos, neg)
}
