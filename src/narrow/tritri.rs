//! The exact closed triangle-triangle test, written once and used both to decide
//! intersection (early exit) and to collect the points of the intersection region.
//!
//! Formulation: two closed triangles (possibly degenerate) intersect iff some edge of one
//! meets the other closed triangle. A degenerate triangle (collinear or coincident corners)
//! *is* the segment between its lexicographically smallest and largest corners, and is
//! tested as that segment (or point).

use super::predicates::{
    keep, lerp, lex_le, orient2d, orient3d, projection_axis, sign, Coordinate, Plane, Tri, P3,
};

/// Receives the candidate points of the intersection region. With `COLLECT = false` the
/// test stops at the first hit and computes no points.
pub(crate) trait Sink {
    const COLLECT: bool;
    fn push(&mut self, p: [f64; 3]);
}

/// Decision only.
pub(crate) struct Decide;

impl Sink for Decide {
    const COLLECT: bool = false;
    #[inline(always)]
    fn push(&mut self, _: [f64; 3]) {}
}

/// Candidate points (a superset of the vertices of the convex intersection region, each
/// lying on it up to `f64` rounding).
pub(crate) struct Points {
    pub(crate) pts: [[f64; 3]; Points::CAP],
    pub(crate) len: usize,
}

impl Points {
    /// Upper bound on pushes: 6 edges x (2 endpoints + 3 edge crossings x up to 4 points)
    /// = 84, plus slack.
    const CAP: usize = 96;

    pub(crate) fn new() -> Self {
        Self {
            pts: [[0.0; 3]; Self::CAP],
            len: 0,
        }
    }

    pub(crate) fn as_slice(&self) -> &[[f64; 3]] {
        &self.pts[..self.len]
    }
}

impl Sink for Points {
    const COLLECT: bool = true;
    fn push(&mut self, p: [f64; 3]) {
        if self.pts[..self.len].contains(&p) {
            return;
        }
        debug_assert!(self.len < Self::CAP, "candidate buffer overflow");
        if self.len < Self::CAP {
            self.pts[self.len] = p;
            self.len += 1;
        }
    }
}

/// Projection axis not computed yet (the triangle is known non-degenerate).
const AXIS_UNKNOWN: usize = usize::MAX;

#[inline(always)]
fn to64<C: Coordinate>(p: &P3<C>) -> [f64; 3] {
    p.map(|x| -> f64 { x.into() })
}

/// Closed axis-aligned boxes of the corners overlap (comparisons only: exact).
#[inline(always)]
fn aabb_overlap<C: Coordinate>(a: &Tri<C>, b: &Tri<C>) -> bool {
    let min = |x: C, y: C| if y < x { y } else { x };
    let max = |x: C, y: C| if y > x { y } else { x };
    for k in 0..3 {
        let amin = min(min(a[0][k], a[1][k]), a[2][k]);
        let amax = max(max(a[0][k], a[1][k]), a[2][k]);
        let bmin = min(min(b[0][k], b[1][k]), b[2][k]);
        let bmax = max(max(b[0][k], b[1][k]), b[2][k]);
        if amax < bmin || bmax < amin {
            return false;
        }
    }
    true
}

/// All three strictly on the same side.
#[inline(always)]
fn one_side(d: &[f64; 3]) -> bool {
    (d[0] > 0.0 && d[1] > 0.0 && d[2] > 0.0) || (d[0] < 0.0 && d[1] < 0.0 && d[2] < 0.0)
}

/// The segment a degenerate triangle is: its lexicographically extreme corners (indices).
#[inline]
fn extreme_corners<C: Coordinate>(t: &Tri<C>) -> (usize, usize) {
    let (mut lo, mut hi) = (0, 0);
    for i in 1..3 {
        if !lex_le(&t[lo], &t[i]) {
            lo = i;
        }
        if lex_le(&t[hi], &t[i]) {
            hi = i;
        }
    }
    (lo, hi)
}

