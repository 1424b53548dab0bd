//! The narrow phase of one leaf pair: the candidate pairs of the two leaves' triangles
//! (`dhcd_kernels::narrow::leaf_candidates`: closed boxes, shared vertices for
//! self-collision, certified separating planes), then the exact test on the candidates.
//!
//! Every filter only drops pairs that cannot intersect, so the contacts are exactly those of
//! the exact test on every pair. `N_P` counts every triangle pair of the leaf pair (the cost
//! model's unit), minus the vertex-sharing pairs of a self query.

use dhcd_kernels::narrow::{leaf_candidates_with, Pairing, MAX_ROW};
use pulp::Simd;

use super::triangles_intersect;
use crate::hierarchy::LeafTris;

/// One leaf of a leaf pair: its cached triangles and their original indices.
#[derive(Clone, Copy)]
pub(crate) struct LeafSide<'a> {
    pub(crate) tris: LeafTris<'a>,
    pub(crate) order: &'a [u32],
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

/// Tests the candidate pairs of leaves `a` x `b`; pushes contacts (original indices;
/// `[min, max]` for self queries) and returns the number of pairs counted in `N_P`.
#[inline(always)]
pub(crate) fn leaf_pair<S: Simd>(
    simd: S,
    a: &LeafSide,
    b: &LeafSide,
    leaves: Leaves,
    out: &mut Vec<[u32; 2]>,
) -> u64 {
    let (na, nb) = (a.tris.len, b.tris.len);
    let (sa, sb) = (&a.tris.soa, &b.tris.soa);
    let mut rows = [0u64; MAX_ROW];
    let mut counted = 0;
    // Blocks of at most MAX_ROW triangles on each side (one block unless a leaf is larger:
    // fixed-depth trees).
    for a0 in (0..na).step_by(MAX_ROW) {
        let ra = (na - a0).min(MAX_ROW);
        for b0 in (0..nb).step_by(MAX_ROW) {
            let rb = (nb - b0).min(MAX_ROW);
            let pairing = match leaves {
                Leaves::Objects => Pairing::All,
                Leaves::SelfDistinct => Pairing::NoSharedVertex,
                // One leaf with itself: blocks below the diagonal hold only j < i.
                Leaves::SelfSame if b0 < a0 => continue,
                Leaves::SelfSame if b0 > a0 => Pairing::NoSharedVertex,
                Leaves::SelfSame => Pairing::NoSharedVertexUpper,
            };
            let (ba, bb) = if na <= MAX_ROW && nb <= MAX_ROW {
                (*sa, *sb)
            } else {
                let ea = (a0 + MAX_ROW).min(sa.len());
                let eb = (b0 + MAX_ROW).min(sb.len());
                (sa.slice(a0..ea), sb.slice(b0..eb))
            };
            counted += leaf_candidates_with(simd, ba, ra, bb, rb, pairing, &mut rows[..ra]);
            for (i, &row) in rows[..ra].iter().enumerate() {
                let mut bits = row;
                if bits == 0 {
                    continue;
                }
                let ti = ba.corners(i);
                while bits != 0 {
                    let j = bits.trailing_zeros() as usize;
                    bits &= bits - 1;
                    if triangles_intersect(&ti, &bb.corners(j)) {
                        let (oi, oj) = (a.order[a0 + i], b.order[b0 + j]);
                        out.push(if leaves == Leaves::Objects {
                            [oi, oj]
                        } else {
                            [oi.min(oj), oi.max(oj)]
                        });
                    }
                }
            }
        }
    }
    counted
}
