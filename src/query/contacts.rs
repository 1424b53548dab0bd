//! Exact contacts: every pair of triangles (one from each hierarchy, or two of one hierarchy
//! sharing no vertex index) whose closed triangles intersect in the current pose.
//!
//! The leaf action is the narrow phase of `crate::narrow::leaves` (the SIMD kernel's
//! certified verdicts, then the exact test on the pairs it leaves undecided). The same walk
//! with a leaf action that only collects the leaf pairs is [`broad_phase`]; [`narrow_phase`]
//! runs the contact action on such a list.

use pulp::Simd;

use super::{LeafAction, NodeTest, Overlap, Posed, PosedQuery};
use crate::bv::BoundingVolume;
use crate::counters::Counters;
use crate::error::{Error, Result};
use crate::hierarchy::Hierarchy;
use crate::narrow::leaves::{counted_pairs, leaf_pair, LeafSide, Leaves};
use crate::par::Par;
use crate::walk::{self, Walked, Workspace};
use dhcd_kernels::narrow::{Row, MAX_ROW};

/// Result of a query: contacts as `[triangle of A, triangle of B]` in the caller's original
/// triangle indices, sorted ascending, and the counted work.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Contacts {
    /// `[triangle of A, triangle of B]` (`a < b` in a self query), sorted ascending.
    pub pairs: Vec<[u32; 2]>,
    /// The counted work.
    pub counters: Counters,
}

/// Result of [`Calibration::broad_phase`](crate::calibration::Calibration::broad_phase): the
/// overlapping leaf pairs (node ids) and the counted work.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct BroadPhase {
    /// `[leaf of A, leaf of B]` (`x <= y` in a self query, a leaf with itself included), in
    /// the walk's order: the same for every thread count.
    pub leaf_pairs: Vec<[u32; 2]>,
    /// `bv_tests`, `bv_updates`, and `prim_tests` as the narrow phase will count the leaf
    /// pairs; `contacts` is 0.
    pub counters: Counters,
}

/// All intersecting triangle pairs between `a` and `b`, with counters, on the calling
/// thread. Refits (lazily) the nodes it tests; `bv_updates` counts those refits.
pub fn collide<K: BoundingVolume>(a: &Hierarchy<K>, b: &Hierarchy<K>) -> Contacts {
    collide_with(a, b, &mut Workspace::default(), Par::Seq)
}

/// [`collide`] with caller-owned scratch and a choice of parallelism. The result does not
/// depend on `par`.
pub fn collide_with<K: BoundingVolume>(
    a: &Hierarchy<K>,
    b: &Hierarchy<K>,
    ws: &mut Workspace,
    par: Par,
) -> Contacts {
    contacts(Posed::pair(a, b, Overlap), ws, par).0
}

/// Every pair of intersecting triangles of one object, `[ti, tj]` with `ti < tj` (the
/// caller's original indices), sorted, excluding pairs that share a vertex index; on the
/// calling thread. Refits (lazily) the nodes it tests.
///
/// ```
/// use dhcd::{bv::Dh, self_collide, Hierarchy, Mesh, Options};
/// // Two triangles of one mesh crossing each other (no shared vertex), and a third one
/// // sharing an edge with the first (neighbours are never reported).
/// let mesh = Mesh::new(
///     vec![
///         [0.0, 0.0, 0.0], [2.0, 0.0, 0.0], [0.0, 2.0, 0.0],
///         [0.5, 0.5, -1.0], [0.5, 0.5, 1.0], [0.2, 0.8, 0.0],
///         [2.0, 2.0, 0.0],
///     ],
///     vec![[0, 1, 2], [3, 4, 5], [1, 6, 2]],
/// )?;
/// let h = Hierarchy::<Dh>::new(&mesh, Options::default())?;
/// let c = self_collide(&h);
/// assert_eq!(c.pairs, vec![[0, 1]]);
/// assert_eq!(c.pairs, dhcd::narrow::brute_force_self_pairs(&mesh));
/// # Ok::<(), dhcd::Error>(())
/// ```
pub fn self_collide<K: BoundingVolume>(h: &Hierarchy<K>) -> Contacts {
    self_collide_with(h, &mut Workspace::default(), Par::Seq)
}