/// Whether the closed triangles intersect (decision only, the narrow phase's test).
///
/// The generic case (no vertex of either triangle on the other's plane) is Guigue and
/// Devillers' canonical-form test ("Fast and robust triangle-triangle overlap test using
/// orientation predicates", JGT 8(1), 2003): after the six vertex-plane orientations, each
/// triangle is rotated so that its lone vertex (alone on its side of the other's plane) comes
/// first and lies on the positive side (swapping the other triangle's last two vertices when
/// it does not), and two more orientations decide. With exact orientation signs that is exact.
/// Every other case (a vertex on the other plane, coplanar or degenerate triangles) goes to
/// the general test ([`tri_tri`]'s body, from the six signs already known), which is also the
/// oracle the fast path is tested against.
#[inline]
pub(crate) fn intersects<C: Coordinate>(a: &Tri<C>, b: &Tri<C>) -> bool {
    aabb_overlap(a, b) && intersects_given_boxes_overlap(a, b)
}

/// [`intersects`] for triangles whose closed boxes are known to overlap (the narrow phase's
/// candidates, whose boxes the leaf filter compared exactly): the same answer without
/// comparing them again.
#[inline]
pub(crate) fn intersects_given_boxes_overlap<C: Coordinate>(a: &Tri<C>, b: &Tri<C>) -> bool {
    debug_assert!(aabb_overlap(a, b));
    // Vertices of `a` against the plane of `b`: (x - b2) . ((b0 - b2) x (b1 - b2)).
    let pb = Plane::new(b);
    let sa = [pb.side(&a[0]), pb.side(&a[1]), pb.side(&a[2])];
    if sa[0] * sa[1] > 0 && sa[0] * sa[2] > 0 {
        return false;
    }
    let pa = Plane::new(a);
    let sb = if sa == [0; 3] && pb.spans() {
        // `a` lies in the plane `b` spans, so `b` lies in `a`'s (the same plane, or none when
        // `a` is degenerate): three exact zeros not recomputed (PERF: coplanar pairs).
        [0; 3]
    } else {
        [pa.side(&b[0]), pa.side(&b[1]), pa.side(&b[2])]
    };
    if sb[0] * sb[1] > 0 && sb[0] * sb[2] > 0 {
        return false;
    }
    if sa.contains(&0) || sb.contains(&0) {
        // A triangle that only touches the other's plane (PERF: corners of a mesh exactly on
        // a neighbour's plane, e.g. the rim of a flat cap, were most of these pairs on the
        // armadillo frames, and the general test pays six edge tests for them).
        if let Some(hit) = touching(a, sa, b).or_else(|| touching(b, sb, a)) {
            return hit;
        }
        // The general test from the signs already known (`Plane::side(x)` is the sign of
        // `orient3d(x, t0, t1, t2) = -orient3d(t0, t1, t2, x)`): recomputing them cost
        // coplanar pairs six more exact orientations.
        let (da, db) = (sa.map(|s| -f64::from(s)), sb.map(|s| -f64::from(s)));
        return tri_tri_full(a, &da, b, &db, &mut Decide);
    }
    // Rotate `a` so that its lone vertex comes first; if it is on the negative side, swap
    // `b`'s last two vertices (which flips the sign of `b`'s plane).
    let i = lone(sa);
    let (p1, q1, r1) = (&a[i], &a[(i + 1) % 3], &a[(i + 2) % 3]);
    let (mut b1, mut b2, mut sb1, mut sb2) = (&b[1], &b[2], sb[1], sb[2]);
    let (mut q1, mut r1) = (q1, r1);
    if sa[i] < 0 {
        (b1, b2, sb1, sb2) = (b2, b1, sb2, sb1);
    }
    // The same for `b` against `a`'s plane (now possibly with `a`'s last two swapped).
    let tb = [&b[0], b1, b2];
    let sbv = [sb[0], sb1, sb2];
    let j = lone(sbv);
    let (p2, q2, r2) = (tb[j], tb[(j + 1) % 3], tb[(j + 2) % 3]);
    if sbv[j] < 0 {
        (q1, r1) = (r1, q1);
    }
    // Canonical form: p1 above b's plane, p2 above a's plane. They intersect iff the two
    // triangles' intervals on the planes' common line overlap:
    // (q2 - q1) . ((p2 - q1) x (p1 - q1)) <= 0 and (r2 - p1) . ((p2 - p1) x (r1 - p1)) <= 0.
    sign(orient3d(q2, p2, p1, q1)) <= 0 && sign(orient3d(r2, p2, r1, p1)) <= 0
}

