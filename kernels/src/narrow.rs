//! The narrow phase's kernel: the verdicts on the triangle pairs of two blocks of triangles
//! (the triangles of two leaves, in structure-of-arrays form), as two bit rows per triangle
//! of the first block: certain *contacts*, and *undecided* pairs the caller decides with its
//! exact test. Every other pair certainly does not intersect. A pair is a *candidate* when
//!
//! 1. the pairing allows it (self-collision excludes pairs sharing a vertex index, and pairs
//!    `j <= i` inside one leaf),
//! 2. the closed boxes overlap (comparisons only: exact), and
//! 3. no separating plane is certified: neither triangle has all three corners strictly on
//!    one side of the other's plane, by a semi-static floating-point filter (below).
//!
//! Every dropped pair certainly does not intersect, so running the exact test on the
//! candidates alone gives exactly the contacts of the exact test on every pair; most
//! candidates are then decided here too (below).
//!
//! **The plane filter.** In `f32`, `s = det[u, v, e]` with `u = b - a`, `v = c - a` (the
//! plane triangle's edges from corner `a`) and `e = d - a` (the tested corner), computed as
//! `(e_x N_x + e_y N_y) + e_z N_z` with `N = u x v`. Shewchuk's `orient3d` arithmetic (a
//! Laplace expansion of the same determinant: rounded differences times rounded 2x2 minors of
//! rounded differences) has a rounding error of at most `(7 + 56 eps) eps P` (eps = 2^-24)
//! when nothing underflows, `P = (|e_x| M_x + |e_y| M_y) + |e_z| M_z` the permanent computed
//! from the same rounded products, `M_x = |u_y v_z| + |u_z v_y|` (cyclically). Gradual
//! underflow adds an absolute error of at most `2^-150` per product, which the products by `e`
//! scale: at most `(2 |e|_1 + 3) 2^-150` in all. The filter bounds `|e|` once per pair
//! instead of once per corner: both corners of every tested difference lie in the union of
//! the two triangles' closed boxes, so `|e_k| <= E_k`, the union box's extent along `k`
//! (rounded: `fl(|e_k|) <= fl(E_k)` by monotonic rounding, and so on through every rounded
//! sum and product). A sign is certified only when `|s| > 8 eps P' + 2^-126 (|E|_1 + 2)`,
//! `P' = (E_x M_x + E_y M_y) + E_z M_z >= P`, which covers both errors with margin (and the
//! rounding of the bound itself), with one bound per plane for the three corners tested
//! against it (a third of the arithmetic of a bound per corner; nearby triangles have `|e|`
//! about `E` anyway). The absolute term is the smallest *normal* `f32`, not the `2^-147` the
//! underflow needs: a subnormal operand costs an FP assist of about a hundred cycles on x86,
//! and with a subnormal constant every bound paid six (measured: half of a cloth
//! self-collision step). It only gives up certifying determinants below about `1e-38`, i.e.
//! triangles of sides below about `1e-12`, which the exact test then decides. Overflow gives
//! an infinite bound (so `|s|` can never exceed it: `|s| <= P` holds in floating point by
//! monotonic rounding); NaN compares false. So a certified sign is the exact sign of the
//! determinant, for every `f32` input. A degenerate triangle has `N = M = 0` and certifies
//! nothing.
//!
//! **The decision.** A candidate whose six corner-plane signs are all certified (none is
//! zero, none unknown) is then decided by Guigue and Devillers' canonical form ("Fast and
//! robust triangle-triangle overlap test using orientation predicates", JGT 8(1), 2003): each
//! triangle is rotated so that its vertex alone on its side of the other's plane comes first,
//! the other triangle's last two vertices swapped when that vertex is on the negative side,
//! and the pair intersects iff two more orientations are `>= 0`. Those two are computed with
//! the same arithmetic from the same `f32` corners, with the bound of each point (`|e|` in
//! place of `E`), so a certified verdict is the exact one. The pair is then a *contact* (both certified positive) or dropped (one
//! certified negative); everything else is *undecided* and left to the caller's exact test.
//! The `dhcd` crate's exact test (`src/narrow/tritri.rs`) is the same formulation on exact
//! predicates, and its tests check every certified verdict against it.
//!
//! **The projection.** A pair neither stage certifies (a corner on or within rounding of the
//! other's plane: coplanar pairs of a flat sheet, the diagonal triangles of two planar quads
//! across an edge) is then tried in the projection that drops the dominant axis of the first
//! triangle's normal: disjoint projections mean disjoint triangles, and two convex polygons
//! are disjoint iff an edge line of one separates them. Such an edge is certified when the
//! edge's third corner is certainly on one side of it and the other triangle's three corners
//! certainly on the other, each sign by a 2D orientation `e_u (c_v - p_v) - e_v (c_u - p_u)`
//! in `f32` and Shewchuk's `orient2d` bound (`(3 + 16 eps) eps` times the sum of the two
//! products' magnitudes; `8 eps` here) plus the smallest normal `f32` for underflow. It only
//! ever drops pairs, and runs on the rows the other stages leave undecided (flat grid:
//! 75 -> 20 ms a step on 100 K triangles; armadillo -16%).
//!
//! **Rounded corners.** For `f64` geometry the blocks hold the nearest `f32`s of the exact
//! corners, with boxes rounded outward so that they hold the exact triangles
//! ([`leaf_candidates_rounded_with`]). Each exact coordinate lies within
//! `delta = 2^-24 M + 2^-126` of its `f32` (`M` the largest magnitude in the pair's union
//! box), so every difference of two points moves by at most `2 delta` per axis and, by
//! multilinearity, a determinant of three differences by at most `12 delta sigma_2(E)`
//! (`sigma_2(E) = E_x E_y + E_y E_z + E_z E_x`, every difference of either corner set bounded
//! by the union extents `E`). The plane filter then certifies a sign only beyond its bound
//! plus `13 delta sigma_2(E)` (the `13` covers the rounding of the slack itself), which is
//! then the exact sign for the `f64` corners: a separating plane certified this way
//! separates the exact triangles. The canonical form and the projection are not run (their
//! verdicts would need the same slack); every candidate is left *undecided*, for the caller's
//! exact test on the `f64` corners.
//!
//! Results are bit-identical to [`crate::reference::leaf_contacts_scalar`] (and
//! [`crate::reference::leaf_candidates_rounded_scalar`]) on every backend (same operation
//! order, no fused multiply-add; the canonical form's vertex choices are selects).

use crate::lanes::{load_prefix, load_prefix_u32, mask_bits};
use crate::{refit, Soa3, Tile};
use pulp::Simd;

/// Lane counts for which the filter culls rows per lane vector of the second block (see
/// [`leaf_contacts_with`]).
const CULL_ROWS_PER_VECTOR: std::ops::RangeInclusive<usize> = 4..=8;

/// `0, 1, 2, ...`: lane indices.
const IOTA: [f32; 64] = {
    let mut a = [0.0; 64];
    let mut i = 0;
    while i < 64 {
        a[i] = i as f32;
        i += 1;
    }
    a
};

/// Largest second block: the bits of one row.
pub const MAX_ROW: usize = 64;

/// The relative factor of the plane filter's certification bound: `8 eps`, `eps = 2^-24`.
pub(crate) const PLANE_ERR: f32 = 8.0 * (f32::EPSILON / 2.0);
/// The absolute factor for gradual underflow: `2^-126`, the smallest normal `f32` (a
/// subnormal factor would make every bound an FP assist; see the module doc).
pub(crate) const PLANE_TINY: f32 = f32::MIN_POSITIVE;

/// The factor of the rounded-corner slack `13 delta sigma_2(E)` (module doc, "Rounded
/// corners").
const SLACK_FACTOR: f32 = 13.0;

/// The rounding error of one `f32` coordinate of magnitude at most `m`, rounded up:
/// `2^-24 m + 2^-126`.
#[inline(always)]
fn coordinate_error(m: f32) -> f32 {
    m * (f32::EPSILON / 2.0) + f32::MIN_POSITIVE
}

