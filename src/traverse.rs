//! The query: a stackless, level-synchronous traversal of two hierarchies, then the exact
//! narrow phase on the triangle pairs of overlapping leaves.
//!
//! The frontier is an array of node pairs. Each round refits the stale nodes it names (lazy
//! refit), batch-tests all its pairs with one kernel call per chunk, and expands the
//! overlapping pairs: two leaves become a leaf pair; a leaf against an internal node pairs
//! the leaf with the node's children; two internal nodes pair all their children. Every node
//! pair is produced at most once, so no contact is reported twice.
//!
//! In parallel, each round is cut into chunks of `grain` pairs (leaf pairs: `grain / 64`)
//! whose outputs are concatenated in chunk order, so contacts and counters are identical for
//! every thread count.

use rayon::prelude::*;

use crate::bv::BvKind;
use crate::counters::Counters;
use crate::error::{Error, Result};
use crate::hierarchy::Hierarchy;
use crate::narrow;
use crate::par::Par;
use crate::points::Points;
use crate::tree::RegionTree;

/// Result of a query: contacts as `[triangle of A, triangle of B]` in the caller's original
/// triangle indices, sorted ascending, and the counted work.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Contacts {
    pub pairs: Vec<[u32; 2]>,
    pub counters: Counters,
}

/// Default number of node pairs per parallel task.
pub const DEFAULT_GRAIN: usize = 1024;

/// Reusable scratch of a query (frontier arrays, masks, leaf pairs): keep one per thread to
/// avoid allocating every step. Also holds the parallel grain.
#[derive(Clone, Debug)]
pub struct Workspace {
    pub(crate) grain: usize,
    pub(crate) ia: Vec<u32>,
    pub(crate) ib: Vec<u32>,
    pub(crate) next_a: Vec<u32>,
    pub(crate) next_b: Vec<u32>,
    pub(crate) mask: Vec<u32>,
    pub(crate) leaves: Vec<[u32; 2]>,
    pub(crate) stale: Vec<u32>,
    pub(crate) sel: Vec<u32>,
}

impl Default for Workspace {
    fn default() -> Self {
        Self::with_grain(DEFAULT_GRAIN)
    }
}

impl Workspace {
    /// A workspace whose parallel tasks take `grain` node pairs each (at least 1). Small
    /// grains force splits everywhere (tests); large ones cut scheduling overhead.
    pub fn with_grain(grain: usize) -> Self {
        Self {
            grain: grain.max(1),
            ia: Vec::new(),
            ib: Vec::new(),
            next_a: Vec::new(),
            next_b: Vec::new(),
            mask: Vec::new(),
            leaves: Vec::new(),
            stale: Vec::new(),
            sel: Vec::new(),
        }
    }
}

/// All intersecting triangle pairs between `a` and `b`, with counters, on the calling
/// thread. Refits (lazily) the nodes it tests.
pub fn collide<K: BvKind>(a: &mut Hierarchy<K>, b: &mut Hierarchy<K>) -> Contacts {
    collide_with(a, b, &mut Workspace::default(), Par::Seq)
}

/// [`collide`] with caller-owned scratch and a choice of parallelism. The result does not
/// depend on `par`.
pub fn collide_with<K: BvKind>(
    a: &mut Hierarchy<K>,
    b: &mut Hierarchy<K>,
    ws: &mut Workspace,
    par: Par,
) -> Contacts {
    par.install(|| run(a, b, ws, par.is_parallel()))
}

fn run<K: BvKind>(
    a: &mut Hierarchy<K>,
    b: &mut Hierarchy<K>,
    ws: &mut Workspace,
    parallel: bool,
) -> Contacts {
    let mut counters = broad(a, b, ws, parallel);
    let narrow = narrow(a, b, &ws.leaves, ws.grain, parallel);
    debug_assert_eq!(narrow.counters.prim_tests, counters.prim_tests);
    counters.contacts = narrow.counters.contacts;
    Contacts {
        pairs: narrow.pairs,
        counters,
    }
}

