//! Kernel microbenchmarks: each `dhcd-kernels` kernel against its scalar reference.
//!
//! - `kernels/{sphere,aabb}_block/{scalar,simd}/<blocks>`: wide node tests (one volume
//!   against a block of 8, the children of an octree node), as the traversal calls them: the
//!   SIMD body inside one dispatch (`*_with`), never dispatched per test, the probe read from
//!   memory. Throughput in BV pairs. `<blocks>` sets how much node data a pass streams:
//!   64 blocks (12 KB of boxes, in L1: the armadillo frame's hierarchy holds 76), 512 (96 KB,
//!   in L2: the 80-146 K-triangle frames' hold 586-593) and 4,096 (768 KB, a hierarchy of
//!   about a million triangles).
//! - `kernels/leaf_contacts{,_self}/{scalar,simd}`: the narrow phase's kernel (boxes, shared
//!   vertices, separating planes, then the certified canonical form on the candidates) on
//!   1,024 pairs of leaves of 8 nearby triangles, throughput in triangle pairs. (Before the
//!   canonical form moved into the kernel this was `leaf_candidates`, the filter alone.)
//! - `kernels/<refit reduction>/{scalar,dispatched}/<n>`: refit reductions over `n` points;
//!   `dispatched` is the `*_with` body in a dispatch of its own per call.
//!
//! Inputs come from a seeded RNG and are generated once.
//!
//!     cargo bench --bench kernels -- --warm-up-time 1 --measurement-time 3
#![allow(clippy::needless_range_loop)]
use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion, Throughput};
use dhcd_kernels::narrow::{self, Pairing, TriSoa};
use dhcd_kernels::overlap::{self, AabbSoa, SphereSoa};
use dhcd_kernels::pulp::{Simd, WithSimd};
use dhcd_kernels::{reference, refit};
use dhcd_kernels::{Soa3, Tile};
use std::hint::black_box;

const SIZES: [usize; 2] = [1024, 16384];
/// Blocks per node-test bench (see the module doc), and the block size (an octree's
/// children).
const BLOCK_COUNTS: [usize; 3] = [64, 512, 4096];
const BLOCK: usize = 8;
/// Leaf pairs per narrow-filter bench, and triangles per leaf.
const LEAF_PAIRS: usize = 1024;
const LEAF: usize = 8;

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

/// Blocks of `BLOCK` spheres and boxes (each block one tile, as a node's children are
/// stored), and one probe per block; about a third of the pairs overlap. A probe is stored
/// like a node (the traversal reads it from its tile): a sphere `(c, r)` for the sphere
/// tests, and the box `c -+ r` around it for the box tests.
struct Blocks {
    sphere: Vec<f32>,
    boxes: Vec<f32>,
    probes: Vec<([f32; 3], f32)>,
    box_probes: Vec<([f32; 3], [f32; 3])>,
}

impl Blocks {
    fn new(rng: &mut Rng, blocks: usize) -> Self {
        let mut sphere = Vec::with_capacity(blocks * 4 * BLOCK);
        let mut boxes = Vec::with_capacity(blocks * 6 * BLOCK);
        for _ in 0..blocks {
            let c = [0; 3].map(|_| rng.vec(BLOCK, -1.0, 1.0));
            let r = rng.vec(BLOCK, 0.0, 0.5);
            for f in c.iter().chain([&r]) {
                sphere.extend_from_slice(f);
            }
            for f in 0..6 {
                let (a, s) = (f % 3, if f < 3 { -1.0 } else { 1.0 });
                boxes.extend((0..BLOCK).map(|i| c[a][i] + s * r[i] * 0.8));
            }
        }
        let probes: Vec<([f32; 3], f32)> = (0..blocks)
            .map(|_| ([0; 3].map(|_| rng.f32_in(-1.0, 1.0)), rng.f32_in(0.0, 0.5)))
            .collect();
        let box_probes = probes
            .iter()
            .map(|&(c, r)| (c.map(|c| c - r), c.map(|c| c + r)))
            .collect();
        Blocks {
            sphere,
            boxes,
            probes,
            box_probes,
        }
    }
    fn sphere(&self, k: usize) -> SphereSoa<'_> {
        let t = &self.sphere[k * 4 * BLOCK..(k + 1) * 4 * BLOCK];
        SphereSoa::new(Tile::new(t, BLOCK))
    }
    fn aabb(&self, k: usize) -> AabbSoa<'_> {
        let t = &self.boxes[k * 6 * BLOCK..(k + 1) * 6 * BLOCK];
        AabbSoa::new(Tile::new(t, BLOCK))
    }
}

