//! Per-call cost of the exact proximity primitives (`dhcd::distance`).
//!
//! Inputs are generated once from a seeded generator: unit-size triangles (edges) with
//! jittered shapes, and a point (second edge) placed in the first one's box grown by `d`, as
//! a box cull with margin `d` hands them over. They are sorted by their true distance into
//! three sets of 4096 calls each:
//!
//! - `far`: farther than `d` (what most culled candidates are);
//! - `near`: farther than `d` by at most 10% (near misses: the filter works hardest);
//! - `within`: at most `d` (the pairs a proximity query reports, value and type computed);
//! - `tie`: exact ties the float filter cannot decide (a point exactly above a triangle's
//!   edge, parallel overlapping edges; integer coordinates), the exact tiers' cost (checked
//!   floats decide these: every operation on small integers is exact).
//!
//! The points are stored once in a position array and each call gathers its 4 points by
//! index, as a proximity query's inner loop does (`x[v]`, `x[t[0]]`, ...).
//!
//! Ids: `distance/{point_triangle,edge_edge}/{far,near,within,tie}`, throughput in calls, so
//! criterion prints the time per call. Run: `cargo bench --bench distance`.

use std::hint::black_box;

use criterion::{criterion_group, Criterion, Throughput};
use dhcd::distance::{edge_edge_distance_sq, edge_edge_within, point_triangle_within};

type P = [f64; 3];

/// xorshift64*: a seeded, dependency-free generator.
struct Rng(u64);

impl Rng {
    fn unit(&mut self) -> f64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        let x = self.0.wrapping_mul(0x2545_f491_4f6c_dd1d);
        (x >> 11) as f64 / (1u64 << 53) as f64
    }
    fn range(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * self.unit()
    }
    fn point(&mut self, lo: f64, hi: f64) -> P {
        [self.range(lo, hi), self.range(lo, hi), self.range(lo, hi)]
    }
}

/// The threshold: about a tenth of a feature's size, like IPC's `dhat` against its meshes'
/// edge lengths.
const D: f64 = 0.1;
const N: usize = 4096;

fn boxed(pts: &[P]) -> (P, P) {
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    for p in pts {
        for k in 0..3 {
            lo[k] = lo[k].min(p[k]);
            hi[k] = hi[k].max(p[k]);
        }
    }
    (lo, hi)
}

/// Point-triangle inputs by set: `[far, near, within]`.
fn point_triangle_sets() -> [Vec<(P, [P; 3])>; 3] {
    let mut rng = Rng(0x9e37_79b9_7f4a_7c15);
    let mut sets: [Vec<(P, [P; 3])>; 3] = Default::default();
    while sets.iter().any(|s| s.len() < N) {
        let t = [
            rng.point(-0.5, 0.5),
            rng.point(-0.5, 0.5),
            rng.point(-0.5, 0.5),
        ];
        // Flatten half of them towards a plane, as mesh neighbourhoods are.
        let (lo, hi) = boxed(&t);
        let p = [0, 1, 2].map(|k| rng.range(lo[k] - D, hi[k] + D));
        let (d2, _) = dhcd::distance::point_triangle_distance_sq(p, t);
        let dist = d2.sqrt();
        let set = if dist <= D {
            2
        } else if dist <= 1.1 * D {
            1
        } else {
            0
        };
        if sets[set].len() < N {
            sets[set].push((p, t));
        }
    }
    sets
}

/// Edge-edge inputs by set: `[far, near, within]`.
fn edge_edge_sets() -> [Vec<[P; 4]>; 3] {
    let mut rng = Rng(0x2545_f491_4f6c_dd1d);
    let mut sets: [Vec<[P; 4]>; 3] = Default::default();
    while sets.iter().any(|s| s.len() < N) {
        let a = [rng.point(-0.5, 0.5), rng.point(-0.5, 0.5)];
        let (lo, hi) = boxed(&a);
        let b0 = [0, 1, 2].map(|k| rng.range(lo[k] - D, hi[k] + D));
        let dir = rng.point(-0.5, 0.5);
        let b1 = [0, 1, 2].map(|k| b0[k] + dir[k]);
        let e = [a[0], a[1], b0, b1];
        let (d2, _) = edge_edge_distance_sq(e[0], e[1], e[2], e[3]);
        let dist = d2.sqrt();
        let set = if dist <= D {
            2
        } else if dist <= 1.1 * D {
            1
        } else {
            0
        };
        if sets[set].len() < N {
            sets[set].push(e);
        }
    }
    sets
}

/// Exact ties, which the float filter cannot decide and the checked floats do: a point
/// exactly above an edge of an axis-aligned right triangle (integer coordinates), with `d`
/// near its distance.
fn point_triangle_ties() -> Vec<(P, [P; 3], f64)> {
    let mut rng = Rng(0x1234_5678_9abc_def1);
    let mut int = |lo: f64, hi: f64| rng.range(lo, hi).floor();
    (0..N)
        .map(|_| {
            let (a, b) = (int(2.0, 100.0), int(2.0, 100.0));
            let (x, h) = (int(1.0, a), int(1.0, 10.0));
            let o = [int(-50.0, 50.0), int(-50.0, 50.0), int(-50.0, 50.0)];
            let at = |v: P| [v[0] + o[0], v[1] + o[1], v[2] + o[2]];
            let t = [at([0.0, 0.0, 0.0]), at([a, 0.0, 0.0]), at([0.0, b, 0.0])];
            let d = h * int(5.0, 20.0) / 10.0;
            (at([x, 0.0, h]), t, d)
        })
        .collect()
}

