//! The real simulation frames, shared by the benches that read them: their file names, the
//! `f64` loader, and IPC's default contact distance relative to a frame's size. Each bench
//! uses part of this module.
#![allow(dead_code)]

use std::path::Path;

use dhcd::io::{self, Limits};
use dhcd::Precision;

/// IPC's default contact distance `dhat`, relative to the bounding-box diagonal.
pub const RELATIVE_DHAT: f64 = 1e-3;

/// Frame `frame` of `dir` (`<frame>.ply`), as an `f64` mesh (the doubles as stored).
pub fn load_f64(dir: &Path, frame: &str) -> dhcd::Mesh {
    let path = dir.join(format!("{frame}.ply"));
    io::load_as(&path, &Limits::default(), Precision::F64)
        .unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

/// The length of the bounding-box diagonal of `p`.
pub fn diagonal(p: &[[f64; 3]]) -> f64 {
    let (mut lo, mut hi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
    for q in p {
        for k in 0..3 {
            lo[k] = lo[k].min(q[k]);
            hi[k] = hi[k].max(q[k]);
        }
    }
    (0..3).map(|k| (hi[k] - lo[k]).powi(2)).sum::<f64>().sqrt()
}

/// Pairs `(N, N+1)` of frames `<name>-<number>.ply` in `dir`, in name order.
pub fn frame_pairs(dir: &Path) -> Vec<(String, String)> {
    let mut by_name: std::collections::BTreeMap<String, Vec<u64>> =
        std::collections::BTreeMap::new();
    for entry in std::fs::read_dir(dir).expect("readable data folder") {
        let file = entry.expect("readable entry").file_name();
        let Some(stem) = file.to_str().and_then(|f| f.strip_suffix(".ply")) else {
            continue;
        };
        if let Some((name, number)) = stem.rsplit_once('-') {
            if let Ok(number) = number.parse() {
                by_name.entry(name.to_owned()).or_default().push(number);
            }
        }
    }
    let mut pairs = Vec::new();
    for (name, mut numbers) in by_name {
        numbers.sort_unstable();
        for w in numbers.windows(2).filter(|w| w[1] == w[0] + 1) {
            pairs.push((format!("{name}-{}", w[0]), format!("{name}-{}", w[1])));
        }
    }
    pairs
}
