//! The traversal engine: one depth-first walk over two hierarchies (or one against itself)
//! with wide node tests, generic over the *query* it serves.
//!
//! A [`Query`] supplies what differs between queries: where a sibling group's bounds come from
//! (the lazily fitted volumes of a pose, or a swept bound over a step), the wide node test
//! (plain overlap, overlap within a distance, overlap during a step) and the action on an
//! overlapping leaf pair with its output (exact contacts, the leaf pair itself, feature pairs
//! within a distance). The walk knows only the region trees:
//!
//! - it keeps a stack of node pairs known to overlap; popping `(x, y)`:
//!   - two leaves: the query's leaf action runs at once (no list of leaf pairs is kept);
//!   - otherwise the larger volume (or the internal one) is descended: the other node is
//!     tested against the whole sibling group of its children in one SIMD operation
//!     (Embree's collider pattern), and the set bits of the result become pairs
//!     ([`push_bits`], the one place that turns a mask into pairs);
//! - self queries start from the *self pair* `(root, root)`, which is never tested (a node
//!   overlaps itself): an internal `x` pushes the self pairs of its children and, for each
//!   child `c_i`, the overlapping `(c_i, c_j)`, `j > i` (one wide test of `c_i` against the
//!   rest of its group); a leaf self pair goes to the leaf action. An internal self pair
//!   the query proves clear ([`Query::clear`]) is dropped, with everything under it.
//!
//! Memory does not grow with the work: the stack holds at most
//! `depth * (MAX_CHILDREN + MAX_CHILDREN^2 / 2)` pairs; the only output is the query's.
//!
//! Work counts come back from the walk ([`Walked`]): `N_V` (node pairs tested), `N_U` (nodes
//! fitted by the query's group fetches, per side) and whatever the leaf action counts
//! (`N_P`). Every node pair is visited at most once whatever the split into parallel tasks
//! ([`parallel`]), and each sibling group is fitted once per pose, so the counts are the same
//! for every thread count.
//!
//! Files: `engine.rs` is the walk of one task, `parallel.rs` the breadth-first start and the
//! split into rayon tasks; the public entry points are in [`crate::query`].

mod engine;
mod parallel;

pub(crate) use parallel::{leaf_pairs, walk};

use pulp::Simd;

use crate::control::Control;
use crate::counters::Counters;
use crate::tree::RegionTree;

/// The two hierarchies of a query: `A` (the first) and `B`. A self query has one hierarchy on
/// both sides.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Side {
    A = 0,
    B = 1,
}

/// What a walk serves. Implementations are small structs over borrowed hierarchies; their
/// methods are `#[inline(always)]` so that the walk compiles once per backend and query
/// (see `engine.rs`).
pub(crate) trait Query: Sync {
    /// One sibling group's bounds, as the node test reads them.
    type Block: Copy;
    /// What one walk task produces; tasks' outputs are merged in task order.
    type Out: Send;

    /// The region tree of a side (the same tree on both sides of a self query).
    fn tree(&self, side: Side) -> &RegionTree;
    /// `A` and `B` are one hierarchy: start from the self pair, never test a node with itself.
    fn is_self(&self) -> bool;
    /// An empty output.
    fn out(&self) -> Self::Out;
    /// Sibling group `g` of `side`, fitted first if stale; whether this call fitted it.
    fn group<S: Simd>(&self, simd: S, side: Side, g: usize) -> (Self::Block, bool);
    /// Overlap bits of entry `i` of block `a` (side A's or B's) against the first `n`
    /// entries of block `b` (the other side's, or the same group in a self pair).
    fn test<S: Simd>(&self, simd: S, a: Self::Block, i: usize, b: Self::Block, n: usize) -> u32;
    /// A size of entry `i`: the walk descends the larger volume of an overlapping pair.
    fn extent(&self, block: Self::Block, i: usize) -> f32;
    /// The action on the overlapping leaf pair `(x, y)` (`x == y` in a self query: a leaf
    /// with itself); counts its own work in `counters` (`prim_tests`).
    fn leaf_pair<S: Simd>(
        &self,
        simd: S,
        x: usize,
        y: usize,
        counters: &mut Counters,
        out: &mut Self::Out,
    );
    /// Whether every feature pair of node `x` (an internal node of a self query) is proven
    /// farther apart than the query looks: its self pair is then skipped, children and all
    /// ([`crate::query::clearance`]). Asked once per internal self pair the walk meets.
    #[inline(always)]
    fn clear(&self, _x: usize) -> bool {
        false
    }
    /// Appends `other` (a later task's output) to `out`.
    fn merge(&self, out: &mut Self::Out, other: Self::Out);
    /// Whether the walk must stop now (its budget spent, or cancelled); `poll`: ask the
    /// control's poll function too. Checked after every leaf pair; queries without a budget
    /// never stop.
    #[inline(always)]
    fn stopped(&self, _poll: bool) -> bool {
        false
    }
}

/// What a walk returns: the query's output and the work counted.
#[derive(Debug)]
pub(crate) struct Walked<O> {
    pub(crate) out: O,
    /// `bv_tests` and `prim_tests`, and `bv_updates` = `fitted[0] + fitted[1]`.
    pub(crate) counters: Counters,
    /// Nodes fitted on side A and side B (on a self query, both are the one hierarchy's).
    pub(crate) fitted: [u64; 2],
    /// The walk ran as several tasks (its natural order is then not the sequential one).
    pub(crate) split: bool,
}

/// Pushes `(node, first + k)` for every set bit `k` of `bits` (`node_first`), or
/// `(first + k, node)`: the one place a node test's mask becomes pairs.
#[inline(always)]
pub(crate) fn push_bits(
    stack: &mut Vec<[u32; 2]>,
    mut bits: u32,
    node: u32,
    first: usize,
    node_first: bool,
) {
    while bits != 0 {
        let k = bits.trailing_zeros() as usize;
        bits &= bits - 1;
        let other = (first + k) as u32;
        stack.push(if node_first {
            [node, other]
        } else {
            [other, node]
        });
    }
}

/// Reusable scratch of a walk (its stack and starting pairs) and of the queries built on
/// walks (the contact set's keyed rows): keep one per thread to avoid allocating every
/// step. It holds on to the memory of its largest query (see `docs/LIMITS.md`). Also holds the smallest number of starting pairs a parallel task
/// takes (the *grain*; the result never depends on it) and the [`Control`] of the queries
/// run with it (the most result pairs, cancellation).
#[derive(Clone, Debug)]
pub struct Workspace {
    /// Limits and cancellation of the queries run with this workspace (proximity, CCD).
    pub control: Control,
    pub(crate) grain: usize,
    pub(crate) stack: Vec<[u32; 2]>,
    pub(crate) seeds: Vec<[u32; 2]>,
    pub(crate) contact: crate::contact::ContactScratch,
}

/// Default smallest number of starting pairs per parallel task.
pub const DEFAULT_GRAIN: usize = 1;

impl Default for Workspace {
    fn default() -> Self {
        Self::with_grain(DEFAULT_GRAIN)
    }
}

impl Workspace {
    /// A workspace whose parallel tasks take at least `grain` starting pairs each (at least
    /// 1). Larger grains cut scheduling overhead; the result never depends on it.
    pub fn with_grain(grain: usize) -> Self {
        Self {
            control: Control::default(),
            grain: grain.max(1),
            stack: Vec::new(),
            seeds: Vec::new(),
            contact: Default::default(),
        }
    }
}
