//! PLY reader: ASCII, binary little-endian and binary big-endian.

use std::collections::HashSet;
use std::path::Path;

use super::{build, fan, line_end, parse_error, Coordinate};
use crate::error::Result;
use crate::mesh::Mesh;

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Encoding {
    Ascii,
    LittleEndian,
    BigEndian,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Ty {
    I8,
    U8,
    I16,
    U16,
    I32,
    U32,
    F32,
    F64,
}

impl Ty {
    fn parse(name: &str) -> Option<Ty> {
        Some(match name {
            "char" | "int8" => Ty::I8,
            "uchar" | "uint8" => Ty::U8,
            "short" | "int16" => Ty::I16,
            "ushort" | "uint16" => Ty::U16,
            "int" | "int32" => Ty::I32,
            "uint" | "uint32" => Ty::U32,
            "float" | "float32" => Ty::F32,
            "double" | "float64" => Ty::F64,
            _ => return None,
        })
    }

    fn size(self) -> usize {
        match self {
            Ty::I8 | Ty::U8 => 1,
            Ty::I16 | Ty::U16 => 2,
            Ty::I32 | Ty::U32 | Ty::F32 => 4,
            Ty::F64 => 8,
        }
    }

    fn is_int(self) -> bool {
        !matches!(self, Ty::F32 | Ty::F64)
    }

    fn range(self) -> (i64, i64) {
        match self {
            Ty::I8 => (i8::MIN.into(), i8::MAX.into()),
            Ty::U8 => (0, u8::MAX.into()),
            Ty::I16 => (i16::MIN.into(), i16::MAX.into()),
            Ty::U16 => (0, u16::MAX.into()),
            Ty::I32 => (i32::MIN.into(), i32::MAX.into()),
            Ty::U32 => (0, u32::MAX.into()),
            Ty::F32 | Ty::F64 => (i64::MIN, i64::MAX),
        }
    }

    fn name(self) -> &'static str {
        match self {
            Ty::I8 => "char",
            Ty::U8 => "uchar",
            Ty::I16 => "short",
            Ty::U16 => "ushort",
            Ty::I32 => "int",
            Ty::U32 => "uint",
            Ty::F32 => "float",
            Ty::F64 => "double",
        }
    }
}

#[derive(Clone, Copy, Debug, PartialEq)]
enum Num {
    Int(i64),
    Float(f64),
}

impl Num {
    fn to<T: Coordinate>(self) -> T {
        match self {
            Num::Int(i) => T::from_i64(i),
            Num::Float(f) => T::from_f64(f),
        }
    }
}

#[derive(Clone, Debug)]
enum Kind {
    Scalar(Ty),
    List { count: Ty, item: Ty },
}

#[derive(Clone, Debug)]
struct Property {
    name: String,
    kind: Kind,
}

#[derive(Clone, Debug)]
struct Element {
    name: String,
    count: u64,
    properties: Vec<Property>,
    line: usize,
}

struct Header {
    encoding: Encoding,
    elements: Vec<Element>,
    /// Byte offset of the data section.
    data_start: usize,
    /// Length of the whole file.
    data_end: usize,
    /// Number of header lines (the data section starts on the next line).
    lines: usize,
}

