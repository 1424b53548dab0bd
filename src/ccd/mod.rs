//! Exact continuous collision detection (CCD) of vertex-face and edge-edge pairs in f64.
//!
//! Every point moves on the straight line from its position at t = 0 to its position at
//! t = 1: `x(t) = x0 + t (x1 - x0)`. A vertex-face pair collides when the vertex lies in
//! the closed triangle at some t in `[0, t_max]`; an edge-edge pair when the two closed
//! segments meet. With `min_distance = delta > 0`, when the distance between the two
//! features is `<= delta` at some such t.
//!
//! # Guarantee
//!
//! - **Exact decision**, for every finite f64 input, with `min_distance = 0` and with
//!   `min_distance > 0` alike: [`vertex_face`] / [`edge_edge`] return `Some` iff the pair
//!   collides as defined above, for the f64 values as given (no tolerance, no false
//!   negative, no false positive). Degenerate input is included: zero-length edges,
//!   collinear or coincident triangle corners, pairs coplanar all step, parallel and
//!   collinear edges, contact at exactly t = 0 or t = t_max, pairs that do not move,
//!   touching without crossing.
//! - **Time of impact**: `Some(toi)` with `toi <= t*`, the true earliest contact time, and
//!   `t* - toi <= 1e-12` ([`TOI_TOLERANCE`]): the root is isolated to an interval of width
//!   `<= 2^-40 ~ 9.1e-13` and its lower end rounded down to f64. `toi = 0` exactly when the
//!   pair already touches at t = 0; `toi = t_max` exactly when the first contact is at
//!   `t_max` (a root at 0 or `t_max` is found by exact evaluation, never approximated).
//! - Invalid options (`t_max` outside `[0, 1]` or NaN, `min_distance` negative or not
//!   finite) and non-finite coordinates are typed errors of [`CcdOptions::new`],
//!   [`check_points`] and the `try_*` entries ([`try_vertex_face`], [`try_edge_edge`]). The
//!   plain entries assume validated input (checked by `debug_assert!`) and return `None`
//!   for invalid input in release builds; they never panic.
//!
//! # Method, and why it is exact
//!
//! **The predicate as polynomial signs.** With `A = a - p`, `B = b - p`, `C = c - p` (the
//! triangle's corners relative to the vertex, each linear in t), the vertex lies in the
//! closed triangle iff the four points are coplanar, `f = A . (B x C) = 0`, and either
//! (i) the three barycentric numerators `d_a = (B x C) . n`, `d_b = (C x A) . n`,
//! `d_c = (A x B) . n`, `n = (b - a) x (c - a)`, are all `> 0` (then `n != 0` and the
//! vertex is strictly inside), or (ii) the vertex lies on one of the three closed edges:
//! `A x B = 0` and `A . B <= 0` for edge ab (likewise bc, ca). Proof: if `n != 0` and the
//! points are coplanar, `d_i / |n|^2` are the barycentric coordinates, so the vertex is in
//! the closed triangle iff all are `>= 0`, i.e. all `> 0` or one is 0 (on an edge); if
//! `n = 0` the triangle is a segment or a point, equal to its longest edge, and (i) cannot
//! hold. For edges `a0 a1` and `b0 b1`: coplanar (`f = 0`) and either a proper crossing,
//! `(u x (b0 - a0)) . (u x (b1 - a0)) < 0` and `(v x (a0 - b0)) . (v x (a1 - b0)) < 0`
//! (each endpoint pair strictly on both sides of the other line, `u = a1 - a0`,
//! `v = b1 - b0`), or an endpoint of one on the other closed segment (the same
//! point-on-segment test). Two closed coplanar segments that meet either cross properly or
//! one has an endpoint on the other (collinear overlaps and degenerate segments included).
//! Every polynomial has degree <= 4 in t.
//!
//! **Earliest solution of such a formula** (`exact.rs`). The contact set S is closed (the
//! projection onto t of a compact set). Write the predicate as clauses (conjunctions of
//! sign conditions). If a clause contains `q = 0` with q not identically zero, its
//! solutions lie among the finitely many roots of q; otherwise its infimum is 0 or a root
//! of one of its polynomials (away from those roots every sign, so the clause, is locally
//! constant); and a clause of strict inequalities only (an open set) can be skipped but
//! for t = 0, since the first point of S it reaches lies in another clause. So the
//! earliest contact is the least candidate at which the whole predicate holds. With `f`
//! not identically 0 (the general case) the candidates are the (at most 3) roots of f in
//! `[0, t_max]`: touching without crossing is a double root, checked like any other. When
//! the motion is coplanar all step (f identically 0), "strictly inside" and "properly
//! crossing" are open, and the candidates are 0 and the roots of the point-on-segment
//! polynomials: the first contact of coplanar motion is at t = 0 or on an edge or
//! endpoint. Degenerate triangles and edges need nothing special: the clauses are exact
//! for them (a degenerate triangle is the union of its edges; a zero-length segment is a
//! point, which the point-on-segment test handles).
//!
//! **Exact arithmetic.** Every f64 is `m 2^e`; one common scaling by a power of two makes
//! all coordinates integers, so the polynomials have integer coefficients (big integers).
//! Roots in `[0, t_max]` are found exactly: 0 and `t_max` by evaluation, the others
//! isolated in dyadic intervals with the Sturm sequence of the square-free part. The sign
//! of another polynomial at an isolated root is decided by a Sturm-Tarski query (the sign
//! variations of the signed remainder sequence of `p, p' s` across the isolating
//! interval), which is exact, zero included, with no separation bound. All remainder
//! sequences are integer pseudo-remainders divided by their content (a positive scaling
//! of each member changes no sign variation) and all evaluation points are dyadic, so no
//! rational arithmetic (and no gcd per operation) is needed.
//!
//! **Separation first** (`axis.rs`), after the swept boxes of stage 0 below (which the
//! walk's pairs skip: their feature boxes already met, `pair_until`): the features'
//! gap along a fixed axis is concave in t (their points move linearly), so a gap above
//! `delta` at t = 0 and at t = `t_max` holds in between. Tested in floats with a proven
//! error bound along the centroids' line, the face normal or the edges' cross product, and
//! the coordinate axes, it ends most pairs of neighbouring features of a mesh for a few dot
//! products.
//!
//! **Float filter next** (`filter.rs`): (0) swept boxes; (1) the Bernstein coefficients
//! of `f` on `[0, 1]` from eight 3x3 determinants with a proven forward error bound
//! (`2^-45 m^3` plus an underflow term, m the largest coordinate difference): all of one
//! sign means no contact; (2) the roots of f isolated by interval Bernstein subdivision,
//! each narrowed by bisection, and at each root interval in increasing order the
//! in-triangle / crossing signs evaluated in interval arithmetic over that time interval
//! (every operation rounded to nearest and widened by one ulp each way, which is sound
//! without rounding-mode control). The filter only answers when certain. If f is so flat
//! (small motions) that floats cannot narrow its root to `2^-40`, the contact is still
//! decided on the wider certified interval and only the time is narrowed exactly (the
//! integer cubic bisected at dyadic points). Everything else (touching, roots at t = 0 or
//! `t_max`, double roots, vertex-on-edge, coplanar motion, coordinate differences beyond
//! 2^200) is left undecided. The filter allocates nothing.
//!
//! **Planar filter next** (`planar.rs`), for what the first left undecided: the features
//! projected on the plane of two coordinate axes, certified apart over pieces of the time
//! interval by a separating-axis test in interval-bounded floats; and, when all eight
//! points share one coordinate exactly (motion in one axis plane, where `f` is
//! identically 0 and the 3D predicate is the 2D one), contact certified at a time after
//! every earlier piece was certified apart, which gives the time within `2^-40`. Touching
//! at a single instant (without entering) is certified too: two points meeting along a
//! line they share, at a root estimated in floats and certified in a window of `2^-41`;
//! or exact contact at a time with few bits (1/2, 1, `k/16`) where the positions are
//! floats (error-free transformations, `expansion.rs`), with every separation before it
//! certified from its exact value there. A sheet lying on a floor and sliding, folding
//! flat, collapsing onto a line or sliding over another sheet is decided there. Only what
//! neither filter decides goes to the exact path.
//!
//! **Minimum distance `delta > 0`**: the same exact engine on the formula "distance <=
//! delta": the vertex within delta of the face's plane with its foot in the
//! (non-degenerate) triangle (`f^2 <= delta^2 |n|^2`, all `d_i >= 0`, `|n| > 0`), or within
//! delta of an edge (an endpoint within delta, or the foot on the non-degenerate segment
//! and `|A x B|^2 <= delta^2 |b - a|^2`); for edges, an endpoint within delta of the other
//! segment, or the closest points of the two non-parallel lines inside both segments and
//! within delta (polynomials of degree <= 6). This is **exact** too (delta is an f64, so
//! `delta^2` is rational and scales with the coordinates). Its float filter (`near.rs`)
//! comes first: swept boxes inflated by delta and the fixed-axis separation, then time
//! pieces of `[0, t_max]` visited earliest first. Each piece is tested along the features'
//! closest direction at its end as a fixed axis (`axis.rs`), then certified apart at its
//! midpoint with a margin (the features' largest relative speed times the half width: the
//! distance is Lipschitz in t) by the boxes, the plane or lines, or the feature's parts
//! farther than delta, or within (a corner, a foot on an edge, the foot in the triangle, or
//! the lines' closest points on both segments within delta) in interval arithmetic, on the
//! corners taken relative to the first one (rounding at the features' extent), and split
//! where neither: the piece holding the contact once at the float estimate of its time,
//! otherwise in halves. The contact time is the start of the first piece not certified
//! apart (or of the piece after the estimate's split), where the distance is within delta
//! by `2^-40` later. Only pairs whose distance touches delta without crossing it, or
//! crosses it too slowly for floats to place within `2^-40`, go to the exact path. On a
//! folding 8 x 8 sheet with `delta = 0.004` (1,065 colliding pairs of 3,581 tested) none
//! reaches it; on armadillo-rollers 326 -> 327 with `delta = 0.001` (68,387 colliding
//! pairs), 19 do.

