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
    /// A mesh without vertices.
    #[error("mesh has no vertices")]
    NoVertices,
    /// A mesh without triangles.
    #[error("mesh has no triangles")]
    NoTriangles,
    /// More vertices than a `u32` index can name (the count given).
    #[error("mesh has {0} vertices; at most {max} are supported", max = u32::MAX - 1)]
    TooManyVertices(usize),
    /// More triangles than a `u32` index can name (the count given).
    #[error("mesh has {0} triangles; at most {max} are supported", max = u32::MAX - 1)]
    TooManyTriangles(usize),
    /// A triangle names a vertex the mesh does not have.
    #[error(
        "triangle {triangle} uses vertex {index}, but the mesh has only {vertex_count} vertices"
    )]
    IndexOutOfRange {
        /// The triangle (index in the input).
        triangle: usize,
        /// The vertex index it uses.
        index: u32,
        /// The mesh's number of vertices.
        vertex_count: usize,
    },
    /// A triangle names one vertex twice.
    #[error("triangle {triangle} repeats vertex {index} ({corners:?})")]
    RepeatedIndex {
        /// The triangle (index in the input).
        triangle: usize,
        /// The repeated vertex index.
        index: u32,
        /// Its three corners.
        corners: [u32; 3],
    },
    /// A NaN or infinite coordinate.
    #[error("vertex {vertex} of {of}{} has a non-finite coordinate {position:?}", in_object(.object))]
    NonFinite {
        /// The vertex (index in the input).
        vertex: usize,
        /// Its coordinates.
        position: [f64; 3],
        /// Which positions: a mesh's, an update, the start or the end of a step.
        of: Positions,
        /// The scene object they belong to, in a scene call.
        object: Option<u64>,
    },
    /// An `f64` coordinate too large to round to a finite `f32` (bounding volumes are `f32`).
    #[error(
        "vertex {vertex} of {of}{} has a coordinate beyond the f32 range {position:?} (|x| \
         must be below about 3.4e38)",
        in_object(.object)
    )]
    OutOfRange {
        /// The vertex (index in the input).
        vertex: usize,
        /// Its coordinates.
        position: [f64; 3],
        /// Which positions.
        of: Positions,
        /// The scene object they belong to, in a scene call.
        object: Option<u64>,
    },
    /// Positions of one precision given to a mesh or hierarchy of the other: an `f32`
    /// update of an `f64` hierarchy would silently round it.
    #[error("positions are {got}, but the mesh or hierarchy is {expected}")]
    PrecisionMismatch {
        /// The precision of the mesh or hierarchy.
        expected: Precision,
        /// The precision of the positions given.
        got: Precision,
    },
    /// Positions (an update, or the start or end of a step) whose length is not the mesh's
    /// vertex count.
    #[error("{of}{} has {got} vertices, but the mesh has {expected}", in_object(.object))]
    WrongVertexCount {
        /// The mesh's number of vertices.
        expected: usize,
        /// The number given.
        got: usize,
        /// Which positions.
        of: Positions,
        /// The scene object they belong to, in a scene call.
        object: Option<u64>,
    },
    /// A region tree depth outside `1..=max` ([`tree::MAX_LEVELS`](crate::tree::MAX_LEVELS)).
    #[error("levels must be between 1 and {max}, got {got}")]
    InvalidLevels {
        /// The depth given.
        got: usize,
        /// The largest depth accepted.
        max: usize,
    },
    /// A leaf size outside `1..=max` ([`tree::MAX_LEAF_SIZE`](crate::tree::MAX_LEAF_SIZE)).
    #[error("leaf size must be between 1 and {max}, got {got}")]
    InvalidLeafSize {
        /// The leaf size given.
        got: usize,
        /// The largest leaf size accepted.
        max: usize,
    },
    /// Two hierarchies of different methods, by name ([`Method::name`](crate::Method::name)).
    #[error("cannot collide a {a} hierarchy with a {b} hierarchy")]
    MethodMismatch {
        /// The first hierarchy's method.
        a: &'static str,
        /// The second hierarchy's method.
        b: &'static str,
    },
    /// An object id that is not (or no longer) in the scene.
    #[error("no object with id {0} in the scene")]
    UnknownObject(u64),
    /// An object id given twice in one update.
    #[error("object {0} is given more than once in one update")]
    RepeatedObject(u64),
    /// A method name that is none of `expected` (the names of
    /// [`Method::ALL`](crate::Method::ALL), comma-separated).
    #[error("unknown method {got:?} (expected one of {expected})")]
    UnknownMethod {
        /// The name given.
        got: String,
        /// The names accepted.
        expected: String,
    },
    /// A refit mode name that is none of `lazy`, `eager`, `bottom-up`.
    #[error("unknown refit mode {0:?} (expected lazy, eager or bottom-up)")]
    UnknownRefit(String),
    /// A central vertex name that is none of `rest-centroid`, `min-radius`.
    #[error("unknown central vertex {0:?} (expected rest-centroid or min-radius)")]
    UnknownCentral(String),
    /// A precision name that is none of `f32`, `f64`.
    #[error("unknown precision {0:?} (expected f32 or f64)")]
    UnknownPrecision(String),
    /// A query distance that is negative, NaN or infinite.
    #[error("distance {} is not a finite number >= 0", Num(*.0))]
    InvalidDistance(f64),
    /// A node id (e.g. given to `refit_nodes`) beyond the hierarchy's nodes.
    #[error("node {node} out of range (the hierarchy has {node_count} nodes)")]
    NodeOutOfRange {
        /// The node id given.
        node: u32,
        /// The hierarchy's number of nodes.
        node_count: usize,
    },
    /// A node id given where a leaf is needed (`narrow_phase`) names an internal node.
    #[error("node {node} is not a leaf")]
    NotALeaf {
        /// The node id given.
        node: u32,
    },
    /// A region tree shared with a mesh it was not built for.
    #[error(
        "region tree of {tree_vertices} vertices / {tree_triangles} triangles does not fit a mesh of {mesh_vertices} / {mesh_triangles}"
    )]
    TreeMismatch {
        /// The tree's number of vertices.
        tree_vertices: usize,
        /// The tree's number of triangles.
        tree_triangles: usize,
        /// The mesh's number of vertices.
        mesh_vertices: usize,
        /// The mesh's number of triangles.
        mesh_triangles: usize,
    },
    /// A contact names a triangle index the mesh does not have.
    #[error("contact names triangle {triangle}, but the mesh has only {triangle_count} triangles")]
    TriangleOutOfRange {
        /// The triangle index given.
        triangle: u64,
        /// The mesh's number of triangles.
        triangle_count: usize,
    },
    /// A contact whose triangles do not intersect in the current pose (contact segments asked
    /// for contacts of an earlier pose).
    #[error("triangles {pair:?} do not intersect in the current pose (stale contacts?)")]
    StaleContact {
        /// The pair given.
        pair: [u32; 2],
    },
    /// A thread count above `max` ([`Par::MAX_THREADS`](crate::Par::MAX_THREADS)); `cores`
    /// is [`Par::max_threads`](crate::Par::max_threads).
    #[error(
        "thread count {got} is out of range: threads must be 0 (all cores), 1 (the calling \
         thread) or up to {max} (at most {cores} are used on this machine)"
    )]
    InvalidThreads {
        /// The count given.
        got: usize,
        /// The largest count accepted.
        max: usize,
        /// The most threads used on this machine.
        cores: usize,
    },
    /// A CCD time limit outside [0, 1] (or NaN).
    #[error("CCD t_max must be in [0, 1], got {}", Num(*.0))]
    InvalidTimeLimit(f64),
    /// A CCD minimum distance that is negative, infinite or NaN.
    #[error("CCD min_distance must be finite and >= 0, got {}", Num(*.0))]
    InvalidMinDistance(f64),
    /// A CCD query point with a NaN or infinite coordinate (`point` 0-3 at t = 0, 4-7 at
    /// t = 1, in the order of the query).
    #[error("CCD point {point} has a non-finite coordinate {position:?}")]
    NonFiniteCcdPoint {
        /// The point (0-3 at t = 0, 4-7 at t = 1).
        point: usize,
        /// Its coordinates.
        position: [f64; 3],
    },
    /// A query would return more result pairs than its [`crate::Control::max_pairs`]: it
    /// stopped when the count passed the limit (nothing is returned).
    #[error(
        "the query stopped at {reached} result pairs, over the limit of {limit} \
         (Control::max_pairs; raise it, up to no limit, or ask a smaller distance or step)"
    )]
    OutputLimit {
        /// Result pairs found when the query stopped (at least `limit + 1`).
        reached: u64,
        /// The limit.
        limit: u64,
    },
    /// A result buffer could not grow: the allocator refused (nothing is returned).
    #[error("out of memory: a result buffer of {bytes} bytes could not be allocated")]
    OutOfMemory {
        /// The size of the buffer asked for, in bytes.
        bytes: u64,
    },
    /// The query was cancelled (its [`crate::Control`]'s flag was set, or its poll
    /// function asked to stop): nothing is returned.
    #[error("the query was cancelled")]
    Cancelled,
    /// A contact type code outside 0..=3 (point-point, point-edge, point-triangle,
    /// edge-edge).
    #[error("unknown contact type {0} (expected 0 point-point, 1 point-edge, 2 point-triangle or 3 edge-edge)")]
    UnknownContactType(u8),
    /// Two arrays that must have one entry each per row differ in length.
    #[error("{what} has {got} rows, expected {expected}")]
    LengthMismatch {
        /// What was given.
        what: &'static str,
        /// The rows expected.
        expected: usize,
        /// The rows given.
        got: usize,
    },
    /// A step-size rescaling outside `(0, 1]`.
    #[error("rescaling must be in (0, 1], got {}", Num(*.0))]
    InvalidRescaling(f64),
    /// A file that cannot be read (or written), with the system's message.
    #[error("{}: {}", escaped_path(.path), escaped(.message))]
    Io {
        /// The file.
        path: PathBuf,
        /// What went wrong.
        message: String,
    },
    /// A mesh file larger than [`io::Limits::max_file_bytes`](crate::io::Limits::max_file_bytes).
    #[error(
        "{}: the file is larger than the limit of {limit} bytes for mesh files (raise it \
         with --max-file-bytes, or io::Limits in the library)",
        escaped_path(.path)
    )]
    FileTooLarge {
        /// The file.
        path: PathBuf,
        /// The limit in bytes.
        limit: u64,
    },
    /// A malformed mesh file: the line (1-based; 0 for binary files and for what concerns
    /// the whole file, which the message then does not cite) and what is wrong.
    #[error("{}{}: {}", escaped_path(.path), at_line(*.line), escaped(.message))]
    Parse {
        /// The file.
        path: PathBuf,
        /// The line (1-based; 0 for binary files and for the whole file).
        line: usize,
        /// What is wrong.
        message: String,
    },
}

