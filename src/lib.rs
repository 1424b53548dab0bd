//! # dhcd — Distance Hierarchy collision detection for deformable triangle meshes
//!
//! Three bounding-volume hierarchies over one shared region tree (the paper's Distance
//! Hierarchy, spheres, axis-aligned boxes), lazily refitted after every deformation, a
//! stackless level-synchronous traversal, and an exact triangle-triangle narrow phase.
//! Every query counts its work (`N_V`, `N_P`, `N_U`) for the cost model
//! `T = N_V*C_V + N_P*C_P + N_U*C_U`.
#![forbid(unsafe_code)]

pub mod error;
pub mod io;
pub mod mesh;
pub mod narrow;
pub mod sim;

pub use error::{Error, Result};
pub use mesh::Mesh;
