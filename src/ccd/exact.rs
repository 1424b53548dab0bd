//! The exact path: the contact predicate as a formula over polynomials in `t` with integer
//! coefficients, its earliest solution in `[0, t_max]` found with Sturm sequences and
//! Sturm-Tarski sign queries in rational arithmetic. Slow (big numbers, allocation), and
//! only reached for what the float filter cannot decide.
//!
//! Every f64 is `m * 2^e` with an integer `m`; scaling all coordinates of a query (and the
//! minimum distance) by `2^-e_min` makes them integers exactly, and scaling moves neither
//! contacts nor their times. A point moving from `x0` to `x1` is then the polynomial
//! `X0 + t (X1 - X0)` with integer coefficients.

use num_bigint::{BigInt, Sign};
use num_integer::Integer;
use num_rational::BigRational;
use num_traits::{One, Signed, ToPrimitive, Zero};

use super::ring::{self, Ring, V3};

type Q = BigRational;

// ---------------------------------------------------------------------------------------
// Integer polynomials in t (the ring of the formulas)
// ---------------------------------------------------------------------------------------

/// A polynomial in `t` with integer coefficients, lowest degree first, no trailing zeros
/// (the zero polynomial is empty).
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct Poly(pub Vec<BigInt>);

impl Poly {
    fn trim(mut v: Vec<BigInt>) -> Poly {
        while v.last().is_some_and(|c| c.is_zero()) {
            v.pop();
        }
        Poly(v)
    }
    pub fn is_zero(&self) -> bool {
        self.0.is_empty()
    }
    pub fn constant(c: BigInt) -> Poly {
        Poly::trim(vec![c])
    }
}

impl Ring for Poly {
    fn add(&self, b: &Self) -> Self {
        let n = self.0.len().max(b.0.len());
        let z = BigInt::zero();
        Poly::trim(
            (0..n)
                .map(|i| self.0.get(i).unwrap_or(&z) + b.0.get(i).unwrap_or(&z))
                .collect(),
        )
    }
    fn sub(&self, b: &Self) -> Self {
        let n = self.0.len().max(b.0.len());
        let z = BigInt::zero();
        Poly::trim(
            (0..n)
                .map(|i| self.0.get(i).unwrap_or(&z) - b.0.get(i).unwrap_or(&z))
                .collect(),
        )
    }
    fn mul(&self, b: &Self) -> Self {
        if self.is_zero() || b.is_zero() {
            return Poly(Vec::new());
        }
        let mut out = vec![BigInt::zero(); self.0.len() + b.0.len() - 1];
        for (i, x) in self.0.iter().enumerate() {
            for (j, y) in b.0.iter().enumerate() {
                out[i + j] += x * y;
            }
        }
        Poly::trim(out)
    }
}

// ---------------------------------------------------------------------------------------
// Rational polynomials (Sturm sequences)
// ---------------------------------------------------------------------------------------

/// Rational coefficients, lowest degree first, no trailing zeros.
type QPoly = Vec<Q>;

fn qtrim(mut v: QPoly) -> QPoly {
    while v.last().is_some_and(|c| c.is_zero()) {
        v.pop();
    }
    v
}

fn to_q(p: &Poly) -> QPoly {
    p.0.iter().map(|c| Q::from_integer(c.clone())).collect()
}

fn qeval(p: &QPoly, x: &Q) -> Q {
    let mut acc = Q::zero();
    for c in p.iter().rev() {
        acc = acc * x + c;
    }
    acc
}

fn qsign(p: &QPoly, x: &Q) -> i8 {
    sign_of(&qeval(p, x))
}

fn sign_of(q: &Q) -> i8 {
    if q.is_positive() {
        1
    } else if q.is_negative() {
        -1
    } else {
        0
    }
}

fn qderiv(p: &QPoly) -> QPoly {
    qtrim(
        p.iter()
            .enumerate()
            .skip(1)
            .map(|(i, c)| c * Q::from_integer(BigInt::from(i)))
            .collect(),
    )
}