/// The broad phase alone: lazy refit and traversal down to the overlapping leaf pairs, which
/// stay in `ws` ([`Workspace::leaf_pairs`]). Its counters have `bv_tests`, `bv_updates` and
/// `prim_tests` (the triangle pairs the narrow phase will test) as [`collide_with`] counts
/// them; `contacts` is 0. With [`narrow_phase`] it is [`collide_with`] split in two, for
/// benchmarks and cost-model calibration.
pub fn broad_phase<K: BvKind>(
    a: &mut Hierarchy<K>,
    b: &mut Hierarchy<K>,
    ws: &mut Workspace,
    par: Par,
) -> Counters {
    par.install(|| broad(a, b, ws, par.is_parallel()))
}

/// The narrow phase alone: exact tests of every triangle pair of the given leaf pairs (node
/// ids, as left in a [`Workspace`] by [`broad_phase`]). Counts `prim_tests` and `contacts`.
/// A pair naming a node beyond its hierarchy is an [`Error::NodeOutOfRange`], one naming an
/// internal node an [`Error::NotALeaf`].
pub fn narrow_phase<K: BvKind>(
    a: &Hierarchy<K>,
    b: &Hierarchy<K>,
    leaves: &[[u32; 2]],
    par: Par,
) -> Result<Contacts> {
    for &[la, lb] in leaves {
        for (h, n) in [(a, la), (b, lb)] {
            if n as usize >= h.node_count() {
                return Err(Error::NodeOutOfRange {
                    node: n,
                    node_count: h.node_count(),
                });
            }
            if !h.tree().is_leaf(n as usize) {
                return Err(Error::NotALeaf { node: n });
            }
        }
    }
    Ok(par.install(|| narrow(a, b, leaves, DEFAULT_GRAIN, par.is_parallel())))
}

impl Workspace {
    /// The overlapping leaf pairs (node ids) found by the last query or [`broad_phase`].
    pub fn leaf_pairs(&self) -> &[[u32; 2]] {
        &self.leaves
    }
}

/// One round of the frontier: batch-tests the pairs `ws.ia[k], ws.ib[k]` (already fitted)
/// and appends the expansion of the overlapping ones to `ws.next_a`/`ws.next_b` (children
/// pairs) and `ws.leaves` (leaf pairs), in chunk order. Returns the number of pairs tested.
/// Shared by the two-object query and self-collision (`a` and `b` the same hierarchy).
pub(crate) fn test_and_expand<K: BvKind>(
    a: &Hierarchy<K>,
    b: &Hierarchy<K>,
    ws: &mut Workspace,
    parallel: bool,
) -> u64 {
    let grain = ws.grain;
    ws.mask.resize(ws.ia.len(), 0);
    let test = |ia: &[u32], ib: &[u32], out: &mut [u32]| {
        K::overlap(a.nodes(), a.points(), b.nodes(), b.points(), ia, ib, out);
    };
    let (ta, tb) = (&**a.tree(), &**b.tree());
    if parallel && ws.ia.len() > grain {
        ws.mask
            .par_chunks_mut(grain)
            .zip(ws.ia.par_chunks(grain).zip(ws.ib.par_chunks(grain)))
            .for_each(|(out, (ia, ib))| test(ia, ib, out));
        let parts: Vec<Expansion> = ws
            .ia
            .par_chunks(grain)
            .zip(ws.ib.par_chunks(grain).zip(ws.mask.par_chunks(grain)))
            .map(|(ia, (ib, mask))| {
                let mut e = Expansion::default();
                e.expand(ta, tb, ia, ib, mask);
                e
            })
            .collect();
        for e in parts {
            ws.next_a.extend_from_slice(&e.next_a);
            ws.next_b.extend_from_slice(&e.next_b);
            ws.leaves.extend_from_slice(&e.leaves);
        }
    } else {
        test(&ws.ia, &ws.ib, &mut ws.mask);
        let mut e = Expansion {
            next_a: std::mem::take(&mut ws.next_a),
            next_b: std::mem::take(&mut ws.next_b),
            leaves: std::mem::take(&mut ws.leaves),
            sel: std::mem::take(&mut ws.sel),
        };
        e.expand(ta, tb, &ws.ia, &ws.ib, &ws.mask);
        (ws.next_a, ws.next_b, ws.leaves, ws.sel) = (e.next_a, e.next_b, e.leaves, e.sel);
    }
    ws.ia.len() as u64
}

