//! The vertex-sharing triangle pairs of each leaf pair: the pairs a self query skips (they
//! always touch) and does not count in `N_P`.
//!
//! They are a fact of the mesh's topology, so they are counted once per tree, by the first
//! self query (queries between two objects never need them): per leaf, the sorted list of
//! the leaves its triangles share a vertex with and how many triangle pairs do (about 20 ms
//! for 100K triangles). A query then takes `N_P` of a leaf pair from the table (the allowed
//! pairs minus the shared ones) and builds the shared-vertex mask only for triangles whose
//! boxes hit something; a leaf pair sharing no vertex skips the mask entirely.
//!
//! "Share a vertex" means a common corner index (not a common position), and within one
//! leaf a pair is counted once. The table takes `O(sum of squared vertex valences)` time
//! to build; a mesh over [`BUILD_BUDGET`] (a fan of thousands of triangles around one
//! vertex) gets none, and its leaf pairs are counted directly (`count_direct`).

use super::edges::Adjacency;
use super::RegionTree;

/// Largest `sum over vertices of valence^2` for which the table is built, per triangle,
/// plus a constant: every mesh of bounded valence fits (a regular mesh is about 18 per
/// triangle; a few poles of valence 500 fit in the constant).
const BUILD_BUDGET: (u64, u64) = (64, 1 << 20);

/// Per leaf rank `r`: the entries `start[r]..start[r + 1]` of `leaf` (ascending ranks,
/// `r` itself included when some of its own pairs share) and `count`.
#[derive(Clone, Debug, PartialEq, Eq)]
pub(crate) struct SharedPairs {
    start: Vec<u32>,
    leaf: Vec<u32>,
    count: Vec<u64>,
}

impl SharedPairs {
    /// The table of `tree` (its triangles and leaves built), or `None` over the budget.
    pub(crate) fn build(tree: &RegionTree) -> Option<Self> {
        let tris = tree.triangles();
        let vertices = tree.vertex_total();
        // Triangles around each vertex (a mesh's corners are distinct).
        let around = Adjacency::build(vertices, || {
            (0u32..).zip(tris).flat_map(|(t, tri)| tri.map(|v| (v, t)))
        });
        let squares: u64 = (0..vertices as u32)
            .map(|v| (around.of(v).len() as u64).pow(2))
            .sum();
        if squares > BUILD_BUDGET.0 * tris.len() as u64 + BUILD_BUDGET.1 {
            return None;
        }
        let leaves: Vec<usize> = tree.leaves().collect();
        let mut tri_leaf = vec![0u32; tris.len()];
        for (r, &n) in leaves.iter().enumerate() {
            tri_leaf[tree.tri_range(n)].fill(r as u32);
        }

        let mut table = SharedPairs {
            start: Vec::with_capacity(leaves.len() + 1),
            leaf: Vec::new(),
            count: Vec::new(),
        };
        // PERF: marks instead of sorting: `seen[u] == t + 1` once triangle `u` was met as a
        // neighbour of `t` (an edge neighbour is met twice), `count[y]` accumulates leaf `y`'s
        // pairs and `touched` lists the leaves to emit (sorted: a dozen per leaf).
        let mut seen = vec![0u32; tris.len()];
        let mut count = vec![0u64; leaves.len()];
        let mut touched = Vec::new();
        for (r, &n) in leaves.iter().enumerate() {
            table.start.push(table.leaf.len() as u32);
            for t in tree.tri_range(n) {
                for &v in &tris[t] {
                    for &u in around.of(v) {
                        let u = u as usize;
                        // Within one leaf, each pair once (when its first triangle is `t`).
                        let y = tri_leaf[u] as usize;
                        if seen[u] == t as u32 + 1 || u == t || (y == r && u < t) {
                            continue;
                        }
                        seen[u] = t as u32 + 1;
                        if count[y] == 0 {
                            touched.push(y as u32);
                        }
                        count[y] += 1;
                    }
                }
            }
            touched.sort_unstable();
            for &y in &touched {
                table.leaf.push(y);
                table.count.push(std::mem::take(&mut count[y as usize]));
            }
            touched.clear();
        }
        table.start.push(table.leaf.len() as u32);
        Some(table)
    }

    /// The shared pairs of leaf ranks `x` and `y` (0 when they share no vertex).
    #[inline]
    pub(crate) fn get(&self, x: usize, y: usize) -> u64 {
        let run = self.start[x] as usize..self.start[x + 1] as usize;
        match self.leaf[run.clone()].binary_search(&(y as u32)) {
            Ok(i) => self.count[run.start + i],
            Err(_) => 0,
        }
    }

    /// Every entry as `(x, y, count)` (both orders of distinct leaves).
    pub(crate) fn entries(&self) -> impl Iterator<Item = (usize, usize, u64)> + '_ {
        (0..self.start.len() - 1).flat_map(move |x| {
            (self.start[x] as usize..self.start[x + 1] as usize)
                .map(move |i| (x, self.leaf[i] as usize, self.count[i]))
        })
    }

    pub(crate) fn bytes(&self) -> usize {
        use std::mem::size_of_val;
        size_of_val(&self.start[..]) + size_of_val(&self.leaf[..]) + size_of_val(&self.count[..])
    }
}

/// The shared pairs of leaves `x` and `y` (node ids) by comparing every pair: the fallback
/// without a table, and the definition the table is checked against.
pub(crate) fn count_direct(tree: &RegionTree, x: usize, y: usize) -> u64 {
    let tris = tree.triangles();
    let (rx, ry) = (tree.tri_range(x), tree.tri_range(y));
    let mut count = 0;
    for t in rx {
        for u in ry.clone() {
            if (x != y || u > t) && tris[t].iter().any(|v| tris[u].contains(v)) {
                count += 1;
            }
        }
    }
    count
}

/// The number of unordered pairs of distinct triangles sharing a vertex in the whole mesh,
/// by inclusion-exclusion over the corner sets they share (a pair sharing `s` corners is
/// counted `s - C(s,2) + C(s,3) = 1` times): independent of the table's construction.
pub(crate) fn total_by_inclusion_exclusion(tree: &RegionTree) -> u64 {
    let mut containing = std::collections::HashMap::<[u32; 3], u64>::new();
    for set in tree.triangles() {
        for mask in 1..8u32 {
            let mut key = [u32::MAX; 3];
            let mut k = 0;
            for (i, &v) in set.iter().enumerate() {
                if mask >> i & 1 == 1 {
                    key[k] = v;
                    k += 1;
                }
            }
            key[..k].sort_unstable();
            *containing.entry(key).or_default() += 1;
        }
    }
    let mut total: i128 = 0;
    for (key, m) in containing {
        let size = key.iter().filter(|&&v| v != u32::MAX).count();
        let pairs = i128::from(m) * (i128::from(m) - 1) / 2;
        total += if size % 2 == 1 { pairs } else { -pairs };
    }
    total as u64
}
