//! The region tree: one topology over the rest pose, shared by all three bounding-volume
//! methods so that they bound identical regions. Each node has up to [`MAX_CHILDREN`]
//! children (an octree's fan-out, so one SIMD block tests a node against all of them).
//!
//! Layout (all indices are `u32`):
//! - nodes are numbered breadth-first, root `0`; the children of a node are contiguous
//!   (a *sibling group*);
//! - triangles are reordered so that every node's triangles are one contiguous run
//!   `tri_range(n)` of the internal triangle array (leaves own triangles);
//! - vertices are reordered by first appearance in that triangle order, so a node's vertex
//!   set (the vertices of its triangles) is one contiguous run `vert_run(n)` plus a few
//!   `borrowed(n)` vertices that first appeared in an earlier subtree (region boundaries);
//! - a vertex no triangle uses (a free point: a particle, a pinned marker) is given to the
//!   leaf whose rest box is nearest and numbered right after that leaf's triangles' vertices,
//!   so it is one of the leaf's own vertices: every bound holds it and the feature queries
//!   (proximity, CCD) pair it with every triangle;
//! - `tri_order`/`vert_order` map internal indices back to the caller's original ones.

mod build;
mod edges;
pub(crate) use edges::MeshTables;
mod patches;
pub(crate) use patches::{Patch, Patches};
mod shared;
mod validate;

pub use validate::TreeError;

use std::ops::Range;
use std::sync::OnceLock;

use crate::error::{Error, Result};

/// Largest supported number of levels of a fixed-depth tree (root = level 0).
pub const MAX_LEVELS: usize = 16;
/// The paper's choice of fixed depth: five levels.
pub const PAPER_LEVELS: usize = 5;
/// Most children of a node: one block of the wide node tests.
pub const MAX_CHILDREN: usize = 8;
/// Default largest number of triangles in a leaf of an adaptive tree (chosen by
/// measurement on real simulation frames: `docs/PERFORMANCE.md`).
pub const DEFAULT_LEAF_SIZE: usize = 64;
/// Largest accepted leaf size (larger leaves only make the narrow phase quadratic).
pub const MAX_LEAF_SIZE: usize = 4096;
/// Sibling groups (node bounds) and leaf triangle runs (narrow-phase caches) are stored
/// padded to a multiple of this many slots: a wide test or row filter then loads whole
/// vectors of x86-v3 (partial loads are out-of-line calls there), and a node's children are
/// one block whatever the backend.
pub(crate) const BLOCK: usize = 8;
const _: () = assert!(MAX_CHILDREN <= BLOCK, "a sibling group fits one block");

/// How far the region tree is subdivided.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[non_exhaustive]
pub enum TreeShape {
    /// Split every node holding more than `leaf_size` triangles (the default: the depth
    /// follows the mesh).
    Adaptive {
        /// Most triangles in a leaf.
        leaf_size: usize,
    },
    /// The paper's fixed depth: split every node of two or more triangles above the last
    /// of this many levels (root = level 0).
    Levels(usize),
}

impl Default for TreeShape {
    fn default() -> Self {
        TreeShape::Adaptive {
            leaf_size: DEFAULT_LEAF_SIZE,
        }
    }
}

impl TreeShape {
    /// A typed error for a depth or leaf size out of range.
    #[doc(hidden)]
    pub fn check(self) -> Result<()> {
        match self {
            TreeShape::Levels(levels) if levels == 0 || levels > MAX_LEVELS => {
                Err(Error::InvalidLevels {
                    got: levels,
                    max: MAX_LEVELS,
                })
            }
            TreeShape::Adaptive { leaf_size } if leaf_size == 0 || leaf_size > MAX_LEAF_SIZE => {
                Err(Error::InvalidLeafSize {
                    got: leaf_size,
                    max: MAX_LEAF_SIZE,
                })
            }
            _ => Ok(()),
        }
    }
}

