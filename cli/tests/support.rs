//! Helpers shared by the suites that run the `dhcd` binary on files.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use dhcd::Mesh;

/// A fresh, empty directory for one test. `name` must be unique across the suites (tests run
/// in parallel and this removes what was there); the process id keeps concurrent runs apart.
pub fn temp_dir(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("dhcd-test-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// Writes `mesh` as OBJ with the library's own writer.
pub fn write_obj(mesh: &Mesh, path: &Path) {
    let mut f = std::fs::File::create(path).unwrap();
    dhcd::io::write_obj(mesh, &mut f).unwrap();
}

/// Runs the built `dhcd` binary with `args`.
pub fn run_dhcd(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_dhcd"))
        .args(args)
        .output()
        .unwrap()
}