fn parse_header(bytes: &[u8], path: &Path) -> Result<Header> {
    if bytes.is_empty() {
        return Err(parse_error(path, 0, "empty PLY file"));
    }
    let mut pos = 0;
    let mut line_no = 0;
    let mut encoding = None;
    let mut elements: Vec<Element> = Vec::new();
    // Names seen so far, so that duplicate checks stay linear in the number of header lines
    // (a header may declare hundreds of thousands of elements).
    let mut element_names: HashSet<&str> = HashSet::new();
    let mut property_names: HashSet<&str> = HashSet::new();
    loop {
        if pos >= bytes.len() {
            return Err(parse_error(
                path,
                line_no,
                "unexpected end of file in the PLY header: missing 'end_header'",
            ));
        }
        let (end, next) = line_end(bytes, pos);
        let raw = &bytes[pos..end];
        pos = next;
        line_no += 1;
        let Ok(line) = std::str::from_utf8(raw) else {
            return Err(parse_error(
                path,
                line_no,
                "PLY header line is not ASCII text",
            ));
        };
        let line = line.trim();
        if line_no == 1 {
            if line != "ply" {
                return Err(parse_error(
                    path,
                    1,
                    "not a PLY file: the first line must be 'ply'",
                ));
            }
            continue;
        }
        let mut words = line.split_ascii_whitespace();
        let err = |message: String| parse_error(path, line_no, message);
        match words.next() {
            None | Some("comment") | Some("obj_info") => {}
            Some("format") => {
                if encoding.is_some() {
                    return Err(err("duplicate 'format' line".into()));
                }
                encoding = Some(match words.next() {
                    Some("ascii") => Encoding::Ascii,
                    Some("binary_little_endian") => Encoding::LittleEndian,
                    Some("binary_big_endian") => Encoding::BigEndian,
                    Some(other) => {
                        return Err(err(format!(
                            "unknown PLY format '{}' (expected ascii, binary_little_endian or \
                             binary_big_endian)",
                            clip(other)
                        )))
                    }
                    None => return Err(err("'format' line without a format".into())),
                });
                match words.next() {
                    Some(v) if v.starts_with('1') => {}
                    Some(v) => return Err(err(format!("unsupported PLY version '{}'", clip(v)))),
                    None => return Err(err("'format' line without a version".into())),
                }
            }
            Some("element") => {
                let (Some(name), Some(count), None) = (words.next(), words.next(), words.next())
                else {
                    return Err(err("expected 'element <name> <count>'".into()));
                };
                let count: u64 = count
                    .parse()
                    .map_err(|_| err(format!("invalid element count '{}'", clip(count))))?;
                if !element_names.insert(name) {
                    return Err(err(format!("duplicate element '{}'", clip(name))));
                }
                property_names.clear();
                elements.push(Element {
                    name: name.to_string(),
                    count,
                    properties: Vec::new(),
                    line: line_no,
                });
            }
            Some("property") => {
                let Some(element) = elements.last_mut() else {
                    return Err(err("'property' before any 'element'".into()));
                };
                let ty = |name: Option<&str>| -> Result<Ty> {
                    let name = name.ok_or_else(|| err("incomplete 'property' line".into()))?;
                    Ty::parse(name)
                        .ok_or_else(|| err(format!("unknown property type '{}'", clip(name))))
                };
                let first = words.next();
                let kind = if first == Some("list") {
                    let count = ty(words.next())?;
                    let item = ty(words.next())?;
                    if !count.is_int() {
                        return Err(err(format!(
                            "list count type must be an integer type, not '{}'",
                            count.name()
                        )));
                    }
                    Kind::List { count, item }
                } else {
                    Kind::Scalar(ty(first)?)
                };
                let (Some(name), None) = (words.next(), words.next()) else {
                    return Err(err("expected 'property <type> <name>' or 'property list \
                                    <count type> <item type> <name>'"
                        .into()));
                };
                if !property_names.insert(name) {
                    return Err(err(format!(
                        "duplicate property '{}' in element '{}'",
                        clip(name),
                        clip(&element.name)
                    )));
                }
                element.properties.push(Property {
                    name: name.to_string(),
                    kind,
                });
            }
            Some("end_header") => break,
            Some(other) => {
                return Err(err(format!("unknown PLY header keyword '{}'", clip(other))))
            }
        }
    }
    let Some(encoding) = encoding else {
        return Err(parse_error(
            path,
            line_no,
            "PLY header has no 'format' line",
        ));
    };
    Ok(Header {
        encoding,
        elements,
        data_start: pos,
        data_end: bytes.len(),
        lines: line_no,
    })
}

fn clip(s: &str) -> &str {
    match s.char_indices().nth(32) {
        Some((i, _)) => &s[..i],
        None => s,
    }
}

/// Where the data values come from.
trait Source {
    /// Starts the next row (ASCII: the next non-blank line).
    fn begin_row(&mut self) -> std::result::Result<(), String>;
    /// Ends a row (ASCII: nothing may remain on the line).
    fn end_row(&mut self) -> std::result::Result<(), String>;
    fn value(&mut self, ty: Ty) -> std::result::Result<Num, String>;
    /// Skips `n` values of type `ty`.
    fn skip(&mut self, ty: Ty, n: u64) -> std::result::Result<(), String>;
    /// Line for messages (0 for binary).
    fn line(&self) -> usize;
}

struct Ascii<'a> {
    rest: &'a [u8],
    line: usize,
    tokens: std::slice::Split<'a, u8, fn(&u8) -> bool>,
}

fn is_space(b: &u8) -> bool {
    b.is_ascii_whitespace()
}

impl<'a> Ascii<'a> {
    fn new(data: &'a [u8], header_lines: usize) -> Self {
        Self {
            rest: data,
            line: header_lines,
            tokens: [].split(is_space as fn(&u8) -> bool),
        }
    }

    fn token(&mut self) -> Option<&'a [u8]> {
        self.tokens.by_ref().find(|t| !t.is_empty())
    }
}

