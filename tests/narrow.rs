//! Tests of `dhcd::narrow`: hand-built cases for every (degenerate) configuration, exact
//! touching and one-ulp perturbations, and property tests against an independent exact
//! reference (Minkowski difference + Caratheodory in `i128`).

use dhcd::narrow::{
    brute_force_pairs, brute_force_self_pairs, intersection_segment, triangles_intersect,
};
use dhcd::Mesh;
use dhcd_kernels::reference::{pair_verdict, Verdict};
use proptest::prelude::*;

type Tri = [[f32; 3]; 3];

// ---------------------------------------------------------------------------------------
// Independent reference: A and B intersect iff 0 is in conv{a_i - b_j}; by Caratheodory,
// iff 0 lies in a simplex of affinely independent difference vectors (point, segment,
// triangle or tetrahedron). Exact in i128 for integer coordinates up to 2^26.
// ---------------------------------------------------------------------------------------

type V = [i128; 3];

fn sub(a: V, b: V) -> V {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}
fn cross(a: V, b: V) -> V {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}
fn dot(a: V, b: V) -> i128 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}
fn det(a: V, b: V, c: V) -> i128 {
    dot(a, cross(b, c))
}
/// Signed volume of the tetrahedron `p q r s` (times 6).
fn vol(p: V, q: V, r: V, s: V) -> i128 {
    det(sub(q, p), sub(r, p), sub(s, p))
}

fn origin_in_hull(s: &[V]) -> bool {
    let o = [0; 3];
    let n = s.len();
    if s.contains(&o) {
        return true;
    }
    for i in 0..n {
        for j in i + 1..n {
            let (u, v) = (s[i], s[j]);
            if cross(u, v) == o && dot(u, v) < 0 {
                return true;
            }
            for k in j + 1..n {
                let w = s[k];
                let nrm = cross(sub(v, u), sub(w, u));
                if nrm != o
                    && det(u, v, w) == 0
                    && dot(nrm, cross(u, v)) >= 0
                    && dot(nrm, cross(v, w)) >= 0
                    && dot(nrm, cross(w, u)) >= 0
                {
                    return true;
                }
                for &x in &s[k + 1..] {
                    let d = vol(u, v, w, x);
                    if d == 0 {
                        continue;
                    }
                    let l0 = vol(o, v, w, x);
                    let l1 = vol(u, o, w, x);
                    let l2 = vol(u, v, o, x);
                    let l3 = vol(u, v, w, o);
                    if [l0, l1, l2, l3]
                        .iter()
                        .all(|&li| li == 0 || (li > 0) == (d > 0))
                    {
                        return true;
                    }
                }
            }
        }
    }
    false
}

/// Exact reference on coordinates that are integers after scaling by `2^scale`.
fn reference_scaled(a: &Tri, b: &Tri, scale: i32) -> bool {
    let f = 2f64.powi(scale);
    let conv = |p: &[f32; 3]| -> V {
        p.map(|c| {
            let x = f64::from(c) * f;
            assert!(
                x == x.trunc() && x.abs() <= 67_108_864.0,
                "not a grid point: {c}"
            );
            x as i128
        })
    };
    let mut s = Vec::with_capacity(9);
    for p in a {
        for q in b {
            s.push(sub(conv(p), conv(q)));
        }
    }
    origin_in_hull(&s)
}

fn reference(a: &Tri, b: &Tri) -> bool {
    reference_scaled(a, b, 0)
}

// ---------------------------------------------------------------------------------------
// Helpers
// ---------------------------------------------------------------------------------------

const PERMS: [[usize; 3]; 6] = [
    [0, 1, 2],
    [1, 2, 0],
    [2, 0, 1],
    [0, 2, 1],
    [2, 1, 0],
    [1, 0, 2],
];

fn permute(t: &Tri, p: [usize; 3]) -> Tri {
    [t[p[0]], t[p[1]], t[p[2]]]
}