/// [`self_collide`] with caller-owned scratch and a choice of parallelism. The result does
/// not depend on `par`.
pub fn self_collide_with<K: BoundingVolume>(
    h: &Hierarchy<K>,
    ws: &mut Workspace,
    par: Par,
) -> Contacts {
    contacts(Posed::single(h, Overlap), ws, par).0
}

/// The contact query on `posed`; also the nodes fitted on each side (the scene credits them
/// per object).
pub(crate) fn contacts<K: BoundingVolume, T: NodeTest>(
    posed: Posed<'_, K, T>,
    ws: &mut Workspace,
    par: Par,
) -> (Contacts, [u64; 2]) {
    // f64 geometry (on either side) takes the rounded-corner narrow phase: a walk of its own.
    let Walked {
        out,
        counters,
        fitted,
        ..
    } = if posed.a.is_rounded() || posed.b.is_rounded() {
        walk::walk(
            &PosedQuery {
                posed,
                action: ContactAction::<true>,
            },
            ws,
            par,
        )
    } else {
        walk::walk(
            &PosedQuery {
                posed,
                action: ContactAction::<false>,
            },
            ws,
            par,
        )
    };
    (finish(out.pairs, counters), fitted)
}

fn finish(mut pairs: Vec<[u32; 2]>, mut counters: Counters) -> Contacts {
    sort_pairs(&mut pairs);
    counters.contacts = pairs.len() as u64;
    Contacts { pairs, counters }
}

/// The broad phase alone: lazy refit and traversal down to the overlapping leaf pairs (a list
/// that, unlike a query's memory, grows with the work). With [`narrow_phase`] it is
/// [`collide_with`] split in two, for benchmarks and cost-model calibration.
pub(crate) fn broad_phase<K: BoundingVolume>(
    a: &Hierarchy<K>,
    b: &Hierarchy<K>,
    ws: &mut Workspace,
    par: Par,
) -> BroadPhase {
    broad(Posed::pair(a, b, Overlap), ws, par)
}

/// [`broad_phase`] of one object against itself: the lazy refit and traversal of
/// [`self_collide_with`] down to the overlapping leaf pairs; no triangle is tested. What a
/// self query costs besides its narrow phase (`dhcd bench --broad-only`).
pub(crate) fn self_broad_phase<K: BoundingVolume>(
    h: &Hierarchy<K>,
    ws: &mut Workspace,
    par: Par,
) -> BroadPhase {
    broad(Posed::single(h, Overlap), ws, par)
}

fn broad<K: BoundingVolume>(
    posed: Posed<'_, K, Overlap>,
    ws: &mut Workspace,
    par: Par,
) -> BroadPhase {
    let q = PosedQuery {
        posed,
        action: CollectLeaves,
    };
    let Walked {
        mut out,
        counters,
        split,
        ..
    } = walk::walk(&q, ws, par);
    // A walk split into tasks visits leaf pairs in another order: sorted, it is the same for
    // every thread count.
    if split {
        sort_pairs(&mut out);
    }
    BroadPhase {
        leaf_pairs: out,
        counters,
    }
}

/// The narrow phase alone: exact tests of every triangle pair of the given leaf pairs (node
/// ids, as [`broad_phase`] returns them). Counts `prim_tests` and `contacts`. A pair naming
/// a node beyond its hierarchy is an [`Error::NodeOutOfRange`], one naming an internal node
/// an [`Error::NotALeaf`].
pub(crate) fn narrow_phase<K: BoundingVolume>(
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
    let posed = Posed::pair(a, b, Overlap);
    let w = if a.is_rounded() || b.is_rounded() {
        let q = PosedQuery {
            posed,
            action: ContactAction::<true>,
        };
        walk::leaf_pairs(&q, leaves, par)
    } else {
        let q = PosedQuery {
            posed,
            action: ContactAction::<false>,
        };
        walk::leaf_pairs(&q, leaves, par)
    };
    Ok(finish(w.out.pairs, w.counters))
}

/// Sorts pairs ascending. PERF: one u64 key per pair sorts several times faster than the
/// lexicographic comparison of `[u32; 2]`.
pub(crate) fn sort_pairs(pairs: &mut [[u32; 2]]) {
    pairs.sort_unstable_by_key(|&[a, b]| (u64::from(a) << 32) | u64::from(b));
}

