//! Every labelled pair of `../shared/data/ccd/frame-truth/*.tsv` (Belgrod et al. 2023;
//! Mathematica ground truth): the pair's f64 vertex positions gathered from the frame
//! (t = 0) and the next frame (t = 1) of `../shared/data/real-frames/`, and the CCD result
//! equal to the label.
//!
//! Positions come from the library's loader at `Precision::F64`; a minimal binary-PLY
//! reader of this suite (f64 little-endian or f32 big-endian vertices, uchar-count int32
//! faces; f32 values widen to f64 exactly) cross-checks them bit for bit.

use std::path::Path;
use std::time::Instant;

use dhcd::ccd::{self, CcdOptions};
use dhcd::io::{load_as, Limits};
use dhcd::Precision;

/// Vertex positions (f64) and triangles of a binary PLY file.
pub fn read_ply(path: &Path) -> (Vec<[f64; 3]>, Vec<[u32; 3]>) {
    let bytes = std::fs::read(path).unwrap();
    let end = bytes
        .windows(11)
        .position(|w| w == b"end_header\n")
        .expect("PLY header")
        + 11;
    let header = std::str::from_utf8(&bytes[..end]).unwrap();
    let little = header.contains("binary_little_endian");
    assert!(little || header.contains("binary_big_endian"));
    let (mut nv, mut nf) = (0usize, 0usize);
    // Vertex properties: (size in bytes, is a coordinate of type f64/f32).
    let mut props: Vec<(usize, Option<bool>)> = Vec::new();
    let mut in_vertex = false;
    for line in header.lines() {
        let w: Vec<&str> = line.split_whitespace().collect();
        match w.as_slice() {
            ["element", "vertex", n] => {
                nv = n.parse().unwrap();
                in_vertex = true;
            }
            ["element", "face", n] => {
                nf = n.parse().unwrap();
                in_vertex = false;
            }
            ["property", "list", cnt, idx, _] => {
                assert!(matches!(*cnt, "uchar" | "uint8") && matches!(*idx, "int" | "int32"));
            }
            ["property", ty, name] if in_vertex => {
                let size = match *ty {
                    "double" | "float64" => 8,
                    "float" | "float32" => 4,
                    "uchar" | "uint8" => 1,
                    t => panic!("unsupported vertex property type {t}"),
                };
                let coord = matches!(*name, "x" | "y" | "z").then_some(size == 8);
                props.push((size, coord));
            }
            _ => {}
        }
    }
    let mut at = end;
    let mut take = |n: usize| {
        let s = &bytes[at..at + n];
        at += n;
        s
    };
    let mut pos = Vec::with_capacity(nv);
    for _ in 0..nv {
        let mut p = [0.0; 3];
        let mut k = 0;
        for &(size, coord) in &props {
            let b = take(size);
            if let Some(is64) = coord {
                p[k] = if is64 {
                    let a: [u8; 8] = b.try_into().unwrap();
                    if little {
                        f64::from_le_bytes(a)
                    } else {
                        f64::from_be_bytes(a)
                    }
                } else {
                    let a: [u8; 4] = b.try_into().unwrap();
                    (if little {
                        f32::from_le_bytes(a)
                    } else {
                        f32::from_be_bytes(a)
                    }) as f64
                };
                k += 1;
            }
        }
        assert_eq!(k, 3);
        pos.push(p);
    }
    let mut tris = Vec::with_capacity(nf);
    for _ in 0..nf {
        assert_eq!(take(1)[0], 3, "only triangles");
        let mut t = [0u32; 3];
        for v in t.iter_mut() {
            let a: [u8; 4] = take(4).try_into().unwrap();
            *v = if little {
                i32::from_le_bytes(a)
            } else {
                i32::from_be_bytes(a)
            } as u32;
        }
        tris.push(t);
    }
    (pos, tris)
}

#[test]
fn frame_truth_labels_match() {
    let Some(data) = crate::support::shared_data("ccd_frames::frame_truth_labels_match", "") else {
        return;
    };
    let data = || data.clone();
    let o = CcdOptions::default();
    let start = Instant::now();
    let (mut total, mut wrong) = (0usize, Vec::new());
    for (name, next) in [
        ("armadillo-rollers-326", "armadillo-rollers-327"),
        ("cloth-ball-92", "cloth-ball-93"),
        ("n-body-simulation-18", "n-body-simulation-19"),
        ("rod-twist-3036", "rod-twist-3037"),
    ] {
        let load = |f: &str| {
            let path = data().join(format!("real-frames/{f}.ply"));
            let mesh = load_as(&path, &Limits::default(), Precision::F64).unwrap();
            let pos = mesh.positions_f64().expect("an f64 mesh").to_vec();
            let (own_pos, own_tris) = read_ply(&path);
            assert!(pos
                .iter()
                .zip(&own_pos)
                .all(|(a, b)| a.map(f64::to_bits) == b.map(f64::to_bits)));
            assert_eq!(
                (pos.len(), mesh.triangles()),
                (own_pos.len(), &own_tris[..])
            );
            (pos, own_tris)
        };
        let (p0, tris) = load(name);
        let (p1, tris1) = load(next);
        assert_eq!(tris, tris1);
        let text =
            std::fs::read_to_string(data().join(format!("ccd/frame-truth/{name}.tsv"))).unwrap();
        let (mut vf, mut ee, mut hits) = (0, 0, 0);
        for line in text.lines().filter(|l| !l.trim().is_empty()) {
            let w: Vec<&str> = line.split_whitespace().collect();
            let num = |i: usize| w[i].parse::<usize>().unwrap();
            let (ids, label, got) = match w[0] {
                "vf" => {
                    let t = tris[num(2)];
                    let ids = [num(1), t[0] as usize, t[1] as usize, t[2] as usize];
                    let (x0, x1) = (ids.map(|i| p0[i]), ids.map(|i| p1[i]));
                    vf += 1;
                    (ids, w[3] == "1", ccd::vertex_face(&x0, &x1, &o))
                }
                "ee" => {
                    let ids = [num(1), num(2), num(3), num(4)];
                    let (x0, x1) = (ids.map(|i| p0[i]), ids.map(|i| p1[i]));
                    ee += 1;
                    (ids, w[5] == "1", ccd::edge_edge(&x0, &x1, &o))
                }
                k => panic!("unknown label kind {k}"),
            };
            total += 1;
            hits += got.is_some() as usize;
            if got.is_some() != label {
                wrong.push(format!(
                    "{name} {} {ids:?}: label {label}, got {got:?}",
                    w[0]
                ));
            }
        }
        println!("{name}: {vf} vf + {ee} ee labels, {hits} colliding");
    }
    println!(
        "frame truth: {} matched of {total} in {:.1} s",
        total - wrong.len(),
        start.elapsed().as_secs_f64()
    );
    assert!(
        wrong.is_empty(),
        "{} mismatches:\n{}",
        wrong.len(),
        wrong.join("\n")
    );
    assert_eq!(
        total,
        4652 + 19313 + 19034 + 94825 + 9460 + 41036 + 801 + 4370
    );
}