fn dist_point_segment(x: [f64; 3], a: [f64; 3], b: [f64; 3]) -> f64 {
    let ab = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
    let ax = [x[0] - a[0], x[1] - a[1], x[2] - a[2]];
    let l2: f64 = ab.iter().map(|c| c * c).sum();
    let t = if l2 > 0.0 {
        ((0..3).map(|k| ab[k] * ax[k]).sum::<f64>() / l2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    (0..3)
        .map(|k| (x[k] - a[k] - t * ab[k]).powi(2))
        .sum::<f64>()
        .sqrt()
}

/// Distance (f64, approximate) from `x` to the closed triangle `t` (possibly degenerate).
fn dist_point_tri(x: [f32; 3], t: &Tri) -> f64 {
    let x = x.map(f64::from);
    let [a, b, c] = t.map(|p| p.map(f64::from));
    let e = dist_point_segment(x, a, b)
        .min(dist_point_segment(x, b, c))
        .min(dist_point_segment(x, c, a));
    let u = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
    let v = [c[0] - a[0], c[1] - a[1], c[2] - a[2]];
    let w = [x[0] - a[0], x[1] - a[1], x[2] - a[2]];
    let n = [
        u[1] * v[2] - u[2] * v[1],
        u[2] * v[0] - u[0] * v[2],
        u[0] * v[1] - u[1] * v[0],
    ];
    let nn: f64 = n.iter().map(|c| c * c).sum();
    if nn == 0.0 {
        return e;
    }
    let trip = |p: [f64; 3], q: [f64; 3]| {
        let cr = [
            p[1] * q[2] - p[2] * q[1],
            p[2] * q[0] - p[0] * q[2],
            p[0] * q[1] - p[1] * q[0],
        ];
        (0..3).map(|k| cr[k] * n[k]).sum::<f64>()
    };
    // Barycentric coordinates of the projection of x onto the plane.
    let l1 = trip(w, v) / nn;
    let l2 = trip(u, w) / nn;
    if l1 >= 0.0 && l2 >= 0.0 && l1 + l2 <= 1.0 {
        let d: f64 = (0..3).map(|k| w[k] * n[k]).sum();
        (d.abs() / nn.sqrt()).min(e)
    } else {
        e
    }
}

fn scale_of(t: &Tri) -> f64 {
    t.iter()
        .flatten()
        .fold(1.0f64, |m, &c| m.max(f64::from(c).abs()))
}

/// Checks the contact segment of an (ordered) pair: Some iff intersect, points on both.
fn check_segment(a: &Tri, b: &Tri, hit: bool) {
    let seg = intersection_segment(a, b);
    assert_eq!(seg.is_some(), hit, "segment presence for {a:?} {b:?}");
    if let Some(seg) = seg {
        let tol = 1e-5 * scale_of(a).max(scale_of(b));
        for p in seg {
            assert!(
                dist_point_tri(p, a) <= tol && dist_point_tri(p, b) <= tol,
                "segment point {p:?} not on both {a:?} {b:?}"
            );
        }
    }
}

/// The narrow kernel's certified verdict (`f32` filters and canonical form) never
/// contradicts the exact answer `want`; `Undecided` is always allowed.
fn check_verdict(a: &Tri, b: &Tri, want: bool) {
    match pair_verdict(a, b) {
        Verdict::Contact => assert!(want, "kernel certified a contact: {a:?} {b:?}"),
        Verdict::Apart => assert!(!want, "kernel certified apart: {a:?} {b:?}"),
        Verdict::Undecided => {}
    }
}

/// Asserts `expected` for both argument orders and all 36 corner permutations, for the
/// decision, the kernel's verdict and the segment's presence; also checks the exact reference when `scale` is
/// given (coordinates integral after scaling by `2^scale`).
fn check_scaled(a: Tri, b: Tri, expected: bool, scale: Option<i32>) {
    if let Some(s) = scale {
        assert_eq!(
            reference_scaled(&a, &b, s),
            expected,
            "reference disagrees with the hand-written expectation for {a:?} {b:?}"
        );
    }
    for pa in PERMS {
        for pb in PERMS {
            let (x, y) = (permute(&a, pa), permute(&b, pb));
            assert_eq!(triangles_intersect(&x, &y), expected, "{x:?} vs {y:?}");
            assert_eq!(triangles_intersect(&y, &x), expected, "{y:?} vs {x:?}");
            check_verdict(&x, &y, expected);
            check_verdict(&y, &x, expected);
            check_segment(&x, &y, expected);
            check_segment(&y, &x, expected);
        }
    }
}

/// Hand-built cases use multiples of 1/4.
fn check(a: Tri, b: Tri, expected: bool) {
    check_scaled(a, b, expected, Some(2));
}

fn up(x: f32) -> f32 {
    x.next_up()
}
fn down(x: f32) -> f32 {
    x.next_down()
}

/// Base triangle in the plane z = 0.
const A: Tri = [[0.0, 0.0, 0.0], [4.0, 0.0, 0.0], [0.0, 4.0, 0.0]];

// ---------------------------------------------------------------------------------------
// General position
// ---------------------------------------------------------------------------------------

#[test]
fn crossing_triangles_intersect() {
    check(
        A,
        [[1.0, 1.0, -1.0], [3.0, 1.0, -1.0], [1.0, 1.0, 1.0]],
        true,
    );
    check(
        A,
        [[1.0, 1.0, -2.0], [2.0, 1.0, 2.0], [1.0, 2.0, 2.0]],
        true,
    );
}

#[test]
fn separated_triangles_do_not_intersect() {
    // Far apart (AABB reject).
    check(
        A,
        [[10.0, 10.0, 10.0], [11.0, 10.0, 10.0], [10.0, 11.0, 10.0]],
        false,
    );
    // Boxes overlap, strictly above the plane.
    check(
        A,
        [[1.0, 1.0, 1.0], [3.0, 1.0, 2.0], [1.0, 1.0, 3.0]],
        false,
    );
    // Crosses the plane outside the triangle (beyond the hypotenuse).
    check(
        A,
        [[3.0, 3.0, -1.0], [4.0, 3.0, 1.0], [3.0, 4.0, 1.0]],
        false,
    );
    // Both straddle each other's plane but miss (interlocked ring-like near miss).
    check(
        [[0.0, 0.0, 0.0], [4.0, 0.0, 0.0], [2.0, 0.0, 4.0]],
        [[2.0, -1.0, 6.0], [2.0, 1.0, 6.0], [2.0, 0.0, 4.5]],
        false,
    );
}

#[test]
fn plane_of_b_misses_a() {
    // b crosses a's plane beside a; a lies strictly on one side of b's plane.
    check(
        [[0.0, 0.0, 0.0], [2.0, 0.0, 0.0], [0.0, 2.0, 0.0]],
        [[3.0, 0.0, -1.0], [3.0, 0.0, 1.0], [1.0, 3.0, 0.0]],
        false,
    );
}

// ---------------------------------------------------------------------------------------
// Touching (exactly representable)
// ---------------------------------------------------------------------------------------

#[test]
fn vertex_touches_face_edge_and_vertex() {
    // Vertex on the face interior.
    check(A, [[1.0, 1.0, 0.0], [2.0, 1.0, 2.0], [1.0, 2.0, 2.0]], true);
    // Vertex on an edge.
    check(
        A,
        [[2.0, 0.0, 0.0], [2.0, 1.0, 2.0], [2.0, -1.0, 2.0]],
        true,
    );
    // Vertex on a vertex.
    check(
        A,
        [[4.0, 0.0, 0.0], [5.0, 1.0, 2.0], [5.0, -1.0, 2.0]],
        true,
    );
    // Vertex just outside an edge in the plane (no touch).
    check(
        A,
        [[2.0, -1.0, 0.0], [2.0, 1.0, 2.0], [2.0, -1.0, 2.0]],
        false,
    );
}

#[test]
fn skew_edges_touch_at_a_point() {
    // b (in the plane x = 2) has an edge lying in a's plane, overlapping a.
    check(
        A,
        [[2.0, -1.0, 0.0], [2.0, 1.0, 0.0], [2.0, 0.0, -3.0]],
        true,
    );
    // Same but b's edge lifted to z = 1: misses.
    check(
        A,
        [[2.0, -1.0, 1.0], [2.0, 1.0, 1.0], [2.0, 0.0, 3.0]],
        false,
    );
    // Edge-edge touching from outside the plane on both sides.
    check(
        A,
        [[2.0, -1.0, 0.0], [2.0, -0.5, 1.0], [2.0, -0.5, -1.0]],
        false,
    );
    check(
        A,
        [[2.0, -1.0, 0.0], [2.0, 0.0, 1.0], [2.0, 0.0, -1.0]],
        true,
    );
    check(
        A,
        [[2.0, -1.0, 1.0], [2.0, 1.0, -1.0], [2.0, -3.0, 0.0]],
        true,
    );
}

/// A wall standing on a's plane on one of its edges (the rim of a flat cap and the side of a
/// cylinder): it meets a exactly where that edge meets a, wherever the rest of it is.
#[test]
fn wall_standing_on_the_plane() {
    // The edge crosses a's boundary.
    check(
        A,
        [[-1.0, 1.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 2.0]],
        true,
    );
    // The edge ends on a's hypotenuse.
    check(A, [[3.0, 1.0, 0.0], [5.0, 1.0, 0.0], [4.0, 1.0, 2.0]], true);
    // The edge stops just short of a (the wall's apex leans over a: no touch).
    check(
        A,
        [[-3.0, 1.0, 0.0], [-0.25, 1.0, 0.0], [2.0, 1.0, 2.0]],
        false,
    );
    // Edge beside a along its leg, wall leaning away or over it.
    check(
        A,
        [[-0.25, 0.0, 0.0], [-0.25, 4.0, 0.0], [-2.0, 2.0, 2.0]],
        false,
    );
    check(
        A,
        [[-0.25, 0.0, 0.0], [-0.25, 4.0, 0.0], [2.0, 2.0, 2.0]],
        false,
    );
    // Degenerate walls: a segment standing on its lower end, and a point.
    check(A, [[1.0, 1.0, 0.0], [1.0, 1.0, 2.0], [1.0, 1.0, 1.0]], true);
    check(
        A,
        [[5.0, 1.0, 0.0], [1.0, 1.0, 2.0], [3.0, 1.0, 1.0]],
        false,
    );
}

#[test]
fn shared_vertex_and_shared_edge() {
    // Shared vertex position, fanning out of the plane.
    check(
        A,
        [[0.0, 0.0, 0.0], [-1.0, -1.0, 2.0], [-2.0, 0.0, 1.0]],
        true,
    );
    // Shared edge, folded.
    check(
        A,
        [[0.0, 0.0, 0.0], [4.0, 0.0, 0.0], [2.0, -2.0, 3.0]],
        true,
    );
    // Shared edge, coplanar, on the other side.
    check(
        A,
        [[0.0, 0.0, 0.0], [4.0, 0.0, 0.0], [2.0, -2.0, 0.0]],
        true,
    );
}

#[test]
fn identical_triangles() {
    check(A, A, true);
    let t = [[1.0, 2.0, 3.0], [-1.0, 0.5, 2.0], [3.0, -2.0, -1.0]];
    for p in PERMS {
        assert!(triangles_intersect(&t, &permute(&t, p)));
    }
}

// ---------------------------------------------------------------------------------------
// Coplanar
// ---------------------------------------------------------------------------------------

#[test]
fn coplanar_cases() {
    // Overlap (edges cross, no vertex inside the other).
    check(
        A,
        [[-1.0, 1.0, 0.0], [3.0, 1.0, 0.0], [1.0, -1.0, 0.0]],
        true,
    );
    // Containment (b inside a, and a contains b).
    check(A, [[1.0, 1.0, 0.0], [2.0, 1.0, 0.0], [1.0, 2.0, 0.0]], true);
    // Disjoint, boxes overlap.
    check(
        A,
        [[3.0, 3.0, 0.0], [4.0, 4.0, 0.0], [3.0, 4.0, 0.0]],
        false,
    );
    // Vertex on edge (hypotenuse x + y = 4).
    check(A, [[2.0, 2.0, 0.0], [4.0, 4.0, 0.0], [3.0, 5.0, 0.0]], true);
    // Collinear edges overlapping, triangles on opposite sides.
    check(
        A,
        [[2.0, 0.0, 0.0], [6.0, 0.0, 0.0], [4.0, -2.0, 0.0]],
        true,
    );
    // Collinear edges touching at an endpoint only.
    check(
        A,
        [[4.0, 0.0, 0.0], [6.0, 0.0, 0.0], [5.0, -2.0, 0.0]],
        true,
    );
    // Collinear edges, a gap between.
    check(
        A,
        [[5.0, 0.0, 0.0], [6.0, 0.0, 0.0], [5.0, -2.0, 0.0]],
        false,
    );
    // Star of David: two triangles, no vertex inside the other.
    check(
        [[0.0, 0.0, 0.0], [6.0, 0.0, 0.0], [3.0, 6.0, 0.0]],
        [[0.0, 4.0, 0.0], [6.0, 4.0, 0.0], [3.0, -2.0, 0.0]],
        true,
    );
    // Coplanar in a tilted plane x + y + z = 4.
    check(
        [[4.0, 0.0, 0.0], [0.0, 4.0, 0.0], [0.0, 0.0, 4.0]],
        [[2.0, 2.0, 0.0], [2.0, 0.0, 2.0], [0.0, 2.0, 2.0]],
        true,
    );
    check(
        [[4.0, 0.0, 0.0], [0.0, 4.0, 0.0], [0.0, 0.0, 4.0]],
        [[3.0, 3.0, -2.0], [5.0, 3.0, -4.0], [3.0, 5.0, -4.0]],
        false,
    );
}

// ---------------------------------------------------------------------------------------
// Degenerate triangles
// ---------------------------------------------------------------------------------------

/// Segment `p q` as a degenerate triangle with its midpoint (collinear corners) and as one
/// with a repeated endpoint position.
fn seg_tris(p: [f32; 3], q: [f32; 3]) -> [Tri; 2] {
    let m = [
        (p[0] + q[0]) / 2.0,
        (p[1] + q[1]) / 2.0,
        (p[2] + q[2]) / 2.0,
    ];
    [[p, m, q], [p, q, q]]
}

fn point_tri(p: [f32; 3]) -> Tri {
    [p, p, p]
}

fn check_seg(p: [f32; 3], q: [f32; 3], b: Tri, expected: bool) {
    for s in seg_tris(p, q) {
        check(s, b, expected);
    }
}

#[test]
fn segment_vs_triangle() {
    // Pierces the face.
    check_seg([1.0, 1.0, -2.0], [1.0, 1.0, 2.0], A, true);
    // Ends on the face.
    check_seg([1.0, 1.0, 0.0], [1.0, 1.0, 2.0], A, true);
    // Stops short of the face.
    check_seg([1.0, 1.0, 2.0], [1.0, 1.0, 4.0], A, false);
    // Passes beside the triangle.
    check_seg([4.0, 4.0, -2.0], [4.0, 4.0, 2.0], A, false);
    // Through a vertex and through an edge.
    check_seg([4.0, 0.0, -2.0], [4.0, 0.0, 2.0], A, true);
    check_seg([2.0, 2.0, -2.0], [2.0, 2.0, 2.0], A, true);
    // Parallel above the plane.
    check_seg([0.0, 0.0, 1.0], [4.0, 4.0, 1.0], A, false);
    // In the plane: inside, crossing, outside, along an edge, touching a vertex.
    check_seg([1.0, 1.0, 0.0], [2.0, 1.0, 0.0], A, true);
    check_seg([-2.0, 2.0, 0.0], [6.0, 2.0, 0.0], A, true);
    check_seg([5.0, 0.0, 0.0], [0.0, 5.0, 0.0], A, false);
    check_seg([-2.0, 0.0, 0.0], [6.0, 0.0, 0.0], A, true);
    check_seg([4.0, 0.0, 0.0], [6.0, 2.0, 0.0], A, true);
    check_seg([5.0, 0.0, 0.0], [6.0, 2.0, 0.0], A, false);
}

#[test]
fn point_vs_triangle() {
    check(point_tri([1.0, 1.0, 0.0]), A, true);
    check(point_tri([2.0, 0.0, 0.0]), A, true);
    check(point_tri([0.0, 4.0, 0.0]), A, true);
    check(point_tri([1.0, 1.0, 1.0]), A, false);
    check(point_tri([3.0, 3.0, 0.0]), A, false);
    check(point_tri([-1.0, 0.0, 0.0]), A, false);
}

#[test]
fn segment_vs_segment() {
    let s = seg_tris([0.0, 0.0, 0.0], [4.0, 4.0, 0.0]);
    let check_ss = |p: [f32; 3], q: [f32; 3], expected: bool| {
        for a in s {
            for b in seg_tris(p, q) {
                check(a, b, expected);
            }
        }
    };
    // Crossing in a plane, touching at an end, T-junction, missing.
    check_ss([0.0, 4.0, 0.0], [4.0, 0.0, 0.0], true);
    check_ss([4.0, 4.0, 0.0], [6.0, 0.0, 0.0], true);
    check_ss([2.0, 2.0, 0.0], [4.0, 0.0, 0.0], true);
    check_ss([3.0, 1.0, 0.0], [4.0, 0.0, 0.0], false);
    // Skew (non-coplanar), crossing above.
    check_ss([0.0, 4.0, 1.0], [4.0, 0.0, 1.0], false);
    // Non-coplanar but the lines meet: crossing in a vertical plane.
    check_ss([2.0, 2.0, -1.0], [2.0, 2.0, 1.0], true);
    // Collinear: overlapping, touching, disjoint, containing.
    check_ss([3.0, 3.0, 0.0], [6.0, 6.0, 0.0], true);
    check_ss([4.0, 4.0, 0.0], [6.0, 6.0, 0.0], true);
    check_ss([5.0, 5.0, 0.0], [6.0, 6.0, 0.0], false);
    check_ss([-1.0, -1.0, 0.0], [6.0, 6.0, 0.0], true);
    // Parallel, distinct lines.
    check_ss([0.0, 1.0, 0.0], [4.0, 5.0, 0.0], false);
    // Collinear along a line with dx = 0 (lexicographic order on y, z).
    check(
        seg_tris([1.0, 0.0, 0.0], [1.0, 2.0, 2.0])[0],
        seg_tris([1.0, 1.0, 1.0], [1.0, 3.0, 3.0])[0],
        true,
    );
    check(
        seg_tris([1.0, 0.0, 0.0], [1.0, 2.0, 2.0])[0],
        seg_tris([1.0, 3.0, 3.0], [1.0, 4.0, 4.0])[0],
        false,
    );
}

#[test]
fn point_vs_segment_and_point() {
    let s = seg_tris([0.0, 0.0, 0.0], [4.0, 2.0, 2.0]);
    for a in s {
        check(a, point_tri([2.0, 1.0, 1.0]), true);
        check(a, point_tri([4.0, 2.0, 2.0]), true);
        check(a, point_tri([6.0, 3.0, 3.0]), false);
        check(a, point_tri([2.0, 1.0, 2.0]), false);
    }
    check(point_tri([1.0, 2.0, 3.0]), point_tri([1.0, 2.0, 3.0]), true);
    check(
        point_tri([1.0, 2.0, 3.0]),
        point_tri([1.0, 2.0, 4.0]),
        false,
    );
    // A point-triangle with a repeated corner vs a collinear one.
    check(
        [[1.0, 1.0, 1.0], [1.0, 1.0, 1.0], [3.0, 3.0, 3.0]],
        point_tri([2.0, 2.0, 2.0]),
        true,
    );
}

#[test]
fn negative_zero_is_zero() {
    let b = [[-0.0, -0.0, -0.0], [-1.0, 0.0, 1.0], [0.0, -1.0, 1.0]];
    check(A, b, true);
    check(point_tri([-0.0, 0.0, -0.0]), A, true);
}

// ---------------------------------------------------------------------------------------
// One-ulp perturbations
// ---------------------------------------------------------------------------------------

#[test]
fn ulp_perturbations_separate_and_merge() {
    // Vertex on the face; one ulp up separates, one ulp down pierces.
    let b = |z: f32| [[1.0, 1.0, z], [2.0, 1.0, 2.0], [1.0, 2.0, 2.0]];
    check_scaled(A, b(0.0), true, Some(2));
    check_scaled(A, b(up(0.0)), false, None);
    check_scaled(A, b(down(0.0)), true, None);
    // Vertex on the face at a non-zero height plane z = 1.
    let a1 = A.map(|p| [p[0], p[1], 1.0]);
    let b1 = |z: f32| [[1.0, 1.0, z], [2.0, 1.0, 3.0], [1.0, 2.0, 3.0]];
    check_scaled(a1, b1(1.0), true, Some(2));
    check_scaled(a1, b1(up(1.0)), false, Some(23));
    check_scaled(a1, b1(down(1.0)), true, Some(24));
    // Coplanar vertex on the hypotenuse x + y = 4; nudge outward / inward.
    let c = |x: f32| [[x, 2.0, 0.0], [4.0, 4.0, 0.0], [3.0, 5.0, 0.0]];
    check_scaled(A, c(2.0), true, Some(2));
    check_scaled(A, c(up(2.0)), false, Some(22));
    check_scaled(A, c(down(2.0)), true, Some(23));
    // Segment parallel to the face, one ulp above / on.
    let s = |z: f32| [[1.0, 1.0, z], [1.5, 1.5, z], [2.0, 2.0, z]];
    check_scaled(A, s(0.0), true, Some(2));
    check_scaled(A, s(up(0.0)), false, None);
    // Skew edges: one ulp apart in z at the crossing point.
    let e = |z: f32| [[2.0, -1.0, z], [2.0, 1.0, z], [2.0, 0.0, 3.0]];
    check_scaled(A, e(0.0), true, Some(2));
    check_scaled(A, e(up(0.0)), false, None);
    // Collinear segments touching at an endpoint; nudge apart by one ulp.
    let p = |x: f32| point_tri([x, 0.0, 0.0]);
    check_scaled(A, p(4.0), true, Some(2));
    check_scaled(A, p(up(4.0)), false, Some(21));
    check_scaled(A, p(down(4.0)), true, Some(22));
}

// ---------------------------------------------------------------------------------------
// intersection_segment
// ---------------------------------------------------------------------------------------

fn same_segment(s: [[f32; 3]; 2], p: [f32; 3], q: [f32; 3]) -> bool {
    (s[0] == p && s[1] == q) || (s[0] == q && s[1] == p)
}

#[test]
fn segment_of_crossing_triangles_is_exact_here() {
    let b = [[1.0, 1.0, -1.0], [3.0, 1.0, -1.0], [1.0, 1.0, 1.0]];
    let s = intersection_segment(&A, &b).expect("they cross");
    assert!(same_segment(s, [1.0, 1.0, 0.0], [2.0, 1.0, 0.0]), "{s:?}");
    let s = intersection_segment(&b, &A).expect("they cross");
    assert!(same_segment(s, [1.0, 1.0, 0.0], [2.0, 1.0, 0.0]), "{s:?}");
}

#[test]
fn segment_of_single_point_contact_is_a_point() {
    let b = [[1.0, 1.0, 0.0], [2.0, 1.0, 2.0], [1.0, 2.0, 2.0]];
    let s = intersection_segment(&A, &b).expect("touch");
    assert_eq!(s, [[1.0, 1.0, 0.0]; 2]);
    let b = [[4.0, 0.0, 0.0], [5.0, 1.0, 2.0], [5.0, -1.0, 2.0]];
    assert_eq!(intersection_segment(&b, &A), Some([[4.0, 0.0, 0.0]; 2]));
}

#[test]
fn segment_of_coplanar_overlap_is_a_diameter() {
    // Identical: the longest edge (the hypotenuse).
    let s = intersection_segment(&A, &A).expect("identical");
    assert!(same_segment(s, [4.0, 0.0, 0.0], [0.0, 4.0, 0.0]), "{s:?}");
    // Collinear shared edge overlap [2, 4] on the x axis.
    let b = [[2.0, 0.0, 0.0], [6.0, 0.0, 0.0], [4.0, -2.0, 0.0]];
    let s = intersection_segment(&A, &b).expect("edge overlap");
    assert!(same_segment(s, [2.0, 0.0, 0.0], [4.0, 0.0, 0.0]), "{s:?}");
    // Segment vs segment collinear overlap.
    let s = intersection_segment(
        &seg_tris([0.0, 0.0, 0.0], [4.0, 4.0, 4.0])[0],
        &seg_tris([2.0, 2.0, 2.0], [6.0, 6.0, 6.0])[1],
    )
    .expect("overlap");
    assert!(same_segment(s, [2.0, 2.0, 2.0], [4.0, 4.0, 4.0]), "{s:?}");
    assert_eq!(
        intersection_segment(&A, &[[9.0, 9.0, 9.0], [9.0, 9.0, 9.0], [9.0, 9.0, 9.0]]),
        None
    );
}

// ---------------------------------------------------------------------------------------
// Brute-force oracles
// ---------------------------------------------------------------------------------------

/// A grid of `n x n` quads (two triangles each) in the plane z = `z`, spanning [0, n].
fn grid(n: u32, z: f32, tilt: f32) -> Mesh {
    let mut pos = Vec::new();
    for j in 0..=n {
        for i in 0..=n {
            pos.push([i as f32, j as f32, z + tilt * i as f32]);
        }
    }
    let mut tris = Vec::new();
    let v = |i: u32, j: u32| j * (n + 1) + i;
    for j in 0..n {
        for i in 0..n {
            tris.push([v(i, j), v(i + 1, j), v(i + 1, j + 1)]);
            tris.push([v(i, j), v(i + 1, j + 1), v(i, j + 1)]);
        }
    }
    Mesh::new(pos, tris).expect("valid grid")
}

fn pairs_by_reference(a: &Mesh, b: &Mesh) -> Vec<[u32; 2]> {
    let mut out = Vec::new();
    for i in 0..a.triangle_count() {
        for j in 0..b.triangle_count() {
            if reference(&a.corners(i), &b.corners(j)) {
                out.push([i as u32, j as u32]);
            }
        }
    }
    out
}

#[test]
fn brute_force_pairs_matches_reference() {
    let a = grid(3, 0.0, 0.0);
    // Tilted sheet crossing the flat one along x = 1.
    let b = grid(3, -1.0, 1.0);
    let got = brute_force_pairs(&a, &b);
    assert!(!got.is_empty());
    assert!(got.windows(2).all(|w| w[0] < w[1]), "sorted and unique");
    assert_eq!(got, pairs_by_reference(&a, &b));
    // A sheet lifted by 1 is disjoint from the flat one except nothing.
    let c = grid(3, 1.0, 0.0);
    assert!(brute_force_pairs(&a, &c).is_empty());
    // Identical meshes: every pair that touches (shares a point) is reported.
    let same = brute_force_pairs(&a, &a);
    assert_eq!(same, pairs_by_reference(&a, &a));
    assert!(same.contains(&[0, 0]) && same.contains(&[0, 1]));
}

#[test]
fn brute_force_self_pairs_skips_shared_vertices() {
    // A flat grid touches itself only through shared vertices: no self pairs.
    let g = grid(3, 0.0, 0.0);
    assert!(brute_force_self_pairs(&g).is_empty());
    // Two crossing quads in one mesh (disjoint index sets) plus a fan sharing vertex 0.
    let pos = vec![
        [0.0, 0.0, 0.0],
        [4.0, 0.0, 0.0],
        [4.0, 4.0, 0.0],
        [0.0, 4.0, 0.0],
        [2.0, 2.0, -1.0],
        [2.0, 2.0, 1.0],
        [3.0, -1.0, 1.0],
        // Lies in the plane z = 0 touching triangle 0 at a vertex position only.
        [-1.0, -1.0, 0.0],
        [-2.0, 0.0, 0.0],
    ];
    let tris = vec![
        [0, 1, 2],
        [0, 2, 3],
        [4, 5, 6],
        [0, 7, 8], // shares vertex 0 with triangles 0 and 1: skipped
    ];
    let m = Mesh::new(pos, tris).expect("valid");
    let got = brute_force_self_pairs(&m);
    let mut want = Vec::new();
    for i in 0..m.triangle_count() {
        for j in i + 1..m.triangle_count() {
            let (ti, tj) = (m.triangles()[i], m.triangles()[j]);
            if ti.iter().any(|v| tj.contains(v)) {
                continue;
            }
            if reference(&m.corners(i), &m.corners(j)) {
                want.push([i as u32, j as u32]);
            }
        }
    }
    assert_eq!(got, want);
    assert!(got.contains(&[0, 2]) || got.contains(&[1, 2]));
    assert!(!got.iter().any(|p| p[1] == 3));
}

// ---------------------------------------------------------------------------------------
// Property tests against the reference
// ---------------------------------------------------------------------------------------

fn grid_tri(r: i32) -> impl Strategy<Value = Tri> {
    prop::array::uniform3(prop::array::uniform3((-r..=r).prop_map(|c| c as f32)))
}

/// Integer coordinates up to 2^24 / 4: `b` is built from `a` with small offsets so that
/// most pairs are near each other, sharing corners now and then.
fn near_pair() -> impl Strategy<Value = (Tri, Tri)> {
    let big = -(1 << 22)..(1 << 22);
    (
        prop::array::uniform3(prop::array::uniform3(big.clone())),
        prop::array::uniform3(prop::array::uniform3(-64i32..=64)),
        prop::array::uniform3(0usize..4),
        0u32..6,
    )
        .prop_map(|(a, off, pick, shift)| {
            let a: Tri = a.map(|p| p.map(|c| c as f32));
            let centroid = |k: usize| (a[0][k] + a[1][k] + a[2][k]) / 3.0;
            let mut b = [[0.0f32; 3]; 3];
            for i in 0..3 {
                for k in 0..3 {
                    let base = if pick[i] < 3 {
                        a[pick[i]][k]
                    } else {
                        centroid(k).round()
                    };
                    b[i][k] = base + (off[i][k] << shift) as f32;
                }
            }
            (a, b)
        })
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(3000))]

    #[test]
    fn small_grid_matches_reference(a in grid_tri(2), b in grid_tri(2)) {
        let want = reference(&a, &b);
        prop_assert_eq!(triangles_intersect(&a, &b), want);
        prop_assert_eq!(triangles_intersect(&b, &a), want);
        check_verdict(&a, &b, want);
        check_verdict(&b, &a, want);
        check_segment(&a, &b, want);
        for p in PERMS {
            prop_assert_eq!(triangles_intersect(&permute(&a, p), &b), want);
            prop_assert_eq!(triangles_intersect(&a, &permute(&b, p)), want);
        }
    }

    #[test]
    fn flat_grid_matches_reference(
        a in grid_tri(3),
        b in grid_tri(3),
        ka in 0usize..3,
        kb in 0usize..3,
    ) {
        // Flatten onto coordinate planes to force coplanar and degenerate cases.
        let (mut a, mut b) = (a, b);
        for p in &mut a {
            p[ka] = 0.0;
        }
        for p in &mut b {
            p[kb] = 0.0;
        }
        let want = reference(&a, &b);
        prop_assert_eq!(triangles_intersect(&a, &b), want);
        prop_assert_eq!(triangles_intersect(&b, &a), want);
        check_verdict(&a, &b, want);
        check_verdict(&b, &a, want);
        check_segment(&a, &b, want);
    }

    #[test]
    fn near_pairs_match_reference((a, b) in near_pair()) {
        let want = reference(&a, &b);
        prop_assert_eq!(triangles_intersect(&a, &b), want);
        prop_assert_eq!(triangles_intersect(&b, &a), want);
        prop_assert_eq!(intersection_segment(&a, &b).is_some(), want);
        check_verdict(&a, &b, want);
        check_verdict(&b, &a, want);
    }

    #[test]
    fn random_floats_are_symmetric_and_permutation_invariant(
        a in prop::array::uniform3(prop::array::uniform3(-1.0f32..1.0)),
        b in prop::array::uniform3(prop::array::uniform3(-1.0f32..1.0)),
    ) {
        let want = triangles_intersect(&a, &b);
        prop_assert_eq!(triangles_intersect(&b, &a), want);
        for p in PERMS {
            prop_assert_eq!(triangles_intersect(&permute(&a, p), &permute(&b, p)), want);
        }
        check_verdict(&a, &b, want);
        check_verdict(&b, &a, want);
        check_segment(&a, &b, want);
        // The reference needs integral coordinates after scaling: compare on a 2^-20 grid.
        let snap = |t: Tri| t.map(|p| p.map(|c| (c * 1_048_576.0).round() / 1_048_576.0));
        let (sa, sb) = (snap(a), snap(b));
        prop_assert_eq!(triangles_intersect(&sa, &sb), reference_scaled(&sa, &sb, 20));
    }
}

