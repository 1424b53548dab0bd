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
use dhcd::{AnyHierarchy, Method, Options, Par, Workspace};
use frames::{diagonal, frame_pairs, load_f64, RELATIVE_DHAT};

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
        let (rest, next) = (load_f64(&dir, &first), load_f64(&dir, &second));
        let frames = [
            rest.positions_f64().expect("f64").to_vec(),
            next.positions_f64().expect("f64").to_vec(),
        ];
        let d = RELATIVE_DHAT * diagonal(&frames[0]);
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
