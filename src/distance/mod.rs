//! Exact proximity primitives on `f64`: point-triangle and edge-edge squared distances, the
//! closest sub-features (IPC's distance types), and the exact decision "distance `<= d`".
//!
//! ```
//! use dhcd::distance::{point_triangle_within, PointTriangle};
//! let t = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
//! // 0.25 above the face: within 0.25 (exactly), not within the float just below it.
//! assert_eq!(point_triangle_within([0.25, 0.25, 0.25], t, 0.25), Some((0.0625, PointTriangle::Face)));
//! assert_eq!(point_triangle_within([0.25, 0.25, 0.25], t, 0.25f64.next_down()), None);
//! ```
//!
//! # What is guaranteed
//!
//! For all finite inputs (any magnitudes: subnormals to `f64::MAX`; degenerate triangles,
//! zero-length and parallel edges included):
//!
//! - **Exact decision.** [`point_triangle_within`] and [`edge_edge_within`] return `Some` iff
//!   the real distance between the closed features, for the `f64` coordinates as given, is
//!   `<= d` for the `f64` `d` as given (`dist^2 <= d^2` over the reals). Negative `d` gives
//!   `None` (exactly right: a distance is nonnegative), `d = 0` asks whether they touch.
//! - **Exact type.** The [`PointTriangle`] / [`EdgeEdge`] returned (by every function here) is
//!   exact: it names the sub-features (corner, open edge, open face) that hold a closest pair
//!   of points. When several do (exact ties: the closest point of a degenerate triangle on two
//!   of its features, parallel edges with many closest pairs, a corner exactly where two
//!   regions meet), the type is the one of **least total dimension, then first in the enum's
//!   order** (which is IPC's numeric order). So a corner type whenever a corner is closest,
//!   `Face` only when the closest point is strictly inside a proper triangle, and `EaEb` only
//!   when every closest pair is interior to both edges (never for parallel edges). IPC's own
//!   `point_triangle_distance_type` / `edge_edge_distance_type` decide the same regions in
//!   floating point (with a parallelism threshold) and may differ near region boundaries.
//! - **Value.** The squared distance `D^` returned is the type's `f64` formula (below),
//!   whose error against the exact squared distance `D` is at most (`eps = 2^-53`):
//!
//!   | type | formula | bound on `|D^ - D|` |
//!   |---|---|---|
//!   | corner-corner (`Vertex*`, `Ea*Eb*` with both indexed) | `|r|^2` | `5.01 eps D` |
//!   | corner-edge (`Edge*`, `EaEb0/1`, `Ea0/1Eb`) | `|e x w|^2 / |e|^2` | `10 eps D + 9 eps sqrt(D) |w| + 19 eps^2 |w|^2` |
//!   | point-face (`Face`), line-line (`EaEb`) | `s (s / |n|^2)`, `s = n.w` | `sigma eps (14 D + 17 sqrt(D) |w|) + 70 sigma^2 eps^2 |w|^2` |
//!
//!   plus `2^-1073` absolute (subnormal results). `w` is the point relative to the first end
//!   of the feature as the formula uses it (`Edge0`: `p - t0`, `Edge1`: `p - t1`, `Edge2`:
//!   `p - t2`, `Face`: `p - t0`; `EaEb0`/`EaEb`: `a0 - b0`, `EaEb1`: `a0 - b1`, `Ea0Eb`:
//!   `a0 - b0`, `Ea1Eb`: `a1 - b0`), `e` the edge's vector, `n` the normal (`(t1 - t0) x
//!   (t2 - t0)`, or `(a1 - a0) x (b1 - b0)`), and `sigma = |t1 - t0| |t2 - t0| / |n|` (resp.
//!   `|a1 - a0| |b1 - b0| / |n|`) >= 1, the inverse sine of the angle at `t0` (between the
//!   edges): slivers and nearly parallel edges lose accuracy as in any float formula. So a
//!   few ulps of `D` when the distance is not much smaller than the features, an absolute
//!   `~eps |w| sqrt(D)` otherwise (the price of cancellation in `e x w`). The float formula is
//!   used when its analysis holds; otherwise the value is computed exactly and **correctly
//!   rounded**: extents beyond `2^60`, a nonzero difference coordinate below `2^-200` (the
//!   formula could underflow), and `sigma >= 2^20` (a sliver, or edges within `1e-6` rad of
//!   parallel, where the float normal is unreliable). The value depends only on the inputs
//!   (not on `d`, nor on which path decided the sign), may be slightly above `d * d` when the
//!   distance is `d` exactly, and is `+inf` if the squared distance exceeds `f64::MAX`
//!   (coordinates beyond ~`1e154`). The tests check these bounds against the exact value.
//!
//! The filter and the checked floats assume IEEE 754 binary64 arithmetic in round-to-nearest
//! with gradual underflow (Rust's default): a host that sets flush-to-zero or
//! denormals-are-zero on the calling thread voids the exactness of the float tiers.
//!
//! Non-finite input: `*_within` returns `None`, `*_distance_sq` returns `(NaN, first type)`;
//! `d = +inf` is within. Nothing here panics; nothing allocates except the exact fallback.
//!
//! # How
//!
//! Each primitive is a short program of sign tests on polynomials in the differences of the
//! input points (and `d`): the closest sub-feature is the Voronoi region of the point (for
//! point-triangle) or the pair of features satisfying the optimality conditions at both ends
//! (edge-edge), each region a conjunction of signs of dot products (degree 2) and Lagrange
//! products (degree 4); the decision is then the sign of `num - d^2 den` for that feature
//! (degree 2, 4 or 6). The tables are in the docs of the `point_triangle` and `edge_edge`
//! source files. Exactness follows from exact signs:
//!
//! 1. **Cheap exits**, exact: a coordinate gap `fl(lo - x) > d` between the boxes (rounding is
//!    monotone and `d` is a float, so `lo - x > d` exactly); `d >= 2 m` with `m` the largest
//!    extent of the points' box (then the distance `<= sqrt(3) m < d`: within without a
//!    distance test); and the plane (lines) test `(n.w)^2 - d^2 |n|^2 > bound` (farther than
//!    `d` from the triangle's plane, or between the two lines).
//! 2. **Float filter** (semi-static, after Shewchuk): every polynomial is evaluated in `f64`
//!    and its sign is accepted when `|value| > c M^k`, with `M = max(m, d)` a bound on every
//!    leaf, `k` the degree, and `c = ((depth + 1) terms + 1) eps` from the formula's shape
//!    (the standard forward bound `gamma_depth * permanent`, the permanent at most
//!    `terms * M^k`); the shapes are recomputed symbolically in the unit tests, so a constant
//!    cannot drift from its formula. The filter runs when `2^-60 <= m <= 2^60`; smaller
//!    configurations are first scaled by a power of two (exact), so that no product overflows
//!    and an underflow stays far below the bound's slack. The classification is first tried
//!    branch-free, all its signs at once; if one is not certified, it is redone sign by sign.
//! 3. **Checked floats**, for a sign the filter leaves open: the same generic formula is
//!    evaluated in floats whose every operation is checked to round nothing (the error term of
//!    Knuth's two-sum or Dekker's two-product is zero; a product with an exact zero is an exact
//!    zero). When none rounded, the value is exact, and so is its sign. Near-ties are mostly
//!    exact ties of this kind: features on a common grid (procedural and coplanar sheets),
//!    coincident points, a coordinate shared exactly.
//! 4. **Exact fallback**, only for a sign the checked floats leave open: all inputs become
//!    integers on their common binary grid (every `f64` is `m 2^e`), and the same generic
//!    formula (one source for the filter and both exact tiers) is evaluated in
//!    `num_bigint::BigInt`. Extents above `2^60` take this path for every sign.
//!
//! # Cost and limits
//!
//! - Float path, per call, on random unit-size features with `d` a tenth of their size
//!   (`benches/distance.rs`; instructions counted under valgrind, independent of load):
//!   point-triangle about 300 instructions when farther than `d` (most leave at the plane
//!   test), 550-600 when within (type and value computed); edge-edge about 350 and 650.
//! - Exact ties and near-ties (a point on an edge's line or on a region boundary, parallel
//!   edges whose closest pair involves an edge's interior, coplanar features with `d = 0`,
//!   zero-length edges, degenerate triangles, a distance equal to `d` to about `1e-13`
//!   relative) leave the float filter. Ties whose formulas are exact in floats (coordinates
//!   on a common grid, coincident points) are decided by the checked floats, about a tenth of
//!   a microsecond; the rest reach the exact fallback: 1-2 microseconds a call on small
//!   integer coordinates, more for coordinates spread over many binades.
//! - Extents above `2^60` (about `1.15e18`) are always exact and slow; no input is rejected,
//!   so there is no range check to call.

