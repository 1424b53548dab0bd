//! `dhcd bench`: the microbenchmark users run on their own frames. Its contacts per frame
//! are the ones `dhcd self` / `dhcd collide` find on each frame alone (the tree is built on
//! the first frame and refitted, never rebuilt), for every method and thread count; bad
//! input is one error line.

use std::path::{Path, PathBuf};

use dhcd::shapes::{grid, icosphere, wave};
use dhcd::Mesh;
use serde_json::Value;

use crate::support::{run_dhcd as dhcd, temp_dir, write_obj};

/// Frames of one mesh of two sheets, a waving one and a vertical one sliding through it: the
/// sheets cross in some frames and not in others.
fn crossing_sheets(dir: &Path, frames: usize) -> Vec<PathBuf> {
    let flat = grid(16, 16, 0.1, [0.0; 3]);
    let n = flat.vertex_count() as u32;
    let mut triangles = flat.triangles().to_vec();
    triangles.extend(flat.triangles().iter().map(|t| t.map(|v| v + n)));
    (0..frames)
        .map(|k| {
            let mut positions = wave(flat.positions(), k as f32, 0.05, [0.0; 3]);
            // The second sheet stands in the plane x = const, moving along x.
            let x = 0.5 + 0.9 * k as f32;
            positions.extend(flat.positions().iter().map(|p| [x, p[0] - 0.2, p[1] - 0.8]));
            let pose = Mesh::new(positions, triangles.clone()).unwrap();
            let path = dir.join(format!("sheets-{k}.obj"));
            write_obj(&pose, &path);
            path
        })
        .collect()
}

/// Frames of a sphere moving through another.
fn passing_sphere(dir: &Path, frames: usize) -> (Vec<PathBuf>, PathBuf) {
    let fixed = icosphere(2, 1.0, [0.0; 3]);
    let fixed_path = dir.join("fixed.obj");
    write_obj(&fixed, &fixed_path);
    let moving = (0..frames)
        .map(|k| {
            let m = icosphere(2, 0.6, [2.0 - 0.8 * k as f32, 0.1, 0.0]);
            let path = dir.join(format!("moving-{k}.obj"));
            write_obj(&m, &path);
            path
        })
        .collect();
    (moving, fixed_path)
}

fn strs(paths: &[PathBuf]) -> Vec<&str> {
    paths.iter().map(|p| p.to_str().unwrap()).collect()
}

/// The arguments of a self bench of three crossing-sheet frames and of a collide bench of
/// a sphere passing a fixed mesh in three frames (no options), and the first sheet frame.
fn self_and_collide_benches(dir: &Path) -> (String, [Vec<String>; 2]) {
    let frames = crossing_sheets(dir, 3);
    let (moving, fixed) = passing_sphere(dir, 3);
    let owned = |args: &[&str]| args.iter().map(|a| a.to_string()).collect::<Vec<_>>();
    let mut self_bench = owned(&["bench", "self"]);
    self_bench.extend(owned(&strs(&frames)));
    let mut collide_bench = owned(&["bench", "collide", "--a"]);
    collide_bench.extend(owned(&strs(&moving)));
    collide_bench.extend(owned(&["--b", fixed.to_str().unwrap()]));
    (self_bench[2].clone(), [self_bench, collide_bench])
}