/// Every block against its probe, scalar or SIMD, summing the bits (so nothing is elided).
struct AllBlocks<'a> {
    blocks: &'a Blocks,
    aabb: bool,
}

impl WithSimd for AllBlocks<'_> {
    type Output = u32;
    #[inline(always)]
    fn with_simd<S: Simd>(self, simd: S) -> u32 {
        let b = self.blocks;
        let mut hits = 0;
        if self.aabb {
            for (k, &(lo, hi)) in b.box_probes.iter().enumerate() {
                hits += overlap::aabb_block_with(simd, lo, hi, b.aabb(k), BLOCK).count_ones();
            }
        } else {
            for (k, &(c, r)) in b.probes.iter().enumerate() {
                hits += overlap::sphere_block_with(simd, c, r, b.sphere(k), BLOCK).count_ones();
            }
        }
        hits
    }
}

fn block_benches(c: &mut Criterion) {
    for (name, aabb) in [("sphere_block", false), ("aabb_block", true)] {
        let mut g = c.benchmark_group(format!("kernels/{name}"));
        for count in BLOCK_COUNTS {
            let blocks = Blocks::new(&mut Rng::new(1), count);
            g.throughput(Throughput::Elements((count * BLOCK) as u64));
            g.bench_function(BenchmarkId::new("scalar", count), |bench| {
                bench.iter(|| {
                    let mut hits = 0;
                    if aabb {
                        for (k, &(lo, hi)) in blocks.box_probes.iter().enumerate() {
                            hits += reference::aabb_block_scalar(lo, hi, blocks.aabb(k), BLOCK)
                                .count_ones();
                        }
                    } else {
                        for (k, &(c, r)) in blocks.probes.iter().enumerate() {
                            hits += reference::sphere_block_scalar(c, r, blocks.sphere(k), BLOCK)
                                .count_ones();
                        }
                    }
                    black_box(hits)
                })
            });
            g.bench_function(BenchmarkId::new("simd", count), |bench| {
                bench.iter(|| {
                    black_box(dhcd_kernels::arch().dispatch(AllBlocks {
                        blocks: black_box(&blocks),
                        aabb,
                    }))
                })
            });
        }
        g.finish();
    }
}

/// `LEAF_PAIRS` pairs of leaves of 8 nearby triangles (one tile per leaf, with corner
/// indices), as the narrow phase meets them.
struct LeafPairs {
    tiles: Vec<f32>,
    vertex: Vec<u32>,
}

impl LeafPairs {
    fn new(rng: &mut Rng) -> Self {
        let mut tiles = Vec::with_capacity(2 * LEAF_PAIRS * 15 * LEAF);
        let mut vertex = Vec::with_capacity(2 * LEAF_PAIRS * 3 * LEAF);
        for _ in 0..LEAF_PAIRS {
            let c = [0; 3].map(|_| rng.f32_in(-1.0, 1.0));
            for _ in 0..2 {
                let tris: Vec<[[f32; 3]; 3]> = (0..LEAF)
                    .map(|_| [0; 3].map(|_| [0, 1, 2].map(|k| c[k] + rng.f32_in(-0.3, 0.3))))
                    .collect();
                for f in 0..15 {
                    tiles.extend(tris.iter().map(|t| match f {
                        0..9 => t[f / 3][f % 3],
                        9..12 => t[0][f - 9].min(t[1][f - 9]).min(t[2][f - 9]),
                        _ => t[0][f - 12].max(t[1][f - 12]).max(t[2][f - 12]),
                    }));
                }
                vertex.extend((0..3 * LEAF).map(|_| rng.below(4000)));
            }
        }
        LeafPairs { tiles, vertex }
    }
    /// Leaf `l` (of `2 * LEAF_PAIRS`).
    fn leaf(&self, l: usize) -> TriSoa<'_> {
        let t = &self.tiles[l * 15 * LEAF..(l + 1) * 15 * LEAF];
        let v = &self.vertex[l * 3 * LEAF..(l + 1) * 3 * LEAF];
        TriSoa::new(Tile::new(t, LEAF), v)
    }
}

struct AllLeafPairs<'a> {
    leaves: &'a LeafPairs,
    pairing: Pairing,
}

impl WithSimd for AllLeafPairs<'_> {
    type Output = u64;
    #[inline(always)]
    fn with_simd<S: Simd>(self, simd: S) -> u64 {
        let mut rows = [narrow::Row::default(); LEAF];
        let mut n = 0;
        for p in 0..LEAF_PAIRS {
            let (a, b) = (self.leaves.leaf(2 * p), self.leaves.leaf(2 * p + 1));
            narrow::leaf_contacts_with(simd, a, LEAF, b, LEAF, self.pairing, &mut rows);
            n += rows
                .iter()
                .map(|r| r.candidates().count_ones() as u64)
                .sum::<u64>();
        }
        n
    }
}

