//! The three bounding-volume kinds over one region tree: Distance Hierarchy (`Dh`), spheres
//! (`Sphere`, the paper's SBV) and axis-aligned boxes (`Aabb`).
//!
//! The kind is a compile-time policy ([`BvKind`]); node data lives in structure-of-arrays
//! buffers (one array per record field, padded to [`PAD`] entries) so that one SIMD load
//! covers a block of nodes. [`Method`] names a kind where it is chosen at run time; every
//! kind is a row of the table in [`crate::kinds`].

mod aabb;
mod dh;
mod sphere;

pub use aabb::{Aabb, AabbNode, AabbNodes};
pub use dh::{Dh, DhNode, DhNodes};
pub use sphere::{Sphere, SphereNode, SphereNodes};

pub use crate::kinds::Method;

use crate::points::Points;
use crate::tree::RegionTree;

/// Node buffers are padded to a multiple of this many entries (the widest SIMD block:
/// 16 f32 lanes of AVX-512). Padding entries never overlap anything.
pub const PAD: usize = 16;

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

pub(crate) fn padded(n: usize) -> usize {
    n.div_ceil(PAD).max(1) * PAD
}

mod sealed {
    pub trait Sealed {}
}

/// A bounding-volume kind: its node record, its SoA buffers, how to fit a node to the
/// current pose, and the batch overlap test. Sealed: the kinds are the rows of the table in
/// [`crate::kinds`], the set the library compares.
pub trait BvKind:
    sealed::Sealed + Copy + Default + Send + Sync + std::fmt::Debug + 'static
{
    const METHOD: Method;
    /// One node as a plain record (`#[repr(C)]`, Pod; size pinned at compile time).
    type Record: bytemuck::Pod + std::fmt::Debug + PartialEq + Send + Sync;
    /// All nodes of one hierarchy, structure-of-arrays.
    type Nodes: Clone + std::fmt::Debug + Send + Sync;

    /// Allocates the buffers and fits every node to the rest pose `rest`.
    fn build(tree: &RegionTree, rest: &Points) -> Self::Nodes;
    /// The tight BV of node `n` for the current positions `p` (reads the node's vertices).
    fn fit(nodes: &Self::Nodes, tree: &RegionTree, p: &Points, n: usize) -> Self::Record;
    /// A BV of internal node `n` that encloses its children's current BVs (bottom-up refit).
    fn merge(nodes: &Self::Nodes, tree: &RegionTree, p: &Points, n: usize) -> Self::Record;
    fn get(nodes: &Self::Nodes, n: usize) -> Self::Record;
    fn set(nodes: &mut Self::Nodes, n: usize, r: Self::Record);
    /// Called right after node `n` is fitted to the current positions `p`: a kind may stage
    /// data its overlap test derives from the pose (DH copies its centre's live position, so
    /// the test reads one array instead of chasing the vertex index). Default: nothing.
    #[inline]
    fn stage(_nodes: &mut Self::Nodes, _p: &Points, _n: usize) {}
    /// Batch overlap test of node pairs `(ia[k], ib[k])`; writes `out[k]` (1 = overlap) and
    /// returns the number of overlapping pairs.
    #[allow(clippy::too_many_arguments)]
    fn overlap(
        a: &Self::Nodes,
        pa: &Points,
        b: &Self::Nodes,
        pb: &Points,
        ia: &[u32],
        ib: &[u32],
        out: &mut [u32],
    ) -> usize;
    /// Whether record `r` encloses point `v` of `p` (checked in f64; for validation).
    fn encloses(r: &Self::Record, p: &Points, v: usize) -> bool;
}

#[inline]
pub(crate) fn dist2_f64(a: [f32; 3], b: [f32; 3]) -> f64 {
    (0..3)
        .map(|k| {
            let d = a[k] as f64 - b[k] as f64;
            d * d
        })
        .sum()
}
