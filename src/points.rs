//! Vertex positions in structure-of-arrays form, in the hierarchy's internal vertex order.

use dhcd_kernels::Soa3;

/// Positions as three coordinate arrays (`x[i], y[i], z[i]` is internal vertex `i`), so a
/// node's contiguous run of vertices is three contiguous slices for the SIMD reductions.
///
/// For an `f64` hierarchy these are the nearest `f32`s of the exact positions
/// ([`Points::is_rounded`]): every bound fitted from them is then widened to hold the exact
/// points too ([`Points::rounding_slack`]).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Points {
    pub x: Vec<f32>,
    pub y: Vec<f32>,
    pub z: Vec<f32>,
    rounded: bool,
}

impl Points {
    pub fn zeros(n: usize) -> Self {
        Self {
            x: vec![0.0; n],
            y: vec![0.0; n],
            z: vec![0.0; n],
            rounded: false,
        }
    }

    /// Whether the coordinates are roundings (to nearest) of `f64` positions.
    #[inline]
    pub fn is_rounded(&self) -> bool {
        self.rounded
    }

    /// How far (Euclidean) an exact point may lie from its rounded one when every coordinate
    /// involved is at most `magnitude` in absolute value: 0 for `f32` positions; for rounded
    /// ones, `sqrt(3)` times the rounding error of one coordinate (`2^-24 |x|`, or `2^-150`
    /// below the normal range), rounded up generously (`2^-23 magnitude + 2^-126`, a normal
    /// absolute term: subnormal arithmetic is slow).
    #[inline]
    pub fn rounding_slack(&self, magnitude: f32) -> f32 {
        if self.rounded {
            magnitude * f32::EPSILON + f32::MIN_POSITIVE
        } else {
            0.0
        }
    }

    /// Gathers the nearest `f32`s of `positions[order[i]]` into internal slot `i` (rounded
    /// points: [`Points::is_rounded`]).
    pub(crate) fn gather_rounded(positions: &[[f64; 3]], order: &[u32]) -> Self {
        let mut p = Self::zeros(order.len());
        p.gather_rounded_from(positions, order);
        p.rounded = true;
        p
    }

    /// Overwrites every slot `i` with the nearest `f32`s of `positions[order[i]]`.
    pub(crate) fn gather_rounded_from(&mut self, positions: &[[f64; 3]], order: &[u32]) {
        debug_assert_eq!(order.len(), self.len());
        for (i, &o) in order.iter().enumerate() {
            let p = positions[o as usize];
            self.x[i] = p[0] as f32;
            self.y[i] = p[1] as f32;
            self.z[i] = p[2] as f32;
        }
    }

    /// Gathers `positions[order[i]]` into internal slot `i`.
    pub fn gather(positions: &[[f32; 3]], order: &[u32]) -> Self {
        let mut p = Self::zeros(order.len());
        p.gather_from(positions, order);
        p
    }

    /// Overwrites every slot `i` with `positions[order[i]]`.
    pub fn gather_from(&mut self, positions: &[[f32; 3]], order: &[u32]) {
        debug_assert_eq!(order.len(), self.len());
        for (i, &o) in order.iter().enumerate() {
            let p = positions[o as usize];
            self.x[i] = p[0];
            self.y[i] = p[1];
            self.z[i] = p[2];
        }
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

    #[inline]
    pub fn soa(&self) -> Soa3<'_> {
        Soa3 {
            x: &self.x,
            y: &self.y,
            z: &self.z,
        }
    }
}
