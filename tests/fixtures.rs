//! Valid mesh files of every format and encoding, built from known meshes: the io suite's
//! fixtures and the fuzzers' seeds (also used by `cli/tests/fuzz.rs`).

#![allow(dead_code)]

use dhcd::io;
use dhcd::Mesh;

/// A closed octahedron: 6 vertices, 8 triangles.
pub fn octahedron() -> Mesh {
    Mesh::new(
        vec![
            [1.0, 0.0, 0.0],
            [-1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [0.0, -1.0, 0.0],
            [0.0, 0.0, 1.0],
            [0.0, 0.0, -1.0],
        ],
        vec![
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
    .unwrap()
}

/// Binary STL with the given 80-byte header prefix, one facet per triangle of `m`.
pub fn stl_binary(m: &Mesh, header: &[u8]) -> Vec<u8> {
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

pub fn stl_ascii(m: &Mesh) -> String {
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
pub struct PlyFixture {
    pub positions: Vec<[f64; 3]>,
    pub faces: Vec<Vec<u32>>,
}

impl PlyFixture {
    pub fn new() -> Self {
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

    pub fn expected(&self) -> Mesh {
        let positions: Vec<[f32; 3]> = self.positions.iter().map(|p| p.map(|x| x as f32)).collect();
        let mut tris = Vec::new();
        for f in &self.faces {
            for i in 1..f.len() - 1 {
                tris.push([f[0], f[i], f[i + 1]]);
            }
        }
        Mesh::new(positions, tris).unwrap()
    }

    pub fn header(&self, format: &str) -> String {
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

    pub fn ascii(&self) -> Vec<u8> {
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

    pub fn binary(&self, big: bool) -> Vec<u8> {
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

/// One valid file of every format and encoding, for the mutation fuzzer.
pub fn seeds() -> Vec<Vec<u8>> {
    let m = octahedron();
    let mut obj = Vec::new();
    io::write_obj(&m, &mut obj).unwrap();
    obj.extend_from_slice(b"f -1/2/3 -2//1 -3 1\n");
    let f = PlyFixture::new();
    let obj_cr: Vec<u8> = obj
        .iter()
        .map(|&b| if b == b'\n' { b'\r' } else { b })
        .collect();
    let stl_bom_crlf = format!("\u{feff}{}", stl_ascii(&m).replace('\n', "\r\n"));
    vec![
        obj,
        obj_cr,
        stl_ascii(&m).into_bytes(),
        stl_bom_crlf.into_bytes(),
        stl_binary(&m, b"solid"),
        f.ascii(),
        f.binary(false),
        f.binary(true),
    ]
}

/// A sheet's end pose for the CCD suites: every point beyond x = 0.45 folded over that line
/// and pushed through the part before it (`fold` = 1 all the way, 0 not at all).
pub fn folded_through(x0: &[[f64; 3]], fold: f64) -> Vec<[f64; 3]> {
    x0.iter()
        .map(|p| {
            if p[0] > 0.45 {
                let folded = [0.9 - p[0], p[1] + 0.013, -0.04 + 0.01 * (p[1] * 7.0).sin()];
                std::array::from_fn(|k| p[k] + fold * (folded[k] - p[k]))
            } else {
                *p
            }
        })
        .collect()
}

/// Two coincident 4 x 4 sheets (cell 1/4) in one mesh at z = 0, the second sliding over the
/// first by (1/8, 1/16) over the step: every pair of the two touches at t0. The mesh and
/// its poses at t0 and t1.
pub fn resting_sheets() -> (Mesh, Vec<[f64; 3]>, Vec<[f64; 3]>) {
    let g = dhcd::shapes::grid(4, 4, 0.25, [0.0; 3]);
    let base: Vec<[f64; 3]> = g.positions().iter().map(|q| q.map(f64::from)).collect();
    let n = base.len() as u32;
    let tris: Vec<[u32; 3]> = g
        .triangles()
        .iter()
        .copied()
        .chain(g.triangles().iter().map(|t| t.map(|v| v + n)))
        .collect();
    let x0: Vec<[f64; 3]> = base.iter().chain(base.iter()).copied().collect();
    let x1: Vec<[f64; 3]> = base
        .iter()
        .copied()
        .chain(base.iter().map(|p| [p[0] + 0.125, p[1] + 0.0625, p[2]]))
        .collect();
    let m = Mesh::new_f64(x0.clone(), tris).unwrap();
    (m, x0, x1)
}
