//! Validated triangle meshes.

use crate::error::{Error, Positions, Result};
use crate::precision::Precision;

impl std::str::FromStr for Precision {
    type Err = Error;
    fn from_str(s: &str) -> Result<Self> {
        Precision::ALL
            .into_iter()
            .find(|p| p.name() == s)
            .ok_or_else(|| Error::UnknownPrecision(s.to_owned()))
    }
}

/// A triangle mesh: vertex positions and triangles as vertex-index triples.
///
/// Construction validates everything the kernels rely on: at least one vertex and one
/// triangle, indices in range, no triangle repeating a vertex index, finite coordinates.
/// Zero-area triangles (collinear or coincident corners) are legal and are treated exactly
/// as the segment or point they are.
///
/// A mesh has a [`Precision`]: [`Mesh::new`] takes `f32` positions, [`Mesh::new_f64`] `f64`
/// ones (kept as given; [`Mesh::positions`] is then their rounding to the nearest `f32`,
/// which the bounding volumes start from, and [`Mesh::positions_f64`] the exact values).
#[derive(Clone, Debug, PartialEq)]
pub struct Mesh {
    positions: Vec<[f32; 3]>,
    /// The exact positions of an `f64` mesh.
    exact: Option<Vec<[f64; 3]>>,
    triangles: Vec<[u32; 3]>,
}

impl Mesh {
    /// Validates and wraps `positions` and `triangles` (an [`Precision::F32`] mesh).
    pub fn new(positions: Vec<[f32; 3]>, triangles: Vec<[u32; 3]>) -> Result<Self> {
        check_finite(&positions, Positions::Mesh)?;
        Self::checked(positions, None, triangles)
    }

    /// Validates and wraps `f64` positions and `triangles` (an [`Precision::F64`] mesh):
    /// besides [`Mesh::new`]'s checks, every coordinate must round to a finite `f32`
    /// (magnitude below about `3.4e38`, [`Error::OutOfRange`]), since the bounding volumes
    /// are `f32` records.
    pub fn new_f64(positions: Vec<[f64; 3]>, triangles: Vec<[u32; 3]>) -> Result<Self> {
        check_finite_f64(&positions, Positions::Mesh)?;
        let rounded = round_to_f32(&positions);
        Self::checked(rounded, Some(positions), triangles)
    }

    fn checked(
        positions: Vec<[f32; 3]>,
        exact: Option<Vec<[f64; 3]>>,
        triangles: Vec<[u32; 3]>,
    ) -> Result<Self> {
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
            exact,
            triangles,
        })
    }

    /// The positions as `f32`: exact for an [`Precision::F32`] mesh, the nearest `f32`s of
    /// an [`Precision::F64`] one (see [`Mesh::positions_f64`]).
    pub fn positions(&self) -> &[[f32; 3]] {
        &self.positions
    }

    /// The exact positions of an [`Precision::F64`] mesh; `None` for an `f32` one (whose
    /// positions convert to `f64` exactly).
    pub fn positions_f64(&self) -> Option<&[[f64; 3]]> {
        self.exact.as_deref()
    }

    /// The positions as `f64`, exactly: an `f64` mesh's own, an `f32` mesh's converted.
    #[doc(hidden)]
    pub fn to_f64_positions(&self) -> Vec<[f64; 3]> {
        match &self.exact {
            Some(p) => p.clone(),
            None => self.positions.iter().map(|p| p.map(f64::from)).collect(),
        }
    }

    /// The precision the mesh was built with.
    pub fn precision(&self) -> Precision {
        match self.exact {
            Some(_) => Precision::F64,
            None => Precision::F32,
        }
    }

    /// The triangles, as the caller's vertex indices.
    pub fn triangles(&self) -> &[[u32; 3]] {
        &self.triangles
    }

    /// Number of vertices.
    pub fn vertex_count(&self) -> usize {
        self.positions.len()
    }

    /// Number of triangles.
    pub fn triangle_count(&self) -> usize {
        self.triangles.len()
    }

    /// Replaces the positions of an `f32` mesh (same vertex count, finite), keeping the
    /// triangles. An `f64` mesh refuses them ([`Error::PrecisionMismatch`]: rounding its
    /// positions silently would change its answers); see [`Mesh::set_positions_f64`].
    pub fn set_positions(&mut self, positions: &[[f32; 3]]) -> Result<()> {
        if self.exact.is_some() {
            return Err(Error::PrecisionMismatch {
                expected: Precision::F64,
                got: Precision::F32,
            });
        }
        check_positions(positions, self.positions.len(), Positions::Update)?;
        self.positions.copy_from_slice(positions);
        Ok(())
    }

    /// Replaces the positions of an `f64` mesh (same vertex count, finite, within `f32`
    /// range), keeping the triangles. An `f32` mesh refuses them
    /// ([`Error::PrecisionMismatch`]).
    pub fn set_positions_f64(&mut self, positions: &[[f64; 3]]) -> Result<()> {
        let Some(exact) = &mut self.exact else {
            return Err(Error::PrecisionMismatch {
                expected: Precision::F32,
                got: Precision::F64,
            });
        };
        check_positions_f64(positions, exact.len(), Positions::Update)?;
        exact.copy_from_slice(positions);
        self.positions = round_to_f32(positions);
        Ok(())
    }

    /// The three corners of triangle `t`.
    #[inline]
    #[doc(hidden)]
    pub fn corners(&self, t: usize) -> [[f32; 3]; 3] {
        let [a, b, c] = self.triangles[t];
        [
            self.positions[a as usize],
            self.positions[b as usize],
            self.positions[c as usize],
        ]
    }
}