/// The rounded-corner slack of a pair (module doc): `13 delta sigma_2(E)`, `delta` the
/// coordinate error at the union box's largest magnitude `m`, in the operation order the
/// SIMD body repeats.
#[inline(always)]
pub(crate) fn rounding_slack(ext: &[f32; 3], m: f32) -> f32 {
    let s2 = (ext[0] * ext[1] + ext[1] * ext[2]) + ext[2] * ext[0];
    (SLACK_FACTOR * coordinate_error(m)) * s2
}

/// The largest magnitude of the union of two boxes.
#[inline(always)]
pub(crate) fn union_magnitude(a: &([f32; 3], [f32; 3]), b: &([f32; 3], [f32; 3])) -> f32 {
    let mut m = 0.0f32;
    for k in 0..3 {
        m = m
            .max(a.0[k].min(b.0[k]).abs())
            .max(a.1[k].max(b.1[k]).abs());
    }
    m
}

/// Fields of a triangle tile: coordinate `k` of corner `c` is field `3c + k`, then the closed
/// box: min x, y, z (fields 9-11), max x, y, z (fields 12-14).
const TRI_FIELDS: usize = 15;
/// Entries of a group's union box (min xyz, max xyz), after its tile.
const UNION_FIELDS: usize = 6;

/// Triangles in structure-of-arrays form: a [`Tile`] of fifteen fields (coordinate `k` of
/// corner `c` is field `3c + k`, then the closed box: min x, y, z, max x, y, z) and a tile of
/// their three corner indices (used by the self pairings only), from entry `offset` on.
/// Padding past the tested count is allowed. Optionally a box known to hold every
/// triangle's closed box ([`TriSoa::with_bounds`]), which spares the kernels computing it.
///
/// A *group* is how a caller caches one leaf's triangles: the tile of `stride` slots, then
/// the union of its boxes (six entries), written by [`fill_group_with`] and read by
/// [`TriSoa::from_group`]; [`TriSoa::group_len`] is its length. The layout is defined here
/// only.
#[derive(Clone, Copy, Debug)]
pub struct TriSoa<'a> {
    tile: Tile<'a>,
    vertex: &'a [u32],
    offset: usize,
    bounds: Option<Bounds>,
}

/// A box as `(min, max)` corners.
pub type Bounds = ([f32; 3], [f32; 3]);

impl<'a> TriSoa<'a> {
    /// Panics unless `tile` has 15 fields and `vertex` 3 fields of the same stride.
    #[inline]
    pub fn new(tile: Tile<'a>, vertex: &'a [u32]) -> Self {
        assert!(
            tile.has_fields(TRI_FIELDS) && vertex.len() == 3 * tile.stride(),
            "TriSoa: 9 corner coordinates and 6 box bounds, 3 corner indices"
        );
        Self {
            tile,
            vertex,
            offset: 0,
            bounds: None,
        }
    }

    /// Entries of a group of `stride` slots: the tile, then the union box.
    #[inline]
    pub const fn group_len(stride: usize) -> usize {
        TRI_FIELDS * stride + UNION_FIELDS
    }

    /// The triangles of a group written by [`fill_group_with`], with its union box as
    /// their bounds. `vertex` is the group's corner-index tile (as given to the fill).
    #[inline]
    pub fn from_group(group: &'a [f32], stride: usize, vertex: &'a [u32]) -> Self {
        let (tile, union) = group.split_at(TRI_FIELDS * stride);
        let bounds = (
            [union[0], union[1], union[2]],
            [union[3], union[4], union[5]],
        );
        TriSoa::new(Tile::new(tile, stride), vertex).with_bounds(bounds)
    }

    /// The same triangles with `bounds`, a box that contains the closed box of every
    /// triangle of the tile (a larger box is allowed: the kernels only use it to skip
    /// triangles that cannot meet the other block, so a box too large costs work, never a
    /// pair). A box that misses a triangle would lose its pairs: debug builds check it.
    /// Callers that cache a leaf's triangles compute it once per leaf instead of once per
    /// leaf pair.
    #[inline]
    pub fn with_bounds(self, bounds: Bounds) -> Self {
        Self {
            bounds: Some(bounds),
            ..self
        }
    }

