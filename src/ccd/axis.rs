//! Separation along a fixed axis over a time interval, in floats with a proven error bound:
//! the cull that ends most pairs of neighbouring features before the filters that look for
//! a contact time.
//!
//! For a fixed direction `c`, every point's projection `x(t) . c` is linear in `t` (the
//! points move on straight lines), so the gap between the two features along `c`,
//! `g(t) = min_j b_j(t) . c - max_i a_i(t) . c` (`a` the first feature's corners, `b` the
//! second's), is a minimum of linear functions minus a maximum of linear ones: concave. Its
//! least value over `[0, 1]` is `g(0)` or `g(1)`, so `g(0)` and `g(1)` both above
//! `delta |c|` (or both below `-delta |c|`, the other side) prove the features farther than
//! `delta` apart at every time of the step: their distance is at least `|g(t)| / |c|`. No
//! margin for the motion is needed; the test is exact for straight-line motion, up to the
//! rounding bounded below. The same holds between any two times of the step, from the poses
//! at those times.
//!
//! **Axes**, in the order they pay on real meshes (a vertex against the triangles around its
//! own, two edges of one neighbourhood): the line between the features' centroids at
//! `t = 0`, the face normal (vertex-face) or the cross product of the edges (edge-edge) at
//! `t = 0`, the same two at `t = 1`, then the coordinate axes (the features' boxes at both
//! ends, sharper than the boxes over the whole step of stage 0). On armadillo-rollers
//! 326 -> 327 the first axis ends 84% of the 7.0 M candidate pairs, all seven 96%. The CCD
//! walk runs the first axis on its candidates 8 at a time first
//! (`dhcd_kernels::apart::centroids_apart_with`, with this bound and margins for its own
//! rounding), and this test on the pairs it leaves.
//!
//! **Rounding** (`u = 2^-53`, `M` at least the largest coordinate magnitude, `C = sum_k
//! |c_k|`). The axis is whatever float vector was computed: any direction is a valid axis,
//! so only the projections and the gaps need a bound. The poses are the given ones (error 0) or
//! interpolated in floats at a time of `[0, 1]` ([`positions_at`]: each coordinate within
//! `5.01 u M`, so its projection within `5.01 u M C`). A projection is a 3-term dot product,
//! within `gamma_3 sum_k |x_k c_k| <= 3.01 u M C` of the exact one, plus `3 * 2^-1075` for
//! underflow; a gap is the difference of two projections, rounded once more (`u` of at most
//! `2.01 M C`). So a computed gap is within `18.1 u M C + 2^-1070` of the exact one, below
//! `E = 2^-48 M C + 2^-1000 = 32 u M C + 2^-1000` with room for the rounding of `C`
//! itself, and a gap is certain when it exceeds `delta |c| + E` rounded up. `|c|` is
//! bounded above from its rounded square (within `2^-51` of `|c|^2`, then a square root and
//! a product each within `2^-53`). Axes with `C` outside `[2^-400, 2^400]`, and queries
//! with `M` outside it, are not tested: there the bound's terms could under- or overflow.

/// `2^-48`: the relative part of a gap's error bound.
const REL: f64 = 3.552_713_678_800_501e-15;
/// `2^-1000`: its absolute part (underflow).
const ABS: f64 = 9.332_636_185_032_189e-302;
/// `2^-400` and `2^400`: the magnitudes (coordinates and axes' 1-norms) tested.
const TINY: f64 = 3.872_591_914_849_318e-121;
const HUGE: f64 = 2.582_249_878_086_908_6e120;
/// `1 + 2^-49`: raises `|c|` computed from its rounded square above the exact `|c|`.
const LENGTH_UP: f64 = 1.000_000_000_000_001_8;

type Points = [[f64; 3]; 4];

#[inline(always)]
fn dot(x: &[f64; 3], c: &[f64; 3]) -> f64 {
    x[0] * c[0] + x[1] * c[1] + x[2] * c[2]
}

