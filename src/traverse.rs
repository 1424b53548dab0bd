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
//! Frame-to-frame coherence (opt-in, [`Workspace::set_front_tracking`]): the walk records
//! its *front*, the node pairs where it stopped (the lanes of each wide test that failed, and
//! the overlapping leaf pairs). Those pairs partition every pair of leaves the query could
//! reach, so the next query of the same trees can start from them instead of the root: each
//! entry is tested again, descended where it now overlaps, and re-recorded. The front is a
//! starting point, never a filter, so the contacts are those of a walk from the root.
//!
//! Parallelism: the walk is expanded breadth-first on the calling thread until there are
//! enough pairs to share, then each pair is walked depth-first as a rayon task. Every pair
//! of nodes is visited at most once whatever the split, so the counters are identical for
//! every thread count, and the contacts are sorted.

use std::sync::Arc;

use pulp::{Simd, WithSimd};
use rayon::prelude::*;

use crate::bv::BvKind;
use crate::counters::Counters;
use crate::error::{Error, Result};
use crate::hierarchy::Hierarchy;
use crate::narrow::leaves::{counted_pairs, leaf_pair, LeafSide, Leaves};
use crate::par::Par;
use crate::tree::RegionTree;
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

/// Most entries a front may hold (16 bytes each: 16 MiB); a walk that would record more
/// drops its front, and the next query starts from the root.
pub const FRONT_MAX_ENTRIES: usize = 1 << 20;

/// A front replayed into more than this many times the entries of the last front recorded
/// from the root is dropped (the next query starts from the root again): a front only
/// descends, so after contacts end it would keep testing pairs a walk from the root skips.
const FRONT_REGROWTH: usize = 2;

/// Reusable scratch of a query (the walk's stack, the leaf pairs of [`broad_phase`]): keep
/// one per thread to avoid allocating every step. Also holds the parallel grain and, with
/// [`Workspace::set_front_tracking`], the last query's traversal front.
#[derive(Clone, Debug)]
pub struct Workspace {
    pub(crate) grain: usize,
    stack: Vec<[u32; 2]>,
    seeds: Vec<[u32; 2]>,
    leaves: Vec<[u32; 2]>,
    front: Front,
}

/// Where the last query of a workspace stopped (see the module documentation).
#[derive(Clone, Debug, Default)]
struct Front {
    tracking: bool,
    /// The trees (and query kind) `entries` partitions; `None`: no front kept.
    owner: Option<FrontOwner>,
    entries: Vec<FrontEntry>,
    /// The buffer the next front is recorded into (the one before `entries`).
    spare: Vec<FrontEntry>,
    /// Entries of the last front recorded from the root.
    fresh_len: usize,
}

#[derive(Clone, Debug)]
struct FrontOwner {
    a: Arc<RegionTree>,
    b: Arc<RegionTree>,
    self_query: bool,
}

/// One entry of a front: pairs of nodes the last query stopped at.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum FrontEntry {
    /// Node `a_node` of `a` against the sibling group `b_group` of `b`, on the set bits of
    /// `lanes` (group positions): those pairs were tested and did not overlap.
    NodeVsGroup {
        a_node: u32,
        b_group: u32,
        lanes: u32,
    },
    /// The sibling group `a_group` of `a` against node `b_node` of `b`, likewise.
    GroupVsNode {
        a_group: u32,
        b_node: u32,
        lanes: u32,
    },
    /// An overlapping leaf pair (narrow-tested; `x == y` in a self query: a leaf with itself).
    Leaves { x: u32, y: u32 },
}

// FRONT_MAX_ENTRIES and LIMITS.md count 16 bytes an entry.
const _: () = assert!(std::mem::size_of::<FrontEntry>() == 16);

impl Front {
    /// Whether the kept front partitions the pairs of a query on trees `a`, `b`.
    fn fits(&self, a: &Arc<RegionTree>, b: &Arc<RegionTree>, self_query: bool) -> bool {
        self.owner.as_ref().is_some_and(|o| {
            Arc::ptr_eq(&o.a, a) && Arc::ptr_eq(&o.b, b) && o.self_query == self_query
        })
    }

