//! Vertex positions in structure-of-arrays form, in the hierarchy's internal vertex order.

use dhcd_kernels::Soa3;

/// Positions as three coordinate arrays (`x[i], y[i], z[i]` is internal vertex `i`), so a
/// node's contiguous run of vertices is three contiguous slices for the SIMD reductions.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Points {
    pub x: Vec<f32>,
    pub y: Vec<f32>,
    pub z: Vec<f32>,
}

impl Points {
    pub fn zeros(n: usize) -> Self {
        Self {
            x: vec![0.0; n],
            y: vec![0.0; n],
            z: vec![0.0; n],
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