mod arith;
mod edge_edge;
mod point_triangle;

/// `x = m 2^e` of a finite f64, shared with the CCD's error-free arithmetic.
pub(crate) use arith::{decompose, two_product, two_sum};

/// Which sub-features of a point-triangle pair are closest: IPC's `PointTriangleDistanceType`
/// (same order and numeric values). Edge `i` joins corners `i` and `i + 1 (mod 3)`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
#[repr(u8)]
pub enum PointTriangle {
    /// IPC `P_T0`: the triangle's corner `t0`.
    Vertex0 = 0,
    /// IPC `P_T1`: the corner `t1`.
    Vertex1 = 1,
    /// IPC `P_T2`: the corner `t2`.
    Vertex2 = 2,
    /// IPC `P_E0`: the open edge `(t0, t1)`.
    Edge0 = 3,
    /// IPC `P_E1`: the open edge `(t1, t2)`.
    Edge1 = 4,
    /// IPC `P_E2`: the open edge `(t2, t0)`.
    Edge2 = 5,
    /// IPC `P_T`: the open face (the triangle is proper).
    Face = 6,
}

impl PointTriangle {
    /// Every type, in order.
    pub const ALL: [Self; 7] = [
        Self::Vertex0,
        Self::Vertex1,
        Self::Vertex2,
        Self::Edge0,
        Self::Edge1,
        Self::Edge2,
        Self::Face,
    ];