/// `b`'s corners are points of `a`'s plane (affine combinations of `a`'s corners, some
/// outside the triangle), snapped to a 2^-20 grid: nearly (rarely exactly) coplanar pairs
/// whose decisions need the exact stages of the predicates.
fn nearly_coplanar_pair() -> impl Strategy<Value = (Tri, Tri)> {
    let coord = (-(1i32 << 20)..(1i32 << 20)).prop_map(|m| m as f32 / 1_048_576.0);
    (
        prop::array::uniform3(prop::array::uniform3(coord)),
        prop::array::uniform3((-0.5f64..1.5, -0.5f64..1.5)),
        prop::array::uniform3(prop::array::uniform3(-1i32..=1)),
    )
        .prop_map(|(a, st, nudge)| {
            let mut b = [[0.0f32; 3]; 3];
            for i in 0..3 {
                let (s, t) = st[i];
                for k in 0..3 {
                    let (p, q, r) = (f64::from(a[0][k]), f64::from(a[1][k]), f64::from(a[2][k]));
                    let x = p + s * (q - p) + t * (r - p);
                    let g = (x * 1_048_576.0).round() + f64::from(nudge[i][k]);
                    b[i][k] = (g.clamp(-2_097_151.0, 2_097_151.0) / 1_048_576.0) as f32;
                }
            }
            (a, b)
        })
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(3000))]

    #[test]
    fn nearly_coplanar_pairs_match_reference((a, b) in nearly_coplanar_pair()) {
        let want = reference_scaled(&a, &b, 20);
        prop_assert_eq!(triangles_intersect(&a, &b), want);
        prop_assert_eq!(triangles_intersect(&b, &a), want);
        check_verdict(&a, &b, want);
        check_verdict(&b, &a, want);
        check_segment(&a, &b, want);
    }
}

