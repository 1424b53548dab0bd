//! Every kernel against its scalar reference, bit for bit, on `pulp::Scalar`, `Scalar128b`,
//! `Scalar256b`, `Scalar512b`, the native x86 backends present on this machine, and the
//! dispatched backend (both through `*_with` and through the public entry).

use dhcd_kernels::narrow::{self, AabbSoaMut};
use dhcd_kernels::overlap::{self, AabbSoa, DhSoa, SphereSoa};
use dhcd_kernels::pulp::{self, Simd, WithSimd};
use dhcd_kernels::refit;
use dhcd_kernels::Soa3;

fn mk(v: &mut [Vec<f32>; 6]) -> AabbSoaMut<'_> {
    let [a, b, c, d, e, f] = v;
    AabbSoaMut {
        min_x: a,
        min_y: b,
        min_z: c,
        max_x: d,
        max_y: e,
        max_z: f,
    }
}

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
// overlap

struct Spheres {
    c: [Vec<f32>; 3],
    r: Vec<f32>,
}

impl Spheres {
    fn random(rng: &mut Rng, n: usize, every: usize) -> Self {
        let c = [
            values(rng, n, every),
            values(rng, n, every),
            values(rng, n, every),
        ];
        let r = (0..n)
            .map(|i| {
                if every > 0 && i % every == 1 {
                    [0.0, -0.0, f32::INFINITY, f32::NAN][rng.below(4)]
                } else {
                    rng.f32_in(0.0, 0.6)
                }
            })
            .collect();
        Spheres { c, r }
    }
    fn soa(&self) -> SphereSoa<'_> {
        SphereSoa {
            cx: &self.c[0],
            cy: &self.c[1],
            cz: &self.c[2],
            r: &self.r,
        }
    }
}

fn pairs(rng: &mut Rng, n: usize, na: usize, nb: usize) -> (Vec<u32>, Vec<u32>) {
    (0..n)
        .map(|_| (rng.below(na) as u32, rng.below(nb) as u32))
        .unzip()
}

/// `out` beyond `n` must be untouched (sentinel 7), and the count must match the mask.
fn check_out(out: &[u32], n: usize, count: usize) {
    assert!(out[..n].iter().all(|&o| o <= 1));
    assert!(
        out[n..].iter().all(|&o| o == 7),
        "kernel wrote past the pair list"
    );
    assert_eq!(out[..n].iter().map(|&o| o as usize).sum::<usize>(), count);
}

fn check_sphere_pairs<S: Simd>(simd: S) {
    let mut rng = Rng::new(1);
    for every in [0, 5] {
        let a = Spheres::random(&mut rng, 97, every);
        let b = Spheres::random(&mut rng, 61, every);
        for n in sizes(S::F32_LANES) {
            let (ia, ib) = pairs(&mut rng, n, 97, 61);
            let mut want = vec![7u32; n + 3];
            let mut got = vec![7u32; n + 3];
            let hw = overlap::sphere_pairs_scalar(a.soa(), b.soa(), &ia, &ib, &mut want);
            let hg = overlap::sphere_pairs_with(simd, a.soa(), b.soa(), &ia, &ib, &mut got);
            assert_eq!((hg, &got), (hw, &want), "{simd:?} n={n} every={every}");
            check_out(&got, n, hg);
        }
    }
}

struct Dh {
    vertex: Vec<u32>,
    r: Vec<f32>,
    p: [Vec<f32>; 3],
}

impl Dh {
    fn random(rng: &mut Rng, nodes: usize, points: usize, every: usize) -> Self {
        let p = [
            values(rng, points, every),
            values(rng, points, every),
            values(rng, points, every),
        ];
        let vertex = (0..nodes).map(|_| rng.below(points) as u32).collect();
        let r = Spheres::random(rng, nodes, every).r;
        Dh { vertex, r, p }
    }
    fn soa(&self) -> DhSoa<'_> {
        DhSoa {
            vertex: &self.vertex,
            r: &self.r,
            points: Soa3::new(&self.p[0], &self.p[1], &self.p[2]),
        }
    }
}

