//! The query: a depth-first traversal of two hierarchies (or one against itself) with wide
//! node tests, and the exact narrow phase on the triangle pairs of overlapping leaves.
//!
//! A stack holds node pairs known to overlap. Popping `(x, y)`:
//! - two leaves: the narrow phase runs on their triangles at once (no list of leaf pairs
//!   is kept);
//! - otherwise the larger volume (or the internal one) is descended: the other node is
//!   tested against the whole sibling group of its children in one SIMD operation
//!   (Embree's collider pattern), and only the overlapping children are pushed.
//!
//! Self-collision starts from the *self pair* `(root, root)`. A self pair `(x, x)` is never
//! tested (a node overlaps itself): an internal `x` pushes the self pairs of its children
//! and, for each child `c_i`, the overlapping `(c_i, c_j)`, `j > i` (one wide test of `c_i`
//! against the rest of the group); a leaf `x` is narrow-tested against itself.
//!
//! Memory does not grow with the work: the stack holds at most
//! `depth * (MAX_CHILDREN + MAX_CHILDREN^2 / 2)` pairs, and the only output is the contact
//! list. Lazy refit happens in the same walk: a sibling group is fitted right before its
//! first test in a step (see [`LazyTiles`](dhcd_kernels::lazy::LazyTiles)), whichever thread gets there first.
//!
//! Parallelism: the walk is expanded breadth-first on the calling thread until there are
//! enough pairs to share, then each pair is walked depth-first as a rayon task. Every pair
//! of nodes is visited at most once whatever the split, so the counters are identical for
//! every thread count, and the contacts are sorted.

use pulp::{Simd, WithSimd};
use rayon::prelude::*;

use crate::bv::BvKind;
use crate::counters::Counters;
use crate::error::{Error, Result};
use crate::hierarchy::Hierarchy;
use crate::narrow::leaves::{counted_pairs, leaf_pair, LeafSide, Leaves};
use crate::par::Par;
use dhcd_kernels::narrow::{Row, MAX_ROW};

/// Result of a query: contacts as `[triangle of A, triangle of B]` in the caller's original
/// triangle indices, sorted ascending, and the counted work.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Contacts {
    pub pairs: Vec<[u32; 2]>,
    pub counters: Counters,
}

/// Default smallest number of starting pairs per parallel task.
pub const DEFAULT_GRAIN: usize = 1;

/// Pairs the breadth-first start aims for, per thread, before the parallel walk.
const SEEDS_PER_THREAD: usize = 64;

