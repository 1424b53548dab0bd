//! Axis-aligned bounding boxes: min/max over the region's vertices (exact in f32).

use super::{padded, sealed, BvKind, Method};
use crate::points::Points;
use crate::tree::RegionTree;
use dhcd_kernels::{overlap, refit};

/// The box node record: min and max corners — 24 bytes.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct AabbNode {
    pub min: [f32; 3],
    pub max: [f32; 3],
}
const _: () = assert!(std::mem::size_of::<AabbNode>() == 24);

/// Box nodes, structure-of-arrays. Padding entries are empty boxes (min = +inf, max = -inf).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct AabbNodes {
    pub min_x: Vec<f32>,
    pub min_y: Vec<f32>,
    pub min_z: Vec<f32>,
    pub max_x: Vec<f32>,
    pub max_y: Vec<f32>,
    pub max_z: Vec<f32>,
}

impl AabbNodes {
    pub fn soa(&self) -> overlap::AabbSoa<'_> {
        overlap::AabbSoa {
            min_x: &self.min_x,
            min_y: &self.min_y,
            min_z: &self.min_z,
            max_x: &self.max_x,
            max_y: &self.max_y,
            max_z: &self.max_z,
        }
    }
}

#[derive(Clone, Copy, Debug, Default)]
pub struct Aabb;
impl sealed::Sealed for Aabb {}

impl BvKind for Aabb {
    const METHOD: Method = Method::Aabb;
    type Record = AabbNode;
    type Nodes = AabbNodes;

    fn build(tree: &RegionTree, rest: &Points) -> AabbNodes {
        let n = padded(tree.node_count());
        let (inf, ninf) = (f32::INFINITY, f32::NEG_INFINITY);
        let mut nodes = AabbNodes {
            min_x: vec![inf; n],
            min_y: vec![inf; n],
            min_z: vec![inf; n],
            max_x: vec![ninf; n],
            max_y: vec![ninf; n],
            max_z: vec![ninf; n],
        };
        for node in 0..tree.node_count() {
            let r = Aabb::fit(&nodes, tree, rest, node);
            Aabb::set(&mut nodes, node, r);
        }
        nodes
    }

    fn fit(_: &AabbNodes, tree: &RegionTree, p: &Points, n: usize) -> AabbNode {
        let (min, max) = refit::merge_bounds(
            refit::bounds(p.soa().slice(tree.vert_run(n))),
            refit::bounds_indexed(p.soa(), tree.borrowed(n)),
        );
        AabbNode { min, max }
    }

    fn merge(nodes: &AabbNodes, tree: &RegionTree, _: &Points, n: usize) -> AabbNode {
        let (min, max) = tree
            .children(n)
            .map(|c| {
                let r = Aabb::get(nodes, c);
                (r.min, r.max)
            })
            .fold(refit::EMPTY_BOUNDS, refit::merge_bounds);
        AabbNode { min, max }
    }

    #[inline]
    fn get(nodes: &AabbNodes, n: usize) -> AabbNode {
        AabbNode {
            min: [nodes.min_x[n], nodes.min_y[n], nodes.min_z[n]],
            max: [nodes.max_x[n], nodes.max_y[n], nodes.max_z[n]],
        }
    }

    #[inline]
    fn set(nodes: &mut AabbNodes, n: usize, r: AabbNode) {
        [nodes.min_x[n], nodes.min_y[n], nodes.min_z[n]] = r.min;
        [nodes.max_x[n], nodes.max_y[n], nodes.max_z[n]] = r.max;
    }

    fn overlap(
        a: &AabbNodes,
        _: &Points,
        b: &AabbNodes,
        _: &Points,
        ia: &[u32],
        ib: &[u32],
        out: &mut [u32],
    ) -> usize {
        overlap::aabb_pairs(a.soa(), b.soa(), ia, ib, out)
    }

    fn encloses(r: &AabbNode, p: &Points, v: usize) -> bool {
        let q = p.get(v);
        (0..3).all(|k| r.min[k] <= q[k] && q[k] <= r.max[k])
    }
}