    /// The box given by [`TriSoa::with_bounds`] (a group's union box), if any.
    #[inline(always)]
    pub fn bounds(&self) -> Option<Bounds> {
        self.bounds
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

    /// Whether no triangle remains from the offset on.
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
            bounds: self.bounds,
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
    /// [`TriSoa::with_bounds`].
    bounds: Option<Bounds>,
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

/// Side of `d` against the plane `(a, n, m)`, with the bound of the point itself: `1`
/// certainly positive, `-1` certainly negative, `0` unknown (or on the plane).
#[inline(always)]
fn side(a: &[f32; 3], n: &[f32; 3], m: &[f32; 3], d: &[f32; 3]) -> i32 {
    let (e, s) = det(a, n, d);
    let p = e[0].abs() * m[0] + e[1].abs() * m[1] + e[2].abs() * m[2];
    let l = e[0].abs() + e[1].abs() + e[2].abs();
    let bound = PLANE_ERR * p + PLANE_TINY * (l + 2.0);
    i32::from(s > bound) - i32::from(s < 0.0 - bound)
}

/// Writes the group (see [`TriSoa`]) of `n` triangles over `stride` slots: the tile (row
/// `3c + k` holds axis `k` of corner `c`, rows 9-11 the boxes' minima, rows 12-14 their
/// maxima), then the union of the boxes (min xyz, max xyz), which the narrow kernel would
/// otherwise compute for every leaf pair. Corner `c` of triangle `i` is point
/// `vertices[c * stride + i]` of `p`. `rounded`: the points are the nearest `f32`s of `f64`
/// coordinates, so each box is widened to the next `f32` outward, which holds the exact
/// corners.
///
/// PERF: one gather loop per corner and axis, then the box rows from the corner rows. The
/// per-triangle form (gather three points, write fifteen scattered entries) took ~190
/// instructions a triangle and 10-13% of an n-body step.
pub fn fill_group_with<S: Simd>(
    simd: S,
    group: &mut [f32],
    stride: usize,
    n: usize,
    vertices: &[u32],
    p: Soa3,
    rounded: bool,
) {
    assert!(
        group.len() == TriSoa::group_len(stride) && n <= stride && vertices.len() == 3 * stride,
        "fill_group_with: a group of {stride} slots, 3 corner-index rows"
    );
    let (tile, union) = group.split_at_mut(TRI_FIELDS * stride);
    let (corners, boxes) = tile.split_at_mut(9 * stride);
    let axes = [p.x, p.y, p.z];
    for c in 0..3 {
        let ids = &vertices[c * stride..][..n];
        for (k, axis) in axes.iter().enumerate() {
            let row = &mut corners[(3 * c + k) * stride..][..n];
            for (x, &v) in row.iter_mut().zip(ids) {
                *x = axis[v as usize];
            }
        }
    }
    let (lo, hi) = boxes.split_at_mut(3 * stride);
    for k in 0..3 {
        let corner = |c: usize| &corners[(3 * c + k) * stride..][..n];
        let (a, b, c) = (corner(0), corner(1), corner(2));
        let lo = &mut lo[k * stride..][..n];
        let hi = &mut hi[k * stride..][..n];
        for i in 0..n {
            lo[i] = a[i].min(b[i]).min(c[i]);
            hi[i] = a[i].max(b[i]).max(c[i]);
        }
        if rounded {
            for x in lo.iter_mut() {
                *x = x.next_down();
            }
            for x in hi.iter_mut() {
                *x = x.next_up();
            }
        }
    }
    // The union of the boxes: the minima's least, the maxima's greatest (the SIMD bounds
    // reduction; a single `min` chain per axis waits on each one's latency).
    union[..3].copy_from_slice(&refit::bounds_with(simd, three_rows(lo, stride, n)).0);
    union[3..].copy_from_slice(&refit::bounds_with(simd, three_rows(hi, stride, n)).1);
}

/// The first `n` entries of three consecutive rows of `stride` slots, as x, y and z.
fn three_rows(rows: &[f32], stride: usize, n: usize) -> Soa3<'_> {
    let row = |k: usize| &rows[k * stride..][..n];
    Soa3::new(row(0), row(1), row(2))
}

/// A triangle's closed box, as the callers' leaf tiles store it.
#[inline(always)]
pub(crate) fn corner_box(t: &[[f32; 3]; 3]) -> ([f32; 3], [f32; 3]) {
    let lo = std::array::from_fn(|k| t[0][k].min(t[1][k]).min(t[2][k]));
    let hi = std::array::from_fn(|k| t[0][k].max(t[1][k]).max(t[2][k]));
    (lo, hi)
}

/// The extents `E` of the union of two closed boxes (module doc).
#[inline(always)]
pub(crate) fn union_extents(a: &([f32; 3], [f32; 3]), b: &([f32; 3], [f32; 3])) -> [f32; 3] {
    std::array::from_fn(|k| a.1[k].max(b.1[k]) - a.0[k].min(b.0[k]))
}

/// The filter's certification bound for every corner of a pair against the plane of
/// magnitudes `m`, the pair's union extents `ext` (module doc), plus `slack` (0, or the
/// rounded-corner slack).
#[inline(always)]
fn pair_bound(m: &[f32; 3], ext: &[f32; 3], slack: f32) -> f32 {
    let p = ext[0] * m[0] + ext[1] * m[1] + ext[2] * m[2];
    let l = ext[0] + ext[1] + ext[2];
    PLANE_ERR * p + (PLANE_TINY * (l + 2.0) + slack)
}

/// The filter's sides of the three points `d` against the plane `(a, n)` with the pair's
/// `bound`: `1` certainly positive, `-1` certainly negative, `0` unknown.
#[inline(always)]
fn sides_within(a: &[f32; 3], n: &[f32; 3], bound: f32, d: &[[f32; 3]; 3]) -> [i32; 3] {
    d.map(|d| {
        let s = det(a, n, &d).1;
        i32::from(s > bound) - i32::from(s < 0.0 - bound)
    })
}

/// `e = d - a` and the determinant `s = e . n` of the plane `(a, n)` (module doc), in the
/// operation order every backend repeats.
#[inline(always)]
fn det(a: &[f32; 3], n: &[f32; 3], d: &[f32; 3]) -> ([f32; 3], f32) {
    let e = [d[0] - a[0], d[1] - a[1], d[2] - a[2]];
    (e, e[0] * n[0] + e[1] * n[1] + e[2] * n[2])
}

/// The filter's signs of a pair: `a`'s corners against `b`'s plane, `b`'s against `a`'s,
/// `ext` the union extents of their boxes.
#[inline(always)]
pub(crate) fn filter_signs(
    a: &[[f32; 3]; 3],
    b: &[[f32; 3]; 3],
    ext: &[f32; 3],
    slack: f32,
) -> ([i32; 3], [i32; 3]) {
    let (an, am) = plane(a);
    let (bn, bm) = plane(b);
    (
        sides_within(&b[0], &bn, pair_bound(&bm, ext, slack), a),
        sides_within(&a[0], &an, pair_bound(&am, ext, slack), b),
    )
}

/// All three signs certain and equal.
#[inline(always)]
pub(crate) fn one_side(s: [i32; 3]) -> bool {
    s[0] != 0 && s[0] == s[1] && s[0] == s[2]
}

/// The axis of `n`'s largest magnitude (the first on ties, 0 for NaN): the axis a pair's
/// projection drops, from its first triangle's normal.
#[inline(always)]
fn dominant_axis(n: &[f32; 3]) -> usize {
    let a = n.map(f32::abs);
    if a[2] > a[0] && a[2] > a[1] {
        2
    } else if a[1] > a[0] {
        1
    } else {
        0
    }
}

/// The two coordinates kept when axis `k` is dropped.
#[inline(always)]
fn kept_axes(k: usize) -> (usize, usize) {
    ((k + 1) % 3, (k + 2) % 3)
}

/// The certified sign of the 2D orientation of `c` against the directed line through `p`
/// with direction `e` (`e_u (c_v - p_v) - e_v (c_u - p_u)`, one point's coordinates as
/// `[u, v]`): `1`, `-1`, or `0` when not certified (module doc, "The projection").
#[inline(always)]
fn orient2(p: [f32; 2], e: [f32; 2], c: [f32; 2]) -> i32 {
    let (l, r) = (e[0] * (c[1] - p[1]), e[1] * (c[0] - p[0]));
    let o = l - r;
    let bound = PLANE_ERR * (l.abs() + r.abs()) + PLANE_TINY;
    i32::from(o > bound) - i32::from(o < 0.0 - bound)
}

/// Whether an edge line of `a` or `b` certainly separates their projections along the
/// dominant axis of `a`'s normal `n_a` (then the triangles are apart): the edge's third
/// corner certainly on one side, the other triangle's three corners certainly on the other.
#[inline(always)]
fn projected_apart(a: &[[f32; 3]; 3], b: &[[f32; 3]; 3], n_a: &[f32; 3]) -> bool {
    let (u, v) = kept_axes(dominant_axis(n_a));
    let flat = |t: &[[f32; 3]; 3]| t.map(|c| [c[u], c[v]]);
    let (a, b) = (flat(a), flat(b));
    let edge_separates = |t: &[[f32; 2]; 3], o: &[[f32; 2]; 3]| {
        (0..3).any(|i| {
            let (p, q, r) = (t[i], t[(i + 1) % 3], t[(i + 2) % 3]);
            let e = [q[0] - p[0], q[1] - p[1]];
            let side = orient2(p, e, r);
            side != 0 && o.iter().all(|&c| orient2(p, e, c) == -side)
        })
    };
    edge_separates(&a, &b) || edge_separates(&b, &a)
}

/// One row of verdicts: triangle `i` of the first block against the second block, bit `j`
/// for triangle `j`. The two rows are disjoint; a pair in neither certainly does not
/// intersect (or is not allowed by the pairing).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Row {
    /// Pairs that certainly intersect.
    pub contact: u64,
    /// Pairs the filters could not decide: the caller's exact test does.
    pub undecided: u64,
}

impl Row {
    /// The pairs not certainly apart: `contact | undecided`.
    #[inline(always)]
    pub fn candidates(&self) -> u64 {
        self.contact | self.undecided
    }
}

/// The verdict on one pair (the unit of the scalar references in [`crate::reference`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Verdict {
    /// Certainly disjoint.
    Apart,
    /// Certainly intersecting.
    Contact,
    /// Not certified either way.
    Undecided,
}

/// [`pair_verdict`] with the union extents of the pair's boxes: the plane filter and the
/// canonical form, then the projection for the pairs they leave undecided.
pub(crate) fn verdict_within(a: &[[f32; 3]; 3], b: &[[f32; 3]; 3], ext: &[f32; 3]) -> Verdict {
    match planes_and_canonical(a, b, ext) {
        Verdict::Undecided if projected_apart(a, b, &plane(a).0) => Verdict::Apart,
        v => v,
    }
}