/// Whether `s` meets `t`, when `s` only touches `t`'s plane: some corner of `s` on it (`ds`,
/// the corners' exact sides of that plane) and the others strictly on one side. `None`
/// otherwise (`s` crosses the plane, lies in it, or misses it).
///
/// The side of the plane is an affine function, nonnegative (say) on the corners of `s` and
/// zero exactly on those in the plane, so `s` meets the plane exactly in the convex hull of
/// those corners (a point or a segment; `s` may be degenerate), and `s` meets `t` iff that
/// hull meets `t`: a 2D test in the plane. `t` is not degenerate, since some corner of `s` is
/// strictly off its plane.
#[inline]
fn touching<C: Coordinate>(s: &Tri<C>, ds: [i32; 3], t: &Tri<C>) -> Option<bool> {
    let zeros = ds.iter().filter(|&&d| d == 0).count();
    let side = ds.iter().sum::<i32>();
    // One or two zeros and the other signs equal: |sum| = number of nonzero signs.
    if zeros == 0 || zeros == 3 || side.unsigned_abs() as usize != 3 - zeros {
        return None;
    }
    let k = projection_axis(&t[0], &t[1], &t[2])?;
    let on: [usize; 2] = match ds {
        [0, 0, _] => [0, 1],
        [0, _, 0] => [0, 2],
        [_, 0, 0] => [1, 2],
        [0, _, _] => [0, 0],
        [_, 0, _] => [1, 1],
        _ => [2, 2],
    };
    Some(if on[0] == on[1] {
        point_in_tri_2d(k, &s[on[0]], t)
    } else {
        coplanar_seg_tri(&s[on[0]], &s[on[1]], t, k, &mut Decide)
    })
}

/// The index of the one sign that differs from the other two (all nonzero, not all equal).
#[inline(always)]
fn lone(s: [i32; 3]) -> usize {
    if s[1] == s[2] {
        0
    } else if s[0] == s[2] {
        1
    } else {
        2
    }
}

/// The core test. Returns whether the closed triangles intersect; with a collecting sink,
/// also pushes candidate points of the intersection (at least one iff `true`).
#[inline]
pub(crate) fn tri_tri<C: Coordinate, S: Sink>(a: &Tri<C>, b: &Tri<C>, sink: &mut S) -> bool {
    if !aabb_overlap(a, b) {
        return false;
    }
    // Corners of `b` against the plane of `a` (all zero if `a` is degenerate).
    let db = [
        orient3d(&a[0], &a[1], &a[2], &b[0]),
        orient3d(&a[0], &a[1], &a[2], &b[1]),
        orient3d(&a[0], &a[1], &a[2], &b[2]),
    ];
    if one_side(&db) {
        return false;
    }
    let da = [
        orient3d(&b[0], &b[1], &b[2], &a[0]),
        orient3d(&b[0], &b[1], &b[2], &a[1]),
        orient3d(&b[0], &b[1], &b[2], &a[2]),
    ];
    if one_side(&da) {
        return false;
    }
    tri_tri_full(a, &da, b, &db, sink)
}

/// Everything after the cheap filters (kept out of line so the filters inline well).
#[inline(never)]
fn tri_tri_full<C: Coordinate, S: Sink>(
    a: &Tri<C>,
    da: &[f64; 3],
    b: &Tri<C>,
    db: &[f64; 3],
    sink: &mut S,
) -> bool {
    // A nonzero orient3d against a's plane proves a non-degenerate.
    let a_axis = if db.iter().all(|&d| d == 0.0) {
        projection_axis(&a[0], &a[1], &a[2])
    } else {
        Some(AXIS_UNKNOWN)
    };
    let b_axis = if da.iter().all(|&d| d == 0.0) {
        projection_axis(&b[0], &b[1], &b[2])
    } else {
        Some(AXIS_UNKNOWN)
    };
    match (a_axis, b_axis) {
        (Some(ka), Some(kb)) => {
            let hit = edges_vs_tri(a, da, b, kb, sink);
            if hit && !S::COLLECT {
                return true;
            }
            edges_vs_tri(b, db, a, ka, sink) || hit
        }
        (None, Some(kb)) => {
            let (i, j) = extreme_corners(a);
            seg_vs_tri(&a[i], &a[j], da[i], da[j], b, kb, sink)
        }
        (Some(ka), None) => {
            let (i, j) = extreme_corners(b);
            seg_vs_tri(&b[i], &b[j], db[i], db[j], a, ka, sink)
        }
        (None, None) => {
            let (i, j) = extreme_corners(a);
            let (k, l) = extreme_corners(b);
            seg_seg_3d(&a[i], &a[j], &b[k], &b[l], sink)
        }
    }
}

