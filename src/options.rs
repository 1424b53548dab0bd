//! Build options of a hierarchy: the region tree's shape, when bounding volumes are refitted,
//! and the DH central vertex.

use crate::error::{Error, Result};
use crate::tree::{TreeShape, DEFAULT_LEAF_SIZE, PAPER_LEVELS};

/// When bounding volumes follow a deformation.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
#[non_exhaustive]
pub enum Refit {
    /// The paper's lazy evaluation: a node is refitted just before its first overlap test
    /// after a position update, and only if it is tested at all.
    #[default]
    Lazy,
    /// Every node is refitted exactly (from its vertices) in `update_positions`.
    Eager,
    /// Every node in `update_positions`, bottom-up: leaves exactly, each internal node as a
    /// bound of its children (for DH, `r_p = max_c(|C_p - C_c| + r_c)`): cheaper, looser.
    EagerBottomUp,
}

impl Refit {
    /// The name in reports (and [`FromStr`](std::str::FromStr)): `lazy`, `eager`,
    /// `bottom-up`.
    pub const fn name(self) -> &'static str {
        match self {
            Refit::Lazy => "lazy",
            Refit::Eager => "eager",
            Refit::EagerBottomUp => "bottom-up",
        }
    }
}

impl std::fmt::Display for Refit {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

impl std::str::FromStr for Refit {
    type Err = Error;
    fn from_str(s: &str) -> Result<Self> {
        match s {
            "lazy" => Ok(Refit::Lazy),
            "eager" => Ok(Refit::Eager),
            "bottom-up" | "eager-bottom-up" => Ok(Refit::EagerBottomUp),
            _ => Err(Error::UnknownRefit(s.to_owned())),
        }
    }
}

/// Which vertex of its region a DH node is centred on (chosen at build, fixed for life). The
/// other methods ignore it.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
#[non_exhaustive]
pub enum CentralVertex {
    /// The paper's choice: the region vertex closest to the centroid (mean) of the region's
    /// vertices at rest.
    #[default]
    RestCentroid,
    /// The region vertex whose rest radius (largest distance to the region's vertices at
    /// rest) is least: the tightest DH sphere at rest. Costlier to build (exact, pruned).
    MinRadius,
}

impl CentralVertex {
    /// Every choice, the default first.
    pub const ALL: [CentralVertex; 2] = [CentralVertex::RestCentroid, CentralVertex::MinRadius];

    /// The name on the command line and in reports: `rest-centroid`, `min-radius`.
    pub const fn name(self) -> &'static str {
        match self {
            CentralVertex::RestCentroid => "rest-centroid",
            CentralVertex::MinRadius => "min-radius",
        }
    }
}

impl std::fmt::Display for CentralVertex {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

impl std::str::FromStr for CentralVertex {
    type Err = Error;
    fn from_str(s: &str) -> Result<Self> {
        CentralVertex::ALL
            .into_iter()
            .find(|c| c.name() == s)
            .ok_or_else(|| Error::UnknownCentral(s.to_owned()))
    }
}

/// Build options of a hierarchy.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Options {
    /// A fixed depth for the region tree (root = level 0; the paper uses 5), or `None`
    /// (the default) for an adaptive tree whose leaves hold at most `leaf_size` triangles.
    pub levels: Option<usize>,
    /// Largest number of triangles in a leaf of an adaptive tree (ignored with `levels`).
    pub leaf_size: usize,
    /// When bounding volumes follow a deformation (default [`Refit::Lazy`]).
    pub refit: Refit,
    /// The DH central vertex of every node (ignored by the other methods).
    pub central: CentralVertex,
}

impl Default for Options {
    fn default() -> Self {
        Self {
            levels: None,
            leaf_size: DEFAULT_LEAF_SIZE,
            refit: Refit::Lazy,
            central: CentralVertex::RestCentroid,
        }
    }
}

impl Options {
    /// The paper's setting: a fixed depth of 5 levels, lazy refit, central vertices closest to
    /// the rest centroid.
    pub fn paper() -> Self {
        Self {
            levels: Some(PAPER_LEVELS),
            ..Self::default()
        }
    }

    /// The region tree these options ask for.
    #[doc(hidden)]
    pub fn shape(&self) -> TreeShape {
        match self.levels {
            Some(levels) => TreeShape::Levels(levels),
            None => TreeShape::Adaptive {
                leaf_size: self.leaf_size,
            },
        }
    }
}