/// The plane filter and the certified canonical form on one pair.
fn planes_and_canonical(a: &[[f32; 3]; 3], b: &[[f32; 3]; 3], ext: &[f32; 3]) -> Verdict {
    // sa: a's corners against b's plane; sb: b's corners against a's plane.
    let (sa, sb) = filter_signs(a, b, ext, 0.0);
    if one_side(sa) || one_side(sb) {
        return Verdict::Apart;
    }
    if sa.contains(&0) || sb.contains(&0) {
        return Verdict::Undecided;
    }
    // a rotated so its lone vertex comes first; b's last two swapped if that one is below.
    let i = lone(sa);
    let (p1, mut q1, mut r1) = (a[i], a[(i + 1) % 3], a[(i + 2) % 3]);
    let (tb, tsb) = if sa[i] < 0 {
        ([b[0], b[2], b[1]], [sb[0], sb[2], sb[1]])
    } else {
        (*b, sb)
    };
    let j = lone(tsb);
    let (p2, q2, r2) = (tb[j], tb[(j + 1) % 3], tb[(j + 2) % 3]);
    if tsb[j] < 0 {
        (q1, r1) = (r1, q1);
    }
    let o1 = oriented_side(&[q2, p2, p1], &q1);
    let o2 = oriented_side(&[r2, p2, r1], &p1);
    if o1 < 0 || o2 < 0 {
        Verdict::Apart
    } else if o1 > 0 && o2 > 0 {
        Verdict::Contact
    } else {
        Verdict::Undecided
    }
}

/// The index of the one sign that differs from the other two (all nonzero, not all equal).
#[inline(always)]
fn lone(s: [i32; 3]) -> usize {
    if s[1] == s[2] {
        0
    } else if s[0] == s[2] {
        1
    } else {
        2
    }
}

/// The certified sign of `det[t1 - t0, t2 - t0, d - t0]` (0: not certified).
#[inline(always)]
fn oriented_side(t: &[[f32; 3]; 3], d: &[f32; 3]) -> i32 {
    let (n, m) = plane(t);
    side(&t[0], &n, &m, d)
}