/// Reusable scratch of a query (the walk's stack, the leaf pairs of [`broad_phase`]): keep
/// one per thread to avoid allocating every step. Also holds the parallel grain.
#[derive(Clone, Debug)]
pub struct Workspace {
    pub(crate) grain: usize,
    stack: Vec<[u32; 2]>,
    seeds: Vec<[u32; 2]>,
    leaves: Vec<[u32; 2]>,
}

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
            grain: grain.max(1),
            stack: Vec::new(),
            seeds: Vec::new(),
            leaves: Vec::new(),
        }
    }

    /// The overlapping leaf pairs (node ids) found by the last [`broad_phase`].
    pub fn leaf_pairs(&self) -> &[[u32; 2]] {
        &self.leaves
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
    let updates = a.take_updates() + b.take_updates();
    let walk = Walk {
        a,
        b,
        self_query: false,
        narrow: true,
        job: None,
    };
    let mut c = par.install(|| walk.run(ws, par.is_parallel()));
    c.counters.bv_updates += updates;
    c
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
/// let mut h = Hierarchy::<Dh>::new(&mesh, Options::default())?;
/// let c = self_collide(&mut h);
/// assert_eq!(c.pairs, vec![[0, 1]]);
/// assert_eq!(c.pairs, dhcd::narrow::brute_force_self_pairs(&mesh));
/// # Ok::<(), dhcd::Error>(())
/// ```
pub fn self_collide<K: BvKind>(h: &mut Hierarchy<K>) -> Contacts {
    self_collide_with(h, &mut Workspace::default(), Par::Seq)
}

/// [`self_collide`] with caller-owned scratch and a choice of parallelism. The result does
/// not depend on `par`.
pub fn self_collide_with<K: BvKind>(
    h: &mut Hierarchy<K>,
    ws: &mut Workspace,
    par: Par,
) -> Contacts {
    let updates = h.take_updates();
    let walk = Walk {
        a: h,
        b: h,
        self_query: true,
        narrow: true,
        job: None,
    };
    let mut c = par.install(|| walk.run(ws, par.is_parallel()));
    c.counters.bv_updates += updates;
    c
}

/// One query of a scene's step on shared hierarchies: `a` against `b`, or `a` against
/// itself when `self_query` (then `b` is `a`). Fitted groups are claimed for `job` instead of
/// counted: the scene credits them ([`Hierarchy::drain_claims`]), and the eager refits
/// ([`Hierarchy::take_updates`]) too, once the step's queries are done.
pub(crate) fn scene_query<K: BvKind>(
    a: &Hierarchy<K>,
    b: &Hierarchy<K>,
    self_query: bool,
    job: usize,
    ws: &mut Workspace,
    par: Par,
) -> Contacts {
    let walk = Walk {
        a,
        b,
        self_query,
        narrow: true,
        job: Some(job),
    };
    par.install(|| walk.run(ws, par.is_parallel()))
}

/// The broad phase alone: lazy refit and traversal down to the overlapping leaf pairs, which
/// stay in `ws` ([`Workspace::leaf_pairs`], in a deterministic order; this list, unlike a
/// query, grows with the work). Its counters have `bv_tests`, `bv_updates` and `prim_tests`
/// (the triangle pairs the narrow phase will test) as [`collide_with`] counts them;
/// `contacts` is 0. With [`narrow_phase`] it is [`collide_with`] split in two, for
/// benchmarks and cost-model calibration.
pub fn broad_phase<K: BvKind>(
    a: &mut Hierarchy<K>,
    b: &mut Hierarchy<K>,
    ws: &mut Workspace,
    par: Par,
) -> Counters {
    let updates = a.take_updates() + b.take_updates();
    Walk {
        a,
        b,
        self_query: false,
        narrow: false,
        job: None,
    }
    .broad(ws, par, updates)
}

/// [`broad_phase`] of one object against itself: the lazy refit and traversal of
/// [`self_collide_with`] down to the overlapping leaf pairs (`[x, y]`, `x <= y`, a leaf with
/// itself included), left in `ws`; no triangle is tested. Its counters have `bv_tests`,
/// `bv_updates` and `prim_tests` (the triangle pairs the narrow phase would test: allowed
/// pairs minus the vertex-sharing ones) as [`self_collide_with`] counts them; `contacts` is
/// 0. What a self query costs besides its narrow phase (`dhcd bench --broad-only`).
pub fn self_broad_phase<K: BvKind>(h: &mut Hierarchy<K>, ws: &mut Workspace, par: Par) -> Counters {
    let updates = h.take_updates();
    Walk {
        a: h,
        b: h,
        self_query: true,
        narrow: false,
        job: None,
    }
    .broad(ws, par, updates)
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
    let walk = Walk {
        a,
        b,
        self_query: false,
        narrow: true,
        job: None,
    };
    let run = |chunk: &[[u32; 2]]| {
        let mut out = Output::default();
        dhcd_kernels::arch().dispatch(NarrowOp {
            walk: &walk,
            leaves: chunk,
            out: &mut out,
        });
        out
    };
    let out = if par.is_parallel() {
        par.install(|| {
            leaves
                .par_chunks(64)
                .map(run)
                .reduce(Output::default, Output::merge)
        })
    } else {
        run(leaves)
    };
    Ok(out.finish())
}

/// One query's hierarchies: `a` against `b`, or one hierarchy against itself.
struct Walk<'h, K: BvKind> {
    a: &'h Hierarchy<K>,
    b: &'h Hierarchy<K>,
    /// `a` and `b` are the same hierarchy: self pairs, shared vertices skipped.
    self_query: bool,
    /// Run the narrow phase on overlapping leaf pairs (else collect them).
    narrow: bool,
    /// A scene job's index: fitted groups are claimed for it ([`Hierarchy::group_for_job`])
    /// and credited by the scene, not counted here.
    job: Option<usize>,
}

