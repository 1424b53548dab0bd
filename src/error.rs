//! Typed errors. Kernels and traversal cannot fail: every precondition is checked once, here,
//! at construction, update and I/O.

use std::path::PathBuf;

/// Everything that can go wrong when building, updating or loading a mesh or hierarchy.
#[derive(Debug, thiserror::Error, Clone, PartialEq)]
pub enum Error {
    #[error("mesh has no vertices")]
    NoVertices,
    #[error("mesh has no triangles")]
    NoTriangles,
    #[error("mesh has {0} vertices; at most {max} are supported", max = u32::MAX - 1)]
    TooManyVertices(usize),
    #[error("mesh has {0} triangles; at most {max} are supported", max = u32::MAX - 1)]
    TooManyTriangles(usize),
    #[error(
        "triangle {triangle} uses vertex {index}, but the mesh has only {vertex_count} vertices"
    )]
    IndexOutOfRange {
        triangle: usize,
        index: u32,
        vertex_count: usize,
    },
    #[error("triangle {triangle} repeats vertex {index} ({corners:?})")]
    RepeatedIndex {
        triangle: usize,
        index: u32,
        corners: [u32; 3],
    },
    #[error("vertex {vertex} has a non-finite coordinate {position:?}")]
    NonFinite { vertex: usize, position: [f32; 3] },
    #[error("position update has {got} vertices, but the mesh has {expected}")]
    WrongVertexCount { expected: usize, got: usize },
    #[error("levels must be between 1 and {max}, got {got}", max = crate::tree::MAX_LEVELS)]
    InvalidLevels { got: usize },
    #[error("leaf size must be between 1 and {max}, got {got}", max = crate::tree::MAX_LEAF_SIZE)]
    InvalidLeafSize { got: usize },
    #[error("cannot collide a {a} hierarchy with a {b} hierarchy")]
    MethodMismatch {
        a: crate::bv::Method,
        b: crate::bv::Method,
    },
    #[error("no object with id {0} in the scene")]
    UnknownObject(u64),
    #[error("invalid option: {0}")]
    InvalidOption(String),
    #[error("{path}: {message}")]
    Io { path: PathBuf, message: String },
    #[error("{path}:{line}: {message}")]
    Parse {
        path: PathBuf,
        line: usize,
        message: String,
    },
}

pub type Result<T, E = Error> = std::result::Result<T, E>;