/// Exact ties for edges: parallel overlapping edges at an integer distance.
fn edge_edge_ties() -> Vec<([P; 4], f64)> {
    let mut rng = Rng(0x0fed_cba9_8765_4321);
    let mut int = |lo: f64, hi: f64| rng.range(lo, hi).floor();
    (0..N)
        .map(|_| {
            let (l, s, l2, h) = (
                int(2.0, 50.0),
                int(-20.0, 20.0),
                int(2.0, 50.0),
                int(1.0, 10.0),
            );
            let d = h * int(5.0, 20.0) / 10.0;
            (
                [
                    [0.0, 0.0, 0.0],
                    [l, 0.0, 0.0],
                    [s, h, 0.0],
                    [s + l2, h, 0.0],
                ],
                d,
            )
        })
        .collect()
}

const NAMES: [&str; 3] = ["far", "near", "within"];

/// A set of calls as a position array and the 4 point indices of each call.
struct Calls {
    x: Vec<P>,
    idx: Vec<[u32; 4]>,
}

impl Calls {
    /// In order: the data (384 KiB a set) streams from cache, so the time is the
    /// primitive's, not the memory's.
    fn new(pts: impl Iterator<Item = [P; 4]>) -> Self {
        let mut x = Vec::new();
        let mut idx = Vec::new();
        for q in pts {
            let i = x.len() as u32;
            x.extend(q);
            idx.push([i, i + 1, i + 2, i + 3]);
        }
        Self { x, idx }
    }
}

fn bench(c: &mut Criterion) {
    let mut g = c.benchmark_group("distance/point_triangle");
    for (name, set) in NAMES.iter().zip(point_triangle_sets()) {
        let calls = Calls::new(set.into_iter().map(|(p, t)| [p, t[0], t[1], t[2]]));
        g.throughput(Throughput::Elements(calls.idx.len() as u64));
        g.bench_function(*name, |b| {
            b.iter(|| {
                let (x, d) = (&calls.x, black_box(D));
                let mut hits = 0usize;
                for &[i, a, b, c] in &calls.idx {
                    let t = [x[a as usize], x[b as usize], x[c as usize]];
                    hits += usize::from(point_triangle_within(x[i as usize], t, d).is_some());
                }
                hits
            })
        });
    }
    let ties = point_triangle_ties();
    g.throughput(Throughput::Elements(ties.len() as u64));
    g.bench_function("tie", |b| {
        b.iter(|| {
            let mut hits = 0usize;
            for (p, t, d) in &ties {
                hits += usize::from(point_triangle_within(*p, *t, black_box(*d)).is_some());
            }
            hits
        })
    });
    g.finish();
    let mut g = c.benchmark_group("distance/edge_edge");
    for (name, set) in NAMES.iter().zip(edge_edge_sets()) {
        let calls = Calls::new(set.into_iter());
        g.throughput(Throughput::Elements(calls.idx.len() as u64));
        g.bench_function(*name, |b| {
            b.iter(|| {
                let (x, d) = (&calls.x, black_box(D));
                let mut hits = 0usize;
                for &[a0, a1, b0, b1] in &calls.idx {
                    let [a0, a1, b0, b1] = [a0, a1, b0, b1].map(|i| x[i as usize]);
                    hits += usize::from(edge_edge_within(a0, a1, b0, b1, d).is_some());
                }
                hits
            })
        });
    }
    let ties = edge_edge_ties();
    g.throughput(Throughput::Elements(ties.len() as u64));
    g.bench_function("tie", |b| {
        b.iter(|| {
            let mut hits = 0usize;
            for ([a0, a1, b0, b1], d) in &ties {
                hits += usize::from(edge_edge_within(*a0, *a1, *b0, *b1, black_box(*d)).is_some());
            }
            hits
        })
    });
    g.finish();
}

criterion_group!(benches, bench);

/// The primitive out of line, to read its code (`objdump -d`, `pt_probe`).
#[inline(never)]
fn pt_probe(p: P, t: [P; 3], d: f64) -> Option<(f64, dhcd::distance::PointTriangle)> {
    point_triangle_within(p, t, d)
}

/// `DISTANCE_CALLS=<set> <reps>` (e.g. `point_triangle/far 10`) runs the set's calls `reps`
/// times and exits, for counting instructions under valgrind (`valgrind --tool=cachegrind
/// --branch-sim=yes`): the difference between two rep counts over the calls made is the cost
/// per call, independent of the machine's load. Otherwise, criterion.
fn main() {
    if let Ok(spec) = std::env::var("DISTANCE_CALLS") {
        let (name, reps) = spec.split_once(' ').expect("<set> <reps>");
        let reps: usize = reps.parse().expect("reps");
        let (kind, set) = name.split_once('/').expect("<kind>/<set>");
        let which = NAMES
            .iter()
            .position(|n| *n == set)
            .expect("far, near or within");
        let mut hits = 0usize;
        if kind == "point_triangle" {
            let calls = Calls::new(
                point_triangle_sets()[which]
                    .iter()
                    .map(|(p, t)| [*p, t[0], t[1], t[2]]),
            );
            for _ in 0..reps {
                for &[i, a, b, c] in &calls.idx {
                    let x = &calls.x;
                    let t = [x[a as usize], x[b as usize], x[c as usize]];
                    hits += usize::from(pt_probe(x[i as usize], t, black_box(D)).is_some());
                }
            }
        } else {
            let calls = Calls::new(edge_edge_sets()[which].iter().copied());
            for _ in 0..reps {
                for &[a0, a1, b0, b1] in &calls.idx {
                    let [a0, a1, b0, b1] = [a0, a1, b0, b1].map(|i| calls.x[i as usize]);
                    hits += usize::from(edge_edge_within(a0, a1, b0, b1, black_box(D)).is_some());
                }
            }
        }
        println!("{hits}");
        return;
    }
    benches();
    Criterion::default().configure_from_args().final_summary();
}
