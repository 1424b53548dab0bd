//! Seeded mutation fuzzing of the command line (issue 9, item 8): `dhcd` on mutated mesh
//! files of every format exits 0 with its report, or 1 with exactly one printable
//! `dhcd: error:` line; never a signal, never more memory than a fixed bound (`ulimit -d`). The generator
//! and the run's size (`DHCD_FUZZ_CASES`, `DHCD_FUZZ_SEED`) are shared with the library's
//! parser fuzzing (`tests/mutation.rs`, `tests/fixtures.rs` at the workspace root).

use crate::mutation::{cases, check_message, keep, mutate, seed, Rng};

/// Data memory the `dhcd` process may take: far above what these small inputs need, far
/// below what an unbounded allocation would take.
#[cfg(unix)]
const CLI_MEMORY_KIB: u64 = 512 << 10;

/// The command line on mutated files: exit 0, or exit 1 with exactly one `dhcd: error:` line
/// on stderr; never a signal (an abort on a failed allocation included).
#[cfg(unix)]
#[test]
fn the_command_line_ends_in_contacts_or_one_error_line() {
    let seeds = crate::fixtures::seeds();
    let exts = ["obj", "obj", "stl", "stl", "stl", "ply", "ply", "ply"];
    assert_eq!(seeds.len(), exts.len());
    let dir = crate::support::temp_dir("fuzz-cli");
    let good = dir.join("good.obj");
    crate::support::write_obj(&dhcd::shapes::icosphere(1, 1.0, [0.0; 3]), &good);
    let (seed, cases) = (seed(), (cases() / 20).max(8));
    for case in 0..cases {
        let mut rng = Rng::new(seed ^ 0xc11, case);
        let k = rng.below(seeds.len());
        let mut bytes = seeds[k].clone();
        mutate(&mut bytes, &mut rng);
        let file = dir.join(format!("case{case}.{}", exts[k]));
        std::fs::write(&file, &bytes).unwrap();
        let (file, good) = (file.to_str().unwrap(), good.to_str().unwrap());
        let args: Vec<&str> = match case % 3 {
            0 => vec!["collide", file, good],
            1 => vec!["self", file, "--json"],
            _ => vec!["scene", good, file, "--threads", "2"],
        };
        let out = crate::support::run_dhcd_bounded(&args, CLI_MEMORY_KIB);
        let stderr = String::from_utf8_lossy(&out.stderr);
        let verdict = match out.status.code() {
            None => Err(format!("killed by a signal: {:?}", out.status)),
            Some(0) if stderr.is_empty() => Ok(()),
            Some(1) => match stderr.strip_suffix('\n') {
                Some(line) if line.starts_with("dhcd: error: ") => check_message(line),
                _ => Err(format!("not one 'dhcd: error:' line: {stderr:?}")),
            },
            Some(code) => Err(format!("exit code {code}, stderr {stderr:?}")),
        };
        if let Err(e) = verdict {
            let kept = keep(&format!("fuzz-cli-{seed}-{case}.{}", exts[k]), &bytes);
            panic!(
                "DHCD_FUZZ_SEED={seed} case {case}: dhcd {} ({}): {e}",
                args.join(" "),
                kept.display()
            );
        }
    }
    let _ = std::fs::remove_dir_all(&dir);
}
