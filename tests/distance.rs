//! Tests of `dhcd::distance`: an exact rational oracle that knows nothing of the fast path
//! (closest points by clamped projection and a 2x2 solve, minimum over candidate features),
//! compared on random and adversarial inputs: integer grids scaled from subnormals to 2^1000
//! (points on edges and corners, coplanar and collinear points, parallel, collinear and
//! overlapping edges, degenerate triangles, zero-length edges), one-ulp nudges, translations
//! far from the origin, and thresholds `d` at the exact distance and one ulp either side.
//! Also: every type on a hand-built case, the stated value bounds against the exact value.

use dhcd::distance::{
    edge_edge_distance_sq, edge_edge_within, point_line_distance_sq, point_triangle_distance_sq,
    point_triangle_within, EdgeEdge, PointTriangle,
};
use num_bigint::BigInt;
use num_rational::BigRational as Q;
use num_traits::{One, Signed, ToPrimitive, Zero};
use proptest::prelude::*;

type P = [f64; 3];

// ---------------------------------------------------------------------------------------
// The oracle.
// ---------------------------------------------------------------------------------------

type R3 = [Q; 3];

fn q(x: f64) -> Q {
    Q::from_float(x).expect("finite")
}
fn r3(p: &P) -> R3 {
    [q(p[0]), q(p[1]), q(p[2])]
}
fn sub(a: &R3, b: &R3) -> R3 {
    [&a[0] - &b[0], &a[1] - &b[1], &a[2] - &b[2]]
}
fn add(a: &R3, b: &R3) -> R3 {
    [&a[0] + &b[0], &a[1] + &b[1], &a[2] + &b[2]]
}
fn scale(a: &R3, s: &Q) -> R3 {
    [&a[0] * s, &a[1] * s, &a[2] * s]
}
fn dot(a: &R3, b: &R3) -> Q {
    &a[0] * &b[0] + &a[1] * &b[1] + &a[2] * &b[2]
}
fn cross(a: &R3, b: &R3) -> R3 {
    [
        &a[1] * &b[2] - &a[2] * &b[1],
        &a[2] * &b[0] - &a[0] * &b[2],
        &a[0] * &b[1] - &a[1] * &b[0],
    ]
}
fn norm2(a: &R3) -> Q {
    dot(a, a)
}
fn clamp01(x: Q) -> Q {
    if x < Q::zero() {
        Q::zero()
    } else if x > Q::one() {
        Q::one()
    } else {
        x
    }
}

/// Squared distance from `p` to the closed segment `[a, b]`.
fn point_segment(p: &R3, a: &R3, b: &R3) -> Q {
    let e = sub(b, a);
    let ee = norm2(&e);
    if ee.is_zero() {
        return norm2(&sub(p, a));
    }
    let t = clamp01(dot(&sub(p, a), &e) / ee);
    norm2(&sub(p, &add(a, &scale(&e, &t))))
}

/// Exact squared distance and type of a point and a closed triangle.
fn pt_oracle(p: &P, t: &[P; 3]) -> (Q, PointTriangle) {
    let p = r3(p);
    let [t0, t1, t2] = [r3(&t[0]), r3(&t[1]), r3(&t[2])];
    let closed = [
        norm2(&sub(&p, &t0)),
        norm2(&sub(&p, &t1)),
        norm2(&sub(&p, &t2)),
        point_segment(&p, &t0, &t1),
        point_segment(&p, &t1, &t2),
        point_segment(&p, &t2, &t0),
    ];
    let mut best = closed.iter().min().unwrap().clone();
    // The face: the projection's barycentric coordinates by a 2x2 solve.
    let (e0, e1, w) = (sub(&t1, &t0), sub(&t2, &t0), sub(&p, &t0));
    let (a, b, c) = (norm2(&e0), dot(&e0, &e1), norm2(&e1));
    let det = &a * &c - &b * &b;
    if !det.is_zero() {
        let (f, g) = (dot(&w, &e0), dot(&w, &e1));
        let s = (&c * &f - &b * &g) / &det;
        let u = (&a * &g - &b * &f) / &det;
        if s >= Q::zero() && u >= Q::zero() && &s + &u <= Q::one() {
            let foot = add(&t0, &add(&scale(&e0, &s), &scale(&e1, &u)));
            let face = norm2(&sub(&p, &foot));
            if face < best {
                best = face;
            }
        }
    }
    let ty = closed
        .iter()
        .position(|x| *x == best)
        .map_or(PointTriangle::Face, |i| PointTriangle::ALL[i]);
    (best, ty)
}

