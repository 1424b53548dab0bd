//! A bounding-volume hierarchy of one deformable mesh: the shared region tree, the live
//! vertex positions (internal order), the node buffers of one kind, and the lazy-refit state.

use std::sync::Arc;

use crate::bv::{BvKind, Method};
use crate::error::{Error, Result};
use crate::mesh::{check_positions, Mesh};
use crate::points::Points;
use crate::tree::{RegionTree, TreeShape, DEFAULT_LEAF_SIZE, PAPER_LEVELS};

/// When bounding volumes follow a deformation.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
#[non_exhaustive]
pub enum Refit {
    /// The paper's lazy evaluation: a node is refitted just before its first overlap test
    /// after a position update, and only if it is tested at all.
    #[default]
    Lazy,
    /// Every node is refitted exactly (from its vertices) in `update_positions`.
    Eager,
    /// Every node in `update_positions`, bottom-up: leaves exactly, each internal node as a
    /// bound of its children (for DH, `r_p = max_c(|C_p - C_c| + r_c)`): cheaper, looser.
    EagerBottomUp,
}

impl std::str::FromStr for Refit {
    type Err = Error;
    fn from_str(s: &str) -> Result<Self> {
        match s {
            "lazy" => Ok(Refit::Lazy),
            "eager" => Ok(Refit::Eager),
            "bottom-up" | "eager-bottom-up" => Ok(Refit::EagerBottomUp),
            _ => Err(Error::UnknownRefit(s.to_owned())),
        }
    }
}

/// Build options of a hierarchy.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Options {
    /// A fixed depth for the region tree (root = level 0; the paper uses 5), or `None`
    /// (the default) for an adaptive tree whose leaves hold at most `leaf_size` triangles.
    pub levels: Option<usize>,
    /// Largest number of triangles in a leaf of an adaptive tree (ignored with `levels`).
    pub leaf_size: usize,
    pub refit: Refit,
}

impl Default for Options {
    fn default() -> Self {
        Self {
            levels: None,
            leaf_size: DEFAULT_LEAF_SIZE,
            refit: Refit::Lazy,
        }
    }
}

impl Options {
    /// The paper's setting: a fixed depth of 5 levels, lazy refit.
    pub fn paper() -> Self {
        Self {
            levels: Some(PAPER_LEVELS),
            ..Self::default()
        }
    }

    /// The region tree these options ask for.
    pub fn shape(&self) -> TreeShape {
        match self.levels {
            Some(levels) => TreeShape::Levels(levels),
            None => TreeShape::Adaptive {
                leaf_size: self.leaf_size,
            },
        }
    }
}

/// A node whose bounding volume fails to enclose its region (a bug in dhcd, never bad input).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{method} node {node} does not enclose vertex {vertex} (original index) of its region: {record}")]
pub struct InvariantError {
    pub method: Method,
    pub node: usize,
    pub vertex: u32,
    pub record: String,
}

/// The hierarchy of one deformable mesh, for bounding-volume kind `K`
/// ([`Dh`](crate::bv::Dh), [`Sphere`](crate::bv::Sphere) or [`Aabb`](crate::bv::Aabb)).
#[derive(Clone, Debug)]
pub struct Hierarchy<K: BvKind> {
    tree: Arc<RegionTree>,
    points: Points,
    nodes: K::Nodes,
    /// `stamp[n] == epoch` iff node `n` is fitted to the current positions.
    stamp: Vec<u32>,
    epoch: u32,
    refit: Refit,
    /// BV updates done since the last query took them (see [`Hierarchy::take_updates`]).
    updates: u64,
    /// Triangle corners and boxes in the current pose, refreshed lazily per leaf.
    tris: TriCache,
}

/// Every triangle's corners and closed box in the current pose (internal triangle order),
/// refreshed lazily, one leaf at a time, by the narrow phase: a leaf meets many leaves of
/// the other object, so its triangles are gathered once per step instead of once per leaf
/// pair. Boxes are SoA so the box filter over a leaf's run is one vectorizable loop.
#[derive(Clone, Debug, Default)]
pub(crate) struct TriCache {
    pub(crate) corners: Vec<[[f32; 3]; 3]>,
    pub(crate) lo: [Vec<f32>; 3],
    pub(crate) hi: [Vec<f32>; 3],
    /// `stamp[leaf] == epoch` iff the leaf's triangles are current.
    stamp: Vec<u32>,
}

impl TriCache {
    fn new(tree: &RegionTree, points: &Points) -> Self {
        let t = tree.triangle_total();
        let mut c = Self {
            corners: vec![[[0.0; 3]; 3]; t],
            lo: std::array::from_fn(|_| vec![0.0; t]),
            hi: std::array::from_fn(|_| vec![0.0; t]),
            stamp: vec![0; tree.node_count()],
        };
        c.fill(tree, points, 0..t);
        c
    }

