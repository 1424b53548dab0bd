//! The geometry of one contact: its squared distance, the gradient and Hessian of that
//! squared distance with respect to its vertices' coordinates, and the closest-point weights.
//!
//! A contact's four vertex slots `x[0..4]` hold, by [`ContactType`]:
//!
//! | type | slots | squared distance |
//! |---|---|---|
//! | point-point | `p, q` | `|p - q|^2` |
//! | point-edge | `p, e0, e1` | `|(p - e0) x (e1 - e0)|^2 / |e1 - e0|^2` (to the edge's line) |
//! | point-triangle | `p, t0, t1, t2` | `(n . (p - t0))^2 / |n|^2`, `n = (t1 - t0) x (t2 - t0)` (to the plane) |
//! | edge-edge | `a0, a1, b0, b1` | `(n . (a0 - b0))^2 / |n|^2`, `n = (a1 - a0) x (b1 - b0)` (between the lines) |
//!
//! These are the IPC Toolkit's per-type formulas: the distance of the features a contact's
//! type names, so smooth where the type holds. Gradients are `[f64; 12]` (slot `i`,
//! coordinate `c` at `3 i + c`) and Hessians `[[f64; 12]; 12]`, zero in unused slots. The
//! values are `f64` evaluations of the formulas (not exact; the exact decisions are the
//! proximity query's); degenerate features (a zero-length edge, a degenerate triangle,
//! parallel edges) divide by zero and give non-finite numbers, as the formulas do.
//!
//! The closest-point weights `w` are those for which `sum_i w[i] x[i]` is the vector from the
//! closest point of the second feature to the closest point of the first (the point, or edge
//! `a`; unclamped projections), the convention of the IPC Toolkit's `compute_coefficients`:
//! point-point `[1, -1]`,
//! point-edge `[1, -(1 - a), -a]`, point-triangle `[1, -(1 - b - c), -b, -c]`, edge-edge
//! `[1 - s, s, -(1 - t), -t]`, with the closest points' parameters on the lines and plane.

use super::dual::{Grad, Hess, Scalar};
use crate::distance::EdgeEdge;
use crate::error::{Error, Result};

/// The type of a contact, as the IPC Toolkit's collision types (the numbers are the C ABI's
/// and Python's `type` codes).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
#[repr(u8)]
pub enum ContactType {
    /// A vertex and a vertex (IPC's vertex-vertex collision).
    PointPoint = 0,
    /// A vertex and the interior of an edge (IPC's edge-vertex collision).
    PointEdge = 1,
    /// A vertex and the interior of a triangle (IPC's face-vertex collision).
    PointTriangle = 2,
    /// The interiors of two edges, or two nearly parallel edges (IPC's edge-edge collision).
    EdgeEdge = 3,
}

impl ContactType {
    /// Every type, in order.
    pub const ALL: [Self; 4] = [
        Self::PointPoint,
        Self::PointEdge,
        Self::PointTriangle,
        Self::EdgeEdge,
    ];

    /// The type of code `code` (0 point-point, 1 point-edge, 2 point-triangle, 3 edge-edge);
    /// [`Error::UnknownContactType`] for any other.
    pub fn from_code(code: u8) -> Result<Self> {
        Self::ALL
            .get(usize::from(code))
            .copied()
            .ok_or(Error::UnknownContactType(code))
    }

    /// How many vertex slots the type uses (2, 3, 4, 4).
    pub const fn vertex_count(self) -> usize {
        [2, 3, 4, 4][self as usize]
    }