/// The kernel's certified verdicts at scales from tiny to huge, on crossing and near-miss
/// pairs: never wrong, and in general position undecided only rarely (so the narrow phase
/// seldom needs the exact test) while the `f32` determinants neither underflow nor
/// overflow; at 1e-30 and 1e30 they do, and everything is left to the exact test.
#[test]
fn kernel_verdicts_are_exact_and_mostly_decided() {
    let mut seed = 0x9e37_79b9_7f4a_7c15u64;
    let mut next = move || {
        seed ^= seed << 13;
        seed ^= seed >> 7;
        seed ^= seed << 17;
        (seed >> 40) as f32 / (1u64 << 24) as f32 * 2.0 - 1.0
    };
    for scale in [1.0f32, 1e-6, 1e6, 1e-30, 1e30] {
        let (mut decided, mut contacts, mut n) = (0, 0, 0);
        for _ in 0..20_000 {
            // Two triangles around the origin, each a third of the box: about half cross.
            let a: Tri = std::array::from_fn(|_| std::array::from_fn(|_| next() * scale));
            let b: Tri = std::array::from_fn(|_| std::array::from_fn(|_| next() * scale));
            let want = triangles_intersect(&a, &b);
            check_verdict(&a, &b, want);
            n += 1;
            contacts += usize::from(want);
            decided += usize::from(pair_verdict(&a, &b) != Verdict::Undecided);
        }
        assert!(contacts > n / 10, "scale {scale}: too few crossing pairs");
        if (1e-6..=1e6).contains(&scale) {
            assert!(
                decided * 100 >= n * 99,
                "scale {scale}: {decided} of {n} decided"
            );
        }
    }
}