//! # Limits
//!
//! None on the input range: any finite f64 coordinates are decided exactly (huge or tiny
//! magnitudes just take the exact path, whose numbers grow with the spread of exponents).
//! The exact path allocates and takes tens of microseconds to a few milliseconds; on the
//! sample queries of Wang et al. 2021 about 14% of the queries reach it (they are built to
//! be degenerate), on the labelled pairs of real simulation steps about 2%.

mod axis;
mod exact;
mod expansion;
mod filter;
mod interval;
mod near;
mod pieces;
mod planar;
mod ring;
#[cfg(test)]
mod testing;

use crate::error::{Error, Result};

/// log2 of the width to which a root is isolated before its lower end is returned.
const TOI_TOL_LOG2: usize = 40;

/// Bound on `t* - toi` (the true earliest contact time minus the returned one): the root's
/// interval width `2^-40` plus rounding down to f64, below `1e-12`.
pub const TOI_TOLERANCE: f64 = 1e-12;

/// Options of one CCD query.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CcdOptions {
    /// End of the time interval, in `[0, 1]` (default 1).
    pub t_max: f64,
    /// Collide when the features come within this distance (>= 0, finite; default 0).
    pub min_distance: f64,
}

impl Default for CcdOptions {
    fn default() -> Self {
        CcdOptions {
            t_max: 1.0,
            min_distance: 0.0,
        }
    }
}