fn broad<K: BvKind>(
    a: &mut Hierarchy<K>,
    b: &mut Hierarchy<K>,
    ws: &mut Workspace,
    parallel: bool,
) -> Counters {
    let mut counters = Counters::default();
    ws.leaves.clear();
    ws.ia.clear();
    ws.ib.clear();
    ws.ia.push(0);
    ws.ib.push(0);
    while !ws.ia.is_empty() {
        a.ensure_fitted(&ws.ia, parallel, &mut ws.stale);
        b.ensure_fitted(&ws.ib, parallel, &mut ws.stale);
        ws.next_a.clear();
        ws.next_b.clear();
        counters.bv_tests += test_and_expand(a, b, ws, parallel);
        std::mem::swap(&mut ws.ia, &mut ws.next_a);
        std::mem::swap(&mut ws.ib, &mut ws.next_b);
    }
    counters.bv_updates = a.take_updates() + b.take_updates();
    // The narrow phase's triangle cache: each leaf met by a leaf pair, once per step.
    for &[la, lb] in &ws.leaves {
        a.ensure_leaf_tris(la as usize);
        b.ensure_leaf_tris(lb as usize);
    }
    let (ta, tb) = (a.tree(), b.tree());
    counters.prim_tests = ws
        .leaves
        .iter()
        .map(|&[x, y]| (ta.tri_range(x as usize).len() * tb.tri_range(y as usize).len()) as u64)
        .sum();
    counters
}

fn narrow<K: BvKind>(
    a: &Hierarchy<K>,
    b: &Hierarchy<K>,
    leaves: &[[u32; 2]],
    grain: usize,
    parallel: bool,
) -> Contacts {
    exact_tests(leaves, grain, parallel, |la, lb, out| {
        narrow_leaf_pair(a, b, la, lb, out)
    })
}

/// Runs `test_pair(x, y, out)` (which pushes contacts and returns the triangle pairs it
/// tested) on every leaf pair, in chunks of `grain / 64` leaf pairs when parallel, with
/// outputs concatenated in chunk order; returns the sorted contacts and `prim_tests` /
/// `contacts`. Shared by the two-object query and self-collision.
pub(crate) fn exact_tests(
    leaves: &[[u32; 2]],
    grain: usize,
    parallel: bool,
    test_pair: impl Fn(usize, usize, &mut Vec<[u32; 2]>) -> u64 + Sync,
) -> Contacts {
    let mut counters = Counters::default();
    let leaf_grain = (grain / 64).max(1);
    let mut pairs = Vec::new();
    if parallel && leaves.len() > leaf_grain {
        let parts: Vec<(Vec<[u32; 2]>, u64)> = leaves
            .par_chunks(leaf_grain)
            .map(|chunk| {
                let mut out = Vec::new();
                let tested = chunk
                    .iter()
                    .map(|&[x, y]| test_pair(x as usize, y as usize, &mut out))
                    .sum::<u64>();
                (out, tested)
            })
            .collect();
        for (out, tested) in parts {
            pairs.extend_from_slice(&out);
            counters.prim_tests += tested;
        }
    } else {
        for &[x, y] in leaves {
            counters.prim_tests += test_pair(x as usize, y as usize, &mut pairs);
        }
    }
    pairs.sort_unstable();
    counters.contacts = pairs.len() as u64;
    Contacts { pairs, counters }
}

/// The output of expanding one chunk of a frontier.
#[derive(Default)]
pub(crate) struct Expansion {
    pub(crate) next_a: Vec<u32>,
    pub(crate) next_b: Vec<u32>,
    pub(crate) leaves: Vec<[u32; 2]>,
    /// Scratch: positions of the overlapping pairs.
    pub(crate) sel: Vec<u32>,
}

