//! Axis-aligned bounding boxes: min/max over the region's vertices (exact in f32).

use super::swept::{self, Step};
use super::{sealed, BoundingVolume, Bounds, Method};
use crate::options::Options;
use crate::points::Points;
use crate::tree::RegionTree;
use dhcd_kernels::{overlap, refit};
use pulp::Simd;

/// The box node record: min and max corners — 24 bytes.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct AabbNode {
    /// Least corner.
    pub min: [f32; 3],
    /// Greatest corner.
    pub max: [f32; 3],
}
const _: () = assert!(std::mem::size_of::<AabbNode>() == 24);

/// Box nodes, structure-of-arrays: `[min_x, min_y, min_z, max_x, max_y, max_z]`, fitted
/// lazily per sibling group.
#[derive(Clone, Debug)]
pub struct AabbNodes {
    fitted: Bounds<6>,
}

/// Axis-aligned bounding boxes (AABB), 24-byte records.
#[derive(Clone, Copy, Debug, Default)]
pub struct Aabb;
impl sealed::Sealed for Aabb {}

#[inline]
fn fields(r: AabbNode) -> [f32; 6] {
    [r.min[0], r.min[1], r.min[2], r.max[0], r.max[1], r.max[2]]
}

fn fit_node<S: Simd>(simd: S, tree: &RegionTree, p: &Points, n: usize) -> AabbNode {
    let (min, max) = refit::merge_bounds(
        refit::bounds_with(simd, p.soa().slice(tree.vert_run(n))),
        refit::bounds_indexed_with(simd, p.soa(), tree.borrowed(n)),
    );
    if p.is_rounded() {
        // An exact coordinate lies within half an ulp of its nearest f32, so beyond the next
        // f32 outward of no rounded one.
        return AabbNode {
            min: min.map(f32::next_down),
            max: max.map(f32::next_up),
        };
    }
    AabbNode { min, max }
}

impl BoundingVolume for Aabb {
    const METHOD: Method = Method::Aabb;
    type Record = AabbNode;
    type Nodes = AabbNodes;
    type Block<'a> = overlap::AabbSoa<'a>;

    fn build(tree: &RegionTree, rest: &Points, _: &Options) -> AabbNodes {
        let mut nodes = AabbNodes {
            fitted: Bounds::new(tree),
        };
        super::refit_all::<Aabb>(&mut nodes, tree, rest, false);
        nodes
    }

    #[inline]
    fn group<'a, S: Simd>(
        simd: S,
        nodes: &'a AabbNodes,
        tree: &RegionTree,
        p: &Points,
        g: usize,
    ) -> (overlap::AabbSoa<'a>, bool) {
        let (tile, fitted) = nodes
            .fitted
            .group(tree, g, |n| fields(fit_node(simd, tree, p, n)));
        (overlap::AabbSoa::new(tile), fitted)
    }

    #[inline]
    fn group_current(nodes: &AabbNodes, g: usize) -> bool {
        nodes.fitted.is_current(g)
    }

    #[inline(always)]
    fn test<S: pulp::Simd>(
        simd: S,
        a: overlap::AabbSoa<'_>,
        i: usize,
        b: overlap::AabbSoa<'_>,
        n: usize,
    ) -> u32 {
        let (lo, hi) = a.get(i);
        overlap::aabb_block_with(simd, lo, hi, b, n)
    }

    #[inline(always)]
    fn test_within<S: pulp::Simd>(
        simd: S,
        a: overlap::AabbSoa<'_>,
        i: usize,
        b: overlap::AabbSoa<'_>,
        n: usize,
        margin: f32,
    ) -> u32 {
        // Grown and rounded outward: a box within `margin` along every axis still meets it.
        let (lo, hi) = a.get(i);
        let lo = lo.map(|x| (x - margin).next_down());
        let hi = hi.map(|x| (x + margin).next_up());
        overlap::aabb_block_with(simd, lo, hi, b, n)
    }

    /// Half the box's perimeter (sum of the extents).
    #[inline(always)]
    fn extent(a: overlap::AabbSoa<'_>, i: usize) -> f32 {
        (a.max(0)[i] - a.min(0)[i]) + (a.max(1)[i] - a.min(1)[i]) + (a.max(2)[i] - a.min(2)[i])
    }

    fn fit<S: Simd>(simd: S, _: &AabbNodes, tree: &RegionTree, p: &Points, n: usize) -> AabbNode {
        fit_node(simd, tree, p, n)
    }

    fn record(nodes: &AabbNodes, tree: &RegionTree, n: usize) -> Option<AabbNode> {
        let f = nodes.fitted.get(tree, n)?;
        Some(AabbNode {
            min: [f[0], f[1], f[2]],
            max: [f[3], f[4], f[5]],
        })
    }

    fn invalidate(nodes: &mut AabbNodes) {
        nodes.fitted.invalidate();
    }

    fn refit_all<S: Simd>(
        simd: S,
        nodes: &mut AabbNodes,
        tree: &RegionTree,
        p: &Points,
        bottom_up: bool,
    ) -> u64 {
        nodes.fitted.refit_all(tree, |n, child| {
            if bottom_up && !tree.is_leaf(n) {
                let mut b = refit::EMPTY_BOUNDS;
                for c in tree.children(n) {
                    let f = child(c);
                    b = refit::merge_bounds(b, ([f[0], f[1], f[2]], [f[3], f[4], f[5]]));
                }
                fields(AabbNode { min: b.0, max: b.1 })
            } else {
                fields(fit_node(simd, tree, p, n))
            }
        })
    }

    fn encloses(r: &AabbNode, _: &Points, q: [f64; 3]) -> bool {
        (0..3).all(|k| f64::from(r.min[k]) <= q[k] && q[k] <= f64::from(r.max[k]))
    }

    type Swept = Bounds<6>;
    type SweptBlock<'a> = overlap::AabbSoa<'a>;

    fn swept(tree: &RegionTree) -> Bounds<6> {
        Bounds::new(tree)
    }

    #[inline]
    fn swept_group<'a>(
        swept: &'a Bounds<6>,
        _: &AabbNodes,
        tree: &RegionTree,
        step: &Step,
        g: usize,
    ) -> (overlap::AabbSoa<'a>, bool) {
        let (tile, fitted) = swept.group(tree, g, |n| swept::box_over_step(tree, step, n));
        (overlap::AabbSoa::new(tile), fitted)
    }

    #[inline(always)]
    fn swept_test<S: pulp::Simd>(
        simd: S,
        a: overlap::AabbSoa<'_>,
        i: usize,
        b: overlap::AabbSoa<'_>,
        n: usize,
        margin: f64,
    ) -> u32 {
        if margin == 0.0 {
            Aabb::test(simd, a, i, b, n)
        } else {
            Aabb::test_within(simd, a, i, b, n, swept::f32_up(margin))
        }
    }

    #[inline(always)]
    fn swept_extent(a: overlap::AabbSoa<'_>, i: usize) -> f32 {
        Aabb::extent(a, i)
    }

    fn swept_encloses(
        swept: &Bounds<6>,
        tree: &RegionTree,
        n: usize,
        _: f64,
        point: [f64; 3],
    ) -> Option<bool> {
        Some(swept::box_encloses(swept.get(tree, n)?, point))
    }
}
