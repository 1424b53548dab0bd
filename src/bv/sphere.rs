//! Sphere bounding volumes (the paper's SBV): centre = mean of the region's vertices,
//! radius = largest distance from it. Refitting reads the region twice (mean, then radius).

use super::swept::{self, MovingBalls, Step};
use super::{conservative_radius, conservative_sum, dist2_f64, exact_radius, Bounds};
use super::{sealed, BoundingVolume, Method};
use crate::options::Options;
use crate::points::Points;
use crate::tree::RegionTree;
use dhcd_kernels::{overlap, refit};
use pulp::Simd;

/// The sphere node record: centre and radius — 16 bytes.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct SphereNode {
    /// Centre.
    pub center: [f32; 3],
    /// Radius.
    pub radius: f32,
}
const _: () = assert!(std::mem::size_of::<SphereNode>() == 16);

/// Sphere nodes, structure-of-arrays: `[cx, cy, cz, radius]`, fitted lazily per sibling
/// group.
#[derive(Clone, Debug)]
pub struct SphereNodes {
    fitted: Bounds<4>,
}

/// Bounding spheres (SBV), 16-byte records.
#[derive(Clone, Copy, Debug, Default)]
pub struct Sphere;
impl sealed::Sealed for Sphere {}

#[inline]
fn fields(r: SphereNode) -> [f32; 4] {
    [r.center[0], r.center[1], r.center[2], r.radius]
}

/// The exact sphere of node `n`.
fn fit_node<S: Simd>(simd: S, tree: &RegionTree, p: &Points, n: usize) -> SphereNode {
    let run = p.soa().slice(tree.vert_run(n));
    let borrowed = tree.borrowed(n);
    let s1 = refit::sum_with(simd, run);
    let s2 = refit::sum_indexed_with(simd, p.soa(), borrowed);
    let inv = 1.0 / tree.vertex_count(n) as f32;
    let mut center = [0, 1, 2].map(|k| (s1[k] + s2[k]) * inv);
    if !center.iter().all(|c| c.is_finite()) {
        // The sum overflowed (coordinates near f32::MAX): any centre is correct, the
        // radius below bounds the region from it; take the box midpoint.
        let (lo, hi) = refit::merge_bounds(
            refit::bounds_with(simd, run),
            refit::bounds_indexed_with(simd, p.soa(), borrowed),
        );
        center = [0, 1, 2].map(|k| lo[k] * 0.5 + hi[k] * 0.5);
    }
    let d2 = refit::max_dist_sq_with(simd, run, center).max(refit::max_dist_sq_indexed_with(
        simd,
        p.soa(),
        borrowed,
        center,
    ));
    SphereNode {
        center,
        radius: exact_radius(p, center, conservative_radius(d2)),
    }
}

impl BoundingVolume for Sphere {
    const METHOD: Method = Method::Sphere;
    type Record = SphereNode;
    type Nodes = SphereNodes;
    type Block<'a> = overlap::SphereSoa<'a>;

    fn build(tree: &RegionTree, rest: &Points, _: &Options) -> SphereNodes {
        let mut nodes = SphereNodes {
            fitted: Bounds::new(tree),
        };
        super::refit_all::<Sphere>(&mut nodes, tree, rest, false);
        nodes
    }

    #[inline]
    fn group<'a, S: Simd>(
        simd: S,
        nodes: &'a SphereNodes,
        tree: &RegionTree,
        p: &Points,
        g: usize,
    ) -> (overlap::SphereSoa<'a>, bool) {
        let (tile, fitted) = nodes
            .fitted
            .group(tree, g, |n| fields(fit_node(simd, tree, p, n)));
        (overlap::SphereSoa::new(tile), fitted)
    }

    #[inline]
    fn group_current(nodes: &SphereNodes, g: usize) -> bool {
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

    fn fit<S: Simd>(
        simd: S,
        _: &SphereNodes,
        tree: &RegionTree,
        p: &Points,
        n: usize,
    ) -> SphereNode {
        fit_node(simd, tree, p, n)
    }

    fn record(nodes: &SphereNodes, tree: &RegionTree, n: usize) -> Option<SphereNode> {
        let [x, y, z, radius] = nodes.fitted.get(tree, n)?;
        Some(SphereNode {
            center: [x, y, z],
            radius,
        })
    }

    fn invalidate(nodes: &mut SphereNodes) {
        nodes.fitted.invalidate();
    }

    fn refit_all<S: Simd>(
        simd: S,
        nodes: &mut SphereNodes,
        tree: &RegionTree,
        p: &Points,
        bottom_up: bool,
    ) -> u64 {
        nodes.fitted.refit_all(tree, |n, child| {
            fields(if bottom_up && !tree.is_leaf(n) {
                merge(tree, n, child)
            } else {
                fit_node(simd, tree, p, n)
            })
        })
    }

    fn encloses(r: &SphereNode, _: &Points, point: [f64; 3]) -> bool {
        let rad = r.radius as f64;
        dist2_f64(r.center, point) <= rad * rad
    }

    type Swept = MovingBalls;
    type SweptBlock<'a> = overlap::MovingSphereSoa<'a>;

    fn swept(tree: &RegionTree) -> MovingBalls {
        MovingBalls::new(tree)
    }

    #[inline]
    fn swept_group<'a>(
        swept: &'a MovingBalls,
        _: &SphereNodes,
        tree: &RegionTree,
        step: &Step,
        g: usize,
    ) -> (overlap::MovingSphereSoa<'a>, bool) {
        swept::ball_group(swept, tree, step, g, |n| {
            (
                swept::mean(tree, &step.x0, n),
                swept::mean(tree, &step.x1, n),
            )
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

/// A sphere enclosing the (fitted) spheres of `n`'s children: centred at their mean.
fn merge(tree: &RegionTree, n: usize, child: &dyn Fn(usize) -> [f32; 4]) -> SphereNode {
    let children = tree.children(n);
    let inv = 1.0 / children.len() as f32;
    let mut center = [0.0f32; 3];
    for c in children.clone() {
        let cc = child(c);
        for k in 0..3 {
            center[k] += cc[k] * inv;
        }
    }
    if !center.iter().all(|c| c.is_finite()) {
        let first = child(children.start);
        center = [first[0], first[1], first[2]];
    }
    let mut radius = 0.0f32;
    for c in children {
        let [x, y, z, rc] = child(c);
        let d2 = (center[0] - x).powi(2) + (center[1] - y).powi(2) + (center[2] - z).powi(2);
        radius = radius.max(conservative_sum(conservative_radius(d2), rc));
    }
    SphereNode { center, radius }
}
