//! The queries: each one is an implementation of the walk engine's `Query` (a node test and
//! a leaf action), with its public entry points.
//!
//! - `contacts.rs`: exact intersecting triangle pairs ([`collide`], [`self_collide`]), and
//!   the split of that query into a broad phase (overlapping leaf pairs) and a narrow phase
//!   for calibration and benchmarks ([`crate::calibration`]);
//! - `proximity.rs`: every vertex-triangle and edge-edge pair within a distance
//!   ([`proximity`], [`self_proximity`]), with distances and closest sub-features;
//! - `ccd.rs`: continuous collision detection over a step ([`ccd_pair`], [`self_ccd`]): every
//!   vertex-triangle and edge-edge pair that touches during the step with its time of
//!   impact, or the earliest time, on the bounds of each region over the step;
//! - `features.rs`: the feature boxes and their SIMD culling that proximity and CCD share;
//! - `clearance.rs`: the proof that a node of a self query holds no feature pair within the
//!   query's distance, so that its walk is skipped (proximity and CCD).
//!
//! Queries on the current pose share `Posed`: two hierarchies' lazily fitted volumes and a
//! node test (`Overlap`, or `Within` a distance); they differ in the leaf action. CCD
//! implements the walk's `Query` itself, on the bounds over a step.

pub(crate) mod ccd;
pub(crate) mod clearance;
pub(crate) mod contacts;
mod features;
pub(crate) mod proximity;

pub use ccd::{
    ccd_pair, ccd_pair_with, self_ccd, self_ccd_with, CcdMode, CcdQuery, EdgeImpact, FaceImpact,
    Impacts, Motion, VertexImpact,
};
pub use contacts::{collide, collide_with, self_collide, self_collide_with, Contacts};
pub use proximity::{
    proximity, proximity_with, self_proximity, self_proximity_with, EdgePair, FaceVertex,
    Proximity, VertexFace,
};

use pulp::Simd;

use crate::bv::BoundingVolume;
use crate::counters::Counters;
use crate::hierarchy::Hierarchy;
use crate::tree::RegionTree;
use crate::walk::{Query, Side};

/// A node test on the volumes of the current pose.
pub(crate) trait NodeTest: Copy + Send + Sync {
    fn test<K: BoundingVolume, S: Simd>(
        self,
        simd: S,
        a: K::Block<'_>,
        i: usize,
        b: K::Block<'_>,
        n: usize,
    ) -> u32;
}

/// The volumes overlap (they share a point).
#[derive(Clone, Copy, Debug)]
pub(crate) struct Overlap;

impl NodeTest for Overlap {
    #[inline(always)]
    fn test<K: BoundingVolume, S: Simd>(
        self,
        simd: S,
        a: K::Block<'_>,
        i: usize,
        b: K::Block<'_>,
        n: usize,
    ) -> u32 {
        K::test(simd, a, i, b, n)
    }
}

/// The volumes come within a distance: `margin`, an `f32` at least the query's distance
/// (rounded up), by which entry `i`'s volume is grown ([`BoundingVolume::test_within`]).
#[derive(Clone, Copy, Debug)]
pub(crate) struct Within {
    pub(crate) margin: f32,
}

impl Within {
    /// The test for distance `d` (finite, `>= 0`): the least `f32` not below `d`.
    pub(crate) fn distance(d: f64) -> Self {
        let m = d as f32;
        let margin = if f64::from(m) < d { m.next_up() } else { m };
        Self { margin }
    }
}

impl NodeTest for Within {
    #[inline(always)]
    fn test<K: BoundingVolume, S: Simd>(
        self,
        simd: S,
        a: K::Block<'_>,
        i: usize,
        b: K::Block<'_>,
        n: usize,
    ) -> u32 {
        K::test_within(simd, a, i, b, n, self.margin)
    }
}