    fn fill(&mut self, tree: &RegionTree, p: &Points, range: std::ops::Range<usize>) {
        for i in range {
            let c = tree.triangles()[i].map(|v| p.get(v as usize));
            self.corners[i] = c;
            let lo = [0, 1, 2].map(|k| c[0][k].min(c[1][k]).min(c[2][k]));
            let hi = [0, 1, 2].map(|k| c[0][k].max(c[1][k]).max(c[2][k]));
            for (k, (l, h)) in lo.into_iter().zip(hi).enumerate() {
                self.lo[k][i] = l;
                self.hi[k][i] = h;
            }
        }
    }
}

impl<K: BvKind> Hierarchy<K> {
    /// Builds the region tree over `mesh` (its positions are the rest pose) and fits `K`'s
    /// volumes to it.
    pub fn new(mesh: &Mesh, options: Options) -> Result<Self> {
        let tree = Arc::new(RegionTree::build(mesh, options.shape())?);
        Self::with_tree(tree, mesh, options.refit)
    }

    /// Fits `K`'s volumes over an existing region tree of `mesh`, so several kinds can
    /// share one tree (identical regions).
    pub fn with_tree(tree: Arc<RegionTree>, mesh: &Mesh, refit: Refit) -> Result<Self> {
        if tree.vertex_total() != mesh.vertex_count()
            || tree.triangle_total() != mesh.triangle_count()
        {
            return Err(Error::TreeMismatch {
                tree_vertices: tree.vertex_total(),
                tree_triangles: tree.triangle_total(),
                mesh_vertices: mesh.vertex_count(),
                mesh_triangles: mesh.triangle_count(),
            });
        }
        let points = Points::gather(mesh.positions(), tree.vert_order());
        let nodes = K::build(&tree, &points);
        let stamp = vec![0; tree.node_count()];
        let tris = TriCache::new(&tree, &points);
        Ok(Self {
            tris,
            tree,
            points,
            nodes,
            stamp,
            epoch: 0,
            refit,
            updates: 0,
        })
    }

    /// Hands the hierarchy the mesh's new vertex positions (caller's vertex order, same
    /// count, finite). Every bounding volume becomes stale; with [`Refit::Lazy`] each is
    /// refitted when first tested, otherwise all are refitted now. On error nothing changes.
    pub fn update_positions(&mut self, positions: &[[f32; 3]]) -> Result<()> {
        check_positions(positions, self.tree.vertex_total())?;
        self.points.gather_from(positions, self.tree.vert_order());
        self.invalidate();
        match self.refit {
            Refit::Lazy => {}
            Refit::Eager => self.refit_all(),
            Refit::EagerBottomUp => self.refit_bottom_up(),
        }
        Ok(())
    }

    /// Marks every bounding volume stale without moving anything (the next query refits
    /// what it tests). Used by calibration and benchmarks to repeat a step's refit work.
    pub fn invalidate(&mut self) {
        if self.epoch == u32::MAX {
            self.stamp.fill(0);
            self.tris.stamp.fill(0);
            self.epoch = 1;
        } else {
            self.epoch += 1;
        }
    }

    /// Refits exactly the stale nodes among `ids` (each once), as the lazy traversal does,
    /// counting them as updates. A node id out of range is an [`Error::NodeOutOfRange`] and
    /// nothing is refitted.
    pub fn refit_nodes(&mut self, ids: &[u32], par: crate::par::Par) -> Result<()> {
        if let Some(&n) = ids.iter().find(|&&n| n as usize >= self.node_count()) {
            return Err(Error::NodeOutOfRange {
                node: n,
                node_count: self.node_count(),
            });
        }
        let mut stale = Vec::new();
        par.install(|| self.ensure_fitted(ids, par.is_parallel(), &mut stale));
        Ok(())
    }

    /// The nodes fitted to the current positions (after a lazy query: the nodes it refitted
    /// or found fresh), in increasing order.
    pub fn fitted_nodes(&self) -> Vec<u32> {
        (0..self.node_count() as u32)
            .filter(|&n| self.stamp[n as usize] == self.epoch)
            .collect()
    }

    /// Refits every stale node exactly.
    pub fn refit_all(&mut self) {
        let all: Vec<u32> = (0..self.node_count() as u32).collect();
        self.ensure_fitted(&all, false, &mut Vec::new());
    }

    /// Refits every node bottom-up: stale leaves exactly, internal nodes from their children.
    pub fn refit_bottom_up(&mut self) {
        let tree = Arc::clone(&self.tree);
        for d in (0..tree.depth_count()).rev() {
            for n in tree.level_nodes(d) {
                if self.stamp[n] == self.epoch {
                    continue;
                }
                let r = if tree.is_leaf(n) {
                    K::fit(&self.nodes, &tree, &self.points, n)
                } else {
                    K::merge(&self.nodes, &tree, &self.points, n)
                };
                K::set(&mut self.nodes, n, r);
                K::stage(&mut self.nodes, &self.points, n);
                self.stamp[n] = self.epoch;
                self.updates += 1;
            }
        }
    }