fn qmul(a: &QPoly, b: &QPoly) -> QPoly {
    if a.is_empty() || b.is_empty() {
        return Vec::new();
    }
    let mut out = vec![Q::zero(); a.len() + b.len() - 1];
    for (i, x) in a.iter().enumerate() {
        for (j, y) in b.iter().enumerate() {
            out[i + j] += x * y;
        }
    }
    qtrim(out)
}

/// Quotient and remainder of `a / b`, `b` nonzero.
fn qdivrem(a: &QPoly, b: &QPoly) -> (QPoly, QPoly) {
    assert!(!b.is_empty(), "division by the zero polynomial");
    let mut r = a.clone();
    let db = b.len() - 1;
    let lead = b[db].clone();
    if r.len() < b.len() {
        return (Vec::new(), r);
    }
    let mut quo = vec![Q::zero(); r.len() - db];
    while r.len() >= b.len() {
        let k = r.len() - 1 - db;
        let c = &r[r.len() - 1] / &lead;
        for (i, bi) in b.iter().enumerate() {
            r[k + i] -= &c * bi;
        }
        quo[k] = c;
        r.pop(); // the leading term cancelled exactly
        r = qtrim(r);
    }
    (qtrim(quo), r)
}

/// Monic gcd.
fn qgcd(a: &QPoly, b: &QPoly) -> QPoly {
    let (mut x, mut y) = (a.clone(), b.clone());
    while !y.is_empty() {
        let (_, r) = qdivrem(&x, &y);
        x = y;
        y = r;
    }
    monic(x)
}

fn monic(p: QPoly) -> QPoly {
    match p.last() {
        None => p,
        Some(l) => {
            let l = l.clone();
            p.into_iter().map(|c| c / &l).collect()
        }
    }
}

/// The signed remainder sequence `p, q, -rem(p, q), ...` (up to the last nonzero term).
fn srs(p: &QPoly, q: &QPoly) -> Vec<QPoly> {
    let mut seq = vec![p.clone()];
    if q.is_empty() {
        return seq;
    }
    seq.push(q.clone());
    loop {
        let n = seq.len();
        let (_, r) = qdivrem(&seq[n - 2], &seq[n - 1]);
        if r.is_empty() {
            return seq;
        }
        // Keep the numbers small: a positive scale changes no sign.
        let r: QPoly = r.into_iter().map(|c| -c).collect();
        let l = r.last().unwrap().abs();
        seq.push(r.into_iter().map(|c| c / &l).collect());
    }
}

/// Sign variations of `seq` at `x` (zeros skipped).
fn variations(seq: &[QPoly], x: &Q) -> i32 {
    let mut last = 0i8;
    let mut v = 0;
    for p in seq {
        let s = qsign(p, x);
        if s != 0 {
            if last != 0 && s != last {
                v += 1;
            }
            last = s;
        }
    }
    v
}

// ---------------------------------------------------------------------------------------
// Roots in [0, T]
// ---------------------------------------------------------------------------------------

/// A real root of a polynomial in `[0, T]`.
#[derive(Clone, Debug)]
pub(crate) enum Root {
    /// Exactly this rational (only `0` and `T` are reported this way).
    Exact(Q),
    /// The only root of the square-free `p` in the open interval `(lo, hi)`, where `p` does
    /// not vanish at `lo` nor `hi`.
    Isolated {
        p: std::rc::Rc<QPoly>,
        lo: Q,
        hi: Q,
    },
}

