//! Self-proximity on the real simulation frames (`../shared/data/real-frames/`), `f64`, at
//! IPC's default contact distance (`dhat` = 1e-3 x the first frame's bounding-box diagonal):
//! one step = `update_positions_f64` to the other frame of a pair (alternating N and N+1) +
//! `self_proximity`, one thread, default options.
//!
//! Ids: `proximity/<frame>/<method>`. The setup asserts that every method finds the same pairs
//! on both frames. Without the folder, nothing is registered and a message says so. The
//! IPC Toolkit's figure on the same frames comes from `benches/scripts/proximity-vs-ipctk.sh`.
//!
//! `cargo bench --bench proximity -- proximity/cloth-ball-92/`

mod frames;

use std::hint::black_box;
use std::path::{Path, PathBuf};

use criterion::{criterion_group, criterion_main, Criterion};
use dhcd::io::{self, Limits};
use dhcd::{AnyHierarchy, Method, Options, Par, Precision, Workspace};
use frames::frame_pairs;

/// IPC's default contact distance, relative to the bounding-box diagonal.
const RELATIVE: f64 = 1e-3;

fn load(dir: &Path, frame: &str) -> dhcd::Mesh {
    let path = dir.join(format!("{frame}.ply"));
    io::load_as(&path, &Limits::default(), Precision::F64)
        .unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

fn diagonal(p: &[[f64; 3]]) -> f64 {
    let (mut lo, mut hi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
    for q in p {
        for k in 0..3 {
            lo[k] = lo[k].min(q[k]);
            hi[k] = hi[k].max(q[k]);
        }
    }
    (0..3).map(|k| (hi[k] - lo[k]).powi(2)).sum::<f64>().sqrt()
}

fn proximity(c: &mut Criterion) {
    let dir: PathBuf = Path::new(env!("CARGO_MANIFEST_DIR")).join("../shared/data/real-frames");
    if !dir.is_dir() {
        eprintln!(
            "proximity bench SKIPPED: no data folder at {}",
            dir.display()
        );
        return;
    }
    for (first, second) in frame_pairs(&dir) {
        let (rest, next) = (load(&dir, &first), load(&dir, &second));
        let frames = [
            rest.positions_f64().expect("f64").to_vec(),
            next.positions_f64().expect("f64").to_vec(),
        ];
        let d = RELATIVE * diagonal(&frames[0]);
        let mut reference = None;
        for method in Method::ALL {
            let mut h = AnyHierarchy::new(method, &rest, Options::default()).expect("hierarchy");
            let mut ws = Workspace::default();
            // Every method finds the same pairs on both frames.
            for f in &frames {
                h.update_positions_f64(f).expect("a pose");
                let mut p = h.self_proximity(d, &mut ws, Par::Seq).expect("distance");
                p.counters = Default::default();
                match &reference {
                    None => reference = Some(vec![p]),
                    Some(r) if r.len() < 2 => reference.as_mut().expect("set").push(p),
                    Some(r) => assert!(r.contains(&p), "{first}: {method} differs"),
                }
            }
            let mut k = 0;
            c.bench_function(&format!("proximity/{first}/{}", method.name()), |b| {
                b.iter(|| {
                    k = (k + 1) % 2;
                    h.update_positions_f64(&frames[k]).expect("a pose");
                    let p = h.self_proximity(d, &mut ws, Par::Seq).expect("distance");
                    black_box(p.counters.contacts)
                })
            });
        }
    }
}

criterion_group! {
    name = benches;
    config = Criterion::default().sample_size(10);
    targets = proximity
}
criterion_main!(benches);
