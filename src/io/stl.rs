//! STL reader, ASCII and binary, with exact vertex welding.

use std::collections::HashMap;
use std::path::Path;

use super::{build, fan, parse_error};
use crate::error::{Error, Result};
use crate::mesh::Mesh;

const HEADER: usize = 80;
const FACET: usize = 50;

/// Whether `bytes` is exactly the size a binary STL declares (`84 + 50 * n`).
pub(crate) fn is_binary(bytes: &[u8]) -> bool {
    declared_facets(bytes).is_some_and(|n| binary_size(n) == bytes.len() as u64)
}

fn declared_facets(bytes: &[u8]) -> Option<u32> {
    let count = bytes.get(HEADER..HEADER + 4)?;
    Some(u32::from_le_bytes([count[0], count[1], count[2], count[3]]))
}

fn binary_size(n: u32) -> u64 {
    (HEADER as u64 + 4) + FACET as u64 * u64::from(n)
}

fn starts_with_solid(bytes: &[u8]) -> bool {
    let t = super::trim_ascii_start(bytes);
    t.len() >= 5 && t[..5].eq_ignore_ascii_case(b"solid")
}

/// Parses an STL file, ASCII or binary. Binary is recognised by its size (`84 + 50 * n`
/// bytes for the `n` facets its header declares), so a binary file whose header starts with
/// `solid` is still read as binary; otherwise a file starting with `solid` is ASCII.
///
/// STL has no shared vertices: corners with bit-identical coordinates (treating `-0.0` and
/// `0.0` as equal) are welded into one vertex, numbered in order of first appearance. Facet
/// order is triangle order (facets with more than three corners, which some ASCII writers
/// emit, are fan-split). A facet whose corners weld to fewer than three distinct vertices is
/// an error naming the facet (0-based) and, for ASCII, its line.
pub fn parse_stl(bytes: &[u8], path: &Path) -> Result<Mesh> {
    if is_binary(bytes) {
        return parse_binary(bytes, path);
    }
    // A text editor may have saved an ASCII file with a byte order mark.
    let text = super::strip_bom(bytes);
    if starts_with_solid(text) {
        // Only worth mentioning binary when the contents are not text.
        let binary_hint = bytes.contains(&0).then(|| declared_facets(bytes)).flatten();
        return parse_ascii(text, path).map_err(|e| match (e, binary_hint) {
            (
                Error::Parse {
                    path,
                    line,
                    message,
                },
                Some(n),
            ) => Error::Parse {
                path,
                line,
                message: format!(
                    "{message} (read as ASCII STL; as binary STL the header would declare {n} \
                     facets = {} bytes, but the file has {} bytes)",
                    binary_size(n),
                    bytes.len()
                ),
            },
            (e, _) => e,
        });
    }
    match declared_facets(bytes) {
        None if bytes.is_empty() => Err(parse_error(path, 0, "empty STL file")),
        None => Err(parse_error(
            path,
            0,
            format!(
                "not an STL file: it does not start with 'solid' (ASCII) and its {} bytes are \
                 too few for a binary STL header (84 bytes)",
                bytes.len()
            ),
        )),
        Some(n) => Err(parse_error(
            path,
            0,
            format!(
                "truncated or corrupt binary STL: the header declares {n} facets = {} bytes, but \
                 the file has {} bytes",
                binary_size(n),
                bytes.len()
            ),
        )),
    }
}

/// Welds corners with identical coordinates.
struct Welder {
    positions: Vec<[f32; 3]>,
    index: HashMap<[u32; 3], u32>,
}

impl Welder {
    fn with_capacity(corners: usize) -> Self {
        // Closed meshes have about half as many vertices as triangles.
        let guess = corners / 6 + 16;
        Self {
            positions: Vec::with_capacity(guess),
            index: HashMap::with_capacity(guess),
        }
    }

    fn weld(&mut self, p: [f32; 3]) -> u32 {
        let key = p.map(|x| if x == 0.0 { 0 } else { x.to_bits() });
        let next = self.positions.len() as u32;
        let positions = &mut self.positions;
        *self.index.entry(key).or_insert_with(|| {
            positions.push(p);
            next
        })
    }
}

