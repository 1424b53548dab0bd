//! The three methods over one region tree: Distance Hierarchy (`Dh`), spheres
//! (`Sphere`, the paper's SBV) and axis-aligned boxes (`Aabb`).
//!
//! The method is a compile-time policy ([`BoundingVolume`]); node data lives in structure-of-arrays
//! buffers (one array per record field) whose sibling groups are contiguous, so one SIMD
//! load covers the children of a node. [`Method`] names a method where it is chosen at run
//! time; every method is a row of the table in `src/methods.rs`.

mod aabb;
mod bounds;
mod central;
mod dh;
mod sphere;
pub(crate) mod swept;

pub(crate) use bounds::Bounds;

pub use aabb::Aabb;
#[doc(hidden)]
pub use aabb::{AabbNode, AabbNodes};
pub use dh::Dh;
#[doc(hidden)]
pub use dh::{DhNode, DhNodes};
pub use sphere::Sphere;
#[doc(hidden)]
pub use sphere::{SphereNode, SphereNodes};

pub use crate::methods::Method;

use crate::options::Options;
use crate::points::Points;
use crate::tree::RegionTree;
use swept::Step;

/// Relative inflation of every computed radius. Radii and overlap tests are evaluated in
/// f32; each is off by a few ulps. Growing radii by 16 ulps keeps every sphere test
/// conservative: two regions that share a point always test as overlapping.
const RADIUS_INFLATION: f32 = 1.0 + 16.0 * f32::EPSILON;

/// Smallest radius. Below about 1e-18 squared distances leave f32's normal range and lose
/// their relative precision (a computed `d2` under 1e-36 only proves the distance is under
/// sqrt(3) * 1e-18), so radii are floored here: regions smaller than that are treated as
/// this size, which costs culling only on absurdly tiny meshes and never an answer.
const MIN_RADIUS: f32 = 2e-18;

/// A radius that encloses a point at squared distance `d2` despite rounding in `d2`.
/// Overflow is conservative too: `d2 = inf` gives an infinite radius.
#[inline]
pub(crate) fn conservative_radius(d2: f32) -> f32 {
    (d2.sqrt() * RADIUS_INFLATION).max(MIN_RADIUS)
}

/// Rounds a sum of distances up the same way (bottom-up bounds).
#[inline]
pub(crate) fn conservative_sum(a: f32, b: f32) -> f32 {
    ((a + b) * RADIUS_INFLATION).max(MIN_RADIUS)
}

/// A radius fitted around `center` from `p`'s `f32` points, grown when they are roundings
/// of `f64` positions by how far an exact point may lie from its rounding (the region lies
/// within `radius` of the centre, so its coordinates within `|center|_inf + radius`).
#[inline]
pub(crate) fn exact_radius(p: &Points, center: [f32; 3], radius: f32) -> f32 {
    if !p.is_rounded() {
        return radius;
    }
    let magnitude = center[0].abs().max(center[1].abs()).max(center[2].abs()) + radius;
    conservative_sum(radius, p.rounding_slack(magnitude))
}

mod sealed {
    /// Only the methods of this crate implement [`super::BoundingVolume`].
    pub trait Sealed {}
}