/// The distinct real roots of the nonzero `poly` in `[0, t_max]`, in increasing order.
pub(crate) fn roots(poly: &Poly, t_max: &Q) -> Vec<Root> {
    let mut out = Vec::new();
    if poly.0.len() <= 1 {
        return out; // a nonzero constant (or zero, which the caller never passes)
    }
    let q = to_q(poly);
    // Square-free part, monic.
    let g = qgcd(&q, &qderiv(&q));
    let mut p = monic(qdivrem(&q, &g).0);
    let zero = Q::zero();
    let at_zero = qsign(&p, &zero) == 0;
    if at_zero {
        out.push(Root::Exact(zero.clone()));
        // p = t * p' with p'(0) != 0 (p is square-free).
        p = qdivrem(&p, &vec![Q::zero(), Q::one()]).0;
    }
    if t_max.is_zero() {
        return out;
    }
    let at_end = qsign(&p, t_max) == 0;
    if at_end {
        p = qdivrem(&p, &vec![-t_max.clone(), Q::one()]).0;
    }
    if p.len() > 1 {
        let sturm = srs(&p, &qderiv(&p));
        let p = std::rc::Rc::new(p);
        isolate(&p, &sturm, zero, t_max.clone(), &mut out);
    }
    if at_end {
        out.push(Root::Exact(t_max.clone()));
    }
    out
}

/// Appends the roots of `p` in `(lo, hi)` (neither a root), in increasing order.
fn isolate(p: &std::rc::Rc<QPoly>, sturm: &[QPoly], lo: Q, hi: Q, out: &mut Vec<Root>) {
    let count = variations(sturm, &lo) - variations(sturm, &hi);
    debug_assert!(count >= 0);
    if count == 0 {
        return;
    }
    if count == 1 {
        out.push(Root::Isolated {
            p: p.clone(),
            lo,
            hi,
        });
        return;
    }
    // Split at a point that is not a root: of 1/2, 3/8, 5/8, 1/4, 3/4, ... of the way
    // (more candidates than p has roots), the first that is not one.
    let w = &hi - &lo;
    let mut split = None;
    for k in [4, 3, 5, 2, 6, 1, 7, 9, 11, 13, 15] {
        let m = &lo + &w * Q::new(BigInt::from(k), BigInt::from(if k < 8 { 8 } else { 16 }));
        if qsign(p, &m) != 0 {
            split = Some(m);
            break;
        }
    }
    let m = split.expect("a polynomial of degree < 11 has a non-root among 11 points");
    isolate(p, sturm, lo, m.clone(), out);
    isolate(p, sturm, m, hi, out);
}

/// The sign of `s` at the root.
fn sign_at(s: &Poly, root: &Root) -> i8 {
    match root {
        Root::Exact(x) => qsign(&to_q(s), x),
        Root::Isolated { p, lo, hi } => {
            if s.is_zero() {
                return 0;
            }
            // Sturm-Tarski: Var(SRS(p, p' s); lo, hi) = sum over the roots r of p in
            // (lo, hi] of sign(s(r)); there is exactly one, and s may be reduced mod p.
            let s = qdivrem(&to_q(s), p).1;
            if s.is_empty() {
                return 0;
            }
            let seq = srs(p, &qmul(&qderiv(p), &s));
            let taq = variations(&seq, lo) - variations(&seq, hi);
            debug_assert!((-1..=1).contains(&taq));
            taq.signum() as i8
        }
    }
}

/// A lower bound of the root, at most `tol` below it (an exact root is itself).
fn lower_bound(root: &Root, tol: &Q) -> Q {
    match root {
        Root::Exact(x) => x.clone(),
        Root::Isolated { p, lo, hi } => {
            let (mut lo, mut hi) = (lo.clone(), hi.clone());
            let s_lo = qsign(p, &lo);
            let two = Q::from_integer(BigInt::from(2));
            while &hi - &lo > *tol {
                let m = (&lo + &hi) / &two;
                let s = qsign(p, &m);
                if s == 0 {
                    return m;
                }
                if s == s_lo {
                    lo = m;
                } else {
                    hi = m;
                }
            }
            lo
        }
    }
}

// ---------------------------------------------------------------------------------------
// Formulas and their earliest solution
// ---------------------------------------------------------------------------------------

/// A sign condition on one polynomial of a formula.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Cond {
    Zero,
    Pos,
    Neg,
    NonPos,
    NonNeg,
}

