//! `dhcd_cli::experiment` and `dhcd experiment`: schema of the report, determinism (seed and
//! thread count), the command line and its files, bad flags.

use dhcd::{CentralVertex, Counters, Refit};
use dhcd_cli::experiment::{output, run, Config, Report};
use dhcd_cli::sim::{pawn_mesh_with, PAWN_HEIGHT};

use crate::support::{run_dhcd as dhcd, temp_dir};

/// A coarse pawn scene run long enough for the pawns to touch, with minimal timing work.
fn small(frames: usize, threads: usize) -> Config {
    Config {
        frames,
        threads,
        mesh: Some(pawn_mesh_with(10, 24, PAWN_HEIGHT).unwrap()),
        timing_reps: 1,
        calibration_frames: 3,
        calibration_reps: 2,
        ..Config::default()
    }
}

fn quiet(config: &Config) -> Report {
    run(config, &mut |_, _, _| {}).unwrap()
}

fn counters(r: &Report) -> Vec<Vec<Counters>> {
    r.methods
        .iter()
        .map(|m| m.steps.iter().map(|s| s.counters).collect())
        .collect()
}

#[test]
fn report_schema_and_contacts_agree() {
    let frames = 30;
    let report = quiet(&small(frames, 1));
    let json = output::to_json(&report);
    for key in [
        "objects",
        "triangles",
        "vertices",
        "frames",
        "levels",
        "threads",
        "seed",
    ] {
        assert!(json["scene"][key].is_number(), "scene.{key}");
    }
    assert_eq!(json["scene"]["frames"], frames);
    assert_eq!(json["scene"]["objects"], 8);
    let methods = json["methods"].as_object().unwrap();
    assert_eq!(
        methods.keys().collect::<Vec<_>>(),
        dhcd::Method::ALL.map(|m| m.name()),
        "methods in order"
    );
    for (name, m) in methods {
        for key in [
            "bytes_per_node",
            "bytes_per_hierarchy",
            "total_time_ns",
            "total_predicted_ns",
        ] {
            assert!(m[key].is_number(), "{name}.{key}");
        }
        for key in ["c_v_ns", "c_p_ns", "c_u_ns"] {
            assert!(
                m["costs"][key].as_f64().unwrap() >= 0.0,
                "{name}.costs.{key}"
            );
            assert!(m["costs"][key.replace("_ns", "_spread")].is_object());
        }
        assert!(m["total_predicted_ns"].as_f64().unwrap() > 0.0, "{name}");
        assert!(m["total_time_ns"].as_f64().unwrap() > 0.0, "{name}");
        let steps = m["steps"].as_array().unwrap();
        assert_eq!(steps.len(), frames, "{name}");
        for s in steps {
            for key in [
                "bv_tests",
                "prim_tests",
                "bv_updates",
                "contacts",
                "time_ns",
                "predicted_ns",
            ] {
                assert!(s[key].is_number(), "{name}.steps[].{key}");
            }
        }
    }
    for m in dhcd::Method::ALL {
        assert_eq!(methods[m.name()]["bytes_per_node"], m.bytes_per_node());
    }
    // Contacts per step are identical across methods, and the pawns do touch.
    let per_method: Vec<Vec<u64>> = report
        .methods
        .iter()
        .map(|m| m.steps.iter().map(|s| s.counters.contacts).collect())
        .collect();
    assert_eq!(per_method[0], per_method[1]);
    assert_eq!(per_method[0], per_method[2]);
    assert!(per_method[0].iter().sum::<u64>() > 0, "no contacts at all");
    // Markdown and figures render.
    assert!(output::markdown(&report).contains("| DH |"));
    let figures = output::figures(&report);
    assert_eq!(figures.len(), 6);
    assert!(figures.iter().all(|(_, svg)| svg.starts_with("<svg")));
}

