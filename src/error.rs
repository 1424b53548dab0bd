//! Typed errors. Kernels and traversal cannot fail: every precondition is checked once, here,
//! at construction, update and I/O.

use std::path::PathBuf;

/// Everything that can go wrong when building, updating, querying or loading a mesh or
/// hierarchy. One variant per failure, so callers (the C ABI, the Python module) map
/// variants, never messages.
#[derive(Debug, thiserror::Error, Clone, PartialEq)]
#[non_exhaustive]
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
    #[error("unknown method {0:?} (expected one of {names})", names = crate::kinds::Method::names())]
    UnknownMethod(String),
    #[error("unknown refit mode {0:?} (expected lazy, eager or bottom-up)")]
    UnknownRefit(String),
    /// A node id (e.g. given to `refit_nodes`) beyond the hierarchy's nodes.
    #[error("node {node} out of range (the hierarchy has {node_count} nodes)")]
    NodeOutOfRange { node: u32, node_count: usize },
    /// A node id given where a leaf is needed (`narrow_phase`) names an internal node.
    #[error("node {node} is not a leaf")]
    NotALeaf { node: u32 },
    /// A region tree shared with a mesh it was not built for.
    #[error(
        "region tree of {tree_vertices} vertices / {tree_triangles} triangles does not fit a mesh of {mesh_vertices} / {mesh_triangles}"
    )]
    TreeMismatch {
        tree_vertices: usize,
        tree_triangles: usize,
        mesh_vertices: usize,
        mesh_triangles: usize,
    },
    /// A contact names a triangle index the mesh does not have.
    #[error("contact names triangle {triangle}, but the mesh has only {triangle_count} triangles")]
    TriangleOutOfRange {
        triangle: u64,
        triangle_count: usize,
    },
    /// A contact whose triangles do not intersect in the current pose (contact detail asked
    /// for contacts of an earlier pose).
    #[error("triangles {pair:?} do not intersect in the current pose (stale contacts?)")]
    StaleContact { pair: [u32; 2] },
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