impl Cond {
    fn holds(self, s: i8) -> bool {
        match self {
            Cond::Zero => s == 0,
            Cond::Pos => s > 0,
            Cond::Neg => s < 0,
            Cond::NonPos => s <= 0,
            Cond::NonNeg => s >= 0,
        }
    }
}

/// A disjunction of conjunctions of sign conditions on polynomials in `t`. The set of `t`
/// where it holds must be closed (it is: a contact set).
pub(crate) struct Formula {
    pub polys: Vec<Poly>,
    pub clauses: Vec<Vec<(usize, Cond)>>,
}

/// The time-of-impact tolerance: the earliest solution is returned as a lower bound at most
/// this much below it (before rounding to f64).
pub(crate) fn tolerance() -> Q {
    Q::new(BigInt::one(), BigInt::one() << super::TOI_TOL_LOG2)
}

/// The earliest `t` in `[0, t_max]` where the formula holds, as a lower bound at most
/// `tolerance()` below it; None if it holds nowhere there.
///
/// Why the candidates suffice: let S be the (closed) solution set and S_c that of clause
/// c, so S = union of the S_c and min S = min over c of inf S_c, each inf S_c lying in
/// the closure of S_c, inside S. If clause c contains `q = 0` with q not identically zero,
/// S_c lies in the finite zero set of q, so inf S_c is a root of q. Otherwise inf S_c is 0
/// or a boundary point of S_c, and away from the roots of the clause's (nonzero)
/// polynomials every sign, hence the clause, is locally constant, so it is a root of one
/// of them. Checking the whole formula at every candidate of every clause and keeping the
/// least that holds therefore yields min S.
pub(crate) fn earliest(formula: &Formula, t_max: &Q) -> Option<Q> {
    let n = formula.polys.len();
    // Which candidate groups: Some(j) = the roots of polynomial j; None = the point 0.
    let mut groups: Vec<Option<usize>> = Vec::new();
    let mut push = |g: Option<usize>| {
        if !groups.contains(&g) {
            groups.push(g);
        }
    };
    for clause in &formula.clauses {
        let eq = clause
            .iter()
            .find(|(j, c)| *c == Cond::Zero && !formula.polys[*j].is_zero());
        match eq {
            Some(&(j, _)) => push(Some(j)),
            None => {
                push(None);
                for &(j, _) in clause {
                    if !formula.polys[j].is_zero() {
                        push(Some(j));
                    }
                }
            }
        }
    }
    let tol = tolerance();
    let mut best: Option<Q> = None;
    let holds_at = |root: &Root| -> bool {
        let mut signs: Vec<Option<i8>> = vec![None; n];
        formula.clauses.iter().any(|clause| {
            clause.iter().all(|&(j, c)| {
                let s = *signs[j].get_or_insert_with(|| sign_at(&formula.polys[j], root));
                c.holds(s)
            })
        })
    };
    for g in groups {
        let cands = match g {
            None => vec![Root::Exact(Q::zero())],
            Some(j) => roots(&formula.polys[j], t_max),
        };
        for root in cands {
            // Candidates of one group come in increasing order: past the best, stop.
            if let Some(b) = &best {
                let lo = match &root {
                    Root::Exact(x) => x,
                    Root::Isolated { lo, .. } => lo,
                };
                if lo >= b {
                    break;
                }
            }
            if holds_at(&root) {
                let lb = lower_bound(&root, &tol);
                if best.as_ref().is_none_or(|b| lb < *b) {
                    best = Some(lb);
                }
                break;
            }
        }
    }
    best
}

/// The largest f64 not above `q` (`q` in [0, 1]).
pub(crate) fn round_down(q: &Q) -> f64 {
    debug_assert!(!q.is_negative());
    if q.is_zero() {
        return 0.0;
    }
    // floor(q * 2^80) / 2^80 is within 2^-80 below q; then step to the exact answer.
    let k = 80u32;
    let scaled: BigInt = (q.numer() << k).div_floor(q.denom());
    let mut x = scaled.to_f64().unwrap_or(0.0) * 2f64.powi(-(k as i32));
    let exact = |x: f64| Q::from_float(x).expect("finite");
    while x > 0.0 && exact(x) > *q {
        x = x.next_down();
    }
    while exact(x.next_up()) <= *q {
        x = x.next_up();
    }
    x
}

