//! The Distance Hierarchy: a region is bounded by the sphere around one of its own vertices
//! (the central vertex, fixed at build: [`crate::CentralVertex`], chosen in `central.rs`)
//! whose radius is refitted after deformation. The
//! centre moves with the mesh for free; only the radius is ever recomputed.

use super::swept::{self, MovingBalls, Step};
use super::{central, sealed, BoundingVolume, Method};
use super::{conservative_radius, conservative_sum, dist2_f64, exact_radius, Bounds};
use crate::options::Options;
use crate::points::Points;
use crate::tree::RegionTree;
use dhcd_kernels::{overlap, refit};
use pulp::Simd;

/// The DH node record: central vertex (internal index) and radius — 8 bytes.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct DhNode {
    /// Central vertex (internal index): the sphere's centre is its current position.
    pub vertex: u32,
    /// Radius around the central vertex.
    pub radius: f32,
}
const _: () = assert!(std::mem::size_of::<DhNode>() == 8);

/// DH nodes, structure-of-arrays: the central vertices (fixed at build) and, per step, the
/// radii.
///
/// The lazily fitted tiles also hold a staging copy of each fitted node's centre (the live
/// position of its central vertex), written when the node is fitted (positions do not change
/// within a step), so the wide test reads contiguous arrays instead of chasing `vertex[n]`
/// into the positions. It is scratch, not part of the 8-byte record; the test is bit for bit
/// the sphere test on the same `f32` values.
#[derive(Clone, Debug)]
pub struct DhNodes {
    /// Each node's central vertex (internal index).
    pub vertex: Vec<u32>,
    /// `[cx, cy, cz, radius]` per node.
    fitted: Bounds<4>,
}

/// The Distance Hierarchy (DH): 8-byte records, a central vertex and a radius.
#[derive(Clone, Copy, Debug, Default)]
pub struct Dh;
impl sealed::Sealed for Dh {}

/// The exact radius of node `n` around its central vertex `c`.
fn radius<S: Simd>(simd: S, tree: &RegionTree, p: &Points, n: usize, c: [f32; 3]) -> f32 {
    let run = refit::max_dist_sq_with(simd, p.soa().slice(tree.vert_run(n)), c);
    let borrowed = refit::max_dist_sq_indexed_with(simd, p.soa(), tree.borrowed(n), c);
    exact_radius(p, c, conservative_radius(run.max(borrowed)))
}

impl BoundingVolume for Dh {
    const METHOD: Method = Method::Dh;
    type Record = DhNode;
    type Nodes = DhNodes;
    type Block<'a> = overlap::SphereSoa<'a>;

    fn build(tree: &RegionTree, rest: &Points, options: &Options) -> DhNodes {
        let vertex = central::central_vertices(tree, rest, options.central);
        let mut nodes = DhNodes {
            vertex,
            fitted: Bounds::new(tree),
        };
        super::refit_all::<Dh>(&mut nodes, tree, rest, false);
        nodes
    }