impl CcdOptions {
    /// Checked options.
    pub fn new(t_max: f64, min_distance: f64) -> Result<CcdOptions> {
        let o = CcdOptions {
            t_max,
            min_distance,
        };
        o.validate()?;
        Ok(o)
    }

    /// `Ok` iff `t_max` is in `[0, 1]` and `min_distance` is finite and `>= 0`.
    #[doc(hidden)]
    pub fn validate(&self) -> Result<()> {
        if !(0.0..=1.0).contains(&self.t_max) {
            return Err(Error::InvalidTimeLimit(self.t_max));
        }
        if !(self.min_distance.is_finite() && self.min_distance >= 0.0) {
            return Err(Error::InvalidMinDistance(self.min_distance));
        }
        Ok(())
    }

    fn is_valid(&self) -> bool {
        self.validate().is_ok()
    }
}

/// `Ok` iff every coordinate of the query is finite.
#[doc(hidden)]
pub fn check_points(x0: &[[f64; 3]; 4], x1: &[[f64; 3]; 4]) -> Result<()> {
    for (i, p) in x0.iter().chain(x1.iter()).enumerate() {
        if !p.iter().all(|c| c.is_finite()) {
            return Err(Error::NonFiniteCcdPoint {
                point: i,
                position: *p,
            });
        }
    }
    Ok(())
}

