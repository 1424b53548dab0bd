//! Narrow-phase cost per triangle pair on a realistic mix.
//!
//! Two jittered UV spheres (radius 1, ~2k triangles each) overlapping by a third of their
//! diameter. The candidate pairs are those whose triangle boxes, inflated by a margin of
//! about one triangle size, overlap: what a hierarchy with small leaves hands to the narrow
//! phase. Most are near-misses; a few percent intersect.
//!
//! Run: `cargo bench --bench narrow`. Time per iteration / pair count = ns per pair (the
//! pair count and hit rate are printed once).

use std::hint::black_box;

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use dhcd::narrow::{intersection_segment, triangles_intersect};

type Tri = [[f32; 3]; 3];

/// xorshift64*: a seeded, dependency-free generator.
struct Rng(u64);

impl Rng {
    fn next_f32(&mut self) -> f32 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        let x = self.0.wrapping_mul(0x2545_f491_4f6c_dd1d);
        (x >> 40) as f32 / (1u64 << 24) as f32
    }
}

fn sphere(center: [f32; 3], rings: u32, segments: u32, rng: &mut Rng) -> Vec<Tri> {
    let mut pos = Vec::new();
    for r in 0..=rings {
        let theta = std::f32::consts::PI * r as f32 / rings as f32;
        for s in 0..segments {
            let phi = 2.0 * std::f32::consts::PI * s as f32 / segments as f32;
            let rad = 1.0 + 0.02 * (rng.next_f32() - 0.5);
            pos.push([
                center[0] + rad * theta.sin() * phi.cos(),
                center[1] + rad * theta.sin() * phi.sin(),
                center[2] + rad * theta.cos(),
            ]);
        }
    }
    let v = |r: u32, s: u32| pos[(r * segments + s % segments) as usize];
    let mut tris = Vec::new();
    for r in 0..rings {
        for s in 0..segments {
            if r > 0 {
                tris.push([v(r, s), v(r + 1, s), v(r, s + 1)]);
            }
            if r + 1 < rings {
                tris.push([v(r, s + 1), v(r + 1, s), v(r + 1, s + 1)]);
            }
        }
    }
    tris
}

fn bbox(t: &Tri, margin: f32) -> [[f32; 3]; 2] {
    let mut b = [t[0], t[0]];
    for p in &t[1..] {
        for k in 0..3 {
            b[0][k] = b[0][k].min(p[k]);
            b[1][k] = b[1][k].max(p[k]);
        }
    }
    [b[0].map(|c| c - margin), b[1].map(|c| c + margin)]
}

fn candidate_pairs() -> Vec<(Tri, Tri)> {
    let mut rng = Rng(0x9e37_79b9_7f4a_7c15);
    let a = sphere([0.0, 0.0, 0.0], 32, 64, &mut rng);
    let b = sphere([1.35, 0.2, 0.1], 32, 64, &mut rng);
    let margin = 0.05;
    let bb: Vec<_> = b.iter().map(|t| bbox(t, margin)).collect();
    let mut pairs = Vec::new();
    for ta in &a {
        let ba = bbox(ta, margin);
        for (tb, bb) in b.iter().zip(&bb) {
            if (0..3).all(|k| ba[1][k] >= bb[0][k] && bb[1][k] >= ba[0][k]) {
                pairs.push((*ta, *tb));
            }
        }
    }
    pairs
}

fn bench(c: &mut Criterion) {
    let pairs = candidate_pairs();
    let hits = pairs
        .iter()
        .filter(|(a, b)| triangles_intersect(a, b))
        .count();
    println!(
        "narrow: {} candidate pairs, {} intersect ({:.1}%)",
        pairs.len(),
        hits,
        100.0 * hits as f64 / pairs.len() as f64
    );
    let hitting: Vec<_> = pairs
        .iter()
        .filter(|(a, b)| triangles_intersect(a, b))
        .copied()
        .collect();

    let mut g = c.benchmark_group("narrow");
    g.throughput(Throughput::Elements(pairs.len() as u64));
    g.bench_function("tritri", |bch| {
        bch.iter(|| {
            let mut n = 0u32;
            for (a, b) in black_box(&pairs) {
                n += u32::from(triangles_intersect(a, b));
            }
            n
        })
    });
    g.throughput(Throughput::Elements(hitting.len() as u64));
    g.bench_function("tritri_on_hits", |bch| {
        bch.iter(|| {
            let mut n = 0u32;
            for (a, b) in black_box(&hitting) {
                n += u32::from(triangles_intersect(a, b));
            }
            n
        })
    });
    g.bench_function("segment_on_hits", |bch| {
        bch.iter(|| {
            let mut acc = 0.0f32;
            for (a, b) in black_box(&hitting) {
                if let Some(s) = intersection_segment(a, b) {
                    acc += s[0][0];
                }
            }
            acc
        })
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
