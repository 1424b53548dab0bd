//! A bounding-volume hierarchy of one deformable mesh: the shared region tree, the live
//! vertex positions (internal order), the node buffers of one method, and the lazy-refit state.

use std::sync::Arc;

use crate::bv::{BoundingVolume, Method};
use crate::error::{Error, Positions, Result};
use crate::mesh::{check_positions, check_positions_f64, Mesh};
use crate::options::{Options, Refit};
use crate::par::Par;
use crate::points::Points;
use crate::precision::Precision;
use crate::tree::RegionTree;
use dhcd_kernels::lazy::LazyTiles;
use dhcd_kernels::narrow::{self, TriSoa};
use dhcd_kernels::overlap::BoxRows;
use pulp::Simd;

/// A node whose bounding volume fails to enclose its region (a bug in dhcd, never bad input).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{method} node {node} does not enclose vertex {vertex} (original index) of its region: {record}")]
pub struct InvariantError {
    /// The hierarchy's method.
    pub method: Method,
    /// The node whose volume fails.
    pub node: usize,
    /// A vertex of its region outside it (the caller's index).
    pub vertex: u32,
    /// The node's record, printed.
    pub record: String,
}

/// The hierarchy of one deformable mesh, for method `K`
/// ([`Dh`](crate::bv::Dh), [`Sphere`](crate::bv::Sphere) or [`Aabb`](crate::bv::Aabb)).
#[derive(Clone, Debug)]
pub struct Hierarchy<K: BoundingVolume> {
    tree: Arc<RegionTree>,
    /// The current positions as `f32` (internal order): exact for an `f32` hierarchy, the
    /// nearest `f32`s of `exact` for an `f64` one. Bounds are fitted from them.
    points: Points,
    /// The exact positions of an `f64` hierarchy (internal order), which the exact tests read.
    exact: Option<Vec<[f64; 3]>>,
    nodes: K::Nodes,
    refit: Refit,
    /// Triangle corners and boxes in the current pose, refreshed lazily per leaf.
    tris: TriCache,
    /// The boxes of each leaf's own edges and vertices in the current pose, refreshed lazily
    /// per leaf; allocated by the first query on features (proximity).
    features: std::sync::OnceLock<FeatureCache>,
    /// The positions it was built with (caller's order, as `f64`): the rest pose the
    /// contact set's mollifier thresholds are measured in.
    rest: Arc<[[f64; 3]]>,
}

/// Every triangle's corners and closed box in the current pose, refreshed lazily one leaf at
/// a time by the narrow phase: a leaf meets several leaves, so its triangles are gathered
/// once per step instead of once per leaf pair. One tile per leaf over its padded slots
/// (fields: the nine corner coordinates, then box min xyz and max xyz), so the narrow
/// phase's filter reads a few contiguous cache lines per leaf.
#[derive(Clone, Debug)]
pub(crate) struct TriCache {
    tiles: LazyTiles,
}

/// The boxes of every leaf's own edges (`tree/edges.rs`) and own vertices (its vertex run) in
/// the current pose, refreshed lazily one leaf at a time: a leaf meets several leaves in a
/// query on features. One group per leaf rank: six rows (min x, y, z, max x, y, z) of its own
/// edges, six of its own vertices, then the box of its edges' boxes (six entries).
#[derive(Clone, Debug)]
struct FeatureCache {
    tiles: LazyTiles,
}

impl FeatureCache {
    fn new(tree: &RegionTree) -> Self {
        let table = tree.leaf_edges();
        let mut start = 0;
        // `leaves()` is in rank order.
        let groups = (tree.leaves().enumerate())
            .map(|(r, leaf)| {
                let n = 6 * (table.of_rank(r).len() + tree.vert_run(leaf).len()) + 6;
                start += n;
                start - n..start
            })
            .collect();
        Self {
            tiles: LazyTiles::new(start, groups),
        }
    }
}

