//! The exact path: the contact predicate as a formula over polynomials in `t` with integer
//! coefficients, its earliest solution in `[0, t_max]` found with Sturm sequences and
//! Sturm-Tarski sign queries in rational arithmetic. Slow (big numbers, allocation), and
//! only reached for what the float filter cannot decide.
//!
//! Every f64 is `m * 2^e` with an integer `m`; scaling all coordinates of a query (and the
//! minimum distance) by `2^-e_min` makes them integers exactly, and scaling moves neither
//! contacts nor their times. A point moving from `x0` to `x1` is then the polynomial
//! `X0 + t (X1 - X0)` with integer coefficients.

use num_bigint::{BigInt, BigUint, Sign};
use num_integer::Integer;
use num_traits::{One, Signed, ToPrimitive, Zero};

use super::ring::{self, Ring, V3};

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
// Integer polynomial remainder sequences, dyadic points
// ---------------------------------------------------------------------------------------
//
// No rationals: every remainder is a pseudo-remainder (a known-sign multiple of the true
// remainder) divided by its content, and every evaluation point is dyadic, `n / 2^k`, where
// `2^(k deg p) p(n / 2^k)` is an integer of the sign of `p(n / 2^k)`. Positive scalings of
// the members of a Sturm or Sturm-Tarski sequence change no sign, so no count.

/// A dyadic rational `n / 2^k`.
#[derive(Clone, Debug, PartialEq, Eq)]
pub(crate) struct Dy {
    n: BigInt,
    k: u64,
}

impl Dy {
    fn zero() -> Dy {
        Dy {
            n: BigInt::zero(),
            k: 0,
        }
    }
    /// The exact value of a finite, non-negative f64.
    fn from_f64(x: f64) -> Dy {
        let (m, e) = decompose(x);
        if e >= 0 {
            Dy {
                n: m << e as usize,
                k: 0,
            }
        } else {
            Dy {
                n: m,
                k: (-e) as u64,
            }
        }
    }
    /// `self + (other - self) * num / 2^den_log2`.
    fn lerp(&self, other: &Dy, num: i64, den_log2: u64) -> Dy {
        let k = self.k.max(other.k) + den_log2;
        let a = &self.n << (k - self.k) as usize;
        let b = &other.n << (k - other.k) as usize;
        let n = &a + (((&b - &a) * num) >> den_log2 as usize);
        Dy { n, k }.normalized()
    }
    fn normalized(mut self) -> Dy {
        if self.n.is_zero() {
            self.k = 0;
            return self;
        }
        let tz = self.n.trailing_zeros().unwrap_or(0).min(self.k);
        self.n >>= tz as usize;
        self.k -= tz;
        self
    }
    fn cmp(&self, other: &Dy) -> std::cmp::Ordering {
        let k = self.k.max(other.k);
        (&self.n << (k - self.k) as usize).cmp(&(&other.n << (k - other.k) as usize))
    }
    /// `other - self <= 2^-tol_log2`.
    fn within(&self, other: &Dy, tol_log2: u64) -> bool {
        let k = self.k.max(other.k).max(tol_log2);
        let d = (&other.n << (k - other.k) as usize) - (&self.n << (k - self.k) as usize);
        d <= (BigInt::one() << (k - tol_log2) as usize)
    }
    /// The largest f64 not above this (non-negative) value.
    fn round_down(&self) -> f64 {
        debug_assert!(!self.n.is_negative());
        if self.n.is_zero() {
            return 0.0;
        }
        let bits = self.n.bits();
        let drop = bits.saturating_sub(53);
        let m = (&self.n >> drop as usize).to_u64().unwrap(); // floor: rounds down
        let e = drop as i64 - self.k as i64;
        if e < -1000 {
            return 0.0; // below 2^-947: 0 is a lower bound within any tolerance
        }
        let mut x = m as f64;
        let mut e = e as i32;
        while e != 0 {
            let s = e.clamp(-1000, 1000);
            x *= 2f64.powi(s); // exact: a power of two, no under- or overflow here
            e -= s;
        }
        x
    }
}

