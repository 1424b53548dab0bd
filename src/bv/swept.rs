//! Bounds of every region over a step, for continuous collision detection.
//!
//! Over a step every vertex moves on the straight line `x(t) = x0 + t (x1 - x0)`,
//! `t` in `[0, 1]`. Each method bounds a region over the whole step, on the same region tree
//! as its bounds of a pose:
//!
//! - **AABB**: the union of the region's boxes at t0 and t1. Every coordinate of a point is
//!   linear in t, so it stays between its end values. Six `f32` (24 bytes), rounded outward
//!   from the `f64` positions.
//! - **DH**: the *moving ball* around the central vertex. With `c(t)` the central vertex's
//!   own motion and `r0`, `r1` the region's DH radii at t0 and t1, every region vertex
//!   satisfies `|v(t) - c(t)| = |(1 - t)(v0 - c0) + t (v1 - c1)| <= (1 - t) r0 + t r1` (the
//!   triangle inequality), so the region lies in the ball `(c(t), (1 - t) r0 + t r1)` for
//!   all t. The record is the central vertex (fixed at build) and the two radii: 12 bytes;
//!   the lazily fitted tile also stages both centres, in `f64`, so the test reads contiguous
//!   arrays (64 bytes of scratch per node).
//! - **Sphere**: the same moving ball with the sphere method's own centres, the means of the
//!   region at t0 and at t1. Any two centres work (the argument above needs only that the
//!   centre moves linearly); the means keep the radii those of the sphere hierarchy.
//!   Record: two centres and two radii, 32 bytes in `f32`; staged as the DH tile.
//!
//! Two moving balls meet during the step iff `|c_a(t) - c_b(t)| <= r_a(t) + r_b(t)` for some
//! t in `[0, 1]`, a quadratic inequality in t ([`dhcd_kernels::reference::moving_spheres_meet`],
//! one SIMD block test per sibling group as for the bounds of a pose).
//!
//! Radii are computed in `f64` from the `f64` positions and rounded up by a bound on their
//! rounding error, so every bound is conservative for the positions as given.
//!
//! (`pub` items of a private module: they appear in the sealed [`super::BoundingVolume`]'s
//! signatures and are not nameable outside the crate.)

use super::Bounds;
use crate::tree::RegionTree;
use dhcd_kernels::overlap::{MovingSphere, MovingSphereSoa, MOVING_SPHERE_FIELDS};

/// A step's positions at t0 and t1, in the hierarchy's internal vertex order.
#[derive(Clone, Debug, Default)]
pub struct Step {
    pub(crate) x0: Vec<[f64; 3]>,
    pub(crate) x1: Vec<[f64; 3]>,
}

impl Step {
    /// A step without motion: `x` (internal order) at t0 and at t1.
    pub(crate) fn still(x: Vec<[f64; 3]>) -> Self {
        Self {
            x0: x.clone(),
            x1: x,
        }
    }

    /// The positions `x0`, `x1` (caller's order, checked) gathered into internal order.
    pub(crate) fn gather(tree: &RegionTree, x0: &[[f64; 3]], x1: &[[f64; 3]]) -> Self {
        let order = tree.vert_order();
        Self {
            x0: order.iter().map(|&o| x0[o as usize]).collect(),
            x1: order.iter().map(|&o| x1[o as usize]).collect(),
        }
    }
}

/// The largest `f32` not above `x`.
#[inline]
pub(crate) fn f32_down(x: f64) -> f32 {
    let y = x as f32;
    if f64::from(y) > x {
        y.next_down()
    } else {
        y
    }
}

/// The least `f32` not below `x`.
#[inline]
pub(crate) fn f32_up(x: f64) -> f32 {
    let y = x as f32;
    if f64::from(y) < x {
        y.next_up()
    } else {
        y
    }
}

/// Grows the box `[lo, hi]` to hold `q`. Plain comparisons, not `f64::min`/`max`: the
/// points are finite (checked on input), and the NaN handling of those costs more than the
/// comparison.
#[inline(always)]
pub(crate) fn widen(lo: &mut [f64; 3], hi: &mut [f64; 3], q: &[f64; 3]) {
    for k in 0..3 {
        if q[k] < lo[k] {
            lo[k] = q[k];
        }
        if q[k] > hi[k] {
            hi[k] = q[k];
        }
    }
}

/// Node `n`'s box over the step: `[lo xyz, hi xyz]` of every region vertex at t0 and t1,
/// rounded outward to `f32`.
pub(crate) fn box_over_step(tree: &RegionTree, step: &Step, n: usize) -> [f32; 6] {
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    for v in tree.region_vertices(n) {
        widen(&mut lo, &mut hi, &step.x0[v as usize]);
        widen(&mut lo, &mut hi, &step.x1[v as usize]);
    }
    [
        f32_down(lo[0]),
        f32_down(lo[1]),
        f32_down(lo[2]),
        f32_up(hi[0]),
        f32_up(hi[1]),
        f32_up(hi[2]),
    ]
}