impl Expansion {
    /// Appends the children pairs of the overlapping pairs (`mask[k] != 0`) and the leaf pairs.
    ///
    /// PERF: most tested pairs do not overlap and the mask is unpredictable, so the overlapping
    /// positions are first compacted without branches (`sel`), then expanded; children runs
    /// are appended with `extend` (one capacity check per run, not per pair).
    pub(crate) fn expand(
        &mut self,
        ta: &RegionTree,
        tb: &RegionTree,
        ia: &[u32],
        ib: &[u32],
        mask: &[u32],
    ) {
        let sel = &mut self.sel;
        sel.clear();
        sel.resize(ia.len(), 0);
        let mut hits = 0;
        for (k, &m) in mask[..ia.len()].iter().enumerate() {
            sel[hits] = k as u32;
            hits += (m != 0) as usize;
        }
        for &k in &sel[..hits] {
            let (x, y) = (ia[k as usize] as usize, ib[k as usize] as usize);
            let (cx, cy) = (ta.children(x), tb.children(y));
            match (cx.is_empty(), cy.is_empty()) {
                (true, true) => self.leaves.push([x as u32, y as u32]),
                (true, false) => {
                    self.next_a.extend(std::iter::repeat_n(x as u32, cy.len()));
                    self.next_b.extend(cy.map(|c| c as u32));
                }
                (false, true) => {
                    self.next_b.extend(std::iter::repeat_n(y as u32, cx.len()));
                    self.next_a.extend(cx.map(|c| c as u32));
                }
                (false, false) => {
                    for c in cx {
                        self.next_a.extend(std::iter::repeat_n(c as u32, cy.len()));
                        self.next_b.extend(cy.clone().map(|c| c as u32));
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
/// (original indices) and returns the number of pairs tested (`N_P`: all of them).
///
/// PERF: corners and boxes come from the hierarchies' triangle caches (gathered once per
/// leaf per step); each triangle of `la` is box-checked against `lb`'s run of boxes and
/// only the pairs whose closed boxes overlap reach the exact test. That box test is the
/// exact test's own first filter (closed boxes, comparisons only): contacts are unchanged.
fn narrow_leaf_pair<K: BvKind>(
    a: &Hierarchy<K>,
    b: &Hierarchy<K>,
    la: usize,
    lb: usize,
    out: &mut Vec<[u32; 2]>,
) -> u64 {
    if !(a.leaf_tris_current(la) && b.leaf_tris_current(lb)) {
        return narrow_leaf_pair_gather(a, b, la, lb, out);
    }
    let (ta, tb) = (a.tree(), b.tree());
    let (ca, cb) = (a.tri_cache(), b.tri_cache());
    let ra = ta.tri_range(la);
    let rb = tb.tri_range(lb);
    let n = rb.len();
    let (lx, ly, lz) = (
        &cb.lo[0][rb.clone()],
        &cb.lo[1][rb.clone()],
        &cb.lo[2][rb.clone()],
    );
    let (hx, hy, hz) = (
        &cb.hi[0][rb.clone()],
        &cb.hi[1][rb.clone()],
        &cb.hi[2][rb.clone()],
    );
    let corners_b = &cb.corners[rb.clone()];
    let order_b = &tb.tri_order()[rb.clone()];
    for i in ra.clone() {
        let tri_a = &ca.corners[i];
        let lo = [ca.lo[0][i], ca.lo[1][i], ca.lo[2][i]];
        let hi = [ca.hi[0][i], ca.hi[1][i], ca.hi[2][i]];
        // Blocks of 64: the box tests become a bit mask without branches (vectorizable),
        // then only the set bits (overlapping boxes) are visited.
        for base in (0..n).step_by(64) {
            let end = (base + 64).min(n);
            let mut bits = 0u64;
            for j in base..end {
                let ov = (hx[j] >= lo[0])
                    & (lx[j] <= hi[0])
                    & (hy[j] >= lo[1])
                    & (ly[j] <= hi[1])
                    & (hz[j] >= lo[2])
                    & (lz[j] <= hi[2]);
                bits |= (ov as u64) << (j - base);
            }
            while bits != 0 {
                let j = base + bits.trailing_zeros() as usize;
                bits &= bits - 1;
                if narrow::triangles_intersect(tri_a, &corners_b[j]) {
                    out.push([ta.tri_order()[i], order_b[j]]);
                }
            }
        }
    }
    (ra.len() * rb.len()) as u64
}

/// [`narrow_leaf_pair`] for leaves whose cached triangles are stale (a caller's own leaf
/// pairs, not from [`broad_phase`] this step): gathers the corners directly; pushes the intersecting ones
/// (original indices) and returns the number of pairs tested.
fn narrow_leaf_pair_gather<K: BvKind>(
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