    fn clear(&mut self) {
        self.owner = None;
        self.entries.clear();
        self.fresh_len = 0;
    }
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
            front: Front::default(),
        }
    }

    /// Frame-to-frame coherence (off by default). When on, each query records where its
    /// traversal stopped (its *front*: the node pairs whose test failed and the overlapping
    /// leaf pairs), and the next query on the same trees (same `Arc<RegionTree>`s, same query
    /// kind) starts from that front instead of the root: it tests each front pair again,
    /// descends where it now overlaps and records the new front. The contacts are exactly
    /// those of a walk from the root (the front pairs partition all the pairs of leaves);
    /// `bv_tests` and `bv_updates` count the work done, which is less above the front, and
    /// are the same for every thread count. A query on other trees starts from the root.
    /// A front is at most [`FRONT_MAX_ENTRIES`] entries (16 bytes each), else dropped; one that
    /// has grown to twice the size of the last front recorded from the root is dropped too
    /// (the next query starts from the root), and so is one of several entries in which no
    /// pair overlapped (the next query starts from the roots: one test if the objects are
    /// apart, a walk down to where they separate if only their bounds meet). Turning it off
    /// drops the front.
    ///
    /// Opt-in because it does not pay on the meshes measured (docs/PERFORMANCE.md,
    /// thirteenth sitting): fewer BV tests on most, but the same time as a walk from the root
    /// on the icosphere and pawn scenes (within -2..+3%) and 2-9% slower on the real frames,
    /// whose walk is a few percent of a step (the triangle tests dominate).
    pub fn set_front_tracking(&mut self, on: bool) {
        self.front.tracking = on;
        if !on {
            self.front.clear();
        }
    }

    /// Whether [`set_front_tracking`](Self::set_front_tracking) is on.
    pub fn front_tracking(&self) -> bool {
        self.front.tracking
    }

    /// Entries of the kept front (0 when none is kept).
    pub fn front_len(&self) -> usize {
        self.front.entries.len()
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
        track: ws.front_tracking(),
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
        track: ws.front_tracking(),
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
        // The scene's per-pair workspaces when it tracks fronts.
        track: ws.front_tracking(),
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
        track: ws.front_tracking(),
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
        track: ws.front_tracking(),
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
        track: false,
    };
    let run = |chunk: &[[u32; 2]]| {
        let mut out = Output::default();
        dispatch(NarrowOp {
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
    /// Record the front ([`Workspace::set_front_tracking`]).
    track: bool,
}

/// What a walk produces: contacts, counters, (broad phase only) leaf pairs and (front
/// tracking only) the front; with the narrow phase's scratch: its rows, and the last leaf of
/// each side (the walk often meets one leaf against several in a row).
struct Output<'h> {
    pairs: Vec<[u32; 2]>,
    counters: Counters,
    leaves: Vec<[u32; 2]>,
    front: Vec<FrontEntry>,
    /// The front outgrew [`FRONT_MAX_ENTRIES`] (and was cleared).
    front_overflow: bool,
    /// Some replayed front entry had a pair that overlapped.
    descended: bool,
    rows: [Row; MAX_ROW],
    last: [Option<(usize, LeafSide<'h>)>; 2],
}

impl Default for Output<'_> {
    fn default() -> Self {
        Self {
            pairs: Vec::new(),
            counters: Counters::default(),
            leaves: Vec::new(),
            front: Vec::new(),
            front_overflow: false,
            descended: false,
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
        self.front_overflow |= other.front_overflow;
        self.descended |= other.descended;
        if self.front.len() + other.front.len() > FRONT_MAX_ENTRIES {
            self.front_overflow = true;
        }
        if self.front_overflow {
            self.front = Vec::new();
        } else {
            self.front.extend_from_slice(&other.front);
        }
        self.counters += other.counters;
        self
    }

    /// Records a front entry, within [`FRONT_MAX_ENTRIES`].
    #[inline(always)]
    fn record(&mut self, entry: FrontEntry) {
        if self.front_overflow {
            return;
        }
        if self.front.len() < FRONT_MAX_ENTRIES {
            self.front.push(entry);
        } else {
            self.front_overflow = true;
            self.front = Vec::new();
        }
    }

    fn finish(mut self) -> Contacts {
        sort_pairs(&mut self.pairs);
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
        if self.track {
            out.front = std::mem::take(&mut ws.front.spare);
            out.front.clear();
        }
        let replay = self.track && ws.front.fits(self.a.tree(), self.b.tree(), self.self_query);
        // The collected leaf pairs (broad phase) are sorted when the walk's order is not a
        // walk from the root: split into tasks, or from a front.
        let sort;
        if replay {
            let entries = std::mem::take(&mut ws.front.entries);
            let chunk = entries
                .len()
                .div_ceil(SEEDS_PER_THREAD * threads)
                .max(ws.grain);
            let work = Work::Front(&entries);
            out = self.walk_tasks(work, threads, chunk, &mut ws.stack, out);
            ws.front.entries = entries;
            sort = true;
        } else {
            dispatch(StartOp {
                walk: self,
                seeds: &mut ws.seeds,
                stack: &mut ws.stack,
                seed_target: if threads > 1 {
                    SEEDS_PER_THREAD * threads
                } else {
                    1
                },
                out: &mut out,
            });
            sort = threads > 1 && !ws.seeds.is_empty();
            let work = Work::Seeds(&ws.seeds);
            out = self.walk_tasks(work, threads, ws.grain, &mut ws.stack, out);
        }
        if sort {
            sort_pairs(&mut out.leaves);
        }
        if self.track {
            self.keep_front(&mut ws.front, &mut out, !replay);
        }
        ws.leaves = std::mem::take(&mut out.leaves);
        out.finish()
    }

    /// Walks `work` (seeds or front entries) into `out`: on the calling thread with `stack`,
    /// or (`threads > 1`) in rayon tasks of `chunk` items, each on its own stack and output,
    /// merged in order.
    fn walk_tasks(
        &self,
        work: Work<'_>,
        threads: usize,
        chunk: usize,
        stack: &mut Vec<[u32; 2]>,
        mut out: Output<'h>,
    ) -> Output<'h> {
        if threads <= 1 {
            dispatch(WalkOp {
                walk: self,
                work,
                stack,
                out: &mut out,
            });
            return out;
        }
        if work.len() == 0 {
            return out;
        }
        // One stack and one output per piece rayon splits the tasks into (not per task):
        // the output is boxed because the fold moves it at every task (its rows are 1 KiB).
        let part = (0..work.len().div_ceil(chunk))
            .into_par_iter()
            .fold(
                || (Box::<Output>::default(), Vec::new()),
                |(mut o, mut stack), task| {
                    dispatch(WalkOp {
                        walk: self,
                        work: work.slice(task * chunk, chunk),
                        stack: &mut stack,
                        out: &mut o,
                    });
                    (o, stack)
                },
            )
            .map(|(o, _)| o)
            .reduce(Box::default, |a, b| Box::new(a.merge(*b)));
        out.merge(*part)
    }

    /// Keeps the front `out` recorded as `front` for the next query, or drops it (outgrown;
    /// see [`Workspace::set_front_tracking`]). `fresh`: recorded by a walk from the root.
    fn keep_front(&self, front: &mut Front, out: &mut Output<'h>, fresh: bool) {
        let entries = std::mem::take(&mut out.front);
        let len = entries.len();
        let outgrown = !fresh && len > FRONT_REGROWTH * front.fresh_len.max(1);
        // A replay in which nothing overlapped: the next query starts from the roots, which
        // is one test if the objects are apart (a front recorded while they touched stays
        // deep), else a walk down to where they separate, recording that front.
        let idle = !fresh && !out.descended && len > 1;
        if out.front_overflow || outgrown || idle {
            front.clear();
            return;
        }
        if fresh {
            front.fresh_len = len;
        }
        front.spare = std::mem::replace(&mut front.entries, entries);
        front.owner = Some(FrontOwner {
            a: Arc::clone(self.a.tree()),
            b: Arc::clone(self.b.tree()),
            self_query: self.self_query,
        });
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
        let overlap = K::test(simd, ba, 0, bb, 1) != 0;
        if self.track && !overlap {
            out.record(FrontEntry::NodeVsGroup {
                a_node: 0,
                b_group: 0,
                lanes: 1,
            });
        }
        overlap.then_some([0, 0])
    }

    /// Expands one overlapping pair: pushes its overlapping children pairs to `next`, or
    /// runs the narrow phase on a leaf pair.
    #[inline(always)]
    fn expand<S: Simd>(
        &self,
        simd: S,
        pair: [u32; 2],
        next: &mut Vec<[u32; 2]>,
        out: &mut Output<'h>,
    ) {
        if !self.split(simd, pair, next, out) {
            self.leaves(simd, pair[0] as usize, pair[1] as usize, out);
        }
    }

    /// Pushes the overlapping children pairs of the overlapping pair `[x, y]` to `next`;
    /// false (nothing pushed) for a leaf pair.
    #[inline(always)]
    fn split<S: Simd>(
        &self,
        simd: S,
        [x, y]: [u32; 2],
        next: &mut Vec<[u32; 2]>,
        out: &mut Output<'h>,
    ) -> bool {
        let (x, y) = (x as usize, y as usize);
        let (ta, tb) = (self.a.tree(), self.b.tree());
        if self.self_query && x == y {
            let Some(g) = ta.child_group(x) else {
                return false;
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
                    let row = !((2u32 << i) - 1);
                    let mut bits = K::test(simd, block, i, block, m) & row;
                    if self.track {
                        self.record_misses(out, ci, g, row & lanes(m), bits, true);
                    }
                    while bits != 0 {
                        let k = bits.trailing_zeros() as usize;
                        bits &= bits - 1;
                        next.push([ci, (nodes.start + k) as u32]);
                    }
                }
            }
            return true;
        }
        let (cx, cy) = (ta.child_group(x), tb.child_group(y));
        if cx.is_none() && cy.is_none() {
            // A leaf pair: decided before reading the groups (a call each, lazy fit check).
            return false;
        }
        let (gx, gy) = (ta.group_of(x), tb.group_of(y));
        let (bx, by) = (self.a.group(gx).0, self.b.group(gy).0);
        let (ix, iy) = (x - ta.group_nodes(gx).start, y - tb.group_nodes(gy).start);
        let descend_x = match (cx, cy) {
            (Some(_), None) => true,
            (None, _) => false,
            (Some(_), Some(_)) => K::extent(bx, ix) >= K::extent(by, iy),
        };
        if descend_x {
            let g = ta.child_group(x).unwrap_or_default();
            let children = self.group(self.a, g, out);
            let nodes = ta.group_nodes(g);
            out.counters.bv_tests += nodes.len() as u64;
            let mut bits = K::test(simd, by, iy, children, nodes.len());
            if self.track {
                self.record_misses(out, y as u32, g, lanes(nodes.len()), bits, false);
            }
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
            if self.track {
                self.record_misses(out, x as u32, g, lanes(nodes.len()), bits, true);
            }
            while bits != 0 {
                let k = bits.trailing_zeros() as usize;
                bits &= bits - 1;
                next.push([x as u32, (nodes.start + k) as u32]);
            }
        }
        true
    }

    /// Records the lanes of `tested` that missed (`hits` clear) as a front entry: node `node`
    /// against group `group` of the other side; `node_in_a`: the node is `a`'s.
    #[inline(always)]
    fn record_misses(
        &self,
        out: &mut Output<'h>,
        node: u32,
        group: usize,
        tested: u32,
        hits: u32,
        node_in_a: bool,
    ) {
        let lanes = tested & !hits;
        if lanes == 0 {
            return;
        }
        let group = group as u32;
        out.record(if node_in_a {
            FrontEntry::NodeVsGroup {
                a_node: node,
                b_group: group,
                lanes,
            }
        } else {
            FrontEntry::GroupVsNode {
                a_group: group,
                b_node: node,
                lanes,
            }
        });
    }

    /// One entry of a kept front, tested again: the pairs that now overlap pushed to
    /// `stack` (to be walked), the others recorded again.
    #[inline(always)]
    fn retest<S: Simd>(
        &self,
        simd: S,
        entry: FrontEntry,
        stack: &mut Vec<[u32; 2]>,
        out: &mut Output<'h>,
    ) {
        let (ta, tb) = (self.a.tree(), self.b.tree());
        match entry {
            FrontEntry::NodeVsGroup {
                a_node,
                b_group,
                lanes,
            } => {
                let gx = ta.group_of(a_node as usize);
                let bx = self.group(self.a, gx, out);
                let ix = a_node as usize - ta.group_nodes(gx).start;
                let (g, nodes) = (b_group as usize, tb.group_nodes(b_group as usize));
                let children = self.group(self.b, g, out);
                out.counters.bv_tests += u64::from(lanes.count_ones());
                let mut bits = K::test(simd, bx, ix, children, nodes.len()) & lanes;
                self.record_misses(out, a_node, g, lanes, bits, true);
                while bits != 0 {
                    let k = bits.trailing_zeros() as usize;
                    bits &= bits - 1;
                    stack.push([a_node, (nodes.start + k) as u32]);
                }
            }
            FrontEntry::GroupVsNode {
                a_group,
                b_node,
                lanes,
            } => {
                let gy = tb.group_of(b_node as usize);
                let by = self.group(self.b, gy, out);
                let iy = b_node as usize - tb.group_nodes(gy).start;
                let (g, nodes) = (a_group as usize, ta.group_nodes(a_group as usize));
                let children = self.group(self.a, g, out);
                out.counters.bv_tests += u64::from(lanes.count_ones());
                let mut bits = K::test(simd, by, iy, children, nodes.len()) & lanes;
                self.record_misses(out, b_node, g, lanes, bits, false);
                while bits != 0 {
                    let k = bits.trailing_zeros() as usize;
                    bits &= bits - 1;
                    stack.push([(nodes.start + k) as u32, b_node]);
                }
            }
            // An overlapping leaf pair is pushed too: `expand` runs its narrow phase.
            FrontEntry::Leaves { x, y } => {
                if self.self_query && x == y {
                    return stack.push([x, y]);
                }
                let (x, y) = (x as usize, y as usize);
                let (gx, gy) = (ta.group_of(x), tb.group_of(y));
                let bx = self.group(self.a, gx, out);
                let by = self.group(self.b, gy, out);
                let (ix, iy) = (x - ta.group_nodes(gx).start, y - tb.group_nodes(gy).start);
                out.counters.bv_tests += 1;
                let lane = 1u32 << iy;
                if K::test(simd, bx, ix, by, iy + 1) & lane != 0 {
                    return stack.push([x as u32, y as u32]);
                }
                self.record_misses(out, x as u32, gy, lane, 0, true);
            }
        }
    }

    /// An overlapping leaf pair: the narrow phase now, or collected (broad phase).
    #[inline(always)]
    fn leaves<S: Simd>(&self, simd: S, x: usize, y: usize, out: &mut Output<'h>) {
        if self.track {
            out.record(FrontEntry::Leaves {
                x: x as u32,
                y: y as u32,
            });
        }
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

    /// Depth-first until `stack` (overlapping pairs) is empty.
    #[inline(always)]
    fn descend<S: Simd>(&self, simd: S, stack: &mut Vec<[u32; 2]>, out: &mut Output<'h>) {
        while let Some(pair) = stack.pop() {
            self.expand(simd, pair, stack, out);
        }
    }
}

/// The calling thread's part of a walk from the root: the root's test, then a breadth-first
/// expansion until `seed_target` pairs are waiting (left in `seeds`; 1: the root alone).
/// Leaf pairs met on the way wait too: the walk tasks run their narrow phase.
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
        self.seeds.push(root);
        let mut next = std::mem::take(self.stack);
        let mut split = true;
        while split && !self.seeds.is_empty() && self.seeds.len() < self.seed_target {
            next.clear();
            split = false;
            for &pair in self.seeds.iter() {
                if self.walk.split(simd, pair, &mut next, self.out) {
                    split = true;
                } else {
                    next.push(pair);
                }
            }
            std::mem::swap(self.seeds, &mut next);
        }
        *self.stack = next;
    }
}