/// Relative rounding bound of a computed distance: three products, two sums and a square
/// root, each within `2^-53`, are far inside `2^-48`.
const DISTANCE_REL: f64 = 1.0 + 1.0 / (1u64 << 48) as f64;
/// Absolute term for underflow: squares of differences below `2^-537` underflow; a
/// distance computed as 0 is then below `sqrt(3) 2^-537`.
const DISTANCE_TINY: f64 = f64::from_bits((1023 - 500) << 52);

/// A radius at least `sqrt(d2_max)` for a computed largest squared distance.
#[inline]
fn conservative_radius_f64(d2_max: f64) -> f64 {
    (d2_max.sqrt() * DISTANCE_REL).next_up() + DISTANCE_TINY
}

/// The largest distance from `c` to node `n`'s region vertices in `pos`, rounded up.
pub(crate) fn radius_around(tree: &RegionTree, pos: &[[f64; 3]], n: usize, c: [f64; 3]) -> f64 {
    let mut d2 = 0.0f64;
    for v in tree.region_vertices(n) {
        let p = pos[v as usize];
        let (x, y, z) = (p[0] - c[0], p[1] - c[1], p[2] - c[2]);
        d2 = d2.max(x * x + y * y + z * z);
    }
    conservative_radius_f64(d2)
}

/// The mean of node `n`'s region vertices in `pos` (any point would do as a centre: the
/// radius is measured from the value returned).
pub(crate) fn mean(tree: &RegionTree, pos: &[[f64; 3]], n: usize) -> [f64; 3] {
    let mut s = [0.0f64; 3];
    let mut count = 0usize;
    for v in tree.region_vertices(n) {
        let p = pos[v as usize];
        for k in 0..3 {
            s[k] += p[k];
        }
        count += 1;
    }
    let inv = 1.0 / count.max(1) as f64;
    s.map(|x| x * inv)
}

/// Moving balls, one per node, fitted lazily per sibling group: `c0 xyz, r0, c1 xyz, r1`.
pub(crate) type MovingBalls = Bounds<MOVING_SPHERE_FIELDS, f64>;

/// The fields of a moving ball, in [`MovingSphereSoa`] order.
#[inline]
pub(crate) fn ball_fields(c0: [f64; 3], r0: f64, c1: [f64; 3], r1: f64) -> [f64; 8] {
    [c0[0], c0[1], c0[2], r0, c1[0], c1[1], c1[2], r1]
}

/// Group `g`'s moving balls, fitted first with `centres(n) = (c0, c1)` and the radii about
/// them if stale.
#[inline]
pub(crate) fn ball_group<'a>(
    balls: &'a MovingBalls,
    tree: &RegionTree,
    step: &Step,
    g: usize,
    centres: impl Fn(usize) -> ([f64; 3], [f64; 3]),
) -> (MovingSphereSoa<'a>, bool) {
    let (data, stride, fitted) = balls.group_data(tree, g, |n| {
        let (c0, c1) = centres(n);
        let r0 = radius_around(tree, &step.x0, n, c0);
        let r1 = radius_around(tree, &step.x1, n, c1);
        ball_fields(c0, r0, c1, r1)
    });
    (MovingSphereSoa::new(data, stride), fitted)
}

/// The moving-ball test of entry `i` of `a` against the first `n` of `b`, entry `i` grown by
/// `margin` (rounded up).
#[inline(always)]
pub(crate) fn balls_test<S: pulp::Simd>(
    simd: S,
    a: MovingSphereSoa<'_>,
    i: usize,
    b: MovingSphereSoa<'_>,
    n: usize,
    margin: f64,
) -> u32 {
    let mut p = a.get(i);
    if margin > 0.0 {
        p.r0 = (p.r0 + margin).next_up();
        p.r1 = (p.r1 + margin).next_up();
    }
    dhcd_kernels::overlap::moving_sphere_block_with(simd, &p, b, n)
}

/// The larger end radius of entry `i`, as an `f32` extent.
#[inline(always)]
pub(crate) fn ball_extent(a: MovingSphereSoa<'_>, i: usize) -> f32 {
    let r = a.field(3)[i].max(a.field(7)[i]);
    r as f32
}

/// Whether node `n`'s fitted moving ball holds `point` at time `t`.
pub(crate) fn ball_encloses(
    balls: &MovingBalls,
    tree: &RegionTree,
    n: usize,
    t: f64,
    point: [f64; 3],
) -> Option<bool> {
    let f = balls.get(tree, n)?;
    let s = MovingSphere {
        c0: [f[0], f[1], f[2]],
        r0: f[3],
        c1: [f[4], f[5], f[6]],
        r1: f[7],
    };
    let c: [f64; 3] = std::array::from_fn(|k| s.c0[k] + t * (s.c1[k] - s.c0[k]));
    let r = (1.0 - t) * s.r0 + t * s.r1;
    let d2: f64 = (0..3).map(|k| (point[k] - c[k]).powi(2)).sum();
    // Checked with a relative slack for the rounding of this check itself.
    Some(d2.sqrt() <= r * (1.0 + 1e-12) + DISTANCE_TINY)
}

/// Whether a fitted box over the step holds `point` (any t: the box is the same for all).
pub(crate) fn box_encloses(f: [f32; 6], point: [f64; 3]) -> bool {
    (0..3).all(|k| f64::from(f[k]) <= point[k] && point[k] <= f64::from(f[3 + k]))
}