/// Exact squared distance and type of two closed segments.
fn ee_oracle(a0: &P, a1: &P, b0: &P, b1: &P) -> (Q, EdgeEdge) {
    let [a0, a1, b0, b1] = [r3(a0), r3(a1), r3(b0), r3(b1)];
    let closed = [
        norm2(&sub(&a0, &b0)),
        norm2(&sub(&a0, &b1)),
        norm2(&sub(&a1, &b0)),
        norm2(&sub(&a1, &b1)),
        point_segment(&b0, &a0, &a1),
        point_segment(&b1, &a0, &a1),
        point_segment(&a0, &b0, &b1),
        point_segment(&a1, &b0, &b1),
    ];
    let mut best = closed.iter().min().unwrap().clone();
    // Interior-interior: the lines' closest points, if both inside.
    let (u, v, r) = (sub(&a1, &a0), sub(&b1, &b0), sub(&a0, &b0));
    let (uu, uv, vv) = (norm2(&u), dot(&u, &v), norm2(&v));
    let (ru, rv) = (dot(&r, &u), dot(&r, &v));
    // s uu - t uv = -ru ; s uv - t vv = -rv
    let det = &uv * &uv - &uu * &vv;
    if !det.is_zero() {
        let s = (&ru * &vv - &uv * &rv) / &det;
        let t = (&uu * &rv - &uv * &ru) / -&det;
        let zero_one = |x: &Q| *x >= Q::zero() && *x <= Q::one();
        if zero_one(&s) && zero_one(&t) {
            let gap = sub(&add(&r, &scale(&u, &s)), &scale(&v, &t));
            let ii = norm2(&gap);
            if ii < best {
                best = ii;
            }
        }
    }
    let ty = closed
        .iter()
        .position(|x| *x == best)
        .map_or(EdgeEdge::EaEb, |i| EdgeEdge::ALL[i]);
    (best, ty)
}

// ---------------------------------------------------------------------------------------
// The value bounds of the module doc, checked exactly.
// ---------------------------------------------------------------------------------------

const EPS: f64 = f64::EPSILON / 2.0;

/// An upper bound on `sqrt(x)` for a nonnegative rational (relative slack 1e-12).
fn sqrt_up(x: &Q) -> Q {
    if x.is_zero() {
        return Q::zero();
    }
    // x = y 4^k with y in a comfortable range for f64.
    let k = (x.numer().bits() as i64 - x.denom().bits() as i64) / 2;
    let four_k = |k: i64| -> Q {
        let p = Q::from_integer(BigInt::one() << (2 * k.unsigned_abs()) as usize);
        if k >= 0 {
            p
        } else {
            p.recip()
        }
    };
    let two_k = |k: i64| -> Q {
        let p = Q::from_integer(BigInt::one() << k.unsigned_abs() as usize);
        if k >= 0 {
            p
        } else {
            p.recip()
        }
    };
    let y = x / four_k(k);
    let s = y.to_f64().unwrap().sqrt() * (1.0 + 1e-12);
    q(s) * two_k(k)
}

/// `|got - exact| <= a D + b sqrt(D |w|^2) + c |w|^2 + 2^-1073` (a, b, c rationals).
fn within_bound(got: f64, exact: &Q, a: Q, b: Q, c: Q, w2: &Q) -> bool {
    if got.is_infinite() {
        return *exact > q(f64::MAX);
    }
    let err = (q(got) - exact).abs();
    let tiny = q(2f64.powi(-1022) * 2f64.powi(-51));
    let bound = a * exact + b * sqrt_up(&(exact * w2)) + c * w2 + tiny;
    err <= bound
}

fn eps(k: f64) -> Q {
    q(k * EPS)
}

/// The stated bound for a corner-edge type.
fn line_ok(got: f64, exact: &Q, w: &R3) -> bool {
    within_bound(
        got,
        exact,
        eps(10.0),
        eps(9.0),
        eps(19.0) * eps(1.0),
        &norm2(w),
    )
}

/// The stated bound for a face or line-line type; `sigma^2 = |x|^2 |y|^2 / |x cross y|^2`.
fn plane_ok(got: f64, exact: &Q, w: &R3, x: &R3, y: &R3) -> bool {
    let sigma = sqrt_up(&(norm2(x) * norm2(y) / norm2(&cross(x, y))));
    let s = sigma.clone();
    within_bound(
        got,
        exact,
        eps(14.0) * &s,
        eps(17.0) * &s,
        eps(70.0) * eps(1.0) * &s * &sigma,
        &norm2(w),
    )
}

fn pt_value_ok(got: f64, exact: &Q, p: &P, t: &[P; 3], ty: PointTriangle) -> bool {
    let p = r3(p);
    let [t0, t1, t2] = [r3(&t[0]), r3(&t[1]), r3(&t[2])];
    match ty {
        PointTriangle::Vertex0 | PointTriangle::Vertex1 | PointTriangle::Vertex2 => {
            within_bound(got, exact, eps(5.01), Q::zero(), Q::zero(), &Q::zero())
        }
        PointTriangle::Edge0 => line_ok(got, exact, &sub(&p, &t0)),
        PointTriangle::Edge1 => line_ok(got, exact, &sub(&p, &t1)),
        PointTriangle::Edge2 => line_ok(got, exact, &sub(&p, &t2)),
        PointTriangle::Face => plane_ok(got, exact, &sub(&p, &t0), &sub(&t1, &t0), &sub(&t2, &t0)),
    }
}

fn ee_value_ok(got: f64, exact: &Q, e: [&P; 4], ty: EdgeEdge) -> bool {
    let [a0, a1, b0, b1] = e.map(r3);
    match ty {
        EdgeEdge::Ea0Eb0 | EdgeEdge::Ea0Eb1 | EdgeEdge::Ea1Eb0 | EdgeEdge::Ea1Eb1 => {
            within_bound(got, exact, eps(5.01), Q::zero(), Q::zero(), &Q::zero())
        }
        EdgeEdge::EaEb0 | EdgeEdge::Ea0Eb => line_ok(got, exact, &sub(&a0, &b0)),
        EdgeEdge::EaEb1 => line_ok(got, exact, &sub(&a0, &b1)),
        EdgeEdge::Ea1Eb => line_ok(got, exact, &sub(&a1, &b0)),
        EdgeEdge::EaEb => plane_ok(got, exact, &sub(&a0, &b0), &sub(&a1, &a0), &sub(&b1, &b0)),
    }
}