/// Edges of `s` against the non-degenerate triangle `t`; `ds[i]` is the orientation of
/// `s[i]` against the plane of `t`; `axis` is a projection keeping `t` non-degenerate, or
/// [`AXIS_UNKNOWN`] (computed on first need).
#[inline]
fn edges_vs_tri<C: Coordinate, S: Sink>(
    s: &Tri<C>,
    ds: &[f64; 3],
    t: &Tri<C>,
    axis: usize,
    sink: &mut S,
) -> bool {
    let mut hit = false;
    for (i, j) in [(0, 1), (1, 2), (2, 0)] {
        if seg_vs_tri(&s[i], &s[j], ds[i], ds[j], t, axis, sink) {
            if !S::COLLECT {
                return true;
            }
            hit = true;
        }
    }
    hit
}

/// Closed segment `pq` against the non-degenerate closed triangle `t`; `sp`, `sq` are the
/// orientations of `p`, `q` against the plane of `t`.
#[inline]
fn seg_vs_tri<C: Coordinate, S: Sink>(
    p: &P3<C>,
    q: &P3<C>,
    sp: f64,
    sq: f64,
    t: &Tri<C>,
    axis: usize,
    sink: &mut S,
) -> bool {
    if (sp > 0.0 && sq > 0.0) || (sp < 0.0 && sq < 0.0) {
        return false;
    }
    if sp == 0.0 && sq == 0.0 {
        let k = if axis == AXIS_UNKNOWN {
            match projection_axis(&t[0], &t[1], &t[2]) {
                Some(k) => k,
                // Only reachable with non-finite input (finite: a nonzero orientation
                // against t's plane proved t non-degenerate); the answer is unspecified.
                None => return false,
            }
        } else {
            axis
        };
        return coplanar_seg_tri(p, q, t, k, sink);
    }
    // The segment meets the plane in exactly one point X; X is in the closed triangle iff
    // the signs of [p,q,t0,t1], [p,q,t1,t2], [p,q,t2,t0] are not strictly mixed.
    let s0 = sign(orient3d(p, q, &t[0], &t[1]));
    let s1 = sign(orient3d(p, q, &t[1], &t[2]));
    if s0 * s1 < 0 {
        return false;
    }
    let s2 = sign(orient3d(p, q, &t[2], &t[0]));
    if s0 * s2 < 0 || s1 * s2 < 0 {
        return false;
    }
    if S::COLLECT {
        let x = if sp == 0.0 {
            to64(p)
        } else if sq == 0.0 {
            to64(q)
        } else {
            lerp(p, q, sp / (sp - sq))
        };
        sink.push(x);
    }
    true
}

/// Point `x` in the closed triangle `t`, all in the plane, projected along `k` where `t`
/// is non-degenerate.
#[inline]
fn point_in_tri_2d<C: Coordinate>(k: usize, x: &P3<C>, t: &Tri<C>) -> bool {
    let e0 = sign(orient2d(k, &t[0], &t[1], x));
    let e1 = sign(orient2d(k, &t[1], &t[2], x));
    let e2 = sign(orient2d(k, &t[2], &t[0], x));
    !((e0 < 0 || e1 < 0 || e2 < 0) && (e0 > 0 || e1 > 0 || e2 > 0))
}

/// Segment `pq` lying in the plane of the non-degenerate triangle `t` (projection `k`).
fn coplanar_seg_tri<C: Coordinate, S: Sink>(
    p: &P3<C>,
    q: &P3<C>,
    t: &Tri<C>,
    k: usize,
    sink: &mut S,
) -> bool {
    let mut hit = false;
    for x in [p, q] {
        if point_in_tri_2d(k, x, t) {
            if !S::COLLECT {
                return true;
            }
            sink.push(to64(x));
            hit = true;
        }
    }
    // Neither endpoint inside: the segment meets the triangle iff it meets its boundary.
    for (i, j) in [(0, 1), (1, 2), (2, 0)] {
        if seg_seg_2d(k, p, q, &t[i], &t[j], sink) {
            if !S::COLLECT {
                return true;
            }
            hit = true;
        }
    }
    hit
}