    /// IPC's name (`"P_T0"`, ..., `"P_T"`).
    pub const fn ipc_name(self) -> &'static str {
        ["P_T0", "P_T1", "P_T2", "P_E0", "P_E1", "P_E2", "P_T"][self as usize]
    }
}

/// Which sub-features of an edge-edge pair are closest: IPC's `EdgeEdgeDistanceType` (same
/// order and numeric values). `Ea0` is the end `a0` of edge A, `Ea` its open interior; the same
/// for B.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
#[repr(u8)]
pub enum EdgeEdge {
    /// IPC `EA0_EB0`.
    Ea0Eb0 = 0,
    /// IPC `EA0_EB1`.
    Ea0Eb1 = 1,
    /// IPC `EA1_EB0`.
    Ea1Eb0 = 2,
    /// IPC `EA1_EB1`.
    Ea1Eb1 = 3,
    /// IPC `EA_EB0`: the open edge A and the end `b0`.
    EaEb0 = 4,
    /// IPC `EA_EB1`.
    EaEb1 = 5,
    /// IPC `EA0_EB`: the end `a0` and the open edge B.
    Ea0Eb = 6,
    /// IPC `EA1_EB`.
    Ea1Eb = 7,
    /// IPC `EA_EB`: both open edges (non-parallel).
    EaEb = 8,
}

impl EdgeEdge {
    /// Every type, in order.
    pub const ALL: [Self; 9] = [
        Self::Ea0Eb0,
        Self::Ea0Eb1,
        Self::Ea1Eb0,
        Self::Ea1Eb1,
        Self::EaEb0,
        Self::EaEb1,
        Self::Ea0Eb,
        Self::Ea1Eb,
        Self::EaEb,
    ];

    /// IPC's name (`"EA0_EB0"`, ..., `"EA_EB"`).
    pub const fn ipc_name(self) -> &'static str {
        [
            "EA0_EB0", "EA0_EB1", "EA1_EB0", "EA1_EB1", "EA_EB0", "EA_EB1", "EA0_EB", "EA1_EB",
            "EA_EB",
        ][self as usize]
    }
}

/// Squared distance between the point `p` and the closed triangle `t` (possibly degenerate),
/// with the closest sub-feature (exact; see the [module doc](self) for the value's bound and
/// the ties).
#[inline]
pub fn point_triangle_distance_sq(p: [f64; 3], t: [[f64; 3]; 3]) -> (f64, PointTriangle) {
    point_triangle::distance(p, t)
}

