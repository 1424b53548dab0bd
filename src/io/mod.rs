//! Mesh file formats: Wavefront OBJ, STL (ASCII and binary) and PLY (ASCII, binary little-
//! and big-endian).
//!
//! All parsers are hand-written so the index semantics are exactly the ones the rest of the
//! crate (and its users) rely on:
//!
//! - Triangles come out in file order of faces, with 0-based vertex indices. A face with
//!   `k > 3` corners is split as a fan, in order: `(v0,v1,v2), (v0,v2,v3), …`.
//! - OBJ: vertex identity is the `v` index. All `v` lines of the file, in order, form one
//!   position array regardless of `o`/`g` groups; texture/normal indices never duplicate a
//!   vertex.
//! - STL: corners whose coordinates are bit-identical f32s (with `-0.0 == 0.0`) are welded into
//!   one vertex, in first-appearance order, so shared edges are recognised.
//! - PLY: `vertex` element with `x`, `y`, `z`; `face` element with a `vertex_indices` (or
//!   `vertex_index`) list; every other element and property is skipped.
//!
//! Every malformed input yields an [`Error::Parse`] (or [`Error::Io`] when the file cannot be
//! read) whose one-line message names the file and, for text formats, the line. No byte input
//! makes a parser panic.

mod obj;
mod ply;
mod stl;

use std::path::Path;

use crate::error::{Error, Result};
use crate::mesh::Mesh;
use crate::precision::Precision;

pub use obj::write_obj;
#[doc(hidden)]
pub use obj::{parse_obj, parse_obj_bytes};
#[doc(hidden)]
pub use ply::parse_ply;
#[doc(hidden)]
pub use stl::parse_stl;

/// The mesh file formats `dhcd` reads.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[non_exhaustive]
pub enum Format {
    /// Wavefront OBJ (text).
    Obj,
    /// STL, ASCII or binary (detected from the contents).
    Stl,
    /// PLY, ASCII or binary of either endianness (declared in the header).
    Ply,
}

impl Format {
    /// The format named by `path`'s extension (case-insensitive), if any.
    #[doc(hidden)]
    pub fn from_extension(path: &Path) -> Option<Format> {
        let ext = path.extension()?.to_str()?.to_ascii_lowercase();
        match ext.as_str() {
            "obj" => Some(Format::Obj),
            "stl" => Some(Format::Stl),
            "ply" => Some(Format::Ply),
            _ => None,
        }
    }

    /// Guesses the format from the first bytes of a file, if they are recognisable.
    #[doc(hidden)]
    pub fn sniff(bytes: &[u8]) -> Option<Format> {
        if bytes.starts_with(b"ply\n") || bytes.starts_with(b"ply\r") {
            return Some(Format::Ply);
        }
        if stl::is_binary(bytes) {
            return Some(Format::Stl);
        }
        let trimmed = trim_ascii_start(strip_bom(bytes));
        if trimmed.len() >= 5 && trimmed[..5].eq_ignore_ascii_case(b"solid") {
            return Some(Format::Stl);
        }
        if obj::looks_like_obj(bytes) {
            return Some(Format::Obj);
        }
        None
    }

    /// Lower-case name, as used in messages.
    pub fn name(self) -> &'static str {
        match self {
            Format::Obj => "OBJ",
            Format::Stl => "STL",
            Format::Ply => "PLY",
        }
    }
}

/// The largest mesh file read by default: 1 GiB (a binary STL of 21 million triangles).
pub const DEFAULT_MAX_FILE_BYTES: u64 = 1 << 30;

/// Bounds on what a loader reads, so that no file (a device that never ends, a sparse file of
/// many gigabytes) can take unbounded memory or time. See `docs/LIMITS.md`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Limits {
    /// Files larger than this are refused with [`Error::FileTooLarge`] before being read.
    pub max_file_bytes: u64,
}

impl Default for Limits {
    fn default() -> Self {
        Self {
            max_file_bytes: DEFAULT_MAX_FILE_BYTES,
        }
    }
}

/// Loads a mesh with the default [`Limits`], choosing the format from the extension
/// (case-insensitive) or, failing that, from the contents. Coordinates are read as `f32`
/// ([`Precision::F32`]); see [`load_as`] for `f64`.
pub fn load(path: &Path) -> Result<Mesh> {
    load_with(path, &Limits::default())
}

/// As [`load`], within `limits`.
pub fn load_with(path: &Path, limits: &Limits) -> Result<Mesh> {
    load_as(path, limits, Precision::F32)
}

