//! The mesh's unique edges, each owned by one leaf: the leaf of the first triangle (internal
//! order) that has it. Queries on features (proximity, CCD) take a leaf's own vertices
//! ([`RegionTree::vert_run`] of a leaf: the vertices first seen in it) and its own edges, so
//! that every vertex and every edge belongs to exactly one leaf and each feature pair comes
//! from exactly one leaf pair, however many triangles share the feature.
//!
//! Built once per tree, by the first query that needs it: one sort of the `3 T` triangle
//! edges (about 10 ms for 150 K triangles).

use super::RegionTree;

/// Per leaf rank `r`: its own edges `edges[start[r]..start[r + 1]]`, in the order of their
/// first triangles, each as its two internal vertex indices and (`ids`, same place) its two
/// original indices, both with the smaller original index first: the order in which the
/// queries report an edge, kept here so that a candidate pair reads it rather than looking
/// both ends up.
#[derive(Clone, Debug, PartialEq, Eq)]
pub(crate) struct LeafEdges {
    start: Vec<u32>,
    edges: Vec<[u32; 2]>,
    ids: Vec<[u32; 2]>,
}

impl LeafEdges {
    pub(crate) fn build(tree: &RegionTree) -> Self {
        let tris = tree.triangles();
        // The leaf rank of every triangle.
        let mut tri_leaf = vec![0u32; tris.len()];
        for leaf in tree.leaves() {
            let r = tree.leaf_rank(leaf).expect("a leaf") as u32;
            tri_leaf[tree.tri_range(leaf)].fill(r);
        }
        // Every triangle edge with its triangle; the first triangle of each edge owns it.
        let mut all: Vec<([u32; 2], u32)> = Vec::with_capacity(3 * tris.len());
        for (t, tri) in tris.iter().enumerate() {
            for k in 0..3 {
                let (u, v) = (tri[k], tri[(k + 1) % 3]);
                all.push(([u.min(v), u.max(v)], t as u32));
            }
        }
        all.sort_unstable();
        all.dedup_by_key(|(e, _)| *e);
        // Grouped by owner leaf (a stable counting sort), each group in first-triangle order.
        all.sort_by_key(|&(_, t)| t);
        let leaves = tree.leaf_count();
        let mut start = vec![0u32; leaves + 1];
        for &(_, t) in &all {
            start[tri_leaf[t as usize] as usize + 1] += 1;
        }
        for r in 0..leaves {
            start[r + 1] += start[r];
        }
        let order = tree.vert_order();
        let mut fill = start.clone();
        let mut edges = vec![[0u32; 2]; all.len()];
        let mut ids = vec![[0u32; 2]; all.len()];
        for &([s, t], tri) in &all {
            let r = tri_leaf[tri as usize] as usize;
            let (os, ot) = (order[s as usize], order[t as usize]);
            let at = fill[r] as usize;
            (edges[at], ids[at]) = if os < ot {
                ([s, t], [os, ot])
            } else {
                ([t, s], [ot, os])
            };
            fill[r] += 1;
        }
        Self { start, edges, ids }
    }

    /// The own edges of the leaf of rank `r` (internal indices).
    #[inline]
    pub(crate) fn of_rank(&self, r: usize) -> &[[u32; 2]] {
        &self.edges[self.range_of_rank(r)]
    }

    /// The original indices of the own edges of the leaf of rank `r`, in [`Self::of_rank`]'s
    /// order.
    #[inline]
    pub(crate) fn ids_of_rank(&self, r: usize) -> &[[u32; 2]] {
        &self.ids[self.range_of_rank(r)]
    }

    /// Where the own edges of the leaf of rank `r` sit in [`LeafEdges::all`].
    #[inline]
    pub(crate) fn range_of_rank(&self, r: usize) -> std::ops::Range<usize> {
        self.start[r] as usize..self.start[r + 1] as usize
    }

    /// Every unique edge, grouped by owner leaf in leaf-rank order.
    pub(crate) fn all(&self) -> &[[u32; 2]] {
        &self.edges
    }
}