/// Squared distance between the closed segments `[a0, a1]` and `[b0, b1]` (possibly of zero
/// length), with the closest sub-features (exact; see the [module doc](self)).
#[inline]
pub fn edge_edge_distance_sq(
    a0: [f64; 3],
    a1: [f64; 3],
    b0: [f64; 3],
    b1: [f64; 3],
) -> (f64, EdgeEdge) {
    edge_edge::distance([a0, a1, b0, b1])
}

/// Squared distance from the point `p` to the line through `e0` and `e1`: the value of a
/// point-edge contact (the corner-edge formula `|e x w|^2 / |e|^2`, `e = e1 - e0`,
/// `w = p - e0`, with its bound in the [module doc](self), correctly rounded where that
/// analysis does not hold). `NaN` when `e0 == e1` or an input is not finite.
#[inline]
pub fn point_line_distance_sq(p: [f64; 3], e0: [f64; 3], e1: [f64; 3]) -> f64 {
    edge_edge::point_line_distance_sq(p, e0, e1)
}

/// `Some((distance_sq, type))` iff the distance between `p` and the closed triangle `t` is
/// `<= d`, decided exactly for the `f64` inputs and the `f64` `d`; `None` otherwise (and for
/// negative or NaN `d`, or non-finite coordinates). The value and type are those of
/// [`point_triangle_distance_sq`].
#[inline]
pub fn point_triangle_within(
    p: [f64; 3],
    t: [[f64; 3]; 3],
    d: f64,
) -> Option<(f64, PointTriangle)> {
    point_triangle::within(p, t, d)
}

/// `Some((distance_sq, type))` iff the distance between the closed segments `[a0, a1]` and
/// `[b0, b1]` is `<= d`, decided exactly; `None` otherwise (see [`point_triangle_within`]).
#[inline]
pub fn edge_edge_within(
    a0: [f64; 3],
    a1: [f64; 3],
    b0: [f64; 3],
    b1: [f64; 3],
    d: f64,
) -> Option<(f64, EdgeEdge)> {
    edge_edge::within([a0, a1, b0, b1], d)
}

/// Whether `|(a1 - a0) x (b1 - b0)|^2 < threshold`, decided exactly for the `f64` inputs:
/// the contact set's test of nearly parallel edges (the IPC Toolkit's mollifier test, which
/// it evaluates in floating point). A float evaluation with a forward error bound decides
/// most; the rest are decided on the integers of the inputs' binary grid.
pub(crate) fn edges_cross_sq_below(e: [[f64; 3]; 4], threshold: f64) -> bool {
    use arith::{cross, dot, sub3, EPS};
    if threshold.is_nan() || threshold <= 0.0 {
        return false;
    }
    if threshold == f64::INFINITY {
        return true;
    }
    let a = sub3(&e[1], &e[0]);
    let b = sub3(&e[3], &e[2]);
    let c = cross(&a, &b);
    let v = dot(&c, &c);
    let l1 = |x: &[f64; 3]| x[0].abs() + x[1].abs() + x[2].abs();
    // |c|^2 <= (|a|_1 |b|_1)^2 term by term; 12 roundings along any path (two differences,
    // the products and sums of the cross product, its square and sum), each at most EPS
    // relative, with ample slack.
    let scale = (l1(&a) * l1(&b)).powi(2);
    let err = 16.0 * EPS * scale;
    if v.is_finite() && scale.is_finite() && scale > arith::VALUE_TINY {
        if v + err < threshold {
            return true;
        }
        if v - err >= threshold {
            return false;
        }
    }
    // Exact: the coordinates as integers X 2^unit, so |c|^2 = C 2^(4 unit).
    let flat: [f64; 12] = std::array::from_fn(|k| e[k / 3][k % 3]);
    let (ints, unit) = arith::to_grid(&flat);
    let p =
        |i: usize| -> [num_bigint::BigInt; 3] { std::array::from_fn(|k| ints[3 * i + k].clone()) };
    let (a, b) = (sub3(&p(1), &p(0)), sub3(&p(3), &p(2)));
    let c = cross(&a, &b);
    let lhs = dot(&c, &c);
    let (m, k) = arith::decompose(threshold);
    if m <= 0 {
        return false;
    }
    let rhs = num_bigint::BigInt::from(m);
    let shift = i64::from(k) - 4 * i64::from(unit);
    if shift >= 0 {
        lhs < rhs << shift as usize
    } else {
        (lhs << (-shift) as usize) < rhs
    }
}
