//! Per-query CCD cost on the sample queries of `tests/data/ccd-sample-queries`
//! (Wang et al. 2021): all queries, and per folder and query kind.
//!
//! Run: `cargo bench --bench ccd`. Before criterion's groups (`ccd/<folder>/<vertex-face|edge-edge>`, one
//! iteration = every query of the set once, so time / queries = mean per query), it prints
//! a table of per-query times: each query timed alone (best of 15 runs of 8 calls), then
//! the median, mean and max over the queries of each set. `CCD_BENCH_TABLE_ONLY=1` skips
//! criterion.

use std::hint::black_box;
use std::path::{Path, PathBuf};
use std::time::Instant;

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use dhcd::ccd::{self, CcdOptions};
use num_bigint::BigInt;
use num_rational::BigRational;
use num_traits::ToPrimitive;

type Query = ([[f64; 3]; 4], [[f64; 3]; 4], bool);

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/ccd-sample-queries")
}

/// num/den as f64, checked exact.
fn value(num: &str, den: &str) -> f64 {
    let q = BigRational::new(
        num.parse::<BigInt>().unwrap(),
        den.parse::<BigInt>().unwrap(),
    );
    let x = q.to_f64().unwrap();
    assert_eq!(
        BigRational::from_float(x).unwrap(),
        q,
        "{num}/{den} is not an f64"
    );
    x
}

fn load(dir: &Path) -> Vec<Query> {
    let mut files: Vec<_> = std::fs::read_dir(dir)
        .unwrap()
        .filter_map(|e| e.ok())
        .map(|e| e.path())
        .collect();
    files.sort();
    let mut out = Vec::new();
    for f in files {
        let text = std::fs::read_to_string(&f).unwrap();
        let rows: Vec<Vec<&str>> = text
            .lines()
            .filter(|l| !l.trim().is_empty())
            .map(|l| l.trim().split(',').collect())
            .collect();
        for q in rows.chunks(8) {
            let pt = |r: &Vec<&str>| [value(r[0], r[1]), value(r[2], r[3]), value(r[4], r[5])];
            out.push((
                std::array::from_fn(|i| pt(&q[i])),
                std::array::from_fn(|i| pt(&q[4 + i])),
                q[0][6].trim() == "1",
            ));
        }
    }
    out
}

fn sets() -> Vec<(String, bool, Vec<Query>)> {
    let mut folders: Vec<_> = std::fs::read_dir(root())
        .unwrap()
        .filter_map(|e| e.ok())
        .filter(|e| e.path().is_dir())
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .collect();
    folders.sort();
    let mut out = Vec::new();
    for f in folders {
        for (kind, vf) in [("vertex-face", true), ("edge-edge", false)] {
            let dir = root().join(&f).join(kind);
            if dir.is_dir() {
                out.push((format!("{f}/{kind}"), vf, load(&dir)));
            }
        }
    }
    out
}

#[inline(always)]
fn run(vf: bool, q: &Query, o: &CcdOptions) -> Option<f64> {
    if vf {
        ccd::vertex_face(&q.0, &q.1, o)
    } else {
        ccd::edge_edge(&q.0, &q.1, o)
    }
}

/// Best-of-15 time of one query, in ns.
fn time_one(vf: bool, q: &Query, o: &CcdOptions) -> f64 {
    let mut best = f64::INFINITY;
    for _ in 0..15 {
        let t = Instant::now();
        for _ in 0..8 {
            black_box(run(vf, black_box(q), o));
        }
        best = best.min(t.elapsed().as_nanos() as f64 / 8.0);
    }
    best
}

fn stats(mut v: Vec<f64>) -> (f64, f64, f64) {
    v.sort_by(|a, b| a.partial_cmp(b).unwrap());
    let med = if v.len() % 2 == 1 {
        v[v.len() / 2]
    } else {
        0.5 * (v[v.len() / 2 - 1] + v[v.len() / 2])
    };
    (
        med,
        v.iter().sum::<f64>() / v.len() as f64,
        *v.last().unwrap(),
    )
}

fn table(all: &[(String, bool, Vec<Query>)]) {
    let o = CcdOptions::default();
    println!(
        "{:<42} {:>6} {:>10} {:>10} {:>12}",
        "set", "n", "median ns", "mean ns", "max ns"
    );
    let mut every = Vec::new();
    for (name, vf, qs) in all {
        let ts: Vec<f64> = qs.iter().map(|q| time_one(*vf, q, &o)).collect();
        every.extend_from_slice(&ts);
        let (med, mean, max) = stats(ts);
        println!(
            "{name:<42} {:>6} {med:>10.0} {mean:>10.0} {max:>12.0}",
            qs.len()
        );
    }
    let n = every.len();
    let (med, mean, max) = stats(every);
    println!("{:<42} {n:>6} {med:>10.0} {mean:>10.0} {max:>12.0}", "all");
}

fn bench(c: &mut Criterion) {
    let all = sets();
    table(&all);
    if std::env::var_os("CCD_BENCH_TABLE_ONLY").is_some() {
        return;
    }
    let o = CcdOptions::default();
    let mut g = c.benchmark_group("ccd");
    g.sample_size(10);
    for (name, vf, qs) in &all {
        g.throughput(Throughput::Elements(qs.len() as u64));
        g.bench_function(name.as_str(), |b| {
            b.iter(|| {
                for q in qs {
                    black_box(run(*vf, black_box(q), &o));
                }
            })
        });
    }
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
