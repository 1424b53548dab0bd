//! Helpers shared by the suites that run the `dhcd` binary on files.

use std::path::Path;
use std::process::{Command, Output};

use dhcd::Mesh;

pub use crate::temp_dir::{temp_dir, TempDir};

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

/// Runs `dhcd` with `args`: exit code, stdout, stderr.
pub fn dhcd(args: &[&str]) -> (i32, String, String) {
    let out = run_dhcd(args);
    (
        out.status.code().unwrap_or(-1),
        String::from_utf8(out.stdout).unwrap(),
        String::from_utf8(out.stderr).unwrap(),
    )
}

/// `s` parsed as JSON (the text in the panic message if it is not).
pub fn json(s: &str) -> serde_json::Value {
    serde_json::from_str(s).unwrap_or_else(|e| panic!("{e}: {s}"))
}

/// Writes an OBJ of `f64` positions to the last bit (`{:?}` prints the shortest decimal
/// that reads back to the same `f64`).
pub fn write_obj_f64(path: &Path, positions: &[[f64; 3]], triangles: &[[u32; 3]]) {
    let mut text = String::new();
    for p in positions {
        text += &format!("v {:?} {:?} {:?}\n", p[0], p[1], p[2]);
    }
    for t in triangles {
        text += &format!("f {} {} {}\n", t[0] + 1, t[1] + 1, t[2] + 1);
    }
    std::fs::write(path, text).unwrap();
}
