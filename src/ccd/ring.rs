//! The predicate's polynomials, written once over a ring and evaluated in three rings: exact
//! polynomials in `t` (the exact path), interval enclosures over a time interval (the float
//! filter) and plain `f64` (approximations that decide nothing). Writing them once is what
//! makes the filter and the exact path decide the same predicate.

/// The operations the formulas need: a commutative ring.
pub(crate) trait Ring: Clone {
    fn add(&self, b: &Self) -> Self;
    fn sub(&self, b: &Self) -> Self;
    fn mul(&self, b: &Self) -> Self;
}

pub(crate) type V3<R> = [R; 3];

#[inline(always)]
pub(crate) fn sub3<R: Ring>(a: &V3<R>, b: &V3<R>) -> V3<R> {
    [a[0].sub(&b[0]), a[1].sub(&b[1]), a[2].sub(&b[2])]
}

#[inline(always)]
pub(crate) fn add3<R: Ring>(a: &V3<R>, b: &V3<R>) -> V3<R> {
    [a[0].add(&b[0]), a[1].add(&b[1]), a[2].add(&b[2])]
}

#[inline(always)]
pub(crate) fn cross<R: Ring>(a: &V3<R>, b: &V3<R>) -> V3<R> {
    [
        a[1].mul(&b[2]).sub(&a[2].mul(&b[1])),
        a[2].mul(&b[0]).sub(&a[0].mul(&b[2])),
        a[0].mul(&b[1]).sub(&a[1].mul(&b[0])),
    ]
}

#[inline(always)]
pub(crate) fn dot<R: Ring>(a: &V3<R>, b: &V3<R>) -> R {
    a[0].mul(&b[0]).add(&a[1].mul(&b[1])).add(&a[2].mul(&b[2]))
}

/// Vertex-face, with `A = a - p`, `B = b - p`, `C = c - p`:
/// `f = A . (B x C)` (zero iff the four points are coplanar) and the barycentric numerators
/// `d = [(B x C) . n, (C x A) . n, (A x B) . n]` with `n = (b - a) x (c - a)
/// = B x C + C x A + A x B`. Also returned: the edge cross products `[A x B, B x C, C x A]`.
pub(crate) struct VfFace<R> {
    pub f: R,
    pub d: [R; 3],
    pub cross: [V3<R>; 3],
    pub n: V3<R>,
}

#[inline]
pub(crate) fn vf_face<R: Ring>(p: &V3<R>, a: &V3<R>, b: &V3<R>, c: &V3<R>) -> VfFace<R> {
    let (aa, bb, cc) = (sub3(a, p), sub3(b, p), sub3(c, p));
    let ab = cross(&aa, &bb);
    let bc = cross(&bb, &cc);
    let ca = cross(&cc, &aa);
    let n = add3(&add3(&bc, &ca), &ab);
    let f = dot(&aa, &bc);
    let d = [dot(&bc, &n), dot(&ca, &n), dot(&ab, &n)];
    VfFace {
        f,
        d,
        cross: [ab, bc, ca],
        n,
    }
}

/// Edge-edge, with `u = a1 - a0`, `v = b1 - b0`: `f = u . ((b0 - a0) x (b1 - a0))` (zero iff
/// the four points are coplanar), `cc = (u x (b0 - a0)) . (u x (b1 - a0))` (negative iff b0
/// and b1 lie strictly on opposite sides of the line of a, given coplanarity) and
/// `ee = (v x (a0 - b0)) . (v x (a1 - b0))` (the same for a0, a1 and the line of b).
pub(crate) struct EeCross<R> {
    pub f: R,
    pub cc: R,
    pub ee: R,
}

#[inline]
pub(crate) fn ee_cross<R: Ring>(a0: &V3<R>, a1: &V3<R>, b0: &V3<R>, b1: &V3<R>) -> EeCross<R> {
    let u = sub3(a1, a0);
    let v = sub3(b1, b0);
    let w0 = sub3(b0, a0);
    let w1 = sub3(b1, a0);
    let c0 = cross(&u, &w0);
    let c1 = cross(&u, &w1);
    let f = dot(&u, &cross(&w0, &w1));
    let z0 = sub3(a0, b0);
    let z1 = sub3(a1, b0);
    let e0 = cross(&v, &z0);
    let e1 = cross(&v, &z1);
    EeCross {
        f,
        cc: dot(&c0, &c1),
        ee: dot(&e0, &e1),
    }
}

impl Ring for f64 {
    fn add(&self, b: &Self) -> Self {
        self + b
    }
    fn sub(&self, b: &Self) -> Self {
        self - b
    }
    fn mul(&self, b: &Self) -> Self {
        self * b
    }
}