#[test]
fn non_finite_inputs_do_not_panic() {
    // Unspecified answer (documented), but no panic, for the decision and the segment.
    for bad in [f32::NAN, f32::INFINITY, f32::NEG_INFINITY] {
        for i in 0..3 {
            for k in 0..3 {
                let mut b = [[1.0, 1.0, -1.0], [3.0, 1.0, -1.0], [1.0, 1.0, 1.0]];
                b[i][k] = bad;
                let _ = triangles_intersect(&A, &b);
                let _ = triangles_intersect(&b, &A);
                let _ = intersection_segment(&A, &b);
                let _ = intersection_segment(&b, &b);
                let _ = triangles_intersect(&b, &b);
            }
        }
    }
    // A degenerate (collinear) triangle against one with a NaN corner.
    let seg = [[0.0, 0.0, 0.0], [1.0, 1.0, 0.0], [2.0, 2.0, 0.0]];
    for i in 0..3 {
        let mut a = A;
        a[i][2] = f32::NAN;
        let _ = triangles_intersect(&a, &seg);
        let _ = triangles_intersect(&seg, &a);
        let _ = intersection_segment(&a, &seg);
        let _ = intersection_segment(&seg, &a);
    }
}

/// The fast path (Guigue-Devillers on the generic case) against the general test on many
/// configurations: small integer grids (shared vertices, vertices on planes, coplanar and
/// degenerate triangles all frequent), a wide grid (mostly generic), and random floats in
/// contact range. Seeded; no proptest shrinking needed (the inputs are printed).
#[test]
fn fast_path_equals_general_test_on_many_configurations() {
    let mut x = 0x9E37_79B9_7F4A_7C15u64;
    let mut next = move || {
        x ^= x >> 12;
        x ^= x << 25;
        x ^= x >> 27;
        x.wrapping_mul(0x2545_F491_4F6C_DD1D)
    };
    let mut hits = 0;
    for case in 0..300_000u32 {
        let span = [3u64, 5, 64][case as usize % 3];
        let mut tri = || -> Tri {
            std::array::from_fn(|_| {
                std::array::from_fn(|_| {
                    if span == 64 {
                        (next() >> 40) as f32 / (1u64 << 24) as f32 * 2.0 - 1.0
                    } else {
                        (next() % span) as f32
                    }
                })
            })
        };
        let (a, b) = (tri(), tri());
        let want = dhcd::narrow::triangles_intersect_reference(&a, &b);
        hits += want as u32;
        assert_eq!(triangles_intersect(&a, &b), want, "{a:?} vs {b:?}");
        assert_eq!(triangles_intersect(&b, &a), want, "{b:?} vs {a:?}");
    }
    assert!(hits > 30_000, "enough intersecting cases: {hits}");
}