fn leaf_benches(c: &mut Criterion) {
    let leaves = LeafPairs::new(&mut Rng::new(2));
    for (name, pairing) in [
        ("leaf_contacts", Pairing::All),
        ("leaf_contacts_self", Pairing::NoSharedVertex),
    ] {
        let mut g = c.benchmark_group(format!("kernels/{name}"));
        g.throughput(Throughput::Elements((LEAF_PAIRS * LEAF * LEAF) as u64));
        g.bench_function("scalar", |bench| {
            bench.iter(|| {
                let mut rows = [narrow::Row::default(); LEAF];
                let mut n = 0;
                for p in 0..LEAF_PAIRS {
                    let (a, b) = (leaves.leaf(2 * p), leaves.leaf(2 * p + 1));
                    reference::leaf_contacts_scalar(a, LEAF, b, LEAF, pairing, &mut rows);
                    n += rows
                        .iter()
                        .map(|r| r.candidates().count_ones() as u64)
                        .sum::<u64>();
                }
                black_box(n)
            })
        });
        g.bench_function("simd", |bench| {
            bench.iter(|| {
                black_box(dhcd_kernels::arch().dispatch(AllLeafPairs {
                    leaves: black_box(&leaves),
                    pairing,
                }))
            })
        });
        g.finish();
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

/// A refit reduction for [`Dispatched`].
#[derive(Clone, Copy)]
enum Reduction {
    MaxDistSq,
    MaxDistSqIndexed,
    Sum,
    SumIndexed,
    Bounds,
    BoundsIndexed,
}

/// One refit reduction (`*_with`) in a dispatch of its own.
struct Dispatched<'a> {
    r: Reduction,
    p: Soa3<'a>,
    idx: &'a [u32],
    c: [f32; 3],
}

impl WithSimd for Dispatched<'_> {
    type Output = [f32; 6];
    #[inline(always)]
    fn with_simd<S: Simd>(self, simd: S) -> [f32; 6] {
        let (p, idx, c) = (self.p, self.idx, self.c);
        match self.r {
            Reduction::MaxDistSq => [refit::max_dist_sq_with(simd, p, c); 6],
            Reduction::MaxDistSqIndexed => [refit::max_dist_sq_indexed_with(simd, p, idx, c); 6],
            Reduction::Sum => s3(refit::sum_with(simd, p)),
            Reduction::SumIndexed => s3(refit::sum_indexed_with(simd, p, idx)),
            Reduction::Bounds => flat(refit::bounds_with(simd, p)),
            Reduction::BoundsIndexed => flat(refit::bounds_indexed_with(simd, p, idx)),
        }
    }
}

/// `r` around the centre `c`, dispatched per call.
fn dispatched(r: Reduction, c: [f32; 3]) -> impl Fn(Soa3, &[u32]) -> [f32; 6] {
    move |p, idx| dhcd_kernels::arch().dispatch(Dispatched { r, p, idx, c })
}

fn refit_benches(c: &mut Criterion) {
    let ctr = [0.1, -0.05, 0.2];
    bench_refit(
        c,
        "max_dist_sq",
        &|p, _| [reference::max_dist_sq_scalar_lanes(p, ctr, 1); 6],
        &dispatched(Reduction::MaxDistSq, ctr),
    );
    bench_refit(
        c,
        "max_dist_sq_indexed",
        &|p, i| [reference::max_dist_sq_indexed_scalar_lanes(p, i, ctr, 1); 6],
        &dispatched(Reduction::MaxDistSqIndexed, ctr),
    );
    bench_refit(
        c,
        "sum",
        &|p, _| s3(reference::sum_scalar_lanes(p, 1)),
        &dispatched(Reduction::Sum, ctr),
    );
    bench_refit(
        c,
        "sum_indexed",
        &|p, i| s3(reference::sum_indexed_scalar_lanes(p, i, 1)),
        &dispatched(Reduction::SumIndexed, ctr),
    );
    bench_refit(
        c,
        "bounds",
        &|p, _| flat(reference::bounds_scalar_lanes(p, 1)),
        &dispatched(Reduction::Bounds, ctr),
    );
    bench_refit(
        c,
        "bounds_indexed",
        &|p, i| flat(reference::bounds_indexed_scalar_lanes(p, i, 1)),
        &dispatched(Reduction::BoundsIndexed, ctr),
    );
}

criterion_group!(benches, block_benches, leaf_benches, refit_benches);
criterion_main!(benches);