/// What a walk produces: contacts, counters, and (broad phase only) leaf pairs; with the
/// narrow phase's scratch: its rows, and the last leaf of each side (the walk often meets
/// one leaf against several in a row).
struct Output<'h> {
    pairs: Vec<[u32; 2]>,
    counters: Counters,
    leaves: Vec<[u32; 2]>,
    rows: [Row; MAX_ROW],
    last: [Option<(usize, LeafSide<'h>)>; 2],
}

impl Default for Output<'_> {
    fn default() -> Self {
        Self {
            pairs: Vec::new(),
            counters: Counters::default(),
            leaves: Vec::new(),
            rows: [Row::default(); MAX_ROW],
            last: [None, None],
        }
    }
}

impl Output<'_> {
    fn merge(mut self, other: Self) -> Self {
        self.last = [None, None];
        self.pairs.extend_from_slice(&other.pairs);
        self.leaves.extend_from_slice(&other.leaves);
        self.counters += other.counters;
        self
    }

    fn finish(mut self) -> Contacts {
        // PERF: one u64 key per pair sorts several times faster than the lexicographic
        // comparison of `[u32; 2]`.
        self.pairs
            .sort_unstable_by_key(|&[a, b]| (u64::from(a) << 32) | u64::from(b));
        self.counters.contacts = self.pairs.len() as u64;
        Contacts {
            pairs: self.pairs,
            counters: self.counters,
        }
    }
}

impl<'h, K: BvKind> Walk<'h, K> {
    fn run(&self, ws: &mut Workspace, parallel: bool) -> Contacts {
        ws.leaves.clear();
        let mut out = Output {
            leaves: std::mem::take(&mut ws.leaves),
            ..Output::default()
        };
        // Only a parallel query asks for the pool's size: asking starts rayon's global pool,
        // which a sequential query must not (one idle thread per core).
        let threads = if parallel {
            rayon::current_num_threads()
        } else {
            1
        };
        let seed_target = if threads > 1 {
            SEEDS_PER_THREAD * threads
        } else {
            0
        };
        dhcd_kernels::arch().dispatch(StartOp {
            walk: self,
            seeds: &mut ws.seeds,
            stack: &mut ws.stack,
            seed_target,
            out: &mut out,
        });
        if !ws.seeds.is_empty() {
            // The breadth-first start left `seeds`: walk them in parallel.
            let part = ws
                .seeds
                .par_chunks(ws.grain)
                .fold(Output::default, |mut o, chunk| {
                    let mut stack = Vec::new();
                    dhcd_kernels::arch().dispatch(WalkOp {
                        walk: self,
                        seeds: chunk,
                        stack: &mut stack,
                        out: &mut o,
                    });
                    o
                })
                .reduce(Output::default, Output::merge);
            out = out.merge(part);
            // Deterministic order of the collected leaf pairs (the broad-phase API).
            out.leaves
                .sort_unstable_by_key(|&[a, b]| (u64::from(a) << 32) | u64::from(b));
        }
        ws.leaves = std::mem::take(&mut out.leaves);
        out.finish()
    }

