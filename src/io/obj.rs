//! Wavefront OBJ reader and writer (hand-written: vertex identity is the `v` index, which
//! general-purpose OBJ crates do not preserve when they split by object/group and reindex).

use std::fmt::Write as _;
use std::io::Write;
use std::path::Path;

use super::{build, fan, parse_error, Coordinate};
use crate::error::Result;
use crate::mesh::Mesh;

/// Statements that are legal OBJ but carry nothing a triangle mesh needs (also used to
/// recognise an OBJ file by its first statement).
const IGNORED: &[&str] = &[
    "vt",
    "vn",
    "vp",
    "o",
    "g",
    "s",
    "mg",
    "usemtl",
    "mtllib",
    "usemap",
    "maplib",
    "l",
    "p",
    "cstype",
    "deg",
    "bmat",
    "step",
    "curv",
    "curv2",
    "surf",
    "parm",
    "trim",
    "hole",
    "scrv",
    "sp",
    "end",
    "con",
    "lod",
    "bevel",
    "c_interp",
    "d_interp",
    "shadow_obj",
    "trace_obj",
    "ctech",
    "stech",
    "call",
    "csh",
];

/// Parses OBJ bytes, reporting invalid UTF-8 with its line.
pub fn parse_obj_bytes(bytes: &[u8], path: &Path) -> Result<Mesh> {
    parse_obj_bytes_as::<f32>(bytes, path)
}

/// [`parse_obj_bytes`] into coordinates of type `T`.
pub(crate) fn parse_obj_bytes_as<T: Coordinate>(bytes: &[u8], path: &Path) -> Result<Mesh> {
    match std::str::from_utf8(bytes) {
        Ok(text) => parse_obj_as::<T>(text, path),
        Err(e) => {
            let good = &bytes[..e.valid_up_to()];
            let line = 1 + good.iter().filter(|&&b| b == b'\n').count();
            Err(parse_error(
                path,
                line,
                format!("invalid UTF-8 at byte offset {}", e.valid_up_to()),
            ))
        }
    }
}

/// Parses Wavefront OBJ text. `path` is only used in error messages.
///
/// Positions are all `v` lines in file order (extra components such as `w` or vertex colours
/// are ignored); triangles are the `f` lines in file order, polygons fan-split. Indices may be
/// positive (1-based) or negative (relative to the vertices defined so far) and may carry
/// texture/normal indices (`i/t`, `i//n`, `i/t/n`), which are ignored.
pub fn parse_obj(text: &str, path: &Path) -> Result<Mesh> {
    parse_obj_as::<f32>(text, path)
}

/// [`parse_obj`] into coordinates of type `T` (each decimal rounded once, to `T`).
pub(crate) fn parse_obj_as<T: Coordinate>(text: &str, path: &Path) -> Result<Mesh> {
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
    let mut positions: Vec<[T; 3]> = Vec::new();
    let mut triangles: Vec<[u32; 3]> = Vec::new();
    let mut corners: Vec<u32> = Vec::new();
    // Largest (0-based) positive index and the line that used it first: positive indices may
    // refer forward, so they are checked once all vertices are known.
    let mut max_index: Option<(u32, usize)> = None;
    let mut continued = String::new();
    let mut continued_from = 0;

    for (number, raw) in lines(text).enumerate() {
        let mut line_no = number + 1;
        // Line continuation: a trailing backslash joins the next line.
        if let Some(head) = raw.strip_suffix('\\') {
            if continued.is_empty() {
                continued_from = line_no;
            }
            continued.push_str(head);
            continued.push(' ');
            continue;
        }
        let joined;
        let line = if continued.is_empty() {
            raw
        } else {
            continued.push_str(raw);
            joined = std::mem::take(&mut continued);
            line_no = continued_from;
            joined.as_str()
        };
        let line = match line.find('#') {
            Some(i) => &line[..i],
            None => line,
        };
        let mut tokens = line.split_whitespace();
        let Some(keyword) = tokens.next() else {
            continue;
        };
        match keyword {
            "v" => {
                let mut p = [T::default(); 3];
                for (axis, slot) in p.iter_mut().enumerate() {
                    let Some(token) = tokens.next() else {
                        return Err(parse_error(
                            path,
                            line_no,
                            format!("vertex has {axis} coordinates; 3 are needed"),
                        ));
                    };
                    *slot = parse_coordinate(token)
                        .map_err(|message| parse_error(path, line_no, message))?;
                }
                positions.push(p);
            }
            "f" | "fo" => {
                corners.clear();
                for token in tokens {
                    let index = parse_corner(token, positions.len())
                        .map_err(|message| parse_error(path, line_no, message))?;
                    if max_index.is_none_or(|(m, _)| index > m) {
                        max_index = Some((index, line_no));
                    }
                    corners.push(index);
                }
                if corners.len() < 3 {
                    return Err(parse_error(
                        path,
                        line_no,
                        format!("face has {} vertices; at least 3 are needed", corners.len()),
                    ));
                }
                fan(&corners, &mut triangles).map_err(|t| {
                    parse_error(
                        path,
                        line_no,
                        format!(
                            "face repeats a vertex: triangle ({} {} {}) of its fan split \
                             (1-based vertex numbers)",
                            u64::from(t[0]) + 1,
                            u64::from(t[1]) + 1,
                            u64::from(t[2]) + 1
                        ),
                    )
                })?;
            }
            // Everything else (groups, materials, texture coordinates, normals, free-form
            // geometry, vendor extensions) does not change positions or faces: ignored, so
            // real-world files load.
            _ => {}
        }
    }
    if !continued.is_empty() {
        return Err(parse_error(
            path,
            continued_from,
            "line continuation ('\\') at the end of the file",
        ));
    }
    if let Some((index, line)) = max_index {
        if index as usize >= positions.len() {
            return Err(parse_error(
                path,
                line,
                format!(
                    "face uses vertex {}, but the file has only {} vertices",
                    u64::from(index) + 1,
                    positions.len()
                ),
            ));
        }
    }
    build(path, positions, triangles)
}