/// A method as a type: its node record, its SoA buffers, how to fit a node to the current
/// pose, and the wide overlap test. Sealed: the methods are the rows of the table in
/// `src/methods.rs`, the set the library compares; everything generic over them is
/// monomorphised (no per-node dispatch).
///
/// Node bounds live in `LazyTiles` buffers grouped by *sibling group* (the children of one
/// node): a group is fitted as a whole, just before its first
/// test in a step, by whichever thread needs it first. A wide test reads one node of a
/// fitted group against a block of another fitted group.
pub trait BoundingVolume:
    sealed::Sealed + Copy + Default + Send + Sync + std::fmt::Debug + 'static
{
    /// The method's row in the table of methods.
    const METHOD: Method;
    /// One node as a plain record (`#[repr(C)]`, Pod; size pinned at compile time).
    type Record: bytemuck::Pod + std::fmt::Debug + PartialEq + Send + Sync;
    /// All nodes of one hierarchy, structure-of-arrays.
    #[doc(hidden)]
    type Nodes: Clone + std::fmt::Debug + Send + Sync;
    /// The fitted bounds of one sibling group, as the overlap kernels read them.
    #[doc(hidden)]
    type Block<'a>: Copy;

    /// Allocates the buffers and fits every node to the rest pose `rest` (all current);
    /// `options` say how (e.g. [`Options::central`] for DH).
    #[doc(hidden)]
    fn build(tree: &RegionTree, rest: &Points, options: &Options) -> Self::Nodes;
    /// The bounds of sibling group `g`, fitting the group exactly to the current pose `p`
    /// first if it is stale (once per step, whichever thread asks first), with the refit
    /// kernels on the backend `simd` (the caller's: a walk dispatches once). Returns the
    /// block and whether this call fitted it.
    #[doc(hidden)]
    fn group<'a, S: pulp::Simd>(
        simd: S,
        nodes: &'a Self::Nodes,
        tree: &RegionTree,
        p: &Points,
        g: usize,
    ) -> (Self::Block<'a>, bool);
    /// Whether sibling group `g` is fitted to the current pose.
    #[doc(hidden)]
    fn group_current(nodes: &Self::Nodes, g: usize) -> bool;
    /// Overlap bits of entry `i` of block `a` against the first `n` entries of block `b`.
    /// Symmetric in the two volumes.
    #[doc(hidden)]
    fn test<S: pulp::Simd>(
        simd: S,
        a: Self::Block<'_>,
        i: usize,
        b: Self::Block<'_>,
        n: usize,
    ) -> u32;
    /// [`BoundingVolume::test`] with entry `i`'s volume grown by `margin` (finite, `>= 0`), rounded
    /// outward: the bits of every entry of `b` whose volume comes within `margin` of it.
    #[doc(hidden)]
    fn test_within<S: pulp::Simd>(
        simd: S,
        a: Self::Block<'_>,
        i: usize,
        b: Self::Block<'_>,
        n: usize,
        margin: f32,
    ) -> u32;
    /// A size of entry `i` of a block, to descend the larger volume of an overlapping pair.
    #[doc(hidden)]
    fn extent(a: Self::Block<'_>, i: usize) -> f32;
    /// The exact bounding volume of node `n` for the current positions `p` (reads the
    /// node's vertices), with the refit kernels on the backend `simd`.
    #[doc(hidden)]
    fn fit<S: pulp::Simd>(
        simd: S,
        nodes: &Self::Nodes,
        tree: &RegionTree,
        p: &Points,
        n: usize,
    ) -> Self::Record;
    /// Node `n`'s record if its group is current.
    #[doc(hidden)]
    fn record(nodes: &Self::Nodes, tree: &RegionTree, n: usize) -> Option<Self::Record>;
    /// Makes every node stale (a new step).
    #[doc(hidden)]
    fn invalidate(nodes: &mut Self::Nodes);
    /// Fits every stale group now: exactly, or bottom-up (leaves exactly, each internal node
    /// as a bound of its children's volumes: for DH `r_p = max_c(|C_p - C_c| + r_c)`).
    /// Returns the number of nodes fitted. The refit kernels run on the backend `simd`
    /// (the crate dispatches once for the whole refit).
    #[doc(hidden)]
    fn refit_all<S: pulp::Simd>(
        simd: S,
        nodes: &mut Self::Nodes,
        tree: &RegionTree,
        p: &Points,
        bottom_up: bool,
    ) -> u64;
    /// Whether record `r` (its centres read from `p`) encloses `point` (checked in f64; for
    /// validation).
    #[doc(hidden)]
    fn encloses(r: &Self::Record, p: &Points, point: [f64; 3]) -> bool;

    /// Every node's bound over a step (see `src/bv/swept.rs`), fitted lazily per sibling
    /// group.
    #[doc(hidden)]
    type Swept: Send + Sync;
    /// One sibling group's bounds over a step, as the swept node test reads them.
    #[doc(hidden)]
    type SweptBlock<'a>: Copy;
    /// Unfitted bounds over a step for the nodes of `tree`.
    #[doc(hidden)]
    fn swept(tree: &RegionTree) -> Self::Swept;
    /// The bounds over `step` of sibling group `g`, fitted first if stale; whether this call
    /// fitted it. `nodes` are the hierarchy's (DH reads its central vertices).
    #[doc(hidden)]
    fn swept_group<'a>(
        swept: &'a Self::Swept,
        nodes: &Self::Nodes,
        tree: &RegionTree,
        step: &Step,
        g: usize,
    ) -> (Self::SweptBlock<'a>, bool);
    /// Bits of the first `n` entries of `b` whose bound comes within `margin` (finite,
    /// `>= 0`) of entry `i`'s at some time of the step; conservative, symmetric.
    #[doc(hidden)]
    fn swept_test<S: pulp::Simd>(
        simd: S,
        a: Self::SweptBlock<'_>,
        i: usize,
        b: Self::SweptBlock<'_>,
        n: usize,
        margin: f64,
    ) -> u32;
    /// A size of entry `i` of a swept block, to descend the larger bound of a pair.
    #[doc(hidden)]
    fn swept_extent(a: Self::SweptBlock<'_>, i: usize) -> f32;
    /// Whether node `n`'s fitted bound over the step encloses `point` at time `t` (checked
    /// in f64, for validation); `None` if its group is not fitted.
    #[doc(hidden)]
    fn swept_encloses(
        swept: &Self::Swept,
        tree: &RegionTree,
        n: usize,
        t: f64,
        point: [f64; 3],
    ) -> Option<bool>;
}

/// [`BoundingVolume::refit_all`] on the runtime-detected backend, dispatched once for the whole
/// refit.
pub(crate) fn refit_all<K: BoundingVolume>(
    nodes: &mut K::Nodes,
    tree: &RegionTree,
    p: &Points,
    bottom_up: bool,
) -> u64 {
    struct Op<'a, K: BoundingVolume> {
        nodes: &'a mut K::Nodes,
        tree: &'a RegionTree,
        p: &'a Points,
        bottom_up: bool,
    }
    impl<K: BoundingVolume> pulp::WithSimd for Op<'_, K> {
        type Output = u64;
        #[inline(always)]
        fn with_simd<S: pulp::Simd>(self, simd: S) -> u64 {
            K::refit_all(simd, self.nodes, self.tree, self.p, self.bottom_up)
        }
    }
    dhcd_kernels::arch().dispatch(Op::<K> {
        nodes,
        tree,
        p,
        bottom_up,
    })
}

#[inline]
pub(crate) fn dist2_f64(a: [f32; 3], b: [f64; 3]) -> f64 {
    (0..3)
        .map(|k| {
            let d = a[k] as f64 - b[k];
            d * d
        })
        .sum()
}