/// Closed segments `pq` and `rs` (either may be a point) whose affine hull the projection
/// along `k` maps injectively.
fn seg_seg_2d<C: Coordinate, S: Sink>(
    k: usize,
    p: &P3<C>,
    q: &P3<C>,
    r: &P3<C>,
    s: &P3<C>,
    sink: &mut S,
) -> bool {
    let o1 = sign(orient2d(k, p, q, r));
    let o2 = sign(orient2d(k, p, q, s));
    if o1 * o2 > 0 {
        return false;
    }
    let o3 = orient2d(k, r, s, p);
    let o4 = orient2d(k, r, s, q);
    if sign(o3) * sign(o4) > 0 {
        return false;
    }
    if o1 == 0 && o2 == 0 && o3 == 0.0 && o4 == 0.0 {
        // All four collinear (or points): the projection is injective on their line.
        let (i, j) = keep(k);
        return collinear_overlap(p, q, r, s, |v| [v[i], v[j]], sink);
    }
    if S::COLLECT {
        // Not all collinear, so p, q are not both on line rs: o3 != o4.
        let x = if o3 == 0.0 {
            to64(p)
        } else if o4 == 0.0 {
            to64(q)
        } else if o3 != o4 {
            lerp(p, q, o3 / (o3 - o4))
        } else {
            to64(p)
        };
        sink.push(x);
    }
    true
}

/// Collinear closed segments `pq`, `rs`: overlap decided by lexicographic comparison of
/// `key` (any coordinates injective on their common line).
#[inline]
fn collinear_overlap<C: Coordinate, S: Sink, K: AsRef<[C]>>(
    p: &P3<C>,
    q: &P3<C>,
    r: &P3<C>,
    s: &P3<C>,
    key: impl Fn(&P3<C>) -> K,
    sink: &mut S,
) -> bool {
    let (kp, kq, kr, ks) = (key(p), key(q), key(r), key(s));
    let (lo1, hi1) = if lex_le(kp.as_ref(), kq.as_ref()) {
        (&kp, &kq)
    } else {
        (&kq, &kp)
    };
    let (lo2, hi2) = if lex_le(kr.as_ref(), ks.as_ref()) {
        (&kr, &ks)
    } else {
        (&ks, &kr)
    };
    let hit = lex_le(lo1.as_ref(), hi2.as_ref()) && lex_le(lo2.as_ref(), hi1.as_ref());
    if S::COLLECT && hit {
        let within = |x: &K, lo: &K, hi: &K| {
            lex_le(lo.as_ref(), x.as_ref()) && lex_le(x.as_ref(), hi.as_ref())
        };
        for (x, kx) in [(p, &kp), (q, &kq)] {
            if within(kx, lo2, hi2) {
                sink.push(to64(x));
            }
        }
        for (x, kx) in [(r, &kr), (s, &ks)] {
            if within(kx, lo1, hi1) {
                sink.push(to64(x));
            }
        }
    }
    hit
}

/// Closed segments (or points) `pq`, `rs` in 3D.
fn seg_seg_3d<C: Coordinate, S: Sink>(
    p: &P3<C>,
    q: &P3<C>,
    r: &P3<C>,
    s: &P3<C>,
    sink: &mut S,
) -> bool {
    if orient3d(p, q, r, s) != 0.0 {
        return false;
    }
    // Coplanar. If the four points span a plane, some triple spans it and the projection
    // along its dominant normal axis is injective on it.
    let mut best = None;
    let mut best_abs = 0.0;
    for k in 0..3 {
        for o in [
            orient2d(k, p, q, r),
            orient2d(k, p, q, s),
            orient2d(k, r, s, p),
            orient2d(k, r, s, q),
        ] {
            if o.abs() > best_abs {
                best_abs = o.abs();
                best = Some(k);
            }
        }
    }
    match best {
        Some(k) => seg_seg_2d(k, p, q, r, s, sink),
        // Every projected triple collinear: all four points on one line (3D lex order).
        None => collinear_overlap(p, q, r, s, |x| *x, sink),
    }
}