// ---------------------------------------------------------------------------------------
// Checks of one configuration against the oracle.
// ---------------------------------------------------------------------------------------

/// Thresholds to try: the float nearest the exact distance and its neighbours (so the exact
/// distance, when it is a float, and a float one ulp either side), zero, and extras.
fn thresholds(exact: &Q, extra: &[f64]) -> Vec<f64> {
    let s = sqrt_of(exact);
    let mut ds = vec![0.0, s, s.next_up(), s.next_down(), s.next_up().next_up()];
    ds.retain(|d| *d >= 0.0 && d.is_finite());
    ds.extend(extra.iter().copied().filter(|d| d.is_finite() && *d >= 0.0));
    ds
}

/// `sqrt` of a rational, rounded to some float near it (for picking thresholds only).
fn sqrt_of(x: &Q) -> f64 {
    let s = sqrt_up(x) * q(1.0 - 1e-12);
    s.to_f64().unwrap_or(f64::INFINITY)
}

fn check_pt(p: &P, t: &[P; 3], extra: &[f64]) -> Result<(), TestCaseError> {
    let (exact, ty) = pt_oracle(p, t);
    let (got, got_ty) = point_triangle_distance_sq(*p, *t);
    prop_assert_eq!(got_ty, ty, "type of {:?} {:?}", p, t);
    prop_assert!(
        pt_value_ok(got, &exact, p, t, ty),
        "value {} vs exact {} ({:?}) for {:?} {:?}",
        got,
        exact.to_f64().unwrap_or(f64::NAN),
        ty,
        p,
        t
    );
    for d in thresholds(&exact, extra) {
        let want = q(d) * q(d) >= exact;
        prop_assert!(
            !(want && filters_say_apart(Filter::PointTriangle, [*p, t[0], t[1], t[2]], d)),
            "the batch filter ends a pair within d = {:e}: {:?} {:?}",
            d,
            p,
            t
        );
        let res = point_triangle_within(*p, *t, d);
        prop_assert_eq!(res.is_some(), want, "d = {:e} for {:?} {:?}", d, p, t);
        if let Some(r) = res {
            prop_assert_eq!(
                r,
                (got, got_ty),
                "within's value and type are distance_sq's"
            );
        }
    }
    Ok(())
}

fn check_ee(e: [&P; 4], extra: &[f64]) -> Result<(), TestCaseError> {
    let [a0, a1, b0, b1] = e;
    let (exact, ty) = ee_oracle(a0, a1, b0, b1);
    let (got, got_ty) = edge_edge_distance_sq(*a0, *a1, *b0, *b1);
    prop_assert_eq!(got_ty, ty, "type of {:?}", e);
    prop_assert!(
        ee_value_ok(got, &exact, e, ty),
        "value {} vs exact {} ({:?}) for {:?}",
        got,
        exact.to_f64().unwrap_or(f64::NAN),
        ty,
        e
    );
    for d in thresholds(&exact, extra) {
        let want = q(d) * q(d) >= exact;
        prop_assert!(
            !(want && filters_say_apart(Filter::Segments, [*a0, *a1, *b0, *b1], d)),
            "the batch filter ends a pair within d = {:e}: {:?}",
            d,
            e
        );
        let res = edge_edge_within(*a0, *a1, *b0, *b1, d);
        prop_assert_eq!(res.is_some(), want, "d = {:e} for {:?}", d, e);
        if let Some(r) = res {
            prop_assert_eq!(
                r,
                (got, got_ty),
                "within's value and type are distance_sq's"
            );
        }
    }
    Ok(())
}

/// The batch filters in front of the exact tests (`dhcd_kernels::apart`).
#[derive(Clone, Copy)]
enum Filter {
    Segments,
    PointTriangle,
}

/// Whether the filter's scalar reference or its kernel on the dispatched backend certifies
/// the pair farther apart than `d` (the proximity query trusts both).
fn filters_say_apart(f: Filter, pts: [P; 4], d: f64) -> bool {
    use dhcd_kernels::apart::{point_triangles_apart_with, segments_apart_with, FourPoints};
    use dhcd_kernels::pulp::{Simd, WithSimd};
    use dhcd_kernels::reference::{point_triangle_apart, segment_pair_apart};
    struct Run(Filter, FourPoints, f64);
    impl WithSimd for Run {
        type Output = bool;
        fn with_simd<S: Simd>(self, simd: S) -> bool {
            let bits = match self.0 {
                Filter::Segments => segments_apart_with(simd, &self.1, 1, self.2),
                Filter::PointTriangle => point_triangles_apart_with(simd, &self.1, 1, self.2),
            };
            bits == 1
        }
    }
    let mut batch = FourPoints::default();
    batch.set(0, pts);
    let one = match f {
        Filter::Segments => segment_pair_apart(pts, d),
        Filter::PointTriangle => point_triangle_apart(pts, d),
    };
    one | dhcd_kernels::arch().dispatch(Run(f, batch, d))
}

// ---------------------------------------------------------------------------------------
// Strategies.
// ---------------------------------------------------------------------------------------