/// The sign of `p` at the dyadic `x`.
fn sign_at_dy(p: &[BigInt], x: &Dy) -> i8 {
    let Some(d) = p.len().checked_sub(1) else {
        return 0;
    };
    let mut acc = p[d].clone();
    for i in (0..d).rev() {
        acc = acc * &x.n + (&p[i] << (x.k as usize * (d - i)));
    }
    match acc.sign() {
        Sign::Plus => 1,
        Sign::Minus => -1,
        Sign::NoSign => 0,
    }
}

fn trimmed(mut v: Vec<BigInt>) -> Vec<BigInt> {
    while v.last().is_some_and(|c| c.is_zero()) {
        v.pop();
    }
    v
}

fn deriv(p: &[BigInt]) -> Vec<BigInt> {
    trimmed(
        p.iter()
            .enumerate()
            .skip(1)
            .map(|(i, c)| c * BigInt::from(i))
            .collect(),
    )
}

fn pmul(a: &[BigInt], b: &[BigInt]) -> Vec<BigInt> {
    if a.is_empty() || b.is_empty() {
        return Vec::new();
    }
    let mut out = vec![BigInt::zero(); a.len() + b.len() - 1];
    for (i, x) in a.iter().enumerate() {
        for (j, y) in b.iter().enumerate() {
            out[i + j] += x * y;
        }
    }
    trimmed(out)
}

/// `p` divided by the gcd of its coefficients (a positive number).
fn primitive(p: Vec<BigInt>) -> Vec<BigInt> {
    let mut g = BigUint::zero();
    for c in &p {
        g = gcd(g, c.magnitude().clone());
        if g.is_one() {
            return p;
        }
    }
    if g.is_zero() {
        return p;
    }
    let g = BigInt::from(g);
    p.into_iter().map(|c| c / &g).collect()
}

/// The gcd of two naturals by Lehmer's algorithm (Knuth, TAOCP vol. 2, 4.5.2, Algorithm L):
/// the quotients of Euclid's algorithm are found on the leading 64 bits while they are
/// certain, and applied to the full numbers as one 2 x 2 step.
///
/// PERF: `Integer::gcd` of num-bigint is Stein's binary algorithm, one bit per step of a
/// shift and a subtraction of the whole number: on the 7,000-bit coefficients of a query
/// whose coordinates span `5e-324` to `3e38`, four fifths of the exact path's time.
fn gcd(a: BigUint, b: BigUint) -> BigUint {
    let (mut u, mut v) = if a >= b { (a, b) } else { (b, a) };
    while !v.is_zero() {
        let n = u.bits();
        if n <= 64 {
            let (mut x, mut y) = (u.to_u64().expect("64 bits"), v.to_u64().expect("at most u"));
            while y != 0 {
                (x, y) = (y, x % y);
            }
            return BigUint::from(x);
        }
        // The leading 64 bits of u, and v's bits at the same places.
        let shift = n - 64;
        let mut x = i128::from((&u >> shift).to_u64().expect("64 bits"));
        let mut y = i128::from((&v >> shift).to_u64().expect("at most u's"));
        let (mut ca, mut cb, mut cc, mut cd) = (1i128, 0i128, 0i128, 1i128);
        loop {
            if y + cc == 0 || y + cd == 0 {
                break;
            }
            let q = (x + ca) / (y + cc);
            if q != (x + cb) / (y + cd) {
                break;
            }
            (ca, cc) = (cc, ca - q * cc);
            (cb, cd) = (cd, cb - q * cd);
            (x, y) = (y, x - q * y);
        }
        if cb == 0 {
            // No quotient was certain: one step of Euclid on the full numbers.
            let r = &u % &v;
            (u, v) = (v, r);
        } else {
            let (bu, bv) = (BigInt::from(u), BigInt::from(v));
            let nu = &bu * ca + &bv * cb;
            let nv = &bu * cc + &bv * cd;
            u = nu.to_biguint().expect("Lehmer's combinations are natural");
            v = nv.to_biguint().expect("Lehmer's combinations are natural");
        }
    }
    u
}

