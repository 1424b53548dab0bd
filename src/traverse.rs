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
pub fn narrow_phase<K: BvKind>(
    a: &Hierarchy<K>,
    b: &Hierarchy<K>,
    leaves: &[[u32; 2]],
    par: Par,
) -> Contacts {
    par.install(|| narrow(a, b, leaves, DEFAULT_GRAIN, par.is_parallel()))
}

impl Workspace {
    /// The overlapping leaf pairs (node ids) found by the last query or [`broad_phase`].
    pub fn leaf_pairs(&self) -> &[[u32; 2]] {
        &self.leaves
    }
}

fn broad<K: BvKind>(
    a: &mut Hierarchy<K>,
    b: &mut Hierarchy<K>,
    ws: &mut Workspace,
    parallel: bool,
) -> Counters {
    let mut counters = Counters::default();
    let grain = ws.grain;
    ws.leaves.clear();
    ws.ia.clear();
    ws.ib.clear();
    ws.ia.push(0);
    ws.ib.push(0);
    while !ws.ia.is_empty() {
        a.ensure_fitted(&ws.ia, parallel, &mut ws.stale);
        b.ensure_fitted(&ws.ib, parallel, &mut ws.stale);
        ws.mask.resize(ws.ia.len(), 0);
        counters.bv_tests += ws.ia.len() as u64;
        let (ha, hb) = (&*a, &*b);
        let test = |ia: &[u32], ib: &[u32], out: &mut [u32]| {
            K::overlap(
                ha.nodes(),
                ha.points(),
                hb.nodes(),
                hb.points(),
                ia,
                ib,
                out,
            );
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
            ws.next_a.clear();
            ws.next_b.clear();
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
            };
            e.next_a.clear();
            e.next_b.clear();
            e.expand(ta, tb, &ws.ia, &ws.ib, &ws.mask);
            (ws.next_a, ws.next_b, ws.leaves) = (e.next_a, e.next_b, e.leaves);
        }
        std::mem::swap(&mut ws.ia, &mut ws.next_a);
        std::mem::swap(&mut ws.ib, &mut ws.next_b);
    }
    counters.bv_updates = a.take_updates() + b.take_updates();
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
                    .map(|&[la, lb]| narrow_leaf_pair(a, b, la as usize, lb as usize, &mut out))
                    .sum::<u64>();
                (out, tested)
            })
            .collect();
        for (out, tested) in parts {
            pairs.extend_from_slice(&out);
            counters.prim_tests += tested;
        }
    } else {
        for &[la, lb] in leaves {
            counters.prim_tests += narrow_leaf_pair(a, b, la as usize, lb as usize, &mut pairs);
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
}

impl Expansion {
    /// Appends the children pairs of the overlapping pairs (`mask[k] != 0`) and the leaf pairs.
    pub(crate) fn expand(
        &mut self,
        ta: &RegionTree,
        tb: &RegionTree,
        ia: &[u32],
        ib: &[u32],
        mask: &[u32],
    ) {
        for k in 0..ia.len() {
            if mask[k] == 0 {
                continue;
            }
            let (x, y) = (ia[k] as usize, ib[k] as usize);
            match (ta.is_leaf(x), tb.is_leaf(y)) {
                (true, true) => self.leaves.push([x as u32, y as u32]),
                (true, false) => {
                    for c in tb.children(y) {
                        self.next_a.push(x as u32);
                        self.next_b.push(c as u32);
                    }
                }
                (false, true) => {
                    for c in ta.children(x) {
                        self.next_a.push(c as u32);
                        self.next_b.push(y as u32);
                    }
                }
                (false, false) => {
                    for cx in ta.children(x) {
                        for cy in tb.children(y) {
                            self.next_a.push(cx as u32);
                            self.next_b.push(cy as u32);
                        }
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
