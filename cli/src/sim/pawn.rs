//! The paper's test object: a chess pawn as a closed surface of revolution.
//!
//! The paper only tells us the pawn has 6,976 polygons. A surface of revolution with 32 rings
//! of 109 segments plus two pole vertices has exactly that many triangles
//! (31 bands x 109 x 2 + 2 x 109 pole fans), so the hierarchy sizes and therefore the work
//! counts are comparable with the paper's.
//!
//! Convention: the pawn stands on the plane `y = 0` and its axis is `+y` (the usual "up" of
//! OBJ files); it is centred on the `y` axis.

use std::f64::consts::PI;

use super::{check, SimError};
use dhcd::Mesh;

/// Rings of the paper-sized pawn (excluding the two poles).
pub const PAWN_RINGS: usize = 32;
/// Segments around the axis of the paper-sized pawn.
pub const PAWN_SEGMENTS: usize = 109;
/// Height of the paper-sized pawn.
pub const PAWN_HEIGHT: f32 = 1.0;

/// The paper-sized pawn: 3,490 vertices, 6,976 triangles, height 1, standing on `y = 0`.
pub fn pawn_mesh() -> Mesh {
    pawn_mesh_with(PAWN_RINGS, PAWN_SEGMENTS, PAWN_HEIGHT)
        .expect("the built-in pawn parameters are valid")
}

/// A pawn with `rings` rings of `segments` vertices between two poles, `height` tall.
///
/// Vertex 0 is the bottom pole, vertex `1 + i * segments + j` is segment `j` of ring `i`
/// (ring 0 at the bottom), and the last vertex is the top pole. Triangles are wound
/// counter-clockwise seen from outside, so normals point outward and the signed volume is
/// positive. Rings are placed at equal arc length along the profile, so triangles have
/// similar heights everywhere (no slivers where the profile is nearly horizontal).
///
/// Errors if `rings < 2`, `segments < 3`, or `height` is not finite and positive.
pub fn pawn_mesh_with(rings: usize, segments: usize, height: f32) -> Result<Mesh, SimError> {
    check(rings >= 2, "pawn rings", rings as f64, "at least 2")?;
    check(
        segments >= 3,
        "pawn segments",
        segments as f64,
        "at least 3",
    )?;
    let finite_positive = height.is_finite() && height > 0.0;
    check(
        finite_positive,
        "pawn height",
        height.into(),
        "finite and positive",
    )?;
    let profile = resample_by_arc_length(&pawn_profile(), rings + 2);
    let h = f64::from(height);

    let mut positions = Vec::with_capacity(rings * segments + 2);
    positions.push([0.0, 0.0, 0.0]);
    for &(r, y) in &profile[1..=rings] {
        for j in 0..segments {
            let theta = 2.0 * PI * j as f64 / segments as f64;
            positions.push([
                (r * theta.cos() * h) as f32,
                (y * h) as f32,
                (r * theta.sin() * h) as f32,
            ]);
        }
    }
    positions.push([0.0, height, 0.0]);

    let s = segments as u32;
    let ring = |i: usize, j: usize| -> u32 { 1 + i as u32 * s + (j % segments) as u32 };
    let top = (rings * segments + 1) as u32;
    let mut triangles = Vec::with_capacity(2 * segments * rings);
    for j in 0..segments {
        triangles.push([0, ring(0, j), ring(0, j + 1)]);
    }
    for i in 0..rings - 1 {
        for j in 0..segments {
            triangles.push([ring(i, j), ring(i + 1, j), ring(i, j + 1)]);
            triangles.push([ring(i, j + 1), ring(i + 1, j), ring(i + 1, j + 1)]);
        }
    }
    for j in 0..segments {
        triangles.push([top, ring(rings - 1, j + 1), ring(rings - 1, j)]);
    }
    Ok(Mesh::new(positions, triangles)?)
}