// ---------------------------------------------------------------------------------------
// The queries' formulas
// ---------------------------------------------------------------------------------------

/// `x = sign * mantissa * 2^exp` of a finite f64.
fn decompose(x: f64) -> (BigInt, i32) {
    let bits = x.to_bits();
    let sign = if bits >> 63 == 1 { Sign::Minus } else { Sign::Plus };
    let exp_bits = ((bits >> 52) & 0x7ff) as i32;
    let frac = bits & ((1u64 << 52) - 1);
    let (mant, exp) = if exp_bits == 0 {
        (frac, -1074)
    } else {
        (frac | (1u64 << 52), exp_bits - 1075)
    };
    if mant == 0 {
        return (BigInt::zero(), 0);
    }
    let tz = mant.trailing_zeros();
    (
        BigInt::from_biguint(sign, (mant >> tz).into()),
        exp + tz as i32,
    )
}

/// The query's eight points (and `extra` values, e.g. the minimum distance) as integers
/// after one common exact scaling by a power of two.
fn to_integers(x0: &[[f64; 3]; 4], x1: &[[f64; 3]; 4], extra: &[f64]) -> (Vec<BigInt>, Vec<BigInt>) {
    let vals: Vec<f64> = x0
        .iter()
        .chain(x1.iter())
        .flat_map(|p| p.iter().copied())
        .chain(extra.iter().copied())
        .collect();
    let parts: Vec<(BigInt, i32)> = vals.iter().map(|&v| decompose(v)).collect();
    let emin = parts
        .iter()
        .filter(|(m, _)| !m.is_zero())
        .map(|&(_, e)| e)
        .min()
        .unwrap_or(0);
    let ints: Vec<BigInt> = parts
        .into_iter()
        .map(|(m, e)| if m.is_zero() { m } else { m << (e - emin) as usize })
        .collect();
    let (pts, rest) = ints.split_at(24);
    (pts.to_vec(), rest.to_vec())
}

/// The four moving points as vectors of linear polynomials `X0 + t (X1 - X0)`.
fn moving_points(ints: &[BigInt]) -> [V3<Poly>; 4] {
    let pt = |i: usize| -> V3<Poly> {
        std::array::from_fn(|k| {
            let a = &ints[i * 3 + k];
            let b = &ints[12 + i * 3 + k];
            Poly::trim(vec![a.clone(), b - a])
        })
    };
    [pt(0), pt(1), pt(2), pt(3)]
}

/// Adds `q` to the formula's polynomials, returns its index.
fn add(polys: &mut Vec<Poly>, q: Poly) -> usize {
    polys.push(q);
    polys.len() - 1
}

/// Clause "point p on the closed segment [a, b]", with `A = a - p`, `B = b - p`:
/// `A x B = 0` and `A . B <= 0`.
fn on_segment(polys: &mut Vec<Poly>, cross: &V3<Poly>, dot: Poly) -> Vec<(usize, Cond)> {
    let mut c: Vec<(usize, Cond)> = cross
        .iter()
        .map(|x| (add(polys, x.clone()), Cond::Zero))
        .collect();
    c.push((add(polys, dot), Cond::NonPos));
    c
}