fn check_dh_pairs<S: Simd>(simd: S) {
    let mut rng = Rng::new(2);
    for every in [0, 5] {
        let a = Dh::random(&mut rng, 80, 300, every);
        let b = Dh::random(&mut rng, 50, 200, every);
        for n in sizes(S::F32_LANES) {
            let (ia, ib) = pairs(&mut rng, n, 80, 50);
            let mut want = vec![7u32; n + 3];
            let mut got = vec![7u32; n + 3];
            let hw = overlap::dh_pairs_scalar(a.soa(), b.soa(), &ia, &ib, &mut want);
            let hg = overlap::dh_pairs_with(simd, a.soa(), b.soa(), &ia, &ib, &mut got);
            assert_eq!((hg, &got), (hw, &want), "{simd:?} n={n} every={every}");
            check_out(&got, n, hg);
        }
    }
}

struct Boxes([Vec<f32>; 6]);

impl Boxes {
    fn random(rng: &mut Rng, n: usize, every: usize) -> Self {
        let mut f: [Vec<f32>; 6] = core::array::from_fn(|_| Vec::with_capacity(n));
        for i in 0..n {
            if every > 0 && i % every == 2 {
                // empty box
                for a in 0..3 {
                    f[a].push(f32::INFINITY);
                    f[3 + a].push(f32::NEG_INFINITY);
                }
                continue;
            }
            for a in 0..3 {
                let c = if every > 0 && i % every == 3 {
                    SPECIALS[rng.below(SPECIALS.len())]
                } else {
                    rng.f32_in(-1.0, 1.0)
                };
                let h = rng.f32_in(0.0, 0.4);
                f[a].push(c - h);
                f[3 + a].push(c + h);
            }
        }
        Boxes(f)
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
    fn get(&self, i: usize) -> ([f32; 3], [f32; 3]) {
        let f = &self.0;
        ([f[0][i], f[1][i], f[2][i]], [f[3][i], f[4][i], f[5][i]])
    }
}

fn check_aabb_pairs<S: Simd>(simd: S) {
    let mut rng = Rng::new(3);
    for every in [0, 5] {
        let a = Boxes::random(&mut rng, 70, every);
        let b = Boxes::random(&mut rng, 90, every);
        for n in sizes(S::F32_LANES) {
            let (ia, ib) = pairs(&mut rng, n, 70, 90);
            let mut want = vec![7u32; n + 3];
            let mut got = vec![7u32; n + 3];
            let mut got2 = vec![7u32; n + 3];
            let hw = overlap::aabb_pairs_scalar(a.soa(), b.soa(), &ia, &ib, &mut want);
            let hg = overlap::aabb_pairs_with(simd, a.soa(), b.soa(), &ia, &ib, &mut got);
            assert_eq!((hg, &got), (hw, &want), "{simd:?} n={n} every={every}");
            check_out(&got, n, hg);
            let ht =
                narrow::tri_aabb_overlap_pairs_with(simd, a.soa(), b.soa(), &ia, &ib, &mut got2);
            assert_eq!((ht, &got2), (hw, &want));
        }
    }
}

fn check_tri_aabb_row<S: Simd>(simd: S) {
    let mut rng = Rng::new(4);
    for every in [0, 5] {
        let a = Boxes::random(&mut rng, 40, every);
        for n in sizes(S::F32_LANES) {
            let b = Boxes::random(&mut rng, n, every);
            for i in 0..40 {
                let mut want = vec![7u32; n + 3];
                let mut got = vec![7u32; n + 3];
                let hw = narrow::tri_aabb_overlap_row_scalar(a.get(i), b.soa(), &mut want);
                let hg = narrow::tri_aabb_overlap_row_with(simd, a.get(i), b.soa(), &mut got);
                assert_eq!((hg, &got), (hw, &want), "{simd:?} n={n} every={every}");
                check_out(&got, n, hg);
            }
        }
    }
}

#[test]
fn sphere_pairs_matches_reference_on_all_backends() {
    on_all_backends!(check_sphere_pairs);
}

#[test]
fn dh_pairs_matches_reference_on_all_backends() {
    on_all_backends!(check_dh_pairs);
}

#[test]
fn aabb_pairs_and_tri_aabb_overlap_pairs_match_reference_on_all_backends() {
    on_all_backends!(check_aabb_pairs);
}

#[test]
fn tri_aabb_overlap_row_matches_reference_on_all_backends() {
    on_all_backends!(check_tri_aabb_row);
}

#[test]
fn dispatched_overlap_entries_match_reference() {
    let mut rng = Rng::new(5);
    let (sa, sb) = (
        Spheres::random(&mut rng, 97, 5),
        Spheres::random(&mut rng, 61, 5),
    );
    let (da, db) = (
        Dh::random(&mut rng, 80, 300, 5),
        Dh::random(&mut rng, 50, 200, 5),
    );
    let (ba, bb) = (
        Boxes::random(&mut rng, 70, 5),
        Boxes::random(&mut rng, 90, 5),
    );
    for n in sizes(dhcd_kernels::f32_lanes()) {
        let mut want = vec![7u32; n];
        let mut got = vec![7u32; n];
        let (ia, ib) = pairs(&mut rng, n, 61, 50);
        let hw = overlap::sphere_pairs_scalar(sa.soa(), sb.soa(), &ia, &ib, &mut want);
        assert_eq!(
            (
                overlap::sphere_pairs(sa.soa(), sb.soa(), &ia, &ib, &mut got),
                &got
            ),
            (hw, &want)
        );
        let hw = overlap::dh_pairs_scalar(da.soa(), db.soa(), &ia, &ib, &mut want);
        assert_eq!(
            (
                overlap::dh_pairs(da.soa(), db.soa(), &ia, &ib, &mut got),
                &got
            ),
            (hw, &want)
        );
        let hw = overlap::aabb_pairs_scalar(ba.soa(), bb.soa(), &ia, &ib, &mut want);
        assert_eq!(
            (
                overlap::aabb_pairs(ba.soa(), bb.soa(), &ia, &ib, &mut got),
                &got
            ),
            (hw, &want)
        );
        assert_eq!(
            (
                overlap::aabb_pairs_vectorized(ba.soa(), bb.soa(), &ia, &ib, &mut got),
                &got
            ),
            (hw, &want)
        );
        let ht = narrow::tri_aabb_overlap_pairs(ba.soa(), bb.soa(), &ia, &ib, &mut got);
        assert_eq!((ht, &got), (hw, &want));
        let bn = Boxes::random(&mut rng, n, 5);
        let hw = narrow::tri_aabb_overlap_row_scalar(ba.get(3), bn.soa(), &mut want);
        assert_eq!(
            (
                narrow::tri_aabb_overlap_row(ba.get(3), bn.soa(), &mut got),
                &got
            ),
            (hw, &want)
        );
    }
}

/// Hand-made pairs with known answers, each tested at every lane position.
fn check_overlap_special_values<S: Simd>(simd: S) {
    let inf = f32::INFINITY;
    let nan = f32::NAN;
    // (centre a, ra, centre b, rb, overlaps)
    /// (centre a, ra, centre b, rb, overlaps)
    type Case = ([f32; 3], f32, [f32; 3], f32, u32);
    let cases: &[Case] = &[
        ([0.0, 0.0, 0.0], 1.0, [3.0, 0.0, 0.0], 2.0, 1), // exactly touching
        ([0.0, 0.0, 0.0], 1.0, [3.0, 0.0, 0.0], 1.75, 0), // just apart
        ([1.0, 2.0, 3.0], 0.0, [1.0, 2.0, 3.0], 0.0, 1), // zero radius, same centre
        ([0.0, 0.0, 0.0], 0.0, [0.0, 0.0, 1.0], 0.0, 0), // zero radius, apart
        ([0.0, -0.0, 0.0], 0.0, [-0.0, 0.0, -0.0], 0.0, 1), // +-0 are equal
        ([nan, 0.0, 0.0], 1.0, [0.0, 0.0, 0.0], 1.0, 0), // NaN never overlaps
        ([0.0, 0.0, 0.0], nan, [0.0, 0.0, 0.0], 1.0, 0), // NaN radius
        ([inf, 0.0, 0.0], 1.0, [0.0, 0.0, 0.0], 1.0, 0), // infinitely far
        ([inf, 0.0, 0.0], 1.0, [inf, 0.0, 0.0], 1.0, 0), // inf - inf = NaN
        ([0.0, 0.0, 0.0], inf, [5.0, 0.0, 0.0], 0.0, 1), // infinite radius
    ];
    let lanes = S::F32_LANES;
    for (ci, &(ca, ra, cb, rb, want)) in cases.iter().enumerate() {
        // Filler pairs: far-apart spheres (never overlap), the case at position `pos`.
        for n in [1, lanes, lanes + 1, 2 * lanes + 1] {
            for pos in 0..n {
                let mut s = Spheres {
                    c: [vec![100.0, 0.0], vec![0.0; 2], vec![0.0; 2]],
                    r: vec![1.0; 2],
                };
                let mut t = Spheres {
                    c: [vec![-100.0, 0.0], vec![0.0; 2], vec![0.0; 2]],
                    r: vec![1.0; 2],
                };
                for k in 0..3 {
                    s.c[k][1] = ca[k];
                    t.c[k][1] = cb[k];
                }
                s.r[1] = ra;
                t.r[1] = rb;
                let ia: Vec<u32> = (0..n).map(|k| (k == pos) as u32).collect();
                let mut out = vec![7u32; n];
                let h = overlap::sphere_pairs_with(simd, s.soa(), t.soa(), &ia, &ia, &mut out);
                let expect: Vec<u32> = (0..n).map(|k| if k == pos { want } else { 0 }).collect();
                assert_eq!(
                    (h, &out),
                    (want as usize, &expect),
                    "{simd:?} case {ci} n={n} pos={pos}"
                );

                // The same case as a DH pair: centres read through the vertex index.
                let p = [
                    vec![100.0, -100.0, ca[0], cb[0]],
                    vec![0.0, 0.0, ca[1], cb[1]],
                    vec![0.0, 0.0, ca[2], cb[2]],
                ];
                let pts = Soa3::new(&p[0], &p[1], &p[2]);
                let da = DhSoa {
                    vertex: &[0, 2],
                    r: &s.r,
                    points: pts,
                };
                let db = DhSoa {
                    vertex: &[1, 3],
                    r: &t.r,
                    points: pts,
                };
                let h = overlap::dh_pairs_with(simd, da, db, &ia, &ia, &mut out);
                assert_eq!(
                    (h, &out),
                    (want as usize, &expect),
                    "{simd:?} dh case {ci} n={n} pos={pos}"
                );
            }
        }
    }

    // Boxes: (a, b, overlaps)
    type B = ([f32; 3], [f32; 3]);
    let unit: B = ([0.0; 3], [1.0; 3]);
    let box_cases: &[(B, B, u32)] = &[
        (unit, ([1.0, 0.0, 0.0], [2.0, 1.0, 1.0]), 1), // touching face
        (unit, ([1.0, 1.0, 1.0], [2.0, 2.0, 2.0]), 1), // touching corner
        (unit, ([1.0000001, 0.0, 0.0], [2.0, 1.0, 1.0]), 0), // next float apart
        (unit, refit::EMPTY_BOUNDS, 0),                // empty box
        (refit::EMPTY_BOUNDS, refit::EMPTY_BOUNDS, 0), // empty vs empty
        (unit, ([0.5; 3], [0.5; 3]), 1),               // point box inside
        (([-0.0; 3], [-0.0; 3]), ([0.0; 3], [0.0; 3]), 1), // +-0 point boxes
        (unit, ([nan, 0.0, 0.0], [1.0; 3]), 0),        // NaN
        (unit, ([-inf; 3], [inf; 3]), 1),              // everything
        (unit, ([inf; 3], [inf; 3]), 0),               // at infinity
    ];
    for (ci, &(ba, bb, want)) in box_cases.iter().enumerate() {
        for n in [1, lanes, lanes + 1, 2 * lanes + 1] {
            for pos in 0..n {
                let far: B = ([10.0; 3], [11.0; 3]);
                let mk = |x: B, filler: B| {
                    let v = [filler, x];
                    Boxes(core::array::from_fn(|f| {
                        v.iter()
                            .map(|b| if f < 3 { b.0[f] } else { b.1[f - 3] })
                            .collect()
                    }))
                };
                let a = mk(ba, ([-11.0; 3], [-10.0; 3]));
                let b = mk(bb, far);
                let ia: Vec<u32> = (0..n).map(|k| (k == pos) as u32).collect();
                let expect: Vec<u32> = (0..n).map(|k| if k == pos { want } else { 0 }).collect();
                let mut out = vec![7u32; n];
                let h = overlap::aabb_pairs_with(simd, a.soa(), b.soa(), &ia, &ia, &mut out);
                assert_eq!(
                    (h, &out),
                    (want as usize, &expect),
                    "{simd:?} box case {ci} n={n} pos={pos}"
                );
                // Row form: a[1] against b[ia[k]].
                let bs: Vec<B> = ia.iter().map(|&i| b.get(i as usize)).collect();
                let row = Boxes(core::array::from_fn(|f| {
                    bs.iter()
                        .map(|b| if f < 3 { b.0[f] } else { b.1[f - 3] })
                        .collect()
                }));
                let h = narrow::tri_aabb_overlap_row_with(simd, a.get(1), row.soa(), &mut out);
                assert_eq!(
                    (h, &out),
                    (want as usize, &expect),
                    "{simd:?} row case {ci} n={n} pos={pos}"
                );
            }
        }
    }
}

#[test]
fn overlap_special_values_on_all_backends() {
    on_all_backends!(check_overlap_special_values);
}

#[test]
#[should_panic(expected = "ia and ib differ")]
fn overlap_rejects_ragged_pair_lists() {
    let s = Spheres {
        c: [vec![0.0], vec![0.0], vec![0.0]],
        r: vec![1.0],
    };
    overlap::sphere_pairs(s.soa(), s.soa(), &[0, 0], &[0], &mut [0; 2]);
}

#[test]
#[should_panic(expected = "out is shorter")]
fn overlap_rejects_short_output() {
    let s = Spheres {
        c: [vec![0.0], vec![0.0], vec![0.0]],
        r: vec![1.0],
    };
    overlap::sphere_pairs(s.soa(), s.soa(), &[0, 0], &[0, 0], &mut [0; 1]);
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
                let want = refit::max_dist_sq_scalar_lanes(p, c, lanes);
                assert_eq!(
                    refit::max_dist_sq_with(simd, p, c).to_bits(),
                    want.to_bits(),
                    "{simd:?} n={n}"
                );
                let want = refit::max_dist_sq_indexed_scalar_lanes(p, idx, c, lanes);
                assert_eq!(
                    refit::max_dist_sq_indexed_with(simd, p, idx, c).to_bits(),
                    want.to_bits()
                );
            }
            assert_eq!(
                bits3(refit::sum_with(simd, p)),
                bits3(refit::sum_scalar_lanes(p, lanes)),
                "{simd:?} n={n} every={every}"
            );
            assert_eq!(
                bits3(refit::sum_indexed_with(simd, p, idx)),
                bits3(refit::sum_indexed_scalar_lanes(p, idx, lanes))
            );
            assert_eq!(
                bits_box(refit::bounds_with(simd, p)),
                bits_box(refit::bounds_scalar_lanes(p, lanes)),
                "{simd:?} n={n}"
            );
            assert_eq!(
                bits_box(refit::bounds_indexed_with(simd, p, idx)),
                bits_box(refit::bounds_indexed_scalar_lanes(p, idx, lanes))
            );
            if lanes == 1 {
                // The sequential references are the 1-lane case.
                assert_eq!(bits3(refit::sum_with(simd, p)), bits3(refit::sum_scalar(p)));
                assert_eq!(
                    bits_box(refit::bounds_with(simd, p)),
                    bits_box(refit::bounds_scalar(p))
                );
            }
            // Max/min do not depend on the order except for +-0 ties; compare values.
            let (lo, hi) = refit::bounds_with(simd, p);
            let (slo, shi) = refit::bounds_scalar(p);
            assert_eq!((lo, hi), (slo, shi));
            assert_eq!(
                refit::max_dist_sq_with(simd, p, [0.5; 3]),
                refit::max_dist_sq_scalar(p, [0.5; 3])
            );
        }
    }
}

