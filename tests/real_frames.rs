//! Real simulation frames (`../shared/data/real-frames/`, beside the checkout; see its
//! README): exact self-collision counts on every frame, for every method, on a fresh build and
//! after a refit from the other frame of the pair; identical pairs for the three methods;
//! two threads equal to one (pairs and counters); invariants after build and refit.
//!
//! The expected counts are the README's (an independent exact brute force, confirmed by
//! CGAL). When the folder is absent the tests print why and pass.

use dhcd::calibration::Calibration;
use std::path::PathBuf;
use std::sync::Arc;

use dhcd::{AnyHierarchy, Contacts, Mesh, Method, Options, Par, RegionTree, Workspace};

/// Every frame of the folder and its exact self-contact count (the README's table).
const EXPECTED: [(&str, usize); 8] = [
    ("armadillo-rollers-326", 0),
    ("armadillo-rollers-327", 0),
    ("cloth-ball-92", 61_530),
    ("cloth-ball-93", 97_320),
    ("n-body-simulation-18", 4_836),
    ("n-body-simulation-19", 4_321),
    ("rod-twist-3036", 0),
    ("rod-twist-3037", 0),
];

/// The data folder, or `None` (with a message saying what is skipped) when it is absent.
fn frames_dir(test: &str) -> Option<PathBuf> {
    crate::support::shared_data(&format!("real_frames::{test}"), "real-frames")
}

fn expected(frame: &str) -> usize {
    EXPECTED
        .iter()
        .find(|(name, _)| *name == frame)
        .unwrap_or_else(|| panic!("{frame} is not in the expected table"))
        .1
}

/// A query on a fresh build (`refit: None`: the volumes fitted by the build), or after
/// `update_positions(positions)` (`Some`), then again with two threads, which must give
/// identical pairs and counters (the positions are handed over again in between, so both
/// queries refit the same nodes).
fn self_collide_at(h: &mut AnyHierarchy, refit: Option<&[[f32; 3]]>, what: &str) -> Contacts {
    let mut ws = Workspace::default();
    let Some(positions) = refit else {
        return h.self_collide(&mut ws, Par::Seq);
    };
    h.update_positions(positions).unwrap();
    let seq = h.self_collide(&mut ws, Par::Seq);
    h.update_positions(positions).unwrap();
    let par = h.self_collide(&mut ws, Par::Rayon(2));
    assert_eq!(
        par.counters, seq.counters,
        "{what}: 2 threads vs 1, counters"
    );
    assert!(
        par.pairs == seq.pairs,
        "{what}: 2 threads vs 1, pairs differ"
    );
    seq
}

/// Checks the invariants of every node: fits every node to the current pose first (a lazy
/// query leaves untested nodes stale, and the checker skips those).
fn validate_all(h: &mut AnyHierarchy, what: &str) {
    let all: Vec<u32> = (0..h.node_count() as u32).collect();
    h.refit_nodes(&all, Par::Seq).unwrap();
    let checked = h.validate().unwrap_or_else(|e| panic!("{what}: {e}"));
    assert_eq!(checked, h.node_count(), "{what}: every node checked");
}

/// Both frames of a pair, every method: build on `first`, query, refit to `second`, query;
/// then build on `second`, query, refit to `first`, query. Every count is the README's, the
/// three methods' pair lists are identical, two threads equal one on every frame (on the
/// refit path), and the invariants hold after the build and after every query.
fn check_pair(first: &str, second: &str) {
    let Some(dir) = frames_dir(&format!("{first}+{second}")) else {
        return;
    };
    let load = |frame: &str| dhcd::io::load(&dir.join(format!("{frame}.ply"))).unwrap();
    let meshes = [load(first), load(second)];
    assert_eq!(
        meshes[0].triangles(),
        meshes[1].triangles(),
        "{first}/{second}: one mesh"
    );
    let names = [first, second];
    for build in 0..2 {
        let rest: &Mesh = &meshes[build];
        let tree = Arc::new(RegionTree::build(rest, Options::default().shape()).unwrap());
        tree.check_topology(rest).unwrap();
        let mut reference: Vec<Vec<[u32; 2]>> = Vec::new();
        for method in Method::ALL {
            let mut h =
                AnyHierarchy::with_tree(method, tree.clone(), rest, Options::default()).unwrap();
            h.validate().unwrap();
            let mut found = Vec::new();
            for frame in [build, 1 - build] {
                let what = format!(
                    "{method} built on {}, frame {}{}",
                    names[build],
                    names[frame],
                    if frame == build { "" } else { " (refit)" }
                );
                // Two threads on the refit path: each frame once per method.
                let refit = (frame != build).then(|| meshes[frame].positions());
                let c = self_collide_at(&mut h, refit, &what);
                assert_eq!(c.pairs.len(), expected(names[frame]), "{what}: contacts");
                assert_eq!(c.counters.contacts as usize, c.pairs.len(), "{what}");
                validate_all(&mut h, &what);
                eprintln!(
                    "{what}: {} contacts, N_V {} N_P {} N_U {}",
                    c.pairs.len(),
                    c.counters.bv_tests,
                    c.counters.prim_tests,
                    c.counters.bv_updates
                );
                found.push(c.pairs);
            }
            if reference.is_empty() {
                reference = found;
            } else {
                assert!(
                    found == reference,
                    "{method} built on {}: pairs differ from {}",
                    names[build],
                    Method::ALL[0]
                );
            }
        }
    }
}

#[test]
fn the_table_is_the_readmes_and_covers_every_frame() {
    let Some(dir) = frames_dir("the_table_is_the_readmes_and_covers_every_frame") else {
        return;
    };
    let readme = std::fs::read_to_string(dir.join("README.md")).unwrap();
    for (frame, count) in EXPECTED {
        // `| cloth-ball-92 | 61,530 |`
        let digits = count.to_string();
        let mut grouped = String::new();
        for (i, d) in digits.chars().enumerate() {
            if i > 0 && (digits.len() - i) % 3 == 0 {
                grouped.push(',');
            }
            grouped.push(d);
        }
        let row = format!("| {frame} | {grouped} |");
        assert!(readme.contains(&row), "README has no row `{row}`");
    }
    let mut files: Vec<String> = std::fs::read_dir(&dir)
        .unwrap()
        .filter_map(|e| {
            let name = e.unwrap().file_name().into_string().unwrap();
            name.strip_suffix(".ply").map(str::to_owned)
        })
        .collect();
    files.sort();
    let table: Vec<&str> = EXPECTED.iter().map(|(f, _)| *f).collect();
    assert_eq!(
        files, table,
        "every frame in the folder has an expected count"
    );
}

#[test]
fn armadillo_rollers_326_327() {
    check_pair("armadillo-rollers-326", "armadillo-rollers-327");
}

#[test]
fn cloth_ball_92_93() {
    check_pair("cloth-ball-92", "cloth-ball-93");
}

#[test]
fn n_body_simulation_18_19() {
    check_pair("n-body-simulation-18", "n-body-simulation-19");
}

#[test]
fn rod_twist_3036_3037() {
    check_pair("rod-twist-3036", "rod-twist-3037");
}