/// Coplanar and quad-diagonal pairs, which no plane certifies (a corner lies on the other's
/// plane): the projection along the first triangle's dominant normal axis decides them, and
/// never against the exact answer. Flat grids at several scales, offsets and tilts (every
/// pair of triangles of nearby cells, touching and apart), and the diagonal pairs across a
/// ring edge of a sphere's planar quads (the n-body frames' balls).
#[test]
fn projection_decides_coplanar_and_quad_diagonal_pairs() {
    let (mut apart, mut decided_apart, mut checked) = (0, 0, 0);
    let mut check = |a: &Tri, b: &Tri| {
        let want = triangles_intersect(a, b);
        check_verdict(a, b, want);
        check_verdict(b, a, want);
        checked += 1;
        if !want {
            apart += 1;
            decided_apart += usize::from(pair_verdict(a, b) == Verdict::Apart);
        }
    };
    // Flat grids: cell (i, j) split along one diagonal or the other; every pair of
    // triangles in cells at most two apart (in-plane frame `ex`, `ey`, origin `o`).
    let frames: [([f32; 3], [f32; 3], [f32; 3]); 4] = [
        ([1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 0.0]),
        ([0.0, 0.0, 1.0], [1.0, 0.0, 0.0], [3.0, -2.0, 0.5]),
        ([0.6, 0.8, 0.0], [0.0, 0.0, 1.0], [100.0, 7.0, -3.0]),
        ([0.0, 0.6, 0.8], [1.0, 0.0, 0.0], [-0.25, 0.0, 1e3]),
    ];
    for (ex, ey, o) in frames {
        for h in [1.0f32, 1e-3, 37.5] {
            let at = |i: i32, j: i32| -> [f32; 3] {
                std::array::from_fn(|k| o[k] + (i as f32 * ex[k] + j as f32 * ey[k]) * h)
            };
            let cell = |i: i32, j: i32, alt: bool| -> [Tri; 2] {
                let (a, b, c, d) = (at(i, j), at(i + 1, j), at(i, j + 1), at(i + 1, j + 1));
                if alt {
                    [[a, b, c], [b, d, c]]
                } else {
                    [[a, b, d], [a, d, c]]
                }
            };
            for alt in [false, true] {
                let tris: Vec<Tri> = (0..4)
                    .flat_map(|i| (0..4).flat_map(move |j| cell(i, j, alt ^ ((i + j) % 2 == 1))))
                    .collect();
                for (x, a) in tris.iter().enumerate() {
                    for b in &tris[x + 1..] {
                        check(a, b);
                    }
                }
            }
        }
    }
    // A UV sphere's planar quads, split along one diagonal: the triangles of two quads
    // sharing a ring edge, each holding one end of it.
    let (rings, segments) = (16, 16);
    let point = |r: usize, s: usize| -> [f32; 3] {
        let (t, p) = (
            std::f32::consts::PI * r as f32 / rings as f32,
            std::f32::consts::TAU * s as f32 / segments as f32,
        );
        [
            4.0 + 0.3 * t.sin() * p.cos(),
            9.0 + 0.3 * t.cos(),
            4.1 + 0.3 * t.sin() * p.sin(),
        ]
    };
    for r in 1..rings - 2 {
        for s in 0..segments {
            let (s1, r1, r2) = ((s + 1) % segments, r + 1, r + 2);
            let upper = [point(r, s), point(r1, s), point(r1, s1)];
            let lower = [point(r1, s1), point(r2, s1), point(r2, s)];
            check(&upper, &lower);
        }
    }
    assert!(checked > 10_000, "{checked} pairs");
    assert!(
        decided_apart * 100 >= apart * 99,
        "{decided_apart} of {apart} separated pairs certified apart"
    );
}
