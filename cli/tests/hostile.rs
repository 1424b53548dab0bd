//! The command line under hostile input (issue 9): thread counts, files that never end,
//! reports of millions of contacts in bounded memory with the same bytes as before, and
//! usage errors on one line that name what is wrong.

use std::path::{Path, PathBuf};

use dhcd::shapes::{icosphere, wave};
use dhcd::{Counters, Mesh};
use serde_json::json;

use crate::support::{run_dhcd as dhcd, temp_dir, write_obj};

/// Exit code and the lines of stderr.
fn failure(args: &[&str]) -> (Option<i32>, String) {
    let out = dhcd(args);
    assert!(out.stdout.is_empty(), "{args:?} printed a report");
    (
        out.status.code(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

/// `stderr` is exactly one printable `dhcd: error:` line.
fn assert_one_error_line(stderr: &str, what: &str) {
    let line = stderr
        .strip_suffix('\n')
        .unwrap_or_else(|| panic!("{what}: {stderr:?}"));
    assert!(line.starts_with("dhcd: error: "), "{what}: {stderr:?}");
    assert!(!line.chars().any(char::is_control), "{what}: {stderr:?}");
}

fn two_balls(dir: &Path) -> (PathBuf, PathBuf) {
    let a = icosphere(2, 1.0, [0.0; 3]);
    let b = Mesh::new(
        wave(a.positions(), 0.5, 0.2, [1.3, 0.0, 0.0]),
        a.triangles().to_vec(),
    )
    .unwrap();
    let (pa, pb) = (dir.join("a.obj"), dir.join("b.obj"));
    write_obj(&a, &pa);
    write_obj(&b, &pb);
    (pa, pb)
}

// ---------------------------------------------------------------------------------------------
// Threads
// ---------------------------------------------------------------------------------------------

#[test]
fn out_of_range_thread_counts_are_one_line_errors() {
    let dir = temp_dir("hostile-threads");
    let (a, _) = two_balls(&dir);
    let a = a.to_str().unwrap();
    for threads in ["16384", "4294967295", "1025"] {
        for args in [
            vec!["scene", a, a, "--threads", threads],
            vec!["experiment", "--frames", "1", "--threads", threads],
        ] {
            let (code, err) = failure(&args);
            assert_eq!(code, Some(1), "{args:?}: {err}");
            assert_one_error_line(&err, threads);
            assert!(err.contains(&format!("thread count {threads} is out of range")));
        }
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// `--threads 4096` took 10 s for 4 triangles and `experiment --threads 1024` 42 s (a pool
/// of that many spinning workers); now the count used is at most the machine's.
#[test]
fn large_accepted_thread_counts_use_at_most_the_machines_threads() {
    let dir = temp_dir("hostile-many-threads");
    let (a, b) = two_balls(&dir);
    let (a, b) = (a.to_str().unwrap(), b.to_str().unwrap());
    let one = dhcd(&["scene", a, b, "--json"]);
    assert!(one.status.success());
    let many = dhcd(&["scene", a, b, "--json", "--threads", "1024"]);
    assert!(many.status.success());
    assert_eq!(many.stdout, one.stdout);
    let out_dir = dir.join("experiment");
    let out = dhcd(&[
        "experiment",
        "--frames",
        "2",
        "--threads",
        "1024",
        "--quiet",
        "--out",
        out_dir.to_str().unwrap(),
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let report: serde_json::Value =
        serde_json::from_slice(&std::fs::read(out_dir.join("report.json")).unwrap()).unwrap();
    let used = report["scene"]["threads"].as_u64().unwrap() as usize;
    assert!(used >= 1 && used <= dhcd::Par::max_threads(), "{used}");
    let _ = std::fs::remove_dir_all(&dir);
}

// ---------------------------------------------------------------------------------------------
// Files
// ---------------------------------------------------------------------------------------------

/// `/dev/zero` was read until memory ran out and a FIFO without a writer blocked forever.
#[cfg(unix)]
#[test]
fn files_that_never_end_are_refused() {
    let dir = temp_dir("hostile-files");
    let (good, _) = two_balls(&dir);
    let good = good.to_str().unwrap();
    let fifo = dir.join("fifo.obj");
    assert!(std::process::Command::new("mkfifo")
        .arg(&fifo)
        .status()
        .is_ok_and(|s| s.success()));
    let link = dir.join("link.stl");
    std::os::unix::fs::symlink("/dev/urandom", &link).unwrap();
    for bad in [
        "/dev/zero",
        "/dev/urandom",
        fifo.to_str().unwrap(),
        link.to_str().unwrap(),
    ] {
        for args in [
            vec!["collide", bad, good],
            vec!["self", bad],
            vec!["scene", good, bad],
            vec!["experiment", "--mesh", bad],
        ] {
            let out = crate::support::run_dhcd_bounded(&args, 256 << 10);
            let err = String::from_utf8_lossy(&out.stderr);
            assert_eq!(out.status.code(), Some(1), "{args:?}: {err}");
            assert_one_error_line(&err, bad);
            assert!(err.contains("not a regular file"), "{args:?}: {err}");
        }
    }
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn the_file_size_limit_is_an_option() {
    let dir = temp_dir("hostile-size");
    let (a, b) = two_balls(&dir);
    let (a, b) = (a.to_str().unwrap(), b.to_str().unwrap());
    let (code, err) = failure(&["collide", a, b, "--max-file-bytes", "100"]);
    assert_eq!(code, Some(1));
    assert_one_error_line(&err, "limit");
    assert!(
        err.contains("larger than the limit of 100 bytes") && err.contains("--max-file-bytes"),
        "{err}"
    );
    let big_enough = std::fs::metadata(a).unwrap().len().to_string();
    let out = dhcd(&["self", a, "--max-file-bytes", &big_enough]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_mesh_too_large_for_the_experiments_layout_is_not_called_non_finite() {
    let dir = temp_dir("hostile-layout");
    let path = dir.join("huge.obj");
    std::fs::write(
        &path,
        "v -3e38 0 0\nv 3e38 0 0\nv 0 1 0\nv 0 0 1\nf 1 2 3\nf 1 2 4\nf 1 3 4\nf 2 3 4\n",
    )
    .unwrap();
    let (code, err) = failure(&[
        "experiment",
        "--frames",
        "1",
        "--mesh",
        path.to_str().unwrap(),
    ]);
    assert_eq!(code, Some(1));
    assert_one_error_line(&err, "layout");
    assert!(
        err.contains("too large for the experiment's scene") && err.contains("finite"),
        "{err}"
    );
    assert!(!err.contains("has a non-finite coordinate"), "{err}");
    let _ = std::fs::remove_dir_all(&dir);
}

// ---------------------------------------------------------------------------------------------
// Reports
// ---------------------------------------------------------------------------------------------

/// The report as it was built before streaming: a `serde_json` value (keys in insertion
/// order), and the text with one line per contact.
fn reference(
    method: &str,
    levels: u64,
    rows: &[Vec<u64>],
    c: Counters,
    what: &str,
) -> (String, String) {
    let bytes_per_node = match method {
        "dh" => 8,
        "sphere" => 16,
        _ => 24,
    };
    let value = json!({
        "method": method,
        "precision": "f32",
        "levels": levels,
        "bytes_per_node": bytes_per_node,
        "pairs": rows,
        "counters": {
            "bv_tests": c.bv_tests,
            "prim_tests": c.prim_tests,
            "bv_updates": c.bv_updates,
            "contacts": c.contacts,
        },
    });
    let mut text = format!(
        "{} {what} ({levels} levels, {bytes_per_node} bytes per node): {} BV pairs tested, {} \
         triangle pairs tested, {} BV updates\n",
        rows.len(),
        c.bv_tests,
        c.prim_tests,
        c.bv_updates
    );
    for r in rows {
        let line: Vec<String> = r.iter().map(u64::to_string).collect();
        text.push_str(&line.join(" "));
        text.push('\n');
    }
    (format!("{value}\n"), text)
}

#[test]
fn streamed_reports_have_the_same_bytes_as_before() {
    let dir = temp_dir("hostile-bytes");
    let (a, b) = two_balls(&dir);
    let crumpled = icosphere(2, 1.0, [0.0; 3]);
    let crumpled = Mesh::new(
        wave(crumpled.positions(), 1.0, 0.6, [0.0; 3]),
        crumpled.triangles().to_vec(),
    )
    .unwrap();
    let c = dir.join("crumpled.obj");
    write_obj(&crumpled, &c);
    let (a, b, c) = (
        a.to_str().unwrap(),
        b.to_str().unwrap(),
        c.to_str().unwrap(),
    );
    for method in ["dh", "sphere", "aabb"] {
        for (args, what, width) in [
            (vec!["collide", a, b], "contacts", 2),
            (vec!["self", c], "self-contacts", 2),
            (
                vec!["scene", a, b, c, "--self-collision"],
                "contacts between 3 objects",
                4,
            ),
        ] {
            let mut args = args.clone();
            args.extend(["--method", method]);
            let json_args: Vec<&str> = args.iter().copied().chain(["--json"]).collect();
            let out = dhcd(&json_args);
            assert!(
                out.status.success(),
                "{}",
                String::from_utf8_lossy(&out.stderr)
            );
            let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
            let rows: Vec<Vec<u64>> = serde_json::from_value(v["pairs"].clone()).unwrap();
            assert!(!rows.is_empty() && rows.iter().all(|r| r.len() == width));
            let counters = Counters {
                bv_tests: v["counters"]["bv_tests"].as_u64().unwrap(),
                prim_tests: v["counters"]["prim_tests"].as_u64().unwrap(),
                bv_updates: v["counters"]["bv_updates"].as_u64().unwrap(),
                contacts: v["counters"]["contacts"].as_u64().unwrap(),
            };
            let levels = v["levels"].as_u64().unwrap();
            let (json, text) = reference(method, levels, &rows, counters, what);
            assert_eq!(String::from_utf8(out.stdout).unwrap(), json, "{args:?}");
            let out = dhcd(&args);
            let got = String::from_utf8(out.stdout).unwrap();
            // The scene's summary names the object pairs past the broad phase; the rest is
            // the same for all three commands.
            let (got_head, got_rows) = got.split_once('\n').unwrap();
            let (want_head, want_rows) = text.split_once('\n').unwrap();
            assert_eq!(got_rows, want_rows, "{args:?}");
            let tail = |s: &str| s.rsplit_once(" (").map(|(_, t)| t.to_string());
            assert_eq!(tail(got_head), tail(want_head), "{args:?}");
            assert!(got_head.starts_with(&format!("{} ", rows.len())));
        }
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// Writes `k` triangles sharing the edge on the z axis (a fan) and `k` horizontal triangles
/// stacked along it: every pair intersects, `k * k` contacts from two small files.
fn fan_and_stack(dir: &Path, k: usize) -> (PathBuf, PathBuf) {
    use std::fmt::Write;
    let mut fan = String::from("v 0 0 -1\nv 0 0 1\n");
    for i in 0..k {
        let t = std::f64::consts::TAU * i as f64 / k as f64;
        let _ = writeln!(fan, "v {} {} 0.1", t.cos(), t.sin());
    }
    for i in 0..k {
        let _ = writeln!(fan, "f 1 2 {}", i + 3);
    }
    let mut stack = String::new();
    for j in 0..k {
        let z = -0.9 + 1.8 * (j as f64 + 0.5) / k as f64;
        let _ = writeln!(stack, "v -1 -1 {z}\nv 2 -1 {z}\nv -1 2 {z}");
    }
    for j in 0..k {
        let _ = writeln!(stack, "f {} {} {}", 3 * j + 1, 3 * j + 2, 3 * j + 3);
    }
    let (a, b) = (dir.join("fan.obj"), dir.join("stack.obj"));
    std::fs::write(&a, fan).unwrap();
    std::fs::write(&b, stack).unwrap();
    (a, b)
}

/// 2.25 million contacts from two files of 150 KB: `--json` used to hold about 300 bytes
/// per contact (690 MB here); streamed, it runs within 256 MiB of data memory (the library's
/// contact array is 8 bytes per contact).
#[cfg(unix)]
#[test]
fn millions_of_contacts_stream_in_bounded_memory() {
    let dir = temp_dir("hostile-stream");
    let k = 1500;
    let (a, b) = fan_and_stack(&dir, k);
    let (a, b) = (a.to_str().unwrap(), b.to_str().unwrap());
    for json in [true, false] {
        let mut args = vec!["collide", a, b, "--method", "aabb"];
        if json {
            args.push("--json");
        }
        let out = crate::support::run_dhcd_bounded(&args, 256 << 10);
        assert!(
            out.status.success(),
            "{args:?}: {:?} {}",
            out.status,
            String::from_utf8_lossy(&out.stderr)
        );
        let contacts = (k * k).to_string();
        if json {
            // One bracket per contact and one for the list.
            assert_eq!(out.stdout.iter().filter(|&&c| c == b'[').count(), k * k + 1);
            let end = format!("\"contacts\":{contacts}}}}}\n");
            assert!(out.stdout.ends_with(end.as_bytes()));
        } else {
            assert_eq!(
                out.stdout.iter().filter(|&&c| c == b'\n').count(),
                k * k + 1
            );
            assert!(out
                .stdout
                .starts_with(format!("{contacts} contacts").as_bytes()));
        }
    }
    let _ = std::fs::remove_dir_all(&dir);
}

// ---------------------------------------------------------------------------------------------
// Messages
// ---------------------------------------------------------------------------------------------

/// Usage errors are one line naming what is missing or wrong; clap listed missing arguments
/// on lines of their own (and `dhcd` alone printed its description and exited 2).
#[test]
fn usage_errors_name_what_is_missing_on_one_line() {
    for (args, names) in [
        (
            vec![],
            vec!["requires a subcommand", "collide", "experiment"],
        ),
        (vec!["collide", "a.obj"], vec!["not provided", "<B>"]),
        (vec!["collide"], vec!["not provided", "<A>", "<B>"]),
        (vec!["self"], vec!["not provided", "<MESH>"]),
        (vec!["scene"], vec!["not provided", "<MESHES>"]),
        (vec!["bogus"], vec!["unrecognized subcommand", "bogus"]),
        (vec!["experiment", "--frames"], vec!["--frames"]),
    ] {
        let (code, err) = failure(&args);
        assert_eq!(code, Some(2), "{args:?}: {err}");
        assert_one_error_line(&err, &format!("{args:?}"));
        for name in names {
            assert!(err.contains(name), "{args:?}: {err:?} does not name {name}");
        }
    }
}

/// A path or a token with a newline, NUL-free control bytes or an escape sequence is echoed
/// escaped: the message stays one printable line (446 fuzz cases printed raw control bytes).
#[test]
fn echoed_paths_and_tokens_are_escaped() {
    let dir = temp_dir("hostile-escape");
    let (good, _) = two_balls(&dir);
    let good = good.to_str().unwrap();
    let evil = dir.join("evil\nname\u{1b}[31m.obj");
    std::fs::write(&evil, "v 0 0 0\nv 1 0 \u{7}x\n").unwrap();
    let evil = evil.to_str().unwrap();
    for (args, shown) in [
        (vec!["collide", evil, good], "evil\\nname\\u{1b}[31m.obj:2:"),
        (vec!["self", evil], "invalid coordinate '\\u{7}x'"),
        (vec!["collide", good, "missing\n.obj"], "missing\\n.obj"),
        (
            vec!["collide", good, good, "--bo\u{1b}gus"],
            "--bo\\u{1b}gus",
        ),
        (vec!["collide", good, good, "--levels", "5\n"], "'5\\n'"),
    ] {
        let out = dhcd(&args);
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(!out.status.success());
        assert_eq!(err.matches('\n').count(), 1, "{args:?}: {err:?}");
        assert!(!err.trim_end().chars().any(char::is_control), "{err:?}");
        assert!(
            err.contains(shown),
            "{args:?}: {err:?} does not show {shown}"
        );
    }
    let _ = std::fs::remove_dir_all(&dir);
}