impl Source for Ascii<'_> {
    fn begin_row(&mut self) -> std::result::Result<(), String> {
        loop {
            if self.rest.is_empty() {
                self.line += 1;
                return Err("unexpected end of file".into());
            }
            let (end, next) = line_end(self.rest, 0);
            let line = &self.rest[..end];
            self.rest = &self.rest[next..];
            self.line += 1;
            if line.iter().any(|b| !b.is_ascii_whitespace()) {
                self.tokens = line.split(is_space as fn(&u8) -> bool);
                return Ok(());
            }
        }
    }

    fn end_row(&mut self) -> std::result::Result<(), String> {
        match self.token() {
            None => Ok(()),
            Some(t) => Err(format!(
                "unexpected extra value '{}' at the end of the row",
                String::from_utf8_lossy(&t[..t.len().min(32)])
            )),
        }
    }

    fn value(&mut self, ty: Ty) -> std::result::Result<Num, String> {
        let Some(token) = self.token() else {
            return Err(format!("row ends early: expected a {} value", ty.name()));
        };
        let text = std::str::from_utf8(token).unwrap_or("");
        let bad = || {
            format!(
                "invalid {} value '{}'",
                ty.name(),
                String::from_utf8_lossy(&token[..token.len().min(32)])
            )
        };
        match ty {
            Ty::F32 => text
                .parse::<f32>()
                .map(|x| Num::Float(x.into()))
                .map_err(|_| bad()),
            Ty::F64 => text.parse::<f64>().map(Num::Float).map_err(|_| bad()),
            _ => {
                let v: i64 = text.parse().map_err(|_| bad())?;
                let (lo, hi) = ty.range();
                if v < lo || v > hi {
                    return Err(format!("{} value {v} is out of range", ty.name()));
                }
                Ok(Num::Int(v))
            }
        }
    }

    fn skip(&mut self, ty: Ty, n: u64) -> std::result::Result<(), String> {
        for _ in 0..n {
            self.value(ty)?;
        }
        Ok(())
    }

    fn line(&self) -> usize {
        self.line
    }
}

struct Binary<'a> {
    data: &'a [u8],
    pos: usize,
    big_endian: bool,
}

impl Binary<'_> {
    fn take<const N: usize>(&mut self) -> std::result::Result<[u8; N], String> {
        let bytes: [u8; N] = self
            .data
            .get(self.pos..)
            .and_then(|rest| rest.get(..N))
            .and_then(|b| b.try_into().ok())
            .ok_or_else(|| "unexpected end of file (truncated binary data)".to_string())?;
        self.pos += N;
        Ok(bytes)
    }
}

macro_rules! read_num {
    ($self:ident, $t:ty) => {{
        let b = $self.take::<{ std::mem::size_of::<$t>() }>()?;
        if $self.big_endian {
            <$t>::from_be_bytes(b)
        } else {
            <$t>::from_le_bytes(b)
        }
    }};
}

impl Source for Binary<'_> {
    fn begin_row(&mut self) -> std::result::Result<(), String> {
        Ok(())
    }

    fn end_row(&mut self) -> std::result::Result<(), String> {
        Ok(())
    }

    fn value(&mut self, ty: Ty) -> std::result::Result<Num, String> {
        Ok(match ty {
            Ty::I8 => Num::Int(read_num!(self, i8).into()),
            Ty::U8 => Num::Int(read_num!(self, u8).into()),
            Ty::I16 => Num::Int(read_num!(self, i16).into()),
            Ty::U16 => Num::Int(read_num!(self, u16).into()),
            Ty::I32 => Num::Int(read_num!(self, i32).into()),
            Ty::U32 => Num::Int(read_num!(self, u32).into()),
            Ty::F32 => Num::Float(read_num!(self, f32).into()),
            Ty::F64 => Num::Float(read_num!(self, f64)),
        })
    }

    fn skip(&mut self, ty: Ty, n: u64) -> std::result::Result<(), String> {
        let remaining = self.data.len().saturating_sub(self.pos) as u64;
        match n.checked_mul(ty.size() as u64) {
            Some(bytes) if bytes <= remaining => {
                self.pos += bytes as usize;
                Ok(())
            }
            _ => Err("unexpected end of file (truncated binary data)".to_string()),
        }
    }

    fn line(&self) -> usize {
        0
    }
}