/// Two hierarchies in their current pose (one, on both sides, for a self query) and a node
/// test: everything a query on the current pose needs but its leaf action.
pub(crate) struct Posed<'h, K: BoundingVolume, T: NodeTest> {
    pub(crate) a: &'h Hierarchy<K>,
    pub(crate) b: &'h Hierarchy<K>,
    pub(crate) self_query: bool,
    pub(crate) node_test: T,
}

impl<'h, K: BoundingVolume, T: NodeTest> Posed<'h, K, T> {
    pub(crate) fn pair(a: &'h Hierarchy<K>, b: &'h Hierarchy<K>, node_test: T) -> Self {
        Self {
            a,
            b,
            self_query: false,
            node_test,
        }
    }

    pub(crate) fn single(h: &'h Hierarchy<K>, node_test: T) -> Self {
        Self {
            a: h,
            b: h,
            self_query: true,
            node_test,
        }
    }

    #[inline(always)]
    pub(crate) fn side(&self, side: Side) -> &'h Hierarchy<K> {
        match side {
            Side::A => self.a,
            Side::B => self.b,
        }
    }
}

/// The action a query on the current pose takes on an overlapping leaf pair.
pub(crate) trait LeafAction<'h, K: BoundingVolume>: Sync {
    type Out: Send;
    fn out(&self) -> Self::Out;
    fn leaf_pair<S: Simd, T: NodeTest>(
        &self,
        posed: &Posed<'h, K, T>,
        simd: S,
        x: usize,
        y: usize,
        counters: &mut Counters,
        out: &mut Self::Out,
    );
    fn merge(&self, out: &mut Self::Out, other: Self::Out);
    /// See [`Query::clear`].
    #[inline(always)]
    fn clear<T: NodeTest>(&self, _posed: &Posed<'h, K, T>, _x: usize) -> bool {
        false
    }
    /// See [`Query::stopped`].
    #[inline(always)]
    fn stopped(&self, _poll: bool) -> bool {
        false
    }
}

/// A query on the current pose: [`Posed`] plus a [`LeafAction`].
pub(crate) struct PosedQuery<'h, K: BoundingVolume, T: NodeTest, L> {
    pub(crate) posed: Posed<'h, K, T>,
    pub(crate) action: L,
}

impl<'h, K: BoundingVolume, T: NodeTest, L: LeafAction<'h, K>> Query for PosedQuery<'h, K, T, L> {
    type Block = K::Block<'h>;
    type Out = L::Out;

    #[inline(always)]
    fn tree(&self, side: Side) -> &RegionTree {
        self.posed.side(side).tree()
    }

    #[inline(always)]
    fn is_self(&self) -> bool {
        self.posed.self_query
    }

    fn out(&self) -> L::Out {
        self.action.out()
    }

    #[inline(always)]
    fn group<S: Simd>(&self, simd: S, side: Side, g: usize) -> (K::Block<'h>, bool) {
        self.posed.side(side).group(simd, g)
    }

    #[inline(always)]
    fn test<S: Simd>(&self, simd: S, a: Self::Block, i: usize, b: Self::Block, n: usize) -> u32 {
        self.posed.node_test.test::<K, S>(simd, a, i, b, n)
    }

    #[inline(always)]
    fn extent(&self, block: Self::Block, i: usize) -> f32 {
        K::extent(block, i)
    }

    #[inline(always)]
    fn leaf_pair<S: Simd>(
        &self,
        simd: S,
        x: usize,
        y: usize,
        counters: &mut Counters,
        out: &mut L::Out,
    ) {
        self.action
            .leaf_pair(&self.posed, simd, x, y, counters, out)
    }

    fn merge(&self, out: &mut L::Out, other: L::Out) {
        self.action.merge(out, other)
    }

    #[inline(always)]
    fn clear(&self, x: usize) -> bool {
        self.action.clear(&self.posed, x)
    }

    #[inline(always)]
    fn stopped(&self, poll: bool) -> bool {
        self.action.stopped(poll)
    }
}
