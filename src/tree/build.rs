//! Top-down construction of the region tree over the rest pose.
//!
//! Every split separates triangles: a node's run is cut into up to [`MAX_CHILDREN`] parts by
//! repeated binary splits of the largest part, each at the median (by count) of its
//! centroids along the longest axis of their bounding box. A median cut cannot be pushed
//! aside by far-away outliers (a midpoint cut can leave every triangle on one side), and the
//! longest axis never cuts a near-flat mesh along its noise (which interleaves children
//! whose bounds never shrink). Ties in the median are broken by triangle index, so even
//! coincident centroids are separated and the build is deterministic.
//!
//! A run holding several connected components (16 balls in one mesh, armadillos and their
//! rollers) is first cut between whole components, at the component boundary nearest the
//! median when that leaves at least a quarter on each side and the two sides lie apart along
//! the axis (components ordered by their centroid along it): a region then never spans two
//! objects that move apart, whose refitted bounds would otherwise grow with their distance. A run of more than
//! [`MAX_CUT_COMPONENTS`] components (a triangle soup) gets the plain median cut.
//!
//! Inside a leaf the same median cuts, at multiples of 16 and then 8 triangles, order the
//! triangles in compact groups of the narrow kernel's lanes (`order_leaf`): measured
//! 1.07-1.20x faster steps on the rod, cloth and n-body frames, armadillo unchanged (fewer
//! lane vectors meet the other leaf at all, fewer rows meet each one).

use std::sync::OnceLock;

use super::{RegionTree, TreeShape, BLOCK, MAX_CHILDREN};
use crate::error::Result;
use crate::mesh::Mesh;

const UNSET: u32 = u32::MAX;
/// A cut between whole components is taken when the parts' centroid extents along the cut
/// axis overlap by at most this fraction of their union (measured on the real frames:
/// bouncing balls and armadillos on rollers gain, twisted strands must not be cut apart).
const SEPARATE_OBJECTS_OVERLAP: f64 = 0.25;
/// Most components a run may hold for a cut between whole components (a triangle soup,
/// every triangle its own component, is cut at the median).
const MAX_CUT_COMPONENTS: usize = 64;

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
        let objects = Objects::new(mesh, centroids);

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
                split(&mut order[s..e], &objects, shape, &mut parts);
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
        for n in 0..tri_start.len() {
            if child_count[n] == 0 {
                order_leaf(
                    &mut order[tri_start[n] as usize..tri_end[n] as usize],
                    &objects,
                );
            }
        }

        // Internal triangles and vertices: vertices numbered by first appearance, and each
        // vertex no triangle uses (a free point) right after the last triangle of the leaf
        // it is given to, so that it is one of that leaf's own vertices.
        let vertex_count = mesh.vertex_count();
        let free_points = free_points_by_leaf(
            mesh,
            &order,
            (&tri_start, &tri_end),
            (&first_child, &child_count),
        );
        let mut vert_slot = vec![UNSET; vertex_count];
        let mut vert_order = Vec::with_capacity(vertex_count);
        let mut new_before = Vec::with_capacity(tri_count + 1);
        let mut tris = Vec::with_capacity(tri_count);
        let mut free = free_points.iter().peekable();
        for i in 0..=tri_count {
            // The free points of the leaf ending before triangle `i`.
            while let Some(&(_, v)) = free.next_if(|(end, _)| *end as usize == i) {
                vert_slot[v as usize] = vert_order.len() as u32;
                vert_order.push(v);
            }
            new_before.push(vert_order.len() as u32);
            let Some(&t) = order.get(i) else { break };
            let tri = mesh.triangles()[t as usize];
            tris.push(tri.map(|v| {
                if vert_slot[v as usize] == UNSET {
                    vert_slot[v as usize] = vert_order.len() as u32;
                    vert_order.push(v);
                }
                vert_slot[v as usize]
            }));
        }
        debug_assert_eq!(vert_order.len(), vertex_count);

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
            leaf_slot,
            leaf_vertex,
            tris,
            tri_vertex,
            tri_order: order,
            vert_order,
            vert_slot,
            shared: OnceLock::new(),
            edges: OnceLock::new(),
            tables: OnceLock::new(),
            patches: OnceLock::new(),
        };
        debug_assert_eq!(tree.check_topology(mesh), Ok(()));
        Ok(tree)
    }
}

