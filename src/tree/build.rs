//! Top-down construction of the region tree over the rest pose.
//!
//! Every split separates triangles: a node's run is cut into up to [`MAX_CHILDREN`] parts by
//! repeated binary splits of the largest part, each at the median (by count) of its
//! centroids along the longest axis of their bounding box. A median cut cannot be pushed
//! aside by far-away outliers (a midpoint cut can leave every triangle on one side), and the
//! longest axis never cuts a near-flat mesh along its noise (which interleaves children
//! whose bounds never shrink). Ties in the median are broken by triangle index, so even
//! coincident centroids are separated and the build is deterministic.

use super::{RegionTree, TreeShape, BLOCK, MAX_CHILDREN};
use crate::error::Result;
use crate::mesh::Mesh;

const UNSET: u32 = u32::MAX;

impl RegionTree {
    /// Builds the region tree of `mesh` (its current positions are the rest pose).
    ///
    /// [`TreeShape::Adaptive`] splits every node holding more than `leaf_size` triangles;
    /// [`TreeShape::Levels`] splits every node of two or more triangles above the last of
    /// `levels` levels (the paper's fixed depth).
    pub fn build(mesh: &Mesh, shape: TreeShape) -> Result<Self> {
        shape.check()?;
        let tri_count = mesh.triangle_count();
        let centroids: Vec<[f64; 3]> = (0..tri_count)
            .map(|t| {
                let c = mesh.corners(t);
                std::array::from_fn(|k| (c[0][k] as f64 + c[1][k] as f64 + c[2][k] as f64) / 3.0)
            })
            .collect();

        // Breadth-first: each node owns the run `order[start..end]` of the working triangle
        // array; splitting a node permutes its run into its children's consecutive runs, so
        // every node's triangles stay contiguous in the final order.
        let mut order: Vec<u32> = (0..tri_count as u32).collect();
        let mut tri_start = vec![0u32];
        let mut tri_end = vec![tri_count as u32];
        let mut depth = vec![0u8];
        let mut parent = vec![UNSET];
        let mut first_child = vec![0u32];
        let mut child_count = vec![0u8];
        let mut level_start = vec![0u32];
        let mut parts = Vec::with_capacity(MAX_CHILDREN);

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
            if shape.splits(e - s, d) {
                split(&mut order[s..e], &centroids, shape, &mut parts);
                first_child[n] = tri_start.len() as u32;
                child_count[n] = parts.len() as u8;
                for &(ps, pe) in &parts {
                    tri_start.push((s + ps) as u32);
                    tri_end.push((s + pe) as u32);
                    depth.push(d as u8 + 1);
                    parent.push(n as u32);
                    first_child.push(0);
                    child_count.push(0);
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
        let tri_vertex = std::array::from_fn(|k| tris.iter().map(|t| t[k]).collect());

        // Sibling groups: the root alone, then each internal node's children, in id order
        // (breadth-first numbering makes them consecutive ranges tiling the node ids).
        let mut group_start = vec![0u32, 1];
        let mut node_group = vec![0u32; node_count];
        let mut leaf_rank = vec![UNSET; node_count];
        let mut leaves = 0u32;
        for n in 0..node_count {
            if child_count[n] == 0 {
                leaf_rank[n] = leaves;
                leaves += 1;
                continue;
            }
            let g = group_start.len() as u32 - 1;
            let (f, c) = (first_child[n], child_count[n] as u32);
            debug_assert_eq!(group_start[g as usize], f);
            node_group[f as usize..(f + c) as usize].fill(g);
            group_start.push(f + c);
        }

        // Padded layouts: every sibling group and every leaf's triangle run takes a multiple
        // of BLOCK slots, so the wide tests and row filters load whole vectors.
        let mut group_slot = vec![0u32];
        for g in 0..group_start.len() - 1 {
            let len = (group_start[g + 1] - group_start[g]) as usize;
            group_slot.push(group_slot[g] + len.next_multiple_of(BLOCK) as u32);
        }
        let mut leaf_slot = vec![0u32];
        let mut leaf_vertex = Vec::with_capacity(3 * tri_count);
        for n in 0..node_count {
            if child_count[n] != 0 {
                continue;
            }
            let run = &tris[tri_start[n] as usize..tri_end[n] as usize];
            let padded = run.len().next_multiple_of(BLOCK);
            for k in 0..3 {
                leaf_vertex.extend(run.iter().map(|t| t[k]));
                leaf_vertex.resize(leaf_vertex.len() + padded - run.len(), u32::MAX);
            }
            leaf_slot.push(leaf_slot.last().copied().unwrap_or(0) + padded as u32);
        }

        let tree = RegionTree {
            shape,
            first_child,
            child_count,
            parent,
            depth,
            tri_start,
            tri_end,
            vert_start,
            vert_end,
            borrowed_start,
            borrowed,
            level_start,
            group_start,
            node_group,
            leaf_rank,
            group_slot,
            leaf_slot,
            leaf_vertex,
            tris,
            tri_vertex,
            tri_order: order,
            vert_order,
            vert_slot,
            referenced_vertices,
        };
        debug_assert_eq!(tree.check_topology(mesh), Ok(()));
        Ok(tree)
    }
}

impl TreeShape {
    /// Whether a node of `count` triangles at depth `depth` is split.
    fn splits(self, count: usize, depth: usize) -> bool {
        match self {
            TreeShape::Adaptive { leaf_size } => count > leaf_size,
            TreeShape::Levels(levels) => depth + 1 < levels && count > 1,
        }
    }

    /// Whether a part of `count` triangles, inside a node being split, is cut again.
    fn cuts(self, count: usize) -> bool {
        match self {
            TreeShape::Adaptive { leaf_size } => count > leaf_size,
            TreeShape::Levels(_) => count > 1,
        }
    }
}

/// Permutes `run` (triangle ids) into up to [`MAX_CHILDREN`] consecutive parts and writes
/// their `(start, end)` offsets, in order, into `parts`. Always at least two parts
/// (`run` has at least two triangles).
fn split(
    run: &mut [u32],
    centroids: &[[f64; 3]],
    shape: TreeShape,
    parts: &mut Vec<(usize, usize)>,
) {
    debug_assert!(run.len() >= 2);
    parts.clear();
    parts.push((0, run.len()));
    while parts.len() < MAX_CHILDREN {
        // The largest part, if it is still to be cut (the first among equals).
        let Some((i, &(s, e))) = parts
            .iter()
            .enumerate()
            .filter(|(_, &(s, e))| shape.cuts(e - s))
            .max_by_key(|(i, &(s, e))| (e - s, std::cmp::Reverse(*i)))
        else {
            break;
        };
        let mid = s + median_cut(&mut run[s..e], centroids);
        parts[i] = (s, mid);
        parts.insert(i + 1, (mid, e));
    }
}

/// Reorders `run` so that its first `len / 2` triangles have centroids at or below the
/// median along the longest axis of the centroids' box (ties by triangle id); returns
/// `len / 2`.
fn median_cut(run: &mut [u32], centroids: &[[f64; 3]]) -> usize {
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    for &t in run.iter() {
        let c = centroids[t as usize];
        for k in 0..3 {
            lo[k] = lo[k].min(c[k]);
            hi[k] = hi[k].max(c[k]);
        }
    }
    let axis = (0..3)
        .max_by(|&a, &b| (hi[a] - lo[a]).total_cmp(&(hi[b] - lo[b])).then(b.cmp(&a)))
        .unwrap_or(0);
    let mid = run.len() / 2;
    run.select_nth_unstable_by(mid, |&a, &b| {
        centroids[a as usize][axis]
            .total_cmp(&centroids[b as usize][axis])
            .then(a.cmp(&b))
    });
    mid
}
