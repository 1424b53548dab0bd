//! Tests of `dhcd::io`: OBJ, STL and PLY loaders and the OBJ writer.

use std::path::{Path, PathBuf};

use dhcd::io::{self, Format};
use dhcd::{Error, Mesh};

use crate::fixtures::{octahedron, seeds, stl_ascii, stl_binary, PlyFixture};

// ---------------------------------------------------------------------------------------------
// Helpers
// ---------------------------------------------------------------------------------------------

fn p(name: &str) -> PathBuf {
    PathBuf::from(name)
}

fn mesh(positions: &[[f32; 3]], triangles: &[[u32; 3]]) -> Mesh {
    Mesh::new(positions.to_vec(), triangles.to_vec()).unwrap()
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
    // Line 0 (the whole file, or a binary one) is not cited.
    let at = if line == 0 {
        format!("{path}: ")
    } else {
        format!("{path}:{line}: ")
    };
    assert!(text.starts_with(&at), "{text}");
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
    // Extensions are matched whatever their case.
    assert_eq!(io::load(&tmp("a.Stl")).unwrap().triangle_count(), 8);
    assert_eq!(io::load(&tmp("a.PlY")).unwrap().triangle_count(), 12);
    assert_eq!(io::load(&tmp("a.OBJ")).unwrap(), m);
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

// ---------------------------------------------------------------------------------------------
// Hostile files: bounded time and memory (issue 9)
// ---------------------------------------------------------------------------------------------

/// Runs `f` on its own thread and fails the test if it has not finished after a generous
/// minute (the inputs are tiny or read nothing; before the fixes these hung or filled memory).
fn finishes<R: Send + 'static>(what: &str, f: impl FnOnce() -> R + Send + 'static) -> R {
    let (tx, rx) = std::sync::mpsc::channel();
    std::thread::spawn(move || {
        let _ = tx.send(f());
    });
    rx.recv_timeout(std::time::Duration::from_secs(60))
        .unwrap_or_else(|_| panic!("{what}: no answer within a minute"))
}

fn one_line(err: &Error) -> String {
    let text = err.to_string();
    assert!(
        !text.chars().any(|c| c.is_control()),
        "one printable line: {text:?}"
    );
    text
}

