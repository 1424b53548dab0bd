//! Every kernel against its scalar reference, bit for bit, on `pulp::Scalar`, `Scalar128b`,
//! `Scalar256b`, `Scalar512b`, the native x86 backends present on this machine, and the
//! dispatched backend (through `*_with`, and through `refit::bounds`, the one dispatching
//! entry).

#![allow(clippy::needless_range_loop)]

use dhcd_kernels::apart;
use dhcd_kernels::narrow;
use dhcd_kernels::overlap::{self, AabbSoa, SphereSoa};
use dhcd_kernels::pulp::{self, Simd, WithSimd};
use dhcd_kernels::{reference, refit};
use dhcd_kernels::{Soa3, Tile};

/// xorshift64*: small, deterministic, good enough for test data.
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
    fn below(&mut self, n: usize) -> usize {
        (self.next_u64() % n as u64) as usize
    }
    /// Uniform in `[lo, hi)`.
    fn f32_in(&mut self, lo: f32, hi: f32) -> f32 {
        let u = (self.next_u64() >> 40) as f32 / (1u64 << 24) as f32;
        lo + (hi - lo) * u
    }
}

const SPECIALS: [f32; 8] = [
    0.0,
    -0.0,
    f32::INFINITY,
    f32::NEG_INFINITY,
    f32::NAN,
    1.0,
    -1.0,
    0.5,
];

/// Random values in `[-1, 1)`, with every `every`-th value (if `every > 0`) a special one.
fn values(rng: &mut Rng, n: usize, every: usize) -> Vec<f32> {
    (0..n)
        .map(|i| {
            if every > 0 && i % every == every - 1 {
                SPECIALS[rng.below(SPECIALS.len())]
            } else {
                rng.f32_in(-1.0, 1.0)
            }
        })
        .collect()
}

fn sizes(lanes: usize) -> Vec<usize> {
    let mut s = vec![
        0,
        1,
        lanes.saturating_sub(1),
        lanes,
        lanes + 1,
        2 * lanes + 3,
        1000,
        1037,
    ];
    s.dedup();
    s
}

/// Bit patterns, with every NaN mapped to one canonical NaN: NaN payloads and signs are not
/// specified by IEEE arithmetic (x86 makes `inf - inf` a negative NaN, and which operand's
/// NaN propagates depends on the instruction's operand order, which the compiler may swap).
fn bits(x: f32) -> u32 {
    if x.is_nan() {
        f32::NAN.to_bits()
    } else {
        x.to_bits()
    }
}

fn bits3(v: [f32; 3]) -> [u32; 3] {
    v.map(bits)
}

fn bits_box(b: ([f32; 3], [f32; 3])) -> ([u32; 3], [u32; 3]) {
    (bits3(b.0), bits3(b.1))
}

/// Runs `$check(simd)` on every backend, then through `Arch` dispatch.
macro_rules! on_all_backends {
    ($check:ident) => {{
        $check(pulp::Scalar::new());
        $check(pulp::Scalar128b);
        $check(pulp::Scalar256b);
        $check(pulp::Scalar512b);
        #[cfg(target_arch = "x86_64")]
        {
            if let Some(s) = pulp::x86::V3::try_new() {
                $check(s);
            }
            if let Some(s) = pulp::x86::V4::try_new() {
                $check(s);
            }
        }
        struct Run;
        impl WithSimd for Run {
            type Output = ();
            fn with_simd<S: Simd>(self, simd: S) {
                $check(simd)
            }
        }
        pulp::Arch::new().dispatch(Run);
    }};
}

// ---------------------------------------------------------------------------------------
// overlap: wide node tests (one volume against a block)

fn spheres(rng: &mut Rng, n: usize, every: usize) -> [Vec<f32>; 4] {
    let r = (0..n)
        .map(|i| {
            if every > 0 && i % every == 1 {
                [0.0, -0.0, f32::INFINITY, f32::NAN][rng.below(4)]
            } else {
                rng.f32_in(0.0, 0.6)
            }
        })
        .collect();
    [
        values(rng, n, every),
        values(rng, n, every),
        values(rng, n, every),
        r,
    ]
}

/// Fields of equal length concatenated into one tile (stride at least 1: empty fields are
/// padded with one NaN).
struct Owned {
    data: Vec<f32>,
    stride: usize,
}

impl Owned {
    fn sphere(&self) -> SphereSoa<'_> {
        SphereSoa::new(Tile::new(&self.data, self.stride))
    }
    fn aabb(&self) -> AabbSoa<'_> {
        AabbSoa::new(Tile::new(&self.data, self.stride))
    }
}

fn tile<const K: usize>(fields: &[Vec<f32>; K]) -> Owned {
    let stride = fields[0].len().max(1);
    let mut data = Vec::with_capacity(K * stride);
    for (k, f) in fields.iter().enumerate() {
        data.extend_from_slice(f);
        data.resize((k + 1) * stride, f32::NAN);
    }
    Owned { data, stride }
}

fn boxes(rng: &mut Rng, n: usize, every: usize) -> [Vec<f32>; 6] {
    let lo: [Vec<f32>; 3] = std::array::from_fn(|_| values(rng, n, every));
    let ext: [Vec<f32>; 3] =
        std::array::from_fn(|_| (0..n).map(|_| rng.f32_in(0.0, 0.5)).collect());
    [
        lo[0].clone(),
        lo[1].clone(),
        lo[2].clone(),
        lo[0].iter().zip(&ext[0]).map(|(a, e)| a + e).collect(),
        lo[1].iter().zip(&ext[1]).map(|(a, e)| a + e).collect(),
        lo[2].iter().zip(&ext[2]).map(|(a, e)| a + e).collect(),
    ]
}

/// Block sizes: 0, 1, lanes - 1, lanes, lanes + 1, and the largest block.
fn block_sizes(lanes: usize, max: usize) -> Vec<usize> {
    let mut s: Vec<usize> = [
        0,
        1,
        lanes.saturating_sub(1),
        lanes,
        lanes + 1,
        2 * lanes + 3,
        max,
    ]
    .into_iter()
    .filter(|&n| n <= max)
    .collect();
    s.sort_unstable();
    s.dedup();
    s
}

fn check_blocks<S: Simd>(simd: S) {
    let mut rng = Rng::new(1);
    for every in [0, 5, 3] {
        for n in block_sizes(S::F32_LANES, overlap::MAX_BLOCK) {
            // Slices padded past `n` (random values: the padding lanes must be masked off).
            for len in [
                n,
                (n + 3).min(overlap::MAX_BLOCK),
                n.next_multiple_of(8).min(overlap::MAX_BLOCK),
            ] {
                let s = spheres(&mut rng, len, every);
                let probe = spheres(&mut rng, 1, every);
                let (c, r) = tile(&probe).sphere().get(0);
                let want = reference::sphere_block_scalar(c, r, tile(&s).sphere(), n);
                let got = overlap::sphere_block_with(simd, c, r, tile(&s).sphere(), n);
                assert_eq!(got, want, "{simd:?} sphere n={n} len={len} every={every}");
                assert_eq!(u64::from(got) >> n, 0, "bits past n");

                let b = boxes(&mut rng, len, every);
                let p = boxes(&mut rng, 1, every);
                let (lo, hi) = tile(&p).aabb().get(0);
                let want = reference::aabb_block_scalar(lo, hi, tile(&b).aabb(), n);
                let got = overlap::aabb_block_with(simd, lo, hi, tile(&b).aabb(), n);
                assert_eq!(got, want, "{simd:?} aabb n={n} len={len} every={every}");
                assert_eq!(u64::from(got) >> n, 0, "bits past n");
            }
        }
    }
}

#[test]
fn blocks_match_reference_on_all_backends() {
    on_all_backends!(check_blocks);
}

/// `boxes_meet_with`: the scalar reference's bits on every backend, for rows of 0 to 64
/// boxes with padding past `n`, special values (NaN, infinities, +-0, touching boxes).
fn check_box_rows<S: Simd>(simd: S) {
    let mut rng = Rng::new(12);
    for every in [0, 5, 3] {
        for n in block_sizes(S::F32_LANES, overlap::MAX_BOX_ROW) {
            for len in [n, (n + 3).min(overlap::MAX_BOX_ROW), n.next_multiple_of(8)] {
                let b = boxes(&mut rng, len, every);
                let p = boxes(&mut rng, 1, every);
                let rows = [&b[0][..], &b[1], &b[2], &b[3], &b[4], &b[5]];
                let (lo, hi) = ([p[0][0], p[1][0], p[2][0]], [p[3][0], p[4][0], p[5][0]]);
                let want = reference::boxes_meet_scalar(lo, hi, rows, n);
                let got = overlap::boxes_meet_with(simd, lo, hi, rows, n);
                assert_eq!(got, want, "{simd:?} n={n} len={len} every={every}");
                if n < 64 {
                    assert_eq!(got >> n, 0, "bits past n");
                }
                // Touching: a probe equal to an entry's box meets it.
                if n > 0 {
                    let k = rng.below(n);
                    let (lo, hi) = ([b[0][k], b[1][k], b[2][k]], [b[0][k], b[1][k], b[2][k]]);
                    let bits = overlap::boxes_meet_with(simd, lo, hi, rows, n);
                    assert_eq!(bits, reference::boxes_meet_scalar(lo, hi, rows, n));
                    let finite = (0..6).all(|f| b[f][k].is_finite());
                    assert!(!finite || bits >> k & 1 == 1, "a touching box meets");
                }
            }
        }
    }
}

