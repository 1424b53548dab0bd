//! Pure batch kernels of `dhcd`: bounding-volume overlap tests and refit reductions over
//! structure-of-arrays slices. No tree knowledge lives here: slices in, masks and values out.
//!
//! Every kernel has a scalar reference beside it (`*_scalar`) with the same operation order.
//!
//! NaN policy: overlap tests use ordered comparisons only, so a NaN anywhere in a pair makes
//! the pair *not* overlap, on every backend. (The `dhcd` crate rejects non-finite input
//! before it reaches a kernel, so this only matters to direct users of this crate.)
#![deny(unsafe_op_in_unsafe_fn)]

pub mod overlap;
pub mod refit;

/// Points (or centres) in structure-of-arrays form: `x[i], y[i], z[i]` is point `i`.
#[derive(Clone, Copy, Debug)]
pub struct Soa3<'a> {
    pub x: &'a [f32],
    pub y: &'a [f32],
    pub z: &'a [f32],
}

impl<'a> Soa3<'a> {
    pub fn new(x: &'a [f32], y: &'a [f32], z: &'a [f32]) -> Self {
        assert!(
            x.len() == y.len() && y.len() == z.len(),
            "Soa3: ragged arrays"
        );
        Self { x, y, z }
    }

    #[inline]
    pub fn len(&self) -> usize {
        self.x.len()
    }

    #[inline]
    pub fn is_empty(&self) -> bool {
        self.x.is_empty()
    }

    #[inline]
    pub fn get(&self, i: usize) -> [f32; 3] {
        [self.x[i], self.y[i], self.z[i]]
    }

    /// The contiguous run `range` of these points.
    #[inline]
    pub fn slice(&self, range: core::ops::Range<usize>) -> Soa3<'a> {
        Soa3 {
            x: &self.x[range.clone()],
            y: &self.y[range.clone()],
            z: &self.z[range],
        }
    }
}