/// A configuration of `N` points: small integers (ties, degeneracies) or random values, all
/// times `2^e`, optionally nudged by an ulp per coordinate and translated.
fn points<const N: usize>() -> impl Strategy<Value = [P; N]> {
    let coord = prop_oneof![
        3 => (-3i32..=3).prop_map(f64::from),
        1 => -1.0e3f64..1.0e3,
        1 => -1.0f64..1.0,
    ];
    let pts = prop::array::uniform::<_, N>(prop::array::uniform3(coord));
    let exp = prop_oneof![
        4 => Just(0i32),
        2 => -40i32..40,
        1 => -1070i32..-1000,
        1 => -200i32..200,
        1 => 900i32..1000,
    ];
    let nudge = prop::array::uniform::<_, N>(prop::array::uniform3(prop_oneof![
        6 => Just(0i32),
        1 => Just(1),
        1 => Just(-1),
    ]));
    let shift = prop_oneof![
        6 => Just([0.0; 3]),
        1 => prop::array::uniform3(-1e6f64..1e6),
        1 => Just([1.0e15, -3.0e15, 7.0e14]),
    ];
    (pts, exp, nudge, shift).prop_map(|(pts, e, nudge, shift)| {
        let mut out = pts;
        for (p, n) in out.iter_mut().zip(nudge) {
            for k in 0..3 {
                // Scale in two exact steps (products by powers of two), then translate.
                let half = e / 2;
                let mut x = p[k] * 2f64.powi(half) * 2f64.powi(e - half);
                if e > -900 {
                    x += shift[k] * 2f64.powi(e.min(0));
                }
                x = match n[k] {
                    1 => x.next_up(),
                    -1 => x.next_down(),
                    _ => x,
                };
                p[k] = x;
            }
        }
        out
    })
}