/// `boxes_meet_from`: on rows longer than 64 boxes, the bits of the block from any start
/// are those of `boxes_meet_with` on the rows cut at that start.
fn check_box_rows_from<S: Simd>(simd: S) {
    let mut rng = Rng::new(13);
    for n in [0, 1, 63, 64, 65, 130, 200] {
        let b = boxes(&mut rng, n + 5, 3);
        let rows = [&b[0][..], &b[1], &b[2], &b[3], &b[4], &b[5]];
        let p = boxes(&mut rng, 1, 0);
        let (lo, hi) = ([p[0][0], p[1][0], p[2][0]], [p[3][0], p[4][0], p[5][0]]);
        for from in [0, 1, 7, 64, 65, n.saturating_sub(3), n] {
            if from > n {
                continue;
            }
            let cut: [&[f32]; 6] = std::array::from_fn(|f| &rows[f][from..]);
            let m = (n - from).min(overlap::MAX_BOX_ROW);
            let want = reference::boxes_meet_scalar(lo, hi, cut, m);
            let got = overlap::boxes_meet_from(simd, lo, hi, &rows, from, n);
            assert_eq!(got, want, "{simd:?} n={n} from={from}");
        }
    }
}

#[test]
fn box_rows_from_match_reference_on_all_backends() {
    on_all_backends!(check_box_rows_from);
}

#[test]
fn box_rows_match_reference_on_all_backends() {
    on_all_backends!(check_box_rows);
}

/// [`overlap::sphere_block_with`] on the dispatched backend.
fn sphere_block_dispatched(c: [f32; 3], r: f32, b: SphereSoa, n: usize) -> u32 {
    struct Op<'a>([f32; 3], f32, SphereSoa<'a>, usize);
    impl WithSimd for Op<'_> {
        type Output = u32;
        fn with_simd<S: Simd>(self, simd: S) -> u32 {
            overlap::sphere_block_with(simd, self.0, self.1, self.2, self.3)
        }
    }
    dhcd_kernels::arch().dispatch(Op(c, r, b, n))
}

/// [`overlap::aabb_block_with`] on the dispatched backend.
fn aabb_block_dispatched(lo: [f32; 3], hi: [f32; 3], b: AabbSoa, n: usize) -> u32 {
    struct Op<'a>([f32; 3], [f32; 3], AabbSoa<'a>, usize);
    impl WithSimd for Op<'_> {
        type Output = u32;
        fn with_simd<S: Simd>(self, simd: S) -> u32 {
            overlap::aabb_block_with(simd, self.0, self.1, self.2, self.3)
        }
    }
    dhcd_kernels::arch().dispatch(Op(lo, hi, b, n))
}

#[test]
fn dispatched_blocks_match_reference() {
    let mut rng = Rng::new(2);
    for n in 0..=overlap::MAX_BLOCK {
        let s = spheres(&mut rng, n, 4);
        let b = boxes(&mut rng, n, 4);
        for _ in 0..20 {
            let probe = spheres(&mut rng, 1, 0);
            let (c, r) = tile(&probe).sphere().get(0);
            assert_eq!(
                sphere_block_dispatched(c, r, tile(&s).sphere(), n),
                reference::sphere_block_scalar(c, r, tile(&s).sphere(), n)
            );
            let p = boxes(&mut rng, 1, 0);
            let (lo, hi) = tile(&p).aabb().get(0);
            assert_eq!(
                aabb_block_dispatched(lo, hi, tile(&b).aabb(), n),
                reference::aabb_block_scalar(lo, hi, tile(&b).aabb(), n)
            );
        }
    }
}

/// Hand-made pairs with known answers, each placed at every position of blocks of several
/// sizes (the other entries far away).
fn check_block_special_values<S: Simd>(simd: S) {
    let inf = f32::INFINITY;
    let nan = f32::NAN;
    /// (centre a, ra, centre b, rb, overlaps)
    type Case = ([f32; 3], f32, [f32; 3], f32, bool);
    let cases: &[Case] = &[
        ([0.0, 0.0, 0.0], 1.0, [3.0, 0.0, 0.0], 2.0, true), // exactly touching
        ([0.0, 0.0, 0.0], 1.0, [3.0, 0.0, 0.0], 1.75, false), // just apart
        ([1.0, 2.0, 3.0], 0.0, [1.0, 2.0, 3.0], 0.0, true), // zero radius, same centre
        ([0.0, 0.0, 0.0], 0.0, [0.0, 0.0, 1.0], 0.0, false), // zero radius, apart
        ([0.0, -0.0, 0.0], 0.0, [-0.0, 0.0, -0.0], 0.0, true), // +-0 are equal
        ([nan, 0.0, 0.0], 1.0, [0.0, 0.0, 0.0], 1.0, false), // NaN never overlaps
        ([0.0, 0.0, 0.0], nan, [0.0, 0.0, 0.0], 1.0, false), // NaN radius (padding)
        ([0.0, 0.0, 0.0], 1.0, [0.0, 0.0, 0.0], nan, false), // NaN radius in the block
        ([inf, 0.0, 0.0], 1.0, [0.0, 0.0, 0.0], 1.0, false), // infinitely far
        ([inf, 0.0, 0.0], 1.0, [inf, 0.0, 0.0], 1.0, false), // inf - inf = NaN
        ([0.0, 0.0, 0.0], inf, [5.0, 0.0, 0.0], 0.0, true), // infinite radius
    ];
    let lanes = S::F32_LANES;
    for (ci, &(ca, ra, cb, rb, want)) in cases.iter().enumerate() {
        for n in block_sizes(lanes, overlap::MAX_BLOCK)
            .into_iter()
            .filter(|&n| n > 0)
        {
            for pos in 0..n {
                // Filler entries: padding (NaN radius: never overlaps, even an infinite probe).
                let mut s = [
                    vec![-100.0; n],
                    vec![0.0; n],
                    vec![0.0; n],
                    vec![f32::NAN; n],
                ];
                for k in 0..3 {
                    s[k][pos] = cb[k];
                }
                s[3][pos] = rb;
                let got = overlap::sphere_block_with(simd, ca, ra, tile(&s).sphere(), n);
                assert_eq!(
                    got,
                    (want as u32) << pos,
                    "{simd:?} case {ci} n={n} pos={pos}"
                );
                // Symmetric: the block entry as the probe.
                let mut t = [
                    vec![-100.0; n],
                    vec![0.0; n],
                    vec![0.0; n],
                    vec![f32::NAN; n],
                ];
                for k in 0..3 {
                    t[k][pos] = ca[k];
                }
                t[3][pos] = ra;
                let got = overlap::sphere_block_with(simd, cb, rb, tile(&t).sphere(), n);
                assert_eq!(
                    got,
                    (want as u32) << pos,
                    "{simd:?} swapped case {ci} n={n}"
                );
            }
        }
    }

    type B = ([f32; 3], [f32; 3]);
    let unit: B = ([0.0; 3], [1.0; 3]);
    let box_cases: &[(B, B, bool)] = &[
        (unit, ([1.0, 0.0, 0.0], [2.0, 1.0, 1.0]), true), // touching face
        (unit, ([1.0, 1.0, 1.0], [2.0, 2.0, 2.0]), true), // touching corner
        (unit, ([1.0000001, 0.0, 0.0], [2.0, 1.0, 1.0]), false), // next float apart
        (unit, refit::EMPTY_BOUNDS, false),               // empty box (padding)
        (refit::EMPTY_BOUNDS, refit::EMPTY_BOUNDS, false), // empty vs empty
        (unit, ([0.5; 3], [0.5; 3]), true),               // point box inside
        (([-0.0; 3], [-0.0; 3]), ([0.0; 3], [0.0; 3]), true), // +-0 point boxes
        (unit, ([nan, 0.0, 0.0], [1.0; 3]), false),       // NaN
        (unit, ([-inf; 3], [inf; 3]), true),              // everything
        (unit, ([inf; 3], [inf; 3]), false),              // at infinity
    ];
    for (ci, &(ba, bb, want)) in box_cases.iter().enumerate() {
        for n in block_sizes(lanes, narrow::MAX_ROW)
            .into_iter()
            .filter(|&n| n > 0)
        {
            for pos in 0..n {
                let mut b: [Vec<f32>; 6] =
                    std::array::from_fn(|f| vec![if f < 3 { 10.0 } else { 11.0 }; n]);
                for k in 0..3 {
                    b[k][pos] = bb.0[k];
                    b[3 + k][pos] = bb.1[k];
                }
                if n <= overlap::MAX_BLOCK {
                    let got = overlap::aabb_block_with(simd, ba.0, ba.1, tile(&b).aabb(), n);
                    assert_eq!(got, (want as u32) << pos, "{simd:?} box case {ci} n={n}");
                }
                // As triangles: the degenerate triangle (lo, hi, lo) has exactly this box
                // and certifies no plane, so the candidate bit is the box test (for boxes a
                // triangle can have: ordered, no NaN).
                let tri = |bx: B| [bx.0, bx.1, bx.0];
                let ordered = |bx: B| (0..3).all(|k| bx.0[k] <= bx.1[k]);
                if !(ordered(ba) && ordered(bb)) {
                    continue;
                }
                let mut row = vec![tri(([10.0; 3], [11.0; 3])); n];
                row[pos] = tri(bb);
                let rb = Tris::new(&row, 0);
                let ra = Tris::new(&[tri(ba)], 100);
                let mut out = [narrow::Row::default(); 1];
                narrow::leaf_contacts_with(
                    simd,
                    ra.soa(),
                    1,
                    rb.soa(),
                    n,
                    narrow::Pairing::All,
                    &mut out,
                );
                assert_eq!(
                    out[0].candidates(),
                    (want as u64) << pos,
                    "{simd:?} row case {ci} n={n}"
                );
            }
        }
    }
}