#[cfg(unix)]
#[test]
fn devices_fifos_and_links_to_them_are_refused_without_reading() {
    let dir = crate::support::temp_dir("io-not-regular");
    let link = dir.join("zero.obj");
    std::os::unix::fs::symlink("/dev/zero", &link).unwrap();
    let fifo = dir.join("fifo.obj");
    let made = std::process::Command::new("mkfifo").arg(&fifo).status();
    assert!(made.is_ok_and(|s| s.success()), "mkfifo");
    let cases = [
        (PathBuf::from("/dev/zero"), "a character device"),
        (PathBuf::from("/dev/urandom"), "a character device"),
        (link, "a character device"),
        (fifo, "a FIFO"),
        (dir.to_path_buf(), "a directory"),
    ];
    for (path, kind) in cases {
        let shown = path.display().to_string();
        let err = finishes(&shown, move || io::load(&path).unwrap_err());
        let text = one_line(&err);
        assert!(matches!(err, Error::Io { .. }), "{err:?}");
        assert!(
            text.contains(&format!("not a regular file ({kind})")) && text.contains(&shown),
            "{text}"
        );
    }
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn files_above_the_size_limit_are_refused_before_reading() {
    let dir = crate::support::temp_dir("io-too-large");
    // A sparse file one byte over the default limit: no disk, and nothing is read.
    let sparse = dir.join("sparse.stl");
    let f = std::fs::File::create(&sparse).unwrap();
    f.set_len(io::DEFAULT_MAX_FILE_BYTES + 1).unwrap();
    drop(f);
    let err = crate::support::peak_bytes(|| io::load(&sparse).unwrap_err());
    assert!(err.1 < 1 << 20, "{} bytes allocated", err.1);
    let err = err.0;
    assert_eq!(
        err,
        Error::FileTooLarge {
            path: sparse.clone(),
            limit: io::DEFAULT_MAX_FILE_BYTES
        }
    );
    assert!(one_line(&err).contains("--max-file-bytes"), "{err}");
    // The limit is the caller's: a small file under a smaller limit.
    let small = dir.join("small.obj");
    std::fs::write(&small, "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n").unwrap();
    let limits = |max_file_bytes| io::Limits { max_file_bytes };
    assert!(matches!(
        io::load_with(&small, &limits(10)),
        Err(Error::FileTooLarge { limit: 10, .. })
    ));
    assert_eq!(
        io::load_with(&small, &limits(32)).unwrap().triangle_count(),
        1
    );
    let _ = std::fs::remove_dir_all(&dir);
}

/// A regular file whose size says 0 but which has content (as files under /proc do) is still
/// read no further than the limit.
#[cfg(target_os = "linux")]
#[test]
fn the_limit_bounds_the_bytes_read_not_only_the_size_on_disk() {
    let path = Path::new("/proc/self/status");
    assert_eq!(std::fs::metadata(path).unwrap().len(), 0);
    let limits = io::Limits { max_file_bytes: 8 };
    assert!(matches!(
        io::load_with(path, &limits),
        Err(Error::FileTooLarge { limit: 8, .. })
    ));
}

/// 400,000 `element` lines took 227 s (duplicate checks scanned every earlier element).
#[test]
fn ply_header_parsing_is_linear_in_its_lines() {
    let mut text = String::from("ply\nformat ascii 1.0\n");
    for k in 0..400_000 {
        text.push_str(&format!("element e{k} 0\nproperty uchar p\n"));
    }
    text.push_str(
        "element vertex 3\nproperty float x\nproperty float y\nproperty float z\n\
         element face 1\nproperty list uchar int vertex_indices\nend_header\n\
         0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n",
    );
    let m = finishes("400,000 elements", move || {
        io::parse_ply(text.as_bytes(), &p("many.ply"))
    })
    .unwrap();
    assert_eq!(m.triangles(), &[[0, 1, 2]]);
}

/// A header that declares four billion vertices over a little data used to reserve twelve
/// bytes per byte of data; now it reserves what the data can hold (12 bytes per binary row).
#[test]
fn ply_reserves_from_what_the_data_can_hold_not_the_declared_count() {
    let data = 1 << 20;
    for (format, row) in [("binary_little_endian", 12), ("ascii", 6)] {
        let mut bytes = format!(
            "ply\nformat {format} 1.0\nelement vertex 4000000000\nproperty float x\n\
             property float y\nproperty float z\nelement face 4000000000\n\
             property list uchar int vertex_indices\nend_header\n"
        )
        .into_bytes();
        let cell: &[u8] = if row == 12 { &[0; 12] } else { b"0 0 0\n" };
        bytes.extend(cell.iter().cycle().take(data));
        let (result, peak) = crate::support::peak_bytes(|| io::parse_ply(&bytes, &p("huge.ply")));
        let err = result.unwrap_err();
        assert!(matches!(err, Error::Parse { .. }), "{err}");
        // Positions read (12 bytes per vertex) plus at most as much again reserved.
        let bound = 2 * 12 * (data / row) + (1 << 16);
        assert!(peak <= bound, "{format}: {peak} bytes, bound {bound}");
    }
}

#[test]
fn ascii_stl_with_a_byte_order_mark_loads() {
    let m = octahedron();
    let mut bytes = b"\xef\xbb\xbf".to_vec();
    bytes.extend_from_slice(stl_ascii(&m).as_bytes());
    assert_eq!(Format::sniff(&bytes), Some(Format::Stl));
    let got = io::parse_stl(&bytes, &p("bom.stl")).unwrap();
    assert_eq!(got, io::parse_stl(&bytes[3..], &p("plain.stl")).unwrap());
}

#[test]
fn cr_only_line_ends_are_line_ends() {
    let obj = "# made on a classic Mac\rv 0 0 0\rv 1 0 0\rv 0 1 0\rv 0 0 1\rf 1 2 3\rf 1 2 4\r";
    let m = io::parse_obj(obj, &p("cr.obj")).unwrap();
    assert_eq!(m.triangles(), &[[0, 1, 2], [0, 1, 3]]);
    assert_eq!(Format::sniff(obj.as_bytes()), Some(Format::Obj));
    // Line numbers count CR, LF and CRLF line ends alike.
    obj_err("v 0 0 0\rv 1 0 0\r\nv 0 1 0\nf 1 2 x\r", 4);
    let stl = stl_ascii(&octahedron()).replace('\n', "\r");
    assert_eq!(
        io::parse_stl(stl.as_bytes(), &p("cr.stl"))
            .unwrap()
            .triangle_count(),
        8
    );
    let bad = stl.replacen("outer", "outre", 1);
    parse_err_at(io::parse_stl(bad.as_bytes(), &p("t.stl")), "t.stl", 3);
    let ply = String::from_utf8(PlyFixture::new().ascii())
        .unwrap()
        .replace("\r\n", "\n")
        .replace('\n', "\r");
    let got = io::parse_ply(ply.as_bytes(), &p("cr.ply")).unwrap();
    assert_eq!(got.triangles(), PlyFixture::new().expected().triangles());
}

#[test]
fn messages_escape_control_characters_in_paths_and_tokens() {
    let err = io::parse_obj("v 0 0 \u{1b}[31mred\n", &p("evil\nname\0.obj")).unwrap_err();
    let text = one_line(&err);
    assert!(
        text.starts_with("evil\\nname\\0.obj:1: invalid coordinate '\\u{1b}[31mred'"),
        "{text}"
    );
    let err = io::parse_ply(b"ply\nformat ascii 1.0\nv\x07x 1\n", &p("b.ply"));
    let text = one_line(&err.unwrap_err());
    assert!(text.contains("v\\u{7}x"), "{text}");
}
