//! The narrow phase of one leaf pair: the verdicts of the kernel on the two leaves' triangles
//! (`dhcd_kernels::narrow::leaf_contacts_with`: closed boxes, shared vertices for self-collision,
//! certified separating planes, then the certified canonical form), then the exact test on
//! the pairs it left undecided.
//!
//! The kernel only drops pairs that cannot intersect and only reports pairs that do, so the
//! contacts are exactly those of the exact test on every pair (debug builds re-check every
//! certified contact with the exact test).
//!
//! `f64` hierarchies (`ROUNDED`): the tiles hold the nearest `f32`s of the exact corners with
//! boxes rounded outward; the kernel's rounded variant only drops pairs certainly apart for
//! the exact corners, and every other pair gets the exact test on the `f64` corners. `N_P` counts every triangle pair of the leaf pair (the cost
//! model's unit), minus the vertex-sharing pairs of a self query, which the region tree
//! tabulates (`RegionTree::shared_pairs`): the kernel never counts.

use dhcd_kernels::narrow::{
    leaf_candidates_rounded_with, leaf_contacts_with, Pairing, Row, TriSoa, MAX_ROW,
};
use pulp::Simd;

use super::tritri::{intersects, intersects_given_boxes_overlap};
use crate::hierarchy::LeafTris;

/// One leaf of a leaf pair: its cached triangles, their original indices, and the exact
/// positions of an `f64` hierarchy (internal vertex order).
#[derive(Clone, Copy)]
pub(crate) struct LeafSide<'a> {
    pub(crate) tris: LeafTris<'a>,
    pub(crate) order: &'a [u32],
    pub(crate) exact: Option<&'a [[f64; 3]]>,
}

/// Triangle `i` of `soa` with its exact corners: from `exact` (internal vertex order) or
/// the `f32` corners widened.
#[inline(always)]
fn corners_f64(soa: &TriSoa, i: usize, exact: Option<&[[f64; 3]]>) -> [[f64; 3]; 3] {
    match exact {
        Some(p) => std::array::from_fn(|c| p[soa.vertex(c)[i] as usize]),
        None => soa.corners(i).map(|c| c.map(f64::from)),
    }
}

/// Which pairs of a leaf pair are tested.
#[derive(Clone, Copy, PartialEq, Eq)]
pub(crate) enum Leaves {
    /// Leaves of two objects: every `(i, j)`.
    Objects,
    /// Two distinct leaves of one object: every `(i, j)` sharing no vertex.
    SelfDistinct,
    /// One leaf with itself: `(i, j)`, `i < j`, sharing no vertex.
    SelfSame,
}

/// Tests the candidate pairs of leaves `a` x `b`, of which `shared` share a vertex (0 for
/// two objects); pushes contacts (original indices; `[min, max]` for self queries) and
/// returns the number of pairs counted in `N_P`.
#[inline(always)]
pub(crate) fn leaf_pair<S: Simd, const ROUNDED: bool>(
    simd: S,
    a: &LeafSide,
    b: &LeafSide,
    leaves: Leaves,
    shared: u64,
    rows: &mut [Row; MAX_ROW],
    out: &mut Vec<[u32; 2]>,
) -> u64 {
    let (na, nb) = (a.tris.len, b.tris.len);
    let pairing = match leaves {
        Leaves::Objects => Pairing::All,
        // No shared vertex: the kernel skips the shared-vertex mask.
        Leaves::SelfDistinct if shared == 0 => Pairing::All,
        Leaves::SelfDistinct => Pairing::NoSharedVertex,
        Leaves::SelfSame => Pairing::NoSharedVertexUpper,
    };
    let ordered = leaves != Leaves::Objects;
    let counted = counted_pairs(na, nb, leaves, shared);
    if na <= MAX_ROW && nb <= MAX_ROW {
        // Adaptive trees: one block per leaf.
        blocks::<S, ROUNDED>(simd, a, 0, na, b, 0, nb, pairing, ordered, rows, out);
        return counted;
    }
    // Leaves longer than a block (fixed-depth trees): blocks of MAX_ROW triangles.
    for a0 in (0..na).step_by(MAX_ROW) {
        for b0 in (0..nb).step_by(MAX_ROW) {
            let pairing = match pairing {
                // One leaf with itself: blocks below the diagonal hold only j < i.
                Pairing::NoSharedVertexUpper if b0 < a0 => continue,
                Pairing::NoSharedVertexUpper if b0 > a0 => Pairing::NoSharedVertex,
                p => p,
            };
            let (ra, rb) = ((na - a0).min(MAX_ROW), (nb - b0).min(MAX_ROW));
            blocks::<S, ROUNDED>(simd, a, a0, ra, b, b0, rb, pairing, ordered, rows, out);
        }
    }
    counted
}

/// The triangle pairs of a leaf pair of `na` and `nb` triangles that `N_P` counts: every
/// pair, minus the `shared` ones sharing a vertex for a self query (one leaf with itself:
/// each unordered pair once).
#[inline(always)]
pub(crate) fn counted_pairs(na: usize, nb: usize, leaves: Leaves, shared: u64) -> u64 {
    let allowed = match leaves {
        Leaves::Objects | Leaves::SelfDistinct => na * nb,
        Leaves::SelfSame => na * na.saturating_sub(1) / 2,
    };
    allowed as u64 - shared
}

/// Triangles `a0..a0 + na` of `a` against `b0..b0 + nb` of `b` (`nb <= MAX_ROW`); contacts
/// as `[min, max]` when `ordered`.
#[allow(clippy::too_many_arguments)]
#[inline(always)]
fn blocks<S: Simd, const ROUNDED: bool>(
    simd: S,
    a: &LeafSide,
    a0: usize,
    na: usize,
    b: &LeafSide,
    b0: usize,
    nb: usize,
    pairing: Pairing,
    ordered: bool,
    rows: &mut [Row; MAX_ROW],
    out: &mut Vec<[u32; 2]>,
) {
    let (sa, sb) = (a.tris.soa.skip(a0), b.tris.soa.skip(b0));
    debug_assert!(na <= MAX_ROW);
    if ROUNDED {
        leaf_candidates_rounded_with(simd, sa, na, sb, nb, pairing, &mut rows[..na]);
    } else {
        leaf_contacts_with(simd, sa, na, sb, nb, pairing, &mut rows[..na]);
    }
    let contact = |i: usize, j: usize| {
        let (oi, oj) = (a.order[a0 + i], b.order[b0 + j]);
        if ordered {
            [oi.min(oj), oi.max(oj)]
        } else {
            [oi, oj]
        }
    };
    for (i, row) in rows[..na].iter().enumerate() {
        if row.candidates() == 0 {
            continue;
        }
        let ti = sa.corners(i);
        let mut bits = row.contact;
        while bits != 0 {
            let j = bits.trailing_zeros() as usize;
            bits &= bits - 1;
            debug_assert!(intersects(&ti, &sb.corners(j)), "certified contact");
            out.push(contact(i, j));
        }
        let mut bits = row.undecided;
        if ROUNDED {
            let ti = corners_f64(&sa, i, a.exact);
            while bits != 0 {
                let j = bits.trailing_zeros() as usize;
                bits &= bits - 1;
                if intersects(&ti, &corners_f64(&sb, j, b.exact)) {
                    out.push(contact(i, j));
                }
            }
            continue;
        }
        while bits != 0 {
            let j = bits.trailing_zeros() as usize;
            bits &= bits - 1;
            if intersects_given_boxes_overlap(&ti, &sb.corners(j)) {
                out.push(contact(i, j));
            }
        }
    }
}
