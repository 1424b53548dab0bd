//! Top-down octree construction over the rest pose.

use super::{RegionTree, MAX_LEVELS};
use crate::error::{Error, Result};
use crate::mesh::Mesh;

const UNSET: u32 = u32::MAX;

impl RegionTree {
    /// Builds the region tree of `mesh` (its current positions are the rest pose) with at
    /// most `levels` levels (root = level 0; the paper uses 5).
    ///
    /// A node is split into the non-empty octants of the bounding box of its triangles'
    /// centroids (each triangle goes to the octant of its centroid); it is a leaf when it
    /// is at the last level, holds one triangle, or all its centroids coincide.
    pub fn build(mesh: &Mesh, levels: usize) -> Result<Self> {
        if levels == 0 || levels > MAX_LEVELS {
            return Err(Error::InvalidLevels { got: levels });
        }
        let tri_count = mesh.triangle_count();
        let centroids: Vec<[f64; 3]> = (0..tri_count)
            .map(|t| {
                let c = mesh.corners(t);
                std::array::from_fn(|k| (c[0][k] as f64 + c[1][k] as f64 + c[2][k] as f64) / 3.0)
            })
            .collect();

        // Breadth-first: each node owns the run `order[start..end]` of the working triangle
        // array; splitting a node stably partitions its run among its children, so every
        // node's triangles stay contiguous in the final order.
        let mut order: Vec<u32> = (0..tri_count as u32).collect();
        let mut scratch: Vec<u32> = Vec::with_capacity(tri_count);
        let mut tri_start = vec![0u32];
        let mut tri_end = vec![tri_count as u32];
        let mut depth = vec![0u8];
        let mut first_child = vec![0u32];
        let mut child_count = vec![0u8];
        let mut level_start = vec![0u32];

        let mut n = 0;
        while n < tri_start.len() {
            let (s, e, d) = (
                tri_start[n] as usize,
                tri_end[n] as usize,
                depth[n] as usize,
            );
            if level_start.len() <= d {
                level_start.push(n as u32);
            }
            if d + 1 < levels && e - s > 1 {
                let octs = octants(&order[s..e], &centroids);
                let mut counts = [0usize; 8];
                for &o in &octs {
                    counts[o as usize] += 1;
                }
                if counts.iter().filter(|&&c| c > 0).count() > 1 {
                    // Counting sort by octant (stable).
                    let mut offs = [0usize; 8];
                    let mut acc = 0;
                    for k in 0..8 {
                        offs[k] = acc;
                        acc += counts[k];
                    }
                    scratch.clear();
                    scratch.resize(e - s, 0);
                    for (i, &o) in octs.iter().enumerate() {
                        scratch[offs[o as usize]] = order[s + i];
                        offs[o as usize] += 1;
                    }
                    order[s..e].copy_from_slice(&scratch);
                    first_child[n] = tri_start.len() as u32;
                    let mut start = s;
                    for &c in counts.iter().filter(|&&c| c > 0) {
                        tri_start.push(start as u32);
                        tri_end.push((start + c) as u32);
                        depth.push(d as u8 + 1);
                        first_child.push(0);
                        child_count.push(0);
                        start += c;
                        child_count[n] += 1;
                    }
                }
            }
            n += 1;
        }
        level_start.push(tri_start.len() as u32);

        // Internal triangles and vertices: vertices numbered by first appearance.
        let vertex_count = mesh.vertex_count();
        let mut vert_slot = vec![UNSET; vertex_count];
        let mut vert_order = Vec::with_capacity(vertex_count);
        let mut new_before = Vec::with_capacity(tri_count + 1);
        let mut tris = Vec::with_capacity(tri_count);
        for &t in &order {
            new_before.push(vert_order.len() as u32);
            let tri = mesh.triangles()[t as usize];
            tris.push(tri.map(|v| {
                if vert_slot[v as usize] == UNSET {
                    vert_slot[v as usize] = vert_order.len() as u32;
                    vert_order.push(v);
                }
                vert_slot[v as usize]
            }));
        }
        new_before.push(vert_order.len() as u32);
        let referenced_vertices = vert_order.len() as u32;
        for (v, slot) in vert_slot.iter_mut().enumerate() {
            if *slot == UNSET {
                *slot = vert_order.len() as u32;
                vert_order.push(v as u32);
            }
        }

        let node_count = tri_start.len();
        let vert_start: Vec<u32> = tri_start.iter().map(|&s| new_before[s as usize]).collect();
        let vert_end: Vec<u32> = tri_end.iter().map(|&e| new_before[e as usize]).collect();
        let mut borrowed_start = Vec::with_capacity(node_count + 1);
        let mut borrowed = Vec::new();
        let mut node_borrowed = Vec::new();
        for n in 0..node_count {
            borrowed_start.push(borrowed.len() as u32);
            node_borrowed.clear();
            for tri in &tris[tri_start[n] as usize..tri_end[n] as usize] {
                node_borrowed.extend(tri.iter().copied().filter(|&w| w < vert_start[n]));
            }
            node_borrowed.sort_unstable();
            node_borrowed.dedup();
            borrowed.extend_from_slice(&node_borrowed);
        }
        borrowed_start.push(borrowed.len() as u32);

        let tree = RegionTree {
            levels,
            first_child,
            child_count,
            depth,
            tri_start,
            tri_end,
            vert_start,
            vert_end,
            borrowed_start,
            borrowed,
            level_start,
            tris,
            tri_order: order,
            vert_order,
            vert_slot,
            referenced_vertices,
        };
        debug_assert_eq!(tree.check_topology(mesh), Ok(()));
        Ok(tree)
    }
}

/// Octant (bit 0: x, bit 1: y, bit 2: z above the midpoint) of each triangle's centroid,
/// relative to the bounding box of the centroids of `tris`.
fn octants(tris: &[u32], centroids: &[[f64; 3]]) -> Vec<u8> {
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    for &t in tris {
        let c = centroids[t as usize];
        for k in 0..3 {
            lo[k] = lo[k].min(c[k]);
            hi[k] = hi[k].max(c[k]);
        }
    }
    let mid: [f64; 3] = std::array::from_fn(|k| lo[k] + 0.5 * (hi[k] - lo[k]));
    tris.iter()
        .map(|&t| {
            let c = centroids[t as usize];
            // `>`: an axis of zero extent never splits.
            (c[0] > mid[0]) as u8 | ((c[1] > mid[1]) as u8) << 1 | ((c[2] > mid[2]) as u8) << 2
        })
        .collect()
}