fn finite<const N: usize>(pts: &[P; N]) -> bool {
    pts.iter().flatten().all(|x| x.is_finite())
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(6000))]

    #[test]
    fn point_triangle_matches_the_oracle(pts in points::<4>(), extra in prop::array::uniform2(0.0f64..4.0)) {
        prop_assume!(finite(&pts));
        let [p, t0, t1, t2] = pts;
        check_pt(&p, &[t0, t1, t2], &extra)?;
    }

    #[test]
    fn edge_edge_matches_the_oracle(pts in points::<4>(), extra in prop::array::uniform2(0.0f64..4.0)) {
        prop_assume!(finite(&pts));
        let [a0, a1, b0, b1] = pts;
        check_ee([&a0, &a1, &b0, &b1], &extra)?;
    }

    /// The point-edge contact's value: the squared distance to the line, within the
    /// corner-edge bound, at every scale.
    #[test]
    fn point_line_is_within_the_corner_edge_bound(pts in points::<3>()) {
        prop_assume!(finite(&pts));
        let [p, e0, e1] = pts;
        let got = point_line_distance_sq(p, e0, e1);
        let (e, w) = (sub(&r3(&e1), &r3(&e0)), sub(&r3(&p), &r3(&e0)));
        if e0 == e1 {
            prop_assert!(got.is_nan());
        } else {
            let exact = norm2(&cross(&e, &w)) / norm2(&e);
            prop_assert!(line_ok(got, &exact, &w), "{p:?} {e0:?} {e1:?}: {got} against {exact}");
        }
    }

    /// Points on the triangle's features and in its plane (affine combinations with simple
    /// dyadic weights, exact), nudged by an ulp, at various offsets along the normal.
    #[test]
    fn point_triangle_on_features_and_in_plane(
        t in prop::array::uniform3(prop::array::uniform3(-8i32..=8)),
        w in prop::array::uniform2(-4i32..=8),
        lift in prop_oneof![Just(0i32), -2i32..=2],
        nudge in prop::array::uniform3(-1i32..=1),
        e in prop_oneof![Just(0i32), -1060i32..-1000, 950i32..1000, -30i32..30],
    ) {
        let s = |x: f64| x * 2f64.powi(e / 2) * 2f64.powi(e - e / 2);
        let t: [P; 3] = t.map(|p| p.map(|x| s(f64::from(x))));
        // p = t0 + (w0/4) (t1 - t0) + (w1/4) (t2 - t0) + lift * (0, 0, 1/4) (exact).
        let mut p = [0.0; 3];
        for k in 0..3 {
            let (a, b, c) = (t[0][k], t[1][k], t[2][k]);
            p[k] = a + f64::from(w[0]) / 4.0 * (b - a) + f64::from(w[1]) / 4.0 * (c - a);
            if k == 2 {
                p[k] += s(f64::from(lift) / 4.0);
            }
            p[k] = match nudge[k] { 1 => p[k].next_up(), -1 => p[k].next_down(), _ => p[k] };
        }
        prop_assume!(finite(&[p, t[0], t[1], t[2]]));
        check_pt(&p, &t, &[s(0.25), s(1.0)])?;
    }

    /// Edges through grid points: parallel, collinear, overlapping, crossing, touching, of
    /// zero length, nudged by an ulp.
    #[test]
    fn edge_edge_parallel_collinear_touching(
        a0 in prop::array::uniform3(-4i32..=4),
        dir in prop::array::uniform3(-2i32..=2),
        len in prop::array::uniform2(0i32..=3),
        off in prop::array::uniform3(-3i32..=3),
        mode in 0u8..4,
        nudge in prop::array::uniform3(-1i32..=1),
        e in prop_oneof![Just(0i32), -1060i32..-1000, 950i32..1000, -30i32..30],
    ) {
        let s = |x: i32| f64::from(x) * 2f64.powi(e / 2) * 2f64.powi(e - e / 2);
        let a0i = a0;
        let a1i = [0, 1, 2].map(|k| a0i[k] + len[0] * dir[k]);
        // B: parallel (same direction), collinear (offset along dir), crossing (another
        // direction), or reversed.
        let b0i = match mode {
            1 => [0, 1, 2].map(|k| a0i[k] + off[0] * dir[k]),
            _ => [0, 1, 2].map(|k| a0i[k] + off[k]),
        };
        let bdir = match mode {
            2 => [dir[1], dir[2], dir[0] + 1],
            3 => dir.map(|x| -x),
            _ => dir,
        };
        let b1i = [0, 1, 2].map(|k| b0i[k] + len[1] * bdir[k]);
        let mut pts = [a0i, a1i, b0i, b1i].map(|p| p.map(s));
        for k in 0..3 {
            pts[3][k] = match nudge[k] { 1 => pts[3][k].next_up(), -1 => pts[3][k].next_down(), _ => pts[3][k] };
        }
        prop_assume!(finite(&pts));
        let [a0, a1, b0, b1] = pts;
        check_ee([&a0, &a1, &b0, &b1], &[s(1), s(2)])?;
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(3000))]

    /// The batch filters are not vacuous: random pairs (non-degenerate almost surely) more
    /// than 1.001 times `d` apart are certified, at scales from 2^-150 to 2^150.
    #[test]
    fn batch_filters_certify_separated_pairs(
        pts in prop::array::uniform4(prop::array::uniform3(-1.0f64..1.0)),
        lift in 0.0f64..3.0,
        k in -150i32..150,
    ) {
        let s = 2f64.powi(k);
        let pts = [0, 1, 2, 3].map(|i| {
            let mut p = pts[i].map(|x| x * s);
            if i >= 2 {
                p[2] += lift * s;
            }
            p
        });
        let [a, b, c, e] = pts;
        let (ee, _) = ee_oracle(&a, &b, &c, &e);
        let (pt, _) = pt_oracle(&a, &[b, c, e]);
        for (f, exact) in [(Filter::Segments, ee), (Filter::PointTriangle, pt)] {
            let d = sqrt_of(&exact) / 1.001;
            if d >= 1e-3 * s {
                prop_assert!(filters_say_apart(f, pts, d), "{:?} at d = {:e}", pts, d);
            }
        }
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(20000))]

    /// Scaling every coordinate and `d` by a power of two (exact) keeps the decision and the
    /// type, and scales the value by its square when nothing underflows: the scaled (tiny
    /// extents), filtered and exact (huge extents) paths agree. No oracle needed, so many
    /// more cases.
    #[test]
    fn power_of_two_scaling_is_invariant(
        pts in prop::array::uniform4(prop::array::uniform3(prop_oneof![
            3 => (-6i32..=6).prop_map(f64::from),
            2 => -8.0f64..8.0,
        ])),
        d in 0.0f64..6.0,
        k in prop_oneof![-1000i32..-900, -300i32..300, 900i32..960],
    ) {
        let s = 2f64.powi(k / 2) * 2f64.powi(k - k / 2);
        let scaled = pts.map(|p| p.map(|x| x * s));
        prop_assume!(finite(&scaled) && scaled.iter().flatten().zip(pts.iter().flatten()).all(|(a, b)| a / s == *b));
        let ds = d * s;
        prop_assume!(ds.is_finite() && ds / s == d);
        let [p, a, b, c] = pts;
        let [ps, as_, bs, cs] = scaled;
        let (v, ty) = point_triangle_distance_sq(p, [a, b, c]);
        let (vs, tys) = point_triangle_distance_sq(ps, [as_, bs, cs]);
        prop_assert_eq!(ty, tys);
        prop_assert_eq!(
            point_triangle_within(p, [a, b, c], d).is_some(),
            point_triangle_within(ps, [as_, bs, cs], ds).is_some()
        );
        // Values: equal up to the bound's slack (different paths may round differently).
        let expect = v * s * s;
        if expect.is_normal() && vs.is_normal() {
            prop_assert!((vs - expect).abs() <= 1e-9 * expect.max(vs) + 1e-12 * s * s, "{} vs {}", vs, expect);
        }
        let (v, ty) = edge_edge_distance_sq(p, a, b, c);
        let (vs, tys) = edge_edge_distance_sq(ps, as_, bs, cs);
        prop_assert_eq!(ty, tys);
        prop_assert_eq!(
            edge_edge_within(p, a, b, c, d).is_some(),
            edge_edge_within(ps, as_, bs, cs, ds).is_some()
        );
        let expect = v * s * s;
        if expect.is_normal() && vs.is_normal() {
            prop_assert!((vs - expect).abs() <= 1e-9 * expect.max(vs) + 1e-12 * s * s, "{} vs {}", vs, expect);
        }
    }
}

// ---------------------------------------------------------------------------------------
// Distances equal to d to the last bit, and one ulp either side.
// ---------------------------------------------------------------------------------------

