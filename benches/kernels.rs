//! Kernel microbenchmarks: each `dhcd-kernels` kernel, scalar reference against the
//! runtime-dispatched SIMD entry, at 1,024 and 16,384 elements (pairs, points or triangles).
//! Ids: `kernels/<kernel>/{scalar,dispatched}/<n>`, throughput in elements per second.
//! Inputs come from a seeded RNG and are generated once per size.
//!
//!     cargo bench --bench kernels -- --warm-up-time 1 --measurement-time 3
use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion, Throughput};
use dhcd_kernels::narrow::{self, AabbSoaMut};
use dhcd_kernels::overlap::{self, AabbSoa, DhSoa, SphereSoa};
use dhcd_kernels::refit;
use dhcd_kernels::Soa3;
use std::hint::black_box;

const SIZES: [usize; 2] = [1024, 16384];
/// Nodes per hierarchy in the overlap benches (a 5-level octree has at most 4,681 nodes).
const NODES: usize = 4096;
/// Vertices per mesh (the paper's pawn has 3,490).
const VERTICES: usize = 3490;

/// xorshift64*.
struct Rng(u64);

impl Rng {
    fn new(seed: u64) -> Self {
        Rng(seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) | 1)
    }
    fn next_u64(&mut self) -> u64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        self.0.wrapping_mul(0x2545_F491_4F6C_DD1D)
    }
    fn below(&mut self, n: usize) -> u32 {
        (self.next_u64() % n as u64) as u32
    }
    fn f32_in(&mut self, lo: f32, hi: f32) -> f32 {
        lo + (hi - lo) * ((self.next_u64() >> 40) as f32 / (1u64 << 24) as f32)
    }
    fn vec(&mut self, n: usize, lo: f32, hi: f32) -> Vec<f32> {
        (0..n).map(|_| self.f32_in(lo, hi)).collect()
    }
    fn idx(&mut self, n: usize, below: usize) -> Vec<u32> {
        (0..n).map(|_| self.below(below)).collect()
    }
}

struct Side {
    c: [Vec<f32>; 3],
    r: Vec<f32>,
    vertex: Vec<u32>,
    p: [Vec<f32>; 3],
    bmin: [Vec<f32>; 3],
    bmax: [Vec<f32>; 3],
}

impl Side {
    fn new(rng: &mut Rng) -> Self {
        let c = [0; 3].map(|_| rng.vec(NODES, -1.0, 1.0));
        // Radii so that roughly a third of random pairs overlap.
        let r = rng.vec(NODES, 0.0, 0.5);
        let vertex = rng.idx(NODES, VERTICES);
        let p = [0; 3].map(|_| rng.vec(VERTICES, -1.0, 1.0));
        let h = [0; 3].map(|_| rng.vec(NODES, 0.0, 0.6));
        let bmin = core::array::from_fn(|a| (0..NODES).map(|i| c[a][i] - h[a][i]).collect());
        let bmax = core::array::from_fn(|a| (0..NODES).map(|i| c[a][i] + h[a][i]).collect());
        Side {
            c,
            r,
            vertex,
            p,
            bmin,
            bmax,
        }
    }
    fn sphere(&self) -> SphereSoa<'_> {
        SphereSoa {
            cx: &self.c[0],
            cy: &self.c[1],
            cz: &self.c[2],
            r: &self.r,
        }
    }
    fn dh(&self) -> DhSoa<'_> {
        DhSoa {
            vertex: &self.vertex,
            r: &self.r,
            points: Soa3::new(&self.p[0], &self.p[1], &self.p[2]),
        }
    }
    fn aabb(&self) -> AabbSoa<'_> {
        AabbSoa {
            min_x: &self.bmin[0],
            min_y: &self.bmin[1],
            min_z: &self.bmin[2],
            max_x: &self.bmax[0],
            max_y: &self.bmax[1],
            max_z: &self.bmax[2],
        }
    }
}

type PairFn<'a> = dyn Fn(&[u32], &[u32], &mut [u32]) -> usize + 'a;