#[test]
fn refit_study_compares_exact_and_bottom_up_radii() {
    let frames = 20;
    let report = quiet(&small(frames, 1));
    let study = report.refit_study.as_ref().expect("DH is measured");
    let dh = report.method(dhcd::Method::Dh).unwrap();
    let refits: Vec<Refit> = study.rows.iter().map(|r| r.refit).collect();
    assert_eq!(refits, [Refit::Eager, Refit::EagerBottomUp]);
    let (exact, bound) = (&study.rows[0], &study.rows[1]);
    for (s, (e, b)) in dh.steps.iter().zip(exact.steps.iter().zip(&bound.steps)) {
        // Eager exact radii are the lazy ones: the same tests, every node updated.
        assert_eq!(
            (
                e.counters.bv_tests,
                e.counters.prim_tests,
                e.counters.contacts
            ),
            (
                s.counters.bv_tests,
                s.counters.prim_tests,
                s.counters.contacts
            )
        );
        assert_eq!(
            e.counters.bv_updates,
            8 * report.scene.nodes_per_hierarchy as u64
        );
        // The bottom-up bound encloses the exact sphere: never fewer tests, same contacts.
        assert!(b.counters.bv_tests >= e.counters.bv_tests);
        assert!(b.counters.prim_tests >= e.counters.prim_tests);
        assert_eq!(b.counters.contacts, e.counters.contacts);
        assert_eq!(b.counters.bv_updates, e.counters.bv_updates);
        assert!(e.refit_ns > 0.0 && b.refit_ns > 0.0 && s.refit_ns == 0.0);
    }
    assert_eq!(exact.steps.len(), frames);
    let l = study.looseness;
    assert!(
        l.nodes > 0 && l.mean >= 1.0 && l.max >= l.mean && l.root_mean >= 1.0,
        "{l:?}"
    );
    // Reports: the JSON section, the Markdown table and the summary lines.
    let json = output::to_json(&report);
    let rows = json["refit_study"]["rows"].as_array().unwrap();
    assert_eq!(rows.len(), 2);
    assert_eq!(rows[1]["refit"], "bottom-up");
    assert_eq!(rows[1]["steps"].as_array().unwrap().len(), frames);
    assert!(rows[1]["totals"]["refit_ns"].as_f64().unwrap() > 0.0);
    let md = output::markdown(&report);
    assert!(
        md.contains("## DH radius: exact against the bottom-up bound"),
        "{md}"
    );
    assert!(md.contains("| bottom-up bound | eager |"), "{md}");
    assert!(md.contains("| exact | lazy (default) |"), "{md}");
    assert!(output::summary_table(&report).contains("bottom-up bound, eager"));
    // No DH, no study.
    let no_dh = quiet(&Config {
        methods: vec![dhcd::Method::Aabb],
        ..small(3, 1)
    });
    assert!(no_dh.refit_study.is_none());
    assert!(output::to_json(&no_dh)["refit_study"].is_null());
}

#[test]
fn central_vertex_changes_dh_work_not_contacts() {
    let paper = quiet(&small(16, 1));
    let tight = quiet(&Config {
        central: CentralVertex::MinRadius,
        ..small(16, 1)
    });
    assert_eq!(tight.scene.central, CentralVertex::MinRadius);
    assert_eq!(output::to_json(&tight)["scene"]["central"], "min-radius");
    let contacts = |r: &Report| -> Vec<Vec<u64>> {
        r.methods
            .iter()
            .map(|m| m.steps.iter().map(|s| s.counters.contacts).collect())
            .collect()
    };
    assert_eq!(contacts(&paper), contacts(&tight));
    // The other methods ignore it.
    let (p, t) = (counters(&paper), counters(&tight));
    assert_eq!(p[1..], t[1..]);
}