fn degenerate_message(facet: usize, t: [u32; 3], welder: &Welder) -> String {
    let show = |v: u32| {
        let p = welder.positions[v as usize];
        format!("({} {} {})", p[0], p[1], p[2])
    };
    format!(
        "facet {facet} (0-based) is degenerate: its corners {} {} {} weld to fewer than 3 \
         distinct vertices",
        show(t[0]),
        show(t[1]),
        show(t[2])
    )
}

fn parse_binary(bytes: &[u8], path: &Path) -> Result<Mesh> {
    let body = &bytes[HEADER + 4..];
    let n = body.len() / FACET;
    let mut welder = Welder::with_capacity(3 * n);
    let mut triangles = Vec::with_capacity(n);
    for (facet, record) in body.chunks_exact(FACET).enumerate() {
        let mut t = [0u32; 3];
        for (corner, slot) in t.iter_mut().enumerate() {
            let mut p = [0.0f32; 3];
            for (axis, x) in p.iter_mut().enumerate() {
                let at = 12 + 12 * corner + 4 * axis;
                *x = f32::from_le_bytes([
                    record[at],
                    record[at + 1],
                    record[at + 2],
                    record[at + 3],
                ]);
            }
            if !p.iter().all(|x| x.is_finite()) {
                return Err(parse_error(
                    path,
                    0,
                    format!(
                        "facet {facet} (0-based) has a non-finite corner coordinate ({} {} {})",
                        p[0], p[1], p[2]
                    ),
                ));
            }
            *slot = welder.weld(p);
        }
        fan(&t, &mut triangles)
            .map_err(|t| parse_error(path, 0, degenerate_message(facet, t, &welder)))?;
    }
    build(path, welder.positions, triangles)
}

/// Whitespace-separated tokens with line numbers.
struct Tokens<'a> {
    bytes: &'a [u8],
    pos: usize,
    line: usize,
}

impl<'a> Tokens<'a> {
    fn new(bytes: &'a [u8]) -> Self {
        Self {
            bytes,
            pos: 0,
            line: 1,
        }
    }

    /// The next token and its line.
    fn next(&mut self) -> Option<(&'a [u8], usize)> {
        while let Some(&b) = self.bytes.get(self.pos) {
            if !b.is_ascii_whitespace() {
                break;
            }
            if ends_line(self.bytes, self.pos) {
                self.line += 1;
            }
            self.pos += 1;
        }
        let start = self.pos;
        while self
            .bytes
            .get(self.pos)
            .is_some_and(|b| !b.is_ascii_whitespace())
        {
            self.pos += 1;
        }
        (self.pos > start).then(|| (&self.bytes[start..self.pos], self.line))
    }

    /// Skips the rest of the current line (a solid's name).
    fn skip_line(&mut self) {
        let (_, next) = super::line_end(self.bytes, self.pos);
        if next > self.pos && matches!(self.bytes[next - 1], b'\n' | b'\r') {
            self.line += 1;
        }
        self.pos = next;
    }
}

/// Whether the byte at `pos` ends a line: `\n`, or a `\r` not followed by `\n`.
fn ends_line(bytes: &[u8], pos: usize) -> bool {
    match bytes[pos] {
        b'\n' => true,
        b'\r' => bytes.get(pos + 1) != Some(&b'\n'),
        _ => false,
    }
}

fn show(token: &[u8]) -> String {
    String::from_utf8_lossy(&token[..token.len().min(32)]).into_owned()
}

fn is(token: &[u8], keyword: &str) -> bool {
    token.eq_ignore_ascii_case(keyword.as_bytes())
}