#[test]
fn block_special_values_on_all_backends() {
    on_all_backends!(check_block_special_values);
}

#[test]
#[should_panic(expected = "at most 32")]
fn oversized_block_is_refused() {
    let v = vec![0.0; 4 * 33];
    sphere_block_dispatched([0.0; 3], 1.0, SphereSoa::new(Tile::new(&v, 33)), 33);
}

// ---------------------------------------------------------------------------------------
// narrow: leaf candidates

/// Triangles in SoA form (a tile of 15 fields, stride at least 1) with corner indices
/// `first + 3t, first + 3t + 1, first + 3t + 2`.
struct Tris {
    tile: Vec<f32>,
    vertex: Vec<u32>,
    stride: usize,
}

impl Tris {
    fn new(tris: &[[[f32; 3]; 3]], first: u32) -> Self {
        let stride = tris.len().max(1);
        let mut tile = vec![f32::NAN; 15 * stride];
        let mut vertex = vec![u32::MAX; 3 * stride];
        for (t, tri) in tris.iter().enumerate() {
            for c in 0..3 {
                for k in 0..3 {
                    tile[(3 * c + k) * stride + t] = tri[c][k];
                }
                vertex[c * stride + t] = first + 3 * t as u32 + c as u32;
            }
            for k in 0..3 {
                tile[(9 + k) * stride + t] = tri[0][k].min(tri[1][k]).min(tri[2][k]);
                tile[(12 + k) * stride + t] = tri[0][k].max(tri[1][k]).max(tri[2][k]);
            }
        }
        Tris {
            tile,
            vertex,
            stride,
        }
    }
    fn soa(&self) -> narrow::TriSoa<'_> {
        narrow::TriSoa::new(Tile::new(&self.tile, self.stride), &self.vertex)
    }
    /// Sets corner `c`'s index of triangle `t`.
    /// Overwrites bound field `f` (9..15: min x, y, z, max x, y, z) of triangle `t`.
    fn set_bound(&mut self, f: usize, t: usize, v: f32) {
        self.tile[f * self.stride + t] = v;
    }

    fn set_vertex(&mut self, c: usize, t: usize, v: u32) {
        self.vertex[c * self.stride + t] = v;
    }
}

fn low64(n: usize) -> u64 {
    if n >= 64 {
        u64::MAX
    } else {
        (1 << n) - 1
    }
}

/// Random triangles around the probe, at `scale`: some nearly coplanar with it (points of
/// its plane nudged by a few ulps), some degenerate, some with special values.
fn nasty_triangles(
    rng: &mut Rng,
    probe: &[[f32; 3]; 3],
    n: usize,
    scale: f32,
) -> Vec<[[f32; 3]; 3]> {
    (0..n)
        .map(|i| {
            let mut t: [[f32; 3]; 3] =
                std::array::from_fn(|_| std::array::from_fn(|_| rng.f32_in(-1.0, 1.0) * scale));
            match i % 6 {
                1 | 2 => {
                    for c in 0..3 {
                        let (s, u) = (rng.f32_in(-1.0, 2.0), rng.f32_in(-1.0, 2.0));
                        for k in 0..3 {
                            let (a, b, cc) =
                                (probe[0][k] as f64, probe[1][k] as f64, probe[2][k] as f64);
                            let mut v = (a + s as f64 * (b - a) + u as f64 * (cc - a)) as f32;
                            for _ in 0..rng.below(3) {
                                v = if rng.below(2) == 0 {
                                    v.next_up()
                                } else {
                                    v.next_down()
                                };
                            }
                            t[c][k] = v;
                        }
                    }
                }
                3 => t[2] = t[1],
                4 => t[rng.below(3)] = probe[rng.below(3)],
                5 if i % 5 == 0 => t[0][0] = [f32::NAN, f32::INFINITY, f32::MAX][rng.below(3)],
                _ => {}
            }
            t
        })
        .collect()
}

fn random_tris(rng: &mut Rng, n: usize, scale: f32) -> Vec<[[f32; 3]; 3]> {
    let probe: [[f32; 3]; 3] =
        std::array::from_fn(|_| std::array::from_fn(|_| rng.f32_in(-1.0, 1.0) * scale));
    nasty_triangles(rng, &probe, n, scale)
}

const PAIRINGS: [narrow::Pairing; 3] = [
    narrow::Pairing::All,
    narrow::Pairing::NoSharedVertex,
    narrow::Pairing::NoSharedVertexUpper,
];

fn check_leaf_contacts<S: Simd>(simd: S) {
    let mut rng = Rng::new(4);
    for scale in [1.0, 1e-30, 1e30, 3e-3] {
        for nb in block_sizes(S::F32_LANES, narrow::MAX_ROW) {
            // More rows than MAX_ROW: the row masks go in chunks.
            for na in [0, 1, 7, 9, 64, 65, 130] {
                // Padded blocks, and corner indices that collide across the two blocks (the
                // second block's indices overlap the first's) so that sharing happens.
                let len_b = nb.next_multiple_of(8).min(narrow::MAX_ROW);
                let a = Tris::new(&random_tris(&mut rng, na, scale), 0);
                let b = Tris::new(
                    &random_tris(&mut rng, len_b, scale),
                    3 * rng.below(8) as u32,
                );
                for pairing in PAIRINGS {
                    let row = |x| narrow::Row {
                        contact: x,
                        undecided: x,
                    };
                    let mut want = vec![row(7); na + 1];
                    let mut got = vec![row(9); na + 1];
                    reference::leaf_contacts_scalar(a.soa(), na, b.soa(), nb, pairing, &mut want);
                    narrow::leaf_contacts_with(simd, a.soa(), na, b.soa(), nb, pairing, &mut got);
                    assert_eq!(
                        &got[..na],
                        &want[..na],
                        "{simd:?} na={na} nb={nb} {pairing:?} scale={scale}"
                    );
                    assert_eq!(got[na], row(9), "wrote past na rows");
                    assert!(
                        got[..na].iter().all(|r| r.contact & r.undecided == 0),
                        "a pair both certain and undecided"
                    );
                    assert!(
                        got[..na].iter().all(|r| r.candidates() & !low64(nb) == 0),
                        "bits past nb"
                    );
                    if pairing == narrow::Pairing::NoSharedVertexUpper {
                        assert!(got[..na]
                            .iter()
                            .enumerate()
                            .all(|(i, r)| r.candidates() & low64(i + 1) == 0));
                    }
                    // The rounded-corner variant: the same bits as its scalar reference, no
                    // certain contact, and a superset of the plain kernel's candidates (its
                    // slack only keeps more pairs).
                    let mut want_r = vec![row(7); na + 1];
                    let mut got_r = vec![row(9); na + 1];
                    reference::leaf_candidates_rounded_scalar(
                        a.soa(),
                        na,
                        b.soa(),
                        nb,
                        pairing,
                        &mut want_r,
                    );
                    narrow::leaf_candidates_rounded_with(
                        simd,
                        a.soa(),
                        na,
                        b.soa(),
                        nb,
                        pairing,
                        &mut got_r,
                    );
                    assert_eq!(
                        &got_r[..na],
                        &want_r[..na],
                        "rounded {simd:?} na={na} nb={nb} {pairing:?} scale={scale}"
                    );
                    assert_eq!(got_r[na], row(9), "wrote past na rows");
                    for (r, p) in got_r[..na].iter().zip(&got[..na]) {
                        assert_eq!(r.contact, 0);
                        assert_eq!(p.candidates() & !r.undecided, 0, "a candidate dropped");
                    }
                }
            }
        }
    }
}

#[test]
fn leaf_contacts_match_reference_on_all_backends() {
    on_all_backends!(check_leaf_contacts);
}

/// `n` triangles of a flat grid (two per unit cell, rows of 5 cells) in the plane spanned by
/// `ex`, `ey`, from triangle `first` on, with the grid's vertex numbering (a mesh's).
fn grid_tris(n: usize, first: usize, ex: [f32; 3], ey: [f32; 3]) -> Tris {
    let at = |i: usize, j: usize| -> [f32; 3] {
        std::array::from_fn(|k| 0.25 * (i as f32 * ex[k] + j as f32 * ey[k]))
    };
    let id = |i: usize, j: usize| (i + 6 * j) as u32;
    let mut tris = Vec::new();
    let mut ids = Vec::new();
    for t in first..first + n {
        let (cell, half) = (t / 2, t % 2);
        let (i, j) = (cell % 5, cell / 5);
        let corners = if half == 0 {
            [(i, j), (i + 1, j), (i + 1, j + 1)]
        } else {
            [(i, j), (i + 1, j + 1), (i, j + 1)]
        };
        tris.push(corners.map(|(i, j)| at(i, j)));
        ids.push(corners.map(|(i, j)| id(i, j)));
    }
    let mut out = Tris::new(&tris, 0);
    for (t, v) in ids.iter().enumerate() {
        for c in 0..3 {
            out.set_vertex(c, t, v[c]);
        }
    }
    out
}