#[test]
fn refit_matches_lane_reference_on_all_backends() {
    on_all_backends!(check_refit);
}

#[test]
fn dispatched_refit_entries_match_lane_reference() {
    let lanes = dhcd_kernels::f32_lanes();
    let mut rng = Rng::new(7);
    for n in sizes(lanes) {
        let pts = Points::random(&mut rng, n, 9);
        let p = pts.soa();
        let idx: Vec<u32> = (0..2 * n).map(|_| rng.below(n.max(1)) as u32).collect();
        let idx: &[u32] = if n == 0 { &[] } else { &idx };
        let c = [0.25, 0.5, -0.125];
        assert_eq!(
            refit::max_dist_sq(p, c).to_bits(),
            refit::max_dist_sq_scalar_lanes(p, c, lanes).to_bits()
        );
        assert_eq!(
            refit::max_dist_sq_indexed(p, idx, c).to_bits(),
            refit::max_dist_sq_indexed_scalar_lanes(p, idx, c, lanes).to_bits()
        );
        assert_eq!(
            bits3(refit::sum(p)),
            bits3(refit::sum_scalar_lanes(p, lanes))
        );
        assert_eq!(
            bits3(refit::sum_indexed(p, idx)),
            bits3(refit::sum_indexed_scalar_lanes(p, idx, lanes))
        );
        assert_eq!(
            bits_box(refit::bounds(p)),
            bits_box(refit::bounds_scalar_lanes(p, lanes))
        );
        assert_eq!(
            bits_box(refit::bounds_indexed(p, idx)),
            bits_box(refit::bounds_indexed_scalar_lanes(p, idx, lanes))
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
    let want = refit::sum_scalar(p);
    assert_eq!(want[0], (0..1000).map(|i| (i % 17) as f32).sum::<f32>());
    for lanes in [1, 2, 4, 8, 16, 64] {
        assert_eq!(refit::sum_scalar_lanes(p, lanes), want);
        assert_eq!(refit::bounds_scalar_lanes(p, lanes), ([0.0; 3], [16.0; 3]));
        assert_eq!(
            refit::max_dist_sq_scalar_lanes(p, [0.0; 3], lanes),
            3.0 * 256.0
        );
    }
}

// ---------------------------------------------------------------------------------------
// triangle_bounds

fn check_triangle_bounds<S: Simd>(simd: S) {
    let mut rng = Rng::new(8);
    for every in [0, 4] {
        let pts = Points::random(&mut rng, 200, every);
        for n in sizes(S::F32_LANES) {
            let tris: Vec<[u32; 3]> = (0..n)
                .map(|_| [0; 3].map(|_| rng.below(200) as u32))
                .collect();
            let mut want: [Vec<f32>; 6] = core::array::from_fn(|_| vec![7.0; n + 2]);
            let mut got = want.clone();

            narrow::triangle_bounds_scalar(pts.soa(), &tris, mk(&mut want));
            narrow::triangle_bounds_with(simd, pts.soa(), &tris, mk(&mut got));
            let bits = |v: &[Vec<f32>; 6]| {
                v.clone()
                    .map(|a| a.iter().map(|x| x.to_bits()).collect::<Vec<_>>())
            };
            assert_eq!(bits(&got), bits(&want), "{simd:?} n={n} every={every}");
            assert!(
                got.iter().all(|a| a[n..].iter().all(|&x| x == 7.0)),
                "wrote past tris"
            );
            // Conservative: each box encloses its (finite) vertices.
            for (t, tri) in tris.iter().enumerate() {
                for &v in tri {
                    let q = pts.soa().get(v as usize);
                    for a in 0..3 {
                        if !q[a].is_nan() {
                            assert!(got[a][t] <= q[a] && q[a] <= got[3 + a][t]);
                        }
                    }
                }
            }
        }
    }
    // Special values: NaN skipped, +-0, inf, degenerate triangle.
    let nan = f32::NAN;
    let x = [nan, 1.0, -0.0, 0.0, f32::INFINITY];
    let y = [nan, nan, nan, 2.0, 3.0];
    let z = [nan, 5.0, 5.0, 5.0, 5.0];
    let p = Soa3::new(&x, &y, &z);
    let tris = [[0, 1, 2], [2, 3, 3], [0, 0, 0], [3, 4, 1]];
    let mut o: [Vec<f32>; 6] = core::array::from_fn(|_| vec![0.0; 4]);
    {
        let [a, b, c, d, e, f] = &mut o;
        let out = AabbSoaMut {
            min_x: a,
            min_y: b,
            min_z: c,
            max_x: d,
            max_y: e,
            max_z: f,
        };
        narrow::triangle_bounds_with(simd, p, &tris, out);
    }
    let inf = f32::INFINITY;
    let boxes: Vec<([f32; 3], [f32; 3])> = (0..4)
        .map(|t| ([o[0][t], o[1][t], o[2][t]], [o[3][t], o[4][t], o[5][t]]))
        .collect();
    assert_eq!(
        boxes[0].0.map(f32::to_bits),
        [-0.0f32, inf, 5.0].map(f32::to_bits)
    );
    assert_eq!(
        boxes[0].1.map(f32::to_bits),
        [1.0f32, -inf, 5.0].map(f32::to_bits)
    );
    assert_eq!(
        boxes[1].0.map(f32::to_bits),
        [-0.0f32, 2.0, 5.0].map(f32::to_bits),
        "+-0 tie: first stays"
    );
    assert_eq!(
        boxes[1].1.map(f32::to_bits),
        [-0.0f32, 2.0, 5.0].map(f32::to_bits)
    );
    assert_eq!(boxes[2], refit::EMPTY_BOUNDS, "all-NaN triangle: empty box");
    assert_eq!(boxes[3], ([0.0, 2.0, 5.0], [inf, 3.0, 5.0]));
}

#[test]
fn triangle_bounds_matches_reference_on_all_backends() {
    on_all_backends!(check_triangle_bounds);
}

#[test]
fn dispatched_triangle_bounds_matches_reference() {
    let mut rng = Rng::new(9);
    let pts = Points::random(&mut rng, 500, 11);
    let tris: Vec<[u32; 3]> = (0..1037)
        .map(|_| [0; 3].map(|_| rng.below(500) as u32))
        .collect();
    let mut want: [Vec<f32>; 6] = core::array::from_fn(|_| vec![0.0; 1037]);
    let mut got = want.clone();
    {
        let [a, b, c, d, e, f] = &mut want;
        narrow::triangle_bounds_scalar(
            pts.soa(),
            &tris,
            AabbSoaMut {
                min_x: a,
                min_y: b,
                min_z: c,
                max_x: d,
                max_y: e,
                max_z: f,
            },
        );
        let [a, b, c, d, e, f] = &mut got;
        narrow::triangle_bounds(
            pts.soa(),
            &tris,
            AabbSoaMut {
                min_x: a,
                min_y: b,
                min_z: c,
                max_x: d,
                max_y: e,
                max_z: f,
            },
        );
    }
    let bits = |v: &[Vec<f32>; 6]| {
        v.clone()
            .map(|a| a.iter().map(|x| x.to_bits()).collect::<Vec<_>>())
    };
    assert_eq!(bits(&got), bits(&want));
}