/// As [`load_with`], building a mesh of `precision`. With [`Precision::F64`], PLY `double`
/// properties and OBJ decimals are read at full `f64` precision (a PLY `float` or an STL
/// coordinate is an `f32` value, which `f64` holds exactly); with [`Precision::F32`] each
/// is rounded to the nearest `f32`.
pub fn load_as(path: &Path, limits: &Limits, precision: Precision) -> Result<Mesh> {
    let bytes = read(path, limits)?;
    let format = match Format::from_extension(path).or_else(|| Format::sniff(&bytes)) {
        Some(format) => format,
        None => {
            return Err(Error::Parse {
                path: path.to_path_buf(),
                line: 0,
                message: "unknown mesh format: the extension is not .obj, .stl or .ply and the \
                          contents look like none of them"
                    .to_string(),
            })
        }
    };
    parse_as(&bytes, format, path, precision)
}

/// Parses `bytes` as `format` (`f32` coordinates); `path` is only used in error messages.
pub fn parse(bytes: &[u8], format: Format, path: &Path) -> Result<Mesh> {
    parse_as(bytes, format, path, Precision::F32)
}

/// Parses `bytes` as `format` into a mesh of `precision` (see [`load_as`]).
pub fn parse_as(bytes: &[u8], format: Format, path: &Path, precision: Precision) -> Result<Mesh> {
    match (format, precision) {
        (Format::Obj, Precision::F32) => obj::parse_obj_bytes_as::<f32>(bytes, path),
        (Format::Obj, Precision::F64) => obj::parse_obj_bytes_as::<f64>(bytes, path),
        (Format::Ply, Precision::F32) => ply::parse_ply_as::<f32>(bytes, path),
        (Format::Ply, Precision::F64) => ply::parse_ply_as::<f64>(bytes, path),
        (Format::Stl, Precision::F32) => parse_stl(bytes, path),
        // STL stores f32 coordinates: f64 holds them exactly.
        (Format::Stl, Precision::F64) => {
            let m = parse_stl(bytes, path)?;
            let positions = m.positions().iter().map(|p| p.map(f64::from)).collect();
            Mesh::new_f64(positions, m.triangles().to_vec())
        }
    }
}

/// A coordinate type the text and PLY parsers read into: `f32` or `f64`.
pub(crate) trait Coordinate: Copy + Default + std::fmt::Display {
    /// The type's name in messages.
    const NAME: &'static str;
    /// A decimal token, rounded once to this type.
    fn parse_decimal(token: &str) -> Option<Self>;
    /// A value read as `f64` (a PLY `double`, or a `float` widened exactly).
    fn from_f64(x: f64) -> Self;
    /// A PLY integer property.
    fn from_i64(i: i64) -> Self;
    fn is_finite(self) -> bool;
    /// The mesh of these positions.
    fn mesh(positions: Vec<[Self; 3]>, triangles: Vec<[u32; 3]>) -> Result<Mesh>;
}

impl Coordinate for f32 {
    const NAME: &'static str = "f32";
    fn parse_decimal(token: &str) -> Option<Self> {
        token.parse().ok()
    }
    fn from_f64(x: f64) -> Self {
        x as f32
    }
    fn from_i64(i: i64) -> Self {
        i as f32
    }
    fn is_finite(self) -> bool {
        f32::is_finite(self)
    }
    fn mesh(positions: Vec<[Self; 3]>, triangles: Vec<[u32; 3]>) -> Result<Mesh> {
        Mesh::new(positions, triangles)
    }
}

impl Coordinate for f64 {
    const NAME: &'static str = "f64";
    fn parse_decimal(token: &str) -> Option<Self> {
        token.parse().ok()
    }
    fn from_f64(x: f64) -> Self {
        x
    }
    fn from_i64(i: i64) -> Self {
        i as f64
    }
    fn is_finite(self) -> bool {
        f64::is_finite(self)
    }
    fn mesh(positions: Vec<[Self; 3]>, triangles: Vec<[u32; 3]>) -> Result<Mesh> {
        Mesh::new_f64(positions, triangles)
    }
}

