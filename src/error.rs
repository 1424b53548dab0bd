//! Typed errors. Kernels and traversal cannot fail: every precondition is checked once, here,
//! at construction, update and I/O.

use std::borrow::Cow;
use std::path::{Path, PathBuf};

use crate::precision::Precision;

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
    NonFinite { vertex: usize, position: [f64; 3] },
    /// An `f64` coordinate too large to round to a finite `f32` (bounding volumes are `f32`).
    #[error("vertex {vertex} has a coordinate beyond the f32 range {position:?} (|x| must be below about 3.4e38)")]
    OutOfRange { vertex: usize, position: [f64; 3] },
    /// Positions of one precision given to a mesh or hierarchy of the other: an `f32`
    /// update of an `f64` hierarchy would silently round it.
    #[error("positions are {got}, but the mesh or hierarchy is {expected}")]
    PrecisionMismatch { expected: Precision, got: Precision },
    #[error("position update has {got} vertices, but the mesh has {expected}")]
    WrongVertexCount { expected: usize, got: usize },
    /// A region tree depth outside `1..=max` ([`tree::MAX_LEVELS`](crate::tree::MAX_LEVELS)).
    #[error("levels must be between 1 and {max}, got {got}")]
    InvalidLevels { got: usize, max: usize },
    /// A leaf size outside `1..=max` ([`tree::MAX_LEAF_SIZE`](crate::tree::MAX_LEAF_SIZE)).
    #[error("leaf size must be between 1 and {max}, got {got}")]
    InvalidLeafSize { got: usize, max: usize },
    /// Two hierarchies of different methods, by name ([`Method::name`](crate::Method::name)).
    #[error("cannot collide a {a} hierarchy with a {b} hierarchy")]
    MethodMismatch { a: &'static str, b: &'static str },
    #[error("no object with id {0} in the scene")]
    UnknownObject(u64),
    #[error("object {0} is given more than once in one update")]
    RepeatedObject(u64),
    /// A method name that is none of `expected` (the names of
    /// [`Method::ALL`](crate::Method::ALL), comma-separated).
    #[error("unknown method {got:?} (expected one of {expected})")]
    UnknownMethod { got: String, expected: String },
    #[error("unknown refit mode {0:?} (expected lazy, eager or bottom-up)")]
    UnknownRefit(String),
    #[error("unknown central vertex {0:?} (expected rest-centroid or min-radius)")]
    UnknownCentral(String),
    #[error("unknown precision {0:?} (expected f32 or f64)")]
    UnknownPrecision(String),
    /// A query distance that is negative, NaN or infinite.
    #[error("distance {0} is not a finite number >= 0")]
    InvalidDistance(f64),
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
    /// A contact whose triangles do not intersect in the current pose (contact segments asked
    /// for contacts of an earlier pose).
    #[error("triangles {pair:?} do not intersect in the current pose (stale contacts?)")]
    StaleContact { pair: [u32; 2] },
    /// A thread count above `max` ([`Par::MAX_THREADS`](crate::Par::MAX_THREADS)); `cores`
    /// is [`Par::max_threads`](crate::Par::max_threads).
    #[error(
        "thread count {got} is out of range: threads must be 0 (all cores), 1 (the calling \
         thread) or up to {max} (at most {cores} are used on this machine)"
    )]
    InvalidThreads {
        got: usize,
        max: usize,
        cores: usize,
    },
    /// A CCD time limit outside [0, 1] (or NaN).
    #[error("CCD t_max must be in [0, 1], got {0}")]
    InvalidTimeLimit(f64),
    /// A CCD minimum distance that is negative, infinite or NaN.
    #[error("CCD min_distance must be finite and >= 0, got {0}")]
    InvalidMinDistance(f64),
    /// A CCD query point with a NaN or infinite coordinate (`point` 0-3 at t = 0, 4-7 at
    /// t = 1, in the order of the query).
    #[error("CCD point {point} has a non-finite coordinate {position:?}")]
    NonFiniteCcdPoint { point: usize, position: [f64; 3] },
    #[error("{}: {}", escaped_path(.path), escaped(.message))]
    Io { path: PathBuf, message: String },
    #[error(
        "{}: the file is larger than the limit of {limit} bytes for mesh files (raise it \
         with --max-file-bytes, or io::Limits in the library)",
        escaped_path(.path)
    )]
    FileTooLarge { path: PathBuf, limit: u64 },
    #[error("{}:{line}: {}", escaped_path(.path), escaped(.message))]
    Parse {
        path: PathBuf,
        line: usize,
        message: String,
    },
}

pub type Result<T, E = Error> = std::result::Result<T, E>;

/// `text` with every control character (newlines and NUL included) and line separator
/// written as an escape (`\n`, `\0`, `\u{1b}`), so that a message that echoes a path or a
/// token from a file is always one line of printable text.
#[doc(hidden)]
pub fn escaped(text: &str) -> Cow<'_, str> {
    let special = |c: char| c.is_control() || matches!(c, '\u{2028}' | '\u{2029}');
    if !text.contains(special) {
        return Cow::Borrowed(text);
    }
    let mut out = String::with_capacity(text.len() + 8);
    for c in text.chars() {
        match c {
            '\0' => out.push_str("\\0"),
            c if special(c) => out.extend(c.escape_default()),
            c => out.push(c),
        }
    }
    Cow::Owned(out)
}

/// A path as [`escaped`] text (bytes that are not UTF-8 shown as U+FFFD).
#[doc(hidden)]
pub fn escaped_path(path: &Path) -> String {
    escaped(&path.to_string_lossy()).into_owned()
}
