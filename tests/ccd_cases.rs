//! Hand-worked CCD cases: every degenerate configuration, contact exactly at t = 0 and at
//! t_max, one-ulp misses, exact scalings, minimum distances, and the typed errors. Each
//! expected answer is worked out in the comment beside it.

use dhcd::ccd::{self, CcdOptions, TOI_TOLERANCE};
use dhcd::Error;

type Q = [[f64; 3]; 4];

fn opts(t_max: f64, min_distance: f64) -> CcdOptions {
    CcdOptions::new(t_max, min_distance).unwrap()
}

/// Checks the filtered entry and the exact path alone against `expect` (None, or the
/// earliest contact time, which the result may undershoot by the tolerance).
fn vf(x0: Q, x1: Q, o: CcdOptions, expect: Option<f64>) {
    let got = ccd::vertex_face(&x0, &x1, &o);
    let exact = ccd::vertex_face_exact(&x0, &x1, &o);
    check("vertex-face", got, expect);
    check("vertex-face exact", exact, expect);
}

fn ee(x0: Q, x1: Q, o: CcdOptions, expect: Option<f64>) {
    let got = ccd::edge_edge(&x0, &x1, &o);
    let exact = ccd::edge_edge_exact(&x0, &x1, &o);
    check("edge-edge", got, expect);
    check("edge-edge exact", exact, expect);
}

fn check(what: &str, got: Option<f64>, expect: Option<f64>) {
    match (got, expect) {
        (None, None) => {}
        (Some(t), Some(e)) => assert!(
            t <= e && e - t <= TOI_TOLERANCE,
            "{what}: toi {t} for a true time {e}"
        ),
        _ => panic!("{what}: got {got:?}, expected {expect:?}"),
    }
}

const D: CcdOptions = CcdOptions {
    t_max: 1.0,
    min_distance: 0.0,
};

/// The unit right triangle in z = 0, static.
const TRI: [[f64; 3]; 3] = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];

fn vf_static_tri(p0: [f64; 3], p1: [f64; 3]) -> (Q, Q) {
    ([p0, TRI[0], TRI[1], TRI[2]], [p1, TRI[0], TRI[1], TRI[2]])
}

#[test]
fn vertex_through_triangle_at_known_time() {
    // z goes 1 -> -1: z = 1 - 2t = 0 at t = 1/2, at (1/4, 1/4), inside.
    let (a, b) = vf_static_tri([0.25, 0.25, 1.0], [0.25, 0.25, -1.0]);
    vf(a, b, D, Some(0.5));
    // z goes 1 -> -2: t = 1/3 (not dyadic: the toi is a lower bound within the tolerance).
    let (a, b) = vf_static_tri([0.25, 0.25, 1.0], [0.25, 0.25, -2.0]);
    vf(a, b, D, Some(1.0 / 3.0));
    // Passes beside the triangle: at t = 1/2 it is at (2, 2, 0), outside.
    let (a, b) = vf_static_tri([2.0, 2.0, 1.0], [2.0, 2.0, -1.0]);
    vf(a, b, D, None);
    // Stops short: z goes 1 -> 0.5, never 0.
    let (a, b) = vf_static_tri([0.25, 0.25, 1.0], [0.25, 0.25, 0.5]);
    vf(a, b, D, None);
}

