//! `dhcd collide` end to end: files in, JSON out, equal to the exact oracle; bad input is a
//! one-line error with a non-zero exit.

use std::process::Command;

use dhcd::narrow::brute_force_pairs;
use dhcd::shapes::{icosphere, wave};
use dhcd::Mesh;

use crate::support::{run_dhcd as dhcd, temp_dir, write_obj as write};

#[test]
fn collide_json_equals_brute_force_for_every_method() {
    let dir = temp_dir("collide-json");
    let a = icosphere(2, 1.0, [0.0; 3]);
    let b0 = icosphere(2, 0.9, [0.0; 3]);
    let b = Mesh::new(
        wave(b0.positions(), 0.7, 0.1, [1.2, 0.3, 0.1]),
        b0.triangles().to_vec(),
    )
    .unwrap();
    let (pa, pb) = (dir.join("a.obj"), dir.join("b.obj"));
    write(&a, &pa);
    write(&b, &pb);
    let expected = brute_force_pairs(&a, &b);
    assert!(!expected.is_empty());
    for m in dhcd::Method::ALL {
        let (method, bytes) = (m.name(), m.bytes_per_node());
        for levels in ["1", "5"] {
            let out = dhcd(&[
                "collide",
                pa.to_str().unwrap(),
                pb.to_str().unwrap(),
                "--method",
                method,
                "--levels",
                levels,
                "--json",
            ]);
            assert!(
                out.status.success(),
                "{}",
                String::from_utf8_lossy(&out.stderr)
            );
            let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
            assert_eq!(v["method"], method);
            // The depth of the built trees: at most the requested fixed depth.
            let built = v["levels"].as_u64().unwrap();
            assert!(
                (1..=levels.parse::<u64>().unwrap()).contains(&built),
                "{built}"
            );
            assert_eq!(v["bytes_per_node"], bytes);
            let pairs: Vec<[u32; 2]> = serde_json::from_value(v["pairs"].clone()).unwrap();
            assert_eq!(pairs, expected, "{method} levels {levels}");
            let c = &v["counters"];
            assert_eq!(c["contacts"], expected.len() as u64);
            assert!(c["bv_tests"].as_u64().unwrap() >= 1);
            assert!(c["prim_tests"].as_u64().unwrap() >= expected.len() as u64);
            assert!(c["bv_updates"].is_u64());
        }
    }
    std::fs::remove_dir_all(dir).ok();
}

#[test]
fn collide_reports_bad_input_in_one_line() {
    let dir = temp_dir("collide-bad");
    let good = dir.join("good.obj");
    write(&icosphere(0, 1.0, [0.0; 3]), &good);
    let cases: Vec<(&str, &str)> = vec![
        ("oob.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 4\n"),
        ("nan.obj", "v 0 0 nan\nv 1 0 0\nv 0 1 0\nf 1 2 3\n"),
        ("empty.obj", ""),
        ("repeat.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 2\n"),
        ("short.obj", "v 0 0 0\nv 1 0 0\nf 1 2\n"),
        (
            "junk.stl",
            "solid x\nfacet normal 0 0 1\nouter loop\nvertex 0 0\n",
        ),
        ("junk.ply", "ply\nformat ascii 1.0\nelement vertex 3\n"),
    ];
    for (name, text) in cases {
        let p = dir.join(name);
        std::fs::write(&p, text).unwrap();
        for args in [
            [good.to_str().unwrap(), p.to_str().unwrap()],
            [p.to_str().unwrap(), good.to_str().unwrap()],
        ] {
            let out = dhcd(&["collide", args[0], args[1], "--json"]);
            let err = String::from_utf8_lossy(&out.stderr);
            assert_eq!(out.status.code(), Some(1), "{name}: {err}");
            assert!(out.stdout.is_empty(), "{name}");
            assert_eq!(err.trim_end().lines().count(), 1, "{name}: {err}");
            assert!(
                err.starts_with("dhcd: error:") && err.contains(name),
                "{name}: {err}"
            );
            assert!(!err.contains("panicked"));
        }
    }
    let missing = dhcd(&["collide", good.to_str().unwrap(), "/nonexistent/x.obj"]);
    assert_eq!(missing.status.code(), Some(1));
    let bad_levels = dhcd(&[
        "collide",
        good.to_str().unwrap(),
        good.to_str().unwrap(),
        "--levels",
        "0",
    ]);
    assert_eq!(bad_levels.status.code(), Some(1));
    let bad_method = dhcd(&[
        "collide",
        good.to_str().unwrap(),
        good.to_str().unwrap(),
        "--method",
        "obb",
    ]);
    assert_eq!(bad_method.status.code(), Some(2));
    std::fs::remove_dir_all(dir).ok();
}

#[test]
fn closed_stdout_is_not_a_panic() {
    // A reader that stops early (`dhcd collide a b | head`) closes the pipe while dhcd is
    // still writing: dhcd must end quietly, not panic in `println!`.
    let dir = temp_dir("collide-pipe");
    let a = icosphere(3, 1.0, [0.0; 3]);
    let pa = dir.join("a.obj");
    write(&a, &pa);
    for json in [true, false] {
        let mut cmd = Command::new(env!("CARGO_BIN_EXE_dhcd"));
        cmd.args(["collide", pa.to_str().unwrap(), pa.to_str().unwrap()]);
        if json {
            cmd.arg("--json");
        }
        let mut child = cmd
            .stdout(std::process::Stdio::piped())
            .stderr(std::process::Stdio::piped())
            .spawn()
            .unwrap();
        drop(child.stdout.take()); // the reader goes away before reading anything
        let out = child.wait_with_output().unwrap();
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(!err.contains("panicked"), "{err}");
        assert_eq!(out.status.code(), Some(0), "{err}");
    }
    std::fs::remove_dir_all(dir).ok();
}