/// The shared region hierarchy (topology and reordering only; no bounding volumes).
#[derive(Clone, Debug)]
pub struct RegionTree {
    shape: TreeShape,
    first_child: Vec<u32>,
    child_count: Vec<u8>,
    /// Parent of each node (`u32::MAX` for the root).
    parent: Vec<u32>,
    depth: Vec<u8>,
    tri_start: Vec<u32>,
    tri_end: Vec<u32>,
    vert_start: Vec<u32>,
    vert_end: Vec<u32>,
    borrowed_start: Vec<u32>,
    borrowed: Vec<u32>,
    level_start: Vec<u32>,
    /// Sibling group `g` is nodes `group_start[g]..group_start[g + 1]`: group 0 the root,
    /// then the children of each internal node in id order.
    group_start: Vec<u32>,
    node_group: Vec<u32>,
    /// Index of each leaf among the leaves (`u32::MAX` for internal nodes).
    leaf_rank: Vec<u32>,
    /// Padded layout of the leaves: leaf rank `r` owns triangle slots
    /// `leaf_slot[r]..leaf_slot[r + 1]` (a multiple of [`BLOCK`]). (Sibling group `g` owns
    /// node slots `g * BLOCK..(g + 1) * BLOCK`: a group has at most `MAX_CHILDREN <= BLOCK`
    /// nodes.)
    leaf_slot: Vec<u32>,
    /// Per leaf, a tile of its triangles' corner indices: corner `k` of slot `i` at
    /// `3 * leaf_slot[r] + k * stride + i` (`u32::MAX` in padding).
    leaf_vertex: Vec<u32>,
    tris: Vec<[u32; 3]>,
    /// `tris` as three arrays of corner indices (the narrow phase's shared-vertex mask).
    tri_vertex: [Vec<u32>; 3],
    tri_order: Vec<u32>,
    vert_order: Vec<u32>,
    vert_slot: Vec<u32>,
    /// The vertex-sharing triangle pairs of each leaf pair, built by the first self query
    /// (`None` inside: over its build budget).
    shared: OnceLock<Option<shared::SharedPairs>>,
    /// Each leaf's own edges, built by the first query on features (`edges.rs`).
    edges: OnceLock<edges::LeafEdges>,
    /// The caller's triangles and the unique edge table, built by the first call that needs
    /// them ([`RegionTree::edges`], the contact set).
    tables: OnceLock<edges::MeshTables>,
    /// Which nodes are disks of triangles, with their boundaries, computed per node as
    /// the clearance test asks (`patches.rs`).
    patches: OnceLock<patches::Patches>,
}

impl RegionTree {
    /// How the tree was subdivided.
    pub fn shape(&self) -> TreeShape {
        self.shape
    }

    /// Number of levels of the built tree (root = level 0; same as [`depth_count`]).
    ///
    /// [`depth_count`]: RegionTree::depth_count
    pub fn levels(&self) -> usize {
        self.depth_count()
    }

    /// Number of leaves.
    pub fn leaf_count(&self) -> usize {
        self.node_count() - (self.group_start.len() - 2)
    }

    /// Number of sibling groups: the root's, and one per internal node (its children, which
    /// a wide test reads as one block and the lazy refit fits together).
    pub(crate) fn group_count(&self) -> usize {
        self.group_start.len() - 1
    }

    /// The nodes of sibling group `g` (consecutive ids).
    #[inline]
    pub(crate) fn group_nodes(&self, g: usize) -> Range<usize> {
        self.group_start[g] as usize..self.group_start[g + 1] as usize
    }

    /// The sibling group of node `n` (0 for the root).
    #[inline]
    pub(crate) fn group_of(&self, n: usize) -> usize {
        self.node_group[n] as usize
    }

    /// The group of `n`'s children (`None` for a leaf).
    #[inline]
    pub(crate) fn child_group(&self, n: usize) -> Option<usize> {
        (self.child_count[n] > 0).then(|| self.node_group[self.first_child[n] as usize] as usize)
    }

    /// Index of leaf `n` among the leaves (`0..leaf_count()`), `None` for internal nodes.
    #[inline]
    pub(crate) fn leaf_rank(&self, n: usize) -> Option<usize> {
        let r = self.leaf_rank[n];
        (r != u32::MAX).then_some(r as usize)
    }

    /// Number of slots of the padded node layout.
    pub(crate) fn slot_count(&self) -> usize {
        self.group_count() * BLOCK
    }

    /// The slots of sibling group `g` (its nodes first, in order, then padding; a multiple
    /// of [`BLOCK`]).
    #[inline]
    pub(crate) fn group_slots(&self, g: usize) -> Range<usize> {
        g * BLOCK..(g + 1) * BLOCK
    }

