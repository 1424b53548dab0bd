//! Axis-aligned bounding boxes: min/max over the region's vertices (exact in f32).

use super::{group_buffers, refit_groups, sealed, slot, BvKind, Method};
use crate::points::Points;
use crate::tree::RegionTree;
use dhcd_kernels::lazy::LazySoa;
use dhcd_kernels::{overlap, refit};

/// The box node record: min and max corners — 24 bytes.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct AabbNode {
    pub min: [f32; 3],
    pub max: [f32; 3],
}
const _: () = assert!(std::mem::size_of::<AabbNode>() == 24);

/// Box nodes, structure-of-arrays: `[min_x, min_y, min_z, max_x, max_y, max_z]`, fitted
/// lazily per sibling group. Unfitted entries are empty boxes (min = +inf, max = -inf).
#[derive(Clone, Debug)]
pub struct AabbNodes {
    fitted: LazySoa<6>,
}

#[derive(Clone, Copy, Debug, Default)]
pub struct Aabb;
impl sealed::Sealed for Aabb {}

#[inline]
fn write(fields: &mut [&mut [f32]; 6], i: usize, r: AabbNode) {
    for k in 0..3 {
        fields[k][i] = r.min[k];
        fields[3 + k][i] = r.max[k];
    }
}

fn fit_node(tree: &RegionTree, p: &Points, n: usize) -> AabbNode {
    let (min, max) = refit::merge_bounds(
        refit::bounds(p.soa().slice(tree.vert_run(n))),
        refit::bounds_indexed(p.soa(), tree.borrowed(n)),
    );
    AabbNode { min, max }
}

impl BvKind for Aabb {
    const METHOD: Method = Method::Aabb;
    type Record = AabbNode;
    type Nodes = AabbNodes;
    type Block<'a> = overlap::AabbSoa<'a>;

    fn build(tree: &RegionTree, rest: &Points) -> AabbNodes {
        let (inf, ninf) = (f32::INFINITY, f32::NEG_INFINITY);
        let mut nodes = AabbNodes {
            fitted: group_buffers(tree, [inf, inf, inf, ninf, ninf, ninf]),
        };
        Aabb::refit_all(&mut nodes, tree, rest, false);
        nodes
    }

    #[inline]
    fn group<'a>(
        nodes: &'a AabbNodes,
        tree: &RegionTree,
        p: &Points,
        g: usize,
    ) -> (overlap::AabbSoa<'a>, bool) {
        let (f, fitted) = nodes.fitted.get_or_fill(g, |_, mut fields| {
            for (i, n) in tree.group_nodes(g).enumerate() {
                write(&mut fields, i, fit_node(tree, p, n));
            }
        });
        let [min_x, min_y, min_z, max_x, max_y, max_z] = f;
        (
            overlap::AabbSoa {
                min_x,
                min_y,
                min_z,
                max_x,
                max_y,
                max_z,
            },
            fitted,
        )
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

    /// Half the box's perimeter (sum of the extents).
    #[inline(always)]
    fn extent(a: overlap::AabbSoa<'_>, i: usize) -> f32 {
        (a.max_x[i] - a.min_x[i]) + (a.max_y[i] - a.min_y[i]) + (a.max_z[i] - a.min_z[i])
    }

    fn fit(_: &AabbNodes, tree: &RegionTree, p: &Points, n: usize) -> AabbNode {
        fit_node(tree, p, n)
    }

    fn record(nodes: &AabbNodes, tree: &RegionTree, n: usize) -> Option<AabbNode> {
        let g = tree.group_of(n);
        let f = nodes.fitted.get(g)?;
        let i = n - tree.group_nodes(g).start;
        Some(AabbNode {
            min: [f[0][i], f[1][i], f[2][i]],
            max: [f[3][i], f[4][i], f[5][i]],
        })
    }

    fn invalidate(nodes: &mut AabbNodes) {
        nodes.fitted.invalidate();
    }

    fn refit_all(nodes: &mut AabbNodes, tree: &RegionTree, p: &Points, bottom_up: bool) -> u64 {
        refit_groups(&mut nodes.fitted, tree, |f, n, s| {
            let r = if bottom_up && !tree.is_leaf(n) {
                let mut b = refit::EMPTY_BOUNDS;
                for c in tree.children(n) {
                    let c = slot(tree, c);
                    let child = ([f[0][c], f[1][c], f[2][c]], [f[3][c], f[4][c], f[5][c]]);
                    b = refit::merge_bounds(b, child);
                }
                AabbNode { min: b.0, max: b.1 }
            } else {
                fit_node(tree, p, n)
            };
            write(f, s, r);
        })
    }

    fn encloses(r: &AabbNode, p: &Points, v: usize) -> bool {
        let q = p.get(v);
        (0..3).all(|k| r.min[k] <= q[k] && q[k] <= r.max[k])
    }
}