/// Where a walk task starts.
#[derive(Clone, Copy)]
enum Work<'w> {
    /// Overlapping pairs: the root, or what the breadth-first start left.
    Seeds(&'w [[u32; 2]]),
    /// Entries of a kept front, each tested again first.
    Front(&'w [FrontEntry]),
}

impl<'w> Work<'w> {
    fn len(self) -> usize {
        match self {
            Work::Seeds(seeds) => seeds.len(),
            Work::Front(entries) => entries.len(),
        }
    }

    /// The items `start..start + n` (fewer at the end).
    fn slice(self, start: usize, n: usize) -> Self {
        let end = (start + n).min(self.len());
        match self {
            Work::Seeds(seeds) => Work::Seeds(&seeds[start..end]),
            Work::Front(entries) => Work::Front(&entries[start..end]),
        }
    }
}

/// One walk task (the whole walk, sequentially): depth-first from each item of its work.
struct WalkOp<'w, 'h, K: BvKind> {
    walk: &'w Walk<'h, K>,
    work: Work<'w>,
    stack: &'w mut Vec<[u32; 2]>,
    out: &'w mut Output<'h>,
}

impl<K: BvKind> WithSimd for WalkOp<'_, '_, K> {
    type Output = ();
    #[inline(always)]
    fn with_simd<S: Simd>(self, simd: S) {
        for i in 0..self.work.len() {
            self.stack.clear();
            match self.work {
                Work::Seeds(seeds) => self.stack.push(seeds[i]),
                Work::Front(entries) => {
                    self.walk.retest(simd, entries[i], self.stack, self.out);
                    self.out.descended |= !self.stack.is_empty();
                }
            }
            // PERF (compile time): the one place the walk engine (`expand`, with the narrow
            // phase and the refit inlined) is instantiated per backend and kind.
            self.walk.descend(simd, self.stack, self.out);
        }
    }
}

/// `op` on the runtime-detected backend ([`dhcd_kernels::arch`]). Not inlined, so the
/// scalar backend's copy of each operation (which `Arch::dispatch` inlines) is compiled once,
/// not at every call site.
#[inline(never)]
fn dispatch<Op: WithSimd>(op: Op) -> Op::Output {
    dhcd_kernels::arch().dispatch(op)
}

/// Sorts pairs ascending. PERF: one u64 key per pair sorts several times faster than the
/// lexicographic comparison of `[u32; 2]`.
fn sort_pairs(pairs: &mut [[u32; 2]]) {
    pairs.sort_unstable_by_key(|&[a, b]| (u64::from(a) << 32) | u64::from(b));
}

/// The lanes `0..n` of a wide test.
#[inline(always)]
fn lanes(n: usize) -> u32 {
    debug_assert!(n <= 32);
    (((1u64) << n) - 1) as u32
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

#[cfg(test)]
mod tests {
    use super::*;

    fn recorded(n: usize) -> Output<'static> {
        let mut out = Output::default();
        for k in 0..n as u32 {
            out.record(FrontEntry::Leaves { x: k, y: k });
        }
        out
    }

    /// A front that would pass its bound is dropped (memory freed), not grown, and stays
    /// dropped; two parts within the bound whose sum is not merge into a dropped front.
    #[test]
    fn a_front_past_its_bound_is_dropped() {
        let mut out = recorded(FRONT_MAX_ENTRIES);
        assert!(!out.front_overflow);
        assert_eq!(out.front.len(), FRONT_MAX_ENTRIES);
        out.record(FrontEntry::Leaves { x: 0, y: 0 });
        assert!(out.front_overflow);
        assert_eq!(out.front.capacity(), 0);
        out.record(FrontEntry::Leaves { x: 0, y: 0 });
        assert!(out.front.is_empty());

        let half = FRONT_MAX_ENTRIES / 2;
        let over = recorded(half + 1).merge(recorded(half));
        assert!(over.front_overflow && over.front.is_empty());
        let full = recorded(half).merge(recorded(half));
        assert!(!full.front_overflow);
        assert_eq!(full.front.len(), FRONT_MAX_ENTRIES);
        assert_eq!(full.front[half], FrontEntry::Leaves { x: 0, y: 0 });
        let dropped = recorded(1).merge(over);
        assert!(dropped.front_overflow && dropped.front.is_empty());
    }
}