/// The projection pass on every backend equals the scalar reference on coplanar blocks (flat
/// grids in three orientations, blocks of neighbouring cells, one mesh's vertex numbering)
/// and decides every allowed pair: they are all apart, and no plane separates any of them.
fn check_coplanar_blocks<S: Simd>(simd: S) {
    let planes = [
        ([1.0, 0.0, 0.0], [0.0, 1.0, 0.0]),
        ([0.0, 0.6, 0.8], [1.0, 0.0, 0.0]),
        ([0.0, 0.0, 1.0], [0.8, 0.6, 0.0]),
    ];
    for (ex, ey) in planes {
        for (na, nb, first_b) in [(64, 64, 10), (20, 64, 0), (64, 17, 30), (9, 9, 4)] {
            let a = grid_tris(na, 0, ex, ey);
            let b = grid_tris(nb, first_b, ex, ey);
            for pairing in [
                narrow::Pairing::NoSharedVertex,
                narrow::Pairing::NoSharedVertexUpper,
            ] {
                let mut want = vec![narrow::Row::default(); na];
                let mut got = vec![narrow::Row::default(); na];
                reference::leaf_contacts_scalar(a.soa(), na, b.soa(), nb, pairing, &mut want);
                narrow::leaf_contacts_with(simd, a.soa(), na, b.soa(), nb, pairing, &mut got);
                assert_eq!(got, want, "{simd:?} na={na} nb={nb} {pairing:?}");
                assert!(
                    got.iter().all(|r| r.candidates() == 0),
                    "{simd:?} na={na} nb={nb} {pairing:?}: a coplanar pair left undecided"
                );
            }
        }
    }
}

#[test]
fn coplanar_blocks_match_reference_on_all_backends() {
    on_all_backends!(check_coplanar_blocks);
}

/// [`narrow::leaf_contacts_with`] on the dispatched backend.
fn leaf_contacts(
    a: narrow::TriSoa,
    na: usize,
    b: narrow::TriSoa,
    nb: usize,
    pairing: narrow::Pairing,
    out: &mut [narrow::Row],
) {
    struct Op<'a> {
        a: narrow::TriSoa<'a>,
        na: usize,
        b: narrow::TriSoa<'a>,
        nb: usize,
        pairing: narrow::Pairing,
        out: &'a mut [narrow::Row],
    }
    impl WithSimd for Op<'_> {
        type Output = ();
        fn with_simd<S: Simd>(self, simd: S) {
            narrow::leaf_contacts_with(
                simd,
                self.a,
                self.na,
                self.b,
                self.nb,
                self.pairing,
                self.out,
            )
        }
    }
    dhcd_kernels::arch().dispatch(Op {
        a,
        na,
        b,
        nb,
        pairing,
        out,
    })
}

#[test]
fn dispatched_leaf_contacts_match_reference() {
    let mut rng = Rng::new(9);
    for _ in 0..50 {
        let (na, nb) = (rng.below(65), rng.below(65));
        let a = Tris::new(&random_tris(&mut rng, na, 1.0), 0);
        let b = Tris::new(&random_tris(&mut rng, nb, 1.0), 3 * rng.below(20) as u32);
        for pairing in PAIRINGS {
            let mut want = vec![narrow::Row::default(); na];
            let mut got = want.clone();
            leaf_contacts(a.soa(), na, b.soa(), nb, pairing, &mut got);
            reference::leaf_contacts_scalar(a.soa(), na, b.soa(), nb, pairing, &mut want);
            assert_eq!(got, want);
        }
    }
}

/// The pairings: which pairs reach the box and plane filters at all. Ten copies of one
/// triangle (boxes overlap, coplanar: no plane certified) keep exactly the allowed pairs.
#[test]
fn leaf_contacts_keep_exactly_the_allowed_pairs() {
    let copies = vec![[[0.0, 0.0, 0.0], [2.0, 1.0, 0.0], [0.0, 1.0, 0.0]]; 10];
    let a = Tris::new(&copies, 0);
    let mut shared = Tris::new(&copies, 0);
    shared.set_vertex(1, 3, 0); // triangle 3 of b shares vertex 0 with triangle 0 of a
    let rows = |b: &Tris, pairing| {
        let mut out = [narrow::Row::default(); 10];
        leaf_contacts(a.soa(), 10, b.soa(), 10, pairing, &mut out);
        // Coplanar copies certify no sign: every candidate is left to the exact test.
        assert!(out.iter().all(|r| r.contact == 0));
        out.map(|r| r.candidates())
    };
    assert_eq!(rows(&a, narrow::Pairing::All), [0x3ff; 10]);
    // The same block: each triangle shares its own three indices with itself only.
    let distinct = rows(&a, narrow::Pairing::NoSharedVertex);
    assert!((0..10).all(|i| distinct[i] == 0x3ff & !(1 << i)));
    let upper = rows(&a, narrow::Pairing::NoSharedVertexUpper);
    assert!((0..10).all(|i| upper[i] == 0x3ff & !low64(i + 1)));
    let with_shared = rows(&shared, narrow::Pairing::NoSharedVertex);
    assert_eq!(with_shared[0], 0x3ff & !0b1001);
    assert!((1..10).all(|i| with_shared[i] == 0x3ff & !(1 << i)));
}

/// The box and plane filters on a strip of triangles.
#[test]
fn leaf_contacts_filter_a_strip() {
    // A strip in the plane z = 0: neighbours' boxes touch (x = t + 1), the others are apart.
    let tris: Vec<[[f32; 3]; 3]> = (0..10)
        .map(|t| {
            let x = 2.0 * t as f32;
            [[x, 0.0, 0.0], [x + 2.0, 1.0, 0.0], [x, 1.0, 0.0]]
        })
        .collect();
    let a = Tris::new(&tris, 0);
    let mut out = [narrow::Row::default(); 10];
    // Coplanar neighbours in one plane, boxes overlapping: left to the exact test.
    leaf_contacts(
        a.soa(),
        10,
        a.soa(),
        10,
        narrow::Pairing::NoSharedVertexUpper,
        &mut out,
    );
    assert_eq!(
        out[0],
        narrow::Row {
            contact: 0,
            undecided: 0b10
        },
        "touching neighbour 1 undecided, far ones dropped by the boxes"
    );
}

/// The leaf-level prefilter (each block's union box against the other's triangles) must
/// not lose a pair: one triangle of a block with a NaN or infinite bound, or far away,
/// never hides its neighbours' hits, on every backend and block size.
fn check_union_boxes<S: Simd>(simd: S) {
    // Vertical triangles crossing the plane z = 0 inside the base triangle.
    let base = [[0.0, 0.0, 0.0], [4.0, 0.0, 0.0], [0.0, 4.0, 0.0]];
    let post = |x: f32| [[x, 0.5, -1.0], [x, 0.5, 1.0], [x + 0.1, 0.7, 1.0]];
    for n in block_sizes(S::F32_LANES, narrow::MAX_ROW)
        .into_iter()
        .filter(|&n| n > 1)
    {
        for odd in 0..n {
            for (f, v) in [
                (9, f32::NAN),
                (12, f32::NAN),
                (10, f32::NEG_INFINITY),
                (13, 1e30),
            ] {
                let posts: Vec<_> = (0..n).map(|t| post(0.5 + 0.02 * t as f32)).collect();
                let mut b = Tris::new(&posts, 100);
                b.set_bound(f, odd, v);
                let a = Tris::new(&[base], 0);
                for (x, nx, y, ny) in [(&a, 1, &b, n), (&b, n, &a, 1)] {
                    let mut got = vec![narrow::Row::default(); nx];
                    let mut want = got.clone();
                    let pairing = narrow::Pairing::All;
                    narrow::leaf_contacts_with(simd, x.soa(), nx, y.soa(), ny, pairing, &mut got);
                    reference::leaf_contacts_scalar(x.soa(), nx, y.soa(), ny, pairing, &mut want);
                    assert_eq!(got, want, "{simd:?} n={n} odd={odd} field {f}");
                    let hits: u32 = got.iter().map(|r| r.candidates().count_ones()).sum();
                    let lost = u32::from(v.is_nan());
                    assert_eq!(hits, n as u32 - lost, "{simd:?} n={n} odd={odd} field {f}");
                }
            }
        }
    }
}

#[test]
fn union_boxes_lose_no_pair_on_all_backends() {
    on_all_backends!(check_union_boxes);
}

/// The union box of `tris`.
fn union_of(tris: &[[[f32; 3]; 3]]) -> narrow::Bounds {
    let mut u = ([f32::INFINITY; 3], [f32::NEG_INFINITY; 3]);
    for c in tris.iter().flatten() {
        for k in 0..3 {
            u.0[k] = u.0[k].min(c[k]);
            u.1[k] = u.1[k].max(c[k]);
        }
    }
    u
}

/// Blocks of posts crossing a base triangle, some far away: given bounds (`with_bounds`, as a
/// leaf cache passes them), exact or larger, give the verdicts of the kernel computing its
/// own union boxes, on every backend and in both orders.
fn check_given_bounds<S: Simd>(simd: S) {
    let base = [[0.0, 0.0, 0.0], [4.0, 0.0, 0.0], [0.0, 4.0, 0.0]];
    let post = |x: f32| [[x, 0.5, -1.0], [x, 0.5, 1.0], [x + 0.1, 0.7, 1.0]];
    for n in block_sizes(S::F32_LANES, narrow::MAX_ROW) {
        // Every third post far beyond the base: the prefilter's business.
        let posts: Vec<_> = (0..n)
            .map(|t| {
                post(if t % 3 == 2 {
                    50.0 + t as f32
                } else {
                    0.5 + 0.02 * t as f32
                })
            })
            .collect();
        let (a, b) = (Tris::new(&[base], 0), Tris::new(&posts, 100));
        let (ua, ub) = (union_of(&[base]), union_of(&posts));
        let grow = |u: narrow::Bounds| (u.0.map(|x| x - 10.0), u.1.map(|x| x + 10.0));
        for (x, nx, bx, y, ny, by) in [(&a, 1, ua, &b, n, ub), (&b, n, ub, &a, 1, ua)] {
            let pairing = narrow::Pairing::All;
            let mut want = vec![narrow::Row::default(); nx];
            narrow::leaf_contacts_with(simd, x.soa(), nx, y.soa(), ny, pairing, &mut want);
            let hits: u32 = want.iter().map(|r| r.candidates().count_ones()).sum();
            assert_eq!(hits as usize, n - n / 3, "{simd:?} n={n}: the near posts");
            for (gx, gy) in [(bx, by), (grow(bx), grow(by))] {
                let mut got = vec![narrow::Row::default(); nx];
                let (sx, sy) = (x.soa().with_bounds(gx), y.soa().with_bounds(gy));
                narrow::leaf_contacts_with(simd, sx, nx, sy, ny, pairing, &mut got);
                assert_eq!(got, want, "{simd:?} n={n}");
            }
        }
    }
}