/// Vertex-face contact with `min_distance = 0`: `f = 0` and either all three barycentric
/// numerators positive, or the vertex on one of the three closed edges.
pub(crate) fn vertex_face_formula(pts: &[V3<Poly>; 4]) -> Formula {
    let [p, a, b, c] = pts;
    let face = ring::vf_face(p, a, b, c);
    let (aa, bb, cc) = (ring::sub3(a, p), ring::sub3(b, p), ring::sub3(c, p));
    let mut polys = vec![face.f.clone()];
    let mut clauses = Vec::new();
    let mut cl = vec![(0, Cond::Zero)];
    for d in face.d.iter() {
        cl.push((add(&mut polys, d.clone()), Cond::Pos));
    }
    clauses.push(cl);
    let dots = [ring::dot(&aa, &bb), ring::dot(&bb, &cc), ring::dot(&cc, &aa)];
    for (cr, dt) in face.cross.iter().zip(dots) {
        let mut cl = vec![(0, Cond::Zero)];
        cl.extend(on_segment(&mut polys, cr, dt));
        clauses.push(cl);
    }
    Formula { polys, clauses }
}

/// Edge-edge contact with `min_distance = 0`: `f = 0` and either a proper crossing
/// (`cc < 0` and `ee < 0`) or an endpoint of one edge on the other edge.
pub(crate) fn edge_edge_formula(pts: &[V3<Poly>; 4]) -> Formula {
    let [a0, a1, b0, b1] = pts;
    let x = ring::ee_cross(a0, a1, b0, b1);
    let mut polys = vec![x.f, x.cc, x.ee];
    let mut clauses = vec![vec![(0, Cond::Zero), (1, Cond::Neg), (2, Cond::Neg)]];
    for (p, s0, s1) in [(a0, b0, b1), (a1, b0, b1), (b0, a0, a1), (b1, a0, a1)] {
        let (aa, bb) = (ring::sub3(s0, p), ring::sub3(s1, p));
        let mut cl = vec![(0, Cond::Zero)];
        cl.extend(on_segment(&mut polys, &ring::cross(&aa, &bb), ring::dot(&aa, &bb)));
        clauses.push(cl);
    }
    Formula { polys, clauses }
}

fn norm2(v: &V3<Poly>) -> Poly {
    ring::dot(v, v)
}

/// Clauses "point p within sqrt(dd) of the closed segment [a, b]" (`A = a - p`,
/// `B = b - p`): an endpoint within the distance, or the foot of the perpendicular inside
/// the (non-degenerate) segment and the distance to the line within it.
fn near_segment(polys: &mut Vec<Poly>, aa: &V3<Poly>, bb: &V3<Poly>, dd: &Poly) -> Vec<Vec<(usize, Cond)>> {
    let e = ring::sub3(bb, aa);
    let le = norm2(&e);
    let cr = ring::cross(aa, bb);
    let dist = norm2(&cr).sub(&dd.mul(&le));
    let s0 = ring::dot(aa, &ring::sub3(aa, bb)); // |e|^2 * (foot parameter)
    let s1 = ring::dot(bb, &e); // |e|^2 * (1 - foot parameter)
    let i_le = add(polys, le);
    let i_dist = add(polys, dist);
    let i_s0 = add(polys, s0);
    let i_s1 = add(polys, s1);
    vec![
        vec![(add(polys, norm2(aa).sub(dd)), Cond::NonPos)],
        vec![(add(polys, norm2(bb).sub(dd)), Cond::NonPos)],
        vec![
            (i_le, Cond::Pos),
            (i_dist, Cond::NonPos),
            (i_s0, Cond::NonNeg),
            (i_s1, Cond::NonNeg),
        ],
    ]
}

/// Vertex-face within `sqrt(dd)`: near the face's plane with the foot inside the
/// (non-degenerate) triangle, or near one of its closed edges.
pub(crate) fn vertex_face_near_formula(pts: &[V3<Poly>; 4], dd: &Poly) -> Formula {
    let [p, a, b, c] = pts;
    let face = ring::vf_face(p, a, b, c);
    let (aa, bb, cc) = (ring::sub3(a, p), ring::sub3(b, p), ring::sub3(c, p));
    let mut polys = Vec::new();
    let nn = norm2(&face.n);
    let plane = face.f.mul(&face.f).sub(&dd.mul(&nn));
    let mut cl = vec![(add(&mut polys, nn), Cond::Pos), (add(&mut polys, plane), Cond::NonPos)];
    for d in face.d.iter() {
        cl.push((add(&mut polys, d.clone()), Cond::NonNeg));
    }
    let mut clauses = vec![cl];
    for (x, y) in [(&aa, &bb), (&bb, &cc), (&cc, &aa)] {
        clauses.extend(near_segment(&mut polys, x, y, dd));
    }
    Formula { polys, clauses }
}