#[inline(always)]
fn all_finite(x0: &[[f64; 3]; 4], x1: &[[f64; 3]; 4]) -> bool {
    x0.iter()
        .chain(x1.iter())
        .all(|p| p.iter().all(|c| c.is_finite()))
}

/// Vertex-face CCD: `x0 = [v, f0, f1, f2]` at t = 0 and `x1` the same points at t = 1.
/// `Some(toi)` iff the vertex lies in the closed triangle (or within `min_distance` of it)
/// at some t in `[0, t_max]`, exactly for the f64 input; `toi` is at most
/// [`TOI_TOLERANCE`] below the earliest such t and never above it.
///
/// Assumes validated input ([`CcdOptions::new`], [`check_points`]); for invalid input it
/// returns `None` (and panics in debug builds).
pub fn vertex_face(x0: &[[f64; 3]; 4], x1: &[[f64; 3]; 4], options: &CcdOptions) -> Option<f64> {
    query(exact::Kind::VertexFace, x0, x1, options, &|| false).unwrap_or(None)
}

/// Edge-edge CCD: `x0 = [a0, a1, b0, b1]` at t = 0 and `x1` at t = 1. `Some(toi)` iff the
/// closed segments meet (or come within `min_distance`) at some t in `[0, t_max]`, with
/// the same time bound as [`vertex_face`].
pub fn edge_edge(x0: &[[f64; 3]; 4], x1: &[[f64; 3]; 4], options: &CcdOptions) -> Option<f64> {
    query(exact::Kind::EdgeEdge, x0, x1, options, &|| false).unwrap_or(None)
}

/// [`try_vertex_face`] that can be stopped: `stop` is asked between the steps of the exact
/// path (the rare queries it decides can take up to seconds, `docs/LIMITS.md` in the
/// repository), and `true` ends the query with [`Error::Cancelled`].
pub fn vertex_face_until(
    x0: &[[f64; 3]; 4],
    x1: &[[f64; 3]; 4],
    options: &CcdOptions,
    stop: &dyn Fn() -> bool,
) -> Result<Option<f64>> {
    options.validate()?;
    check_points(x0, x1)?;
    query(exact::Kind::VertexFace, x0, x1, options, stop).map_err(|_| Error::Cancelled)
}

/// [`try_edge_edge`] that can be stopped, as [`vertex_face_until`].
pub fn edge_edge_until(
    x0: &[[f64; 3]; 4],
    x1: &[[f64; 3]; 4],
    options: &CcdOptions,
    stop: &dyn Fn() -> bool,
) -> Result<Option<f64>> {
    options.validate()?;
    check_points(x0, x1)?;
    query(exact::Kind::EdgeEdge, x0, x1, options, stop).map_err(|_| Error::Cancelled)
}