#[test]
fn given_bounds_change_no_verdict_on_all_backends() {
    on_all_backends!(check_given_bounds);
}

/// Two strips along x, in order (as lane-ordered leaves are): a flat triangle at `x = i`
/// meets the posts at `x = t` within 0.15 of it, so each lane vector of one strip meets a few
/// rows of the other and the per-vector row culling removes the rest. Some posts are NaN
/// (their boxes must not poison a vector's box). Verdicts equal the scalar reference for
/// every pairing, every block size and both orders, and the expected crossings are found.
fn check_vector_culling<S: Simd>(simd: S) {
    let flat = |x: f32| [[x - 0.3, 0.0, 0.0], [x + 0.3, 0.0, 0.0], [x, 1.0, 0.0]];
    let post = |x: f32| [[x, 0.5, -1.0], [x, 0.5, 1.0], [x + 0.1, 0.7, 1.0]];
    let nan = [[f32::NAN; 3]; 3];
    for n in block_sizes(S::F32_LANES, narrow::MAX_ROW) {
        let flats: Vec<_> = (0..n).map(|i| flat(0.5 * i as f32)).collect();
        let posts: Vec<_> = (0..n)
            .map(|t| {
                if t % 7 == 3 {
                    nan
                } else {
                    post(0.5 * t as f32 + 0.05)
                }
            })
            .collect();
        // Flat i meets post t iff t == i (0.05 apart; neighbours are 0.5 apart), NaN aside.
        let crossings = (0..n).filter(|t| t % 7 != 3).count();
        let mixed: Vec<_> = (0..n)
            .map(|t| if t % 2 == 0 { flats[t] } else { posts[t] })
            .collect();
        let (a, b, m) = (
            Tris::new(&flats, 0),
            Tris::new(&posts, 1000),
            Tris::new(&mixed, 0),
        );
        let cases = [
            (&a, &b, Some(crossings)),
            (&b, &a, Some(crossings)),
            (&m, &m, None),
        ];
        for (x, y, expected) in cases {
            for pairing in PAIRINGS {
                let mut want = vec![narrow::Row::default(); n];
                let mut got = want.clone();
                reference::leaf_contacts_scalar(x.soa(), n, y.soa(), n, pairing, &mut want);
                narrow::leaf_contacts_with(simd, x.soa(), n, y.soa(), n, pairing, &mut got);
                assert_eq!(got, want, "{simd:?} n={n} {pairing:?}");
                let found: u32 = got.iter().map(|r| r.candidates().count_ones()).sum();
                if let (Some(e), narrow::Pairing::All) = (expected, pairing) {
                    assert_eq!(found as usize, e, "{simd:?} n={n}: the crossings");
                }
            }
        }
    }
}

#[test]
fn vector_culling_loses_no_pair_on_all_backends() {
    on_all_backends!(check_vector_culling);
}

/// A box that misses a triangle would lose its pairs: debug builds refuse it.
#[test]
#[cfg_attr(not(debug_assertions), ignore = "the check is a debug assertion")]
#[should_panic(expected = "the box misses a triangle")]
fn given_bounds_that_miss_a_triangle_panic_in_debug_builds() {
    let base = [[0.0, 0.0, 0.0], [4.0, 0.0, 0.0], [0.0, 4.0, 0.0]];
    let post = [[1.0, 0.5, -1.0], [1.0, 0.5, 1.0], [1.1, 0.7, 1.0]];
    let (a, b) = (Tris::new(&[base], 0), Tris::new(&[post], 10));
    let short = ([0.0; 3], [1.0; 3]);
    let mut out = [narrow::Row::default(); 1];
    leaf_contacts(
        a.soa(),
        1,
        b.soa().with_bounds(short),
        1,
        narrow::Pairing::All,
        &mut out,
    );
}

/// The canonical form's three outcomes on pairs whose six corner-plane signs are certified,
/// on every backend, in every rotation of both triangles (the lone vertices move) and both
/// orders.
fn check_canonical_form<S: Simd>(simd: S) {
    use reference::Verdict::{Apart, Contact};
    let base = [[0.0, 0.0, 0.0], [4.0, 0.0, 0.0], [0.0, 4.0, 0.0]];
    let cases: [([[f32; 3]; 3], reference::Verdict); 4] = [
        // Pierces base's interior: intersect.
        (
            [[1.0, 1.0, -1.0], [1.0, 1.0, 1.0], [1.5, 1.2, 1.0]],
            Contact,
        ),
        // Crosses base's plane beyond its hypotenuse: the planes' common line misses base.
        ([[3.0, 3.0, -1.0], [3.0, 3.0, 1.0], [3.5, 3.2, 1.0]], Apart),
        // Straddles base's plane but stops short of it along the common line.
        (
            [[-2.0, 1.0, -1.0], [-2.0, 1.0, 1.0], [-1.0, 1.0, 1.0]],
            Apart,
        ),
        // A long sliver crossing the whole of base.
        (
            [[-1.0, 1.0, 0.5], [6.0, 1.0, -0.5], [-1.0, 1.1, 0.5]],
            Contact,
        ),
    ];
    let rot = |t: [[f32; 3]; 3], r: usize| [t[r % 3], t[(r + 1) % 3], t[(r + 2) % 3]];
    let mirror = |t: [[f32; 3]; 3]| [t[0], t[2], t[1]];
    for (ci, &(other, want)) in cases.iter().enumerate() {
        for r in 0..6 {
            let a = if r < 3 {
                rot(base, r)
            } else {
                mirror(rot(base, r))
            };
            for s in 0..6 {
                let b = if s < 3 {
                    rot(other, s)
                } else {
                    mirror(rot(other, s))
                };
                for (x, y) in [(a, b), (b, a)] {
                    assert!(
                        !reference::plane_separated(&x, &y),
                        "case {ci}: no plane separates"
                    );
                    assert_eq!(
                        reference::pair_verdict(&x, &y),
                        want,
                        "case {ci} r={r} s={s}"
                    );
                    let (tx, ty) = (Tris::new(&[x], 0), Tris::new(&[y], 10));
                    let mut out = [narrow::Row::default(); 1];
                    narrow::leaf_contacts_with(
                        simd,
                        tx.soa(),
                        1,
                        ty.soa(),
                        1,
                        narrow::Pairing::All,
                        &mut out,
                    );
                    let bit = u64::from(want == Contact);
                    assert_eq!(
                        out[0],
                        narrow::Row {
                            contact: bit,
                            undecided: 0
                        },
                        "{simd:?} case {ci} r={r} s={s}"
                    );
                }
            }
        }
    }
}

#[test]
fn canonical_form_on_all_backends() {
    on_all_backends!(check_canonical_form);
}

/// Exact sign of `orient3d` (the robust crate is exact for f64 inputs, and f32 converts
/// exactly).
fn exact_side(p: &[[f32; 3]; 3], d: [f32; 3]) -> i32 {
    let c = |v: [f32; 3]| robust::Coord3D {
        x: v[0] as f64,
        y: v[1] as f64,
        z: v[2] as f64,
    };
    let o = robust::orient3d(c(p[0]), c(p[1]), c(p[2]), c(d));
    (o > 0.0) as i32 - (o < 0.0) as i32
}

/// The plane filter drops a pair only when one triangle is strictly on one side of the
/// other's plane, decided exactly: checked against exact orientations on adversarial
/// inputs, from subnormal-producing to overflow-producing scales.
#[test]
fn plane_filter_drops_only_certainly_separated_pairs() {
    let mut rng = Rng::new(5);
    // Drops among the plain random pairs (every sixth of `nasty_triangles`).
    let (mut dropped, mut total) = (0, 0);
    for round in 0..3000 {
        let scale = [1.0, 1e-20, 1e20, 7e-4, 1e-38, 3e-44, 1e35][round % 7];
        let probe: [[f32; 3]; 3] =
            std::array::from_fn(|_| std::array::from_fn(|_| rng.f32_in(-1.0, 1.0) * scale));
        for (i, t) in nasty_triangles(&mut rng, &probe, 16, scale)
            .into_iter()
            .enumerate()
        {
            if t.iter().flatten().any(|v| !v.is_finite()) {
                // No exact oracle for non-finite input (the library rejects it).
                continue;
            }
            let separated = reference::plane_separated(&probe, &t);
            // Local scales whose degree-3 products stay normal f32 (at 1e-20 they underflow,
            // at 1e20 they overflow: the filter then certifies nothing, which is sound).
            if i % 6 == 0 && (scale == 1.0 || scale == 7e-4) {
                total += 1;
                dropped += separated as usize;
            }
            if !separated {
                continue;
            }
            let one_side = |p: &[[f32; 3]; 3], q: &[[f32; 3]; 3]| {
                let s = q.map(|d| exact_side(p, d));
                s.iter().all(|&x| x > 0) || s.iter().all(|&x| x < 0)
            };
            assert!(
                one_side(&probe, &t) || one_side(&t, &probe),
                "dropped a pair that is not strictly separated: {probe:?} {t:?}"
            );
        }
    }
    // The filter is useful, not only safe: random pairs are separated by one of the planes
    // with probability about 0.4.
    assert!(dropped * 10 > 3 * total, "dropped {dropped} of {total}");
    assert!(total > 1000);
}