    /// Sibling group `g` of `h` (one of this walk's two hierarchies), fitted first if stale:
    /// the fitted nodes counted in `bv_updates`, or claimed for the scene job.
    #[inline(always)]
    fn group(&self, h: &'h Hierarchy<K>, g: usize, out: &mut Output<'h>) -> K::Block<'h> {
        match self.job {
            Some(job) => h.group_for_job(g, job),
            None => {
                let (block, fitted) = h.group(g);
                if fitted {
                    out.counters.bv_updates += h.tree().group_nodes(g).len() as u64;
                }
                block
            }
        }
    }

    /// The root entry: the roots' test (two objects) or the root self pair.
    #[inline(always)]
    fn root<S: Simd>(&self, simd: S, out: &mut Output<'h>) -> Option<[u32; 2]> {
        if self.self_query {
            return Some([0, 0]);
        }
        let (ba, bb) = (self.group(self.a, 0, out), self.group(self.b, 0, out));
        out.counters.bv_tests += 1;
        (K::test(simd, ba, 0, bb, 1) != 0).then_some([0, 0])
    }

    /// Expands one overlapping pair: pushes its overlapping children pairs to `next`, or
    /// runs the narrow phase on a leaf pair.
    #[inline(always)]
    fn expand<S: Simd>(
        &self,
        simd: S,
        [x, y]: [u32; 2],
        next: &mut Vec<[u32; 2]>,
        out: &mut Output<'h>,
    ) {
        let (x, y) = (x as usize, y as usize);
        let (ta, tb) = (self.a.tree(), self.b.tree());
        if self.self_query && x == y {
            let Some(g) = ta.child_group(x) else {
                return self.leaves(simd, x, y, out);
            };
            let block = self.group(self.a, g, out);
            let nodes = ta.group_nodes(g);
            let m = nodes.len();
            for i in 0..m {
                let ci = (nodes.start + i) as u32;
                next.push([ci, ci]);
                if i + 1 < m {
                    // The whole group in one test (aligned loads); the pairs j <= i are
                    // masked off and not counted.
                    out.counters.bv_tests += (m - i - 1) as u64;
                    let mut bits = K::test(simd, block, i, block, m) & !((2u32 << i) - 1);
                    while bits != 0 {
                        let k = bits.trailing_zeros() as usize;
                        bits &= bits - 1;
                        next.push([ci, (nodes.start + k) as u32]);
                    }
                }
            }
            return;
        }
        let (gx, gy) = (ta.group_of(x), tb.group_of(y));
        let (bx, by) = (self.a.group(gx).0, self.b.group(gy).0);
        let (ix, iy) = (x - ta.group_nodes(gx).start, y - tb.group_nodes(gy).start);
        let descend_x = match (ta.child_group(x), tb.child_group(y)) {
            (None, None) => return self.leaves(simd, x, y, out),
            (Some(_), None) => true,
            (None, Some(_)) => false,
            (Some(_), Some(_)) => K::extent(bx, ix) >= K::extent(by, iy),
        };
        if descend_x {
            let g = ta.child_group(x).unwrap_or_default();
            let children = self.group(self.a, g, out);
            let nodes = ta.group_nodes(g);
            out.counters.bv_tests += nodes.len() as u64;
            let mut bits = K::test(simd, by, iy, children, nodes.len());
            while bits != 0 {
                let k = bits.trailing_zeros() as usize;
                bits &= bits - 1;
                next.push([(nodes.start + k) as u32, y as u32]);
            }
        } else {
            let g = tb.child_group(y).unwrap_or_default();
            let children = self.group(self.b, g, out);
            let nodes = tb.group_nodes(g);
            out.counters.bv_tests += nodes.len() as u64;
            let mut bits = K::test(simd, bx, ix, children, nodes.len());
            while bits != 0 {
                let k = bits.trailing_zeros() as usize;
                bits &= bits - 1;
                next.push([x as u32, (nodes.start + k) as u32]);
            }
        }
    }

    /// An overlapping leaf pair: the narrow phase now, or collected (broad phase).
    #[inline(always)]
    fn leaves<S: Simd>(&self, simd: S, x: usize, y: usize, out: &mut Output<'h>) {
        if !self.narrow {
            out.leaves.push([x as u32, y as u32]);
            return;
        }
        fn side<'h, K: BvKind>(
            h: &'h Hierarchy<K>,
            leaf: usize,
            last: &mut Option<(usize, LeafSide<'h>)>,
        ) -> LeafSide<'h> {
            match *last {
                Some((n, s)) if n == leaf => s,
                _ => {
                    let s = LeafSide {
                        tris: h.leaf_tris(leaf),
                        order: &h.tree().tri_order()[h.tree().tri_range(leaf)],
                    };
                    *last = Some((leaf, s));
                    s
                }
            }
        }
        let (leaves, shared) = self.leaf_pair_kind(x, y);
        let [la, lb] = &mut out.last;
        let (sa, sb) = (side(self.a, x, la), side(self.b, y, lb));
        out.counters.prim_tests += leaf_pair(
            simd,
            &sa,
            &sb,
            leaves,
            shared,
            &mut out.rows,
            &mut out.pairs,
        );
    }

    /// Which pairs of leaf pair `(x, y)` are tested, and how many of them share a vertex.
    #[inline(always)]
    fn leaf_pair_kind(&self, x: usize, y: usize) -> (Leaves, u64) {
        let leaves = match (self.self_query, x == y) {
            (false, _) => Leaves::Objects,
            (true, false) => Leaves::SelfDistinct,
            (true, true) => Leaves::SelfSame,
        };
        let shared = match leaves {
            Leaves::Objects => 0,
            _ => self.a.tree().shared_pairs_of_leaves(x, y),
        };
        (leaves, shared)
    }

    /// The broad phase of this walk (`narrow` off): the walk's counters, with `updates` from
    /// outside the query and `prim_tests` as the narrow phase would count the collected leaf
    /// pairs.
    fn broad(&self, ws: &mut Workspace, par: Par, updates: u64) -> Counters {
        debug_assert!(!self.narrow);
        let c = par.install(|| self.run(ws, par.is_parallel()));
        let (ta, tb) = (self.a.tree(), self.b.tree());
        let prim_tests = ws
            .leaves
            .iter()
            .map(|&[x, y]| {
                let (x, y) = (x as usize, y as usize);
                let (leaves, shared) = self.leaf_pair_kind(x, y);
                counted_pairs(ta.tri_range(x).len(), tb.tri_range(y).len(), leaves, shared)
            })
            .sum();
        Counters {
            bv_updates: c.counters.bv_updates + updates,
            prim_tests,
            ..c.counters
        }
    }

    /// Depth-first from each of `seeds`.
    #[inline(always)]
    fn walk<S: Simd>(
        &self,
        simd: S,
        seeds: &[[u32; 2]],
        stack: &mut Vec<[u32; 2]>,
        out: &mut Output<'h>,
    ) {
        for &seed in seeds {
            stack.clear();
            stack.push(seed);
            while let Some(pair) = stack.pop() {
                self.expand(simd, pair, stack, out);
            }
        }
    }
}