#[test]
fn deterministic_for_seed_and_thread_count() {
    let a = quiet(&small(16, 1));
    let b = quiet(&small(16, 1));
    let c = quiet(&small(16, 2));
    assert_eq!(counters(&a), counters(&b));
    assert_eq!(counters(&a), counters(&c));
    let study = |r: &Report| -> Vec<Vec<Counters>> {
        let rows = &r.refit_study.as_ref().unwrap().rows;
        rows.iter()
            .map(|row| row.steps.iter().map(|s| s.counters).collect())
            .collect()
    };
    assert_eq!(study(&a), study(&c));
    assert_eq!(
        a.refit_study.as_ref().unwrap().looseness,
        c.refit_study.as_ref().unwrap().looseness
    );
    assert_eq!(a.snapshot, c.snapshot);
    let other_seed = quiet(&Config {
        seed: 7,
        ..small(16, 1)
    });
    assert_eq!(other_seed.scene.seed, 7);
}

#[test]
fn bad_configs_are_errors() {
    for config in [
        Config {
            frames: 0,
            ..small(1, 1)
        },
        Config {
            threads: dhcd::Par::MAX_THREADS + 1,
            ..small(1, 1)
        },
        Config {
            methods: vec![],
            ..small(1, 1)
        },
        Config {
            methods: vec![dhcd::Method::Dh, dhcd::Method::Dh],
            ..small(1, 1)
        },
        Config {
            levels: 0,
            ..small(1, 1)
        },
    ] {
        assert!(run(&config, &mut |_, _, _| {}).is_err(), "{config:?}");
    }
}

/// Runs `dhcd experiment ARGS --quiet --out DIR`, which must succeed; its standard output
/// and `report.json`.
fn experiment_cli(dir: &std::path::Path, args: &[&str]) -> (String, serde_json::Value) {
    let mut all = vec!["experiment"];
    all.extend(args);
    all.extend(["--quiet", "--out", dir.to_str().unwrap()]);
    let out = dhcd(&all);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let json = serde_json::from_slice(&std::fs::read(dir.join("report.json")).unwrap()).unwrap();
    (String::from_utf8_lossy(&out.stdout).into_owned(), json)
}

#[test]
fn cli_writes_every_file() {
    let dir = temp_dir("experiment-cli");
    let (stdout, json) = experiment_cli(&dir, &["--frames", "3"]);
    for f in output::FILES {
        let meta = std::fs::metadata(dir.join(f)).unwrap_or_else(|e| panic!("{f}: {e}"));
        assert!(meta.len() > 0, "{f} is empty");
    }
    assert!(stdout.contains("dh") && stdout.contains("aabb"), "{stdout}");
    assert_eq!(json["methods"]["dh"]["steps"].as_array().unwrap().len(), 3);
    assert_eq!(json["scene"]["central"], "rest-centroid");
    assert!(
        stdout.contains("DH central vertex rest-centroid"),
        "{stdout}"
    );
    assert!(stdout.contains("bottom-up bound, eager"), "{stdout}");
    // The least-radius central vertex, asked for on the command line.
    let args = [
        "--frames",
        "2",
        "--methods",
        "dh",
        "--central",
        "min-radius",
    ];
    let (_, json) = experiment_cli(&dir, &args);
    assert_eq!(json["scene"]["central"], "min-radius");
    assert_eq!(json["refit_study"]["rows"].as_array().unwrap().len(), 2);
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn cli_bad_flags_fail_cleanly() {
    let dir = temp_dir("experiment-bad");
    let missing = dir.join("missing.obj");
    for args in [
        vec!["experiment", "--frames", "0"],
        vec!["experiment", "--frames", "many"],
        vec!["experiment", "--methods", "dh,octree"],
        vec!["experiment", "--threads", "16384"],
        vec!["experiment", "--threads", "-1"],
        vec!["experiment", "--levels", "0", "--frames", "1"],
        vec!["experiment", "--central", "middle"],
        vec!["experiment", "--mesh", missing.to_str().unwrap()],
        vec!["experiment", "--bogus"],
    ] {
        let out = dhcd(&args);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(!out.status.success(), "{args:?} succeeded");
        assert!(!stderr.contains("panicked"), "{args:?}: {stderr}");
        assert_eq!(stderr.trim_end().lines().count(), 1, "{args:?}: {stderr}");
        assert!(stderr.starts_with("dhcd: error:"), "{args:?}: {stderr}");
        assert!(out.stdout.is_empty(), "{args:?}");
    }
}