/// The cached boxes of one leaf's own edges and vertices ([`Hierarchy::leaf_feature_boxes`]).
pub(crate) struct LeafFeatureBoxes<'a> {
    /// Its own edges' boxes (`tree/edges.rs` order).
    pub(crate) edges: BoxRows<'a>,
    /// The box of its own edges' boxes.
    pub(crate) edge_bounds: ([f32; 3], [f32; 3]),
    /// Its own vertices' boxes (its vertex run's order).
    pub(crate) vertices: BoxRows<'a>,
}

/// The cached triangles of one leaf: the tile of its padded slots (its `len` triangles
/// first, then padding up to a multiple of [`crate::tree::BLOCK`]).
#[derive(Clone, Copy, Debug)]
pub(crate) struct LeafTris<'a> {
    /// Number of triangles (the tile is longer: padding).
    pub(crate) len: usize,
    pub(crate) soa: TriSoa<'a>,
}

impl TriCache {
    fn new(tree: &RegionTree) -> Self {
        // Leaf `r`'s group, in rank order (the layout is `TriSoa`'s).
        let mut len = 0;
        let groups = (0..tree.leaf_count())
            .map(|r| {
                let start = len;
                len += TriSoa::group_len(tree.leaf_slots(r).len());
                start..len
            })
            .collect();
        Self {
            tiles: LazyTiles::new(len, groups),
        }
    }

    /// Leaf `leaf`'s triangles in the current pose, gathered first if stale.
    #[inline]
    pub(crate) fn leaf<'a, S: Simd>(
        &'a self,
        simd: S,
        tree: &'a RegionTree,
        p: &Points,
        leaf: usize,
    ) -> LeafTris<'a> {
        let r = tree.leaf_rank(leaf).expect("a leaf");
        let len = tree.tri_range(leaf).len();
        let stride = tree.leaf_slots(r).len();
        let vertices = tree.leaf_vertex_tile(r);
        let (group, _) = self.tiles.get_or_fill(r, |group| {
            narrow::fill_group_with(simd, group, stride, len, vertices, p.soa(), p.is_rounded())
        });
        LeafTris {
            len,
            soa: TriSoa::from_group(group, stride, vertices),
        }
    }
}

/// [`Hierarchy::refit_nodes`]'s fits of the stale `groups` on one dispatched backend.
struct RefitGroups<'a, K: BoundingVolume> {
    h: &'a Hierarchy<K>,
    groups: &'a [usize],
    par: Par,
}

impl<K: BoundingVolume> pulp::WithSimd for RefitGroups<'_, K> {
    type Output = u64;
    #[inline(always)]
    fn with_simd<S: Simd>(self, simd: S) -> u64 {
        let h = self.h;
        let fit = |g: &usize| {
            if h.group(simd, *g).1 {
                h.tree.group_nodes(*g).len() as u64
            } else {
                0
            }
        };
        if self.par.is_parallel() {
            use rayon::prelude::*;
            self.par.install(|| self.groups.par_iter().map(fit).sum())
        } else {
            self.groups.iter().map(fit).sum()
        }
    }
}

impl<K: BoundingVolume> Hierarchy<K> {
    /// Builds the region tree over `mesh` (its positions are the rest pose) and fits `K`'s
    /// volumes to it.
    pub fn new(mesh: &Mesh, options: Options) -> Result<Self> {
        let tree = Arc::new(RegionTree::build(mesh, options.shape())?);
        Self::with_tree(tree, mesh, options)
    }

    /// Fits `K`'s volumes over an existing region tree of `mesh`, so several methods can
    /// share one tree (identical regions). The tree's shape is the given tree's: `options`'
    /// `levels` and `leaf_size` are not read.
    pub fn with_tree(tree: Arc<RegionTree>, mesh: &Mesh, options: Options) -> Result<Self> {
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
        let (points, exact) = match mesh.positions_f64() {
            None => (Points::gather(mesh.positions(), tree.vert_order()), None),
            Some(p) => (
                Points::gather_rounded(p, tree.vert_order()),
                Some(tree.vert_order().iter().map(|&o| p[o as usize]).collect()),
            ),
        };
        let nodes = K::build(&tree, &points, &options);
        let rest: Arc<[[f64; 3]]> = match mesh.positions_f64() {
            Some(p) => p.into(),
            None => mesh.positions().iter().map(|p| p.map(f64::from)).collect(),
        };
        Ok(Self {
            rest,
            tris: TriCache::new(&tree),
            features: std::sync::OnceLock::new(),
            tree,
            points,
            exact,
            nodes,
            refit: options.refit,
        })
    }