/// Checks positions (`of`: an update, the start or end of a step): `expected` vertices, all
/// coordinates finite.
pub fn check_positions(positions: &[[f32; 3]], expected: usize, of: Positions) -> Result<()> {
    if positions.len() != expected {
        return Err(Error::WrongVertexCount {
            expected,
            got: positions.len(),
            of,
            object: None,
        });
    }
    check_finite(positions, of)
}

fn check_finite(positions: &[[f32; 3]], of: Positions) -> Result<()> {
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
        position: positions[vertex].map(f64::from),
        of,
        object: None,
    })
}

/// Checks `f64` positions (`of`: an update, the start or end of a step): `expected`
/// vertices, every coordinate finite and within the `f32` range ([`Mesh::new_f64`]).
pub fn check_positions_f64(positions: &[[f64; 3]], expected: usize, of: Positions) -> Result<()> {
    if positions.len() != expected {
        return Err(Error::WrongVertexCount {
            expected,
            got: positions.len(),
            of,
            object: None,
        });
    }
    check_finite_f64(positions, of)
}

/// Every coordinate finite, and finite once rounded to `f32`.
fn check_finite_f64(positions: &[[f64; 3]], of: Positions) -> Result<()> {
    // As `check_finite`: one branch per chunk. `|x| <= F32_LIMIT` is false for NaN and
    // infinities too.
    if positions
        .as_flattened()
        .chunks(1024)
        .all(|c| c.iter().fold(true, |ok, x| ok & (x.abs() <= F32_LIMIT)))
    {
        return Ok(());
    }
    let vertex = positions
        .iter()
        .position(|p| !p.iter().all(|x| x.abs() <= F32_LIMIT))
        .expect("a bad vertex exists");
    let position = positions[vertex];
    Err(if position.iter().all(|x| x.is_finite()) {
        Error::OutOfRange {
            vertex,
            position,
            of,
            object: None,
        }
    } else {
        Error::NonFinite {
            vertex,
            position,
            of,
            object: None,
        }
    })
}

/// The largest `f64` magnitude that rounds to a finite `f32`: `f32::MAX` plus just under half
/// an ulp of it (ties round to even, i.e. to infinity, so the bound itself is excluded by
/// taking the `f64` just below it).
const F32_LIMIT: f64 = {
    let max = f32::MAX as f64;
    // f32::MAX = (2 - 2^-23) 2^127; its ulp is 2^104, half of it 2^103.
    let half_ulp = 10141204801825835211973625643008.0; // 2^103
                                                       // `max + half_ulp` is exact in f64 (it needs 25 bits); the next f64 below it.
    f64::from_bits((max + half_ulp).to_bits() - 1)
};

/// Each coordinate rounded to the nearest `f32`.
pub(crate) fn round_to_f32(positions: &[[f64; 3]]) -> Vec<[f32; 3]> {
    positions.iter().map(|p| p.map(|x| x as f32)).collect()
}