#[test]
fn vertex_contact_at_the_ends_of_the_step() {
    // Touching at t = 0 (in the triangle), then leaving: toi exactly 0.
    let (a, b) = vf_static_tri([0.25, 0.25, 0.0], [0.25, 0.25, 1.0]);
    assert_eq!(ccd::vertex_face(&a, &b, &D), Some(0.0));
    assert_eq!(ccd::vertex_face_exact(&a, &b, &D), Some(0.0));
    // Arriving at t = 1 exactly.
    let (a, b) = vf_static_tri([0.25, 0.25, 1.0], [0.25, 0.25, 0.0]);
    assert_eq!(ccd::vertex_face(&a, &b, &D), Some(1.0));
    // Contact at t = 3/4 (z = 1 - 4t/3 with z1 = -1/3 is not exact; use z: 3 -> -1, z = 3 - 4t).
    let (a, b) = vf_static_tri([0.25, 0.25, 3.0], [0.25, 0.25, -1.0]);
    vf(a, b, D, Some(0.75));
    vf(a, b, opts(0.75, 0.0), Some(0.75)); // exactly at t_max
    assert_eq!(ccd::vertex_face(&a, &b, &opts(0.75, 0.0)), Some(0.75));
    vf(a, b, opts(0.5, 0.0), None); // after t_max
    vf(a, b, opts(0.7499999999999999, 0.0), None); // one ulp before the contact
                                                   // t_max = 0: only the configuration at t = 0 counts.
    vf(a, b, opts(0.0, 0.0), None);
    let (a, b) = vf_static_tri([0.5, 0.5, 0.0], [9.0, 9.0, 9.0]); // on the hypotenuse at t = 0
    vf(a, b, opts(0.0, 0.0), Some(0.0));
}

#[test]
fn vertex_on_edges_and_corners() {
    // Through the middle of edge ab (y = 0) at t = 1/2.
    let (a, b) = vf_static_tri([0.5, 0.0, 1.0], [0.5, 0.0, -1.0]);
    vf(a, b, D, Some(0.5));
    // Through corner c.
    let (a, b) = vf_static_tri([0.0, 1.0, 1.0], [0.0, 1.0, -1.0]);
    vf(a, b, D, Some(0.5));
    // Through the hypotenuse x + y = 1 at (0.5, 0.5).
    let (a, b) = vf_static_tri([0.5, 0.5, 1.0], [0.5, 0.5, -1.0]);
    vf(a, b, D, Some(0.5));
    // One tiny step outside edge ab (y = -2^-60): never in the triangle.
    let e = 2f64.powi(-60);
    let (a, b) = vf_static_tri([0.5, -e, 1.0], [0.5, -e, -1.0]);
    vf(a, b, D, None);
    // ... and inside.
    let (a, b) = vf_static_tri([0.5, e, 1.0], [0.5, e, -1.0]);
    vf(a, b, D, Some(0.5));
    // Outside the hypotenuse by one ulp of 0.5: x + y = 0.5 + next_up(0.5) > 1.
    let (a, b) = vf_static_tri([0.5, 0.5f64.next_up(), 1.0], [0.5, 0.5f64.next_up(), -1.0]);
    vf(a, b, D, None);
}

#[test]
fn vertex_coplanar_motion() {
    // In the triangle's plane all step (f = 0 identically): from (2, 1/4) to (-1, 1/4),
    // x = 2 - 3t; it enters across the hypotenuse at x = 3/4: t = 5/12.
    let (a, b) = vf_static_tri([2.0, 0.25, 0.0], [-1.0, 0.25, 0.0]);
    vf(a, b, D, Some(5.0 / 12.0));
    // In the plane and moving away: never.
    let (a, b) = vf_static_tri([2.0, 2.0, 0.0], [3.0, 3.0, 0.0]);
    vf(a, b, D, None);
    // Sliding along the line of edge ab from outside, reaching corner b at t = 1.
    let (a, b) = vf_static_tri([2.0, 0.0, 0.0], [1.0, 0.0, 0.0]);
    vf(a, b, D, Some(1.0));
    // Sliding along that line but stopping one unit short.
    let (a, b) = vf_static_tri([3.0, 0.0, 0.0], [2.0, 0.0, 0.0]);
    vf(a, b, D, None);
    // A rotating plane that carries the vertex along (vertex and triangle in the plane
    // z = s x at every t... here all four points move in the plane y = 0 rotated: the
    // triangle (0,0,0), (1,0,t), (0,1,0) and the vertex (1/4, 1/4, t/4) coplanar for all t).
    let x0 = [
        [0.25, 0.25, 0.0],
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
    ];
    let x1 = [
        [0.25, 0.25, 0.25],
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 1.0],
        [0.0, 1.0, 0.0],
    ];
    vf(x0, x1, D, Some(0.0));
}