/// `Result` with this crate's [`Error`].
pub type Result<T, E = Error> = std::result::Result<T, E>;

/// Which positions an error is about.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[non_exhaustive]
pub enum Positions {
    /// A mesh's own positions (at construction).
    Mesh,
    /// A position update of a hierarchy or scene object.
    Update,
    /// The positions at the start of a step (`x0`, t = 0).
    Start,
    /// The positions at the end of a step (`x1`, t = 1).
    End,
    /// Rest positions given for a contact set's mollifier thresholds.
    Rest,
}

impl std::fmt::Display for Positions {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            Positions::Mesh => "the mesh",
            Positions::Update => "the position update",
            Positions::Start => "x0 (the positions at t = 0)",
            Positions::End => "x1 (the positions at t = 1)",
            Positions::Rest => "the rest positions",
        })
    }
}

/// ":N" for a line of a text file, nothing for line 0 (the whole file, or a binary one).
fn at_line(line: usize) -> String {
    if line == 0 {
        String::new()
    } else {
        format!(":{line}")
    }
}

/// " of object N" for an error in a scene call, else nothing.
fn in_object(object: &Option<u64>) -> String {
    object.map_or_else(String::new, |id| format!(" of object {id}"))
}

/// A number in messages: the shortest text that reads back as the same `f64`, with an
/// exponent for very large or small magnitudes (`1e-300`, not 300 digits).
pub(crate) struct Num(pub(crate) f64);

impl std::fmt::Display for Num {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        // `Debug` of an f64 is the shortest round-trip text, with an exponent outside
        // 1e-5..1e16.
        write!(f, "{:?}", self.0)
    }
}

impl Error {
    /// The error with the scene object it concerns (for errors about an object's
    /// positions); other errors unchanged.
    #[doc(hidden)]
    pub fn in_object(mut self, id: u64) -> Self {
        if let Error::NonFinite { object, .. }
        | Error::OutOfRange { object, .. }
        | Error::WrongVertexCount { object, .. } = &mut self
        {
            *object = Some(id);
        }
        self
    }
}

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