fn bench_pairs(c: &mut Criterion, name: &str, scalar: &PairFn, dispatched: &PairFn) {
    let mut g = c.benchmark_group(format!("kernels/{name}"));
    for n in SIZES {
        let mut rng = Rng::new(n as u64);
        let (ia, ib) = (rng.idx(n, NODES), rng.idx(n, NODES));
        let mut out = vec![0u32; n];
        assert_eq!(scalar(&ia, &ib, &mut out), dispatched(&ia, &ib, &mut out));
        g.throughput(Throughput::Elements(n as u64));
        g.bench_function(BenchmarkId::new("scalar", n), |b| {
            b.iter(|| scalar(black_box(&ia), black_box(&ib), black_box(&mut out)))
        });
        g.bench_function(BenchmarkId::new("dispatched", n), |b| {
            b.iter(|| dispatched(black_box(&ia), black_box(&ib), black_box(&mut out)))
        });
    }
    g.finish();
}

fn overlap_benches(c: &mut Criterion) {
    let mut rng = Rng::new(42);
    let (a, b) = (Side::new(&mut rng), Side::new(&mut rng));
    bench_pairs(
        c,
        "sphere_pairs",
        &|ia, ib, out| overlap::sphere_pairs_scalar(a.sphere(), b.sphere(), ia, ib, out),
        &|ia, ib, out| overlap::sphere_pairs(a.sphere(), b.sphere(), ia, ib, out),
    );
    bench_pairs(
        c,
        "dh_pairs",
        &|ia, ib, out| overlap::dh_pairs_scalar(a.dh(), b.dh(), ia, ib, out),
        &|ia, ib, out| overlap::dh_pairs(a.dh(), b.dh(), ia, ib, out),
    );
    bench_pairs(
        c,
        "aabb_pairs",
        &|ia, ib, out| overlap::aabb_pairs_scalar(a.aabb(), b.aabb(), ia, ib, out),
        &|ia, ib, out| overlap::aabb_pairs_vectorized(a.aabb(), b.aabb(), ia, ib, out),
    );
    bench_pairs(
        c,
        "tri_aabb_overlap_pairs",
        &|ia, ib, out| narrow::tri_aabb_overlap_pairs_scalar(a.aabb(), b.aabb(), ia, ib, out),
        &|ia, ib, out| narrow::tri_aabb_overlap_pairs(a.aabb(), b.aabb(), ia, ib, out),
    );

    // One box against a contiguous run of n boxes (no gather).
    let mut g = c.benchmark_group("kernels/tri_aabb_overlap_row");
    for n in SIZES {
        let mut rng = Rng::new(7 + n as u64);
        let side = BigBoxes::new(&mut rng, n);
        let bx = ([-0.2f32, -0.1, 0.0], [0.3f32, 0.2, 0.4]);
        let mut out = vec![0u32; n];
        g.throughput(Throughput::Elements(n as u64));
        g.bench_function(BenchmarkId::new("scalar", n), |b| {
            b.iter(|| {
                narrow::tri_aabb_overlap_row_scalar(black_box(bx), side.soa(), black_box(&mut out))
            })
        });
        g.bench_function(BenchmarkId::new("dispatched", n), |b| {
            b.iter(|| narrow::tri_aabb_overlap_row(black_box(bx), side.soa(), black_box(&mut out)))
        });
    }
    g.finish();
}

struct BigBoxes([Vec<f32>; 6]);

impl BigBoxes {
    fn new(rng: &mut Rng, n: usize) -> Self {
        let c = [0; 3].map(|_| rng.vec(n, -1.0, 1.0));
        let h = [0; 3].map(|_| rng.vec(n, 0.0, 0.3));
        BigBoxes(core::array::from_fn(|f| {
            let a = f % 3;
            let s = if f < 3 { -1.0 } else { 1.0 };
            (0..n).map(|i| c[a][i] + s * h[a][i]).collect()
        }))
    }
    fn soa(&self) -> AabbSoa<'_> {
        let f = &self.0;
        AabbSoa {
            min_x: &f[0],
            min_y: &f[1],
            min_z: &f[2],
            max_x: &f[3],
            max_y: &f[4],
            max_z: &f[5],
        }
    }
}

type RefitFn<'a> = dyn Fn(Soa3, &[u32]) -> [f32; 6] + 'a;