#[test]
fn vertex_and_degenerate_triangles() {
    // Collinear corners on the x axis (a segment from 0 to 2): the vertex crosses it at
    // (1/2, 0, 0) at t = 1/2.
    let seg = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [2.0, 0.0, 0.0]];
    let q =
        |p0: [f64; 3], p1: [f64; 3]| ([p0, seg[0], seg[1], seg[2]], [p1, seg[0], seg[1], seg[2]]);
    let (a, b) = q([0.5, 1.0, 0.0], [0.5, -1.0, 0.0]);
    vf(a, b, D, Some(0.5));
    // Crossing the far part (x = 1.5, between b and c: the hull is the segment [0, 2]).
    let (a, b) = q([1.5, 1.0, 0.0], [1.5, -1.0, 0.0]);
    vf(a, b, D, Some(0.5));
    // Passing above it (z = 1): never.
    let (a, b) = q([0.5, 1.0, 1.0], [0.5, -1.0, 1.0]);
    vf(a, b, D, None);
    // Beyond its end (x = 2.5).
    let (a, b) = q([2.5, 1.0, 0.0], [2.5, -1.0, 0.0]);
    vf(a, b, D, None);
    // All three corners at the origin: the vertex goes through it at t = 1/2 ...
    let o = [[0.0; 3]; 3];
    let (a, b) = ([[-1.0; 3], o[0], o[1], o[2]], [[1.0; 3], o[0], o[1], o[2]]);
    vf(a, b, D, Some(0.5));
    // ... or misses it: at t = 1/2 it is at (0, 0, 1/4).
    let (a, b) = (
        [[-1.0; 3], o[0], o[1], o[2]],
        [[1.0, 1.0, 1.5], o[0], o[1], o[2]],
    );
    vf(a, b, D, None);
    // A triangle that collapses to a segment at t = 1/2 while the vertex sits on it:
    // corner c goes (0, 1, 0) -> (0, -1, 0), so at t = 1/2 the triangle is the segment
    // [0, 1] of the x axis, and the vertex (1/2, 0, 1 - 2t) reaches it then.
    let x0 = [
        [0.5, 0.0, 1.0],
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
    ];
    let x1 = [
        [0.5, 0.0, -1.0],
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [0.0, -1.0, 0.0],
    ];
    vf(x0, x1, D, Some(0.5));
}

#[test]
fn pairs_that_do_not_move() {
    let (a, _) = vf_static_tri([0.25, 0.25, 0.0], [0.0; 3]);
    vf(a, a, D, Some(0.0)); // inside, still
    let (a, _) = vf_static_tri([0.25, 0.25, 1e-300], [0.0; 3]);
    vf(a, a, D, None); // just above, still
    let e = [
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [0.5, -1.0, 0.0],
        [0.5, 1.0, 0.0],
    ];
    ee(e, e, D, Some(0.0)); // crossing, still
    let e = [
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [0.5, -1.0, 1e-300],
        [0.5, 1.0, 1e-300],
    ];
    ee(e, e, D, None);
}