    /// Lazy refit: fits every node of `ids` that is stale (each once), counting the updates.
    /// `stale` is scratch. In parallel, the fits are computed on the current rayon pool and
    /// stored in order; a fit reads only positions and its own node, so the result is the
    /// same either way.
    pub(crate) fn ensure_fitted(&mut self, ids: &[u32], parallel: bool, stale: &mut Vec<u32>) {
        stale.clear();
        // PERF: frontiers repeat a node in runs (a parent's child against all of the other
        // parent's children); a repeat of the previous id is already fitted.
        let mut last = u32::MAX;
        for &n in ids {
            if n == last {
                continue;
            }
            last = n;
            let slot = &mut self.stamp[n as usize];
            if *slot != self.epoch {
                *slot = self.epoch;
                stale.push(n);
            }
        }
        self.updates += stale.len() as u64;
        if parallel && stale.len() > 1 {
            use rayon::prelude::*;
            let (nodes, tree, points) = (&self.nodes, &*self.tree, &self.points);
            let fitted: Vec<K::Record> = stale
                .par_iter()
                .with_min_len(4)
                .map(|&n| K::fit(nodes, tree, points, n as usize))
                .collect();
            for (&n, r) in stale.iter().zip(fitted) {
                K::set(&mut self.nodes, n as usize, r);
                K::stage(&mut self.nodes, &self.points, n as usize);
            }
        } else {
            for &n in stale.iter() {
                let r = K::fit(&self.nodes, &self.tree, &self.points, n as usize);
                K::set(&mut self.nodes, n as usize, r);
                K::stage(&mut self.nodes, &self.points, n as usize);
            }
        }
    }

    /// Brings leaf `leaf`'s entries of the triangle cache to the current pose (once per step).
    #[inline]
    pub(crate) fn ensure_leaf_tris(&mut self, leaf: usize) {
        if self.tris.stamp[leaf] != self.epoch {
            self.tris.stamp[leaf] = self.epoch;
            self.tris
                .fill(&self.tree, &self.points, self.tree.tri_range(leaf));
        }
    }

    /// Whether leaf `leaf`'s entries of the triangle cache are current.
    #[inline]
    pub(crate) fn leaf_tris_current(&self, leaf: usize) -> bool {
        self.tris.stamp[leaf] == self.epoch
    }

    /// The triangle cache (current only for leaves passed to `ensure_leaf_tris` this step).
    #[inline]
    pub(crate) fn tri_cache(&self) -> &TriCache {
        &self.tris
    }

    /// The BV updates done since the last call (queries add them to their `bv_updates`).
    pub fn take_updates(&mut self) -> u64 {
        std::mem::take(&mut self.updates)
    }

    /// Checks that every fitted node's volume encloses every vertex of its region in the
    /// current pose (so it encloses the region's triangles), and that DH central vertices lie
    /// in their regions. Stale nodes (lazy refit, not yet tested) are skipped: they are
    /// never tested before being refitted. Returns the number of nodes checked.
    pub fn validate(&self) -> std::result::Result<usize, InvariantError> {
        let mut checked = 0;
        for n in 0..self.node_count() {
            if self.stamp[n] != self.epoch {
                continue;
            }
            let rec = K::get(&self.nodes, n);
            if let Some(v) = self
                .tree
                .region_vertices(n)
                .find(|&v| !K::encloses(&rec, &self.points, v as usize))
            {
                return Err(InvariantError {
                    method: K::METHOD,
                    node: n,
                    vertex: self.tree.vert_order()[v as usize],
                    record: format!("{rec:?}"),
                });
            }
            checked += 1;
        }
        Ok(checked)
    }

    /// Whether node `n` is fitted to the current positions.
    pub fn is_fitted(&self, n: usize) -> bool {
        self.stamp[n] == self.epoch
    }

    /// Node `n`'s record (possibly stale: see [`Hierarchy::is_fitted`]).
    pub fn record(&self, n: usize) -> K::Record {
        K::get(&self.nodes, n)
    }

    pub fn tree(&self) -> &Arc<RegionTree> {
        &self.tree
    }

    pub fn nodes(&self) -> &K::Nodes {
        &self.nodes
    }

    /// Current positions in internal vertex order (see [`RegionTree::vert_order`]).
    pub fn points(&self) -> &Points {
        &self.points
    }

    pub fn refit_mode(&self) -> Refit {
        self.refit
    }

    pub fn node_count(&self) -> usize {
        self.tree.node_count()
    }

    pub fn method(&self) -> Method {
        K::METHOD
    }

    /// Bytes of one node record: 8 (DH), 16 (sphere), 24 (AABB).
    pub fn bytes_per_node(&self) -> usize {
        std::mem::size_of::<K::Record>()
    }

    /// Bytes of all node records of this hierarchy (`node_count * bytes_per_node`; the
    /// shared topology is [`RegionTree::topology_bytes`], the SIMD padding is not counted).
    pub fn bv_bytes(&self) -> usize {
        self.node_count() * self.bytes_per_node()
    }
}