/// `(r, s)` with `r = c * rem(a, b)` for some `c` of sign `s` (+1 or -1), `b` nonzero.
fn prem(a: &[BigInt], b: &[BigInt]) -> (Vec<BigInt>, i8) {
    assert!(!b.is_empty(), "division by the zero polynomial");
    let db = b.len() - 1;
    let lb = &b[db];
    let neg = lb.is_negative();
    let mut r = a.to_vec();
    let mut sign = 1i8;
    while r.len() > db {
        let k = r.len() - 1 - db;
        let lr = r[r.len() - 1].clone();
        for c in r.iter_mut() {
            *c *= lb;
        }
        for (i, bi) in b.iter().enumerate() {
            r[k + i] -= &lr * bi;
        }
        debug_assert!(r[r.len() - 1].is_zero());
        r.pop();
        r = trimmed(r);
        if neg {
            sign = -sign;
        }
    }
    (r, sign)
}

/// Exact quotient `a / b` (b divides a over the integers).
fn pdiv_exact(a: &[BigInt], b: &[BigInt]) -> Vec<BigInt> {
    let db = b.len() - 1;
    let mut r = a.to_vec();
    if r.len() <= db {
        return Vec::new();
    }
    let mut q = vec![BigInt::zero(); r.len() - db];
    while r.len() > db && !r.is_empty() {
        let k = r.len() - 1 - db;
        let (c, rest) = r[r.len() - 1].div_rem(&b[db]);
        debug_assert!(rest.is_zero(), "inexact polynomial division");
        for (i, bi) in b.iter().enumerate() {
            r[k + i] -= &c * bi;
        }
        q[k] = c;
        r.pop();
        r = trimmed(r);
    }
    debug_assert!(r.is_empty(), "inexact polynomial division");
    trimmed(q)
}

/// The signed remainder sequence `p, q, -rem(p, q), ...` up to positive factors.
fn srs(p: &[BigInt], q: &[BigInt]) -> Vec<Vec<BigInt>> {
    let mut seq = vec![primitive(p.to_vec())];
    if q.is_empty() {
        return seq;
    }
    seq.push(primitive(q.to_vec()));
    loop {
        let n = seq.len();
        let (r, s) = prem(&seq[n - 2], &seq[n - 1]);
        if r.is_empty() {
            return seq;
        }
        // -rem = -s * r up to a positive factor.
        let r = if s > 0 {
            r.into_iter().map(|c| -c).collect()
        } else {
            r
        };
        seq.push(primitive(r));
    }
}

/// Primitive gcd of two nonzero polynomials (up to sign).
fn pgcd(a: &[BigInt], b: &[BigInt]) -> Vec<BigInt> {
    let (mut x, mut y) = (primitive(a.to_vec()), primitive(b.to_vec()));
    while !y.is_empty() {
        let (r, _) = prem(&x, &y);
        x = y;
        y = primitive(r);
    }
    x
}

