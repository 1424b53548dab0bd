//! The query: a stackless, level-synchronous traversal of two hierarchies, then the exact
//! narrow phase on the triangle pairs of overlapping leaves.
//!
//! The frontier is an array of node pairs. Each round refits the stale nodes it names (lazy
//! refit), batch-tests all its pairs with one kernel call, and expands the overlapping pairs:
//! two leaves become a leaf pair; a leaf against an internal node pairs the leaf with the
//! node's children; two internal nodes pair all their children. Every node pair is produced
//! at most once, so no contact is reported twice.

use crate::bv::BvKind;
use crate::counters::Counters;
use crate::hierarchy::Hierarchy;
use crate::narrow;
use crate::points::Points;
use crate::tree::RegionTree;

/// Result of a query: contacts as `[triangle of A, triangle of B]` in the caller's original
/// triangle indices, sorted ascending, and the counted work.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Contacts {
    pub pairs: Vec<[u32; 2]>,
    pub counters: Counters,
}

/// Reusable scratch of a query (frontier arrays, masks, leaf pairs); keep one per thread to
/// avoid allocating every step.
#[derive(Clone, Debug, Default)]
pub struct Workspace {
    ia: Vec<u32>,
    ib: Vec<u32>,
    next_a: Vec<u32>,
    next_b: Vec<u32>,
    mask: Vec<u32>,
    leaves: Vec<[u32; 2]>,
}

/// All intersecting triangle pairs between `a` and `b`, with counters. Refits (lazily) the
/// nodes it tests.
pub fn collide<K: BvKind>(a: &mut Hierarchy<K>, b: &mut Hierarchy<K>) -> Contacts {
    collide_with(a, b, &mut Workspace::default())
}

/// [`collide`] with caller-owned scratch.
pub fn collide_with<K: BvKind>(
    a: &mut Hierarchy<K>,
    b: &mut Hierarchy<K>,
    ws: &mut Workspace,
) -> Contacts {
    let mut counters = Counters::default();
    ws.leaves.clear();
    ws.ia.clear();
    ws.ib.clear();
    ws.ia.push(0);
    ws.ib.push(0);
    while !ws.ia.is_empty() {
        a.ensure_fitted(&ws.ia);
        b.ensure_fitted(&ws.ib);
        ws.mask.resize(ws.ia.len(), 0);
        K::overlap(
            a.nodes(),
            a.points(),
            b.nodes(),
            b.points(),
            &ws.ia,
            &ws.ib,
            &mut ws.mask,
        );
        counters.bv_tests += ws.ia.len() as u64;
        expand(
            a.tree(),
            b.tree(),
            &ws.ia,
            &ws.ib,
            &ws.mask,
            &mut ws.next_a,
            &mut ws.next_b,
            &mut ws.leaves,
        );
        std::mem::swap(&mut ws.ia, &mut ws.next_a);
        std::mem::swap(&mut ws.ib, &mut ws.next_b);
    }
    counters.bv_updates = a.take_updates() + b.take_updates();

    let mut pairs = Vec::new();
    for &[la, lb] in &ws.leaves {
        counters.prim_tests += narrow_leaf_pair(a, b, la as usize, lb as usize, &mut pairs);
    }
    pairs.sort_unstable();
    counters.contacts = pairs.len() as u64;
    Contacts { pairs, counters }
}

/// Expands the overlapping pairs of one frontier into the next frontier and the leaf pairs.
#[allow(clippy::too_many_arguments)]
fn expand(
    ta: &RegionTree,
    tb: &RegionTree,
    ia: &[u32],
    ib: &[u32],
    mask: &[u32],
    next_a: &mut Vec<u32>,
    next_b: &mut Vec<u32>,
    leaves: &mut Vec<[u32; 2]>,
) {
    next_a.clear();
    next_b.clear();
    for k in 0..ia.len() {
        if mask[k] == 0 {
            continue;
        }
        let (x, y) = (ia[k] as usize, ib[k] as usize);
        match (ta.is_leaf(x), tb.is_leaf(y)) {
            (true, true) => leaves.push([x as u32, y as u32]),
            (true, false) => {
                for c in tb.children(y) {
                    next_a.push(x as u32);
                    next_b.push(c as u32);
                }
            }
            (false, true) => {
                for c in ta.children(x) {
                    next_a.push(c as u32);
                    next_b.push(y as u32);
                }
            }
            (false, false) => {
                for cx in ta.children(x) {
                    for cy in tb.children(y) {
                        next_a.push(cx as u32);
                        next_b.push(cy as u32);
                    }
                }
            }
        }
    }
}

#[inline]
pub(crate) fn corners(p: &Points, tri: [u32; 3]) -> [[f32; 3]; 3] {
    tri.map(|v| p.get(v as usize))
}

/// Exact tests of every triangle pair of leaves `la` x `lb`; pushes the intersecting ones
/// (original indices) and returns the number of pairs tested.
fn narrow_leaf_pair<K: BvKind>(
    a: &Hierarchy<K>,
    b: &Hierarchy<K>,
    la: usize,
    lb: usize,
    out: &mut Vec<[u32; 2]>,
) -> u64 {
    let (ta, tb) = (a.tree(), b.tree());
    let ra = ta.tri_range(la);
    let rb = tb.tri_range(lb);
    for i in ra.clone() {
        let tri_a = corners(a.points(), ta.triangles()[i]);
        for j in rb.clone() {
            let tri_b = corners(b.points(), tb.triangles()[j]);
            if narrow::triangles_intersect(&tri_a, &tri_b) {
                out.push([ta.tri_order()[i], tb.tri_order()[j]]);
            }
        }
    }
    (ra.len() * rb.len()) as u64
}