    /// Hands the hierarchy the mesh's new vertex positions (caller's vertex order, same
    /// count, finite). Every bounding volume becomes stale; with [`Refit::Lazy`] each is
    /// refitted when first tested, otherwise all are refitted now. Returns the number of
    /// volumes refitted now (`N_U` of the eager modes; 0 with [`Refit::Lazy`], whose refits
    /// the queries count). On error nothing changes.
    ///
    /// An `f64` hierarchy refuses `f32` positions ([`Error::PrecisionMismatch`]): see
    /// [`Hierarchy::update_positions_f64`].
    pub fn update_positions(&mut self, positions: &[[f32; 3]]) -> Result<u64> {
        self.check_precision(Precision::F32)?;
        check_positions(positions, self.tree.vertex_total(), Positions::Update)?;
        Ok(self.apply_positions(positions))
    }

    /// [`Hierarchy::update_positions`] for an `f64` hierarchy (built from a
    /// [`Mesh::new_f64`]): the positions are kept exactly (every coordinate finite and
    /// within the `f32` range, as [`Mesh::new_f64`] asks); an `f32` hierarchy refuses them
    /// ([`Error::PrecisionMismatch`]).
    pub fn update_positions_f64(&mut self, positions: &[[f64; 3]]) -> Result<u64> {
        self.check_precision(Precision::F64)?;
        check_positions_f64(positions, self.tree.vertex_total(), Positions::Update)?;
        Ok(self.apply_positions_f64(positions))
    }

    fn check_precision(&self, got: Precision) -> Result<()> {
        let expected = self.precision();
        if got == expected {
            Ok(())
        } else {
            Err(Error::PrecisionMismatch { expected, got })
        }
    }

    /// [`Hierarchy::update_positions`] of positions the caller has checked
    /// ([`check_positions`] against [`RegionTree::vertex_total`], an `f32` hierarchy).
    pub(crate) fn apply_positions(&mut self, positions: &[[f32; 3]]) -> u64 {
        debug_assert!(
            check_positions(positions, self.tree.vertex_total(), Positions::Update).is_ok()
        );
        debug_assert!(self.exact.is_none());
        self.points.gather_from(positions, self.tree.vert_order());
        self.refit_after_update()
    }

    /// [`Hierarchy::update_positions_f64`] of positions the caller has checked.
    pub(crate) fn apply_positions_f64(&mut self, positions: &[[f64; 3]]) -> u64 {
        debug_assert!(
            check_positions_f64(positions, self.tree.vertex_total(), Positions::Update).is_ok()
        );
        let order = self.tree.vert_order();
        self.points.gather_rounded_from(positions, order);
        if let Some(exact) = &mut self.exact {
            for (e, &o) in exact.iter_mut().zip(order) {
                *e = positions[o as usize];
            }
        }
        self.refit_after_update()
    }

    fn refit_after_update(&mut self) -> u64 {
        self.invalidate();
        match self.refit {
            Refit::Lazy => 0,
            Refit::Eager => self.refit_all(),
            Refit::EagerBottomUp => self.refit_bottom_up(),
        }
    }

    /// See [`Calibration::invalidate`](crate::calibration::Calibration::invalidate).
    pub(crate) fn invalidate(&mut self) {
        K::invalidate(&mut self.nodes);
        self.tris.tiles.invalidate();
        if let Some(features) = self.features.get_mut() {
            features.tiles.invalidate();
        }
    }