#[test]
fn edges_crossing_and_missing() {
    // a on the x axis [-1, 1]; b along y at x = 0 coming down from z = 1 to z = -1: they
    // cross at the origin at t = 1/2.
    let a = [[-1.0, 0.0, 0.0], [1.0, 0.0, 0.0]];
    let q = |b0: [[f64; 3]; 2], b1: [[f64; 3]; 2]| -> (Q, Q) {
        ([a[0], a[1], b0[0], b0[1]], [a[0], a[1], b1[0], b1[1]])
    };
    let (x0, x1) = q(
        [[0.0, -1.0, 1.0], [0.0, 1.0, 1.0]],
        [[0.0, -1.0, -1.0], [0.0, 1.0, -1.0]],
    );
    ee(x0, x1, D, Some(0.5));
    // Same at x = 2: beyond a's end.
    let (x0, x1) = q(
        [[2.0, -1.0, 1.0], [2.0, 1.0, 1.0]],
        [[2.0, -1.0, -1.0], [2.0, 1.0, -1.0]],
    );
    ee(x0, x1, D, None);
    // At x = 1: through a's endpoint (a T contact).
    let (x0, x1) = q(
        [[1.0, -1.0, 1.0], [1.0, 1.0, 1.0]],
        [[1.0, -1.0, -1.0], [1.0, 1.0, -1.0]],
    );
    ee(x0, x1, D, Some(0.5));
    // At x = next_up(1): misses by one ulp.
    let x = 1f64.next_up();
    let (x0, x1) = q(
        [[x, -1.0, 1.0], [x, 1.0, 1.0]],
        [[x, -1.0, -1.0], [x, 1.0, -1.0]],
    );
    ee(x0, x1, D, None);
    // b's endpoint b0 = (0, 0, 1 - 2t) comes down on a's interior at t = 1/2.
    let (x0, x1) = q(
        [[0.0, 0.0, 1.0], [0.0, 0.0, 2.0]],
        [[0.0, 0.0, -1.0], [0.0, 0.0, 0.0]],
    );
    ee(x0, x1, D, Some(0.5));
    // Touching at t = 0 (b0 on a), then leaving.
    let (x0, x1) = q(
        [[0.0, 0.0, 0.0], [0.0, 0.0, 1.0]],
        [[0.0, 0.0, 1.0], [0.0, 0.0, 2.0]],
    );
    ee(x0, x1, D, Some(0.0));
    // Meeting exactly at t = 1.
    let (x0, x1) = q(
        [[0.0, -1.0, 1.0], [0.0, 1.0, 1.0]],
        [[0.0, -1.0, 0.0], [0.0, 1.0, 0.0]],
    );
    ee(x0, x1, D, Some(1.0));
    assert_eq!(ccd::edge_edge(&x0, &x1, &D), Some(1.0));
    ee(x0, x1, opts(0.5, 0.0), None);
}

#[test]
fn parallel_and_collinear_edges() {
    let a = [[-1.0, 0.0, 0.0], [1.0, 0.0, 0.0]];
    let q = |b0: [[f64; 3]; 2], b1: [[f64; 3]; 2]| -> (Q, Q) {
        ([a[0], a[1], b0[0], b0[1]], [a[0], a[1], b1[0], b1[1]])
    };
    // b parallel to a in the plane y = 0, coming down: collinear and overlapping at t = 1/2
    // (coplanar all step: f = 0 identically).
    let (x0, x1) = q(
        [[-1.0, 0.0, 1.0], [1.0, 0.0, 1.0]],
        [[-1.0, 0.0, -1.0], [1.0, 0.0, -1.0]],
    );
    ee(x0, x1, D, Some(0.5));
    // Parallel but offset (y = 1/2): never.
    let (x0, x1) = q(
        [[-1.0, 0.5, 1.0], [1.0, 0.5, 1.0]],
        [[-1.0, 0.5, -1.0], [1.0, 0.5, -1.0]],
    );
    ee(x0, x1, D, None);
    // Collinear on the x axis, b sliding from [3, 4] to [1, 2]: b0 reaches a1 = 1 at t = 1.
    let (x0, x1) = q(
        [[3.0, 0.0, 0.0], [4.0, 0.0, 0.0]],
        [[1.0, 0.0, 0.0], [2.0, 0.0, 0.0]],
    );
    ee(x0, x1, D, Some(1.0));
    // ... from [4, 5] to [2, 3]: stops short.
    let (x0, x1) = q(
        [[4.0, 0.0, 0.0], [5.0, 0.0, 0.0]],
        [[2.0, 0.0, 0.0], [3.0, 0.0, 0.0]],
    );
    ee(x0, x1, D, None);
    // ... from [5, 6] to [-3, -2]: b0 = 5 - 8t reaches 1 at t = 1/2.
    let (x0, x1) = q(
        [[5.0, 0.0, 0.0], [6.0, 0.0, 0.0]],
        [[-3.0, 0.0, 0.0], [-2.0, 0.0, 0.0]],
    );
    ee(x0, x1, D, Some(0.5));
    // Collinear and overlapping from the start.
    let (x0, x1) = q(
        [[0.5, 0.0, 0.0], [3.0, 0.0, 0.0]],
        [[0.5, 0.0, 0.0], [3.0, 0.0, 0.0]],
    );
    ee(x0, x1, D, Some(0.0));
}

