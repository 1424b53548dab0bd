//! Exact geometric primitives on `f32` points.
//!
//! Every sign here is exact: `f32 -> f64` is exact and Shewchuk's adaptive predicates (the
//! `robust` crate) are exact for any `f64` input whose products neither overflow nor
//! underflow, which holds for all finite `f32` coordinates (a degree-3 product of `f32`
//! differences stays far inside the `f64` exponent range). Comparisons of `f32` are exact.

use robust::{Coord, Coord3D};

/// A point.
pub(crate) type P3 = [f32; 3];
/// A triangle (possibly degenerate).
pub(crate) type Tri = [P3; 3];

#[inline(always)]
fn c3(p: &P3) -> Coord3D<f64> {
    Coord3D {
        x: f64::from(p[0]),
        y: f64::from(p[1]),
        z: f64::from(p[2]),
    }
}

/// Sign-exact orientation of `d` against the plane through `a, b, c` (zero iff coplanar).
#[inline(always)]
pub(crate) fn orient3d(a: &P3, b: &P3, c: &P3, d: &P3) -> f64 {
    robust::orient3d(c3(a), c3(b), c3(c), c3(d))
}

/// The two axes kept when projecting along axis `k` (cyclic, so orientation is consistent).
const KEEP: [(usize, usize); 3] = [(1, 2), (2, 0), (0, 1)];

/// The two axes kept when projecting along axis `k`.
#[inline(always)]
pub(crate) fn keep(k: usize) -> (usize, usize) {
    KEEP[k]
}

/// Sign-exact 2D orientation of `a, b, c` projected along axis `k` (zero iff the
/// projections are collinear).
#[inline]
pub(crate) fn orient2d(k: usize, a: &P3, b: &P3, c: &P3) -> f64 {
    let (i, j) = KEEP[k];
    let p = |v: &P3| Coord {
        x: f64::from(v[i]),
        y: f64::from(v[j]),
    };
    robust::orient2d(p(a), p(b), p(c))
}

/// The projection axis `k` that keeps the triangle `a, b, c` most non-degenerate (largest
/// `|orient2d|`, i.e. the dominant normal component), or `None` when the corners are
/// collinear in 3D (all three projections are then collinear, exactly).
#[inline]
pub(crate) fn projection_axis(a: &P3, b: &P3, c: &P3) -> Option<usize> {
    let mut best = None;
    let mut best_abs = 0.0;
    for k in 0..3 {
        let o = orient2d(k, a, b, c).abs();
        if o > best_abs {
            best_abs = o;
            best = Some(k);
        }
    }
    best
}

/// Strict sign of `x` as -1, 0 or 1.
#[inline(always)]
pub(crate) fn sign(x: f64) -> i32 {
    i32::from(x > 0.0) - i32::from(x < 0.0)
}

/// Lexicographic `a <= b`. On any line, lexicographic order is a linear order compatible
/// with the line's parametrisation, so it decides betweenness of collinear points exactly.
#[inline]
pub(crate) fn lex_le(a: &[f32], b: &[f32]) -> bool {
    for (x, y) in a.iter().zip(b) {
        if x < y {
            return true;
        }
        if x > y {
            return false;
        }
    }
    true
}

/// `p + t (q - p)` in `f64`, `t` clamped to `[0, 1]`; exact at `t = 0` and `t = 1`.
#[inline]
pub(crate) fn lerp(p: &P3, q: &P3, t: f64) -> [f64; 3] {
    let t = t.clamp(0.0, 1.0);
    if t == 1.0 {
        return q.map(f64::from);
    }
    let mut x = [0.0; 3];
    for i in 0..3 {
        let (a, b) = (f64::from(p[i]), f64::from(q[i]));
        x[i] = a + t * (b - a);
    }
    x
}