/// The vertices no triangle uses (free points), each given to the leaf whose rest box is
/// nearest to it (descending from the root, the nearest child's box at each level; ties to
/// the first child), as `(end of that leaf's triangle run, vertex)` sorted by both. A free
/// point is then one of its leaf's own vertices: every bound of the leaf and its ancestors
/// holds it, and the feature queries pair it with every triangle as a point.
fn free_points_by_leaf(
    mesh: &Mesh,
    order: &[u32],
    (tri_start, tri_end): (&[u32], &[u32]),
    (first_child, child_count): (&[u32], &[u8]),
) -> Vec<(u32, u32)> {
    let mut used = vec![false; mesh.vertex_count()];
    for t in mesh.triangles() {
        for &v in t {
            used[v as usize] = true;
        }
    }
    if used.iter().all(|&u| u) {
        return Vec::new();
    }
    let p = mesh.positions();
    let node_count = tri_start.len();
    // Rest boxes, children after parents: filled from the triangles of the leaves, then
    // merged upwards in reverse breadth-first order.
    let mut boxes = vec![([f32::INFINITY; 3], [f32::NEG_INFINITY; 3]); node_count];
    for n in (0..node_count).rev() {
        let b = if child_count[n] == 0 {
            let mut b = boxes[n];
            for &t in &order[tri_start[n] as usize..tri_end[n] as usize] {
                for &v in &mesh.triangles()[t as usize] {
                    for (k, &x) in p[v as usize].iter().enumerate() {
                        b.0[k] = b.0[k].min(x);
                        b.1[k] = b.1[k].max(x);
                    }
                }
            }
            b
        } else {
            let children =
                first_child[n] as usize..(first_child[n] + child_count[n] as u32) as usize;
            children.fold(boxes[n], |b, c| {
                (
                    std::array::from_fn(|k| b.0[k].min(boxes[c].0[k])),
                    std::array::from_fn(|k| b.1[k].max(boxes[c].1[k])),
                )
            })
        };
        boxes[n] = b;
    }
    let gap_sq = |b: &([f32; 3], [f32; 3]), q: [f32; 3]| -> f64 {
        (0..3)
            .map(|k| {
                let (x, lo, hi) = (f64::from(q[k]), f64::from(b.0[k]), f64::from(b.1[k]));
                let d = (lo - x).max(x - hi).max(0.0);
                d * d
            })
            .sum()
    };
    let mut free: Vec<(u32, u32)> = (0..mesh.vertex_count())
        .filter(|&v| !used[v])
        .map(|v| {
            let mut n = 0;
            while child_count[n] > 0 {
                let children =
                    first_child[n] as usize..(first_child[n] + child_count[n] as u32) as usize;
                n = children
                    .min_by(|&a, &b| gap_sq(&boxes[a], p[v]).total_cmp(&gap_sq(&boxes[b], p[v])))
                    .expect("an internal node has children");
            }
            (tri_end[n], v as u32)
        })
        .collect();
    free.sort_unstable();
    free
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
fn split(run: &mut [u32], objects: &Objects, shape: TreeShape, parts: &mut Vec<(usize, usize)>) {
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
        let mid = s + objects.cut(&mut run[s..e]);
        parts[i] = (s, mid);
        parts.insert(i + 1, (mid, e));
    }
}

/// Orders a leaf's triangles in compact groups of the narrow kernel's lane counts (16 with
/// AVX-512, 8 with AVX2): median cuts at multiples of 16, then of 8, so each vector of lanes
/// holds nearby triangles and its union box culls the rows of the other leaf it cannot meet.
fn order_leaf(run: &mut [u32], objects: &Objects) {
    let n = run.len();
    if n <= 8 {
        return;
    }
    let unit = if n > 16 { 16 } else { 8 };
    let first = unit * (n.div_ceil(unit) / 2);
    objects.cut_at(run, first);
    let (a, b) = run.split_at_mut(first);
    order_leaf(a, objects);
    order_leaf(b, objects);
}

/// Per triangle: its centroid and connected component (triangles sharing a vertex are
/// connected), and per component the mean of its triangles' centroids.
struct Objects {
    centroids: Vec<[f64; 3]>,
    component: Vec<u32>,
    component_centroid: Vec<[f64; 3]>,
}

impl Objects {
    fn new(mesh: &Mesh, centroids: Vec<[f64; 3]>) -> Self {
        // Union-find over vertices, with path halving.
        let mut up: Vec<u32> = (0..mesh.vertex_count() as u32).collect();
        fn root(up: &mut [u32], mut v: u32) -> u32 {
            while up[v as usize] != v {
                up[v as usize] = up[up[v as usize] as usize];
                v = up[v as usize];
            }
            v
        }
        for t in mesh.triangles() {
            let r0 = root(&mut up, t[0]);
            for &v in &t[1..] {
                let r = root(&mut up, v);
                if r != r0 {
                    up[r as usize] = r0;
                }
            }
        }
        let mut label = vec![UNSET; up.len()];
        let mut sums: Vec<([f64; 3], f64)> = Vec::new();
        let component: Vec<u32> = mesh
            .triangles()
            .iter()
            .zip(&centroids)
            .map(|(t, c)| {
                let r = root(&mut up, t[0]) as usize;
                if label[r] == UNSET {
                    label[r] = sums.len() as u32;
                    sums.push(([0.0; 3], 0.0));
                }
                let s = &mut sums[label[r] as usize];
                for (sum, x) in s.0.iter_mut().zip(c) {
                    *sum += x;
                }
                s.1 += 1.0;
                label[r]
            })
            .collect();
        let component_centroid = sums.iter().map(|(s, n)| s.map(|x| x / n)).collect();
        Self {
            centroids,
            component,
            component_centroid,
        }
    }