    /// The triangle slots of the leaf of rank `r` (its triangles first, in order, then
    /// padding; a multiple of [`BLOCK`]).
    #[inline]
    pub(crate) fn leaf_slots(&self, r: usize) -> Range<usize> {
        self.leaf_slot[r] as usize..self.leaf_slot[r + 1] as usize
    }

    /// The corner indices of the leaf of rank `r`, as a tile over its padded slots: corner
    /// `k` of triangle `i` at `k * stride + i` (`u32::MAX` in padding).
    #[inline]
    pub(crate) fn leaf_vertex_tile(&self, r: usize) -> &[u32] {
        let s = self.leaf_slots(r);
        &self.leaf_vertex[3 * s.start..3 * s.end]
    }

    /// The leaves, in id order (`leaves()[leaf_rank(n)] == n`).
    #[doc(hidden)]
    pub fn leaves(&self) -> impl Iterator<Item = usize> + '_ {
        (0..self.node_count()).filter(|&n| self.is_leaf(n))
    }

    /// Number of nodes.
    pub fn node_count(&self) -> usize {
        self.first_child.len()
    }

    /// Nodes at depth `d` are `level_nodes(d)`; `d` ranges over `0..depth_count()`.
    pub(crate) fn level_nodes(&self, d: usize) -> Range<usize> {
        self.level_start[d] as usize..self.level_start[d + 1] as usize
    }

    /// Number of non-empty levels.
    #[doc(hidden)]
    pub fn depth_count(&self) -> usize {
        self.level_start.len() - 1
    }

    #[inline]
    #[doc(hidden)]
    pub fn is_leaf(&self, n: usize) -> bool {
        self.child_count[n] == 0
    }

    #[inline]
    #[doc(hidden)]
    pub fn children(&self, n: usize) -> Range<usize> {
        let f = self.first_child[n] as usize;
        f..f + self.child_count[n] as usize
    }

    /// The parent of `n`, `None` for the root.
    #[inline]
    pub(crate) fn parent(&self, n: usize) -> Option<usize> {
        let p = self.parent[n];
        (p != u32::MAX).then_some(p as usize)
    }

    #[inline]
    #[doc(hidden)]
    pub fn depth(&self, n: usize) -> usize {
        self.depth[n] as usize
    }

    /// The node's triangles, as a run of internal triangle indices.
    #[inline]
    #[doc(hidden)]
    pub fn tri_range(&self, n: usize) -> Range<usize> {
        self.tri_start[n] as usize..self.tri_end[n] as usize
    }

    /// The node's own contiguous run of internal vertex indices.
    #[inline]
    pub(crate) fn vert_run(&self, n: usize) -> Range<usize> {
        self.vert_start[n] as usize..self.vert_end[n] as usize
    }

    /// The node's other vertices (internal indices below its run, owned by earlier subtrees).
    #[inline]
    pub(crate) fn borrowed(&self, n: usize) -> &[u32] {
        &self.borrowed[self.borrowed_start[n] as usize..self.borrowed_start[n + 1] as usize]
    }

    /// Size of the node's vertex set.
    #[inline]
    pub(crate) fn vertex_count(&self, n: usize) -> usize {
        self.vert_run(n).len() + self.borrowed(n).len()
    }

    /// Internal vertex indices of every vertex of the node's region.
    #[doc(hidden)]
    pub fn region_vertices(&self, n: usize) -> impl Iterator<Item = u32> + '_ {
        self.vert_run(n)
            .map(|v| v as u32)
            .chain(self.borrowed(n).iter().copied())
    }

    /// Internal triangles (corner indices are internal vertex indices).
    #[inline]
    #[doc(hidden)]
    pub fn triangles(&self) -> &[[u32; 3]] {
        &self.tris
    }

    /// Internal triangle index -> the caller's triangle index.
    #[inline]
    #[doc(hidden)]
    pub fn tri_order(&self) -> &[u32] {
        &self.tri_order
    }

    /// Internal vertex index -> the caller's vertex index (every vertex of the mesh, free
    /// points included).
    #[inline]
    pub(crate) fn vert_order(&self) -> &[u32] {
        &self.vert_order
    }

    /// Caller's vertex index -> internal vertex index.
    #[inline]
    pub(crate) fn vert_slot(&self) -> &[u32] {
        &self.vert_slot
    }

    /// Number of vertices (those no triangle uses included).
    pub fn vertex_total(&self) -> usize {
        self.vert_order.len()
    }

    /// Number of triangles.
    pub fn triangle_total(&self) -> usize {
        self.tris.len()
    }

    /// The triangle pairs of leaves `x` and `y` (node ids; `x == y`: unordered pairs of
    /// distinct triangles) that share a vertex index: the pairs a self query skips. Read
    /// from a table built by the first call (counted directly for a mesh over the table's
    /// budget). A node beyond the tree is an [`Error::NodeOutOfRange`], an internal node an
    /// [`Error::NotALeaf`].
    #[doc(hidden)]
    pub fn shared_pairs(&self, x: usize, y: usize) -> Result<u64> {
        for n in [x, y] {
            if n >= self.node_count() {
                return Err(Error::NodeOutOfRange {
                    node: u32::try_from(n).unwrap_or(u32::MAX),
                    node_count: self.node_count(),
                });
            }
            if !self.is_leaf(n) {
                return Err(Error::NotALeaf { node: n as u32 });
            }
        }
        Ok(self.shared_pairs_of_leaves(x, y))
    }

    /// [`shared_pairs`](Self::shared_pairs) for two leaves the caller knows (the walk's hot
    /// path: no checks).
    #[inline]
    pub(crate) fn shared_pairs_of_leaves(&self, x: usize, y: usize) -> u64 {
        debug_assert!(self.is_leaf(x) && self.is_leaf(y));
        match self.shared_table() {
            Some(table) => table.get(self.leaf_rank[x] as usize, self.leaf_rank[y] as usize),
            None => shared::count_direct(self, x, y),
        }
    }

    /// The shared-pair table, built on first use.
    #[inline]
    fn shared_table(&self) -> Option<&shared::SharedPairs> {
        self.shared
            .get_or_init(|| shared::SharedPairs::build(self))
            .as_ref()
    }

    /// Each leaf's own edges (built by the first call; see `edges.rs`).
    pub(crate) fn leaf_edges(&self) -> &edges::LeafEdges {
        self.edges.get_or_init(|| edges::LeafEdges::build(self))
    }

    /// The mesh's unique edges, each as its two vertices (the caller's indices, smaller
    /// first), sorted: edge ids (as the contact set's `edges` give them) index this table.
    /// Built by the first call (one sort of the `3 T` triangle edges).
    pub fn edges(&self) -> &[[u32; 2]] {
        &self.tables().edges
    }

    /// The id of the edge joining vertices `u` and `v` (caller's indices, either order), or
    /// `None` if no triangle has that edge.
    pub fn edge_id(&self, u: u32, v: u32) -> Option<u32> {
        self.tables().edge_id(u, v)
    }

    pub(crate) fn tables(&self) -> &edges::MeshTables {
        self.tables.get_or_init(|| edges::MeshTables::build(self))
    }

    /// Which nodes are patches (disks of triangles), each computed on its first ask (see
    /// `patches.rs`).
    pub(crate) fn patches(&self) -> &Patches {
        self.patches.get_or_init(|| Patches::new(self))
    }

    /// Bytes of topology (shared by the three methods; not part of a BV's record; the
    /// shared-pair table once a self query built it).
    pub fn topology_bytes(&self) -> usize {
        use std::mem::size_of_val;
        size_of_val(&self.first_child[..])
            + size_of_val(&self.child_count[..])
            + size_of_val(&self.parent[..])
            + size_of_val(&self.group_start[..])
            + size_of_val(&self.node_group[..])
            + size_of_val(&self.leaf_rank[..])
            + size_of_val(&self.leaf_slot[..])
            + size_of_val(&self.leaf_vertex[..])
            + size_of_val(&self.depth[..])
            + size_of_val(&self.tri_start[..])
            + size_of_val(&self.tri_end[..])
            + size_of_val(&self.vert_start[..])
            + size_of_val(&self.vert_end[..])
            + size_of_val(&self.borrowed_start[..])
            + size_of_val(&self.borrowed[..])
            + self
                .shared
                .get()
                .and_then(Option::as_ref)
                .map_or(0, |s| s.bytes())
            + self.patches.get().map_or(0, Patches::bytes)
    }
}