/// The lines of `text` as [`super::line_end`] ends them (`\n`, `\r\n` or a lone `\r`); like
/// `split('\n')`, a final line end is followed by an empty last line.
fn lines(text: &str) -> impl Iterator<Item = &str> {
    let mut pos = Some(0);
    std::iter::from_fn(move || {
        let start = pos?;
        let (end, next) = super::line_end(text.as_bytes(), start);
        pos = (end < text.len()).then_some(next);
        // Line ends are ASCII, so both ends are character boundaries.
        text.get(start..end)
    })
}

fn truncate(token: &str) -> &str {
    match token.char_indices().nth(32) {
        Some((i, _)) => &token[..i],
        None => token,
    }
}

fn parse_coordinate<T: Coordinate>(token: &str) -> std::result::Result<T, String> {
    let value = T::parse_decimal(token)
        .ok_or_else(|| format!("invalid coordinate '{}'", truncate(token)))?;
    if !value.is_finite() {
        return Err(format!(
            "non-finite coordinate '{}' (NaN, infinite or out of {} range)",
            truncate(token),
            T::NAME
        ));
    }
    Ok(value)
}

/// Parses one face corner `i`, `i/t`, `i//n` or `i/t/n`; returns the 0-based vertex index.
/// `defined` is the number of vertices defined so far (for negative indices).
fn parse_corner(token: &str, defined: usize) -> std::result::Result<u32, String> {
    let mut parts = token.split('/');
    let vertex = parts.next().unwrap_or("");
    let mut extra = 0;
    for part in parts {
        extra += 1;
        if extra > 2 {
            return Err(format!(
                "invalid face vertex '{}': too many '/'",
                truncate(token)
            ));
        }
        if !part.is_empty() && part.parse::<i64>().map_or(true, |v| v == 0) {
            return Err(format!(
                "invalid texture/normal index in face vertex '{}'",
                truncate(token)
            ));
        }
    }
    let index: i64 = vertex
        .parse()
        .map_err(|_| format!("invalid face vertex index '{}'", truncate(token)))?;
    let resolved = match index {
        0 => return Err("face vertex index 0 is invalid (OBJ indices start at 1)".to_string()),
        i if i > 0 => i - 1,
        i => {
            // Relative: -1 is the last vertex defined so far.
            let r = defined as i64 + i;
            if r < 0 {
                return Err(format!(
                    "relative face vertex index {i} refers before the first vertex \
                     ({defined} vertices defined so far)"
                ));
            }
            r
        }
    };
    if resolved >= i64::from(u32::MAX - 1) {
        return Err(format!("face vertex index {index} is too large"));
    }
    Ok(resolved as u32)
}

/// Whether the first meaningful line of `bytes` is an OBJ statement.
pub(crate) fn looks_like_obj(bytes: &[u8]) -> bool {
    let text = match std::str::from_utf8(bytes) {
        Ok(t) => t,
        Err(e) => std::str::from_utf8(&bytes[..e.valid_up_to()]).unwrap_or(""),
    };
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
    for line in lines(text).take(1000) {
        let line = match line.find('#') {
            Some(i) => &line[..i],
            None => line,
        };
        if let Some(keyword) = line.split_whitespace().next() {
            return keyword == "v" || keyword == "f" || IGNORED.contains(&keyword);
        }
    }
    false
}

/// Writes `mesh` as OBJ: one `v` line per vertex (shortest decimal that round-trips the f32
/// exactly) and one 1-based `f` line per triangle, both in mesh order.
pub fn write_obj(mesh: &Mesh, w: &mut impl Write) -> std::io::Result<()> {
    let mut buf = String::with_capacity(64 * 1024);
    let _ = writeln!(
        buf,
        "# dhcd mesh: {} vertices, {} triangles",
        mesh.vertex_count(),
        mesh.triangle_count()
    );
    let flush = |buf: &mut String, w: &mut dyn Write| -> std::io::Result<()> {
        w.write_all(buf.as_bytes())?;
        buf.clear();
        Ok(())
    };
    for p in mesh.positions() {
        let _ = writeln!(buf, "v {} {} {}", p[0], p[1], p[2]);
        if buf.len() > 60 * 1024 {
            flush(&mut buf, w)?;
        }
    }
    for t in mesh.triangles() {
        let _ = writeln!(
            buf,
            "f {} {} {}",
            u64::from(t[0]) + 1,
            u64::from(t[1]) + 1,
            u64::from(t[2]) + 1
        );
        if buf.len() > 60 * 1024 {
            flush(&mut buf, w)?;
        }
    }
    flush(&mut buf, w)?;
    w.flush()
}
