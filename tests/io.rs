//! Tests of `dhcd::io`: OBJ, STL and PLY loaders and the OBJ writer.

use std::path::{Path, PathBuf};

use dhcd::io::{self, Format};
use dhcd::{Error, Mesh};
use proptest::prelude::*;

// ---------------------------------------------------------------------------------------------
// Helpers
// ---------------------------------------------------------------------------------------------

fn p(name: &str) -> PathBuf {
    PathBuf::from(name)
}

fn mesh(positions: &[[f32; 3]], triangles: &[[u32; 3]]) -> Mesh {
    Mesh::new(positions.to_vec(), triangles.to_vec()).unwrap()
}

/// A closed octahedron: 6 vertices, 8 triangles.
fn octahedron() -> Mesh {
    mesh(
        &[
            [1.0, 0.0, 0.0],
            [-1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [0.0, -1.0, 0.0],
            [0.0, 0.0, 1.0],
            [0.0, 0.0, -1.0],
        ],
        &[
            [0, 2, 4],
            [2, 1, 4],
            [1, 3, 4],
            [3, 0, 4],
            [2, 0, 5],
            [1, 2, 5],
            [3, 1, 5],
            [0, 3, 5],
        ],
    )
}

/// The error's display, asserting it is a `Parse` error at `line` for `path`.
fn parse_err_at(result: dhcd::Result<Mesh>, path: &str, line: usize) -> String {
    let err = result.expect_err("malformed input must be rejected");
    let text = err.to_string();
    match &err {
        Error::Parse {
            path: p, line: l, ..
        } => {
            assert_eq!(p, Path::new(path), "{text}");
            assert_eq!(*l, line, "wrong line in: {text}");
        }
        other => panic!("expected a Parse error, got {other:?}"),
    }
    assert!(text.starts_with(&format!("{path}:{line}: ")), "{text}");
    assert!(!text.contains('\n'), "message must be one line: {text}");
    text
}

fn obj_err(text: &str, line: usize) -> String {
    parse_err_at(io::parse_obj(text, &p("t.obj")), "t.obj", line)
}

fn tmp(name: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("dhcd-io-tests");
    std::fs::create_dir_all(&dir).unwrap();
    dir.join(name)
}

/// Binary STL with the given 80-byte header prefix, one facet per triangle of `m`.
fn stl_binary(m: &Mesh, header: &[u8]) -> Vec<u8> {
    let mut out = vec![0u8; 80];
    out[..header.len()].copy_from_slice(header);
    out.extend_from_slice(&(m.triangle_count() as u32).to_le_bytes());
    for t in 0..m.triangle_count() {
        out.extend_from_slice(&[0u8; 12]); // normal
        for c in m.corners(t) {
            for x in c {
                out.extend_from_slice(&x.to_le_bytes());
            }
        }
        out.extend_from_slice(&[0u8; 2]);
    }
    out
}

fn stl_ascii(m: &Mesh) -> String {
    let mut s = String::from("solid test mesh\n");
    for t in 0..m.triangle_count() {
        s.push_str("  facet normal 0 0 1\n    outer loop\n");
        for c in m.corners(t) {
            s.push_str(&format!("      vertex {} {} {}\n", c[0], c[1], c[2]));
        }
        s.push_str("    endloop\n  endfacet\n");
    }
    s.push_str("endsolid test mesh\n");
    s
}

/// A PLY polygon mesh with extra properties and elements, in the three encodings.
struct PlyFixture {
    positions: Vec<[f64; 3]>,
    faces: Vec<Vec<u32>>,
}

impl PlyFixture {
    fn new() -> Self {
        // A cube with quad faces.
        let positions = vec![
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [1.0, 1.0, 0.0],
            [0.0, 1.0, 0.0],
            [0.0, 0.0, 1.0],
            [1.0, 0.0, 1.0],
            [1.0, 1.0, 1.0],
            [0.0, 1.0, 1.0],
        ];
        let faces = vec![
            vec![0, 3, 2, 1],
            vec![4, 5, 6, 7],
            vec![0, 1, 5, 4],
            vec![1, 2, 6, 5],
            vec![2, 3, 7, 6],
            vec![3, 0, 4, 7],
        ];
        Self { positions, faces }
    }

    fn expected(&self) -> Mesh {
        let positions: Vec<[f32; 3]> = self.positions.iter().map(|p| p.map(|x| x as f32)).collect();
        let mut tris = Vec::new();
        for f in &self.faces {
            for i in 1..f.len() - 1 {
                tris.push([f[0], f[i], f[i + 1]]);
            }
        }
        Mesh::new(positions, tris).unwrap()
    }

    fn header(&self, format: &str) -> String {
        format!(
            "ply\r\nformat {format} 1.0\r\ncomment made by dhcd tests\r\n\
             element vertex {}\r\nproperty double x\r\nproperty float nx\r\n\
             property double y\r\nproperty double z\r\nproperty uchar red\r\n\
             element edge 2\r\nproperty list uchar int pair\r\nproperty short weight\r\n\
             element face {}\r\nproperty uchar flags\r\nproperty list uchar uint vertex_indices\r\n\
             property list ushort float texcoord\r\n\
             end_header\r\n",
            self.positions.len(),
            self.faces.len()
        )
    }

    fn ascii(&self) -> Vec<u8> {
        let mut s = self.header("ascii");
        for p in &self.positions {
            s.push_str(&format!("{} 0.5 {} {} 255\n", p[0], p[1], p[2]));
        }
        s.push_str("2 0 1 -7\n2 1 2 7\n");
        for f in &self.faces {
            s.push_str(&format!("9 {}", f.len()));
            for i in f {
                s.push_str(&format!(" {i}"));
            }
            s.push_str(" 2 0.25 0.75\n");
        }
        s.into_bytes()
    }

    fn binary(&self, big: bool) -> Vec<u8> {
        let fmt = if big {
            "binary_big_endian"
        } else {
            "binary_little_endian"
        };
        let mut out = self.header(fmt).into_bytes();
        macro_rules! put {
            ($v:expr) => {
                if big {
                    out.extend_from_slice(&$v.to_be_bytes())
                } else {
                    out.extend_from_slice(&$v.to_le_bytes())
                }
            };
        }
        for p in &self.positions {
            put!(p[0]);
            put!(0.5f32);
            put!(p[1]);
            put!(p[2]);
            put!(255u8);
        }
        for (a, b, w) in [(0i32, 1i32, -7i16), (1, 2, 7)] {
            put!(2u8);
            put!(a);
            put!(b);
            put!(w);
        }
        for f in &self.faces {
            put!(9u8);
            put!(f.len() as u8);
            for &i in f {
                put!(i);
            }
            put!(2u16);
            put!(0.25f32);
            put!(0.75f32);
        }
        out
    }
}

// ---------------------------------------------------------------------------------------------
// OBJ
// ---------------------------------------------------------------------------------------------

#[test]
fn obj_round_trip_is_exact() {
    let m = mesh(
        &[
            [0.1, -0.0, 1e-30],
            [3.4028235e38, -1.1754944e-38, 123456.79],
            [-7.25, 0.333_333_34, 2.0],
            [1.0, 1.0, 1.0],
        ],
        &[[0, 1, 2], [2, 1, 3], [3, 0, 2]],
    );
    let mut buf = Vec::new();
    io::write_obj(&m, &mut buf).unwrap();
    let back = io::parse_obj(std::str::from_utf8(&buf).unwrap(), &p("rt.obj")).unwrap();
    assert_eq!(back.triangles(), m.triangles());
    for (a, b) in back.positions().iter().zip(m.positions()) {
        assert_eq!(a.map(f32::to_bits), b.map(f32::to_bits));
    }
}

#[test]
fn obj_round_trip_large_mesh_through_file() {
    // Larger than the writer's internal buffer.
    let n = 60u32;
    let mut positions = Vec::new();
    for i in 0..n {
        for j in 0..n {
            positions.push([i as f32 * 0.1, j as f32 * 0.37, (i * j) as f32 * 1e-3]);
        }
    }
    let mut tris = Vec::new();
    for i in 0..n - 1 {
        for j in 0..n - 1 {
            let a = i * n + j;
            tris.push([a, a + 1, a + n]);
            tris.push([a + 1, a + n + 1, a + n]);
        }
    }
    let m = Mesh::new(positions, tris).unwrap();
    let path = tmp("grid.obj");
    let mut file = std::fs::File::create(&path).unwrap();
    io::write_obj(&m, &mut file).unwrap();
    drop(file);
    assert_eq!(io::load(&path).unwrap(), m);
    assert_eq!(io::load_obj(&path).unwrap(), m);
}

#[test]
fn obj_fan_splits_polygons_in_order() {
    let text = "v 0 0 0\nv 1 0 0\nv 2 1 0\nv 1 2 0\nv 0 1 0\nf 1 2 3\nf 1 2 3 4 5\nf 5 4 3 2\n";
    let m = io::parse_obj(text, &p("fan.obj")).unwrap();
    assert_eq!(
        m.triangles(),
        &[
            [0, 1, 2],
            [0, 1, 2],
            [0, 2, 3],
            [0, 3, 4],
            [4, 3, 2],
            [4, 2, 1]
        ]
    );
}

#[test]
fn obj_negative_indices_are_relative() {
    let text = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf -3 -2 -1\nv 1 1 0\nf -3 -2 -1\nf 1 -1 -3\n";
    let m = io::parse_obj(text, &p("neg.obj")).unwrap();
    assert_eq!(m.triangles(), &[[0, 1, 2], [1, 2, 3], [0, 3, 1]]);
}

#[test]
fn obj_slash_forms_ignore_texture_and_normal_indices() {
    let text = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nvt 0 0\nvt 1 0\nvn 0 0 1\n\
                f 1 2 3\nf 1/1 2/2 3/1\nf 1//1 2//1 3//1\nf 1/2/1 2/1/1 4/2/1\nf -4/-2/-1 -3//-1 -1/1\n";
    let m = io::parse_obj(text, &p("slash.obj")).unwrap();
    assert_eq!(
        m.vertex_count(),
        4,
        "no vertex duplication per texcoord/normal"
    );
    assert_eq!(
        m.triangles(),
        &[[0, 1, 2], [0, 1, 2], [0, 1, 2], [0, 1, 3], [0, 1, 3]]
    );
}

#[test]
fn obj_groups_objects_and_noise_do_not_reindex() {
    let text = "# a comment\r\n\r\nmtllib scene.mtl\r\no first\r\ng part\r\nv 0 0 0\r\n\
                v 1 0 0 # trailing comment\r\nv 0 1 0\r\nusemtl red\r\ns 1\r\nf 1 2 3\r\n\
                o second\r\ng other\r\ns off\r\nv 5 5 5 1.0\r\nv 6 5 5 0.2 0.3 0.4\r\n\
                v 5 6 5\r\nvt 0.5 0.5\r\nvn 0 0 1\r\nl 1 2\r\nf 4 5 6\r\nf 3 4 6\r\n";
    let m = io::parse_obj(text, &p("groups.obj")).unwrap();
    assert_eq!(
        m.positions(),
        &[
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [5.0, 5.0, 5.0],
            [6.0, 5.0, 5.0],
            [5.0, 6.0, 5.0]
        ]
    );
    assert_eq!(m.triangles(), &[[0, 1, 2], [3, 4, 5], [2, 3, 5]]);
}

#[test]
fn obj_forward_references_and_line_continuation() {
    let text = "f 1 2 \\\n 3\nv 0 0 0\nv 1 0 0\nv 0 1 0\n";
    let m = io::parse_obj(text, &p("fwd.obj")).unwrap();
    assert_eq!(m.triangles(), &[[0, 1, 2]]);
}

#[test]
fn obj_malformed_inputs_are_errors_with_lines() {
    let v3 = "v 0 0 0\nv 1 0 0\nv 0 1 0\n";
    let cases: &[(String, usize, &str)] = &[
        (format!("{v3}f 1 2\n"), 4, "at least 3"),
        (format!("{v3}f\n"), 4, "at least 3"),
        (format!("{v3}f 1 2 4\n"), 4, "only 3 vertices"),
        (format!("{v3}f 1 2 3\nf 1 2 9\n"), 5, "only 3 vertices"),
        (format!("{v3}f 0 1 2\n"), 4, "index 0"),
        (format!("{v3}f -4 1 2\n"), 4, "before the first vertex"),
        (format!("{v3}f 1 2 x\n"), 4, "invalid face vertex"),
        (format!("{v3}f 1/2/3/4 2 3\n"), 4, "too many"),
        (format!("{v3}f 1/a 2 3\n"), 4, "texture/normal"),
        (format!("{v3}f 1 2 1\n"), 4, "repeats a vertex"),
        (format!("{v3}f 1 2 1 3\n"), 4, "repeats a vertex"),
        ("v 0 0\nv 1 0 0\n".to_string(), 1, "3 are needed"),
        ("v 0 0 0\nv 1 zero 0\n".to_string(), 2, "invalid coordinate"),
        ("v 0 0 0\nv 1 nan 0\n".to_string(), 2, "non-finite"),
        ("v 0 0 0\nv 1 0 inf\n".to_string(), 2, "non-finite"),
        ("v 0 0 0\nv 1 0 -1e40\n".to_string(), 2, "non-finite"),
        ("v 0 0 0 \\".to_string(), 1, "continuation"),
        (String::new(), 0, "no vertices"),
        ("# nothing\n\n".to_string(), 0, "no vertices"),
        (v3.to_string(), 0, "no triangles"),
    ];
    for (text, line, needle) in cases {
        let msg = obj_err(text, *line);
        assert!(msg.contains(needle), "{msg:?} should mention {needle:?}");
    }
}

#[test]
fn obj_non_utf8_is_an_error_with_line() {
    let bytes = b"v 0 0 0\nv 1 0 0\nv 0 \xff 0\nf 1 2 3\n";
    let msg = parse_err_at(io::parse_obj_bytes(bytes, &p("bad.obj")), "bad.obj", 3);
    assert!(msg.contains("UTF-8"), "{msg}");
    let path = tmp("bad_utf8.obj");
    std::fs::write(&path, bytes).unwrap();
    let err = io::load(&path).unwrap_err();
    assert!(matches!(err, Error::Parse { line: 3, .. }), "{err}");
}

// ---------------------------------------------------------------------------------------------
// STL
// ---------------------------------------------------------------------------------------------

#[test]
fn stl_ascii_and_binary_give_the_same_welded_mesh() {
    let m = octahedron();
    let ascii = io::parse_stl(stl_ascii(&m).as_bytes(), &p("a.stl")).unwrap();
    let binary = io::parse_stl(&stl_binary(&m, b"dhcd binary"), &p("b.stl")).unwrap();
    assert_eq!(ascii, binary);
    // Welded: 6 vertices, numbered in order of first appearance, which for the octahedron
    // triangles is 0,2,4,1,3,5.
    assert_eq!(ascii.vertex_count(), 6);
    assert_eq!(ascii.triangle_count(), 8);
    let order = [0usize, 2, 4, 1, 3, 5];
    for (new, &old) in order.iter().enumerate() {
        assert_eq!(ascii.positions()[new], m.positions()[old]);
    }
    // Same triangles up to that renumbering, in facet order.
    for t in 0..8 {
        assert_eq!(ascii.corners(t), m.corners(t));
    }
    assert_eq!(ascii.triangles()[0], [0, 1, 2]);
    assert_eq!(ascii.triangles()[1], [1, 3, 2]);
}

#[test]
fn stl_binary_starting_with_solid_is_read_as_binary() {
    let m = octahedron();
    let bytes = stl_binary(&m, b"solid but actually binary");
    let got = io::parse_stl(&bytes, &p("solid.stl")).unwrap();
    assert_eq!(got.triangle_count(), 8);
    assert_eq!(got.vertex_count(), 6);
    for t in 0..8 {
        assert_eq!(got.corners(t), m.corners(t));
    }
    // And through `load` with sniffing (no extension).
    let path = tmp("solid_binary_noext");
    std::fs::write(&path, &bytes).unwrap();
    assert_eq!(io::load(&path).unwrap(), got);
}

#[test]
fn stl_welds_negative_and_positive_zero_but_nothing_else() {
    let text = "solid z\n\
        facet normal 0 0 1\n outer loop\n vertex 0 0 0\n vertex 1 0 0\n vertex 0 1 0\n endloop\nendfacet\n\
        facet normal 0 0 1\n outer loop\n vertex -0 -0.0 0\n vertex 0 1 0\n vertex 0 0 1\n endloop\nendfacet\n\
        facet normal 0 0 1\n outer loop\n vertex 1.0000001 0 0\n vertex 0 1 0\n vertex 0 0 1\n endloop\nendfacet\n\
        endsolid z\n";
    let m = io::parse_stl(text.as_bytes(), &p("z.stl")).unwrap();
    assert_eq!(m.triangles(), &[[0, 1, 2], [0, 2, 3], [4, 2, 3]]);
    assert_eq!(m.vertex_count(), 5);
}

#[test]
fn stl_ascii_tolerates_case_multiple_solids_and_polygons() {
    let text = "SOLID a\nFACET NORMAL 0 0 1\nOUTER LOOP\nVERTEX 0 0 0\nVERTEX 1 0 0\nVERTEX 1 1 0\n\
                VERTEX 0 1 0\nENDLOOP\nENDFACET\nENDSOLID a\nsolid b\r\nfacet normal nan nan nan\r\n\
                outer loop\r\nvertex 0 0 0\r\nvertex 0 1 0\r\nvertex 0 0 1\r\nendloop\r\nendfacet\r\n\
                endsolid\r\n";
    let m = io::parse_stl(text.as_bytes(), &p("multi.stl")).unwrap();
    assert_eq!(m.triangles(), &[[0, 1, 2], [0, 2, 3], [0, 3, 4]]);
}

#[test]
fn stl_malformed_inputs_are_errors() {
    let m = octahedron();
    let good_ascii = stl_ascii(&m);
    let good_bin = stl_binary(&m, b"bin");

    // Truncated binary: size check fails and it does not start with "solid".
    let err = parse_err_at(
        io::parse_stl(&good_bin[..good_bin.len() - 7], &p("t.stl")),
        "t.stl",
        0,
    );
    assert!(err.contains("declares 8 facets"), "{err}");
    // Too short for a header.
    let err = parse_err_at(io::parse_stl(b"abc", &p("t.stl")), "t.stl", 0);
    assert!(err.contains("not an STL file"), "{err}");
    let err = parse_err_at(io::parse_stl(b"", &p("t.stl")), "t.stl", 0);
    assert!(err.contains("empty"), "{err}");
    // Zero facets.
    let err = parse_err_at(
        io::parse_stl(
            &stl_binary(&m, b"x")[..84]
                .iter()
                .enumerate()
                .map(|(i, &b)| if i >= 80 { 0 } else { b })
                .collect::<Vec<_>>(),
            &p("t.stl"),
        ),
        "t.stl",
        0,
    );
    assert!(err.contains("no vertices"), "{err}");
    let err = parse_err_at(
        io::parse_stl(b"solid x\nendsolid x\n", &p("t.stl")),
        "t.stl",
        0,
    );
    assert!(err.contains("no vertices"), "{err}");

    // Degenerate facets name the facet.
    let mut bin = good_bin.clone();
    let facet2 = 84 + 2 * 50;
    let corner0: Vec<u8> = bin[facet2 + 12..facet2 + 24].to_vec();
    bin[facet2 + 24..facet2 + 36].copy_from_slice(&corner0);
    let err = parse_err_at(io::parse_stl(&bin, &p("t.stl")), "t.stl", 0);
    assert!(
        err.contains("facet 2 ") && err.contains("degenerate"),
        "{err}"
    );
    let degenerate_ascii = "solid d\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\n\
        vertex 0 1 0\nendloop\nendfacet\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\n\
        vertex 1 0 0\nvertex -0 0 0\nendloop\nendfacet\nendsolid d\n";
    let err = parse_err_at(
        io::parse_stl(degenerate_ascii.as_bytes(), &p("t.stl")),
        "t.stl",
        9,
    );
    assert!(
        err.contains("facet 1 ") && err.contains("degenerate"),
        "{err}"
    );

    // Non-finite binary coordinates.
    let mut bin = good_bin.clone();
    bin[84 + 50 * 3 + 16..84 + 50 * 3 + 20].copy_from_slice(&f32::NAN.to_le_bytes());
    let err = parse_err_at(io::parse_stl(&bin, &p("t.stl")), "t.stl", 0);
    assert!(
        err.contains("facet 3 ") && err.contains("non-finite"),
        "{err}"
    );

    // ASCII: bad number, NaN, inf, truncation, missing endsolid, garbage, too few vertices.
    let replace_line = |line: usize, with: &str| -> String {
        let mut lines: Vec<&str> = good_ascii.lines().collect();
        lines[line - 1] = with;
        lines.join("\n")
    };
    let cases: Vec<(String, usize, &str)> = vec![
        (replace_line(4, "      vertex 1 x 0"), 4, "invalid vertex coordinate"),
        (replace_line(4, "      vertex 1 nan 0"), 4, "non-finite"),
        (replace_line(5, "      vertex 1 0 -inf"), 5, "non-finite"),
        (replace_line(2, "  facet normal 0 0"), 3, "invalid normal component"),
        (replace_line(3, "    outer"), 4, "expected 'loop'"),
        (replace_line(7, "    endlop"), 7, "expected 'vertex' or 'endloop'"),
        (replace_line(8, "  "), 9, "expected 'endfacet'"),
        (good_ascii[..good_ascii.len() - 18].to_string(), 58, "expected 'facet' or 'endsolid'"),
        (good_ascii[..200].to_string(), 12, "unexpected end of file"),
        (format!("{good_ascii}garbage\n"), 59, "expected 'solid'"),
        (
            "solid s\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nendloop\nendfacet\nendsolid\n"
                .to_string(),
            2,
            "at least 3",
        ),
    ];
    for (text, line, needle) in cases {
        let msg = parse_err_at(io::parse_stl(text.as_bytes(), &p("t.stl")), "t.stl", line);
        assert!(msg.contains(needle), "{msg:?} should mention {needle:?}");
    }
}

// ---------------------------------------------------------------------------------------------
// PLY
// ---------------------------------------------------------------------------------------------

#[test]
fn ply_ascii_and_binary_encodings_give_the_same_mesh() {
    let f = PlyFixture::new();
    let expected = f.expected();
    let ascii = io::parse_ply(&f.ascii(), &p("a.ply")).unwrap();
    let le = io::parse_ply(&f.binary(false), &p("le.ply")).unwrap();
    let be = io::parse_ply(&f.binary(true), &p("be.ply")).unwrap();
    assert_eq!(ascii, expected);
    assert_eq!(le, expected);
    assert_eq!(be, expected);
    assert_eq!(expected.triangle_count(), 12);
    assert_eq!(expected.triangles()[0], [0, 3, 2]);
    assert_eq!(expected.triangles()[1], [0, 2, 1]);
}

#[test]
fn ply_integer_coordinates_vertex_index_name_and_faces_first() {
    let text = "ply\nformat ascii 1.0\nelement face 2\nproperty list int short vertex_index\n\
                element vertex 4\nproperty short x\nproperty int y\nproperty uchar z\nend_header\n\
                3 0 1 2\n4 0 1 3 2\n0 0 0\n1 0 0\n0 1 0\n1 1 7\n";
    let m = io::parse_ply(text.as_bytes(), &p("ints.ply")).unwrap();
    assert_eq!(
        m.positions(),
        &[
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [1.0, 1.0, 7.0]
        ]
    );
    assert_eq!(m.triangles(), &[[0, 1, 2], [0, 1, 3], [0, 3, 2]]);
}

#[test]
fn ply_malformed_inputs_are_errors() {
    let f = PlyFixture::new();
    let ascii = String::from_utf8(f.ascii()).unwrap();
    let header_lines = ascii
        .lines()
        .position(|l| l.trim() == "end_header")
        .unwrap()
        + 1;
    let first_vertex = header_lines + 1;
    let first_face = header_lines + 8 + 2 + 1;
    let replace_line = |line: usize, with: &str| -> String {
        let mut lines: Vec<&str> = ascii.lines().collect();
        lines[line - 1] = with;
        lines.join("\n")
    };
    let minimal =
        |header: &str, body: &str| format!("ply\nformat ascii 1.0\n{header}end_header\n{body}");
    let vf = "element vertex 3\nproperty float x\nproperty float y\nproperty float z\n\
              element face 1\nproperty list uchar int vertex_indices\n";
    let vbody = "0 0 0\n1 0 0\n0 1 0\n";
    let cases: Vec<(String, usize, &str)> = vec![
        (String::new(), 0, "empty"),
        ("plx\nformat ascii 1.0\n".to_string(), 1, "first line must be 'ply'"),
        ("ply\nformat ascii 1.0\nelement vertex 3\n".to_string(), 3, "missing 'end_header'"),
        ("ply\nelement vertex 0\nend_header\n".to_string(), 3, "no 'format'"),
        ("ply\nformat text 1.0\n".to_string(), 2, "unknown PLY format"),
        ("ply\nformat ascii\n".to_string(), 2, "without a version"),
        ("ply\nformat ascii 1.0\nelement vertex\n".to_string(), 3, "element <name> <count>"),
        ("ply\nformat ascii 1.0\nelement vertex -3\n".to_string(), 3, "invalid element count"),
        ("ply\nformat ascii 1.0\nproperty float x\n".to_string(), 3, "before any 'element'"),
        ("ply\nformat ascii 1.0\nelement vertex 1\nproperty half x\n".to_string(), 4, "unknown property type"),
        ("ply\nformat ascii 1.0\nelement vertex 1\nproperty float\n".to_string(), 4, "property <type> <name>"),
        ("ply\nformat ascii 1.0\nelement face 1\nproperty list float int vertex_indices\n".to_string(), 4, "integer type"),
        ("ply\nformat ascii 1.0\nfoo\n".to_string(), 3, "unknown PLY header keyword"),
        (minimal("element face 0\nproperty list uchar int vertex_indices\n", ""), 5, "no 'vertex' element"),
        (minimal("element vertex 0\nproperty float x\n", ""), 5, "no 'face' element"),
        (minimal("element vertex 1\nproperty float x\nproperty float y\nelement face 0\nproperty list uchar int vertex_indices\n", "0 0\n"), 3, "no 'z' property"),
        (minimal("element vertex 0\nproperty float x\nproperty float y\nproperty float z\nelement face 0\nproperty int vertex_indices\n", ""), 7, "must be a list"),
        (minimal("element vertex 0\nproperty float x\nproperty float y\nproperty float z\nelement face 0\nproperty list uchar float vertex_indices\n", ""), 7, "integer type"),
        (minimal("element vertex 0\nproperty float x\nproperty float y\nproperty float z\nelement face 0\nproperty list uchar int corners\n", ""), 7, "no 'vertex_indices'"),
        (minimal(vf, &format!("{vbody}3 0 1 3\n")), 13, "out of range"),
        (minimal(vf, &format!("{vbody}3 0 1 -1\n")), 13, "invalid vertex index"),
        (minimal(vf, &format!("{vbody}2 0 1\n")), 13, "at least 3"),
        (minimal(vf, &format!("{vbody}3 0 1 1\n")), 13, "repeats a vertex"),
        (minimal(vf, &format!("{vbody}3 0 1\n")), 13, "row ends early"),
        (minimal(vf, &format!("{vbody}3 0 1 2 5\n")), 13, "extra value"),
        (minimal(vf, &format!("{vbody}300 0 1 2\n")), 13, "out of range"),
        (minimal(vf, vbody), 13, "unexpected end of file"),
        (minimal(vf, "0 0 0\n1 nan 0\n0 1 0\n3 0 1 2\n"), 11, "non-finite"),
        (minimal(vf, "0 0 0\n1 0 0\n0 1 1e39\n3 0 1 2\n"), 12, "non-finite"),
        (minimal(vf, "0 0 0\n1 0.x 0\n0 1 0\n3 0 1 2\n"), 11, "invalid float value"),
        (minimal(&vf.replace("face 1", "face 0"), vbody), 0, "no triangles"),
        (replace_line(first_vertex, "0 0.5 zero 0 255"), first_vertex, "invalid double value"),
        (replace_line(first_face, "9 4 0 3 2 1 2 0.25"), first_face, "row ends early"),
        (ascii[..ascii.len() - 30].to_string(), first_face + 4, "element 'face' row 4"),
    ];
    for (text, line, needle) in cases {
        let msg = parse_err_at(io::parse_ply(text.as_bytes(), &p("t.ply")), "t.ply", line);
        assert!(msg.contains(needle), "{msg:?} should mention {needle:?}");
    }

    // Binary truncation at every length gives a clean error.
    for big in [false, true] {
        let bin = f.binary(big);
        let data_start = bin.windows(11).position(|w| w == b"end_header\r").unwrap() + 12;
        for len in data_start..bin.len() {
            let err = io::parse_ply(&bin[..len], &p("t.ply")).unwrap_err();
            assert!(err.to_string().contains("truncated"), "{err}");
        }
        // Index out of range in binary: the last index of the first face.
        let mut bad = bin.clone();
        let vertex_row = 8 + 4 + 8 + 8 + 1;
        let edge_row = 1 + 4 + 4 + 2;
        let at = data_start + 8 * vertex_row + 2 * edge_row + 2 + 3 * 4;
        let huge = if big {
            99u32.to_be_bytes()
        } else {
            99u32.to_le_bytes()
        };
        bad[at..at + 4].copy_from_slice(&huge);
        let err = parse_err_at(io::parse_ply(&bad, &p("t.ply")), "t.ply", 0);
        assert!(
            err.contains("row 0") && err.contains("out of range"),
            "{err}"
        );
    }
}

// ---------------------------------------------------------------------------------------------
// load / format detection
// ---------------------------------------------------------------------------------------------

#[test]
fn load_uses_extension_case_insensitively_and_sniffs_otherwise() {
    let m = octahedron();
    let mut obj = Vec::new();
    io::write_obj(&m, &mut obj).unwrap();
    let f = PlyFixture::new();
    let files: Vec<(&str, Vec<u8>, Format)> = vec![
        ("a.OBJ", obj.clone(), Format::Obj),
        ("a.Stl", stl_binary(&m, b"x"), Format::Stl),
        ("b.STL", stl_ascii(&m).into_bytes(), Format::Stl),
        ("a.PlY", f.binary(true), Format::Ply),
        ("noext_obj", obj.clone(), Format::Obj),
        (
            "noext_stl_ascii.mesh",
            stl_ascii(&m).into_bytes(),
            Format::Stl,
        ),
        ("noext_stl_bin", stl_binary(&m, b"whatever"), Format::Stl),
        ("noext_ply.dat", f.ascii(), Format::Ply),
    ];
    for (name, bytes, format) in files {
        let path = tmp(name);
        std::fs::write(&path, &bytes).unwrap();
        let loaded = io::load(&path).unwrap_or_else(|e| panic!("{name}: {e}"));
        let parsed = io::parse(&bytes, format, &path).unwrap();
        assert_eq!(loaded, parsed, "{name}");
        if Format::from_extension(&path).is_none() {
            assert_eq!(Format::sniff(&bytes), Some(format), "{name}");
        }
    }
    assert_eq!(io::load_stl(&tmp("a.Stl")).unwrap().triangle_count(), 8);
    assert_eq!(io::load_ply(&tmp("a.PlY")).unwrap().triangle_count(), 12);
    assert_eq!(io::load_obj(&tmp("a.OBJ")).unwrap(), m);
}

#[test]
fn load_reports_unknown_formats_and_missing_files() {
    let path = tmp("mystery.xyz");
    std::fs::write(&path, b"hello world\n1 2 3\n").unwrap();
    let err = io::load(&path).unwrap_err();
    let msg = err.to_string();
    assert!(
        msg.contains("mystery.xyz") && msg.contains("unknown mesh format"),
        "{msg}"
    );

    let missing = tmp("does_not_exist.obj");
    let err = io::load(&missing).unwrap_err();
    assert!(matches!(err, Error::Io { .. }), "{err:?}");
    assert!(err.to_string().contains("does_not_exist.obj"), "{err}");
    assert!(matches!(io::load_ply(&missing), Err(Error::Io { .. })));
}

// ---------------------------------------------------------------------------------------------
// Never panic on any input
// ---------------------------------------------------------------------------------------------

fn all_parsers(bytes: &[u8]) {
    let path = p("fuzz");
    let _ = io::parse_obj_bytes(bytes, &path);
    let _ = io::parse_obj(&String::from_utf8_lossy(bytes), &path);
    let _ = io::parse_stl(bytes, &path);
    let _ = io::parse_ply(bytes, &path);
    if let Some(format) = Format::sniff(bytes) {
        let _ = io::parse(bytes, format, &path);
    }
}

fn seeds() -> Vec<Vec<u8>> {
    let m = octahedron();
    let mut obj = Vec::new();
    io::write_obj(&m, &mut obj).unwrap();
    obj.extend_from_slice(b"f -1/2/3 -2//1 -3 1\n");
    let f = PlyFixture::new();
    vec![
        obj,
        stl_ascii(&m).into_bytes(),
        stl_binary(&m, b"solid"),
        f.ascii(),
        f.binary(false),
        f.binary(true),
    ]
}

#[derive(Debug, Clone)]
enum Mutation {
    Set(usize, u8),
    Insert(usize, u8),
    Remove(usize),
    Truncate(usize),
    InsertText(usize, &'static str),
}

fn mutation() -> impl Strategy<Value = Mutation> {
    let tokens = prop::sample::select(vec![
        "-1",
        "0",
        "4294967295",
        "99999999999999999999",
        "nan",
        "inf",
        "-0",
        "1e39",
        "/",
        "//",
        "\n",
        "\r\n",
        " ",
        "\\",
        "#",
        "f ",
        "v ",
        "facet",
        "endloop",
        "endsolid",
        "solid",
        "element face 4294967295\n",
        "property list uint uint vertex_indices\n",
        "end_header\n",
        "\u{7f}",
        "\u{ff}",
        "255",
        "-128",
    ]);
    prop_oneof![
        (any::<usize>(), any::<u8>()).prop_map(|(i, b)| Mutation::Set(i, b)),
        (any::<usize>(), any::<u8>()).prop_map(|(i, b)| Mutation::Insert(i, b)),
        any::<usize>().prop_map(Mutation::Remove),
        any::<usize>().prop_map(Mutation::Truncate),
        (any::<usize>(), tokens).prop_map(|(i, t)| Mutation::InsertText(i, t)),
    ]
}

fn apply(bytes: &mut Vec<u8>, m: &Mutation) {
    let n = bytes.len();
    match *m {
        Mutation::Set(i, b) if n > 0 => bytes[i % n] = b,
        Mutation::Insert(i, b) => bytes.insert(i % (n + 1), b),
        Mutation::Remove(i) if n > 0 => {
            bytes.remove(i % n);
        }
        Mutation::Truncate(i) => bytes.truncate(i % (n + 1)),
        Mutation::InsertText(i, t) => {
            let at = i % (n + 1);
            bytes.splice(at..at, t.bytes());
        }
        _ => {}
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(512))]

    #[test]
    fn parsers_never_panic_on_random_bytes(bytes in prop::collection::vec(any::<u8>(), 0..600)) {
        all_parsers(&bytes);
        // Also behind plausible magic.
        for prefix in [&b"ply\nformat ascii 1.0\n"[..], b"ply\nformat binary_little_endian 1.0\n", b"solid ", b"v 1 2 3\nf "] {
            let mut with = prefix.to_vec();
            with.extend_from_slice(&bytes);
            all_parsers(&with);
        }
    }

    #[test]
    fn parsers_never_panic_on_mutated_valid_files(
        seed in 0usize..6,
        mutations in prop::collection::vec(mutation(), 1..6),
    ) {
        let mut bytes = seeds().swap_remove(seed);
        for m in &mutations {
            apply(&mut bytes, m);
        }
        all_parsers(&bytes);
    }
}

#[test]
fn seeds_are_valid() {
    for (i, s) in seeds().iter().enumerate() {
        let format = Format::sniff(s).unwrap_or_else(|| panic!("seed {i} not sniffed"));
        io::parse(s, format, &p("seed")).unwrap_or_else(|e| panic!("seed {i}: {e}"));
    }
}

#[test]
fn obj_with_byte_order_mark_loads() {
    let m = io::parse_obj(
        "\u{feff}v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n",
        &p("bom.obj"),
    )
    .unwrap();
    assert_eq!(m.triangles(), &[[0, 1, 2]]);
    assert_eq!(
        Format::sniff("\u{feff}# c\nv 0 0 0\n".as_bytes()),
        Some(Format::Obj)
    );
}

#[test]
fn huge_declared_counts_fail_fast_without_allocating() {
    let text =
        "ply\nformat binary_little_endian 1.0\nelement vertex 4000000000\nproperty float x\n\
                property float y\nproperty float z\nelement face 4000000000\n\
                property list uint uint vertex_indices\nend_header\n\x00\x00\x00\x00";
    let err = io::parse_ply(text.as_bytes(), &p("huge.ply")).unwrap_err();
    assert!(err.to_string().contains("truncated"), "{err}");
    let mut stl = vec![0u8; 84];
    stl[80..84].copy_from_slice(&u32::MAX.to_le_bytes());
    let err = io::parse_stl(&stl, &p("huge.stl")).unwrap_err();
    assert!(
        err.to_string().contains("declares 4294967295 facets"),
        "{err}"
    );
}

#[test]
fn loading_a_directory_is_an_io_error() {
    let dir = tmp("a_directory.obj");
    std::fs::create_dir_all(&dir).unwrap();
    assert!(matches!(io::load(&dir), Err(Error::Io { .. })));
}

#[test]
fn ply_sized_type_names_and_int_list_counts() {
    let mut bytes = b"ply\nformat binary_little_endian 1.0\nelement vertex 4\nproperty float32 x\n\
        property float32 y\nproperty float32 z\nproperty int8 tag\nelement face 1\n\
        property list int32 int32 vertex_indices\nend_header\n"
        .to_vec();
    for (i, v) in [
        [0.0f32, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [1.0, 1.0, 0.0],
        [0.0, 1.0, 0.5],
    ]
    .iter()
    .enumerate()
    {
        for x in v {
            bytes.extend_from_slice(&x.to_le_bytes());
        }
        bytes.push(i as u8);
    }
    for i in [4i32, 3, 2, 1, 0] {
        bytes.extend_from_slice(&i.to_le_bytes());
    }
    let m = io::parse_ply(&bytes, &p("sized.ply")).unwrap();
    assert_eq!(m.triangles(), &[[3, 2, 1], [3, 1, 0]]);
    assert_eq!(m.positions()[3], [0.0, 1.0, 0.5]);
}