/// The pawn's profile `(radius, height)` for a pawn of height 1, densely sampled from the
/// bottom pole `(0, 0)` to the top pole `(0, 1)`: flat bottom, rounded base rim, a stem that
/// flares into the base, a thin collar, a short neck and a spherical head.
fn pawn_profile() -> Vec<(f64, f64)> {
    const N: usize = 256;
    let mut pts: Vec<(f64, f64)> = Vec::new();
    let line = |pts: &mut Vec<(f64, f64)>, a: (f64, f64), b: (f64, f64)| {
        for k in 0..=N {
            let t = k as f64 / N as f64;
            pts.push((a.0 + (b.0 - a.0) * t, a.1 + (b.1 - a.1) * t));
        }
    };
    let arc = |pts: &mut Vec<(f64, f64)>, c: (f64, f64), rad: f64, a0: f64, a1: f64| {
        for k in 0..=N {
            let a = a0 + (a1 - a0) * k as f64 / N as f64;
            pts.push((c.0 + rad * a.cos(), c.1 + rad * a.sin()));
        }
    };
    // Flat bottom disk, then the rounded rim of the base.
    line(&mut pts, (0.0, 0.0), (0.30, 0.0));
    arc(&mut pts, (0.30, 0.045), 0.045, -PI / 2.0, PI / 2.0);
    // Stem: r = 0.11 + 0.19 (1 - s)^2.2, flaring concavely into the base.
    for k in 0..=N {
        let s = k as f64 / N as f64;
        pts.push((0.11 + 0.19 * (1.0 - s).powf(2.2), 0.09 + 0.47 * s));
    }
    // Collar: out, round rim, back in to the neck.
    line(&mut pts, (0.11, 0.56), (0.19, 0.575));
    arc(&mut pts, (0.19, 0.595), 0.02, -PI / 2.0, PI / 2.0);
    line(&mut pts, (0.19, 0.615), (0.10, 0.63));
    // Neck, then the head: a sphere of radius 0.19 centred at height 0.81 up to the top pole.
    let (c, rad) = (0.81, 0.19);
    let phi0 = (0.10f64 / rad).asin();
    line(&mut pts, (0.10, 0.63), (0.10, c - rad * phi0.cos()));
    for k in 0..=N {
        let phi = phi0 + (PI - phi0) * k as f64 / N as f64;
        pts.push((rad * phi.sin(), c - rad * phi.cos()));
    }
    // Make the poles exact and drop consecutive duplicates (piece joints).
    let last = pts.len() - 1;
    pts[last] = (0.0, 1.0);
    pts.dedup_by(|b, a| (a.0 - b.0).hypot(a.1 - b.1) < 1e-12);
    pts
}

/// `count` points at equal arc length along the polyline, including both ends.
fn resample_by_arc_length(pts: &[(f64, f64)], count: usize) -> Vec<(f64, f64)> {
    let mut cumulative = Vec::with_capacity(pts.len());
    let mut total = 0.0;
    cumulative.push(0.0);
    for w in pts.windows(2) {
        total += (w[1].0 - w[0].0).hypot(w[1].1 - w[0].1);
        cumulative.push(total);
    }
    let mut out = Vec::with_capacity(count);
    let mut seg = 0;
    for k in 0..count {
        let target = total * k as f64 / (count - 1) as f64;
        while seg + 2 < pts.len() && cumulative[seg + 1] < target {
            seg += 1;
        }
        let (l0, l1) = (cumulative[seg], cumulative[seg + 1]);
        let t = if l1 > l0 {
            ((target - l0) / (l1 - l0)).clamp(0.0, 1.0)
        } else {
            0.0
        };
        let (a, b) = (pts[seg], pts[seg + 1]);
        out.push((a.0 + (b.0 - a.0) * t, a.1 + (b.1 - a.1) * t));
    }
    out[0] = pts[0];
    out[count - 1] = pts[pts.len() - 1];
    out
}
