//! The `dhcd` binary's `self` and `scene` commands (JSON output, errors).

use std::path::PathBuf;

use dhcd::narrow::{brute_force_pairs, brute_force_self_pairs};
use dhcd::shapes::{icosphere, wave};
use dhcd::Mesh;

use crate::support::{self, dhcd, json};

/// Writes `mesh` as `name` in this suite's directory.
fn write_obj(name: &str, mesh: &Mesh) -> PathBuf {
    // A static is never dropped: the suite's directory stays.
    static DIR: std::sync::OnceLock<support::TempDir> = std::sync::OnceLock::new();
    let path = DIR
        .get_or_init(|| support::temp_dir("self-scene-cli"))
        .join(name);
    support::write_obj(mesh, &path);
    path
}

/// An icosphere waved at phase `t` by `amplitude`, moved by `offset`.
fn waved_sphere(t: f32, amplitude: f32, offset: [f32; 3]) -> Mesh {
    let s = icosphere(2, 1.0, [0.0; 3]);
    Mesh::new(
        wave(s.positions(), t, amplitude, offset),
        s.triangles().to_vec(),
    )
    .unwrap()
}

#[test]
fn self_json_equals_brute_force() {
    let crumpled = waved_sphere(1.0, 0.6, [0.0; 3]);
    let path = write_obj("crumpled.obj", &crumpled);
    let expected = brute_force_self_pairs(&crumpled);
    assert!(!expected.is_empty());
    for method in dhcd::Method::ALL.map(|m| m.name()) {
        let (code, out, err) = dhcd(&[
            "self",
            path.to_str().unwrap(),
            "--method",
            method,
            "--levels",
            "4",
            "--json",
        ]);
        assert_eq!(code, 0, "{err}");
        let v = json(&out);
        let keys: Vec<&str> = v.as_object().unwrap().keys().map(|k| k.as_str()).collect();
        assert_eq!(
            keys,
            [
                "method",
                "precision",
                "levels",
                "bytes_per_node",
                "pairs",
                "counters"
            ]
        );
        assert_eq!(v["method"], method);
        assert_eq!(v["levels"], 4);
        let pairs: Vec<[u32; 2]> = serde_json::from_value(v["pairs"].clone()).unwrap();
        assert_eq!(pairs, expected);
        assert_eq!(v["counters"]["contacts"], expected.len() as u64);
    }
    let (code, out, _) = dhcd(&["self", path.to_str().unwrap()]);
    assert_eq!(code, 0);
    assert!(out.starts_with(&format!("{} self-contacts", expected.len())));
}

#[test]
fn central_vertex_choices_find_the_same_contacts() {
    let crumpled = waved_sphere(1.0, 0.6, [0.0; 3]);
    let other = waved_sphere(0.3, 0.2, [1.1, 0.2, 0.0]);
    let (pa, pb) = (
        write_obj("central-a.obj", &crumpled),
        write_obj("central-b.obj", &other),
    );
    let (pa, pb) = (pa.to_str().unwrap(), pb.to_str().unwrap());
    let own = brute_force_self_pairs(&crumpled);
    let cross = brute_force_pairs(&crumpled, &other);
    assert!(!own.is_empty() && !cross.is_empty());
    for central in ["rest-centroid", "min-radius"] {
        for method in ["dh", "aabb"] {
            for (args, expected) in [(vec!["self", pa], &own), (vec!["collide", pa, pb], &cross)] {
                let mut args = args.clone();
                args.extend(["--method", method, "--central", central, "--json"]);
                let (code, out, err) = dhcd(&args);
                assert_eq!(code, 0, "{args:?}: {err}");
                let pairs: Vec<[u32; 2]> =
                    serde_json::from_value(json(&out)["pairs"].clone()).unwrap();
                assert_eq!(&pairs, expected, "{args:?}");
            }
        }
    }
    // `scene` takes the same flag: the same contacts either way.
    let scene: Vec<serde_json::Value> = ["rest-centroid", "min-radius"]
        .map(|central| {
            let (code, out, err) = dhcd(&["scene", pa, pb, "--central", central, "--json"]);
            assert_eq!(code, 0, "{err}");
            json(&out)["pairs"].clone()
        })
        .into();
    assert_eq!(scene[0], scene[1]);
    assert_eq!(scene[0].as_array().unwrap().len(), cross.len());
    let (code, out, err) = dhcd(&["self", pa, "--central", "middle"]);
    assert_ne!(code, 0);
    assert!(out.is_empty());
    assert_eq!(err.lines().count(), 1, "{err}");
    assert!(
        err.contains("middle") && err.contains("min-radius"),
        "{err}"
    );
}

#[test]
fn scene_json_equals_brute_force() {
    let a = icosphere(2, 1.0, [0.0; 3]);
    let b = Mesh::new(
        wave(a.positions(), 0.5, 0.2, [1.3, 0.0, 0.0]),
        a.triangles().to_vec(),
    )
    .unwrap();
    let c = Mesh::new(
        wave(a.positions(), 0.5, 0.2, [0.0, 1.5, 0.2]),
        a.triangles().to_vec(),
    )
    .unwrap();
    let paths: Vec<String> = [("a.obj", &a), ("b.obj", &b), ("c.obj", &c)]
        .iter()
        .map(|(n, m)| write_obj(n, m).to_str().unwrap().to_owned())
        .collect();
    let meshes = [&a, &b, &c];
    let mut expected = Vec::new();
    for i in 0..3 {
        for j in i + 1..3 {
            for [x, y] in brute_force_pairs(meshes[i], meshes[j]) {
                expected.push([i as u64, x as u64, j as u64, y as u64]);
            }
        }
    }
    expected.sort_unstable();
    assert!(expected.iter().any(|p| p[0] == 0 && p[2] == 2));
    let mut args = vec!["scene"];
    args.extend(paths.iter().map(String::as_str));
    args.extend(["--method", "aabb", "--json"]);
    let (code, out, err) = dhcd(&args);
    assert_eq!(code, 0, "{err}");
    let v = json(&out);
    assert_eq!(v["method"], "aabb");
    assert_eq!(v["bytes_per_node"], 24);
    let pairs: Vec<[u64; 4]> = serde_json::from_value(v["pairs"].clone()).unwrap();
    assert_eq!(pairs, expected);
    assert_eq!(v["counters"]["contacts"], expected.len() as u64);
    // Threads do not change the output.
    args.extend(["--threads", "2"]);
    assert_eq!(dhcd(&args).1, out);
}

#[test]
fn errors_are_one_line_and_non_zero() {
    let bad = std::env::temp_dir().join("dhcd-cli-missing-file.obj");
    for args in [
        vec!["self", bad.to_str().unwrap()],
        vec!["scene", bad.to_str().unwrap()],
        vec!["self", bad.to_str().unwrap(), "--levels", "0"],
    ] {
        let (code, out, err) = dhcd(&args);
        assert_ne!(code, 0);
        assert!(out.is_empty());
        assert_eq!(err.lines().count(), 1, "{err}");
        assert!(err.starts_with("dhcd: error:"), "{err}");
        assert!(!err.contains("panicked"));
    }
    let m = icosphere(0, 1.0, [0.0; 3]);
    let p = write_obj("ok.obj", &m);
    let (code, _, err) = dhcd(&["self", p.to_str().unwrap(), "--levels", "0"]);
    assert_ne!(code, 0);
    assert!(err.contains("levels"), "{err}");
    let (code, _, _) = dhcd(&["scene"]);
    assert_ne!(code, 0, "scene needs at least one mesh");
}