/// `(3, 4, 0) 2^e` and friends: exact distances `5 2^e`, `13 2^e`, `h 2^e`.
#[test]
fn distance_equal_to_d_to_the_last_bit() {
    for e in [-1074 + 60, -600, -30, -1, 0, 7, 40, 300, 900] {
        let s = |x: f64| x * 2f64.powi(e / 2) * 2f64.powi(e - e / 2);
        let t = [[0.0, 0.0, 0.0], [s(8.0), 0.0, 0.0], [0.0, s(8.0), 0.0]];
        let cases: [(P, f64, PointTriangle); 5] = [
            // Above the face: distance = height.
            ([s(1.0), s(2.0), s(3.0)], s(3.0), PointTriangle::Face),
            // Beside a corner in the plane: 3-4-5.
            ([s(-3.0), s(-4.0), 0.0], s(5.0), PointTriangle::Vertex0),
            // Off the corner t1 in 3D: (3, 4, 12) -> 13.
            ([s(11.0), s(-4.0), s(12.0)], s(13.0), PointTriangle::Vertex1),
            // Off the edge t0 t1 (y < 0), lifted: (0, -5, 12) -> 13.
            ([s(2.0), s(-5.0), s(12.0)], s(13.0), PointTriangle::Edge0),
            // Off the hypotenuse: (4, 4, 0) + (3, 3, 0) -> |(3,3)| not a float; use a
            // lift instead: p = (4, 4, 7) above the hypotenuse's midpoint... on the edge.
            ([s(4.0), s(4.0), s(7.0)], s(7.0), PointTriangle::Edge1),
        ];
        for (p, d, ty) in cases {
            let at = point_triangle_within(p, t, d);
            assert_eq!(at.map(|x| x.1), Some(ty), "e = {e}, p = {p:?}");
            if (d * d).is_finite() {
                assert!(
                    (at.unwrap().0 - d * d).abs() <= 8.0 * EPS * d * d + 1e-320,
                    "{at:?}"
                );
            }
            assert!(
                point_triangle_within(p, t, d.next_up()).is_some(),
                "e = {e}"
            );
            assert_eq!(
                point_triangle_within(p, t, d.next_down()),
                None,
                "e = {e}, {p:?}"
            );
            check_pt(&p, &t, &[d]).unwrap();
        }
        // Edge-edge: crossing at height h, parallel at distance 5 (3-4-5), collinear gap.
        let ee: [([P; 4], f64, EdgeEdge); 4] = [
            (
                [
                    [s(-1.0), 0.0, 0.0],
                    [s(1.0), 0.0, 0.0],
                    [0.0, s(-1.0), s(3.0)],
                    [0.0, s(1.0), s(3.0)],
                ],
                s(3.0),
                EdgeEdge::EaEb,
            ),
            (
                [
                    [0.0, 0.0, 0.0],
                    [s(2.0), 0.0, 0.0],
                    [s(1.0), s(3.0), s(4.0)],
                    [s(5.0), s(3.0), s(4.0)],
                ],
                s(5.0),
                EdgeEdge::EaEb0,
            ),
            (
                [
                    [0.0, 0.0, 0.0],
                    [s(2.0), 0.0, 0.0],
                    [s(7.0), 0.0, 0.0],
                    [s(9.0), 0.0, 0.0],
                ],
                s(5.0),
                EdgeEdge::Ea1Eb0,
            ),
            (
                [
                    [0.0, 0.0, 0.0],
                    [0.0, 0.0, s(2.0)],
                    [s(3.0), s(4.0), s(-1.0)],
                    [s(3.0), s(4.0), s(1.0)],
                ],
                s(5.0),
                EdgeEdge::EaEb1,
            ),
        ];
        for ([a0, a1, b0, b1], d, ty) in ee {
            let at = edge_edge_within(a0, a1, b0, b1, d);
            assert_eq!(
                at.map(|x| x.1),
                Some(ty),
                "e = {e}, {a0:?} {a1:?} {b0:?} {b1:?}"
            );
            assert!(edge_edge_within(a0, a1, b0, b1, d.next_up()).is_some());
            assert_eq!(
                edge_edge_within(a0, a1, b0, b1, d.next_down()),
                None,
                "e = {e}"
            );
            check_ee([&a0, &a1, &b0, &b1], &[d]).unwrap();
        }
    }
}

/// Touching (`d = 0`): a point on an edge, on a corner, inside the face; crossing and
/// overlapping edges; and one ulp away.
#[test]
fn touching_at_zero_distance() {
    let t = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
    for (p, ty) in [
        ([0.5, 0.0, 0.0], PointTriangle::Edge0),
        ([0.5, 0.5, 0.0], PointTriangle::Edge1),
        ([0.0, 0.25, 0.0], PointTriangle::Edge2),
        ([1.0, 0.0, 0.0], PointTriangle::Vertex1),
        ([0.25, 0.25, 0.0], PointTriangle::Face),
    ] {
        assert_eq!(point_triangle_within(p, t, 0.0), Some((0.0, ty)));
        let off = [p[0], p[1], f64::from_bits(1)];
        assert_eq!(point_triangle_within(off, t, 0.0), None);
        assert!(point_triangle_within(off, t, f64::from_bits(1)).is_some());
    }
    let a = [[-1.0, 0.0, 0.0], [1.0, 0.0, 0.0]];
    assert_eq!(
        edge_edge_within(a[0], a[1], [0.0, -1.0, 0.0], [0.0, 1.0, 0.0], 0.0),
        Some((0.0, EdgeEdge::EaEb))
    );
    assert_eq!(
        edge_edge_within(a[0], a[1], [0.0, -1.0, 1e-300], [0.0, 1.0, 1e-300], 0.0),
        None
    );
    // Overlapping collinear edges: a corner of one inside the other.
    assert_eq!(
        edge_edge_within(a[0], a[1], [0.5, 0.0, 0.0], [3.0, 0.0, 0.0], 0.0),
        Some((0.0, EdgeEdge::EaEb0))
    );
}