/// `idx` names `n` random points of the same `n`-point cloud (indexed kernels only).
fn bench_refit(c: &mut Criterion, name: &str, scalar: &RefitFn, dispatched: &RefitFn) {
    let mut g = c.benchmark_group(format!("kernels/{name}"));
    for n in SIZES {
        let mut rng = Rng::new(100 + n as u64);
        let p = [0; 3].map(|_| rng.vec(n, -1.0, 1.0));
        let idx = rng.idx(n, n);
        let pts = Soa3::new(&p[0], &p[1], &p[2]);
        g.throughput(Throughput::Elements(n as u64));
        g.bench_function(BenchmarkId::new("scalar", n), |b| {
            b.iter(|| scalar(black_box(pts), black_box(&idx)))
        });
        g.bench_function(BenchmarkId::new("dispatched", n), |b| {
            b.iter(|| dispatched(black_box(pts), black_box(&idx)))
        });
    }
    g.finish();
}

fn flat(b: ([f32; 3], [f32; 3])) -> [f32; 6] {
    [b.0[0], b.0[1], b.0[2], b.1[0], b.1[1], b.1[2]]
}

fn s3(s: [f32; 3]) -> [f32; 6] {
    [s[0], s[1], s[2], 0.0, 0.0, 0.0]
}

fn refit_benches(c: &mut Criterion) {
    let ctr = [0.1, -0.05, 0.2];
    bench_refit(
        c,
        "max_dist_sq",
        &|p, _| [refit::max_dist_sq_scalar(p, ctr); 6],
        &|p, _| [refit::max_dist_sq(p, ctr); 6],
    );
    bench_refit(
        c,
        "max_dist_sq_indexed",
        &|p, i| [refit::max_dist_sq_indexed_scalar(p, i, ctr); 6],
        &|p, i| [refit::max_dist_sq_indexed(p, i, ctr); 6],
    );
    bench_refit(c, "sum", &|p, _| s3(refit::sum_scalar(p)), &|p, _| {
        s3(refit::sum(p))
    });
    bench_refit(
        c,
        "sum_indexed",
        &|p, i| s3(refit::sum_indexed_scalar(p, i)),
        &|p, i| s3(refit::sum_indexed(p, i)),
    );
    bench_refit(
        c,
        "bounds",
        &|p, _| flat(refit::bounds_scalar(p)),
        &|p, _| flat(refit::bounds(p)),
    );
    bench_refit(
        c,
        "bounds_indexed",
        &|p, i| flat(refit::bounds_indexed_scalar(p, i)),
        &|p, i| flat(refit::bounds_indexed(p, i)),
    );
}

fn out(o: &mut [Vec<f32>; 6]) -> AabbSoaMut<'_> {
    let [a, b, c, d, e, f] = o;
    AabbSoaMut {
        min_x: a,
        min_y: b,
        min_z: c,
        max_x: d,
        max_y: e,
        max_z: f,
    }
}

fn narrow_benches(c: &mut Criterion) {
    let mut g = c.benchmark_group("kernels/triangle_bounds");
    let mut rng = Rng::new(9);
    let p = [0; 3].map(|_| rng.vec(VERTICES, -1.0, 1.0));
    let pts = Soa3::new(&p[0], &p[1], &p[2]);
    for n in SIZES {
        let tris: Vec<[u32; 3]> = (0..n)
            .map(|_| [0; 3].map(|_| rng.below(VERTICES)))
            .collect();
        let mut o: [Vec<f32>; 6] = core::array::from_fn(|_| vec![0.0; n]);
        g.throughput(Throughput::Elements(n as u64));
        g.bench_function(BenchmarkId::new("scalar", n), |b| {
            b.iter(|| narrow::triangle_bounds_scalar(black_box(pts), black_box(&tris), out(&mut o)))
        });
        g.bench_function(BenchmarkId::new("dispatched", n), |b| {
            b.iter(|| narrow::triangle_bounds(black_box(pts), black_box(&tris), out(&mut o)))
        });
    }
    g.finish();
}

criterion_group!(benches, overlap_benches, refit_benches, narrow_benches);
criterion_main!(benches);