// ---------------------------------------------------------------------------------------
// refit

struct Points([Vec<f32>; 3]);

impl Points {
    fn random(rng: &mut Rng, n: usize, every: usize) -> Self {
        Points([
            values(rng, n, every),
            values(rng, n, every),
            values(rng, n, every),
        ])
    }
    fn soa(&self) -> Soa3<'_> {
        Soa3::new(&self.0[0], &self.0[1], &self.0[2])
    }
}

fn check_refit<S: Simd>(simd: S) {
    let lanes = S::F32_LANES;
    let mut rng = Rng::new(6);
    for every in [0, 3, 7] {
        for n in sizes(lanes) {
            let pts = Points::random(&mut rng, n, every);
            let p = pts.soa();
            let idx: Vec<u32> = (0..n + 5).map(|_| rng.below(n.max(1)) as u32).collect();
            let idx: &[u32] = if n == 0 { &[] } else { &idx };
            for c in [[0.1f32, -0.2, 0.3], [0.0, -0.0, 0.0]] {
                let want = reference::max_dist_sq_scalar_lanes(p, c, lanes);
                assert_eq!(
                    refit::max_dist_sq_with(simd, p, c).to_bits(),
                    want.to_bits(),
                    "{simd:?} n={n}"
                );
                let want = reference::max_dist_sq_indexed_scalar_lanes(p, idx, c, lanes);
                assert_eq!(
                    refit::max_dist_sq_indexed_with(simd, p, idx, c).to_bits(),
                    want.to_bits()
                );
            }
            assert_eq!(
                bits3(refit::sum_with(simd, p)),
                bits3(reference::sum_scalar_lanes(p, lanes)),
                "{simd:?} n={n} every={every}"
            );
            assert_eq!(
                bits3(refit::sum_indexed_with(simd, p, idx)),
                bits3(reference::sum_indexed_scalar_lanes(p, idx, lanes))
            );
            assert_eq!(
                bits_box(refit::bounds_with(simd, p)),
                bits_box(reference::bounds_scalar_lanes(p, lanes)),
                "{simd:?} n={n}"
            );
            assert_eq!(
                bits_box(refit::bounds_indexed_with(simd, p, idx)),
                bits_box(reference::bounds_indexed_scalar_lanes(p, idx, lanes))
            );
            if lanes == 1 {
                // The sequential references are the 1-lane case.
                assert_eq!(
                    bits3(refit::sum_with(simd, p)),
                    bits3(reference::sum_scalar_lanes(p, 1))
                );
                assert_eq!(
                    bits_box(refit::bounds_with(simd, p)),
                    bits_box(reference::bounds_scalar_lanes(p, 1))
                );
            }
            // Max/min do not depend on the order except for +-0 ties; compare values.
            let (lo, hi) = refit::bounds_with(simd, p);
            let (slo, shi) = reference::bounds_scalar_lanes(p, 1);
            assert_eq!((lo, hi), (slo, shi));
            assert_eq!(
                refit::max_dist_sq_with(simd, p, [0.5; 3]),
                reference::max_dist_sq_scalar_lanes(p, [0.5; 3], 1)
            );
        }
    }
}

#[test]
fn refit_matches_lane_reference_on_all_backends() {
    on_all_backends!(check_refit);
}

/// The refit reductions on the dispatched backend: max distance, indexed max distance, sum,
/// indexed sum, bounds, indexed bounds.
struct Refits<'a> {
    p: Soa3<'a>,
    idx: &'a [u32],
    c: [f32; 3],
}

type RefitValues = (
    f32,
    f32,
    [f32; 3],
    [f32; 3],
    ([f32; 3], [f32; 3]),
    ([f32; 3], [f32; 3]),
);

impl WithSimd for Refits<'_> {
    type Output = RefitValues;
    fn with_simd<S: Simd>(self, simd: S) -> RefitValues {
        let (p, idx, c) = (self.p, self.idx, self.c);
        (
            refit::max_dist_sq_with(simd, p, c),
            refit::max_dist_sq_indexed_with(simd, p, idx, c),
            refit::sum_with(simd, p),
            refit::sum_indexed_with(simd, p, idx),
            refit::bounds_with(simd, p),
            refit::bounds_indexed_with(simd, p, idx),
        )
    }
}

#[test]
fn dispatched_refits_match_lane_reference() {
    let lanes = reference::f32_lanes();
    let mut rng = Rng::new(7);
    for n in sizes(lanes) {
        let pts = Points::random(&mut rng, n, 9);
        let p = pts.soa();
        let idx: Vec<u32> = (0..2 * n).map(|_| rng.below(n.max(1)) as u32).collect();
        let idx: &[u32] = if n == 0 { &[] } else { &idx };
        let c = [0.25, 0.5, -0.125];
        let (d, d_idx, s, s_idx, b, b_idx) = dhcd_kernels::arch().dispatch(Refits { p, idx, c });
        assert_eq!(
            d.to_bits(),
            reference::max_dist_sq_scalar_lanes(p, c, lanes).to_bits()
        );
        assert_eq!(
            d_idx.to_bits(),
            reference::max_dist_sq_indexed_scalar_lanes(p, idx, c, lanes).to_bits()
        );
        assert_eq!(bits3(s), bits3(reference::sum_scalar_lanes(p, lanes)));
        assert_eq!(
            bits3(s_idx),
            bits3(reference::sum_indexed_scalar_lanes(p, idx, lanes))
        );
        let want = bits_box(reference::bounds_scalar_lanes(p, lanes));
        assert_eq!(bits_box(b), want);
        // The one dispatching entry.
        assert_eq!(bits_box(refit::bounds(p)), want);
        assert_eq!(
            bits_box(b_idx),
            bits_box(reference::bounds_indexed_scalar_lanes(p, idx, lanes))
        );
    }
}

fn check_refit_special_values<S: Simd>(simd: S) {
    let (inf, nan) = (f32::INFINITY, f32::NAN);
    let lanes = S::F32_LANES;
    let empty = Soa3::new(&[], &[], &[]);
    assert_eq!(
        refit::max_dist_sq_with(simd, empty, [1.0; 3]).to_bits(),
        0.0f32.to_bits()
    );
    assert_eq!(bits3(refit::sum_with(simd, empty)), [0; 3]);
    assert_eq!(
        bits_box(refit::bounds_with(simd, empty)),
        bits_box(refit::EMPTY_BOUNDS)
    );
    assert_eq!(
        bits_box(refit::bounds_indexed_with(simd, empty, &[])),
        bits_box(refit::EMPTY_BOUNDS)
    );

    for n in [
        1,
        lanes.saturating_sub(1).max(1),
        lanes,
        lanes + 1,
        3 * lanes + 2,
    ] {
        // Points on the x axis at 1..=n, except one NaN point: NaN is skipped by max/min.
        let mut x: Vec<f32> = (1..=n).map(|i| i as f32).collect();
        let y = vec![0.0f32; n];
        let z = vec![-0.0f32; n];
        x[n / 2] = nan;
        let p = Soa3::new(&x, &y, &z);
        let top = if n / 2 == n - 1 && n > 1 {
            (n - 1) as f32
        } else {
            n as f32
        };
        let d = refit::max_dist_sq_with(simd, p, [0.0; 3]);
        if n == 1 {
            assert_eq!(d.to_bits(), 0.0f32.to_bits(), "only point is NaN: 0");
        } else {
            assert_eq!(d, top * top, "{simd:?} n={n}");
        }
        let (lo, hi) = refit::bounds_with(simd, p);
        assert_eq!(
            (lo[1].to_bits(), hi[1].to_bits()),
            (0.0f32.to_bits(), 0.0f32.to_bits())
        );
        assert_eq!(
            (lo[2].to_bits(), hi[2].to_bits()),
            ((-0.0f32).to_bits(), (-0.0f32).to_bits())
        );
        if n > 1 {
            assert_eq!((lo[0], hi[0]), (if n / 2 == 0 { 2.0 } else { 1.0 }, top));
        } else {
            assert_eq!((lo[0], hi[0]), (inf, -inf), "all-NaN axis stays empty");
        }
        // Sums propagate NaN; zeros keep their sign.
        let s = refit::sum_with(simd, p);
        assert!(s[0].is_nan());
        assert_eq!(s[1].to_bits(), 0.0f32.to_bits());
        assert_eq!(
            s[2].to_bits(),
            0.0f32.to_bits(),
            "sums start at +0 and +0 + -0 = +0"
        );
        // A sum that starts from a nonzero value keeps its exact value through -0 padding.
        let w: Vec<f32> = (0..n).map(|i| if i == 0 { 0.75 } else { -0.0 }).collect();
        assert_eq!(refit::sum_with(simd, Soa3::new(&w, &w, &w))[0], 0.75);

        // Infinities: an infinite point is infinitely far; inf - inf is NaN and skipped.
        let xi: Vec<f32> = (0..n).map(|i| if i == n - 1 { inf } else { 0.5 }).collect();
        let p = Soa3::new(&xi, &y, &y);
        assert_eq!(refit::max_dist_sq_with(simd, p, [0.0; 3]), inf);
        let d = refit::max_dist_sq_with(simd, p, [inf, 0.0, 0.0]);
        assert_eq!(
            d,
            if n == 1 { 0.0 } else { inf },
            "inf - inf skipped, 0.5 - inf = -inf"
        );
        assert_eq!(refit::bounds_with(simd, p).1[0], inf);
        assert_eq!(refit::sum_with(simd, p)[0], inf);
    }
    // +-0 ties: the first in lane order stays.
    let x = [-0.0f32, 0.0];
    let p = Soa3::new(&x, &x, &x);
    let (lo, hi) = refit::bounds_with(simd, p);
    assert_eq!(
        (lo[0].to_bits(), hi[0].to_bits()),
        ((-0.0f32).to_bits(), (-0.0f32).to_bits())
    );
    let x = [0.0f32, -0.0];
    let p = Soa3::new(&x, &x, &x);
    let (lo, hi) = refit::bounds_with(simd, p);
    assert_eq!(
        (lo[0].to_bits(), hi[0].to_bits()),
        (0.0f32.to_bits(), 0.0f32.to_bits())
    );
    // inf + -inf is NaN in the sum.
    let x = [inf, -inf];
    let p = Soa3::new(&x, &x, &x);
    assert!(refit::sum_with(simd, p)[0].is_nan());
}