    /// Short name: `"PP"`, `"PE"`, `"PT"`, `"EE"`.
    pub const fn name(self) -> &'static str {
        ["PP", "PE", "PT", "EE"][self as usize]
    }

    /// The squared distance of the features in `x` (see the [module](self) table).
    pub fn distance_sq(self, x: &[[f64; 3]; 4]) -> f64 {
        Formula::of_type(self).eval::<f64>(x, |v, _| v)
    }

    /// The gradient of [`ContactType::distance_sq`] with respect to `x` (slot `i`, coordinate
    /// `c` at `3 i + c`; zero in unused slots).
    pub fn distance_gradient(self, x: &[[f64; 3]; 4]) -> [f64; 12] {
        Formula::of_type(self).gradient(x)
    }

    /// The Hessian of [`ContactType::distance_sq`] with respect to `x` (12 x 12, symmetric;
    /// zero in unused slots).
    pub fn distance_hessian(self, x: &[[f64; 3]; 4]) -> [[f64; 12]; 12] {
        Formula::of_type(self).hessian(x)
    }

    /// The closest-point weights of the features in `x` (see the [module](self); zero in
    /// unused slots).
    pub fn weights(self, x: &[[f64; 3]; 4]) -> [f64; 4] {
        Formula::of_type(self).weights(x)
    }
}

/// Which formula gives a contact's distance, and on which slots. A contact set's nearly
/// parallel edge-edge rows keep the edge-edge type but are measured by the formula of their
/// closest features (a corner pair, a corner and an edge, or the lines), as the IPC Toolkit
/// does.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Formula {
    /// `|x[p] - x[q]|^2`.
    PointPoint(usize, usize),
    /// Point `x[p]` to the line through `x[e0]`, `x[e1]`.
    PointLine(usize, usize, usize),
    /// Point `x[0]` to the plane through `x[1..4]`.
    PointPlane,
    /// Line `x[0] x[1]` to line `x[2] x[3]`.
    LineLine,
}

impl Formula {
    pub(crate) const fn of_type(t: ContactType) -> Self {
        match t {
            ContactType::PointPoint => Self::PointPoint(0, 1),
            ContactType::PointEdge => Self::PointLine(0, 1, 2),
            ContactType::PointTriangle => Self::PointPlane,
            ContactType::EdgeEdge => Self::LineLine,
        }
    }

    /// The formula of an edge-edge row `[a0, a1, b0, b1]` whose closest features are `kind`.
    pub(crate) const fn of_edge_edge(kind: EdgeEdge) -> Self {
        match kind {
            EdgeEdge::Ea0Eb0 => Self::PointPoint(0, 2),
            EdgeEdge::Ea0Eb1 => Self::PointPoint(0, 3),
            EdgeEdge::Ea1Eb0 => Self::PointPoint(1, 2),
            EdgeEdge::Ea1Eb1 => Self::PointPoint(1, 3),
            EdgeEdge::EaEb0 => Self::PointLine(2, 0, 1),
            EdgeEdge::EaEb1 => Self::PointLine(3, 0, 1),
            EdgeEdge::Ea0Eb => Self::PointLine(0, 2, 3),
            EdgeEdge::Ea1Eb => Self::PointLine(1, 2, 3),
            EdgeEdge::EaEb => Self::LineLine,
        }
    }

    /// The formula over `x`, each coordinate lifted to `S` by `lift(value, 3 slot + c)`.
    #[inline(always)]
    fn eval<S: Scalar>(self, x: &[[f64; 3]; 4], lift: impl Fn(f64, usize) -> S) -> S {
        let p = |i: usize| -> [S; 3] { std::array::from_fn(|c| lift(x[i][c], 3 * i + c)) };
        match self {
            Self::PointPoint(i, j) => {
                let r = sub(p(i), p(j));
                dot(r, r)
            }
            Self::PointLine(i, e0, e1) => {
                let e0 = p(e0);
                let e = sub(p(e1), e0);
                let c = cross(sub(p(i), e0), e);
                dot(c, c) / dot(e, e)
            }
            Self::PointPlane => {
                let t0 = p(1);
                let n = cross(sub(p(2), t0), sub(p(3), t0));
                let s = dot(n, sub(p(0), t0));
                s * s / dot(n, n)
            }
            Self::LineLine => {
                let (a0, b0) = (p(0), p(2));
                let n = cross(sub(p(1), a0), sub(p(3), b0));
                let s = dot(n, sub(a0, b0));
                s * s / dot(n, n)
            }
        }
    }

