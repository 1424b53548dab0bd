//! Per-test temporary directories, shared by the library's and the CLI's suites (the CLI's
//! includes this file).

use std::path::{Path, PathBuf};

/// A fresh, empty directory for one test, removed when the test passes (kept for inspection
/// when it panics). `name` must be unique across the suites (tests run in parallel and this
/// removes what was there); the process id keeps concurrent runs apart.
pub fn temp_dir(name: &str) -> TempDir {
    let dir = std::env::temp_dir().join(format!("dhcd-test-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    TempDir(dir)
}

/// See [`temp_dir`].
pub struct TempDir(PathBuf);

impl std::ops::Deref for TempDir {
    type Target = Path;
    fn deref(&self) -> &Path {
        &self.0
    }
}

impl AsRef<Path> for TempDir {
    fn as_ref(&self) -> &Path {
        &self.0
    }
}

impl Drop for TempDir {
    fn drop(&mut self) {
        if !std::thread::panicking() {
            let _ = std::fs::remove_dir_all(&self.0);
        }
    }
}