pub(crate) fn check(a: &TriSoa, na: usize, b: &TriSoa, nb: usize, out: &[Row]) {
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

/// The low `n` bits set (`n <= 64`): the mask of a batch's first `n` entries.
#[inline(always)]
pub fn low_bits(n: usize) -> u64 {
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

/// The splatted constants of the plane arithmetic: `PLANE_ERR`, `PLANE_TINY`, `2`, `0`.
#[derive(Clone, Copy)]
struct Consts<S: Simd> {
    err: S::f32s,
    tiny: S::f32s,
    two: S::f32s,
    zero: S::f32s,
    /// Every lane true.
    all: S::m32s,
}

impl<S: Simd> Consts<S> {
    #[inline(always)]
    fn new(simd: S) -> Self {
        let (two, zero) = (simd.splat_f32s(2.0), simd.splat_f32s(0.0));
        Self {
            err: simd.splat_f32s(PLANE_ERR),
            tiny: simd.splat_f32s(PLANE_TINY),
            two,
            zero,
            all: simd.less_than_or_equal_f32s(zero, two),
        }
    }
}

/// The verdicts on the first `na` triangles of `a` against the first `nb <= MAX_ROW` of `b`,
/// on the backend `simd` (inlined into the caller's dispatched body): `out[i]` gets bit `j`
/// in `contact` iff `(i, j)` is allowed by `pairing`, the closed boxes overlap and the pair
/// certainly intersects, in `undecided` iff it is allowed, the boxes overlap and neither a
/// separating plane nor the canonical form is certified (module doc). Panics if
/// `nb > MAX_ROW`, a block is shorter than its count, or `out` is shorter than `na`. (It
/// does not count the allowed pairs, `N_P`: that is a fact of the mesh's topology, which the
/// caller tabulates once.)
///
///
/// Two passes: the filter (boxes, shared vertices, separating planes) leaves the candidates
/// in `undecided`, then the canonical form decides the candidates it can certify.
///
/// PERF: first each block's union box against the other block's triangles: only the rows
/// and lane vectors that meet it are visited (leaves whose volumes overlap but whose
/// triangles are far apart, the norm with spheres, cost two union boxes; measured 1.1-1.3x on
/// DH and sphere steps, 18-22% fewer instructions). The second block is loaded one vector of
/// lanes at a time (its boxes; its vertices, corners and planes only once a row's box meets
/// one of its lanes: 0.3-0.8% of a real frame's instructions) and every remaining triangle
/// of the first block is tested against it from registers. With 4-8 lanes and several vectors in B, the rows are
/// first culled by the vector's own box (a reduction of the loaded boxes): with 8 lanes 6-13%
/// fewer instructions a step on the real frames (cachegrind, x86-v3); with 16 lanes the box
/// is looser and its reduction dearer, about break-even by count, so not done there; the
/// shared-vertex
/// mask only for rows with a box hit, the plane filter only for rows with a pair left after
/// both (most rows of neighbouring leaves have no hit: the mask was 15% of a cloth step when
/// every row built it to count `N_P`). The decision is a second pass over the rows with
/// candidates: inside the filter's loop, inlined, its dozen live masks spilled the filter's
/// registers, and out of line, the call made every vector register live across it a stack
/// slot (both measured ~18% slower filters on a mesh with few candidates). No closures
/// here: they may be compiled without the dispatched target features.
#[inline(always)]
pub fn leaf_contacts_with<S: Simd>(
    simd: S,
    a: TriSoa,
    na: usize,
    b: TriSoa,
    nb: usize,
    pairing: Pairing,
    out: &mut [Row],
) {
    leaf_rows::<S, false>(simd, a, na, b, nb, pairing, out)
}

/// [`leaf_contacts_with`] for blocks whose corners are the nearest `f32`s of `f64` corners
/// and whose boxes are rounded outward (module doc, "Rounded corners"): `out[i].undecided`
/// gets bit `j` iff `(i, j)` is allowed, the boxes overlap and no separating plane is
/// certified for the exact corners (the slack included); `contact` is always empty. Every
/// pair left out certainly does not intersect for the exact corners.
#[inline(always)]
pub fn leaf_candidates_rounded_with<S: Simd>(
    simd: S,
    a: TriSoa,
    na: usize,
    b: TriSoa,
    nb: usize,
    pairing: Pairing,
    out: &mut [Row],
) {
    leaf_rows::<S, true>(simd, a, na, b, nb, pairing, out)
}

#[inline(always)]
fn leaf_rows<S: Simd, const ROUNDED: bool>(
    simd: S,
    a: TriSoa,
    na: usize,
    b: TriSoa,
    nb: usize,
    pairing: Pairing,
    out: &mut [Row],
) {
    check(&a, na, &b, nb, out);
    for row in out[..na].iter_mut() {
        *row = Row::default();
    }
    // B is read in whole vectors: its fields over the lanes covering `nb` (padding allowed).
    let len = nb.next_multiple_of(S::F32_LANES).min(b.len());
    let fb = b.fields(len);
    let k = Consts::new(simd);
    // The passes keep masks of rows in a `u64`: rows go in chunks of at most MAX_ROW. Rows
    // are independent of their index except for the one-block-with-itself pairing, whose
    // rows from `nb - 1` on allow nothing (`j > i`), so all of its work is in the first chunk.
    let rows = match pairing {
        Pairing::NoSharedVertexUpper => na.min(MAX_ROW),
        _ => na,
    };
    let mut a0 = 0;
    while a0 < rows {
        let n = (rows - a0).min(MAX_ROW);
        let (fa, out) = (a.skip(a0).fields(n), &mut out[a0..a0 + n]);
        let mut decidable_rows = [0u64; MAX_ROW];
        let mut candidate_rows = [0u64; MAX_ROW];
        if filter::<S, ROUNDED>(
            simd,
            k,
            &fa,
            n,
            &fb,
            nb,
            len,
            pairing,
            out,
            &mut decidable_rows,
            &mut candidate_rows,
        ) {
            decide(simd, k, &fa, &fb, nb, len, out, &decidable_rows);
        }
        if !ROUNDED
            && candidate_rows[..nb.div_ceil(S::F32_LANES)]
                .iter()
                .any(|&r| r != 0)
        {
            project(simd, k, &fa, &fb, nb, len, out, &candidate_rows);
        }
        a0 += n;
    }
}

/// The filter pass of [`leaf_contacts_with`]: the candidates in `undecided`, and per lane
/// vector of B (`base / F32_LANES`) the rows with candidates the decision pass may certify
/// and the rows with any candidate. Returns whether there is any of the first kind (never,
/// for `ROUNDED` corners: their candidates are all left undecided).
#[allow(clippy::too_many_arguments)]
#[inline(always)]
fn filter<S: Simd, const ROUNDED: bool>(
    simd: S,
    k: Consts<S>,
    fa: &Fields,
    na: usize,
    fb: &Fields,
    nb: usize,
    len: usize,
    pairing: Pairing,
    out: &mut [Row],
    decidable_rows: &mut [u64; MAX_ROW],
    candidate_rows: &mut [u64; MAX_ROW],
) -> bool {
    let mut any = 0;
    // Rows of A that meet B's union box, lanes of B that meet A's: the others cannot meet
    // anything across (one block with itself: all of them do).
    let (rows, lanes) = if pairing == Pairing::NoSharedVertexUpper {
        (low_bits(na), low_bits(nb))
    } else {
        let (ua, ub) = (block_box(simd, fa, na), block_box(simd, fb, nb));
        (meet(simd, fa, na, &ub), meet(simd, fb, nb, &ua))
    };
    if rows == 0 || lanes == 0 {
        return false;
    }
    // Per row of A, the lanes of the current vector of B whose boxes it meets (written for
    // every row of `rows` before it is read).
    let mut box_hits = [0u64; MAX_ROW];
    let mut base = 0;
    while base < nb {
        let end = (base + S::F32_LANES).min(len);
        let lanes_valid = (lanes >> base) & low_bits((nb - base).min(S::F32_LANES));
        if lanes_valid == 0 {
            base += S::F32_LANES;
            continue;
        }
        let mut blo = [k.zero; 3];
        let mut bhi = [k.zero; 3];
        for d in 0..3 {
            blo[d] = load_prefix(simd, &fb.lo[d][base..end]);
            bhi[d] = load_prefix(simd, &fb.hi[d][base..end]);
        }
        // With several vectors of B, the rows of A that meet this vector's box: tighter than
        // B's union box (vectors of lane-ordered leaves are compact groups).
        let rows = if CULL_ROWS_PER_VECTOR.contains(&S::F32_LANES) && nb > S::F32_LANES {
            let vbox = vector_box(simd, (base + S::F32_LANES).min(nb) - base, &blo, &bhi);
            let rows = rows & meet(simd, fa, na, &vbox);
            if rows == 0 {
                base += S::F32_LANES;
                continue;
            }
            rows
        } else {
            rows
        };
        // Two passes: the box test of every row first, without a branch per row (a row
        // without hits mispredicted about a quarter of the time), then the rest of the
        // filter on the rows with hits only.
        let mut hit_rows = 0u64;
        let mut todo = rows;
        while todo != 0 {
            let i = todo.trailing_zeros() as usize;
            todo &= todo - 1;
            let mut valid = lanes_valid;
            if pairing == Pairing::NoSharedVertexUpper {
                // Only j > i.
                valid &= !low_bits((i + 1).saturating_sub(base));
            }
            let mut hit = simd.less_than_or_equal_f32s(simd.splat_f32s(fa.lo[0][i]), bhi[0]);
            hit = simd.and_m32s(
                hit,
                simd.less_than_or_equal_f32s(blo[0], simd.splat_f32s(fa.hi[0][i])),
            );
            for d in 1..3 {
                hit = simd.and_m32s(
                    hit,
                    simd.less_than_or_equal_f32s(simd.splat_f32s(fa.lo[d][i]), bhi[d]),
                );
                hit = simd.and_m32s(
                    hit,
                    simd.less_than_or_equal_f32s(blo[d], simd.splat_f32s(fa.hi[d][i])),
                );
            }
            let bits = u64::from(mask_bits(simd, hit)) & valid;
            box_hits[i] = bits;
            hit_rows |= u64::from(bits != 0) << i;
        }
        if hit_rows == 0 {
            // No box hit: the vector's corners, planes and vertices are not needed.
            base += S::F32_LANES;
            continue;
        }
        let mut todo = hit_rows;
        if pairing != Pairing::All {
            let bv = [
                load_prefix_u32(simd, &fb.vertex[0][base..end]),
                load_prefix_u32(simd, &fb.vertex[1][base..end]),
                load_prefix_u32(simd, &fb.vertex[2][base..end]),
            ];
            // The shared-vertex pass, on the rows with box hits (again no branch per row).
            let mut kept = 0u64;
            while todo != 0 {
                let i = todo.trailing_zeros() as usize;
                todo &= todo - 1;
                let mut share = simd.equal_u32s(simd.splat_u32s(fa.vertex[0][i]), bv[0]);
                for d in 0..3 {
                    let v = simd.splat_u32s(fa.vertex[d][i]);
                    for (c, w) in bv.iter().enumerate() {
                        if d != 0 || c != 0 {
                            share = simd.or_m32s(share, simd.equal_u32s(v, *w));
                        }
                    }
                }
                let bits = box_hits[i] & !u64::from(mask_bits(simd, share));
                box_hits[i] = bits;
                kept |= u64::from(bits != 0) << i;
            }
            todo = kept;
        }
        if todo == 0 {
            base += S::F32_LANES;
            continue;
        }
        let bc = load_corners(simd, fb, base, end);
        let (bn, bm) = plane_simd(simd, &bc);
        while todo != 0 {
            let i = todo.trailing_zeros() as usize;
            todo &= todo - 1;
            let mut bits = box_hits[i];
            let RowTri {
                n: an,
                m: am,
                c: pc,
            } = row_tri(simd, fa, i);
            // One bound per plane for its three corners, from the pairs' union boxes.
            let mut ext = [k.zero; 3];
            for d in 0..3 {
                ext[d] = simd.sub_f32s(
                    simd.max_f32s(simd.splat_f32s(fa.hi[d][i]), bhi[d]),
                    simd.min_f32s(simd.splat_f32s(fa.lo[d][i]), blo[d]),
                );
            }
            let mut tiny = simd.mul_f32s(
                k.tiny,
                simd.add_f32s(simd.add_f32s(simd.add_f32s(ext[0], ext[1]), ext[2]), k.two),
            );
            if ROUNDED {
                tiny = simd.add_f32s(tiny, slack_simd(simd, k, fa, i, &blo, &bhi, &ext));
            }
            let bound_a = bound_simd(simd, k, &ext, &splat3(simd, am), tiny);
            let bound_b = bound_simd(simd, k, &ext, &bm, tiny);
            // The block's corners against triangle i's plane, then i's corners against the
            // block's planes.
            let (sep_a, cert_a) = separated_simd(simd, k, &pc[0], &splat3(simd, an), bound_a, &bc);
            let (sep_b, cert_b) = separated_simd(simd, k, &bc[0], &bn, bound_b, &pc);
            bits &= !u64::from(mask_bits(simd, simd.or_m32s(sep_a, sep_b)));
            if ROUNDED {
                out[i].undecided |= bits << base;
                candidate_rows[base / S::F32_LANES] |= u64::from(bits != 0) << i;
                continue;
            }
            let decidable = bits & u64::from(mask_bits(simd, simd.and_m32s(cert_a, cert_b)));
            // `contact` holds the decidable candidates until the decision pass.
            out[i].contact |= decidable << base;
            out[i].undecided |= bits << base;
            decidable_rows[base / S::F32_LANES] |= u64::from(decidable != 0) << i;
            candidate_rows[base / S::F32_LANES] |= u64::from(bits != 0) << i;
            any |= decidable;
        }
        base += S::F32_LANES;
    }
    any != 0
}

/// Triangle `i` of a block as a row: its plane (`N`, `M`) and its corners splatted.
struct RowTri<S: Simd> {
    n: [f32; 3],
    m: [f32; 3],
    c: [[S::f32s; 3]; 3],
}

#[inline(always)]
fn row_tri<S: Simd>(simd: S, f: &Fields, i: usize) -> RowTri<S> {
    let t = f.corners(i);
    let (n, m) = plane(&t);
    RowTri {
        n,
        m,
        c: [splat3(simd, t[0]), splat3(simd, t[1]), splat3(simd, t[2])],
    }
}

/// The corners of entries `base..end` of a block, one vector per coordinate.
///
/// PERF: index loops; the `iter_mut().zip(..)` form of the same loads measured 7-9% slower
/// DH steps (cloth, n-body).
#[inline(always)]
fn load_corners<S: Simd>(simd: S, f: &Fields, base: usize, end: usize) -> [[S::f32s; 3]; 3] {
    let zero = simd.splat_f32s(0.0);
    let mut bc = [[zero; 3]; 3];
    for c in 0..3 {
        for d in 0..3 {
            bc[c][d] = load_prefix(simd, &f.corner[c][d][base..end]);
        }
    }
    bc
}

/// A box containing the closed boxes of the first `n` triangles of `f`: the caller's
/// [`TriSoa::with_bounds`] if given (checked in debug builds), else [`union_box`].
#[inline(always)]
fn block_box<S: Simd>(simd: S, f: &Fields, n: usize) -> Bounds {
    match f.bounds {
        Some(b) => {
            debug_assert!(
                {
                    let u = union_box(simd, f, n);
                    (0..3).all(|d| b.0[d] <= u.0[d] && u.1[d] <= b.1[d])
                },
                "TriSoa::with_bounds: the box misses a triangle"
            );
            b
        }
        None => union_box(simd, f, n),
    }
}

/// The union of the boxes whose minima and maxima are the first `n` lanes of `lo` and `hi`
/// (NaN bounds skipped; empty: `+inf..-inf`).
#[inline(always)]
fn vector_box<S: Simd>(simd: S, n: usize, lo: &[S::f32s; 3], hi: &[S::f32s; 3]) -> Bounds {
    let first = simd.less_than_f32s(
        load_prefix(simd, &IOTA[..S::F32_LANES]),
        simd.splat_f32s(n as f32),
    );
    let (inf, neg_inf) = (
        simd.splat_f32s(f32::INFINITY),
        simd.splat_f32s(f32::NEG_INFINITY),
    );
    let (mut vlo, mut vhi) = ([0.0; 3], [0.0; 3]);
    for d in 0..3 {
        // `x == x` is false on NaN.
        let keep = simd.and_m32s(first, simd.equal_f32s(lo[d], lo[d]));
        vlo[d] = simd.reduce_min_f32s(simd.select_f32s(keep, lo[d], inf));
        let keep = simd.and_m32s(first, simd.equal_f32s(hi[d], hi[d]));
        vhi[d] = simd.reduce_max_f32s(simd.select_f32s(keep, hi[d], neg_inf));
    }
    (vlo, vhi)
}

/// The union of the closed boxes of the first `n` triangles of `f` (NaN bounds skipped;
/// empty: `+inf..-inf`).
#[inline(always)]
fn union_box<S: Simd>(simd: S, f: &Fields, n: usize) -> ([f32; 3], [f32; 3]) {
    let lanes = S::F32_LANES;
    let mut lo = [f32::INFINITY; 3];
    let mut hi = [f32::NEG_INFINITY; 3];
    if n < lanes {
        for t in 0..n {
            for d in 0..3 {
                // Comparisons, not `min`: a NaN bound is skipped on every backend.
                if f.lo[d][t] < lo[d] {
                    lo[d] = f.lo[d][t];
                }
                if f.hi[d][t] > hi[d] {
                    hi[d] = f.hi[d][t];
                }
            }
        }
        return (lo, hi);
    }
    for d in 0..3 {
        let (mut vlo, mut vhi) = (simd.splat_f32s(lo[d]), simd.splat_f32s(hi[d]));
        // Whole vectors, the last one ending at `n` (overlapping is harmless here).
        let mut start = 0;
        loop {
            let x = crate::lanes::load::<S>(&f.lo[d][start..]);
            vlo = simd.select_f32s(simd.less_than_f32s(x, vlo), x, vlo);
            let x = crate::lanes::load::<S>(&f.hi[d][start..]);
            vhi = simd.select_f32s(simd.greater_than_f32s(x, vhi), x, vhi);
            if start + lanes == n {
                break;
            }
            start = (start + lanes).min(n - lanes);
        }
        lo[d] = simd.reduce_min_f32s(vlo);
        hi[d] = simd.reduce_max_f32s(vhi);
    }
    (lo, hi)
}

/// The triangles among the first `n` of `f` whose closed boxes meet the box `u`, as bits.
#[inline(always)]
fn meet<S: Simd>(simd: S, f: &Fields, n: usize, u: &([f32; 3], [f32; 3])) -> u64 {
    let mut bits = 0;
    let mut base = 0;
    while base < n {
        let end = (base + S::F32_LANES).min(n);
        let mut m = simd.less_than_or_equal_f32s(
            load_prefix(simd, &f.lo[0][base..end]),
            simd.splat_f32s(u.1[0]),
        );
        for d in 0..3 {
            if d > 0 {
                m = simd.and_m32s(
                    m,
                    simd.less_than_or_equal_f32s(
                        load_prefix(simd, &f.lo[d][base..end]),
                        simd.splat_f32s(u.1[d]),
                    ),
                );
            }
            m = simd.and_m32s(
                m,
                simd.less_than_or_equal_f32s(
                    simd.splat_f32s(u.0[d]),
                    load_prefix(simd, &f.hi[d][base..end]),
                ),
            );
        }
        bits |= u64::from(mask_bits(simd, m)) << base;
        base += S::F32_LANES;
    }
    bits & low_bits(n)
}

/// The decision pass of [`leaf_contacts_with`]: moves the candidates the canonical form
/// certifies out of `undecided` (into `contact`, or dropped).
#[allow(clippy::too_many_arguments)]
#[inline(always)]
fn decide<S: Simd>(
    simd: S,
    k: Consts<S>,
    fa: &Fields,
    fb: &Fields,
    nb: usize,
    len: usize,
    out: &mut [Row],
    decidable_rows: &[u64; MAX_ROW],
) {
    let mut base = 0;
    while base < nb {
        let end = (base + S::F32_LANES).min(len);
        let lanes = low_bits(S::F32_LANES) << base;
        // The rows with decidable lanes in this vector (the filter's list).
        let mut todo = decidable_rows[base / S::F32_LANES];
        if todo == 0 {
            base += S::F32_LANES;
            continue;
        }
        let bc = load_corners(simd, fb, base, end);
        let (bn, bm) = plane_simd(simd, &bc);
        while todo != 0 {
            let i = todo.trailing_zeros() as usize;
            todo &= todo - 1;
            let decidable = (out[i].contact & lanes) >> base;
            let RowTri {
                n: an,
                m: am,
                c: pc,
            } = row_tri(simd, fa, i);
            // Every sign is certified on these lanes: "positive" is "not negative".
            let pb = positive_simd(simd, k, &pc[0], &splat3(simd, an), &splat3(simd, am), &bc);
            let pa = positive_simd(simd, k, &bc[0], &bn, &bm, &pc);
            let (yes, no) = canonical_simd(simd, k, &pc, &bc, &pa, &pb);
            let contact = decidable & u64::from(mask_bits(simd, yes));
            let apart = decidable & !contact & u64::from(mask_bits(simd, no));
            out[i].contact &= !(decidable << base);
            out[i].contact |= contact << base;
            out[i].undecided &= !((contact | apart) << base);
        }
        base += S::F32_LANES;
    }
}

/// The projection pass of [`leaf_contacts_with`]: drops the candidates still undecided
/// whose projections along the dominant axis of the row triangle's normal an edge line of
/// either triangle certainly separates ([`projected_apart`], lane-wise, same arithmetic).
#[allow(clippy::too_many_arguments)]
#[inline(always)]
fn project<S: Simd>(
    simd: S,
    k: Consts<S>,
    fa: &Fields,
    fb: &Fields,
    nb: usize,
    len: usize,
    out: &mut [Row],
    candidate_rows: &[u64; MAX_ROW],
) {
    let mut base = 0;
    while base < nb {
        let end = (base + S::F32_LANES).min(len);
        let lanes = low_bits(S::F32_LANES);
        // The rows with a candidate the other passes left undecided in this vector.
        let mut todo = 0u64;
        let mut rows = candidate_rows[base / S::F32_LANES];
        while rows != 0 {
            let i = rows.trailing_zeros() as usize;
            rows &= rows - 1;
            todo |= u64::from((out[i].undecided >> base) & lanes != 0) << i;
        }
        if todo == 0 {
            base += S::F32_LANES;
            continue;
        }
        let bc = load_corners(simd, fb, base, end);
        while todo != 0 {
            let i = todo.trailing_zeros() as usize;
            todo &= todo - 1;
            let t = fa.corners(i);
            let (u, v) = kept_axes(dominant_axis(&plane(&t).0));
            let pa = [[t[0][u], t[0][v]], [t[1][u], t[1][v]], [t[2][u], t[2][v]]];
            let pb = [
                [bc[0][u], bc[0][v]],
                [bc[1][u], bc[1][v]],
                [bc[2][u], bc[2][v]],
            ];
            // Lanes left; an edge that separates them all ends the row (often the first
            // or second: the diagonal of a quad).
            let undecided = (out[i].undecided >> base) & lanes;
            let mut left = undecided;
            // The row's edges: its third corner's side in scalar, B's corners lane-wise.
            for e in 0..3 {
                let (p, q, r) = (pa[e], pa[(e + 1) % 3], pa[(e + 2) % 3]);
                let dir = [q[0] - p[0], q[1] - p[1]];
                let side = orient2(p, dir, r);
                if side == 0 {
                    continue;
                }
                let (p, dir) = (splat2(simd, p), splat2(simd, dir));
                let mut all = k.all;
                for c in &pb {
                    let (pos, neg) = orient2_simd(simd, k, &p, &dir, c);
                    all = simd.and_m32s(all, if side > 0 { neg } else { pos });
                }
                left &= !u64::from(mask_bits(simd, all));
                if left == 0 {
                    break;
                }
            }
            // B's edges lane-wise, against the row's corners.
            for e in 0..3 {
                if left == 0 {
                    break;
                }
                let (p, q, r) = (pb[e], pb[(e + 1) % 3], pb[(e + 2) % 3]);
                let dir = [simd.sub_f32s(q[0], p[0]), simd.sub_f32s(q[1], p[1])];
                let (r_pos, r_neg) = orient2_simd(simd, k, &p, &dir, &r);
                let (mut all_pos, mut all_neg) = (k.all, k.all);
                for c in &pa {
                    let (pos, neg) = orient2_simd(simd, k, &p, &dir, &splat2(simd, *c));
                    all_pos = simd.and_m32s(all_pos, pos);
                    all_neg = simd.and_m32s(all_neg, neg);
                }
                let apart =
                    simd.or_m32s(simd.and_m32s(r_pos, all_neg), simd.and_m32s(r_neg, all_pos));
                left &= !u64::from(mask_bits(simd, apart));
            }
            out[i].undecided &= !((undecided & !left) << base);
        }
        base += S::F32_LANES;
    }
}

#[inline(always)]
fn splat2<S: Simd>(simd: S, p: [f32; 2]) -> [S::f32s; 2] {
    [simd.splat_f32s(p[0]), simd.splat_f32s(p[1])]
}

/// The lane-wise [`orient2`]: (certainly positive, certainly negative).
#[inline(always)]
fn orient2_simd<S: Simd>(
    simd: S,
    k: Consts<S>,
    p: &[S::f32s; 2],
    e: &[S::f32s; 2],
    c: &[S::f32s; 2],
) -> (S::m32s, S::m32s) {
    let l = simd.mul_f32s(e[0], simd.sub_f32s(c[1], p[1]));
    let r = simd.mul_f32s(e[1], simd.sub_f32s(c[0], p[0]));
    let o = simd.sub_f32s(l, r);
    let bound = simd.add_f32s(simd.mul_f32s(k.err, abs_sum(simd, l, r)), k.tiny);
    (
        simd.greater_than_f32s(o, bound),
        simd.less_than_f32s(o, simd.sub_f32s(k.zero, bound)),
    )
}

/// The lane-wise [`rounding_slack`] of row `i` of `fa` against the lanes `blo..bhi`, whose
/// union extents are `ext`.
#[inline(always)]
fn slack_simd<S: Simd>(
    simd: S,
    k: Consts<S>,
    fa: &Fields,
    i: usize,
    blo: &[S::f32s; 3],
    bhi: &[S::f32s; 3],
    ext: &[S::f32s; 3],
) -> S::f32s {
    // |x| as max(x, -x): comparisons and subtractions only, the same on every backend.
    let abs = |x: S::f32s| simd.max_f32s(x, simd.sub_f32s(k.zero, x));
    let mut m = k.zero;
    for d in 0..3 {
        let lo = simd.min_f32s(simd.splat_f32s(fa.lo[d][i]), blo[d]);
        let hi = simd.max_f32s(simd.splat_f32s(fa.hi[d][i]), bhi[d]);
        m = simd.max_f32s(simd.max_f32s(m, abs(lo)), abs(hi));
    }
    let delta = simd.add_f32s(
        simd.mul_f32s(m, simd.splat_f32s(f32::EPSILON / 2.0)),
        k.tiny,
    );
    let s2 = simd.add_f32s(
        simd.add_f32s(simd.mul_f32s(ext[0], ext[1]), simd.mul_f32s(ext[1], ext[2])),
        simd.mul_f32s(ext[2], ext[0]),
    );
    simd.mul_f32s(simd.mul_f32s(simd.splat_f32s(SLACK_FACTOR), delta), s2)
}

/// The lane-wise [`pair_bound`], its absolute term `tiny` given.
#[inline(always)]
fn bound_simd<S: Simd>(
    simd: S,
    k: Consts<S>,
    ext: &[S::f32s; 3],
    m: &[S::f32s; 3],
    tiny: S::f32s,
) -> S::f32s {
    let p = simd.add_f32s(
        simd.add_f32s(simd.mul_f32s(ext[0], m[0]), simd.mul_f32s(ext[1], m[1])),
        simd.mul_f32s(ext[2], m[2]),
    );
    simd.add_f32s(simd.mul_f32s(k.err, p), tiny)
}

/// The lane-wise [`sides_within`] folded: (the three points `d` all certainly strictly on
/// one side of the plane `(a, n)`, all three signs certified), with the pair's `bound`.
#[inline(always)]
fn separated_simd<S: Simd>(
    simd: S,
    k: Consts<S>,
    a: &[S::f32s; 3],
    n: &[S::f32s; 3],
    bound: S::f32s,
    d: &[[S::f32s; 3]; 3],
) -> (S::m32s, S::m32s) {
    let neg_bound = simd.sub_f32s(k.zero, bound);
    let mut pos = k.all;
    let mut neg = pos;
    let mut certified = pos;
    for p in d {
        let s = det_simd(simd, a, n, p).1;
        let (sp, sn) = (
            simd.greater_than_f32s(s, bound),
            simd.less_than_f32s(s, neg_bound),
        );
        pos = simd.and_m32s(pos, sp);
        neg = simd.and_m32s(neg, sn);
        certified = simd.and_m32s(certified, simd.or_m32s(sp, sn));
    }
    (simd.or_m32s(pos, neg), certified)
}

/// The lane-wise [`det`].
#[inline(always)]
fn det_simd<S: Simd>(
    simd: S,
    a: &[S::f32s; 3],
    n: &[S::f32s; 3],
    d: &[S::f32s; 3],
) -> ([S::f32s; 3], S::f32s) {
    let e = [
        simd.sub_f32s(d[0], a[0]),
        simd.sub_f32s(d[1], a[1]),
        simd.sub_f32s(d[2], a[2]),
    ];
    let s = simd.add_f32s(
        simd.add_f32s(simd.mul_f32s(e[0], n[0]), simd.mul_f32s(e[1], n[1])),
        simd.mul_f32s(e[2], n[2]),
    );
    (e, s)
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
    simd.add_f32s(abs_simd(simd, a), abs_simd(simd, b))
}

/// Lane-wise `|a|` (clears the sign bit). Not pulp's `abs_f32s`: that default method is only
/// `#[inline]`, and in the AVX-512 kernels it was compiled out of line, without the target
/// features, so every call went through memory and `vzeroupper` (~9% of an n-body step).
#[inline(always)]
fn abs_simd<S: Simd>(simd: S, a: S::f32s) -> S::f32s {
    simd.and_f32s(a, simd.splat_f32s(f32::from_bits(0x7fff_ffff)))
}

/// The lane-wise [`side`] of one point `d` against the plane `(a, n, m)`: (certainly
/// positive, certainly negative).
#[inline(always)]
fn side_simd<S: Simd>(
    simd: S,
    k: Consts<S>,
    a: &[S::f32s; 3],
    n: &[S::f32s; 3],
    m: &[S::f32s; 3],
    d: &[S::f32s; 3],
) -> (S::m32s, S::m32s) {
    let (e, s) = det_simd(simd, a, n, d);
    let ae = [
        abs_simd(simd, e[0]),
        abs_simd(simd, e[1]),
        abs_simd(simd, e[2]),
    ];
    let perm = simd.add_f32s(
        simd.add_f32s(simd.mul_f32s(ae[0], m[0]), simd.mul_f32s(ae[1], m[1])),
        simd.mul_f32s(ae[2], m[2]),
    );
    let l = simd.add_f32s(simd.add_f32s(ae[0], ae[1]), ae[2]);
    let bound = simd.add_f32s(
        simd.mul_f32s(k.err, perm),
        simd.mul_f32s(k.tiny, simd.add_f32s(l, k.two)),
    );
    (
        simd.greater_than_f32s(s, bound),
        simd.less_than_f32s(s, simd.sub_f32s(k.zero, bound)),
    )
}

/// The lane-wise "certainly positive" [`side`]s of the three points `d` against the plane
/// `(a, n, m)`.
#[inline(always)]
fn positive_simd<S: Simd>(
    simd: S,
    k: Consts<S>,
    a: &[S::f32s; 3],
    n: &[S::f32s; 3],
    m: &[S::f32s; 3],
    d: &[[S::f32s; 3]; 3],
) -> [S::m32s; 3] {
    [
        side_simd(simd, k, a, n, m, &d[0]).0,
        side_simd(simd, k, a, n, m, &d[1]).0,
        side_simd(simd, k, a, n, m, &d[2]).0,
    ]
}

/// Lane-wise `if m { x } else { y }` on points.
#[inline(always)]
fn select3<S: Simd>(simd: S, m: S::m32s, x: &[S::f32s; 3], y: &[S::f32s; 3]) -> [S::f32s; 3] {
    [
        simd.select_f32s(m, x[0], y[0]),
        simd.select_f32s(m, x[1], y[1]),
        simd.select_f32s(m, x[2], y[2]),
    ]
}

/// Lane-wise mask `x == y`.
#[inline(always)]
fn mask_eq<S: Simd>(simd: S, k: Consts<S>, x: S::m32s, y: S::m32s) -> S::m32s {
    simd.xor_m32s(simd.xor_m32s(x, y), k.all)
}

/// Lane-wise [`lone`] of three nonzero signs given by their positive masks: masks of "lone is
/// 0" and "lone is 1" (else 2).
#[inline(always)]
fn lone_simd<S: Simd>(simd: S, k: Consts<S>, pos: &[S::m32s; 3]) -> (S::m32s, S::m32s) {
    let l0 = mask_eq(simd, k, pos[1], pos[2]);
    let l1 = simd.and_m32s(simd.xor_m32s(l0, k.all), mask_eq(simd, k, pos[0], pos[2]));
    (l0, l1)
}

/// Lane-wise `[x0, x1, x2][lone]` for the lone masks of [`lone_simd`].
#[inline(always)]
fn pick<S: Simd>(simd: S, (l0, l1): (S::m32s, S::m32s), x: [&[S::f32s; 3]; 3]) -> [S::f32s; 3] {
    select3(simd, l0, x[0], &select3(simd, l1, x[1], x[2]))
}

/// Lane-wise `[x0, x1, x2][lone]` on masks.
#[inline(always)]
fn pick_mask<S: Simd>(
    simd: S,
    k: Consts<S>,
    (l0, l1): (S::m32s, S::m32s),
    x: [S::m32s; 3],
) -> S::m32s {
    let l2 = simd.xor_m32s(simd.or_m32s(l0, l1), k.all);
    simd.or_m32s(
        simd.or_m32s(simd.and_m32s(l0, x[0]), simd.and_m32s(l1, x[1])),
        simd.and_m32s(l2, x[2]),
    )
}

/// The lane-wise [`pair_verdict`] past the plane filter, for lanes whose six signs are
/// certified and not separating: `a` (the row's triangle, splatted) and `b` (the block's
/// triangles), `pa`/`pb` the positive masks of a's corners against b's plane and of b's
/// against a's. Returns (certainly intersecting, certainly apart).
#[inline(always)]
fn canonical_simd<S: Simd>(
    simd: S,
    k: Consts<S>,
    a: &[[S::f32s; 3]; 3],
    b: &[[S::f32s; 3]; 3],
    pa: &[S::m32s; 3],
    pb: &[S::m32s; 3],
) -> (S::m32s, S::m32s) {
    // a rotated so that its lone vertex comes first.
    let la = lone_simd(simd, k, pa);
    let p1 = pick(simd, la, [&a[0], &a[1], &a[2]]);
    let q1 = pick(simd, la, [&a[1], &a[2], &a[0]]);
    let r1 = pick(simd, la, [&a[2], &a[0], &a[1]]);
    // p1 below b's plane: swap b's last two (with their signs).
    let flip = simd.xor_m32s(pick_mask(simd, k, la, *pa), k.all);
    let b1 = select3(simd, flip, &b[2], &b[1]);
    let b2 = select3(simd, flip, &b[1], &b[2]);
    let s1 = simd.or_m32s(
        simd.and_m32s(flip, pb[2]),
        simd.and_m32s(simd.xor_m32s(flip, k.all), pb[1]),
    );
    let s2 = simd.or_m32s(
        simd.and_m32s(flip, pb[1]),
        simd.and_m32s(simd.xor_m32s(flip, k.all), pb[2]),
    );
    // b rotated so that its lone vertex comes first.
    let tb = [pb[0], s1, s2];
    let lb = lone_simd(simd, k, &tb);
    let p2 = pick(simd, lb, [&b[0], &b1, &b2]);
    let q2 = pick(simd, lb, [&b1, &b2, &b[0]]);
    let r2 = pick(simd, lb, [&b2, &b[0], &b1]);
    // p2 below a's plane: swap q1 and r1.
    let flip = simd.xor_m32s(pick_mask(simd, k, lb, tb), k.all);
    let (q1, r1) = (select3(simd, flip, &r1, &q1), select3(simd, flip, &q1, &r1));
    let (n1, m1) = plane_simd(simd, &[q2, p2, p1]);
    let (pos1, neg1) = side_simd(simd, k, &q2, &n1, &m1, &q1);
    let (n2, m2) = plane_simd(simd, &[r2, p2, r1]);
    let (pos2, neg2) = side_simd(simd, k, &r2, &n2, &m2, &p1);
    (simd.and_m32s(pos1, pos2), simd.or_m32s(neg1, neg2))
}
