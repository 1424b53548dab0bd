//! Validated triangle meshes.

use crate::error::{Error, Result};

/// A triangle mesh: vertex positions and triangles as vertex-index triples.
///
/// Construction validates everything the kernels rely on: at least one vertex and one
/// triangle, indices in range, no triangle repeating a vertex index, finite coordinates.
/// Zero-area triangles (collinear or coincident corners) are legal and are treated exactly
/// as the segment or point they are.
#[derive(Clone, Debug, PartialEq)]
pub struct Mesh {
    positions: Vec<[f32; 3]>,
    triangles: Vec<[u32; 3]>,
}

impl Mesh {
    /// Validates and wraps `positions` and `triangles`.
    pub fn new(positions: Vec<[f32; 3]>, triangles: Vec<[u32; 3]>) -> Result<Self> {
        if positions.is_empty() {
            return Err(Error::NoVertices);
        }
        if triangles.is_empty() {
            return Err(Error::NoTriangles);
        }
        if positions.len() >= u32::MAX as usize {
            return Err(Error::TooManyVertices(positions.len()));
        }
        if triangles.len() >= u32::MAX as usize {
            return Err(Error::TooManyTriangles(triangles.len()));
        }
        check_finite(&positions)?;
        for (t, tri) in triangles.iter().enumerate() {
            for &index in tri {
                if index as usize >= positions.len() {
                    return Err(Error::IndexOutOfRange {
                        triangle: t,
                        index,
                        vertex_count: positions.len(),
                    });
                }
            }
            let [a, b, c] = *tri;
            if a == b || a == c || b == c {
                let index = if a == b || a == c { a } else { b };
                return Err(Error::RepeatedIndex {
                    triangle: t,
                    index,
                    corners: *tri,
                });
            }
        }
        Ok(Self {
            positions,
            triangles,
        })
    }

    pub fn positions(&self) -> &[[f32; 3]] {
        &self.positions
    }

    pub fn triangles(&self) -> &[[u32; 3]] {
        &self.triangles
    }

    pub fn vertex_count(&self) -> usize {
        self.positions.len()
    }

    pub fn triangle_count(&self) -> usize {
        self.triangles.len()
    }

    /// Replaces the positions (same vertex count, finite), keeping the triangles.
    pub fn set_positions(&mut self, positions: &[[f32; 3]]) -> Result<()> {
        check_positions(positions, self.positions.len())?;
        self.positions.copy_from_slice(positions);
        Ok(())
    }

    /// The three corners of triangle `t`.
    #[inline]
    pub fn corners(&self, t: usize) -> [[f32; 3]; 3] {
        let [a, b, c] = self.triangles[t];
        [
            self.positions[a as usize],
            self.positions[b as usize],
            self.positions[c as usize],
        ]
    }
}

/// Checks a position update: `expected` vertices, all coordinates finite.
pub fn check_positions(positions: &[[f32; 3]], expected: usize) -> Result<()> {
    if positions.len() != expected {
        return Err(Error::WrongVertexCount {
            expected,
            got: positions.len(),
        });
    }
    check_finite(positions)
}

fn check_finite(positions: &[[f32; 3]]) -> Result<()> {
    // PERF: one branch per chunk of coordinates, the chunk folded without one (it vectorizes;
    // the per-vertex `all` was ~3% of a small scene's step); the error path finds the first
    // culprit.
    if positions
        .as_flattened()
        .chunks(1024)
        .all(|c| c.iter().fold(true, |ok, x| ok & x.is_finite()))
    {
        return Ok(());
    }
    let vertex = positions
        .iter()
        .position(|p| !(p[0].is_finite() && p[1].is_finite() && p[2].is_finite()))
        .expect("a non-finite vertex exists");
    Err(Error::NonFinite {
        vertex,
        position: positions[vertex],
    })
}