/// Parses a PLY file (ASCII, binary little- or big-endian).
///
/// Needs a `vertex` element with scalar `x`, `y`, `z` properties (any numeric type) and a
/// `face` element with a `vertex_indices` (or `vertex_index`) list of integers; faces are
/// fan-split in order. All other elements and properties are skipped.
pub fn parse_ply(bytes: &[u8], path: &Path) -> Result<Mesh> {
    parse_ply_as::<f32>(bytes, path)
}

/// [`parse_ply`] into coordinates of type `T` (`double` properties read at full precision
/// for `f64`).
pub(crate) fn parse_ply_as<T: Coordinate>(bytes: &[u8], path: &Path) -> Result<Mesh> {
    let header = parse_header(bytes, path)?;
    let data = &bytes[header.data_start..];
    match header.encoding {
        Encoding::Ascii => read_body::<T>(&header, &mut Ascii::new(data, header.lines), path),
        Encoding::LittleEndian | Encoding::BigEndian => read_body::<T>(
            &header,
            &mut Binary {
                data,
                pos: 0,
                big_endian: header.encoding == Encoding::BigEndian,
            },
            path,
        ),
    }
}

/// What each property of an element is used for.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Role {
    Skip,
    Coordinate(usize),
    Indices,
}

fn roles(header: &Header, path: &Path) -> Result<(usize, Vec<Role>, usize, Vec<Role>)> {
    let find = |name: &str| header.elements.iter().position(|e| e.name == name);
    let Some(v) = find("vertex") else {
        return Err(parse_error(
            path,
            header.lines,
            "PLY header has no 'vertex' element",
        ));
    };
    let Some(f) = find("face") else {
        return Err(parse_error(
            path,
            header.lines,
            "PLY header has no 'face' element",
        ));
    };
    let vertex = &header.elements[v];
    let mut vertex_roles = vec![Role::Skip; vertex.properties.len()];
    for (axis, name) in ["x", "y", "z"].into_iter().enumerate() {
        let Some(i) = vertex.properties.iter().position(|p| p.name == name) else {
            return Err(parse_error(
                path,
                vertex.line,
                format!("'vertex' element has no '{name}' property"),
            ));
        };
        if !matches!(vertex.properties[i].kind, Kind::Scalar(_)) {
            return Err(parse_error(
                path,
                vertex.line,
                format!("vertex property '{name}' must be a scalar, not a list"),
            ));
        }
        vertex_roles[i] = Role::Coordinate(axis);
    }
    let face = &header.elements[f];
    let mut face_roles = vec![Role::Skip; face.properties.len()];
    let Some(i) = face
        .properties
        .iter()
        .position(|p| p.name == "vertex_indices")
        .or_else(|| {
            face.properties
                .iter()
                .position(|p| p.name == "vertex_index")
        })
    else {
        return Err(parse_error(
            path,
            face.line,
            "'face' element has no 'vertex_indices' (or 'vertex_index') property",
        ));
    };
    match face.properties[i].kind {
        Kind::List { item, .. } if item.is_int() => {}
        Kind::List { item, .. } => {
            return Err(parse_error(
                path,
                face.line,
                format!(
                    "face vertex indices must have an integer type, not '{}'",
                    item.name()
                ),
            ))
        }
        Kind::Scalar(_) => {
            return Err(parse_error(
                path,
                face.line,
                "face property 'vertex_indices' must be a list",
            ))
        }
    }
    face_roles[i] = Role::Indices;
    Ok((v, vertex_roles, f, face_roles))
}

/// Reserves room for the rows of `element` that the data can hold, never for the declared
/// count (a header may declare four billion rows over a few bytes). A used row yields at least
/// one position or triangle, and takes at least [`min_row_bytes`].
fn reserve<T>(out: &mut Vec<T>, element: &Element, roles: &[Role], header: &Header, data: usize) {
    let rows = (data / min_row_bytes(element, roles, header.encoding)) as u64;
    // Only a hint: if even that much memory is not to be had, the rows are pushed one by one.
    let _ = out.try_reserve(element.count.min(rows) as usize);
}

/// The fewest bytes a row of `element` can take: every value takes its size in binary, at
/// least a character and a separator in ASCII; the index list of a face has at least 3 items.
fn min_row_bytes(element: &Element, roles: &[Role], encoding: Encoding) -> usize {
    let size = |ty: Ty| match encoding {
        Encoding::Ascii => 2,
        Encoding::LittleEndian | Encoding::BigEndian => ty.size(),
    };
    let bytes: usize = element
        .properties
        .iter()
        .zip(roles)
        .map(|(p, role)| match (&p.kind, role) {
            (Kind::Scalar(ty), _) => size(*ty),
            (Kind::List { count, item }, Role::Indices) => size(*count) + 3 * size(*item),
            (Kind::List { count, .. }, _) => size(*count),
        })
        .sum();
    bytes.max(1)
}

