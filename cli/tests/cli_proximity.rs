//! `dhcd proximity`, `dhcd bench proximity` and `--precision` (JSON output, errors).

use std::path::{Path, PathBuf};

use dhcd::narrow::{brute_force_proximity, brute_force_self_proximity};
use dhcd::shapes::{grid, icosphere, wave};
use dhcd::{Mesh, Proximity};

use crate::support::{self, dhcd, json};

fn dir() -> &'static Path {
    static DIR: std::sync::OnceLock<support::TempDir> = std::sync::OnceLock::new();
    DIR.get_or_init(|| support::temp_dir("proximity-cli"))
}

fn write(name: &str, mesh: &Mesh) -> PathBuf {
    let path = dir().join(name);
    support::write_obj(mesh, &path);
    path
}

fn write_f64(name: &str, positions: &[[f64; 3]], triangles: &[[u32; 3]]) -> PathBuf {
    let path = dir().join(name);
    support::write_obj_f64(&path, positions, triangles);
    path
}

/// The JSON's pairs as the library's result reports them.
fn check_against(v: &serde_json::Value, want: &Proximity, two_meshes: bool) {
    let rows = |key: &str| v[key].as_array().unwrap().clone();
    let vf = rows("vertex_face");
    assert_eq!(vf.len(), want.vertex_face.len());
    for (r, w) in vf.iter().zip(&want.vertex_face) {
        assert_eq!(r[0], w.vertex);
        assert_eq!(r[1], w.triangle);
        assert_eq!(r[2].as_f64().unwrap(), w.distance_sq);
        assert_eq!(r[3], w.kind.ipc_name(), "the JSON names the distance type");
    }
    let ee = rows("edge_edge");
    assert_eq!(ee.len(), want.edge_edge.len());
    for (r, w) in ee.iter().zip(&want.edge_edge) {
        let ids: Vec<u64> = (0..4).map(|k| r[k].as_u64().unwrap()).collect();
        assert_eq!(ids, [w.a[0], w.a[1], w.b[0], w.b[1]].map(u64::from));
        assert_eq!(r[4].as_f64().unwrap(), w.distance_sq);
        assert_eq!(r[5], w.kind.ipc_name());
    }
    if two_meshes {
        let fv = rows("face_vertex");
        assert_eq!(fv.len(), want.face_vertex.len());
        for (r, w) in fv.iter().zip(&want.face_vertex) {
            assert_eq!(
                (r[0].as_u64(), r[1].as_u64()),
                (Some(w.triangle.into()), Some(w.vertex.into()))
            );
        }
    } else {
        assert!(v.get("face_vertex").is_none());
    }
    assert_eq!(v["counters"]["contacts"], want.counters.contacts);
}