fn json_of(args: &[&str]) -> Value {
    let out = dhcd(args);
    assert!(
        out.status.success(),
        "{args:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    serde_json::from_slice(&out.stdout).unwrap()
}

/// Contacts of `dhcd self|collide ... --json` on one frame.
fn contacts_alone(args: &[&str]) -> u64 {
    json_of(args)["counters"]["contacts"].as_u64().unwrap()
}

/// Checks one bench result's shape and returns its contacts per frame.
fn frame_contacts(run: &Value, method: &str, threads: u64, frames: usize) -> Vec<u64> {
    assert_eq!(run["method"], method, "{run}");
    assert_eq!(run["threads"], threads, "{run}");
    assert!(run["build_ms"].as_f64().unwrap() >= 0.0, "{run}");
    let (median, min) = (
        run["step_ms"]["median"].as_f64().unwrap(),
        run["step_ms"]["min"].as_f64().unwrap(),
    );
    assert!(0.0 <= min && min <= median, "{run}");
    let list = run["frames"].as_array().unwrap();
    assert_eq!(list.len(), frames, "{run}");
    // Every step is some frame's: the overall least is the least frame's least, and each
    // frame's least is at most its median.
    let mut least = f64::INFINITY;
    let contacts = list
        .iter()
        .map(|f| {
            let contacts = f["contacts"].as_u64().unwrap();
            assert_eq!(f["counters"]["contacts"].as_u64(), Some(contacts), "{run}");
            assert!(f["counters"]["bv_tests"].as_u64().unwrap() > 0, "{run}");
            let (fmedian, fmin) = (
                f["step_ms"]["median"].as_f64().unwrap(),
                f["step_ms"]["min"].as_f64().unwrap(),
            );
            assert!(0.0 <= fmin && fmin <= fmedian, "{run}");
            least = least.min(fmin);
            contacts
        })
        .collect();
    assert_eq!(least, min, "{run}");
    contacts
}

#[test]
fn self_bench_finds_each_frames_contacts_with_every_method_and_thread_count() {
    let dir = temp_dir("bench-self");
    let frames = crossing_sheets(&dir, 3);
    let expected: Vec<u64> = frames
        .iter()
        .map(|f| contacts_alone(&["self", f.to_str().unwrap(), "--json"]))
        .collect();
    assert!(
        expected.iter().any(|&c| c > 0) && expected.contains(&0),
        "the sheets must cross in some frames only: {expected:?}"
    );
    for threads in ["1", "2"] {
        let mut args = vec!["bench", "self"];
        args.extend(strs(&frames));
        args.extend([
            "--method",
            "all",
            "--repeat",
            "2",
            "--json",
            "--threads",
            threads,
        ]);
        let runs = json_of(&args);
        let runs = runs.as_array().unwrap();
        let used = dhcd::Par::threads(threads.parse().unwrap())
            .unwrap()
            .thread_count() as u64;
        for (run, method) in runs.iter().zip(["dh", "sphere", "aabb"]) {
            assert_eq!(frame_contacts(run, method, used, 3), expected, "{method}");
        }
        assert_eq!(runs.len(), 3);
    }
    // The DH central vertex changes the work, never the contacts.
    let mut args = vec!["bench", "self"];
    args.extend(strs(&frames));
    args.extend(["--central", "min-radius", "--repeat", "1", "--json"]);
    assert_eq!(frame_contacts(&json_of(&args), "dh", 1, 3), expected);
}

#[test]
fn collide_bench_finds_each_frames_contacts_and_cycles_the_shorter_list() {
    let dir = temp_dir("bench-collide");
    let (moving, fixed) = passing_sphere(&dir, 4);
    let fixed = fixed.to_str().unwrap();
    let expected: Vec<u64> = moving
        .iter()
        .map(|m| contacts_alone(&["collide", m.to_str().unwrap(), fixed, "--json"]))
        .collect();
    assert!(
        expected.iter().any(|&c| c > 0) && expected.contains(&0),
        "{expected:?}"
    );
    let mut args = vec!["bench", "collide", "--a"];
    args.extend(strs(&moving));
    args.extend(["--b", fixed, "--method", "aabb", "--json", "--repeat", "1"]);
    let run = json_of(&args);
    assert_eq!(frame_contacts(&run, "aabb", 1, 4), expected);
}

/// `--broad-only` times the query without its triangle tests: the same node tests, refits
/// and counted triangle pairs as the full step, no contacts; for self and two-object benches.
#[test]
fn broad_only_counts_what_the_full_step_counts_without_contacts() {
    let dir = temp_dir("bench-broad");
    let (first_frame, benches) = self_and_collide_benches(&dir);
    for base in &benches {
        let base: Vec<&str> = base.iter().map(String::as_str).collect();
        let mut full = base.clone();
        full.extend(["--method", "all", "--repeat", "1", "--json"]);
        let mut broad = full.clone();
        broad.push("--broad-only");
        let (full, broad) = (json_of(&full), json_of(&broad));
        let mut some_contacts = false;
        for (f, b) in full
            .as_array()
            .unwrap()
            .iter()
            .zip(broad.as_array().unwrap())
        {
            assert_eq!(f["broad_only"], false);
            assert_eq!(b["broad_only"], true);
            for (ff, bf) in f["frames"]
                .as_array()
                .unwrap()
                .iter()
                .zip(b["frames"].as_array().unwrap())
            {
                some_contacts |= ff["contacts"].as_u64().unwrap() > 0;
                assert_eq!(bf["contacts"], 0, "{b}");
                for k in ["bv_tests", "prim_tests", "bv_updates"] {
                    assert_eq!(bf["counters"][k], ff["counters"][k], "{k}: {f} {b}");
                }
            }
        }
        assert!(some_contacts, "{full}");
    }
    let out = dhcd(&["bench", "self", &first_frame, "--broad-only"]);
    let text = String::from_utf8(out.stdout).unwrap();
    assert!(text.contains("(broad phase only)"), "{text}");
}

#[test]
fn text_output_names_the_build_and_step_times_and_every_frame() {
    let dir = temp_dir("bench-text");
    let frames = crossing_sheets(&dir, 2);
    let mut args = vec!["bench", "self"];
    args.extend(strs(&frames));
    let out = dhcd(&args);
    assert!(out.status.success());
    let text = String::from_utf8(out.stdout).unwrap();
    assert!(text.contains("dh: build "), "{text}");
    assert!(text.contains("step median "), "{text}");
    assert!(
        text.contains("  step 0: median ") && text.contains("  step 1: median "),
        "{text}"
    );
}

#[test]
fn bad_input_is_one_error_line() {
    let dir = temp_dir("bench-bad");
    let frames = crossing_sheets(&dir, 1);
    let frame = frames[0].to_str().unwrap();
    let other = dir.join("other.obj");
    write_obj(&icosphere(1, 1.0, [0.0; 3]), &other);
    let other = other.to_str().unwrap();
    let missing = dir.join("missing.obj");
    let missing = missing.to_str().unwrap();
    let cases: Vec<(Vec<&str>, &str)> = vec![
        (vec!["bench", "self", frame, other], "not a pose of"),
        (vec!["bench", "self", frame, "--repeat", "0"], "--repeat"),
        (
            vec!["bench", "self", frame, "--repeat", "99999999"],
            "--repeat",
        ),
        (vec!["bench", "self", frame, "--threads", "5000"], "threads"),
        (vec!["bench", "self", frame, "--method", "obb"], "obb"),
        (vec!["bench", "self", frame, "--leaf-size", "0"], "leaf"),
        (vec!["bench", "self", frame, "--central", "mean"], "mean"),
        (vec!["bench", "self", missing], "missing.obj"),
        // Options are checked before any file is read.
        (vec!["bench", "self", missing, "--repeat", "0"], "--repeat"),
        (vec!["bench", "self", missing, "--method", "obb"], "obb"),
        (vec!["bench", "collide", "--a", frame], "--b"),
        (vec!["bench", "self"], "FRAMES"),
        (vec!["bench"], "subcommand"),
    ];
    for (args, needle) in cases {
        let out = dhcd(&args);
        assert!(!out.status.success(), "{args:?} succeeded");
        assert!(out.stdout.is_empty(), "{args:?} printed a report");
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(err.lines().count(), 1, "{args:?}: {err:?}");
        assert!(err.starts_with("dhcd: "), "{args:?}: {err:?}");
        assert!(
            err.to_lowercase().contains(&needle.to_lowercase()),
            "{args:?}: {err:?} should name {needle}"
        );
    }
}