/// The mesh's triangles and unique edges in the caller's indices: the public edge table
/// ([`RegionTree::edges`]) and what the contact set reads to name a row's vertices.
#[derive(Clone, Debug, PartialEq, Eq)]
pub(crate) struct MeshTables {
    /// Every unique edge as its two vertices (caller's indices, smaller first), sorted: an
    /// edge's id is its position here.
    pub(crate) edges: Vec<[u32; 2]>,
    /// Per vertex `u`, the ids of the edges whose smaller vertex is `u`:
    /// `edges_from[u]..edges_from[u + 1]` (the table is sorted, so they are one run).
    edges_from: Vec<u32>,
    /// Every triangle's corners (caller's indices and order), by the caller's triangle index.
    pub(crate) triangles: Vec<[u32; 3]>,
}

/// A list per key, flattened: key `k`'s items are `items[start[k]..start[k + 1]]`.
#[derive(Clone, Debug, PartialEq, Eq)]
pub(crate) struct Adjacency {
    start: Vec<u32>,
    items: Vec<u32>,
}

impl Adjacency {
    /// The lists of `keys` keys from `(key, item)` links, each list in the links' order
    /// (a counting sort: two passes over `links`).
    pub(crate) fn build<I: Iterator<Item = (u32, u32)>>(
        keys: usize,
        links: impl Fn() -> I,
    ) -> Self {
        let mut start = vec![0u32; keys + 1];
        for (k, _) in links() {
            start[k as usize + 1] += 1;
        }
        for k in 0..keys {
            start[k + 1] += start[k];
        }
        let mut next = start.clone();
        let mut items = vec![0u32; start[keys] as usize];
        for (k, item) in links() {
            items[next[k as usize] as usize] = item;
            next[k as usize] += 1;
        }
        Self { start, items }
    }

    /// Key `k`'s items.
    #[inline]
    pub(crate) fn of(&self, k: u32) -> &[u32] {
        &self.items[self.start[k as usize] as usize..self.start[k as usize + 1] as usize]
    }
}

impl MeshTables {
    pub(crate) fn build(tree: &RegionTree) -> Self {
        let order = tree.vert_order();
        let mut triangles = vec![[0u32; 3]; tree.triangle_total()];
        for (tri, &t) in tree.triangles().iter().zip(tree.tri_order()) {
            triangles[t as usize] = tri.map(|v| order[v as usize]);
        }
        let mut edges: Vec<[u32; 2]> = triangles
            .iter()
            .flat_map(|t| (0..3).map(move |k| (t[k], t[(k + 1) % 3])))
            .map(|(u, v)| [u.min(v), u.max(v)])
            .collect();
        edges.sort_unstable();
        edges.dedup();
        let vertices = tree.vertex_total();
        let mut edges_from = vec![0u32; vertices + 1];
        for &[u, _] in &edges {
            edges_from[u as usize + 1] += 1;
        }
        for u in 0..vertices {
            edges_from[u + 1] += edges_from[u];
        }
        Self {
            edges,
            edges_from,
            triangles,
        }
    }

    /// The id of the edge `(u, v)` (either order), if the mesh has it.
    pub(crate) fn edge_id(&self, u: u32, v: u32) -> Option<u32> {
        edge_between(&self.edges, &self.edges_from, u, v)
    }
}

/// The id of the edge `(u, v)` (either order) among `edges` (sorted, each smaller vertex
/// first), if there is one: a scan of the run of edges from the smaller end (`edges_from`,
/// see [`MeshTables`]), a few consecutive entries.
// PERF: the run is contiguous; scanning a vertex's edge ids and reading each edge (one cache
// miss each) was 4% of cloth-ball's contact set.
fn edge_between(edges: &[[u32; 2]], edges_from: &[u32], u: u32, v: u32) -> Option<u32> {
    let (u, v) = (u.min(v), u.max(v));
    let u = u as usize;
    if u + 1 >= edges_from.len() {
        return None;
    }
    let (first, end) = (edges_from[u] as usize, edges_from[u + 1] as usize);
    edges[first..end]
        .iter()
        .position(|e| e[1] == v)
        .map(|k| (first + k) as u32)
}