/// Sign variations of `seq` at `x` (zeros skipped).
fn variations(seq: &[Vec<BigInt>], x: &Dy) -> i32 {
    let mut last = 0i8;
    let mut v = 0;
    for p in seq {
        let s = sign_at_dy(p, x);
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
    /// Exactly this dyadic (only `0` and `T` are reported this way).
    Exact(Dy),
    /// The only root of the square-free `p` in the open interval `(lo, hi)`, where `p` does
    /// not vanish at `lo` nor `hi`.
    Isolated {
        p: std::rc::Rc<Vec<BigInt>>,
        lo: Dy,
        hi: Dy,
    },
}

impl Root {
    fn lower(&self) -> &Dy {
        match self {
            Root::Exact(x) => x,
            Root::Isolated { lo, .. } => lo,
        }
    }
}

/// Asked between the steps of the exact path (`true`: stop now). A stopped solve returns
/// [`Stopped`]; its caller discards the query.
pub(crate) type Stop<'a> = &'a dyn Fn() -> bool;

/// The exact path was stopped by its [`Stop`] before it finished.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct Stopped;

/// The distinct real roots of the nonzero `poly` in `[0, t_max]`, in increasing order.
pub(crate) fn roots(poly: &Poly, t_max: &Dy, stop: Stop<'_>) -> Result<Vec<Root>, Stopped> {
    let mut out = Vec::new();
    if poly.0.len() <= 1 {
        return Ok(out); // a nonzero constant (or zero, which the caller never passes)
    }
    // Square-free part.
    let q = primitive(poly.0.clone());
    let g = pgcd(&q, &deriv(&q));
    let mut p = if g.len() > 1 { pdiv_exact(&q, &g) } else { q };
    let zero = Dy::zero();
    let at_zero = sign_at_dy(&p, &zero) == 0;
    if at_zero {
        out.push(Root::Exact(zero.clone()));
        p.remove(0); // p = t p', p'(0) != 0 (p is square-free)
    }
    if t_max.n.is_zero() {
        return Ok(out);
    }
    if stop() {
        return Err(Stopped);
    }
    let at_end = sign_at_dy(&p, t_max) == 0;
    if at_end {
        // Divide by the primitive (2^k t - n).
        let lin = vec![-t_max.n.clone(), BigInt::one() << t_max.k as usize];
        p = pdiv_exact(&p, &lin);
    }
    if p.len() > 1 {
        let sturm = srs(&p, &deriv(&p));
        let p = std::rc::Rc::new(p);
        isolate(&p, &sturm, zero, t_max.clone(), &mut out, stop)?;
    }
    if at_end {
        out.push(Root::Exact(t_max.clone()));
    }
    Ok(out)
}

/// Appends the roots of `p` in `(lo, hi)` (neither a root), in increasing order.
fn isolate(
    p: &std::rc::Rc<Vec<BigInt>>,
    sturm: &[Vec<BigInt>],
    lo: Dy,
    hi: Dy,
    out: &mut Vec<Root>,
    stop: Stop<'_>,
) -> Result<(), Stopped> {
    if stop() {
        return Err(Stopped);
    }
    let count = variations(sturm, &lo) - variations(sturm, &hi);
    debug_assert!(count >= 0);
    if count == 0 {
        return Ok(());
    }
    if count == 1 {
        out.push(Root::Isolated {
            p: p.clone(),
            lo,
            hi,
        });
        return Ok(());
    }
    // Split at a point that is not a root: of 1/2, 3/8, 5/8, 1/4, 3/4, 1/8, 7/8, ... of the
    // way (more candidates than p has roots), the first that is not one.
    let mut split = None;
    for (num, den) in [
        (8, 4),
        (3, 3),
        (5, 3),
        (1, 2),
        (3, 2),
        (1, 3),
        (7, 3),
        (9, 4),
        (11, 4),
        (13, 4),
        (15, 4),
    ] {
        let m = lo.lerp(&hi, num, den);
        if sign_at_dy(p, &m) != 0 {
            split = Some(m);
            break;
        }
    }
    let m = split.expect("a polynomial of degree < 11 has a non-root among 11 points");
    isolate(p, sturm, lo, m.clone(), out, stop)?;
    isolate(p, sturm, m, hi, out, stop)
}

/// The sign of `s` at the root.
fn sign_at(s: &Poly, root: &Root) -> i8 {
    match root {
        Root::Exact(x) => sign_at_dy(&s.0, x),
        Root::Isolated { p, lo, hi } => {
            if s.is_zero() {
                return 0;
            }
            // Sturm-Tarski: Var(SRS(p, p' s); lo, hi) = sum over the roots r of p in
            // (lo, hi] of sign(s(r)); there is exactly one, and s may be replaced by its
            // remainder mod p (here a multiple of known sign).
            let (r, m) = prem(&s.0, p);
            if r.is_empty() {
                return 0;
            }
            let seq = srs(p, &pmul(&deriv(p), &r));
            let taq = variations(&seq, lo) - variations(&seq, hi);
            debug_assert!((-1..=1).contains(&taq));
            taq.signum() as i8 * m
        }
    }
}

/// A lower bound of the root, at most `2^-tol_log2` below it (an exact root is itself).
fn lower_bound(root: &Root, tol_log2: u64, stop: Stop<'_>) -> Result<Dy, Stopped> {
    match root {
        Root::Exact(x) => Ok(x.clone()),
        Root::Isolated { p, lo, hi } => {
            let (mut lo, mut hi) = (lo.clone(), hi.clone());
            let s_lo = sign_at_dy(p, &lo);
            while !lo.within(&hi, tol_log2) {
                if stop() {
                    return Err(Stopped);
                }
                let m = lo.lerp(&hi, 1, 1);
                let s = sign_at_dy(p, &m);
                if s == 0 {
                    return Ok(m);
                }
                if s == s_lo {
                    lo = m;
                } else {
                    hi = m;
                }
            }
            Ok(lo)
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
///
/// Open clauses: if every condition of clause c is strict (or holds identically), S_c is
/// open in [0, t_max]. Let t* = min S > 0. Were t* only in open clauses' sets, one of them
/// would hold on a neighbourhood of t*, below t* too: so t* lies in a clause that is not
/// open, and is that clause's minimum. Open clauses therefore only need the candidate 0.
/// (Coplanar motion is the case: with f identically 0, "strictly inside" and "properly
/// crossing" are open, and the first contact is on an edge or at an endpoint.)
pub(crate) fn earliest(
    formula: &Formula,
    t_max: &Dy,
    stop: Stop<'_>,
) -> Result<Option<Dy>, Stopped> {
    let n = formula.polys.len();
    // Which candidate groups: Some(j) = the roots of polynomial j; None = the point 0.
    let mut groups: Vec<Option<usize>> = Vec::new();
    let mut push = |g: Option<usize>| {
        if !groups.contains(&g) {
            groups.push(g);
        }
    };
    for clause in &formula.clauses {
        // A clause whose conditions are all strict inequalities (or hold identically) has
        // an open solution set: its infimum, if > 0, lies outside it but in S, hence in
        // another clause, so it only contributes the candidate 0 (see below).
        let open = clause
            .iter()
            .all(|&(j, c)| matches!(c, Cond::Pos | Cond::Neg) || formula.polys[j].is_zero());
        if open {
            push(None);
            continue;
        }
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
    let tol = super::TOI_TOL_LOG2 as u64;
    let mut best: Option<Dy> = None;
    let holds_at = |root: &Root| -> Result<bool, Stopped> {
        let mut signs: Vec<Option<i8>> = vec![None; n];
        let mut stopped = false;
        let holds = formula.clauses.iter().any(|clause| {
            !stopped
                && clause.iter().all(|&(j, c)| {
                    let s = *signs[j].get_or_insert_with(|| {
                        // Each sign is a Sturm-Tarski query: ask between them.
                        stopped = stopped || stop();
                        if stopped {
                            0
                        } else {
                            sign_at(&formula.polys[j], root)
                        }
                    });
                    !stopped && c.holds(s)
                })
        });
        if stopped {
            Err(Stopped)
        } else {
            Ok(holds)
        }
    };
    for g in groups {
        let cands = match g {
            None => vec![Root::Exact(Dy::zero())],
            Some(j) => roots(&formula.polys[j], t_max, stop)?,
        };
        for root in cands {
            // Candidates of one group come in increasing order: past the best, stop.
            if best.as_ref().is_some_and(|b| root.lower().cmp(b).is_ge()) {
                break;
            }
            if holds_at(&root)? {
                let lb = lower_bound(&root, tol, stop)?;
                if best.as_ref().is_none_or(|b| lb.cmp(b).is_lt()) {
                    best = Some(lb);
                }
                break;
            }
        }
    }
    Ok(best)
}

// ---------------------------------------------------------------------------------------
// The queries' formulas
// ---------------------------------------------------------------------------------------

/// `x = sign * mantissa * 2^exp` of a finite f64.
fn decompose(x: f64) -> (BigInt, i32) {
    let bits = x.to_bits();
    let sign = if bits >> 63 == 1 {
        Sign::Minus
    } else {
        Sign::Plus
    };
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
fn to_integers(
    x0: &[[f64; 3]; 4],
    x1: &[[f64; 3]; 4],
    extra: &[f64],
) -> (Vec<BigInt>, Vec<BigInt>) {
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
        .map(|(m, e)| {
            if m.is_zero() {
                m
            } else {
                m << (e - emin) as usize
            }
        })
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
    let dots = [
        ring::dot(&aa, &bb),
        ring::dot(&bb, &cc),
        ring::dot(&cc, &aa),
    ];
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
        cl.extend(on_segment(
            &mut polys,
            &ring::cross(&aa, &bb),
            ring::dot(&aa, &bb),
        ));
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
fn near_segment(
    polys: &mut Vec<Poly>,
    aa: &V3<Poly>,
    bb: &V3<Poly>,
    dd: &Poly,
) -> Vec<Vec<(usize, Cond)>> {
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
    let mut cl = vec![
        (add(&mut polys, nn), Cond::Pos),
        (add(&mut polys, plane), Cond::NonPos),
    ];
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
pub(crate) fn solve(
    kind: Kind,
    x0: &[[f64; 3]; 4],
    x1: &[[f64; 3]; 4],
    t_max: f64,
    min_distance: f64,
    stop: Stop<'_>,
) -> Result<Option<f64>, Stopped> {
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
    Ok(earliest(&formula, &Dy::from_f64(t_max), stop)?.map(|t| t.round_down()))
}

/// The coplanarity polynomial f of the query (the same as the filter's, up to a positive
/// power-of-two scale).
/// For both kinds it is `det(x1 - x0, x2 - x0, x3 - x0)` of the four points in query
/// order: `det(a - p, b - p, c - p)` and `det(a1 - a0, b0 - a0, b1 - a0)`.
fn coplanarity(pts: &[V3<Poly>; 4]) -> Poly {
    let [p, a, b, c] = pts;
    let (aa, bb, cc) = (ring::sub3(a, p), ring::sub3(b, p), ring::sub3(c, p));
    ring::dot(&aa, &ring::cross(&bb, &cc))
}

/// The only root of the coplanarity polynomial in `(s0, s1)`, where it changes sign
/// (certified by the filter), as a lower bound at most 2^-40 below it.
pub(crate) fn refine_root(
    x0: &[[f64; 3]; 4],
    x1: &[[f64; 3]; 4],
    s0: f64,
    s1: f64,
    stop: Stop<'_>,
) -> Result<f64, Stopped> {
    let (ints, _) = to_integers(x0, x1, &[]);
    let f = coplanarity(&moving_points(&ints));
    let root = Root::Isolated {
        p: std::rc::Rc::new(f.0),
        lo: Dy::from_f64(s0),
        hi: Dy::from_f64(s1),
    };
    debug_assert!(match &root {
        Root::Isolated { p, lo, hi } => sign_at_dy(p, lo) * sign_at_dy(p, hi) < 0,
        _ => false,
    });
    Ok(lower_bound(&root, super::TOI_TOL_LOG2 as u64, stop)?.round_down())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Lehmer's gcd equals Stein's (`Integer::gcd`) on numbers of every size, with common
    /// factors planted, zeros and equal arguments.
    #[test]
    fn lehmer_gcd_equals_steins() {
        let mut state = 0x2545_f491_4f6c_dd1du64;
        let mut next = || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            state
        };
        let mut number = |words: usize| {
            let digits: Vec<u64> = (0..words).map(|_| next()).collect();
            BigUint::from_slice(
                &digits
                    .iter()
                    .flat_map(|d| [*d as u32, (*d >> 32) as u32])
                    .collect::<Vec<_>>(),
            )
        };
        for words in [0, 1, 2, 3, 5, 17, 60, 120] {
            for _ in 0..20 {
                let common = number(words / 2 + 1);
                let a = number(words) * &common;
                let b = number(words / 3 + 1) * &common;
                assert_eq!(gcd(a.clone(), b.clone()), a.gcd(&b), "{words}");
                assert_eq!(gcd(b.clone(), a.clone()), a.gcd(&b));
                assert_eq!(gcd(a.clone(), a.clone()), a);
                assert_eq!(gcd(a.clone(), BigUint::zero()), a);
                assert_eq!(gcd(BigUint::zero(), a.clone()), a);
                let pow = BigUint::one() << (words * 40);
                assert_eq!(gcd(&a * &pow, &b * &pow), a.gcd(&b) * &pow);
            }
        }
    }
}