/// The query of one pair that the whole-mesh CCD walk runs: as [`vertex_face`] or
/// [`edge_edge`], with `stop` asked between the steps of the exact path (`Err` once it
/// said stop). The walk has already done what the entry points do first, so this starts
/// after them: its positions were checked finite on input, the pair's swept feature boxes
/// met (stage 0 would end almost none of its pairs), and `magnitude`, at least every
/// coordinate's magnitude (the whole step's largest), bounds the culls' rounding in place
/// of the pair's own largest coordinate (any upper bound keeps them certain).
/// `boxes_until`: test the pair's boxes over `[0, t_max]` (when `t_max < 1`), which the
/// walk skips where its own boxes covered nearly that interval (they would meet again).
#[inline(always)]
pub(crate) fn pair_until(
    vf: bool,
    x0: &[[f64; 3]; 4],
    x1: &[[f64; 3]; 4],
    options: &CcdOptions,
    magnitude: f64,
    boxes_until: bool,
    stop: &dyn Fn() -> bool,
) -> std::result::Result<Option<f64>, exact::Stopped> {
    debug_assert!(
        options.is_valid() && all_finite(x0, x1),
        "invalid CCD input: {options:?} {x0:?} {x1:?}"
    );
    debug_assert!(max_magnitude(x0, x1) <= magnitude);
    let kind = if vf {
        exact::Kind::VertexFace
    } else {
        exact::Kind::EdgeEdge
    };
    if boxes_until && apart_until(kind, x0, x1, options, magnitude) {
        return Ok(None);
    }
    after_boxes(kind, x0, x1, options, magnitude, None, stop)
}

/// [`try_vertex_face`] with its input checked: a typed error instead of an assumption.
pub fn try_vertex_face(
    x0: &[[f64; 3]; 4],
    x1: &[[f64; 3]; 4],
    options: &CcdOptions,
) -> Result<Option<f64>> {
    options.validate()?;
    check_points(x0, x1)?;
    Ok(vertex_face(x0, x1, options))
}

/// [`edge_edge`] with its input checked.
pub fn try_edge_edge(
    x0: &[[f64; 3]; 4],
    x1: &[[f64; 3]; 4],
    options: &CcdOptions,
) -> Result<Option<f64>> {
    options.validate()?;
    check_points(x0, x1)?;
    Ok(edge_edge(x0, x1, options))
}

#[inline(always)]
fn query(
    kind: exact::Kind,
    x0: &[[f64; 3]; 4],
    x1: &[[f64; 3]; 4],
    options: &CcdOptions,
    stop: exact::Stop<'_>,
) -> std::result::Result<Option<f64>, exact::Stopped> {
    let valid = options.is_valid() && all_finite(x0, x1);
    debug_assert!(valid, "invalid CCD input: {options:?} {x0:?} {x1:?}");
    if !valid {
        return Ok(None);
    }
    let delta = options.min_distance;
    // Stage 0, the swept boxes, on the input as given: comparisons, exact at every scale.
    // Most pairs end here, before paying for the scaling below.
    let apart = if kind == exact::Kind::VertexFace {
        filter::vf_boxes_apart(x0, x1, delta)
    } else {
        filter::ee_boxes_apart(x0, x1, delta)
    };
    if apart {
        return Ok(None);
    }
    let magnitude = max_magnitude(x0, x1);
    if apart_until(kind, x0, x1, options, magnitude) {
        return Ok(None);
    }
    after_boxes(kind, x0, x1, options, magnitude, Some(magnitude), stop)
}

/// With a time limit below 1 (the earliest-time mode's pruning), the pair's boxes over
/// `[0, t_max]` apart: far smaller than over the whole step when `t_max` is small. Their
/// rounding bound holds for coordinates below 2^1000 (no overflow), at any scale; `bound`
/// is at least every coordinate's magnitude.
#[inline(always)]
fn apart_until(
    kind: exact::Kind,
    x0: &[[f64; 3]; 4],
    x1: &[[f64; 3]; 4],
    options: &CcdOptions,
    bound: f64,
) -> bool {
    options.t_max < 1.0
        && bound <= BOXES_UNTIL_MAX
        && filter::boxes_apart_until(kind, x0, x1, options.t_max, options.min_distance)
}