// ---------------------------------------------------------------------------------------
// Every type on a hand-built case, and IPC's names.
// ---------------------------------------------------------------------------------------

#[test]
fn every_point_triangle_type() {
    let t = [[0.0, 0.0, 0.0], [4.0, 0.0, 0.0], [0.0, 4.0, 0.0]];
    let cases = [
        ([-1.0, -1.0, 1.0], PointTriangle::Vertex0, 3.0),
        ([5.0, -1.0, 1.0], PointTriangle::Vertex1, 3.0),
        ([-1.0, 5.0, -1.0], PointTriangle::Vertex2, 3.0),
        ([2.0, -1.0, 1.0], PointTriangle::Edge0, 2.0),
        ([3.0, 3.0, 0.0], PointTriangle::Edge1, 2.0),
        ([-1.0, 2.0, 2.0], PointTriangle::Edge2, 5.0),
        ([1.0, 1.0, -2.0], PointTriangle::Face, 4.0),
    ];
    for (p, ty, d2) in cases {
        assert_eq!(point_triangle_distance_sq(p, t), (d2, ty), "{p:?}");
        assert_eq!(point_triangle_within(p, t, 10.0), Some((d2, ty)));
        assert_eq!(point_triangle_within(p, t, 1.0), None);
        assert_eq!(pt_oracle(&p, &t), (q(d2), ty));
    }
    let names: Vec<_> = PointTriangle::ALL.iter().map(|t| t.ipc_name()).collect();
    assert_eq!(
        names,
        ["P_T0", "P_T1", "P_T2", "P_E0", "P_E1", "P_E2", "P_T"]
    );
    assert!(PointTriangle::ALL
        .iter()
        .enumerate()
        .all(|(i, t)| *t as usize == i));
}

#[test]
fn every_edge_edge_type() {
    let a = ([0.0, 0.0, 0.0], [4.0, 0.0, 0.0]);
    let cases = [
        ([-1.0, 0.0, 1.0], [-1.0, 0.0, 5.0], EdgeEdge::Ea0Eb0, 2.0),
        ([-3.0, 0.0, 5.0], [-1.0, 0.0, 1.0], EdgeEdge::Ea0Eb1, 2.0),
        ([5.0, 1.0, 0.0], [9.0, 1.0, 0.0], EdgeEdge::Ea1Eb0, 2.0),
        ([9.0, 1.0, 0.0], [5.0, 1.0, 0.0], EdgeEdge::Ea1Eb1, 2.0),
        ([2.0, 1.0, 1.0], [2.0, 5.0, 5.0], EdgeEdge::EaEb0, 2.0),
        ([2.0, 5.0, 5.0], [2.0, 1.0, 1.0], EdgeEdge::EaEb1, 2.0),
        ([-1.0, -2.0, 1.0], [-1.0, 2.0, 1.0], EdgeEdge::Ea0Eb, 2.0),
        ([5.0, -2.0, 1.0], [5.0, 2.0, 1.0], EdgeEdge::Ea1Eb, 2.0),
        ([2.0, -2.0, 1.0], [2.0, 2.0, 1.0], EdgeEdge::EaEb, 1.0),
    ];
    for (b0, b1, ty, d2) in cases {
        assert_eq!(
            edge_edge_distance_sq(a.0, a.1, b0, b1),
            (d2, ty),
            "{b0:?} {b1:?}"
        );
        assert_eq!(edge_edge_within(a.0, a.1, b0, b1, 10.0), Some((d2, ty)));
        assert_eq!(edge_edge_within(a.0, a.1, b0, b1, 0.5), None);
        assert_eq!(ee_oracle(&a.0, &a.1, &b0, &b1), (q(d2), ty));
    }
    let names: Vec<_> = EdgeEdge::ALL.iter().map(|t| t.ipc_name()).collect();
    assert_eq!(
        names,
        [
            "EA0_EB0", "EA0_EB1", "EA1_EB0", "EA1_EB1", "EA_EB0", "EA_EB1", "EA0_EB", "EA1_EB",
            "EA_EB"
        ]
    );
}

