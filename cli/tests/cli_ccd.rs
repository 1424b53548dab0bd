//! `dhcd ccd` and `dhcd bench ccd`: the JSON equals the brute force over every pair (the
//! exact tests of `dhcd::ccd`) for every method, thread count, mode and minimum distance; bad
//! input is one line on stderr.

use std::path::{Path, PathBuf};

use dhcd::ccd::CcdOptions;
use dhcd::narrow::{brute_force_self_ccd, earliest_of};
use dhcd::shapes::{grid, jitter};
use dhcd::{Impacts, Mesh, Motion};

use crate::fixtures;
use crate::support::{self, dhcd, json};

fn dir() -> &'static Path {
    static DIR: std::sync::OnceLock<support::TempDir> = std::sync::OnceLock::new();
    DIR.get_or_init(|| support::temp_dir("ccd-cli"))
}

fn write_f64(name: &str, positions: &[[f64; 3]], triangles: &[[u32; 3]]) -> PathBuf {
    let path = dir().join(name);
    support::write_obj_f64(&path, positions, triangles);
    path
}

/// A jittered `n` x `n` sheet and its pose after folding over x = 0.45 through its lower
/// half, in f64 (the motion of `tests/ccd_query.rs`'s folding sheet, at `fold` times its
/// depth).
fn folding_sheet(n: u32, fold: f64) -> (Mesh, Vec<[f64; 3]>, Vec<[f64; 3]>) {
    let g = grid(n, n, 0.8 / n as f32, [0.0; 3]);
    let x0: Vec<[f64; 3]> = jitter(g.positions(), [0.002; 3], 5)
        .iter()
        .map(|p| p.map(f64::from))
        .collect();
    let x1 = fixtures::folded_through(&x0, fold);
    (g, x0, x1)
}

/// The JSON's toi and pair lists equal `want`'s, to the bit.
fn check_against(v: &serde_json::Value, want: &Impacts) {
    assert_eq!(v["toi"].as_f64(), want.toi, "toi");
    let rows = |key: &str| v[key].as_array().unwrap().clone();
    let vf = rows("vertex_face");
    assert_eq!(vf.len(), want.vertex_face.len());
    for (r, w) in vf.iter().zip(&want.vertex_face) {
        assert_eq!(r[0], w.vertex);
        assert_eq!(r[1], w.triangle);
        assert_eq!(r[2].as_f64().unwrap(), w.toi);
    }
    let ee = rows("edge_edge");
    assert_eq!(ee.len(), want.edge_edge.len());
    for (r, w) in ee.iter().zip(&want.edge_edge) {
        let got: Vec<u64> = (0..4).map(|k| r[k].as_u64().unwrap()).collect();
        assert_eq!(got, [w.a[0], w.a[1], w.b[0], w.b[1]].map(u64::from));
        assert_eq!(r[4].as_f64().unwrap(), w.toi);
    }
    assert_eq!(
        v["counters"]["contacts"].as_u64().unwrap(),
        want.counters.contacts
    );
}

#[test]
fn ccd_json_equals_brute_force() {
    let (g, x0, x1) = folding_sheet(8, 1.0);
    let t0 = write_f64("fold0.obj", &x0, g.triangles());
    let t1 = write_f64("fold1.obj", &x1, g.triangles());
    let (t0, t1) = (t0.to_str().unwrap(), t1.to_str().unwrap());
    let runs = [(&g, &x0, &x1, t0, t1, 0.0), (&g, &x0, &x1, t0, t1, 0.004)];
    for (mesh, x0, x1, t0, t1, delta) in runs {
        let all = brute_force_self_ccd(
            mesh,
            Motion::new(x0, x1),
            &CcdOptions::new(1.0, delta).unwrap(),
        );
        assert!(
            !all.vertex_face.is_empty() && !all.edge_edge.is_empty(),
            "the fold collides"
        );
        let delta_arg = format!("--min-distance={delta}");
        for method in ["dh", "sphere", "aabb"] {
            for threads in ["1", "2"] {
                for earliest in [false, true] {
                    let mut args = vec![
                        "ccd",
                        t0,
                        t1,
                        "--json",
                        "--method",
                        method,
                        "--threads",
                        threads,
                        &delta_arg,
                    ];
                    if earliest {
                        args.push("--earliest");
                    }
                    let (code, out, err) = dhcd(&args);
                    assert_eq!(code, 0, "{args:?}: {err}");
                    let v = json(&out);
                    assert_eq!(v["method"], method);
                    assert_eq!(v["precision"], "f64");
                    assert_eq!(v["earliest"], earliest);
                    assert_eq!(v["min_distance"].as_f64(), Some(delta));
                    let want = if earliest {
                        earliest_of(&all, all.toi)
                    } else {
                        all.clone()
                    };
                    check_against(&v, &want);
                }
            }
        }
    }
    // A still step: nothing collides, toi is null.
    let (code, out, err) = dhcd(&["ccd", t0, t0, "--json"]);
    assert_eq!(code, 0, "{err}");
    let v = json(&out);
    assert!(v["toi"].is_null(), "{out}");
    assert_eq!(v["vertex_face"].as_array().unwrap().len(), 0);
    assert_eq!(v["edge_edge"].as_array().unwrap().len(), 0);
}

