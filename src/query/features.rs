//! Feature boxes and their culling, shared by the queries on features (proximity, CCD):
//! boxes are `f32`, closed, rounded outward from the positions; a leaf's boxes are six rows
//! (`lo xyz`, `hi xyz`) tested 64 at a time by [`boxes_meet_with`].

use pulp::Simd;

use crate::bv::swept::{f32_down, f32_up};
use dhcd_kernels::overlap::{boxes_meet_with, BoxRows, MAX_BOX_ROW};

pub(crate) type FeatureBox = ([f32; 3], [f32; 3]);

/// The union of the first `n` boxes of `rows` (empty: `+inf..-inf`).
pub(crate) fn union_of(rows: &BoxRows, n: usize) -> FeatureBox {
    let lo = |k: usize| rows[k][..n].iter().fold(f32::INFINITY, |m, &x| m.min(x));
    let hi = |k: usize| {
        rows[3 + k][..n]
            .iter()
            .fold(f32::NEG_INFINITY, |m, &x| m.max(x))
    };
    ([lo(0), lo(1), lo(2)], [hi(0), hi(1), hi(2)])
}

/// The bits of boxes `base..base + 64` of the first `n` of `rows` that meet `probe` (bit
/// `j` for box `base + j`).
#[inline(always)]
pub(crate) fn meeting<S: Simd>(
    simd: S,
    probe: &FeatureBox,
    rows: &BoxRows,
    base: usize,
    n: usize,
) -> u64 {
    let m = (n - base).min(MAX_BOX_ROW);
    let part: BoxRows = std::array::from_fn(|f| &rows[f][base..]);
    boxes_meet_with(simd, probe.0, probe.1, part, m)
}

/// Whether two closed boxes meet.
#[inline(always)]
pub(crate) fn meet(a: &FeatureBox, b: &FeatureBox) -> bool {
    (0..3).all(|k| a.0[k] <= b.1[k] && b.0[k] <= a.1[k])
}

/// `b` grown by `m` along every axis, rounded outward.
#[inline(always)]
pub(crate) fn grown(b: &FeatureBox, m: f32) -> FeatureBox {
    (
        b.0.map(|x| (x - m).next_down()),
        b.1.map(|x| (x + m).next_up()),
    )
}

/// The closed box of points `p` (`f32` values of the hierarchy's positions), widened by an
/// ulp when they are roundings of `f64` positions, so it holds the exact points too.
#[inline(always)]
pub(crate) fn points_box<const N: usize>(p: [[f32; 3]; N], rounded: bool) -> FeatureBox {
    let mut b = (p[0], p[0]);
    for q in &p[1..] {
        b.0 = std::array::from_fn(|k| b.0[k].min(q[k]));
        b.1 = std::array::from_fn(|k| b.1[k].max(q[k]));
    }
    if rounded {
        (b.0.map(f32::next_down), b.1.map(f32::next_up))
    } else {
        b
    }
}

/// The closed box of `f64` points, rounded outward to `f32`.
#[inline(always)]
pub(crate) fn points_box_f64<const N: usize>(p: [[f64; 3]; N]) -> FeatureBox {
    let mut lo = p[0];
    let mut hi = p[0];
    for q in &p[1..] {
        for k in 0..3 {
            lo[k] = lo[k].min(q[k]);
            hi[k] = hi[k].max(q[k]);
        }
    }
    (lo.map(f32_down), hi.map(f32_up))
}

/// An edge (internal vertex indices) as its original indices, smaller first, and its
/// internal indices in that same order. `order` maps internal to original indices.
#[inline(always)]
pub(crate) fn ordered_edge(order: &[u32], [s, t]: [u32; 2]) -> ([u32; 2], [u32; 2]) {
    let (os, ot) = (order[s as usize], order[t as usize]);
    if os < ot {
        ([os, ot], [s, t])
    } else {
        ([ot, os], [t, s])
    }
}
