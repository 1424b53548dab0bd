//! Structural invariants of the region tree.

use super::{shared, RegionTree, TreeShape, MAX_CHILDREN};
use crate::mesh::Mesh;

/// A broken structural invariant of a [`RegionTree`] (a bug in dhcd, never bad input).
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("region tree invariant violated at node {node}: {what}")]
pub struct TreeError {
    /// The node where the invariant fails.
    pub node: usize,
    /// Which invariant.
    pub what: String,
}

fn fail(node: usize, what: impl Into<String>) -> Result<(), TreeError> {
    Err(TreeError {
        node,
        what: what.into(),
    })
}

impl RegionTree {
    /// Checks the topology against the mesh it was built from: levels contiguous and
    /// breadth-first, children nested and partitioning their parent's triangles, leaves
    /// covering every triangle exactly once, each node's vertex set (run + borrowed) equal
    /// to the vertices of its triangles plus the free points (vertices in no triangle) of
    /// its run, the root's holding every vertex, and the permutations consistent with the
    /// mesh; and the shared-pair table (which this builds if no self query has yet).
    pub fn check_topology(&self, mesh: &Mesh) -> Result<(), TreeError> {
        let nodes = self.node_count();
        if self.tris.len() != mesh.triangle_count() || self.vert_order.len() != mesh.vertex_count()
        {
            return fail(0, "triangle or vertex count differs from the mesh");
        }
        if let TreeShape::Levels(levels) = self.shape {
            if self.depth_count() > levels {
                return fail(0, "deeper than the requested levels");
            }
        }
        let mut used = vec![false; self.vertex_total()];
        for &v in self.tris.iter().flatten() {
            used[v as usize] = true;
        }
        let mut leaves = 0;
        for g in 0..self.group_count() {
            let nodes = self.group_nodes(g);
            if nodes.is_empty() || nodes.clone().any(|n| self.group_of(n) != g) {
                return fail(nodes.start, format!("sibling group {g} broken"));
            }
            let parent = nodes.clone().map(|n| self.parent(n)).collect::<Vec<_>>();
            if parent.windows(2).any(|w| w[0] != w[1])
                || parent[0].is_some_and(|p| self.child_group(p) != Some(g))
                || (g == 0) != parent[0].is_none()
            {
                return fail(
                    nodes.start,
                    format!("sibling group {g} is not one node's children"),
                );
            }
        }
        if self.group_nodes(self.group_count() - 1).end != nodes {
            return fail(0, "sibling groups do not tile the nodes");
        }
        for n in 0..nodes {
            if self.leaf_rank(n) != self.is_leaf(n).then_some(leaves) {
                return fail(n, "leaf rank out of order");
            }
            leaves += self.is_leaf(n) as usize;
        }
        if self.parent[0] != u32::MAX {
            return fail(0, "the root has a parent");
        }
        for (k, corner) in self.tri_vertex.iter().enumerate() {
            if corner.len() != self.tris.len()
                || corner.iter().zip(&self.tris).any(|(&v, t)| t[k] != v)
            {
                return fail(0, format!("tri_vertex({k}) differs from the triangles"));
            }
        }
        if self.tri_range(0) != (0..self.tris.len()) {
            return fail(0, "root does not own every triangle");
        }
        for (i, &o) in self.vert_order.iter().enumerate() {
            if self.vert_slot[o as usize] as usize != i {
                return fail(0, format!("vertex permutation broken at internal {i}"));
            }
        }
        for (i, tri) in self.tris.iter().enumerate() {
            let orig = mesh.triangles()[self.tri_order[i] as usize];
            if tri.map(|v| self.vert_order[v as usize]) != orig {
                return fail(0, format!("internal triangle {i} does not match the mesh"));
            }
        }
        let mut covered = vec![false; self.tris.len()];
        for d in 0..self.depth_count() {
            for n in self.level_nodes(d) {
                if self.depth(n) != d {
                    return fail(n, "stored in the wrong level");
                }
                if self.tri_range(n).is_empty() {
                    return fail(n, "empty region");
                }
                let count = self.tri_range(n).len();
                if let TreeShape::Adaptive { leaf_size } = self.shape {
                    if self.is_leaf(n) == (count > leaf_size) {
                        return fail(
                            n,
                            format!("{count} triangles but leaf = {}", self.is_leaf(n)),
                        );
                    }
                }
                if self.child_count[n] as usize > MAX_CHILDREN || self.child_count[n] == 1 {
                    return fail(n, "a split must make 2 to MAX_CHILDREN children");
                }
                if self.is_leaf(n) {
                    for t in self.tri_range(n) {
                        if std::mem::replace(&mut covered[t], true) {
                            return fail(n, format!("triangle {t} in two leaves"));
                        }
                    }
                } else {
                    let mut next = self.tri_range(n).start;
                    for c in self.children(n) {
                        if c >= nodes || self.depth(c) != d + 1 || self.parent(c) != Some(n) {
                            return fail(
                                n,
                                format!("child {c} out of range or at the wrong depth"),
                            );
                        }
                        if self.tri_range(c).start != next {
                            return fail(n, "children do not partition the parent's triangles");
                        }
                        next = self.tri_range(c).end;
                    }
                    if next != self.tri_range(n).end {
                        return fail(n, "children do not cover the parent's triangles");
                    }
                }
                let mut expected: Vec<u32> = self.tris[self.tri_range(n)]
                    .iter()
                    .flatten()
                    .copied()
                    .collect();
                // Free points (in no triangle) are their leaf's own vertices, so its
                // ancestors' too.
                expected.extend(self.vert_run(n).filter(|&v| !used[v]).map(|v| v as u32));
                expected.sort_unstable();
                expected.dedup();
                let mut got: Vec<u32> = self.region_vertices(n).collect();
                got.sort_unstable();
                if got != expected {
                    return fail(n, "vertex set differs from the vertices of its triangles");
                }
                if n == 0 && got.len() != self.vertex_total() {
                    return fail(n, "some vertex is in no region");
                }
            }
        }
        if let Some(t) = covered.iter().position(|&c| !c) {
            return fail(0, format!("triangle {t} is in no leaf"));
        }
        self.check_shared_pairs()
    }

    /// The shared-pair table: every entry symmetric and (for leaf pairs small enough to
    /// compare directly) equal to the direct count, and the entries adding up to the
    /// mesh's total by inclusion-exclusion (so none is missing).
    fn check_shared_pairs(&self) -> Result<(), TreeError> {
        let Some(table) = self.shared_table() else {
            return Ok(());
        };
        let leaves: Vec<usize> = self.leaves().collect();
        let mut sum = 0;
        for (x, y, count) in table.entries() {
            let (nx, ny) = (leaves[x], leaves[y]);
            if count == 0 || table.get(y, x) != count {
                return fail(nx, format!("shared pairs with leaf {ny} not symmetric"));
            }
            let size = self.tri_range(nx).len() * self.tri_range(ny).len();
            if size <= 1 << 16 && shared::count_direct(self, nx, ny) != count {
                return fail(nx, format!("shared pairs with leaf {ny} miscounted"));
            }
            sum += if x <= y { count } else { 0 };
        }
        if sum != shared::total_by_inclusion_exclusion(self) {
            return fail(0, "shared pairs missing from the table");
        }
        Ok(())
    }
}
