//! Helpers shared by the suites that run the `dhcd` binary on files.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use dhcd::Mesh;

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

impl TempDir {
    /// The path, no longer removed (a directory shared by a suite's tests through a static,
    /// which is never dropped anyway).
    pub fn keep(self) -> PathBuf {
        let path = self.0.clone();
        std::mem::forget(self);
        path
    }
}

impl std::ops::Deref for TempDir {
    type Target = std::path::Path;
    fn deref(&self) -> &std::path::Path {
        &self.0
    }
}

impl AsRef<std::path::Path> for TempDir {
    fn as_ref(&self) -> &std::path::Path {
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

/// Runs `dhcd` with `args`, at most `data_kib` KiB of data memory (`ulimit -d`: heap and
/// private writable mappings, so an unbounded allocation aborts instead of filling the
/// machine), and fails the test if it has not ended after a generous two minutes (then it is
/// killed: a hang, not slowness).
#[cfg(unix)]
pub fn run_dhcd_bounded(args: &[&str], data_kib: u64) -> Output {
    use std::io::Read;
    use std::process::Stdio;
    let mut child = Command::new("sh")
        .arg("-c")
        .arg(format!("ulimit -d {data_kib} && exec \"$0\" \"$@\""))
        .arg(env!("CARGO_BIN_EXE_dhcd"))
        .args(args)
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let drain = |mut pipe: Box<dyn Read + Send>| {
        std::thread::spawn(move || {
            let mut bytes = Vec::new();
            let _ = pipe.read_to_end(&mut bytes);
            bytes
        })
    };
    let stdout = drain(Box::new(child.stdout.take().unwrap()));
    let stderr = drain(Box::new(child.stderr.take().unwrap()));
    let deadline = std::time::Instant::now() + std::time::Duration::from_secs(120);
    let status = loop {
        if let Some(status) = child.try_wait().unwrap() {
            break status;
        }
        if std::time::Instant::now() > deadline {
            let _ = child.kill();
            let _ = child.wait();
            panic!("dhcd {} did not end within two minutes", args.join(" "));
        }
        std::thread::sleep(std::time::Duration::from_millis(10));
    };
    Output {
        status,
        stdout: stdout.join().unwrap(),
        stderr: stderr.join().unwrap(),
    }
}