    pub(crate) fn distance_sq(self, x: &[[f64; 3]; 4]) -> f64 {
        self.eval::<f64>(x, |v, _| v)
    }

    pub(crate) fn gradient(self, x: &[[f64; 3]; 4]) -> [f64; 12] {
        self.eval(x, Grad::<12>::variable).g
    }

    pub(crate) fn hessian(self, x: &[[f64; 3]; 4]) -> [[f64; 12]; 12] {
        self.eval(x, Hess::<12>::variable).h
    }

    pub(crate) fn weights(self, x: &[[f64; 3]; 4]) -> [f64; 4] {
        let mut w = [0.0; 4];
        match self {
            Self::PointPoint(i, j) => {
                w[i] = 1.0;
                w[j] = -1.0;
            }
            Self::PointLine(i, e0, e1) => {
                let e = sub(x[e1], x[e0]);
                let a = dot(sub(x[i], x[e0]), e) / dot(e, e);
                // The first feature minus the second: the point minus its projection, but
                // for an edge-edge row whose point is on the second edge, the projection
                // (on the first edge) minus the point.
                let sign = if i < e0 { 1.0 } else { -1.0 };
                w[i] = sign;
                w[e0] = -sign * (1.0 - a);
                w[e1] = -sign * a;
            }
            Self::PointPlane => {
                // The projection t0 + b (t1 - t0) + c (t2 - t0) of the point: the normal
                // equations of the plane's two edge vectors.
                let (e1, e2, r) = (sub(x[2], x[1]), sub(x[3], x[1]), sub(x[0], x[1]));
                let (b, c) = solve2(
                    [dot(e1, e1), dot(e1, e2), dot(e2, e2)],
                    [dot(e1, r), dot(e2, r)],
                );
                w = [1.0, -(1.0 - b - c), -b, -c];
            }
            Self::LineLine => {
                // a0 + s (a1 - a0) and b0 + t (b1 - b0) closest: the normal equations of
                // |r + s a - t b|^2 with r = a0 - b0.
                let (a, b, r) = (sub(x[1], x[0]), sub(x[3], x[2]), sub(x[0], x[2]));
                let (s, t) = solve2([dot(a, a), -dot(a, b), dot(b, b)], [-dot(a, r), dot(b, r)]);
                w = [1.0 - s, s, -(1.0 - t), -t];
            }
        }
        w
    }
}

/// The solution of the symmetric 2 x 2 system `[[m0, m1], [m1, m2]] z = r`.
fn solve2(m: [f64; 3], r: [f64; 2]) -> (f64, f64) {
    let det = m[0] * m[2] - m[1] * m[1];
    (
        (r[0] * m[2] - m[1] * r[1]) / det,
        (m[0] * r[1] - m[1] * r[0]) / det,
    )
}