#[test]
fn refit_special_values_on_all_backends() {
    on_all_backends!(check_refit_special_values);
}

#[test]
fn lane_references_agree_with_sequential_on_exact_data() {
    // Small integers sum exactly in any order, so every lane count gives the same sum.
    let x: Vec<f32> = (0..1000).map(|i| (i % 17) as f32).collect();
    let p = Soa3::new(&x, &x, &x);
    let want = reference::sum_scalar_lanes(p, 1);
    assert_eq!(want[0], (0..1000).map(|i| (i % 17) as f32).sum::<f32>());
    for lanes in [1, 2, 4, 8, 16, 64] {
        assert_eq!(reference::sum_scalar_lanes(p, lanes), want);
        assert_eq!(
            reference::bounds_scalar_lanes(p, lanes),
            ([0.0; 3], [16.0; 3])
        );
        assert_eq!(
            reference::max_dist_sq_scalar_lanes(p, [0.0; 3], lanes),
            3.0 * 256.0
        );
    }
}

fn moving(rng: &mut Rng, scale: f32) -> overlap::MovingSphere {
    let v = |rng: &mut Rng| f64::from(rng.f32_in(-1.0, 1.0) * scale);
    overlap::MovingSphere {
        c0: [v(rng), v(rng), v(rng)],
        r0: f64::from(rng.f32_in(0.0, 0.3) * scale),
        c1: [v(rng), v(rng), v(rng)],
        r1: f64::from(rng.f32_in(0.0, 0.3) * scale),
    }
}

fn moving_soa(spheres: &[overlap::MovingSphere], stride: usize) -> Vec<f64> {
    let mut data = vec![f64::NAN; overlap::MOVING_SPHERE_FIELDS * stride];
    for (k, s) in spheres.iter().enumerate() {
        let f = [
            s.c0[0], s.c0[1], s.c0[2], s.r0, s.c1[0], s.c1[1], s.c1[2], s.r1,
        ];
        for (i, x) in f.into_iter().enumerate() {
            data[i * stride + k] = x;
        }
    }
    data
}

/// The moving-sphere block test: the scalar reference's bits on every backend (padding of
/// NaN lanes, every block size up to 32, tiny and huge scales).
fn check_moving_blocks<S: Simd>(simd: S) {
    let mut rng = Rng::new(21);
    for scale in [1.0, 1e-20, 1e20, 3e-3] {
        for n in block_sizes(S::F32_LANES, overlap::MAX_BLOCK) {
            for len in [n, (n + 3).min(overlap::MAX_BLOCK)] {
                let entries: Vec<_> = (0..n).map(|_| moving(&mut rng, scale)).collect();
                let data = moving_soa(&entries, len);
                let block = overlap::MovingSphereSoa::new(&data, len);
                let p = moving(&mut rng, scale);
                let want = reference::moving_sphere_block_scalar(&p, block, n);
                let got = overlap::moving_sphere_block_with(simd, &p, block, n);
                assert_eq!(got, want, "{simd:?} n={n} len={len} scale={scale}");
                assert_eq!(u64::from(got) >> n, 0, "bits past n");
            }
        }
    }
}

#[test]
fn moving_blocks_match_reference_on_all_backends() {
    on_all_backends!(check_moving_blocks);
}

/// Conservative: whenever the spheres meet at a sampled time (by an `f64` margin), the test
/// says so; and the cases a swept test must tell apart are told apart.
#[test]
fn moving_spheres_meet_whenever_they_do() {
    let meet_at = |a: &overlap::MovingSphere, b: &overlap::MovingSphere, t: f64| {
        let c = |x: [f64; 3], y: [f64; 3]| {
            std::array::from_fn::<f64, 3, _>(|k| x[k] + t * (y[k] - x[k]))
        };
        let (ca, cb) = (c(a.c0, a.c1), c(b.c0, b.c1));
        let d = ((0..3).map(|k| (ca[k] - cb[k]).powi(2)).sum::<f64>()).sqrt();
        let r = (1.0 - t) * (a.r0 + b.r0) + t * (a.r1 + b.r1);
        d <= r * (1.0 - 1e-9)
    };
    let mut rng = Rng::new(5);
    let mut met = 0;
    for _ in 0..200_000 {
        let (a, b) = (moving(&mut rng, 1.0), moving(&mut rng, 1.0));
        let sampled = (0..=64).any(|i| meet_at(&a, &b, i as f64 / 64.0));
        if sampled {
            met += 1;
            assert!(reference::moving_spheres_meet(&a, &b), "{a:?} {b:?}");
        }
    }
    assert!(met > 1000);
    let still = |c: [f64; 3], r: f64| overlap::MovingSphere {
        c0: c,
        r0: r,
        c1: c,
        r1: r,
    };
    // Still and apart: culled (the near-still guard); still and touching: kept.
    assert!(!reference::moving_spheres_meet(
        &still([0.0; 3], 1.0),
        &still([3.0, 0.0, 0.0], 1.0)
    ));
    assert!(reference::moving_spheres_meet(
        &still([0.0; 3], 1.0),
        &still([2.0, 0.0, 0.0], 1.0)
    ));
    // Passing through each other mid-step (apart at both ends): kept.
    let across = overlap::MovingSphere {
        c0: [-5.0, 0.0, 0.0],
        r0: 1.0,
        c1: [5.0, 0.0, 0.0],
        r1: 1.0,
    };
    assert!(reference::moving_spheres_meet(
        &across,
        &still([0.0, 0.5, 0.0], 0.5)
    ));
    // Crossing the same point at different times (each first, then the other): culled.
    let other = overlap::MovingSphere {
        c0: [0.0, 5.0, 0.0],
        r0: 0.4,
        c1: [0.0, -15.0, 0.0],
        r1: 0.4,
    };
    let fast = overlap::MovingSphere {
        c0: [-10.0, 0.0, 0.0],
        r0: 0.4,
        c1: [10.0, 0.0, 0.0],
        r1: 0.4,
    };
    assert!(!reference::moving_spheres_meet(&fast, &other));
    // NaN never meets.
    let nan = still([f64::NAN, 0.0, 0.0], 1.0);
    assert!(!reference::moving_spheres_meet(&nan, &still([0.0; 3], 1.0)));
}

// ---------------------------------------------------------------------------------------
// apart: feature pairs certainly farther than a distance

/// Random pairs of four points in `[-1, 1)^3` (a few of them moved away by up to 3 along
/// one axis, so that some are apart and some not at every `d` tried), scaled by `scale`.
fn four_points(rng: &mut Rng, n: usize, scale: f64) -> apart::FourPoints {
    let mut pairs = apart::FourPoints::default();
    for i in 0..n {
        let shift = [0, 1, 2].map(|_| f64::from(rng.f32_in(-3.0, 3.0)));
        let points = std::array::from_fn(|e| {
            std::array::from_fn(|k| {
                let x = f64::from(rng.f32_in(-1.0, 1.0)) + f64::from(rng.f32_in(-1.0, 1.0)) * 1e-9;
                (if e < 2 { x } else { x + shift[k] }) * scale
            })
        });
        pairs.set(i, points);
    }
    pairs
}

fn check_apart<S: Simd>(simd: S) {
    let mut rng = Rng::new(41);
    let mut certified = [0u32; 2];
    for scale in [1.0, 1e-30, 3e25] {
        for n in [0, 1, 3, 7, 8, 9, 31, 63, 64] {
            let pairs = four_points(&mut rng, n, scale);
            for d in [
                0.0,
                0.1 * scale,
                0.7 * scale,
                2.0 * scale,
                1e-300,
                f64::INFINITY,
            ] {
                let s = apart::segments_apart_with(simd, &pairs, n, d);
                assert_eq!(
                    s,
                    reference::segments_apart_scalar(&pairs, n, d),
                    "n {n} d {d}"
                );
                let t = apart::point_triangles_apart_with(simd, &pairs, n, d);
                assert_eq!(
                    t,
                    reference::point_triangles_apart_scalar(&pairs, n, d),
                    "n {n} d {d}"
                );
                assert!(n == 64 || (s | t) >> n == 0, "no bit past n");
                certified[0] += s.count_ones();
                certified[1] += t.count_ones();
            }
        }
    }
    // The data holds pairs certainly apart (the bits are not all zero by accident).
    assert!(certified.iter().all(|&c| c > 100), "{certified:?}");
}

#[test]
fn apart_matches_reference_on_all_backends() {
    on_all_backends!(check_apart);
}

