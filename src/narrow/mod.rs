//! Exact narrow phase: closed triangle-triangle intersection decided exactly for `f32`
//! input, the intersection segment as contact detail, and brute-force oracles.
//!
//! Exactness: every decision is a comparison of `f32` values or the sign of Shewchuk's
//! adaptive `orient3d`/`orient2d` (the `robust` crate; its `orient3d` floating-point filter
//! is inlined here, same formula and error bound) on the inputs widened to `f64`. That is
//! exact for all finite `f32` coordinates: their products can neither overflow nor
//! underflow in `f64`. An `orient3d` the filter leaves open is first tried in exact integer
//! arithmetic (the points on their common binary grid, when it fits `i128`), the adaptive
//! predicate only otherwise. Degenerate triangles (collinear corners, or all three corners equal)
//! are tested exactly as the segment or point they are. Inputs are expected finite (a
//! [`Mesh`](crate::Mesh) guarantees it); with NaN or infinite coordinates the answer is
//! unspecified but nothing panics.
//!
//! Method: closed triangles intersect iff some edge of one meets the other closed triangle.
//! An edge crossing the other's plane is tested with three `orient3d` signs (not strictly
//! mixed); an edge in the plane with a 2D test in a projection that keeps the triangle
//! non-degenerate (chosen by exact `orient2d != 0`); a degenerate triangle is reduced to
//! its lexicographically extreme corners, and two degenerate ones meet by an exact
//! segment-segment test (collinear overlap decided by lexicographic comparison).
//!
//! Cost: an exact AABB interval test, then the three corners of each triangle against the
//! other's plane (early exit when all are strictly on one side). Only pairs surviving both
//! filters pay for the edge tests (measured by `cargo bench --bench narrow`).

mod exact;
pub(crate) mod leaves;
mod oracle;
mod predicates;
mod tritri;

pub use oracle::{
    brute_force_ccd, brute_force_pairs, brute_force_proximity, brute_force_self_ccd,
    brute_force_self_pairs, brute_force_self_proximity, earliest_of,
};

/// Whether the closed triangles share at least one point, decided exactly for the f32 inputs.
#[inline]
pub fn triangles_intersect(a: &[[f32; 3]; 3], b: &[[f32; 3]; 3]) -> bool {
    tritri::intersects(a, b)
}

/// Whether the closed triangles share at least one point, decided exactly for the f64 inputs
/// (any finite values).
#[inline]
pub fn triangles_intersect_f64(a: &[[f64; 3]; 3], b: &[[f64; 3]; 3]) -> bool {
    tritri::intersects(a, b)
}

/// [`triangles_intersect`] by the general edge-against-triangle test alone (no fast path):
/// the reference the fast path is tested against, and the brute-force oracles' test.
pub fn triangles_intersect_reference(a: &[[f32; 3]; 3], b: &[[f32; 3]; 3]) -> bool {
    tritri::tri_tri(a, b, &mut tritri::Decide)
}

/// Contact detail: the intersection of two closed triangles as a segment `[p, q]`, or
/// `None` exactly when [`triangles_intersect`] is `false`.
///
/// The topology (which edges cross which face, which corners lie inside) is decided by the
/// same exact predicates as [`triangles_intersect`]. The candidate points (corners inside
/// the other triangle, edge/face and edge/edge crossings) are computed in `f64` and the
/// pair farthest apart is returned, rounded to `f32`:
/// - crossing triangles: the intersection segment (`p == q` when it is a single point);
/// - coplanar overlap: the two vertices of the overlap polygon farthest apart (a diameter);
/// - corners that are inputs are returned exactly.
///
/// Accuracy: a computed crossing point is `p + t (q - p)` with `t` the ratio of two
/// exact-sign determinants, so it lies on the crossing edge within a few `f64` ulps of the
/// edge length times the relative error of `t`, then rounded to `f32` (half an `f32` ulp).
/// For well-conditioned crossings the result is within about one `f32` ulp of the true
/// point; for nearly parallel edge/face pairs the error along the edge can grow (the point
/// stays on the edge, clamped to it).
pub fn intersection_segment(a: &[[f32; 3]; 3], b: &[[f32; 3]; 3]) -> Option<[[f32; 3]; 2]> {
    let mut pts = tritri::Points::new();
    if !tritri::tri_tri(a, b, &mut pts) {
        return None;
    }
    let pts = pts.as_slice();
    debug_assert!(
        !pts.is_empty() || a.iter().chain(b).flatten().any(|c| !c.is_finite()),
        "an intersecting pair of finite triangles yields a candidate point"
    );
    let first = *pts.first()?;
    let (mut p, mut q, mut best) = (first, first, -1.0);
    for (i, u) in pts.iter().enumerate() {
        for v in &pts[i..] {
            let d = (0..3).map(|k| (u[k] - v[k]) * (u[k] - v[k])).sum::<f64>();
            if d > best {
                (p, q, best) = (*u, *v, d);
            }
        }
    }
    let r = |x: [f64; 3]| x.map(|c| c as f32);
    Some([r(p), r(q)])
}