#[test]
fn proximity_json_equals_brute_force() {
    let s = icosphere(2, 1.0, [0.0; 3]);
    let crumpled = Mesh::new(
        wave(s.positions(), 1.0, 0.5, [0.0; 3]),
        s.triangles().to_vec(),
    )
    .unwrap();
    let a = Mesh::new(
        wave(s.positions(), 1.0, 0.05, [0.0; 3]),
        s.triangles().to_vec(),
    )
    .unwrap();
    let b = Mesh::new(
        wave(s.positions(), 0.3, 0.05, [2.05, 0.0, 0.0]),
        s.triangles().to_vec(),
    )
    .unwrap();
    let (pc, pa, pb) = (
        write("crumpled.obj", &crumpled),
        write("a.obj", &a),
        write("b.obj", &b),
    );
    for method in ["dh", "sphere", "aabb"] {
        for threads in ["1", "2"] {
            let args = [
                "proximity",
                pc.to_str().unwrap(),
                "--distance",
                "0.05",
                "--method",
                method,
                "--threads",
                threads,
                "--json",
            ];
            let (code, out, err) = dhcd(&args);
            assert_eq!(code, 0, "{err}");
            let v = json(&out);
            let keys: Vec<&str> = v.as_object().unwrap().keys().map(|k| k.as_str()).collect();
            assert_eq!(
                keys,
                [
                    "method",
                    "precision",
                    "distance",
                    "vertex_face",
                    "edge_edge",
                    "counters"
                ]
            );
            assert_eq!(
                (v["method"].as_str(), v["precision"].as_str()),
                (Some(method), Some("f32"))
            );
            let want = brute_force_self_proximity(&crumpled, 0.05);
            assert!(!want.vertex_face.is_empty());
            check_against(&v, &want, false);

            let (code, out, err) = dhcd(&[
                "proximity",
                pa.to_str().unwrap(),
                pb.to_str().unwrap(),
                "--distance",
                "0.1",
                "--method",
                method,
                "--threads",
                threads,
                "--json",
            ]);
            assert_eq!(code, 0, "{err}");
            let v = json(&out);
            let want = brute_force_proximity(&a, &b, 0.1);
            assert!(!want.face_vertex.is_empty() && !want.vertex_face.is_empty());
            check_against(&v, &want, true);
        }
    }
    // Text: a summary line, then one line per pair with its IPC type.
    let (code, out, _) = dhcd(&["proximity", pc.to_str().unwrap(), "--distance", "0.05"]);
    assert_eq!(code, 0);
    let want = brute_force_self_proximity(&crumpled, 0.05);
    assert_eq!(out.lines().count(), 1 + want.counters.contacts as usize);
    assert!(out
        .lines()
        .skip(1)
        .all(|l| l.starts_with("vf ") || l.starts_with("ee ")));
}

/// Grids `1e-9` apart at `z = 1000` (an f32 ulp there is 6e-5): read as `f64` they are
/// apart at `d = 5e-10` and within at `1e-9`; read as `f32` they coincide.
#[test]
fn precision_f64_reads_and_decides_the_f64_values() {
    let g = grid(3, 3, 0.5, [0.0, 0.0, 1000.0]);
    let pa: Vec<[f64; 3]> = g.positions().iter().map(|p| p.map(f64::from)).collect();
    let pb: Vec<[f64; 3]> = pa.iter().map(|p| [p[0], p[1], p[2] + 1e-9]).collect();
    let (fa, fb) = (
        write_f64("ga.obj", &pa, g.triangles()),
        write_f64("gb.obj", &pb, g.triangles()),
    );
    let run = |precision: &str, d: &str| {
        let (code, out, err) = dhcd(&[
            "proximity",
            fa.to_str().unwrap(),
            fb.to_str().unwrap(),
            "--distance",
            d,
            "--precision",
            precision,
            "--json",
        ]);
        assert_eq!(code, 0, "{err}");
        let v = json(&out);
        assert_eq!(v["precision"], precision);
        v["counters"]["contacts"].as_u64().unwrap()
    };
    assert_eq!(run("f64", "5e-10"), 0);
    assert!(run("f64", "1e-9") > 0);
    assert!(run("f32", "5e-10") > 0, "f32 roundings coincide");
    // Every command that reads meshes takes it and reports it.
    for cmd in [
        &["self", fa.to_str().unwrap()][..],
        &["collide", fa.to_str().unwrap(), fb.to_str().unwrap()],
    ] {
        let mut args = cmd.to_vec();
        args.extend(["--precision", "f64", "--json"]);
        let (code, out, err) = dhcd(&args);
        assert_eq!(code, 0, "{err}");
        assert_eq!(json(&out)["precision"], "f64");
    }
    let (code, _, err) = dhcd(&["self", fa.to_str().unwrap(), "--precision", "f16"]);
    assert_eq!(code, 2);
    assert!(err.contains("f16") && err.lines().count() == 1, "{err}");
}

#[test]
fn bad_distances_are_one_line_errors() {
    let m = write("ball.obj", &icosphere(1, 1.0, [0.0; 3]));
    for d in ["-1", "NaN", "inf"] {
        let arg = format!("--distance={d}");
        let (code, out, err) = dhcd(&["proximity", m.to_str().unwrap(), &arg]);
        assert_eq!(code, 1, "{d}: {out}");
        assert!(out.is_empty());
        assert_eq!(err.lines().count(), 1, "{err}");
        assert!(err.contains("distance"), "{err}");
    }
    let (code, _, err) = dhcd(&["proximity", m.to_str().unwrap()]);
    assert_eq!(code, 2, "--distance is required: {err}");
    let (code, _, err) = dhcd(&["bench", "proximity", m.to_str().unwrap()]);
    assert_eq!(code, 2, "--distance or --relative is required: {err}");
    let (code, _, err) = dhcd(&["bench", "proximity", m.to_str().unwrap(), "--relative=-0.5"]);
    assert_eq!(code, 1, "{err}");
    assert!(err.contains("--relative"), "{err}");
}