#[test]
fn apart_certifies_far_pairs_and_never_near_ones() {
    use reference::{point_triangle_apart, segment_pair_apart};
    // Two unit segments 2 apart along z, crossing in projection.
    let ee = [
        [-1.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [0.0, -1.0, 2.0],
        [0.0, 1.0, 2.0],
    ];
    assert!(segment_pair_apart(ee, 1.999));
    assert!(!segment_pair_apart(ee, 2.0));
    // Parallel segments 1 apart, overlapping along their length.
    let par = [
        [0.0, 0.0, 0.0],
        [4.0, 0.0, 0.0],
        [1.0, 1.0, 0.0],
        [3.0, 1.0, 0.0],
    ];
    assert!(segment_pair_apart(par, 0.999));
    assert!(!segment_pair_apart(par, 1.0));
    // A point 3 above a triangle's interior; then beyond its edge in its plane; then
    // beyond a corner.
    let t = [[0.0, 0.0, 0.0], [4.0, 0.0, 0.0], [0.0, 4.0, 0.0]];
    let pt = |p: [f64; 3]| [p, t[0], t[1], t[2]];
    assert!(point_triangle_apart(pt([1.0, 1.0, 3.0]), 2.999));
    assert!(!point_triangle_apart(pt([1.0, 1.0, 3.0]), 3.0));
    assert!(point_triangle_apart(pt([3.0, 3.0, 0.0]), 1.414));
    assert!(!point_triangle_apart(pt([3.0, 3.0, 0.0]), 1.415));
    assert!(point_triangle_apart(pt([-3.0, -4.0, 0.0]), 4.999));
    assert!(!point_triangle_apart(pt([-3.0, -4.0, 0.0]), 5.0));
    // Touching, degenerate, non-finite and out-of-range input certify nothing.
    assert!(!point_triangle_apart(pt([2.0, 0.0, 0.0]), 0.0));
    assert!(!point_triangle_apart(pt([1.0, 1.0, 3.0]), 3e200));
    assert!(!segment_pair_apart([[0.0; 3]; 4], 0.0));
    assert!(!segment_pair_apart(
        [[f64::NAN; 3], [1.0; 3], [5.0; 3], [6.0; 3]],
        0.1
    ));
    assert!(!point_triangle_apart(
        [[9.0; 3], [0.0; 3], [0.0; 3], [0.0; 3]],
        f64::NAN
    ));
    // Two points (zero-length segments) far apart: some direction still certifies or
    // nothing does; never a wrong answer.
    let dots = [[0.0; 3], [0.0; 3], [1.0, 0.0, 0.0], [1.0, 0.0, 0.0]];
    assert!(!segment_pair_apart(dots, 1.0));
}

fn check_centroids_apart<S: Simd>(simd: S) {
    let mut rng = Rng::new(43);
    let mut certified = 0u32;
    for scale in [1.0, 1e-30, 3e25] {
        for n in [0, 1, 5, 8, 13, 64] {
            let p0 = four_points(&mut rng, n, scale);
            let p1 = four_points(&mut rng, n, scale);
            let mut pairs = apart::MovingPoints::default();
            for i in 0..n {
                // Half the pairs move a little, half across the box.
                let (x0, mut x1) = (p0.get(i), p1.get(i));
                if i % 2 == 0 {
                    x1 = std::array::from_fn(|e| {
                        std::array::from_fn(|k| x0[e][k] + 0.01 * x1[e][k])
                    });
                }
                pairs.set(i, &x0, &x1);
            }
            let m = 5.0 * scale;
            for vf in [true, false] {
                for delta in [0.0, 0.05 * scale, 2.0 * scale] {
                    for t_end in [1.0, 0.3] {
                        let got = apart::centroids_apart_with(simd, &pairs, n, vf, delta, m, t_end);
                        let want =
                            reference::centroids_apart_scalar(&pairs, n, vf, delta, m, t_end);
                        assert_eq!(got, want, "n {n} vf {vf} delta {delta} t {t_end}");
                        certified += got.count_ones();
                    }
                }
            }
        }
    }
    assert!(certified > 100, "{certified}");
}

#[test]
fn centroids_apart_matches_reference_on_all_backends() {
    on_all_backends!(check_centroids_apart);
}

fn check_apart_beyond_motion<S: Simd>(simd: S) {
    let mut rng = Rng::new(47);
    let mut certified = 0u32;
    for scale in [1.0, 1e-30, 3e25] {
        for n in [0, 1, 5, 8, 13, 64] {
            let p0 = four_points(&mut rng, n, scale);
            let p1 = four_points(&mut rng, n, scale);
            let mut pairs = apart::MovingPoints::default();
            for i in 0..n {
                // Most pairs move a little (a translation and a small part of another pose),
                // some across the box.
                let (x0, mut x1) = (p0.get(i), p1.get(i));
                if i % 4 != 0 {
                    let shift = x1[0];
                    x1 = std::array::from_fn(|e| {
                        std::array::from_fn(|k| x0[e][k] + shift[k] + 0.01 * x1[e][k])
                    });
                }
                pairs.set(i, &x0, &x1);
            }
            let m = 15.0 * scale;
            for vf in [true, false] {
                for delta in [0.0, 0.05 * scale, 2.0 * scale] {
                    for (t_end, closing) in [(1.0, 1.0), (0.3, 1.0), (1e-300, 1.0), (1.0, 1.25)] {
                        let got = apart::apart_beyond_motion_with(
                            simd, &pairs, n, vf, delta, closing, m, t_end,
                        );
                        let want = reference::apart_beyond_motion_scalar(
                            &pairs, n, vf, delta, closing, m, t_end,
                        );
                        assert_eq!(got, want, "n {n} vf {vf} delta {delta} t {t_end}");
                        certified += got.count_ones();
                    }
                }
            }
        }
    }
    assert!(certified > 100, "{certified}");
}

#[test]
fn apart_beyond_motion_matches_reference_on_all_backends() {
    on_all_backends!(check_apart_beyond_motion);
}

/// The motion bound on hand-made moves: a vertex falling onto a face is apart only over the
/// part of the step before it can arrive; features translating together stay apart by their
/// distance at pose 0, and no further.
#[test]
fn apart_beyond_motion_on_hand_cases() {
    let apart = |x0: &[[f64; 3]; 4], x1: &[[f64; 3]; 4], vf, delta, m, t_end| {
        reference::moving_apart_beyond_motion(x0, x1, vf, delta, 1.0, m, t_end)
    };
    let closing = |x0: &[[f64; 3]; 4], x1: &[[f64; 3]; 4], c| {
        reference::moving_apart_beyond_motion(x0, x1, true, 0.0, c, 1.0, 1.0)
    };
    let tri = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
    let falling = (
        [[0.25, 0.25, 1.0], tri[0], tri[1], tri[2]],
        [[0.25, 0.25, 0.0], tri[0], tri[1], tri[2]],
    );
    let m = 1.0;
    // It reaches the face at t = 1: never apart over the whole step, with or without delta.
    assert!(!apart(&falling.0, &falling.1, true, 0.0, m, 1.0));
    assert!(!apart(&falling.0, &falling.1, true, 0.1, m, 1.0));
    // Over [0, 0.9] it stays 0.1 above: apart for a delta below that, not at it.
    assert!(apart(&falling.0, &falling.1, true, 0.0, m, 0.9));
    assert!(apart(&falling.0, &falling.1, true, 0.099, m, 0.9));
    assert!(!apart(&falling.0, &falling.1, true, 0.1, m, 0.9));
    // A sheet's neighbours translating together: 0.5 apart in the plane all step.
    let shift = [0.3, -0.2, 0.0];
    let moved = |x: [[f64; 3]; 4]| x.map(|p| [p[0] + shift[0], p[1] + shift[1], p[2] + shift[2]]);
    let beside = [[1.5, 0.0, 0.0], tri[0], tri[1], tri[2]];
    assert!(apart(&beside, &moved(beside), true, 0.0, 2.0, 1.0));
    assert!(apart(&beside, &moved(beside), true, 0.499, 2.0, 1.0));
    assert!(!apart(&beside, &moved(beside), true, 0.5, 2.0, 1.0));
    // Two edges 0.5 apart, one turning towards the other by 0.4 at its far end (the bound
    // is |D_a1| = 0.4): apart at delta 0.05 (0.5 > 0.45), not at 0.2 (0.5 < 0.6).
    let edges0 = [
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [0.0, 0.5, 0.0],
        [1.0, 0.5, 0.0],
    ];
    let mut edges1 = edges0;
    edges1[1][1] = 0.4;
    assert!(apart(&edges0, &edges1, false, 0.05, 1.0, 1.0));
    assert!(!apart(&edges0, &edges1, false, 0.2, 1.0, 1.0));
    // A vertex 1 above a face, moving 0.5 towards it: apart with the motion counted twice
    // less a little (1 > 0.999), not counted twice (1 = 1) or with a closing below 1.
    let mut half = falling.1;
    half[0][2] = 0.5;
    assert!(closing(&falling.0, &half, 1.998));
    assert!(!closing(&falling.0, &half, 2.0));
    assert!(!closing(&falling.0, &falling.0, 0.5));
    assert!(!closing(&falling.0, &falling.0, f64::INFINITY));
    // Out of range: nothing certified.
    assert!(!apart(&beside, &moved(beside), true, 0.0, 2.0, 0.0));
    assert!(!apart(&beside, &moved(beside), true, -1.0, 2.0, 1.0));
    assert!(!apart(
        &beside,
        &moved(beside),
        true,
        0.0,
        2f64.powi(500),
        1.0
    ));
}