/// Which pairs of leaf pair `(x, y)` are tested, and how many of them share a vertex.
#[inline(always)]
pub(crate) fn leaf_pair_kind<K: BoundingVolume, T: NodeTest>(
    posed: &Posed<'_, K, T>,
    x: usize,
    y: usize,
) -> (Leaves, u64) {
    let leaves = match (posed.self_query, x == y) {
        (false, _) => Leaves::Objects,
        (true, false) => Leaves::SelfDistinct,
        (true, true) => Leaves::SelfSame,
    };
    let shared = match leaves {
        Leaves::Objects => 0,
        _ => posed.a.tree().shared_pairs_of_leaves(x, y),
    };
    (leaves, shared)
}

/// The leaf action of the contact query: the narrow phase of the leaf pair (`ROUNDED`: of
/// `f64` geometry, see `crate::narrow::leaves`).
struct ContactAction<const ROUNDED: bool>;

/// The contact query's output: the contacts, and the narrow phase's scratch (its rows, and
/// the last leaf of each side: the walk often meets one leaf against several in a row).
struct ContactOut<'h> {
    pairs: Vec<[u32; 2]>,
    rows: [Row; MAX_ROW],
    last: [Option<(usize, LeafSide<'h>)>; 2],
}

impl<'h, K: BoundingVolume, const ROUNDED: bool> LeafAction<'h, K> for ContactAction<ROUNDED> {
    type Out = ContactOut<'h>;

    fn out(&self) -> ContactOut<'h> {
        ContactOut {
            pairs: Vec::new(),
            rows: [Row::default(); MAX_ROW],
            last: [None, None],
        }
    }

    #[inline(always)]
    fn leaf_pair<S: Simd, T: NodeTest>(
        &self,
        posed: &Posed<'h, K, T>,
        simd: S,
        x: usize,
        y: usize,
        counters: &mut Counters,
        out: &mut ContactOut<'h>,
    ) {
        fn side<'h, K: BoundingVolume, S: Simd>(
            simd: S,
            h: &'h Hierarchy<K>,
            leaf: usize,
            last: &mut Option<(usize, LeafSide<'h>)>,
        ) -> LeafSide<'h> {
            match *last {
                Some((n, s)) if n == leaf => s,
                _ => {
                    let s = LeafSide {
                        tris: h.leaf_tris(simd, leaf),
                        order: &h.tree().tri_order()[h.tree().tri_range(leaf)],
                        exact: h.exact_points(),
                    };
                    *last = Some((leaf, s));
                    s
                }
            }
        }
        let (leaves, shared) = leaf_pair_kind(posed, x, y);
        let [la, lb] = &mut out.last;
        let (sa, sb) = (side(simd, posed.a, x, la), side(simd, posed.b, y, lb));
        counters.prim_tests += leaf_pair::<S, ROUNDED>(
            simd,
            &sa,
            &sb,
            leaves,
            shared,
            &mut out.rows,
            &mut out.pairs,
        );
    }

    fn merge(&self, out: &mut ContactOut<'h>, other: ContactOut<'h>) {
        out.last = [None, None];
        out.pairs.extend_from_slice(&other.pairs);
    }
}

/// The leaf action of [`broad_phase`]: the leaf pair itself, with the triangle pairs the
/// narrow phase would count.
struct CollectLeaves;

impl<'h, K: BoundingVolume> LeafAction<'h, K> for CollectLeaves {
    type Out = Vec<[u32; 2]>;

    fn out(&self) -> Vec<[u32; 2]> {
        Vec::new()
    }

    #[inline(always)]
    fn leaf_pair<S: Simd, T: NodeTest>(
        &self,
        posed: &Posed<'h, K, T>,
        _simd: S,
        x: usize,
        y: usize,
        counters: &mut Counters,
        out: &mut Vec<[u32; 2]>,
    ) {
        let (leaves, shared) = leaf_pair_kind(posed, x, y);
        let (ta, tb) = (posed.a.tree(), posed.b.tree());
        counters.prim_tests +=
            counted_pairs(ta.tri_range(x).len(), tb.tri_range(y).len(), leaves, shared);
        out.push([x as u32, y as u32]);
    }

    fn merge(&self, out: &mut Vec<[u32; 2]>, other: Vec<[u32; 2]>) {
        out.extend_from_slice(&other);
    }
}