/// A valid query whose swept boxes meet (over the step, and over `[0, t_max]` where tested:
/// [`apart_until`]): the axes over `[0, t_max]` (their rounding bounded with `bound`, at
/// least every coordinate's magnitude), then the filters and the exact path on the query
/// scaled to unit size (by its own largest coordinate magnitude, `own` when known).
#[inline(always)]
fn after_boxes(
    kind: exact::Kind,
    x0: &[[f64; 3]; 4],
    x1: &[[f64; 3]; 4],
    options: &CcdOptions,
    bound: f64,
    own: Option<f64>,
    stop: exact::Stop<'_>,
) -> std::result::Result<Option<f64>, exact::Stopped> {
    let vf = kind == exact::Kind::VertexFace;
    let delta = options.min_distance;
    // Separation along a few fixed axes at both ends of [0, t_max]: ends most pairs of
    // neighbouring features, which the boxes do not, for a few dot products.
    let apart = if options.t_max < 1.0 {
        let end = axis::positions_at(x0, x1, options.t_max);
        axis::apart(vf, x0, &end, delta, bound)
    } else {
        axis::apart(vf, x0, x1, delta, bound)
    };
    if apart {
        return Ok(None);
    }
    // One power-of-two scaling (when it is exact) brings the largest coordinate near 1:
    // contacts and times do not change, and the float filters never overflow or drown in
    // their underflow terms.
    let magnitude = own.unwrap_or_else(|| max_magnitude(x0, x1));
    let unit = to_unit_scale(x0, x1, delta, magnitude);
    let (x0, x1, delta) = match &unit {
        Some((y0, y1, d)) => (y0, y1, *d),
        None => (x0, x1, delta),
    };
    if delta == 0.0 {
        let verdict = match kind {
            exact::Kind::VertexFace => filter::vertex_face(x0, x1, options.t_max),
            exact::Kind::EdgeEdge => filter::edge_edge(x0, x1, options.t_max),
        };
        match verdict {
            filter::Verdict::Miss => Ok(None),
            filter::Verdict::Hit(t) => Ok(Some(t)),
            filter::Verdict::Refine(lo, hi) => exact::refine_root(x0, x1, lo, hi, stop).map(Some),
            filter::Verdict::Unknown => undecided(kind, x0, x1, options.t_max, stop),
        }
    } else {
        match near::decide(vf, x0, x1, options.t_max, delta) {
            filter::Verdict::Miss => Ok(None),
            filter::Verdict::Hit(t) => Ok(Some(t)),
            _ => exact::solve(kind, x0, x1, options.t_max, delta, stop),
        }
    }
}

/// A query (with `min_distance = 0`) the main filter left undecided: the planar filter, then
/// the exact path. Out of line: rare, and kept out of the hot loop of the walks.
#[cold]
#[inline(never)]
fn undecided(
    kind: exact::Kind,
    x0: &[[f64; 3]; 4],
    x1: &[[f64; 3]; 4],
    t_max: f64,
    stop: exact::Stop<'_>,
) -> std::result::Result<Option<f64>, exact::Stopped> {
    match planar::decide(kind == exact::Kind::VertexFace, x0, x1, t_max) {
        filter::Verdict::Miss => Ok(None),
        filter::Verdict::Hit(t) => Ok(Some(t)),
        _ => exact::solve(kind, x0, x1, t_max, 0.0, stop),
    }
}

/// Coordinates up to this magnitude keep [`filter::boxes_apart_until`]'s arithmetic finite.
const BOXES_UNTIL_MAX: f64 = 1.071_508_607_186_267_3e301; // 2^1000

