//! The Distance Hierarchy: a region is bounded by the sphere around one of its own vertices
//! (the central vertex, fixed at build) whose radius is refitted after deformation. The
//! centre moves with the mesh for free; only the radius is ever recomputed.

use super::{conservative_radius, conservative_sum, dist2_f64, padded, sealed, BvKind, Method};
use crate::points::Points;
use crate::tree::RegionTree;
use dhcd_kernels::{overlap, refit};

/// The DH node record: central vertex (internal index) and radius — 8 bytes.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct DhNode {
    pub vertex: u32,
    pub radius: f32,
}
const _: () = assert!(std::mem::size_of::<DhNode>() == 8);

/// DH nodes, structure-of-arrays. Padding entries have radius NaN (never overlap).
///
/// `centre` is not part of the node record: it is a staging copy of the live position of
/// each fitted node's central vertex, written when the node is fitted (positions do not
/// change between two fits of a step), so the overlap test reads one array per coordinate
/// instead of chasing `vertex[n]` into the positions (PERF: the two-level gather was the
/// traversal's largest cost). The test is bit-for-bit the same.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct DhNodes {
    pub vertex: Vec<u32>,
    pub radius: Vec<f32>,
    pub(crate) centre: [Vec<f32>; 3],
}

#[derive(Clone, Copy, Debug, Default)]
pub struct Dh;
impl sealed::Sealed for Dh {}

impl BvKind for Dh {
    const METHOD: Method = Method::Dh;
    type Record = DhNode;
    type Nodes = DhNodes;

    fn build(tree: &RegionTree, rest: &Points) -> DhNodes {
        let n = tree.node_count();
        let mut nodes = DhNodes {
            vertex: vec![0; padded(n)],
            radius: vec![f32::NAN; padded(n)],
            centre: std::array::from_fn(|_| vec![0.0; padded(n)]),
        };
        for node in 0..n {
            nodes.vertex[node] = central_vertex(tree, rest, node);
            nodes.radius[node] = Dh::fit(&nodes, tree, rest, node).radius;
            Dh::stage(&mut nodes, rest, node);
        }
        nodes
    }

    fn fit(nodes: &DhNodes, tree: &RegionTree, p: &Points, n: usize) -> DhNode {
        let vertex = nodes.vertex[n];
        let c = p.get(vertex as usize);
        let run = refit::max_dist_sq(p.soa().slice(tree.vert_run(n)), c);
        let borrowed = refit::max_dist_sq_indexed(p.soa(), tree.borrowed(n), c);
        DhNode {
            vertex,
            radius: conservative_radius(run.max(borrowed)),
        }
    }

    fn merge(nodes: &DhNodes, tree: &RegionTree, p: &Points, n: usize) -> DhNode {
        let vertex = nodes.vertex[n];
        let c = p.get(vertex as usize);
        let mut radius = 0.0f32;
        for child in tree.children(n) {
            let cc = p.get(nodes.vertex[child] as usize);
            let d = (0..3).map(|k| (c[k] - cc[k]) * (c[k] - cc[k])).sum::<f32>();
            radius = radius.max(conservative_sum(
                conservative_radius(d),
                nodes.radius[child],
            ));
        }
        DhNode { vertex, radius }
    }

    #[inline]
    fn get(nodes: &DhNodes, n: usize) -> DhNode {
        DhNode {
            vertex: nodes.vertex[n],
            radius: nodes.radius[n],
        }
    }

    #[inline]
    fn set(nodes: &mut DhNodes, n: usize, r: DhNode) {
        nodes.vertex[n] = r.vertex;
        nodes.radius[n] = r.radius;
    }

    #[inline]
    fn stage(nodes: &mut DhNodes, p: &Points, n: usize) {
        let c = p.get(nodes.vertex[n] as usize);
        for (k, ck) in c.into_iter().enumerate() {
            nodes.centre[k][n] = ck;
        }
    }

    /// `|P_a[c_a] - P_b[c_b]|^2 <= (r_a + r_b)^2`, with the centres read from the staged
    /// copies (identical values; see [`DhNodes`]) by the sphere kernel.
    fn overlap(
        a: &DhNodes,
        _pa: &Points,
        b: &DhNodes,
        _pb: &Points,
        ia: &[u32],
        ib: &[u32],
        out: &mut [u32],
    ) -> usize {
        fn soa(d: &DhNodes) -> overlap::SphereSoa<'_> {
            let [cx, cy, cz] = &d.centre;
            overlap::SphereSoa {
                cx,
                cy,
                cz,
                r: &d.radius,
            }
        }
        overlap::sphere_pairs(soa(a), soa(b), ia, ib, out)
    }

    fn encloses(r: &DhNode, p: &Points, v: usize) -> bool {
        let rad = r.radius as f64;
        dist2_f64(p.get(r.vertex as usize), p.get(v)) <= rad * rad
    }
}

/// The region vertex closest to the centroid (mean) of the region's vertices at rest; ties
/// go to the smallest internal index.
fn central_vertex(tree: &RegionTree, rest: &Points, n: usize) -> u32 {
    let count = tree.vertex_count(n) as f64;
    let mut mean = [0.0f64; 3];
    for v in tree.region_vertices(n) {
        let q = rest.get(v as usize);
        for k in 0..3 {
            mean[k] += q[k] as f64;
        }
    }
    let mean = mean.map(|s| s / count);
    let mut best = (f64::INFINITY, u32::MAX);
    for v in tree.region_vertices(n) {
        let q = rest.get(v as usize);
        let d: f64 = (0..3).map(|k| (q[k] as f64 - mean[k]).powi(2)).sum();
        if (d, v) < best {
            best = (d, v);
        }
    }
    best.1
}