/// Edge-edge within `sqrt(dd)`: an endpoint near the other closed segment, or the closest
/// points of the two (non-parallel) lines inside both segments and within the distance.
pub(crate) fn edge_edge_near_formula(pts: &[V3<Poly>; 4], dd: &Poly) -> Formula {
    let [a0, a1, b0, b1] = pts;
    let mut polys = Vec::new();
    let mut clauses = Vec::new();
    for (p, s0, s1) in [(a0, b0, b1), (a1, b0, b1), (b0, a0, a1), (b1, a0, a1)] {
        let (aa, bb) = (ring::sub3(s0, p), ring::sub3(s1, p));
        clauses.extend(near_segment(&mut polys, &aa, &bb, dd));
    }
    // Lines a0 + s u and b0 + r v, w = a0 - b0. With A = u.u, B = u.v, C = v.v, D = u.w,
    // E = v.w and den = AC - B^2 = |u x v|^2: s = (BE - CD)/den, r = (AE - BD)/den.
    let u = ring::sub3(a1, a0);
    let v = ring::sub3(b1, b0);
    let w = ring::sub3(a0, b0);
    let (ca, cb, cc) = (ring::dot(&u, &u), ring::dot(&u, &v), ring::dot(&v, &v));
    let (cd, ce) = (ring::dot(&u, &w), ring::dot(&v, &w));
    let den = ca.mul(&cc).sub(&cb.mul(&cb));
    let sn = cb.mul(&ce).sub(&cc.mul(&cd));
    let rn = ca.mul(&ce).sub(&cb.mul(&cd));
    let vol = ring::dot(&w, &ring::cross(&u, &v));
    let dist = vol.mul(&vol).sub(&dd.mul(&den));
    let i_den = add(&mut polys, den.clone());
    let i_dist = add(&mut polys, dist);
    let i_s0 = add(&mut polys, sn.clone());
    let i_s1 = add(&mut polys, den.sub(&sn));
    let i_r0 = add(&mut polys, rn.clone());
    let i_r1 = add(&mut polys, den.sub(&rn));
    clauses.push(vec![
        (i_den, Cond::Pos),
        (i_dist, Cond::NonPos),
        (i_s0, Cond::NonNeg),
        (i_s1, Cond::NonNeg),
        (i_r0, Cond::NonNeg),
        (i_r1, Cond::NonNeg),
    ]);
    Formula { polys, clauses }
}

/// Which query.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Kind {
    VertexFace,
    EdgeEdge,
}

/// The exact earliest contact time (rounded down to f64, at most the tolerance early).
pub(crate) fn solve(kind: Kind, x0: &[[f64; 3]; 4], x1: &[[f64; 3]; 4], t_max: f64, min_distance: f64) -> Option<f64> {
    let (ints, extra) = to_integers(x0, x1, &[min_distance]);
    let pts = moving_points(&ints);
    let formula = if min_distance == 0.0 {
        match kind {
            Kind::VertexFace => vertex_face_formula(&pts),
            Kind::EdgeEdge => edge_edge_formula(&pts),
        }
    } else {
        let d = Poly::constant(extra[0].clone());
        let dd = d.mul(&d);
        match kind {
            Kind::VertexFace => vertex_face_near_formula(&pts, &dd),
            Kind::EdgeEdge => edge_edge_near_formula(&pts, &dd),
        }
    };
    let t = Q::from_float(t_max).expect("t_max is finite");
    earliest(&formula, &t).map(|q| round_down(&q))
}