    /// See [`Calibration::refit_nodes`](crate::calibration::Calibration::refit_nodes).
    pub(crate) fn refit_nodes(&mut self, ids: &[u32], par: Par) -> Result<u64> {
        if let Some(&n) = ids.iter().find(|&&n| n as usize >= self.node_count()) {
            return Err(Error::NodeOutOfRange {
                node: n,
                node_count: self.node_count(),
            });
        }
        let mut groups: Vec<usize> = ids
            .iter()
            .map(|&n| self.tree.group_of(n as usize))
            .collect();
        groups.sort_unstable();
        groups.dedup();
        Ok(dhcd_kernels::arch().dispatch(RefitGroups {
            h: self,
            groups: &groups,
            par,
        }))
    }

    /// See [`Calibration::fitted_nodes`](crate::calibration::Calibration::fitted_nodes).
    pub(crate) fn fitted_nodes(&self) -> Vec<u32> {
        (0..self.node_count() as u32)
            .filter(|&n| self.is_fitted(n as usize))
            .collect()
    }

    /// Refits every stale node exactly; returns the number of nodes fitted.
    pub(crate) fn refit_all(&mut self) -> u64 {
        crate::bv::refit_all::<K>(&mut self.nodes, &self.tree, &self.points, false)
    }

    /// Refits every stale node bottom-up; returns the number of nodes fitted.
    pub(crate) fn refit_bottom_up(&mut self) -> u64 {
        crate::bv::refit_all::<K>(&mut self.nodes, &self.tree, &self.points, true)
    }

    /// Sibling group `g`'s volumes, fitted first if stale (the refit kernels on `simd`);
    /// whether this call fitted them.
    #[inline]
    pub(crate) fn group<S: Simd>(&self, simd: S, g: usize) -> (K::Block<'_>, bool) {
        K::group(simd, &self.nodes, &self.tree, &self.points, g)
    }