fn parse_ascii(bytes: &[u8], path: &Path) -> Result<Mesh> {
    let mut tokens = Tokens::new(bytes);
    let mut welder = Welder::with_capacity(bytes.len() / 80);
    let mut triangles = Vec::new();
    let mut corners: Vec<u32> = Vec::new();
    let mut facet = 0usize;

    let expect = |tokens: &mut Tokens, keyword: &str, context: &str| -> Result<()> {
        match tokens.next() {
            Some((t, _)) if is(t, keyword) => Ok(()),
            Some((t, line)) => Err(parse_error(
                path,
                line,
                format!("expected '{keyword}' {context}, found '{}'", show(t)),
            )),
            None => Err(parse_error(
                path,
                tokens.line,
                format!("unexpected end of file: expected '{keyword}' {context}"),
            )),
        }
    };
    let number = |tokens: &mut Tokens, what: &str| -> Result<(f32, usize)> {
        match tokens.next() {
            Some((t, line)) => std::str::from_utf8(t)
                .ok()
                .and_then(|s| s.parse::<f32>().ok())
                .map(|x| (x, line))
                .ok_or_else(|| parse_error(path, line, format!("invalid {what} '{}'", show(t)))),
            None => Err(parse_error(
                path,
                tokens.line,
                format!("unexpected end of file: expected {what}"),
            )),
        }
    };

    let mut solids = 0;
    loop {
        // Outside a solid.
        match tokens.next() {
            None if solids > 0 => break,
            None => return Err(parse_error(path, tokens.line, "empty ASCII STL file")),
            Some((t, _)) if is(t, "solid") => {
                solids += 1;
                tokens.skip_line();
            }
            Some((t, line)) => {
                return Err(parse_error(
                    path,
                    line,
                    format!("expected 'solid', found '{}'", show(t)),
                ))
            }
        }
        // Inside a solid.
        loop {
            let (t, facet_line) = match tokens.next() {
                Some(tok) => tok,
                None => {
                    return Err(parse_error(
                        path,
                        tokens.line,
                        "unexpected end of file: expected 'facet' or 'endsolid'",
                    ))
                }
            };
            if is(t, "endsolid") {
                tokens.skip_line();
                break;
            }
            if !is(t, "facet") {
                return Err(parse_error(
                    path,
                    facet_line,
                    format!("expected 'facet' or 'endsolid', found '{}'", show(t)),
                ));
            }
            expect(&mut tokens, "normal", "after 'facet'")?;
            for _ in 0..3 {
                number(&mut tokens, "normal component")?;
            }
            expect(&mut tokens, "outer", "after the facet normal")?;
            expect(&mut tokens, "loop", "after 'outer'")?;
            corners.clear();
            loop {
                match tokens.next() {
                    Some((t, _)) if is(t, "vertex") => {
                        let mut p = [0.0f32; 3];
                        let mut line = 0;
                        for x in &mut p {
                            (*x, line) = number(&mut tokens, "vertex coordinate")?;
                        }
                        if !p.iter().all(|x| x.is_finite()) {
                            return Err(parse_error(
                                path,
                                line,
                                format!(
                                    "non-finite vertex coordinate ({} {} {}) in facet {facet} \
                                     (0-based)",
                                    p[0], p[1], p[2]
                                ),
                            ));
                        }
                        corners.push(welder.weld(p));
                    }
                    Some((t, _)) if is(t, "endloop") => break,
                    Some((t, line)) => {
                        return Err(parse_error(
                            path,
                            line,
                            format!("expected 'vertex' or 'endloop', found '{}'", show(t)),
                        ))
                    }
                    None => {
                        return Err(parse_error(
                            path,
                            tokens.line,
                            "unexpected end of file: expected 'vertex' or 'endloop'",
                        ))
                    }
                }
            }
            if corners.len() < 3 {
                return Err(parse_error(
                    path,
                    facet_line,
                    format!(
                        "facet {facet} (0-based) has {} vertices; at least 3 are needed",
                        corners.len()
                    ),
                ));
            }
            fan(&corners, &mut triangles).map_err(|t| {
                parse_error(path, facet_line, degenerate_message(facet, t, &welder))
            })?;
            expect(&mut tokens, "endfacet", "after 'endloop'")?;
            facet += 1;
        }
    }
    build(path, welder.positions, triangles)
}
