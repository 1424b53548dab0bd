//! The floating-point type of coordinates.

/// The floating-point type of a mesh's coordinates: every answer is exact for the
/// coordinates as given in it.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
#[non_exhaustive]
pub enum Precision {
    /// `f32` coordinates (the fastest path).
    #[default]
    F32,
    /// `f64` coordinates, as simulators hold them. Bounding volumes stay `f32` records,
    /// rounded outward; the triangle, proximity and CCD tests decide for the `f64` values.
    F64,
}

impl Precision {
    /// Every precision, the default first.
    pub const ALL: [Precision; 2] = [Precision::F32, Precision::F64];

    /// The name on the command line and in JSON reports: `f32`, `f64`.
    pub const fn name(self) -> &'static str {
        match self {
            Precision::F32 => "f32",
            Precision::F64 => "f64",
        }
    }
}

impl std::fmt::Display for Precision {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}