    /// Leaf `leaf`'s triangles in the current pose, gathered first if stale.
    #[inline]
    pub(crate) fn leaf_tris<S: Simd>(&self, simd: S, leaf: usize) -> LeafTris<'_> {
        self.tris.leaf(simd, &self.tree, &self.points, leaf)
    }

    /// The closed boxes of leaf `leaf`'s own edges and own vertices in the current pose
    /// (rounded outward for an `f64` hierarchy), as six rows each, computed first if stale.
    #[inline]
    pub(crate) fn leaf_feature_boxes(&self, leaf: usize) -> LeafFeatureBoxes<'_> {
        let cache = self.features.get_or_init(|| FeatureCache::new(&self.tree));
        let r = self.tree.leaf_rank(leaf).expect("a leaf");
        let edges = self.tree.leaf_edges().of_rank(r);
        let vertices = self.tree.vert_run(leaf);
        let (ne, nv) = (edges.len(), vertices.len());
        let p = &self.points;
        let rounded = p.is_rounded();
        let outward = |lo: f32, hi: f32| {
            if rounded {
                (lo.next_down(), hi.next_up())
            } else {
                (lo, hi)
            }
        };
        let (tile, _) = cache.tiles.get_or_fill(r, |tile| {
            let (edge_rows, rest) = tile.split_at_mut(6 * ne);
            let (vertex_rows, bounds) = rest.split_at_mut(6 * nv);
            let (mut least, mut most) = ([f32::INFINITY; 3], [f32::NEG_INFINITY; 3]);
            for (i, &[u, v]) in edges.iter().enumerate() {
                let (a, b) = (p.get(u as usize), p.get(v as usize));
                for k in 0..3 {
                    let (lo, hi) = outward(a[k].min(b[k]), a[k].max(b[k]));
                    edge_rows[k * ne + i] = lo;
                    edge_rows[(3 + k) * ne + i] = hi;
                    least[k] = least[k].min(lo);
                    most[k] = most[k].max(hi);
                }
            }
            bounds[..3].copy_from_slice(&least);
            bounds[3..].copy_from_slice(&most);
            for (i, v) in vertices.clone().enumerate() {
                let a = p.get(v);
                for k in 0..3 {
                    let (lo, hi) = outward(a[k], a[k]);
                    vertex_rows[k * nv + i] = lo;
                    vertex_rows[(3 + k) * nv + i] = hi;
                }
            }
        });
        let (edge_rows, rest) = tile.split_at(6 * ne);
        let (vertex_rows, bounds) = rest.split_at(6 * nv);
        LeafFeatureBoxes {
            edges: std::array::from_fn(|f| &edge_rows[f * ne..(f + 1) * ne]),
            edge_bounds: (
                [bounds[0], bounds[1], bounds[2]],
                [bounds[3], bounds[4], bounds[5]],
            ),
            vertices: std::array::from_fn(|f| &vertex_rows[f * nv..(f + 1) * nv]),
        }
    }

    /// Checks that every fitted node's volume encloses every vertex of its region in the
    /// current pose (so it encloses the region's triangles), and that DH central vertices lie
    /// in their regions. Stale nodes (lazy refit, not yet tested) are skipped: they are
    /// never tested before being refitted. Returns the number of nodes checked.
    pub fn validate(&self) -> std::result::Result<usize, InvariantError> {
        let mut checked = 0;
        for n in 0..self.node_count() {
            let Some(rec) = self.record(n) else {
                continue;
            };
            if let Some(v) = self
                .tree
                .region_vertices(n)
                .find(|&v| !K::encloses(&rec, &self.points, self.position_f64(v as usize)))
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

    /// Whether node `n` is fitted to the current positions (its sibling group is).
    #[doc(hidden)]
    pub fn is_fitted(&self, n: usize) -> bool {
        K::group_current(&self.nodes, self.tree.group_of(n))
    }

    /// Node `n`'s record, if it is fitted to the current positions.
    #[doc(hidden)]
    pub fn record(&self, n: usize) -> Option<K::Record> {
        K::record(&self.nodes, &self.tree, n)
    }

    /// The region tree (shareable with hierarchies of the other methods: [`Hierarchy::with_tree`]).
    pub fn tree(&self) -> &Arc<RegionTree> {
        &self.tree
    }

    #[doc(hidden)]
    pub fn nodes(&self) -> &K::Nodes {
        &self.nodes
    }

    /// Current positions in internal vertex order (see [`RegionTree::vert_order`]), as
    /// `f32` (the nearest `f32`s of an `f64` hierarchy's positions).
    #[doc(hidden)]
    pub fn points(&self) -> &Points {
        &self.points
    }

    /// The positions the hierarchy was built with (the rest pose; caller's vertex order).
    pub fn rest_positions(&self) -> &[[f64; 3]] {
        &self.rest
    }

    /// The exact current position of internal vertex `v`.
    #[inline]
    #[doc(hidden)]
    pub fn position_f64(&self, v: usize) -> [f64; 3] {
        match &self.exact {
            Some(e) => e[v],
            None => self.points.get(v).map(f64::from),
        }
    }

    /// The exact positions of an `f64` hierarchy, internal order (`None` for `f32`).
    #[inline]
    pub(crate) fn exact_points(&self) -> Option<&[[f64; 3]]> {
        self.exact.as_deref()
    }

    /// Whether the `f32` points are roundings of `f64` positions (an `f64` hierarchy).
    #[inline]
    pub(crate) fn is_rounded(&self) -> bool {
        self.points.is_rounded()
    }

    /// The precision of the positions the hierarchy was built from and takes.
    pub fn precision(&self) -> Precision {
        match self.exact {
            Some(_) => Precision::F64,
            None => Precision::F32,
        }
    }

    /// When the volumes follow a deformation ([`Options::refit`]).
    pub fn refit_mode(&self) -> Refit {
        self.refit
    }

    /// Number of nodes of the region tree.
    pub fn node_count(&self) -> usize {
        self.tree.node_count()
    }

    /// The method, `K::METHOD`.
    pub fn method(&self) -> Method {
        K::METHOD
    }

    /// Bytes of one node record: 8 (DH), 16 (sphere), 24 (AABB).
    pub fn bytes_per_node(&self) -> usize {
        std::mem::size_of::<K::Record>()
    }

    /// Bytes of all node records of this hierarchy (`node_count * bytes_per_node`; the
    /// shared topology is [`RegionTree::topology_bytes`]).
    pub fn bv_bytes(&self) -> usize {
        self.node_count() * self.bytes_per_node()
    }
}