/// Reads a whole mesh file: only regular files (symbolic links followed), at most
/// `limits.max_file_bytes`.
#[doc(hidden)]
pub fn read(path: &Path, limits: &Limits) -> Result<Vec<u8>> {
    use std::io::Read;
    let io = |message: String| Error::Io {
        path: path.to_path_buf(),
        message,
    };
    let cannot = |e: std::io::Error| io(format!("cannot read mesh file: {e}"));
    // Look before opening: opening a FIFO that has no writer blocks forever.
    let meta = std::fs::metadata(path).map_err(cannot)?;
    if !meta.is_file() {
        return Err(io(format!(
            "not a regular file ({}): mesh files must be regular files",
            file_kind(&meta.file_type())
        )));
    }
    let too_large = || Error::FileTooLarge {
        path: path.to_path_buf(),
        limit: limits.max_file_bytes,
    };
    if meta.len() > limits.max_file_bytes {
        return Err(too_large());
    }
    let file = std::fs::File::open(path).map_err(cannot)?;
    // The file may have grown (or been replaced) since: never read past the limit.
    let mut bytes = Vec::new();
    let _ = bytes.try_reserve_exact(meta.len() as usize);
    file.take(limits.max_file_bytes.saturating_add(1))
        .read_to_end(&mut bytes)
        .map_err(cannot)?;
    if bytes.len() as u64 > limits.max_file_bytes {
        return Err(too_large());
    }
    Ok(bytes)
}

fn file_kind(t: &std::fs::FileType) -> &'static str {
    #[cfg(unix)]
    {
        use std::os::unix::fs::FileTypeExt;
        if t.is_fifo() {
            return "a FIFO";
        }
        if t.is_char_device() {
            return "a character device";
        }
        if t.is_block_device() {
            return "a block device";
        }
        if t.is_socket() {
            return "a socket";
        }
    }
    if t.is_dir() {
        "a directory"
    } else {
        "not a file"
    }
}

/// Where the line that starts at `pos` ends, and where the next one starts. A line ends at
/// `\n`, `\r\n`, a lone `\r` (classic Mac files) or the end of `bytes`.
pub(crate) fn line_end(bytes: &[u8], pos: usize) -> (usize, usize) {
    let rest = &bytes[pos.min(bytes.len())..];
    match rest.iter().position(|&b| b == b'\n' || b == b'\r') {
        None => (bytes.len(), bytes.len()),
        Some(i) => {
            let crlf = rest[i] == b'\r' && rest.get(i + 1) == Some(&b'\n');
            (pos + i, pos + i + 1 + usize::from(crlf))
        }
    }
}

/// `bytes` without a leading UTF-8 byte order mark.
pub(crate) fn strip_bom(bytes: &[u8]) -> &[u8] {
    bytes.strip_prefix(b"\xef\xbb\xbf").unwrap_or(bytes)
}

fn trim_ascii_start(bytes: &[u8]) -> &[u8] {
    let start = bytes
        .iter()
        .position(|b| !b.is_ascii_whitespace())
        .unwrap_or(bytes.len());
    &bytes[start..]
}

/// A parse error at `line` (0 when not applicable).
pub(crate) fn parse_error(path: &Path, line: usize, message: impl Into<String>) -> Error {
    Error::Parse {
        path: path.to_path_buf(),
        line,
        message: message.into(),
    }
}

/// Builds the mesh; any validation error the parser did not already report with a line number
/// is reported against the file.
pub(crate) fn build<T: Coordinate>(
    path: &Path,
    positions: Vec<[T; 3]>,
    triangles: Vec<[u32; 3]>,
) -> Result<Mesh> {
    if positions.is_empty() && triangles.is_empty() {
        return Err(parse_error(
            path,
            0,
            "file contains no vertices and no triangles (empty mesh)",
        ));
    }
    if positions.is_empty() {
        return Err(parse_error(path, 0, "file contains no vertices"));
    }
    if triangles.is_empty() {
        return Err(parse_error(path, 0, "file contains no triangles"));
    }
    T::mesh(positions, triangles).map_err(|e| match e {
        Error::Io { .. } | Error::Parse { .. } => e,
        other => parse_error(path, 0, format!("invalid mesh: {other}")),
    })
}

/// Splits a polygon as a fan `(v0,v1,v2), (v0,v2,v3), …`, appending to `out`. Returns the
/// first fan triangle that repeats a vertex index (which a [`Mesh`] rejects), if any; nothing
/// is appended then.
pub(crate) fn fan(corners: &[u32], out: &mut Vec<[u32; 3]>) -> std::result::Result<(), [u32; 3]> {
    let Some((&v0, rest)) = corners.split_first() else {
        return Ok(());
    };
    for pair in rest.windows(2) {
        let t = [v0, pair[0], pair[1]];
        if t[0] == t[1] || t[0] == t[2] || t[1] == t[2] {
            return Err(t);
        }
    }
    out.extend(rest.windows(2).map(|pair| [v0, pair[0], pair[1]]));
    Ok(())
}
