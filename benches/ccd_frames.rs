//! CCD over the real simulation steps (`../shared/data/real-frames/`, frame N -> N+1, `f64`):
//! one iteration = `self_ccd` over the whole step, one thread, default options.
//!
//! Ids: `ccd/<frame>/<method>` (every colliding pair with its time of impact),
//! `ccd-earliest/<frame>/<method>` (the earliest time of impact, what a line search asks) and
//! `ccd-near/<frame>/dh` (every pair coming within `NEAR` = 1e-3 of each other, with its
//! time: the minimum-distance filter, against `ccd/<frame>/dh` at distance 0). The setup
//! asserts that every method finds the same pairs. Without the folder, nothing is
//! registered and a message says so. The IPC Toolkit's figure on the same steps comes from
//! `benches/scripts/ccd-vs-ipctk.sh`. (The per-query bench on the sample queries is
//! `benches/ccd.rs`.)
//!
//! `cargo bench --bench ccd_frames -- ccd/rod-twist-3036/`

mod frames;

use std::hint::black_box;
use std::path::{Path, PathBuf};

use criterion::{criterion_group, criterion_main, Criterion};
use dhcd::{AnyHierarchy, CcdQuery, Method, Motion, Options, Par, Workspace};
use frames::{frame_pairs, load_f64};

/// The minimum distance of the `ccd-near` group (absolute; the frames' extents are 1-10).
const NEAR: f64 = 1e-3;

fn ccd(c: &mut Criterion) {
    let dir: PathBuf = Path::new(env!("CARGO_MANIFEST_DIR")).join("../shared/data/real-frames");
    if !dir.is_dir() {
        eprintln!(
            "ccd_frames bench SKIPPED: no data folder at {}",
            dir.display()
        );
        return;
    }
    for (first, second) in frame_pairs(&dir) {
        let (m0, m1) = (load_f64(&dir, &first), load_f64(&dir, &second));
        let motion = Motion::new(
            m0.positions_f64().expect("f64"),
            m1.positions_f64().expect("f64"),
        );
        let mut reference = None;
        for method in Method::ALL {
            let h = AnyHierarchy::new(method, &m0, Options::default()).expect("hierarchy");
            let mut ws = Workspace::default();
            let mut got = h
                .self_ccd(motion, &CcdQuery::all(), &mut ws, Par::Seq)
                .expect("a step");
            got.counters = Default::default();
            match &reference {
                None => reference = Some(got),
                Some(r) => assert!(*r == got, "{first}: {method} differs"),
            }
            for (group, query) in [
                ("ccd", CcdQuery::all()),
                ("ccd-earliest", CcdQuery::earliest()),
            ] {
                c.bench_function(&format!("{group}/{first}/{}", method.name()), |b| {
                    b.iter(|| {
                        let p = h
                            .self_ccd(motion, &query, &mut ws, Par::Seq)
                            .expect("a step");
                        black_box(p.toi)
                    })
                });
            }
            if method == Method::Dh {
                let near = CcdQuery::all().with_min_distance(NEAR);
                c.bench_function(&format!("ccd-near/{first}/dh"), |b| {
                    b.iter(|| {
                        let p = h
                            .self_ccd(motion, &near, &mut ws, Par::Seq)
                            .expect("a step");
                        black_box(p.toi)
                    })
                });
            }
        }
    }
}

criterion_group! {
    name = benches;
    config = Criterion::default().sample_size(10);
    targets = ccd
}
criterion_main!(benches);
