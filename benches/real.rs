//! Real simulation frames (`../shared/data/real-frames/`, beside the checkout; see its
//! README): one step = `update_positions` to the other frame of a pair (alternating N and
//! N+1) + self-collision, one thread, default options.
//!
//! Ids: `real/<frame>/<impl>` for every pair of consecutive frames `<frame>` (N) and N+1 in
//! the folder, `impl` in `dhcd-dh`, `dhcd-sphere`, `dhcd-aabb`, `parry3d` (see
//! `common/mod.rs`: only the hierarchy differs). The setup asserts that every implementation
//! finds the same pairs on both frames. Without the folder, nothing is registered and a
//! message says so.
//!
//! `cargo bench --bench real -- real/cloth-ball-92/`

mod common;
mod frames;

use std::path::{Path, PathBuf};

use common::{bench_steps, Impl, Sequence};
use criterion::{criterion_group, criterion_main, Criterion};
use dhcd::Method;
use frames::frame_pairs;

fn load(dir: &Path, frame: &str) -> dhcd::Mesh {
    let path = dir.join(format!("{frame}.ply"));
    dhcd::io::load(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

fn real(c: &mut Criterion) {
    let dir: PathBuf = Path::new(env!("CARGO_MANIFEST_DIR")).join("../shared/data/real-frames");
    if !dir.is_dir() {
        eprintln!(
            "real bench SKIPPED: no data folder at {} (the frames of the Sample-Scalable-CCD-Data \
             repository; see the issue)",
            dir.display()
        );
        return;
    }
    let pairs = frame_pairs(&dir);
    assert!(!pairs.is_empty(), "no frame pairs in {}", dir.display());
    let impls: Vec<Impl> = Method::ALL
        .into_iter()
        .map(Impl::Dhcd)
        .chain([Impl::Parry])
        .collect();
    for (first, second) in pairs {
        bench_steps(c, "real", &first, &impls, || {
            let (rest, next) = (load(&dir, &first), load(&dir, &second));
            assert_eq!(
                rest.triangles(),
                next.triangles(),
                "{first}/{second}: one mesh"
            );
            let frames = vec![rest.positions().to_vec(), next.positions().to_vec()];
            Sequence { rest, frames }
        });
    }
}

criterion_group! {
    name = benches;
    // A step takes tens to hundreds of milliseconds: ten samples.
    config = Criterion::default().sample_size(10);
    targets = real
}
criterion_main!(benches);