/// Ties: the least total dimension, then the first in order.
#[test]
fn ties_resolve_to_the_least_dimension_then_the_first() {
    // Coincident corners t0 = t1: Vertex0.
    let t = [[0.0, 0.0, 0.0], [0.0, 0.0, 0.0], [0.0, 4.0, 0.0]];
    assert_eq!(
        point_triangle_distance_sq([0.0, -1.0, 0.0], t).1,
        PointTriangle::Vertex0
    );
    // Collinear triangle with t2 between t0 and t1, point beside t2: Vertex2.
    let t = [[0.0, 0.0, 0.0], [4.0, 0.0, 0.0], [2.0, 0.0, 0.0]];
    assert_eq!(
        point_triangle_distance_sq([2.0, 1.0, 0.0], t),
        (1.0, PointTriangle::Vertex2)
    );
    // Same triangle, point beside (1, 0, 0): inside the edges t0 t1 and t2 t0: Edge0.
    assert_eq!(
        point_triangle_distance_sq([1.0, 1.0, 0.0], t),
        (1.0, PointTriangle::Edge0)
    );
    // All three corners equal.
    let t = [[1.0, 2.0, 3.0]; 3];
    assert_eq!(
        point_triangle_distance_sq([1.0, 2.0, 4.0], t),
        (1.0, PointTriangle::Vertex0)
    );
    // Parallel overlapping edges: a corner pair if one is closest, else a corner and an edge.
    let (a0, a1) = ([0.0, 0.0, 0.0], [4.0, 0.0, 0.0]);
    assert_eq!(
        edge_edge_distance_sq(a0, a1, [4.0, 1.0, 0.0], [8.0, 1.0, 0.0]),
        (1.0, EdgeEdge::Ea1Eb0)
    );
    assert_eq!(
        edge_edge_distance_sq(a0, a1, [2.0, 1.0, 0.0], [8.0, 1.0, 0.0]),
        (1.0, EdgeEdge::EaEb0)
    );
    assert_eq!(
        edge_edge_distance_sq(a0, a1, [-2.0, 1.0, 0.0], [8.0, 1.0, 0.0]),
        (1.0, EdgeEdge::Ea0Eb)
    );
    // Zero-length edges.
    assert_eq!(
        edge_edge_distance_sq(a0, a0, [1.0, 1.0, 0.0], [1.0, 1.0, 0.0]),
        (2.0, EdgeEdge::Ea0Eb0)
    );
    assert_eq!(
        edge_edge_distance_sq(a0, a1, [1.0, 1.0, 0.0], [1.0, 1.0, 0.0]),
        (1.0, EdgeEdge::EaEb0)
    );
}

/// Extreme magnitudes: exact decisions and bounded values from subnormals to `f64::MAX`.
#[test]
fn extreme_magnitudes() {
    let tiny = f64::from_bits(1);
    let t = [
        [0.0, 0.0, 0.0],
        [4.0 * tiny, 0.0, 0.0],
        [0.0, 4.0 * tiny, 0.0],
    ];
    let p = [tiny, tiny, tiny];
    assert_eq!(
        point_triangle_within(p, t, tiny),
        Some((0.0, PointTriangle::Face))
    );
    assert_eq!(point_triangle_within(p, t, 0.0), None);
    check_pt(&p, &t, &[tiny, 2.0 * tiny]).unwrap();
    let big = f64::MAX / 4.0;
    let t = [[-big, -big, 0.0], [big, -big, 0.0], [0.0, big, 0.0]];
    let p = [0.0, 0.0, big];
    let (v, ty) = point_triangle_distance_sq(p, t);
    assert_eq!((v, ty), (f64::INFINITY, PointTriangle::Face));
    assert!(point_triangle_within(p, t, big).is_some());
    assert!(point_triangle_within(p, t, big.next_down()).is_none());
    check_pt(&p, &t, &[big]).unwrap();
    // Far from the origin: a unit triangle at 1e300 and a point 2^-20 above it.
    let o = 1e300;
    let t = [[o, o, o], [o * 2.0, o, o], [o, o * 2.0, o]];
    let p = [o * 1.25, o * 1.25, o + 2f64.powi(-20) * o];
    check_pt(&p, &t, &[1e280, 1e290]).unwrap();
    // Mixed: a subnormal offset from 1e300 coordinates.
    let e = [
        [1e300, 0.0, 0.0],
        [1e300, 0.0, tiny],
        [0.0, tiny, 0.0],
        [1.0, tiny, 0.0],
    ];
    check_ee([&e[0], &e[1], &e[2], &e[3]], &[1e300, 1.0]).unwrap();
}

/// Non-finite input and bad `d`: `None` (no panic).
#[test]
fn non_finite_and_bad_d() {
    let t = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
    let p = [0.25, 0.25, 0.5];
    assert_eq!(point_triangle_within(p, t, -1.0), None);
    assert_eq!(point_triangle_within(p, t, f64::NAN), None);
    assert_eq!(point_triangle_within(p, t, -0.0), None);
    assert!(point_triangle_within(p, t, f64::INFINITY).is_some());
    for bad in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
        for i in 0..12 {
            let mut pts = [p, t[0], t[1], t[2]];
            pts[i / 3][i % 3] = bad;
            let [p, a, b, c] = pts;
            assert_eq!(point_triangle_within(p, [a, b, c], 1.0), None, "{pts:?}");
            assert_eq!(point_triangle_within(p, [a, b, c], 1e10), None, "{pts:?}");
            assert!(point_triangle_distance_sq(p, [a, b, c]).0.is_nan());
            assert_eq!(edge_edge_within(p, a, b, c, 1.0), None, "{pts:?}");
            assert_eq!(edge_edge_within(p, a, b, c, 1e10), None, "{pts:?}");
            assert!(edge_edge_distance_sq(p, a, b, c).0.is_nan());
        }
    }
}

/// Regression: nearly parallel edges whose rounded directions are exactly parallel (the float
/// normal is zero, the exact one is not): the value came out NaN. Now exact.
#[test]
fn nearly_parallel_edges_with_a_zero_float_normal() {
    let a0 = [0.0, -1.0, 0.0];
    let a1 = [2.0, -3.0, -4.0];
    let b0 = [2.0, -2.0, -3.0];
    let b1 = [0.0, (0.0f64).next_down(), (1.0f64).next_down()];
    let (v, ty) = edge_edge_distance_sq(a0, a1, b0, b1);
    assert_eq!(ty, EdgeEdge::EaEb);
    assert!(v.is_finite());
    check_ee([&a0, &a1, &b0, &b1], &[0.5, 1.0]).unwrap();
}