#[inline(always)]
fn sub<S: Scalar>(a: [S; 3], b: [S; 3]) -> [S; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

#[inline(always)]
fn dot<S: Scalar>(a: [S; 3], b: [S; 3]) -> S {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

#[inline(always)]
fn cross<S: Scalar>(a: [S; 3], b: [S; 3]) -> [S; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

fn check_lengths(types: usize, x: usize) -> Result<()> {
    if types == x {
        Ok(())
    } else {
        Err(Error::LengthMismatch {
            what: "contact positions",
            expected: types,
            got: x,
        })
    }
}

/// [`ContactType::distance_sq`] of each row: `x[k]` the four slots of row `k` (unused slots
/// ignored). [`Error::LengthMismatch`] when the lengths differ.
pub fn distance_sq(types: &[ContactType], x: &[[[f64; 3]; 4]]) -> Result<Vec<f64>> {
    check_lengths(types.len(), x.len())?;
    Ok(types.iter().zip(x).map(|(t, x)| t.distance_sq(x)).collect())
}

/// [`ContactType::distance_gradient`] of each row.
pub fn distance_gradient(types: &[ContactType], x: &[[[f64; 3]; 4]]) -> Result<Vec<[f64; 12]>> {
    check_lengths(types.len(), x.len())?;
    Ok(types
        .iter()
        .zip(x)
        .map(|(t, x)| t.distance_gradient(x))
        .collect())
}

/// [`ContactType::distance_hessian`] of each row.
pub fn distance_hessian(
    types: &[ContactType],
    x: &[[[f64; 3]; 4]],
) -> Result<Vec<[[f64; 12]; 12]>> {
    check_lengths(types.len(), x.len())?;
    Ok(types
        .iter()
        .zip(x)
        .map(|(t, x)| t.distance_hessian(x))
        .collect())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sample() -> [[f64; 3]; 4] {
        [
            [0.3, 0.2, 0.7],
            [0.0, 0.1, 0.0],
            [1.1, -0.2, 0.1],
            [0.2, 0.9, -0.3],
        ]
    }

    /// Every formula's gradient and Hessian against central differences of the value and of
    /// the gradient.
    #[test]
    fn derivatives_match_finite_differences() {
        let x = sample();
        let formulas = [
            Formula::PointPoint(0, 1),
            Formula::PointLine(0, 1, 2),
            Formula::PointLine(3, 0, 1),
            Formula::PointPlane,
            Formula::LineLine,
        ];
        let h = 1e-6;
        for f in formulas {
            let g = f.gradient(&x);
            let hess = f.hessian(&x);
            for k in 0..12 {
                let (mut xp, mut xm) = (x, x);
                xp[k / 3][k % 3] += h;
                xm[k / 3][k % 3] -= h;
                let fd = (f.distance_sq(&xp) - f.distance_sq(&xm)) / (2.0 * h);
                assert!((g[k] - fd).abs() < 1e-7, "{f:?} d/dx{k}: {} vs {fd}", g[k]);
                let (gp, gm) = (f.gradient(&xp), f.gradient(&xm));
                for j in 0..12 {
                    let fd = (gp[j] - gm[j]) / (2.0 * h);
                    assert!(
                        (hess[j][k] - fd).abs() < 1e-6,
                        "{f:?} H[{j}][{k}]: {} vs {fd}",
                        hess[j][k]
                    );
                    assert_eq!(hess[j][k], hess[k][j], "{f:?} symmetric");
                }
            }
        }
    }

    /// The weights give the vector between the closest points: its squared length is the
    /// distance, and it is orthogonal to the features.
    #[test]
    fn weights_reproduce_the_distance() {
        let x = sample();
        for t in ContactType::ALL {
            let w = t.weights(&x);
            let v: [f64; 3] = std::array::from_fn(|c| (0..4).map(|i| w[i] * x[i][c]).sum());
            let d = dot(v, v);
            assert!((d - t.distance_sq(&x)).abs() < 1e-14, "{t:?}: {d}");
            assert!(w[t.vertex_count()..].iter().all(|&w| w == 0.0));
            assert!(
                (w.iter().sum::<f64>()).abs() < 1e-15,
                "{t:?}: weights sum to 0"
            );
        }
    }

    #[test]
    fn type_codes_round_trip() {
        for t in ContactType::ALL {
            assert_eq!(ContactType::from_code(t as u8).unwrap(), t);
        }
        assert!(matches!(
            ContactType::from_code(4),
            Err(Error::UnknownContactType(4))
        ));
        let e = distance_sq(&[ContactType::PointPoint], &[]).unwrap_err();
        assert!(matches!(e, Error::LengthMismatch { .. }));
    }
}