#[inline(always)]
fn sub(a: &[f64; 3], b: &[f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

#[inline(always)]
fn cross(a: &[f64; 3], b: &[f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

/// The gaps along `c` at the positions `x`: the second feature (points `split..4`) above
/// the first (`0..split`), and below it.
#[inline(always)]
fn gaps(split: usize, x: &Points, c: &[f64; 3]) -> (f64, f64) {
    let (mut a_lo, mut a_hi) = (f64::INFINITY, f64::NEG_INFINITY);
    let (mut b_lo, mut b_hi) = (f64::INFINITY, f64::NEG_INFINITY);
    for (i, p) in x.iter().enumerate() {
        let v = dot(p, c);
        if i < split {
            a_lo = a_lo.min(v);
            a_hi = a_hi.max(v);
        } else {
            b_lo = b_lo.min(v);
            b_hi = b_hi.max(v);
        }
    }
    (b_lo - a_hi, a_lo - b_hi)
}

/// The two features certainly farther than `delta` apart along `c` at every time between
/// two poses `x0` and `x1` of the points, given or interpolated by [`positions_at`] (see
/// the module docs); `m`, at least the query's largest coordinate magnitude, is in
/// `[2^-400, 2^400]`.
#[inline(always)]
fn apart_along(
    split: usize,
    (x0, x1): (&Points, &Points),
    c: &[f64; 3],
    delta: f64,
    m: f64,
) -> bool {
    let norm1 = c[0].abs() + c[1].abs() + c[2].abs();
    if !(TINY..=HUGE).contains(&norm1) {
        return false;
    }
    let error = (REL * m * norm1).next_up() + ABS;
    let bound = if delta == 0.0 {
        error
    } else {
        let length = (dot(c, c).sqrt() * LENGTH_UP).next_up();
        (delta * length).next_up() + error
    }
    .next_up();
    let (up0, down0) = gaps(split, x0, c);
    if up0 > bound {
        let (up1, _) = gaps(split, x1, c);
        up1 > bound
    } else if down0 > bound {
        let (_, down1) = gaps(split, x1, c);
        down1 > bound
    } else {
        false
    }
}

/// The centroid of the first feature's corners to the second's, at the positions `x`.
#[inline(always)]
fn centroid_axis(split: usize, x: &Points) -> [f64; 3] {
    let mean = |points: &[[f64; 3]]| -> [f64; 3] {
        let n = points.len() as f64;
        std::array::from_fn(|k| points.iter().map(|p| p[k]).sum::<f64>() / n)
    };
    sub(&mean(&x[split..]), &mean(&x[..split]))
}

/// The face normal (vertex-face: points 1, 2, 3) or the edges' cross product (edge-edge:
/// `(x1 - x0) x (x3 - x2)`) at the positions `x`.
#[inline(always)]
fn normal_axis(vf: bool, x: &Points) -> [f64; 3] {
    if vf {
        cross(&sub(&x[2], &x[1]), &sub(&x[3], &x[1]))
    } else {
        cross(&sub(&x[1], &x[0]), &sub(&x[3], &x[2]))
    }
}

/// The pair (`vf`: a vertex and a triangle, else two edges, as the CCD queries lay out
/// their points) certainly farther than `delta` apart at every time between the poses `x0`
/// and `x1` (given, or interpolated by [`positions_at`]), by separation along the axes of
/// the module docs. `m` is at least the largest coordinate magnitude of the query (its
/// own, or the whole step's: any upper bound keeps the error bound of the module docs);
/// outside `[2^-400, 2^400]` nothing is certified.
#[inline(always)]
pub(crate) fn apart(vf: bool, x0: &Points, x1: &Points, delta: f64, m: f64) -> bool {
    if !(TINY..=HUGE).contains(&m) {
        return false;
    }
    let split = if vf { 1 } else { 2 };
    let along = |c: &[f64; 3]| apart_along(split, (x0, x1), c, delta, m);
    along(&centroid_axis(split, x0))
        || along(&normal_axis(vf, x0))
        || along(&centroid_axis(split, x1))
        || along(&normal_axis(vf, x1))
        || along(&[1.0, 0.0, 0.0])
        || along(&[0.0, 1.0, 0.0])
        || along(&[0.0, 0.0, 1.0])
}

/// The points at time `t` in `[0, 1]`, `x0 + t (x1 - x0)` in floats: each coordinate within
/// `5.01 u m` of the exact one (`u = 2^-53`; three roundings, `|x1 - x0| <= 2 m`), which the
/// gap's bound allows for (module docs).
#[inline(always)]
pub(crate) fn positions_at(x0: &Points, x1: &Points, t: f64) -> Points {
    std::array::from_fn(|i| std::array::from_fn(|k| x0[i][k] + t * (x1[i][k] - x0[i][k])))
}

/// The features certainly farther than `delta` apart along `c` at every time of `[lo, hi]`,
/// from their poses at `lo` and `hi` (the gap is concave on any time interval). `m`: at
/// least every exact coordinate's magnitude over the motion (the query's largest, or the
/// largest relative to a corner when the poses are taken relative to it: a translation at
/// each time changes no gap), each given coordinate within `8.1 u m` of the exact one
/// ([`positions_at`]: `5.01 u m`); nothing is certified outside `[2^-400, 2^400]`. The
/// bound's `32 u m C` holds for such poses: each projection is within `(8.1 + 3.01) u m C`,
/// the gap within twice that plus `2.01 u m C` for its own rounding, `24.3 u m C`.
#[inline(always)]
pub(crate) fn apart_between(
    vf: bool,
    poses: (&Points, &Points),
    c: &[f64; 3],
    delta: f64,
    m: f64,
) -> bool {
    (TINY..=HUGE).contains(&m) && apart_along(if vf { 1 } else { 2 }, poses, c, delta, m)
}

#[cfg(test)]
mod tests {
    //! Every pair the cull calls apart is apart for the exact path, over the whole step and
    //! from a pose interpolated in floats, on motions built to touch (coordinates on a
    //! coarse grid, so contacts at exactly t = 0, t = 1 and in between are frequent), at
    //! scales from 2^-390 to 2^390 and with minimum distances; and the cull ends a fair
    //! share of them, so the check is not vacuous.
    use super::super::exact::{solve, Kind};
    use super::super::testing::Rng;
    use super::*;

    fn scaled(x: &Points, s: f64) -> Points {
        x.map(|p| p.map(|c| c * s))
    }

    /// A batch cull of the walk on one pair: its scalar reference, and the kernel on the
    /// dispatched backend (equal; both checked). `MOTION`: the motion bound
    /// (`apart_beyond_motion_with`), else the centroids' line (`centroids_apart_with`).
    fn batch_apart<const MOTION: bool>(
        vf: bool,
        x0: &Points,
        x1: &Points,
        d: f64,
        m: f64,
        t_end: f64,
    ) -> bool {
        use dhcd_kernels::apart::{apart_beyond_motion_with, centroids_apart_with, MovingPoints};
        use dhcd_kernels::pulp::{Simd, WithSimd};
        use dhcd_kernels::reference::{moving_apart_beyond_motion, moving_centroids_apart};
        struct Run<'a, const MOTION: bool>(&'a MovingPoints, bool, f64, f64, f64);
        impl<const MOTION: bool> WithSimd for Run<'_, MOTION> {
            type Output = u64;
            fn with_simd<S: Simd>(self, simd: S) -> u64 {
                if MOTION {
                    apart_beyond_motion_with(simd, self.0, 1, self.1, self.2, 1.0, self.3, self.4)
                } else {
                    centroids_apart_with(simd, self.0, 1, self.1, self.2, self.3, self.4)
                }
            }
        }
        let mut pairs = MovingPoints::default();
        pairs.set(0, x0, x1);
        let one = if MOTION {
            moving_apart_beyond_motion(x0, x1, vf, d, 1.0, m, t_end)
        } else {
            moving_centroids_apart(x0, x1, vf, d, m, t_end)
        };
        let batch = dhcd_kernels::arch().dispatch(Run::<MOTION>(&pairs, vf, d, m, t_end)) == 1;
        assert_eq!(
            one, batch,
            "kernel and reference disagree: {x0:?} -> {x1:?}"
        );
        one
    }

    #[test]
    fn every_pair_called_apart_is_apart_exactly() {
        let mut rng = Rng(0x9e37_79b9_7f4a_7c15);
        let (mut apart_count, mut between_count, mut total) = (0u32, 0u32, 0u32);
        let (mut batch_count, mut motion_count) = (0u32, 0u32);
        for case in 0..4000 {
            let vf = case % 2 == 0;
            let x0: Points = std::array::from_fn(|_| std::array::from_fn(|_| rng.small()));
            let mut x1: Points = std::array::from_fn(|_| std::array::from_fn(|_| rng.small()));
            if rng.below(3) == 0 {
                // A small step: the motion a simulation takes.
                x1 = std::array::from_fn(|i| {
                    std::array::from_fn(|k| x0[i][k] + (rng.small() / 16.0))
                });
            }
            let delta = [0.0, 0.0, 1.0 / 64.0, 0.25][rng.below(4) as usize];
            let t_max = if rng.below(4) == 0 { 0.5 } else { 1.0 };
            let s = 2f64.powi([0, 0, -390, 390, -60, 60][rng.below(6) as usize]);
            let (y0, y1, d) = (scaled(&x0, s), scaled(&x1, s), delta * s);
            let m = y0
                .iter()
                .chain(&y1)
                .flatten()
                .fold(0.0f64, |m, x| m.max(x.abs()));
            total += 1;
            let kind = if vf { Kind::VertexFace } else { Kind::EdgeEdge };
            if apart(vf, &y0, &y1, d, m) {
                apart_count += 1;
                let exact = solve(kind, &x0, &x1, t_max, delta, &|| false).unwrap();
                assert_eq!(
                    exact, None,
                    "vf {vf} {x0:?} -> {x1:?} delta {delta} scale {s}"
                );
            }
            // Over [0, hi] from the pose interpolated (rounded) at a time that is not dyadic,
            // along the centroid axis there.
            let hi = [0.1, 1.0 / 3.0, 0.7][rng.below(3) as usize];
            // The batch cull of the walk (the centroids' line at t0, the kernel and its
            // scalar reference), over [0, 1] and over [0, hi].
            for t_end in [1.0, hi] {
                if batch_apart::<false>(vf, &y0, &y1, d, m, t_end) {
                    batch_count += 1;
                    let exact = solve(kind, &x0, &x1, t_end, delta, &|| false).unwrap();
                    assert_eq!(
                        exact, None,
                        "batch: vf {vf} {x0:?} -> {x1:?} delta {delta} until {t_end}"
                    );
                }
                if batch_apart::<true>(vf, &y0, &y1, d, m, t_end) {
                    motion_count += 1;
                    let exact = solve(kind, &x0, &x1, t_end, delta, &|| false).unwrap();
                    assert_eq!(
                        exact, None,
                        "motion: vf {vf} {x0:?} -> {x1:?} delta {delta} until {t_end}"
                    );
                }
            }
            let end = positions_at(&y0, &y1, hi);
            let c = centroid_axis(if vf { 1 } else { 2 }, &end);
            if apart_between(vf, (&y0, &end), &c, d, m) {
                between_count += 1;
                let exact = solve(kind, &x0, &x1, hi, delta, &|| false).unwrap();
                assert_eq!(
                    exact, None,
                    "vf {vf} {x0:?} -> {x1:?} delta {delta} until {hi}"
                );
            }
        }
        assert!(between_count > total / 4, "{between_count} of {total}");
        assert!(batch_count > total / 4, "{batch_count} of {}", 2 * total);
        assert!(motion_count > total / 8, "{motion_count} of {}", 2 * total);
        // Random pairs in one cube are often far apart: most must be culled.
        assert!(apart_count > total / 4, "{apart_count} of {total}");
    }

    /// Features that touch exactly at one end of the step, along the very axis tested
    /// (the gap there is 0), are never called apart; a gap of one ulp at `t = 1` is.
    #[test]
    fn a_zero_gap_at_either_end_is_not_apart() {
        // A vertex coming down onto the face z = 0 at t = 1, and leaving it from t = 0.
        let tri = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
        let x0 = [[0.25, 0.25, 1.0], tri[0], tri[1], tri[2]];
        let x1 = [[0.25, 0.25, 0.0], tri[0], tri[1], tri[2]];
        assert!(!apart(true, &x0, &x1, 0.0, 1.0));
        assert!(!apart(true, &x1, &x0, 0.0, 1.0));
        let mut above = x1;
        above[0][2] = f64::MIN_POSITIVE;
        // One subnormal above: within the error bound, so not certified either.
        assert!(!apart(true, &x0, &above, 0.0, 1.0));
        above[0][2] = 2f64.powi(-40);
        assert!(apart(true, &x0, &above, 0.0, 1.0));
        // With a minimum distance just above the final gap, not apart; just below, apart.
        assert!(!apart(true, &x0, &above, 2f64.powi(-40), 1.0));
        assert!(apart(true, &x0, &above, 2f64.powi(-41), 1.0));
    }

    /// Magnitudes outside the tested range certify nothing.
    #[test]
    fn extreme_magnitudes_are_left_to_the_filters() {
        let x0 = [[0.0, 0.0, 5.0], [0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
        let x1 = x0;
        assert!(apart(true, &x0, &x1, 0.0, 5.0));
        for s in [2f64.powi(-500), 2f64.powi(500)] {
            let (y0, y1) = (scaled(&x0, s), scaled(&x1, s));
            assert!(!apart(true, &y0, &y1, 0.0, 5.0 * s));
        }
    }

    /// The batch cull's certificate against exact arithmetic: along the very axis the kernel
    /// computes, the exact gaps at both ends exceed `delta |c|` whenever it certifies. Points
    /// far from the origin (every projection rounds) with the second feature placed within
    /// a few ulps of touching the first along the axis at t1, so a bound too small would
    /// certify pairs that touch.
    #[test]
    fn batch_certificates_hold_in_exact_arithmetic() {
        use num_rational::BigRational as Q;
        use num_traits::{Signed, Zero};
        let q = |x: f64| Q::from_float(x).expect("finite");
        let mut rng = Rng(0x2545_f491_4f6c_dd1d);
        let (mut certified, mut total) = (0u32, 0u32);
        for case in 0..20000 {
            let vf = case % 2 == 0;
            let offset = [1.0e6, -3.0e5, 7.5e5];
            let near = |r: &mut Rng| std::array::from_fn(|k| offset[k] + r.small() / 8.0);
            let x0: Points = std::array::from_fn(|_| near(&mut rng));
            let mut x1: Points =
                std::array::from_fn(|i| std::array::from_fn(|k| x0[i][k] + rng.small() / 64.0));
            // The axis the kernel uses.
            let c: [f64; 3] = std::array::from_fn(|k| {
                if vf {
                    ((x0[1][k] + x0[2][k]) + x0[3][k]) * (1.0 / 3.0) - x0[0][k]
                } else {
                    ((x0[2][k] + x0[3][k]) - (x0[0][k] + x0[1][k])) * 0.5
                }
            });
            // At t1, put the first feature's points level with the second feature's lowest
            // point along c (offset across c by `w = c x e_x`, exactly perpendicular), then
            // nudge them by a few ulps: gaps of about zero, of either sign, after rounding.
            let proj = |p: &[f64; 3]| (p[0] * c[0] + p[1] * c[1]) + p[2] * c[2];
            let split = if vf { 1 } else { 2 };
            let low = (split..4)
                .min_by(|&i, &j| proj(&x1[i]).total_cmp(&proj(&x1[j])))
                .expect("points");
            let corner = x1[low];
            let w = [0.0, c[2], -c[1]];
            for (p, s) in x1.iter_mut().take(split).zip([0.5, -0.25]) {
                for k in 0..3 {
                    let mut v = corner[k] + s * w[k];
                    for _ in 0..rng.below(3) {
                        v = if rng.below(2) == 0 {
                            v.next_up()
                        } else {
                            v.next_down()
                        };
                    }
                    p[k] = v;
                }
            }
            // With a minimum distance, the same pairs moved down along c by it: gaps of
            // about `delta |c|`.
            let delta = [0.0, 0.0, 1e-6][rng.below(3) as usize];
            let length = ((c[0] * c[0] + c[1] * c[1]) + c[2] * c[2]).sqrt();
            for p in x1.iter_mut().take(split) {
                for k in 0..3 {
                    p[k] -= delta * c[k] / length;
                }
            }
            let m = x0
                .iter()
                .chain(&x1)
                .flatten()
                .fold(0.0f64, |m, x| m.max(x.abs()));
            total += 1;
            if !batch_apart::<false>(vf, &x0, &x1, delta, m, 1.0) {
                continue;
            }
            certified += 1;
            let cq = c.map(q);
            let cc = cq.iter().map(|x| x * x).fold(Q::zero(), |a, b| a + b);
            for x in [&x0, &x1] {
                let p: Vec<Q> = x
                    .iter()
                    .map(|p| {
                        (0..3)
                            .map(|k| q(p[k]) * &cq[k])
                            .fold(Q::zero(), |a, b| a + b)
                    })
                    .collect();
                let (a, b) = p.split_at(split);
                let lo = |v: &[Q]| v.iter().min().unwrap().clone();
                let hi = |v: &[Q]| v.iter().max().unwrap().clone();
                let up = lo(b) - hi(a);
                let down = lo(a) - hi(b);
                let gap = if up.is_positive() { up } else { down };
                let dd = q(delta) * q(delta);
                assert!(
                    gap.is_positive() && &gap * &gap > dd * &cc,
                    "vf {vf}: certified, but an exact gap is {gap} along {c:?}: {x0:?} -> {x1:?}"
                );
            }
        }
        // Every pair is level along the axis at t1 within rounding: none may be certified
        // but by a gap above the error bound, and the bound leaves almost none.
        assert!(certified < total / 100, "{certified} of {total}");
    }
}