    /// Cuts `run` in two (see the module doc) and returns the length of the first part,
    /// between `len / 4` and `len - len / 4` for a component cut, `len / 2` otherwise.
    fn cut(&self, run: &mut [u32]) -> usize {
        let axis = self.longest_axis(run);
        if let Some(first) = self.component_cut(run, axis) {
            return first;
        }
        let mid = run.len() / 2;
        self.cut_along(run, mid, axis);
        mid
    }

    /// Cuts `run` at `first` along the longest axis of its centroids.
    fn cut_at(&self, run: &mut [u32], first: usize) {
        let axis = self.longest_axis(run);
        self.cut_along(run, first, axis);
    }

    /// Partitions `run` so that its first `first` triangles have the least centroids along
    /// `axis` (ties by index).
    fn cut_along(&self, run: &mut [u32], first: usize, axis: usize) {
        let c = &self.centroids;
        let own = |a: u32, b: u32| {
            c[a as usize][axis]
                .total_cmp(&c[b as usize][axis])
                .then(a.cmp(&b))
        };
        run.select_nth_unstable_by(first, |&a, &b| own(a, b));
    }

    /// The longest axis of the box of `run`'s centroids (the lowest among equals).
    fn longest_axis(&self, run: &[u32]) -> usize {
        let c = &self.centroids;
        let mut lo = [f64::INFINITY; 3];
        let mut hi = [f64::NEG_INFINITY; 3];
        for &t in run.iter() {
            for k in 0..3 {
                lo[k] = lo[k].min(c[t as usize][k]);
                hi[k] = hi[k].max(c[t as usize][k]);
            }
        }
        (0..3)
            .max_by(|&a, &b| (hi[a] - lo[a]).total_cmp(&(hi[b] - lo[b])).then(b.cmp(&a)))
            .unwrap_or(0)
    }

    /// The cut between whole components (see the module doc), if `run` holds between two and
    /// [`MAX_CUT_COMPONENTS`] components and one is acceptable: partitions `run` and returns
    /// the first part's length.
    fn component_cut(&self, run: &mut [u32], axis: usize) -> Option<usize> {
        if self.component_centroid.len() < 2 {
            return None; // one object: nothing to cut between
        }
        // Per component of the run: id, triangle count, centroid extent along the axis.
        let mut comps: Vec<(u32, usize, f64, f64)> = Vec::new();
        for &t in run.iter() {
            let (id, x) = (self.component[t as usize], self.centroids[t as usize][axis]);
            if let Some(c) = comps.iter_mut().find(|c| c.0 == id) {
                c.1 += 1;
                c.2 = c.2.min(x);
                c.3 = c.3.max(x);
            } else if comps.len() == MAX_CUT_COMPONENTS {
                return None;
            } else {
                comps.push((id, 1, x, x));
            }
        }
        if comps.len() < 2 {
            return None;
        }
        let key = |c: &(u32, usize, f64, f64)| self.component_centroid[c.0 as usize][axis];
        comps.sort_unstable_by(|a, b| key(a).total_cmp(&key(b)).then(a.0.cmp(&b.0)));
        // The boundary nearest the median, at least a quarter of the run on each side.
        let (len, mid, quarter) = (run.len(), run.len() / 2, run.len() / 4);
        let mut best: Option<(usize, usize)> = None; // (components before, triangles before)
        let mut before = 0;
        for (k, c) in comps.iter().enumerate().take(comps.len() - 1) {
            before += c.1;
            if before >= quarter.max(1)
                && before <= len - quarter
                && best.is_none_or(|(_, b)| before.abs_diff(mid) < b.abs_diff(mid))
            {
                best = Some((k + 1, before));
            }
        }
        let (k, first) = best?;
        // Only objects apart along the axis: interleaved ones (twisted strands) cut apart
        // would give two long overlapping parts.
        let extent = |cs: &[(u32, usize, f64, f64)]| {
            cs.iter()
                .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), c| {
                    (l.min(c.2), h.max(c.3))
                })
        };
        let ((l1, h1), (l2, h2)) = (extent(&comps[..k]), extent(&comps[k..]));
        let overlap = (h1.min(h2) - l1.max(l2)).max(0.0);
        if overlap > SEPARATE_OBJECTS_OVERLAP * (h1.max(h2) - l1.min(l2)) {
            return None;
        }
        let left: Vec<u32> = comps[..k].iter().map(|c| c.0).collect();
        let (a, b): (Vec<u32>, Vec<u32>) = run
            .iter()
            .partition(|&&t| left.contains(&self.component[t as usize]));
        run[..first].copy_from_slice(&a);
        run[first..].copy_from_slice(&b);
        Some(first)
    }
}
