//! Forward-mode derivatives: one formula, written once over [`Scalar`], evaluated as a plain
//! `f64`, with its gradient ([`Grad`]) or with its gradient and Hessian ([`Hess`]) in `N`
//! variables. The distance formulas of [`super::geometry`] are small (a few cross and dot
//! products and one division), so carrying the derivatives through each operation costs a
//! few hundred flops per operation and needs no generated code.

// The product and quotient rules mix operations inside `Mul` and `Div`, which is what the
// lint suspects.
#![allow(clippy::suspicious_arithmetic_impl)]

use std::ops::{Add, Div, Mul, Sub};

/// What the distance formulas need of a number.
pub(crate) trait Scalar:
    Copy + Add<Output = Self> + Sub<Output = Self> + Mul<Output = Self> + Div<Output = Self>
{
}

impl Scalar for f64 {}

/// A value and its gradient in `N` variables.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Grad<const N: usize> {
    pub(crate) v: f64,
    pub(crate) g: [f64; N],
}

impl<const N: usize> Grad<N> {
    /// Variable `i` with value `v`.
    pub(crate) fn variable(v: f64, i: usize) -> Self {
        let mut g = [0.0; N];
        g[i] = 1.0;
        Self { v, g }
    }
}

impl<const N: usize> Scalar for Grad<N> {}

impl<const N: usize> Add for Grad<N> {
    type Output = Self;
    #[inline(always)]
    fn add(self, o: Self) -> Self {
        Self {
            v: self.v + o.v,
            g: std::array::from_fn(|i| self.g[i] + o.g[i]),
        }
    }
}

impl<const N: usize> Sub for Grad<N> {
    type Output = Self;
    #[inline(always)]
    fn sub(self, o: Self) -> Self {
        Self {
            v: self.v - o.v,
            g: std::array::from_fn(|i| self.g[i] - o.g[i]),
        }
    }
}

impl<const N: usize> Mul for Grad<N> {
    type Output = Self;
    #[inline(always)]
    fn mul(self, o: Self) -> Self {
        Self {
            v: self.v * o.v,
            g: std::array::from_fn(|i| self.v * o.g[i] + o.v * self.g[i]),
        }
    }
}

impl<const N: usize> Div for Grad<N> {
    type Output = Self;
    #[inline(always)]
    fn div(self, o: Self) -> Self {
        let q = self.v / o.v;
        Self {
            v: q,
            g: std::array::from_fn(|i| (self.g[i] - q * o.g[i]) / o.v),
        }
    }
}

/// A value, its gradient and its Hessian (full, symmetric) in `N` variables.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Hess<const N: usize> {
    pub(crate) v: f64,
    pub(crate) g: [f64; N],
    pub(crate) h: [[f64; N]; N],
}

impl<const N: usize> Hess<N> {
    /// Variable `i` with value `v`.
    pub(crate) fn variable(v: f64, i: usize) -> Self {
        let mut g = [0.0; N];
        g[i] = 1.0;
        Self {
            v,
            g,
            h: [[0.0; N]; N],
        }
    }
}

impl<const N: usize> Scalar for Hess<N> {}

impl<const N: usize> Add for Hess<N> {
    type Output = Self;
    #[inline(always)]
    fn add(self, o: Self) -> Self {
        Self {
            v: self.v + o.v,
            g: std::array::from_fn(|i| self.g[i] + o.g[i]),
            h: std::array::from_fn(|i| std::array::from_fn(|j| self.h[i][j] + o.h[i][j])),
        }
    }
}

impl<const N: usize> Sub for Hess<N> {
    type Output = Self;
    #[inline(always)]
    fn sub(self, o: Self) -> Self {
        Self {
            v: self.v - o.v,
            g: std::array::from_fn(|i| self.g[i] - o.g[i]),
            h: std::array::from_fn(|i| std::array::from_fn(|j| self.h[i][j] - o.h[i][j])),
        }
    }
}

impl<const N: usize> Mul for Hess<N> {
    type Output = Self;
    /// `(ab)'' = a b'' + b a'' + a' b'^T + b' a'^T`.
    #[inline(always)]
    fn mul(self, o: Self) -> Self {
        Self {
            v: self.v * o.v,
            g: std::array::from_fn(|i| self.v * o.g[i] + o.v * self.g[i]),
            h: std::array::from_fn(|i| {
                std::array::from_fn(|j| {
                    // The symmetric pair summed first: the result is exactly symmetric.
                    self.v * o.h[i][j]
                        + o.v * self.h[i][j]
                        + (self.g[i] * o.g[j] + o.g[i] * self.g[j])
                })
            }),
        }
    }
}

impl<const N: usize> Div for Hess<N> {
    type Output = Self;
    /// `q = a / b`: `q' = (a' - q b') / b`, `q'' = (a'' - q b'' - q' b'^T - b' q'^T) / b`.
    #[inline(always)]
    fn div(self, o: Self) -> Self {
        let q = self.v / o.v;
        let g: [f64; N] = std::array::from_fn(|i| (self.g[i] - q * o.g[i]) / o.v);
        Self {
            v: q,
            g,
            h: std::array::from_fn(|i| {
                std::array::from_fn(|j| {
                    (self.h[i][j] - q * o.h[i][j] - (g[i] * o.g[j] + o.g[i] * g[j])) / o.v
                })
            }),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `f(x, y) = x^2 y / (x + y)` against its derivatives by hand.
    #[test]
    fn derivatives_of_a_rational_function() {
        fn f<S: Scalar>(x: S, y: S) -> S {
            x * x * y / (x + y)
        }
        let (x, y) = (1.5, 0.5);
        let h = f(Hess::<2>::variable(x, 0), Hess::<2>::variable(y, 1));
        let s = x + y;
        assert!((h.v - x * x * y / s).abs() < 1e-15);
        let fx = (2.0 * x * y * s - x * x * y) / (s * s);
        let fy = (x * x * s - x * x * y) / (s * s);
        assert!((h.g[0] - fx).abs() < 1e-14 && (h.g[1] - fy).abs() < 1e-14);
        // Second derivatives by central differences of the exact first derivatives.
        let e = 1e-6;
        let gx = |x: f64, y: f64| {
            let s = x + y;
            (2.0 * x * y * s - x * x * y) / (s * s)
        };
        let fxx = (gx(x + e, y) - gx(x - e, y)) / (2.0 * e);
        let fxy = (gx(x, y + e) - gx(x, y - e)) / (2.0 * e);
        assert!((h.h[0][0] - fxx).abs() < 1e-8, "{} {fxx}", h.h[0][0]);
        assert!((h.h[0][1] - fxy).abs() < 1e-8 && (h.h[1][0] - fxy).abs() < 1e-8);
        let g = f(Grad::<2>::variable(x, 0), Grad::<2>::variable(y, 1));
        assert_eq!(g.g, h.g);
        assert_eq!(f(x, y), h.v);
    }
}