/// The calling thread's part: the root, then either the whole walk (sequential) or a
/// breadth-first expansion until `seed_target` pairs are waiting (left in `seeds`).
struct StartOp<'w, 'h, K: BvKind> {
    walk: &'w Walk<'h, K>,
    seeds: &'w mut Vec<[u32; 2]>,
    stack: &'w mut Vec<[u32; 2]>,
    seed_target: usize,
    out: &'w mut Output<'h>,
}

impl<K: BvKind> WithSimd for StartOp<'_, '_, K> {
    type Output = ();
    #[inline(always)]
    fn with_simd<S: Simd>(self, simd: S) {
        self.seeds.clear();
        let Some(root) = self.walk.root(simd, self.out) else {
            return;
        };
        if self.seed_target == 0 {
            return self.walk.walk(simd, &[root], self.stack, self.out);
        }
        self.seeds.push(root);
        let mut next = std::mem::take(self.stack);
        while !self.seeds.is_empty() && self.seeds.len() < self.seed_target {
            next.clear();
            for &pair in self.seeds.iter() {
                self.walk.expand(simd, pair, &mut next, self.out);
            }
            std::mem::swap(self.seeds, &mut next);
        }
        *self.stack = next;
    }
}

/// One parallel task: depth-first from each of its seeds.
struct WalkOp<'w, 'h, K: BvKind> {
    walk: &'w Walk<'h, K>,
    seeds: &'w [[u32; 2]],
    stack: &'w mut Vec<[u32; 2]>,
    out: &'w mut Output<'h>,
}

impl<K: BvKind> WithSimd for WalkOp<'_, '_, K> {
    type Output = ();
    #[inline(always)]
    fn with_simd<S: Simd>(self, simd: S) {
        self.walk.walk(simd, self.seeds, self.stack, self.out);
    }
}

/// The narrow phase of given leaf pairs ([`narrow_phase`]).
struct NarrowOp<'w, 'h, K: BvKind> {
    walk: &'w Walk<'h, K>,
    leaves: &'w [[u32; 2]],
    out: &'w mut Output<'h>,
}

impl<K: BvKind> WithSimd for NarrowOp<'_, '_, K> {
    type Output = ();
    #[inline(always)]
    fn with_simd<S: Simd>(self, simd: S) {
        for &[x, y] in self.leaves {
            self.walk.leaves(simd, x as usize, y as usize, self.out);
        }
    }
}