    #[inline]
    fn group<'a, S: Simd>(
        simd: S,
        nodes: &'a DhNodes,
        tree: &RegionTree,
        p: &Points,
        g: usize,
    ) -> (overlap::SphereSoa<'a>, bool) {
        let (tile, fitted) = nodes.fitted.group(tree, g, |n| {
            let c = p.get(nodes.vertex[n] as usize);
            [c[0], c[1], c[2], radius(simd, tree, p, n, c)]
        });
        (overlap::SphereSoa::new(tile), fitted)
    }

    #[inline]
    fn group_current(nodes: &DhNodes, g: usize) -> bool {
        nodes.fitted.is_current(g)
    }

    #[inline(always)]
    fn test<S: pulp::Simd>(
        simd: S,
        a: overlap::SphereSoa<'_>,
        i: usize,
        b: overlap::SphereSoa<'_>,
        n: usize,
    ) -> u32 {
        let (c, r) = a.get(i);
        overlap::sphere_block_with(simd, c, r, b, n)
    }

    #[inline(always)]
    fn test_within<S: pulp::Simd>(
        simd: S,
        a: overlap::SphereSoa<'_>,
        i: usize,
        b: overlap::SphereSoa<'_>,
        n: usize,
        margin: f32,
    ) -> u32 {
        // The sum rounded up like a bottom-up radius: the test stays conservative.
        let (c, r) = a.get(i);
        overlap::sphere_block_with(simd, c, conservative_sum(r, margin), b, n)
    }

    #[inline(always)]
    fn extent(a: overlap::SphereSoa<'_>, i: usize) -> f32 {
        a.r()[i]
    }

    fn fit<S: Simd>(simd: S, nodes: &DhNodes, tree: &RegionTree, p: &Points, n: usize) -> DhNode {
        let vertex = nodes.vertex[n];
        DhNode {
            vertex,
            radius: radius(simd, tree, p, n, p.get(vertex as usize)),
        }
    }

    fn record(nodes: &DhNodes, tree: &RegionTree, n: usize) -> Option<DhNode> {
        let [_, _, _, radius] = nodes.fitted.get(tree, n)?;
        Some(DhNode {
            vertex: nodes.vertex[n],
            radius,
        })
    }

    fn invalidate(nodes: &mut DhNodes) {
        nodes.fitted.invalidate();
    }

    fn refit_all<S: Simd>(
        simd: S,
        nodes: &mut DhNodes,
        tree: &RegionTree,
        p: &Points,
        bottom_up: bool,
    ) -> u64 {
        let vertex = &nodes.vertex;
        nodes.fitted.refit_all(tree, |n, child| {
            let c = p.get(vertex[n] as usize);
            let r = if bottom_up && !tree.is_leaf(n) {
                // r_p = max_c (|C_p - C_c| + r_c): children are fitted (deeper groups first).
                let mut r = 0.0f32;
                for ch in tree.children(n) {
                    let [x, y, z, rc] = child(ch);
                    let d =
                        (c[0] - x) * (c[0] - x) + (c[1] - y) * (c[1] - y) + (c[2] - z) * (c[2] - z);
                    r = r.max(conservative_sum(conservative_radius(d), rc));
                }
                r
            } else {
                radius(simd, tree, p, n, c)
            };
            [c[0], c[1], c[2], r]
        })
    }

    fn encloses(r: &DhNode, p: &Points, point: [f64; 3]) -> bool {
        let rad = r.radius as f64;
        dist2_f64(p.get(r.vertex as usize), point) <= rad * rad
    }

    type Swept = MovingBalls;
    type SweptBlock<'a> = overlap::MovingSphereSoa<'a>;

    fn swept(tree: &RegionTree) -> MovingBalls {
        MovingBalls::new(tree)
    }

    #[inline]
    fn swept_group<'a>(
        swept: &'a MovingBalls,
        nodes: &DhNodes,
        tree: &RegionTree,
        step: &Step,
        g: usize,
    ) -> (overlap::MovingSphereSoa<'a>, bool) {
        swept::ball_group(swept, tree, step, g, |n| {
            let c = nodes.vertex[n] as usize;
            (step.x0[c], step.x1[c])
        })
    }

    #[inline(always)]
    fn swept_test<S: pulp::Simd>(
        simd: S,
        a: overlap::MovingSphereSoa<'_>,
        i: usize,
        b: overlap::MovingSphereSoa<'_>,
        n: usize,
        margin: f64,
    ) -> u32 {
        swept::balls_test(simd, a, i, b, n, margin)
    }

    #[inline(always)]
    fn swept_extent(a: overlap::MovingSphereSoa<'_>, i: usize) -> f32 {
        swept::ball_extent(a, i)
    }

    fn swept_encloses(
        swept: &MovingBalls,
        tree: &RegionTree,
        n: usize,
        t: f64,
        point: [f64; 3],
    ) -> Option<bool> {
        swept::ball_encloses(swept, tree, n, t, point)
    }
}
