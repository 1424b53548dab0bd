//! Sphere bounding volumes (the paper's SBV): centre = mean of the region's vertices,
//! radius = largest distance from it. Refitting reads the region twice (mean, then radius).

use super::{conservative_radius, conservative_sum, dist2_f64, padded, sealed, BvKind, Method};
use crate::points::Points;
use crate::tree::RegionTree;
use dhcd_kernels::{overlap, refit};

/// The sphere node record: centre and radius — 16 bytes.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct SphereNode {
    pub center: [f32; 3],
    pub radius: f32,
}
const _: () = assert!(std::mem::size_of::<SphereNode>() == 16);

/// Sphere nodes, structure-of-arrays. Padding entries have radius NaN (never overlap).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct SphereNodes {
    pub cx: Vec<f32>,
    pub cy: Vec<f32>,
    pub cz: Vec<f32>,
    pub radius: Vec<f32>,
}

impl SphereNodes {
    pub fn soa(&self) -> overlap::SphereSoa<'_> {
        overlap::SphereSoa {
            cx: &self.cx,
            cy: &self.cy,
            cz: &self.cz,
            r: &self.radius,
        }
    }
}

#[derive(Clone, Copy, Debug, Default)]
pub struct Sphere;
impl sealed::Sealed for Sphere {}

impl BvKind for Sphere {
    const METHOD: Method = Method::Sphere;
    type Record = SphereNode;
    type Nodes = SphereNodes;

    fn build(tree: &RegionTree, rest: &Points) -> SphereNodes {
        let n = tree.node_count();
        let mut nodes = SphereNodes {
            cx: vec![0.0; padded(n)],
            cy: vec![0.0; padded(n)],
            cz: vec![0.0; padded(n)],
            radius: vec![f32::NAN; padded(n)],
        };
        for node in 0..n {
            let r = Sphere::fit(&nodes, tree, rest, node);
            Sphere::set(&mut nodes, node, r);
        }
        nodes
    }

    fn fit(_: &SphereNodes, tree: &RegionTree, p: &Points, n: usize) -> SphereNode {
        let run = p.soa().slice(tree.vert_run(n));
        let borrowed = tree.borrowed(n);
        let s1 = refit::sum(run);
        let s2 = refit::sum_indexed(p.soa(), borrowed);
        let inv = 1.0 / tree.vertex_count(n) as f32;
        let mut center = [0, 1, 2].map(|k| (s1[k] + s2[k]) * inv);
        if !center.iter().all(|c| c.is_finite()) {
            // The sum overflowed (coordinates near f32::MAX): any centre is correct, the
            // radius below bounds the region from it; take the box midpoint.
            let (lo, hi) =
                refit::merge_bounds(refit::bounds(run), refit::bounds_indexed(p.soa(), borrowed));
            center = [0, 1, 2].map(|k| lo[k] * 0.5 + hi[k] * 0.5);
        }
        let d2 = refit::max_dist_sq(run, center).max(refit::max_dist_sq_indexed(
            p.soa(),
            borrowed,
            center,
        ));
        SphereNode {
            center,
            radius: conservative_radius(d2),
        }
    }

    fn merge(nodes: &SphereNodes, tree: &RegionTree, _: &Points, n: usize) -> SphereNode {
        let children = tree.children(n);
        let inv = 1.0 / children.len() as f32;
        let mut center = [0.0f32; 3];
        for c in children.clone() {
            let cc = Sphere::get(nodes, c).center;
            for k in 0..3 {
                center[k] += cc[k] * inv;
            }
        }
        if !center.iter().all(|c| c.is_finite()) {
            center = Sphere::get(nodes, children.start).center;
        }
        let mut radius = 0.0f32;
        for c in children {
            let child = Sphere::get(nodes, c);
            let d2 = (0..3)
                .map(|k| (center[k] - child.center[k]).powi(2))
                .sum::<f32>();
            radius = radius.max(conservative_sum(conservative_radius(d2), child.radius));
        }
        SphereNode { center, radius }
    }

    #[inline]
    fn get(nodes: &SphereNodes, n: usize) -> SphereNode {
        SphereNode {
            center: [nodes.cx[n], nodes.cy[n], nodes.cz[n]],
            radius: nodes.radius[n],
        }
    }

    #[inline]
    fn set(nodes: &mut SphereNodes, n: usize, r: SphereNode) {
        [nodes.cx[n], nodes.cy[n], nodes.cz[n]] = r.center;
        nodes.radius[n] = r.radius;
    }

    fn overlap(
        a: &SphereNodes,
        _: &Points,
        b: &SphereNodes,
        _: &Points,
        ia: &[u32],
        ib: &[u32],
        out: &mut [u32],
    ) -> usize {
        overlap::sphere_pairs(a.soa(), b.soa(), ia, ib, out)
    }

    fn encloses(r: &SphereNode, p: &Points, v: usize) -> bool {
        let rad = r.radius as f64;
        dist2_f64(r.center, p.get(v)) <= rad * rad
    }
}