#[test]
fn bench_proximity_reports_pairs_distance_and_precision() {
    let s = icosphere(2, 1.0, [0.0; 3]);
    let f0 = write(
        "p0.obj",
        &Mesh::new(
            wave(s.positions(), 0.0, 0.4, [0.0; 3]),
            s.triangles().to_vec(),
        )
        .unwrap(),
    );
    let f1 = write(
        "p1.obj",
        &Mesh::new(
            wave(s.positions(), 0.7, 0.4, [0.0; 3]),
            s.triangles().to_vec(),
        )
        .unwrap(),
    );
    let (code, out, err) = dhcd(&[
        "bench",
        "proximity",
        f0.to_str().unwrap(),
        f1.to_str().unwrap(),
        "--relative",
        "0.1",
        "--precision",
        "f64",
        "--method",
        "all",
        "--repeat",
        "2",
        "--json",
    ]);
    assert_eq!(code, 0, "{err}");
    let runs = json(&out);
    let runs = runs.as_array().unwrap();
    assert_eq!(runs.len(), 3);
    let d = runs[0]["distance"].as_f64().unwrap();
    // The waved ball's box: about 2 x 2 x 2 plus the wave.
    assert!((0.3..0.5).contains(&d), "0.1 x the diagonal: {d}");
    for r in runs {
        assert_eq!(r["precision"], "f64");
        assert_eq!(r["distance"].as_f64(), Some(d));
        for (k, f) in r["frames"].as_array().unwrap().iter().enumerate() {
            assert_eq!(
                f["contacts"], runs[0]["frames"][k]["contacts"],
                "methods agree"
            );
            assert!(f["contacts"].as_u64().unwrap() > 0);
        }
    }
}

/// The red team's findings on the command line: a negative distance is a value (not an
/// unknown flag) and is refused by name; numbers are echoed in short form; a relative
/// distance that overflows says so; a vertex no face uses is a point.
#[test]
fn negative_and_overflowing_distances_and_free_points() {
    let m = Mesh::new(
        vec![
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [0.25, 0.25, 0.5],
        ],
        vec![[0, 1, 2]],
    )
    .unwrap();
    let path = write("free_point.obj", &m);
    let p = path.to_str().unwrap();
    let (code, _, err) = dhcd(&["proximity", p, "--distance", "-1"]);
    assert_ne!(code, 0);
    assert!(
        err.contains("distance -1.0 is not a finite number >= 0"),
        "{err}"
    );
    let (code, _, err) = dhcd(&["proximity", p, "--distance", "-1e-300"]);
    assert_ne!(code, 0);
    assert!(err.contains("-1e-300") && err.len() < 200, "{err}");
    let (code, _, err) = dhcd(&["bench", "proximity", p, "--relative", "1.7e308"]);
    assert_ne!(code, 0);
    assert!(err.contains("overflows"), "{err}");
    let (code, out, err) = dhcd(&["proximity", p, "--distance", "1", "--json"]);
    assert_eq!(code, 0, "{err}");
    let v = json(&out);
    assert_eq!(v["vertex_face"][0][0], 3);
    assert_eq!(v["vertex_face"][0][1], 0);
    assert_eq!(v["vertex_face"][0][3], "P_T");
    // Whole-file errors cite no line 0.
    let empty = dir().join("empty.obj");
    std::fs::write(&empty, "# nothing\n").unwrap();
    let (code, _, err) = dhcd(&["proximity", empty.to_str().unwrap(), "--distance", "1"]);
    assert_ne!(code, 0);
    assert!(!err.contains(":0:"), "{err}");
}
