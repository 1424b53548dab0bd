//! The narrow phase of one leaf pair: every triangle of one leaf against the other leaf's
//! contiguous run, filtered as bit masks before the exact test.
//!
//! Per triangle `i` of leaf A, rows of up to 64 triangles of leaf B go through
//! 1. the closed-box test (`box_row`),
//! 2. for self-collision, the shared-vertex mask (`share_row`: such pairs are never contacts
//!    and are not counted in `N_P`),
//! 3. the plane filter (`plane_row`: drops pairs certainly separated by one triangle's plane),
//!
//! and only the surviving bits reach [`triangles_intersect`]. Each filter only drops pairs
//! that cannot intersect, so the contacts are exactly those of the exact test on every pair.
//! `N_P` counts every triangle pair of the leaf pair (the cost model's unit), minus the
//! vertex-sharing pairs of a self query.

use dhcd_kernels::narrow::{box_row_with, plane_row_with, share_row_with, PlaneProbe, MAX_ROW};
use pulp::Simd;

use super::triangles_intersect;
use crate::hierarchy::LeafTris;

/// One leaf of a leaf pair: its cached triangles (padded slots), their original indices
/// and their corner indices (padded slots; self queries).
#[derive(Clone, Copy)]
pub(crate) struct LeafSide<'a> {
    pub(crate) tris: LeafTris<'a>,
    pub(crate) order: &'a [u32],
    pub(crate) vertex: [&'a [u32]; 3],
}

/// Which pairs of a leaf pair are candidates.
#[derive(Clone, Copy, PartialEq, Eq)]
pub(crate) enum Pairing {
    /// Two objects: every `(i, j)`.
    Objects,
    /// Two distinct leaves of one object: every `(i, j)` sharing no vertex.
    SelfLeaves,
    /// One leaf with itself: `(i, j)`, `i < j`, sharing no vertex.
    SelfLeaf,
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

/// Tests the candidate pairs of leaves `a` x `b`; pushes contacts (original indices;
/// `[min, max]` for self queries) and returns the number of pairs counted in `N_P`.
#[inline(always)]
pub(crate) fn leaf_pair<S: Simd>(
    simd: S,
    a: &LeafSide,
    b: &LeafSide,
    pairing: Pairing,
    out: &mut Vec<[u32; 2]>,
) -> u64 {
    let self_query = pairing != Pairing::Objects;
    let (nb, slots) = (b.tris.len, b.tris.boxes.len());
    let mut counted = 0u64;
    for i in 0..a.tris.len {
        let (lo, hi) = a.tris.boxes.get(i);
        let v = [a.vertex[0][i], a.vertex[1][i], a.vertex[2][i]];
        let mut probe = None;
        let mut base = 0;
        while base < nb {
            let n = (nb - base).min(MAX_ROW);
            // One row holds the whole (padded) leaf unless it is longer than a row.
            let row = if base == 0 && slots <= MAX_ROW {
                b.tris
            } else {
                b.tris.slice(base..(base + MAX_ROW).min(slots))
            };
            let mut valid = low_bits(n);
            if pairing == Pairing::SelfLeaf {
                // Only j > i.
                valid &= !low_bits((i + 1).saturating_sub(base));
            }
            let mut candidates = box_row_with(simd, lo, hi, row.boxes, n) & valid;
            if self_query {
                let end = base + row.boxes.len();
                let rv = [
                    &b.vertex[0][base..end],
                    &b.vertex[1][base..end],
                    &b.vertex[2][base..end],
                ];
                let share = share_row_with(simd, v, rv, n);
                counted += u64::from((valid & !share).count_ones());
                candidates &= !share;
            } else {
                counted += n as u64;
            }
            if candidates != 0 {
                let corners = a.tris.corners(i);
                let probe = probe.get_or_insert_with(|| PlaneProbe::new(&corners));
                candidates = plane_row_with(simd, probe, row.corner, candidates);
                while candidates != 0 {
                    let j = candidates.trailing_zeros() as usize;
                    candidates &= candidates - 1;
                    if triangles_intersect(&corners, &row.corners(j)) {
                        let (ti, tj) = (a.order[i], b.order[base + j]);
                        out.push(if self_query {
                            [ti.min(tj), ti.max(tj)]
                        } else {
                            [ti, tj]
                        });
                    }
                }
            }
            base += MAX_ROW;
        }
    }
    counted
}