#[test]
fn zero_length_edges() {
    // b is a point coming down through a's interior at t = 1/2.
    let a = [[-1.0, 0.0, 0.0], [1.0, 0.0, 0.0]];
    let x0 = [a[0], a[1], [0.5, 0.0, 1.0], [0.5, 0.0, 1.0]];
    let x1 = [a[0], a[1], [0.5, 0.0, -1.0], [0.5, 0.0, -1.0]];
    ee(x0, x1, D, Some(0.5));
    // Both points: (0,0,0) still and (-1 + 2t, 0, 0): meet at t = 1/2.
    let x0 = [[0.0; 3], [0.0; 3], [-1.0, 0.0, 0.0], [-1.0, 0.0, 0.0]];
    let x1 = [[0.0; 3], [0.0; 3], [1.0, 0.0, 0.0], [1.0, 0.0, 0.0]];
    ee(x0, x1, D, Some(0.5));
    // ... or miss by 2^-70 in y.
    let e = 2f64.powi(-70);
    let x0 = [[0.0; 3], [0.0; 3], [-1.0, e, 0.0], [-1.0, e, 0.0]];
    let x1 = [[0.0; 3], [0.0; 3], [1.0, e, 0.0], [1.0, e, 0.0]];
    ee(x0, x1, D, None);
    // A segment that shrinks to a point while a point passes through its middle.
    let x0 = [
        [-1.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [0.0, 1.0, 0.0],
    ];
    let x1 = [
        [0.0, 0.0, 0.0],
        [0.0, 0.0, 0.0],
        [0.0, -1.0, 0.0],
        [0.0, -1.0, 0.0],
    ];
    ee(x0, x1, D, Some(0.5));
}

#[test]
fn exact_scalings_change_nothing() {
    // Scaling all coordinates by a power of two is exact and moves no contact.
    let cases: Vec<(bool, Q, Q, Option<f64>)> = vec![
        {
            let (a, b) = vf_static_tri([0.25, 0.25, 1.0], [0.25, 0.25, -2.0]);
            (true, a, b, Some(1.0 / 3.0))
        },
        {
            let (a, b) = vf_static_tri([0.5, -2f64.powi(-60), 1.0], [0.5, -2f64.powi(-60), -1.0]);
            (true, a, b, None)
        },
        {
            let (a, b) = vf_static_tri([2.0, 0.25, 0.0], [-1.0, 0.25, 0.0]);
            (true, a, b, Some(5.0 / 12.0))
        },
        (
            false,
            [
                [-1.0, 0.0, 0.0],
                [1.0, 0.0, 0.0],
                [0.0, -1.0, 1.0],
                [0.0, 1.0, 1.0],
            ],
            [
                [-1.0, 0.0, 0.0],
                [1.0, 0.0, 0.0],
                [0.0, -1.0, -2.0],
                [0.0, 1.0, -2.0],
            ],
            Some(1.0 / 3.0),
        ),
    ];
    for k in [-1000, -600, -100, -1, 1, 100, 600, 900] {
        let s = 2f64.powi(k);
        for (is_vf, a, b, expect) in &cases {
            let sc = |q: &Q| q.map(|p| p.map(|c| c * s));
            let (a, b) = (sc(a), sc(b));
            if *is_vf {
                vf(a, b, D, *expect);
            } else {
                ee(a, b, D, *expect);
            }
        }
    }
    // Subnormal coordinates (2^-1070 = 16 times the least subnormal).
    let s = 2f64.powi(-1070);
    let (a, b) = vf_static_tri([0.25, 0.25, 1.0], [0.25, 0.25, -1.0]);
    let sc = |q: &Q| q.map(|p| p.map(|c| c * s));
    vf(sc(&a), sc(&b), D, Some(0.5));
    // Coordinates near the largest f64 (differences overflow in floats).
    let s = 2f64.powi(1020);
    let sc = |q: &Q| q.map(|p| p.map(|c| c * s));
    vf(sc(&a), sc(&b), D, Some(0.5));
}

#[test]
fn minimum_distance() {
    // The vertex comes down to z = 0.2 (at t = 1) above the triangle's interior.
    let (a, b) = vf_static_tri([0.25, 0.25, 1.0], [0.25, 0.25, 0.2]);
    vf(a, b, D, None);
    vf(a, b, opts(1.0, 0.2), Some(1.0)); // distance exactly 0.2 (the same f64) at t = 1
    vf(a, b, opts(1.0, 0.2f64.next_down()), None);
    // z = 1 - t comes within 0.5 at t = 1/2.
    let (a, b) = vf_static_tri([0.25, 0.25, 1.0], [0.25, 0.25, 0.0]);
    vf(a, b, opts(1.0, 0.5), Some(0.5));
    // Beside edge ab (y = -0.3) coming down: distance^2 = 0.09 + (1 - 2t)^2, least 0.3
    // at t = 1/2 exactly.
    let (a, b) = vf_static_tri([0.5, -0.3, 1.0], [0.5, -0.3, -1.0]);
    vf(a, b, D, None);
    vf(a, b, opts(1.0, 0.3), Some(0.5));
    vf(a, b, opts(1.0, 0.29), None);
    // Beyond corner b = (1, 0, 0): the vertex at (1 + 3/4, 0, 1 - 2t), distance 3/4 at 1/2.
    let (a, b) = vf_static_tri([1.75, 0.0, 1.0], [1.75, 0.0, -1.0]);
    vf(a, b, opts(1.0, 0.75), Some(0.5));
    vf(a, b, opts(1.0, 0.75f64.next_down()), None);
    // Already within the distance at t = 0.
    vf(a, b, opts(1.0, 2.0), Some(0.0));
    // Edges: b along y at height z = 1 - t/2, over a on the x axis; distance z.
    let x0 = [
        [-1.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [0.0, -1.0, 1.0],
        [0.0, 1.0, 1.0],
    ];
    let x1 = [
        [-1.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [0.0, -1.0, 0.5],
        [0.0, 1.0, 0.5],
    ];
    ee(x0, x1, D, None);
    ee(x0, x1, opts(1.0, 0.5), Some(1.0));
    ee(x0, x1, opts(1.0, 0.75), Some(0.5));
    ee(x0, x1, opts(1.0, 0.25), None);
    // Parallel edges 0.5 apart, still: within 0.5, not within less.
    let x0 = [
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [0.5, 0.5, 0.0],
        [3.0, 0.5, 0.0],
    ];
    ee(x0, x0, opts(1.0, 0.5), Some(0.0));
    ee(x0, x0, opts(1.0, 0.4999999999999999), None);
    // A contact at delta = 0 is one for any delta, at an earlier or equal time.
    let (a, b) = vf_static_tri([0.25, 0.25, 1.0], [0.25, 0.25, -1.0]);
    let t = ccd::vertex_face(&a, &b, &opts(1.0, 1e-9)).unwrap();
    assert!(t <= 0.5 && t > 0.5 - 1e-8);
}

#[test]
fn invalid_input_is_a_typed_error() {
    assert_eq!(CcdOptions::new(1.5, 0.0), Err(Error::InvalidTimeLimit(1.5)));
    assert!(matches!(
        CcdOptions::new(f64::NAN, 0.0),
        Err(Error::InvalidTimeLimit(_))
    ));
    assert_eq!(
        CcdOptions::new(-0.5, 0.0),
        Err(Error::InvalidTimeLimit(-0.5))
    );
    assert_eq!(
        CcdOptions::new(1.0, -1.0),
        Err(Error::InvalidMinDistance(-1.0))
    );
    assert!(matches!(
        CcdOptions::new(1.0, f64::INFINITY),
        Err(Error::InvalidMinDistance(_))
    ));
    assert!(matches!(
        CcdOptions::new(1.0, f64::NAN),
        Err(Error::InvalidMinDistance(_))
    ));
    assert!(CcdOptions::new(0.0, 0.0).is_ok() && CcdOptions::new(1.0, 1e300).is_ok());
    assert_eq!(CcdOptions::default(), CcdOptions::new(1.0, 0.0).unwrap());
    let (a, mut b) = vf_static_tri([0.25, 0.25, 1.0], [0.25, 0.25, -1.0]);
    b[2][1] = f64::NAN;
    assert!(matches!(
        ccd::try_vertex_face(&a, &b, &D),
        Err(Error::NonFiniteCcdPoint { point: 6, .. })
    ));
    b[2][1] = f64::INFINITY;
    assert!(matches!(
        ccd::try_edge_edge(&a, &b, &D),
        Err(Error::NonFiniteCcdPoint { point: 6, .. })
    ));
    let bad = CcdOptions {
        t_max: 2.0,
        min_distance: 0.0,
    };
    let (a, b) = vf_static_tri([0.25, 0.25, 1.0], [0.25, 0.25, -1.0]);
    assert_eq!(
        ccd::try_vertex_face(&a, &b, &bad),
        Err(Error::InvalidTimeLimit(2.0))
    );
    assert!(ccd::try_vertex_face(&a, &b, &D).unwrap().is_some());
    let msg = Error::NonFiniteCcdPoint {
        point: 3,
        position: [f64::NAN, 0.0, 0.0],
    }
    .to_string();
    assert!(msg.contains("point 3") && !msg.contains('\n'));
}

/// The filtered and the exact answers agree: the same decision, and both times within the
/// tolerance below the true one (so within it of each other).
fn agree(what: &str, filtered: Option<f64>, exact: Option<f64>) {
    match (filtered, exact) {
        (None, None) => {}
        (Some(a), Some(b)) => assert!((a - b).abs() <= TOI_TOLERANCE, "{what}: {a} vs {b}"),
        _ => panic!("{what}: filtered {filtered:?}, exact {exact:?}"),
    }
}

#[test]
fn minimum_distance_filter_agrees_with_the_exact_path() {
    // The delta > 0 filter decides in interval arithmetic where it can: on the first queries
    // of every sample set at three distances, and on random motions of points in the unit
    // cube passing each other at about those distances, the filtered entry decides as the
    // exact path alone.
    let mut counts = [0usize; 2];
    let mut run = |what: &str, vf: bool, x0: &Q, x1: &Q, o: &CcdOptions| {
        let (a, b) = if vf {
            (
                ccd::vertex_face(x0, x1, o),
                ccd::vertex_face_exact(x0, x1, o),
            )
        } else {
            (ccd::edge_edge(x0, x1, o), ccd::edge_edge_exact(x0, x1, o))
        };
        agree(
            &format!("{what} delta {}: {x0:?} -> {x1:?}", o.min_distance),
            a,
            b,
        );
        counts[a.is_some() as usize] += 1;
    };
    for delta in [1e-6, 1e-3, 0.1] {
        let o = opts(1.0, delta);
        for (_, kind, qs) in super::ccd_samples::all_samples() {
            for (x0, x1, _) in qs.iter().take(8) {
                run(kind, kind == "vertex-face", x0, x1, &o);
            }
        }
    }
    let mut state = 99u64;
    let mut unit = || (dhcd::shapes::splitmix64(&mut state) >> 11) as f64 / (1u64 << 53) as f64;
    for delta in [1e-3, 0.05, 0.2] {
        for t_max in [1.0, 0.6] {
            let o = opts(t_max, delta);
            for k in 0..48 {
                let x0: Q = std::array::from_fn(|_| std::array::from_fn(|_| unit()));
                let x1: Q = std::array::from_fn(|_| std::array::from_fn(|_| unit()));
                run("random", k % 2 == 0, &x0, &x1, &o);
            }
        }
    }
    assert!(counts[0] > 20 && counts[1] > 20, "{counts:?}");
}