fn read_body<T: Coordinate>(header: &Header, src: &mut impl Source, path: &Path) -> Result<Mesh> {
    let data_len = header.data_end - header.data_start;
    let (v_elem, vertex_roles, f_elem, face_roles) = roles(header, path)?;
    let mut positions: Vec<[T; 3]> = Vec::new();
    let mut triangles: Vec<[u32; 3]> = Vec::new();
    let mut corners: Vec<u32> = Vec::new();
    // Largest index used, with the face row and line that used it first (faces may precede
    // the vertices, so the range is checked at the end).
    let mut max_index: Option<(i64, u64, usize)> = None;

    for (e, element) in header.elements.iter().enumerate() {
        if element.properties.is_empty() {
            continue;
        }
        let no_roles = Vec::new();
        let roles = if e == v_elem {
            reserve(&mut positions, element, &vertex_roles, header, data_len);
            &vertex_roles
        } else if e == f_elem {
            reserve(&mut triangles, element, &face_roles, header, data_len);
            &face_roles
        } else {
            &no_roles
        };
        for row in 0..element.count {
            let at = |line: usize, message: String| {
                parse_error(
                    path,
                    line,
                    format!(
                        "element '{}' row {row} (0-based): {message}",
                        clip(&element.name)
                    ),
                )
            };
            src.begin_row().map_err(|m| at(src.line(), m))?;
            let mut p = [T::default(); 3];
            corners.clear();
            for (i, property) in element.properties.iter().enumerate() {
                let role = roles.get(i).copied().unwrap_or(Role::Skip);
                match (&property.kind, role) {
                    (Kind::Scalar(ty), Role::Coordinate(axis)) => {
                        p[axis] = src.value(*ty).map_err(|m| at(src.line(), m))?.to::<T>();
                    }
                    (Kind::Scalar(ty), _) => {
                        src.skip(*ty, 1).map_err(|m| at(src.line(), m))?;
                    }
                    (Kind::List { count, item }, role) => {
                        let n = match src.value(*count).map_err(|m| at(src.line(), m))? {
                            Num::Int(n) if n >= 0 => n as u64,
                            Num::Int(n) => {
                                return Err(at(src.line(), format!("negative list length {n}")))
                            }
                            Num::Float(_) => {
                                return Err(at(src.line(), "list length is not an integer".into()))
                            }
                        };
                        if role != Role::Indices {
                            src.skip(*item, n).map_err(|m| at(src.line(), m))?;
                            continue;
                        }
                        if n < 3 {
                            return Err(at(
                                src.line(),
                                format!("face has {n} vertices; at least 3 are needed"),
                            ));
                        }
                        for _ in 0..n {
                            let index = match src.value(*item).map_err(|m| at(src.line(), m))? {
                                Num::Int(i) => i,
                                Num::Float(_) => {
                                    return Err(at(
                                        src.line(),
                                        "vertex index is not an integer".into(),
                                    ))
                                }
                            };
                            if index < 0 || index >= i64::from(u32::MAX - 1) {
                                return Err(at(
                                    src.line(),
                                    format!("invalid vertex index {index}"),
                                ));
                            }
                            if max_index.is_none_or(|(m, _, _)| index > m) {
                                max_index = Some((index, row, src.line()));
                            }
                            corners.push(index as u32);
                        }
                    }
                }
            }
            src.end_row().map_err(|m| at(src.line(), m))?;
            if e == v_elem {
                if !p.iter().all(|x| x.is_finite()) {
                    return Err(at(
                        src.line(),
                        format!(
                            "non-finite vertex coordinate ({} {} {}): NaN, infinite or beyond the \
                             {} range",
                            p[0],
                            p[1],
                            p[2],
                            T::NAME
                        ),
                    ));
                }
                positions.push(p);
            } else if e == f_elem {
                fan(&corners, &mut triangles).map_err(|t| {
                    at(
                        src.line(),
                        format!(
                            "face repeats a vertex: triangle ({} {} {}) of its fan split",
                            t[0], t[1], t[2]
                        ),
                    )
                })?;
            }
        }
    }
    if let Some((index, row, line)) = max_index {
        if index as u64 >= positions.len() as u64 {
            return Err(parse_error(
                path,
                line,
                format!(
                    "element 'face' row {row} (0-based): vertex index {index} is out of range \
                     (the file has {} vertices)",
                    positions.len()
                ),
            ));
        }
    }
    build(path, positions, triangles)
}