/// The largest coordinate magnitude of a query.
#[inline(always)]
fn max_magnitude(x0: &[[f64; 3]; 4], x1: &[[f64; 3]; 4]) -> f64 {
    x0.iter()
        .chain(x1)
        .flatten()
        .fold(0.0f64, |m, x| m.max(x.abs()))
}

/// `x` times `2^k`, computed in at most two exact steps, if the result is exact.
fn scaled_exactly(x: f64, k: i32) -> Option<f64> {
    let step = |x: f64, k: i32| x * f64::from_bits(((1023 + k) as u64) << 52);
    let (k1, k2) = (k / 2, k - k / 2);
    let y = step(step(x, k1), k2);
    // Exact iff scaling back gives `x` (scaling up never loses bits short of overflow, which
    // the range of `k` rules out; scaling down loses only bits shifted below 2^-1074).
    (y.is_finite() && step(step(y, -k1), -k2) == x).then_some(y)
}

/// The query scaled by one power of two so that its largest coordinate magnitude `m` is in
/// `[1, 2)`, when every coordinate and `delta` scale exactly (none loses bits below the
/// smallest subnormal); `None` when already there, all zero, or not exact.
#[allow(clippy::type_complexity)]
fn to_unit_scale(
    x0: &[[f64; 3]; 4],
    x1: &[[f64; 3]; 4],
    delta: f64,
    m: f64,
) -> Option<([[f64; 3]; 4], [[f64; 3]; 4], f64)> {
    if m == 0.0 {
        return None;
    }
    // The binary exponent of m (subnormals included).
    let e = if m >= f64::MIN_POSITIVE {
        ((m.to_bits() >> 52) as i32) - 1023
    } else {
        -1074 + (63 - m.to_bits().leading_zeros() as i32)
    };
    let k = -e;
    if k == 0 {
        return None;
    }
    // The common case, `2^k` a normal float: a product by it is exact unless it overflows
    // (delta far above the coordinates) or falls below the normal range (scaling down).
    if (-1022..=1023).contains(&k) {
        let s = f64::from_bits(((1023 + k) as u64) << 52);
        let least = x0
            .iter()
            .chain(x1)
            .flatten()
            .chain(std::iter::once(&delta))
            .filter(|x| **x != 0.0)
            .fold(f64::INFINITY, |m, x| m.min(x.abs()));
        let exact = (delta * s).is_finite() && (k > 0 || least * s >= f64::MIN_POSITIVE);
        if exact {
            let scale = |x: &[[f64; 3]; 4]| x.map(|p| p.map(|c| c * s));
            return Some((scale(x0), scale(x1), delta * s));
        }
    }
    let mut y0 = [[0.0; 3]; 4];
    let mut y1 = [[0.0; 3]; 4];
    for i in 0..4 {
        for j in 0..3 {
            y0[i][j] = scaled_exactly(x0[i][j], k)?;
            y1[i][j] = scaled_exactly(x1[i][j], k)?;
        }
    }
    Some((y0, y1, scaled_exactly(delta, k)?))
}

/// The exact path alone, without the float filter (slow; for tests and comparisons).
#[doc(hidden)]
pub fn vertex_face_exact(
    x0: &[[f64; 3]; 4],
    x1: &[[f64; 3]; 4],
    options: &CcdOptions,
) -> Option<f64> {
    options.validate().ok()?;
    check_points(x0, x1).ok()?;
    exact::solve(
        exact::Kind::VertexFace,
        x0,
        x1,
        options.t_max,
        options.min_distance,
        &|| false,
    )
    .unwrap_or(None)
}

/// The exact path alone for edge-edge.
#[doc(hidden)]
pub fn edge_edge_exact(
    x0: &[[f64; 3]; 4],
    x1: &[[f64; 3]; 4],
    options: &CcdOptions,
) -> Option<f64> {
    options.validate().ok()?;
    check_points(x0, x1).ok()?;
    exact::solve(
        exact::Kind::EdgeEdge,
        x0,
        x1,
        options.t_max,
        options.min_distance,
        &|| false,
    )
    .unwrap_or(None)
}