#[test]
fn ccd_text_names_the_counts_and_lists_every_pair() {
    let (g, x0, x1) = folding_sheet(8, 1.0);
    let t0 = write_f64("text0.obj", &x0, g.triangles());
    let t1 = write_f64("text1.obj", &x1, g.triangles());
    let all = brute_force_self_ccd(&g, Motion::new(&x0, &x1), &CcdOptions::default());
    let (code, out, err) = dhcd(&["ccd", t0.to_str().unwrap(), t1.to_str().unwrap()]);
    assert_eq!(code, 0, "{err}");
    let mut lines = out.lines();
    let summary = lines.next().unwrap();
    assert!(
        summary.starts_with(&format!(
            "{} vertex-face and {} edge-edge pairs collide",
            all.vertex_face.len(),
            all.edge_edge.len()
        )),
        "{summary}"
    );
    let rest: Vec<&str> = lines.collect();
    assert_eq!(
        rest.iter().filter(|l| l.starts_with("vf ")).count(),
        all.vertex_face.len()
    );
    assert_eq!(
        rest.iter().filter(|l| l.starts_with("ee ")).count(),
        all.edge_edge.len()
    );
}

#[test]
fn ccd_bad_input_is_one_line() {
    let (g, x0, x1) = folding_sheet(8, 1.0);
    let t0 = write_f64("bad0.obj", &x0, g.triangles());
    let t1 = write_f64("bad1.obj", &x1, g.triangles());
    // The end pose of another mesh: one triangle fewer.
    let other = write_f64("other.obj", &x1, &g.triangles()[1..]);
    let nan = dir().join("nan.obj");
    std::fs::write(&nan, "v 0 0 0\nv 1 0 0\nv NaN 1 0\nf 1 2 3\n").unwrap();
    let (t0, t1) = (t0.to_str().unwrap(), t1.to_str().unwrap());
    let missing = dir().join("missing.obj");
    let cases: Vec<(Vec<&str>, &str)> = vec![
        (vec!["ccd", t0, other.to_str().unwrap()], "not a pose"),
        (vec!["ccd", t0, t1, "--min-distance=-1"], "distance"),
        (vec!["ccd", t0, t1, "--min-distance=NaN"], "distance"),
        (vec!["ccd", t0, missing.to_str().unwrap()], "missing.obj"),
        (vec!["ccd", nan.to_str().unwrap(), t1], "nan.obj"),
        (
            vec!["bench", "ccd", t0, other.to_str().unwrap()],
            "not a pose",
        ),
        (vec!["bench", "ccd", t0, t1, "--precision", "f32"], "f64"),
        (vec!["bench", "ccd", t0, t1, "--broad-only"], "broad-only"),
    ];
    for (args, needle) in cases {
        let (code, out, err) = dhcd(&args);
        assert_ne!(code, 0, "{args:?}");
        assert!(out.is_empty(), "{args:?}: {out}");
        assert_eq!(err.lines().count(), 1, "{args:?}: {err}");
        assert!(err.contains(needle), "{args:?}: {err}");
    }
}

#[test]
fn bench_ccd_counts_each_steps_pairs() {
    // Three poses: halfway folded, folded, and back to halfway: two steps.
    let (g, _, half) = folding_sheet(8, 0.5);
    let (_, _, full) = folding_sheet(8, 1.0);
    let poses = [&half, &full, &half];
    let paths: Vec<PathBuf> = poses
        .iter()
        .enumerate()
        .map(|(k, x)| write_f64(&format!("step{k}.obj"), x, g.triangles()))
        .collect();
    let want: Vec<Impacts> = (0..2)
        .map(|k| {
            brute_force_self_ccd(
                &g,
                Motion::new(poses[k], poses[k + 1]),
                &CcdOptions::default(),
            )
        })
        .collect();
    assert!(want.iter().all(|w| w.counters.contacts > 0));
    let p: Vec<&str> = paths.iter().map(|p| p.to_str().unwrap()).collect();
    for earliest in [false, true] {
        let mut args = vec![
            "bench",
            "ccd",
            p[0],
            p[1],
            p[2],
            "--method",
            "all",
            "--repeat",
            "2",
            "--threads",
            "2",
            "--json",
        ];
        if earliest {
            args.push("--earliest");
        }
        let (code, out, err) = dhcd(&args);
        assert_eq!(code, 0, "{err}");
        let runs = json(&out);
        let runs = runs.as_array().unwrap();
        assert_eq!(runs.len(), 3, "one run per method");
        for r in runs {
            assert_eq!(r["precision"], "f64");
            assert_eq!(r["earliest"], earliest);
            assert_eq!(r["min_distance"].as_f64(), Some(0.0));
            assert!(r["step_ms"]["min"].as_f64().unwrap() > 0.0);
            let frames = r["frames"].as_array().unwrap();
            assert_eq!(frames.len(), 2, "steps between consecutive frames");
            for (f, w) in frames.iter().zip(&want) {
                let w = if earliest {
                    earliest_of(w, w.toi)
                } else {
                    w.clone()
                };
                assert_eq!(f["contacts"].as_u64().unwrap(), w.counters.contacts);
            }
        }
    }
}
