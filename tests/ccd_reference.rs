//! Property tests of `dhcd::ccd` against a slow, independent exact reference, on random
//! motions and on adversarial ones: contacts planted at a chosen time on a face's
//! interior, edge or corner, on an edge's interior or endpoint; coplanar motion;
//! degenerate triangles and edges (collinear, coincident, zero length); parallel edges;
//! one-ulp perturbations; scalings by 2^-300 and 2^300.
//!
//! The reference shares no code and a different formulation: the predicate with
//! barycentric coordinates by Cramer's rule (segment parameters for edges) and
//! point-on-segment as collinear-and-inside-the-coordinate-box; every polynomial computed
//! in `BigRational`; candidate times = 0 and the roots in [0, t_max] of every polynomial
//! of the formula (no reduction), isolated by Descartes' rule of signs (not Sturm); the
//! sign of a polynomial at an isolated root by a gcd test for 0 and bisection until
//! Descartes sees no root of it (not Sturm-Tarski).

use dhcd::ccd::{self, CcdOptions, TOI_TOLERANCE};
use num_bigint::BigInt;
use num_rational::BigRational;
use num_traits::{One, Signed, Zero};
use proptest::prelude::*;
use proptest::strategy::ValueTree;

type Q = BigRational;
type P = Vec<Q>; // lowest degree first, trimmed
type Pts = [[f64; 3]; 4];

fn trim(mut p: P) -> P {
    while p.last().is_some_and(|c| c.is_zero()) {
        p.pop();
    }
    p
}
fn padd(a: &P, b: &P) -> P {
    let n = a.len().max(b.len());
    let z = Q::zero();
    trim(
        (0..n)
            .map(|i| a.get(i).unwrap_or(&z) + b.get(i).unwrap_or(&z))
            .collect(),
    )
}
fn pneg(a: &P) -> P {
    a.iter().map(|c| -c).collect()
}
fn psub(a: &P, b: &P) -> P {
    padd(a, &pneg(b))
}
fn pmul(a: &P, b: &P) -> P {
    if a.is_empty() || b.is_empty() {
        return vec![];
    }
    let mut o = vec![Q::zero(); a.len() + b.len() - 1];
    for (i, x) in a.iter().enumerate() {
        for (j, y) in b.iter().enumerate() {
            o[i + j] += x * y;
        }
    }
    trim(o)
}
fn eval(p: &P, x: &Q) -> Q {
    p.iter().rev().fold(Q::zero(), |acc, c| acc * x + c)
}
fn sgn(q: &Q) -> i8 {
    if q.is_positive() {
        1
    } else if q.is_negative() {
        -1
    } else {
        0
    }
}
fn deriv(p: &P) -> P {
    trim(
        p.iter()
            .enumerate()
            .skip(1)
            .map(|(i, c)| c * Q::from_integer(i.into()))
            .collect(),
    )
}
fn divrem(a: &P, b: &P) -> (P, P) {
    let mut r = a.clone();
    let mut q = vec![Q::zero(); a.len().saturating_sub(b.len()) + 1];
    while r.len() >= b.len() && !r.is_empty() {
        let k = r.len() - b.len();
        let c = r.last().unwrap() / b.last().unwrap();
        for (i, bi) in b.iter().enumerate() {
            r[k + i] -= &c * bi;
        }
        q[k] = c;
        r.pop();
        r = trim(r);
    }
    (trim(q), r)
}
fn gcd(a: &P, b: &P) -> P {
    let (mut x, mut y) = (a.clone(), b.clone());
    while !y.is_empty() {
        let r = divrem(&x, &y).1;
        x = y;
        y = r;
    }
    x
}
/// p(lo + (hi - lo) x).
fn compose(p: &P, lo: &Q, w: &Q) -> P {
    let lin = vec![lo.clone(), w.clone()];
    p.iter()
        .rev()
        .fold(vec![], |acc, c| padd(&pmul(&acc, &lin), &vec![c.clone()]))
}
/// Descartes' bound on the number of roots of p in (lo, hi): sign variations of
/// (1 + y)^d p((lo + hi y) / (1 + y)).
fn descartes(p: &P, lo: &Q, hi: &Q) -> usize {
    let mut q = compose(p, lo, &(hi - lo)); // roots now in (0, 1)
    q.reverse(); // x^d q(1/x): roots in (1, inf)
    let q = compose(&trim(q), &Q::one(), &Q::one()); // x -> x + 1: roots in (0, inf)
    let signs: Vec<i8> = q.iter().map(sgn).filter(|&s| s != 0).collect();
    signs.windows(2).filter(|w| w[0] != w[1]).count()
}

#[derive(Clone)]
enum Root {
    At(Q),
    In(P, Q, Q), // the only root of square-free P in (lo, hi)
}

fn isolate(p: &P, lo: Q, hi: Q, out: &mut Vec<Root>) {
    assert!(
        &hi - &lo > Q::new(BigInt::one(), BigInt::one() << 400),
        "isolate: {p:?}"
    );
    let v = descartes(p, &lo, &hi);
    if v == 0 {
        return;
    }
    if v == 1 {
        out.push(Root::In(p.clone(), lo, hi));
        return;
    }
    // Split at a non-root (isolating intervals have non-root ends): 1/2, 1/3, 2/3, ...
    let m = (2..10)
        .flat_map(|d| (1..d).map(move |k| Q::new(k.into(), d.into())))
        .map(|f| &lo + (&hi - &lo) * f)
        .find(|m| sgn(&eval(p, m)) != 0)
        .unwrap();
    isolate(p, lo, m.clone(), out);
    isolate(p, m, hi, out);
}

fn roots(p: &P, t: &Q) -> Vec<Root> {
    if p.len() <= 1 {
        return vec![];
    }
    let mut sf = divrem(p, &gcd(p, &deriv(p))).0;
    let mut out = vec![];
    for x in [Q::zero(), t.clone()] {
        if sf.len() > 1 && sgn(&eval(&sf, &x)) == 0 {
            out.push(Root::At(x.clone()));
            sf = divrem(&sf, &vec![-x, Q::one()]).0; // deflate: interval ends are non-roots
        }
    }
    if sf.len() <= 1 {
        return out;
    }
    if t.is_positive() {
        isolate(&sf, Q::zero(), t.clone(), &mut out);
    }
    out
}

fn sign_at(s: &P, r: &Root) -> i8 {
    match r {
        Root::At(x) => sgn(&eval(s, x)),
        Root::In(p, lo, hi) => {
            if s.is_empty() {
                return 0;
            }
            let g = gcd(p, s);
            if g.len() > 1 && sgn(&eval(&g, lo)) * sgn(&eval(&g, hi)) < 0 {
                return 0;
            }
            let (mut lo, mut hi) = (lo.clone(), hi.clone());
            let sp = sgn(&eval(p, &lo));
            for _ in 0..2000 {
                if descartes(s, &lo, &hi) == 0 && sgn(&eval(s, &lo)) != 0 {
                    return sgn(&eval(s, &lo));
                }
                let m = (&lo + &hi) / Q::from_integer(2.into());
                if sgn(&eval(p, &m)) == sp {
                    lo = m;
                } else {
                    hi = m;
                }
            }
            panic!("sign_at did not converge: s {s:?} p {p:?}");
        }
    }
}

fn lower(r: &Root) -> Q {
    match r {
        Root::At(x) => x.clone(),
        Root::In(_, lo, _) => lo.clone(),
    }
}
fn upper(r: &Root) -> Q {
    match r {
        Root::At(x) => x.clone(),
        Root::In(p, lo, hi) => {
            // Narrow to width <= 2^-60 and return the upper end.
            let (mut lo, mut hi) = (lo.clone(), hi.clone());
            let eps = Q::new(BigInt::one(), BigInt::one() << 60);
            let sp = sgn(&eval(p, &lo));
            while &hi - &lo > eps {
                let m = (&lo + &hi) / Q::from_integer(2.into());
                match sgn(&eval(p, &m)) {
                    0 => return m,
                    s if s == sp => lo = m,
                    _ => hi = m,
                }
            }
            hi
        }
    }
}

#[derive(Clone, Copy)]
enum C {
    Z,
    Ge,
    Le,
    Gt,
}
type V = [P; 3];

fn vsub(a: &V, b: &V) -> V {
    [psub(&a[0], &b[0]), psub(&a[1], &b[1]), psub(&a[2], &b[2])]
}
fn vcross(a: &V, b: &V) -> V {
    [
        psub(&pmul(&a[1], &b[2]), &pmul(&a[2], &b[1])),
        psub(&pmul(&a[2], &b[0]), &pmul(&a[0], &b[2])),
        psub(&pmul(&a[0], &b[1]), &pmul(&a[1], &b[0])),
    ]
}
fn vdot(a: &V, b: &V) -> P {
    padd(
        &padd(&pmul(&a[0], &b[0]), &pmul(&a[1], &b[1])),
        &pmul(&a[2], &b[2]),
    )
}

/// q on the closed segment [x, y]: collinear, and inside the box of x and y.
fn on_seg(q: &V, x: &V, y: &V) -> Vec<(P, C)> {
    let mut c: Vec<(P, C)> = vcross(&vsub(x, q), &vsub(y, q))
        .into_iter()
        .map(|p| (p, C::Z))
        .collect();
    for k in 0..3 {
        c.push((pmul(&psub(&q[k], &x[k]), &psub(&q[k], &y[k])), C::Le));
    }
    c
}

/// 2-adic valuation of a nonzero dyadic rational.
fn val2(q: &Q) -> i64 {
    q.numer().trailing_zeros().unwrap() as i64 - q.denom().trailing_zeros().unwrap() as i64
}

fn formula(vf: bool, x0: &Pts, x1: &Pts) -> Vec<Vec<(P, C)>> {
    // One common power-of-two scaling (it moves no contact) keeps the numbers small.
    let all = x0
        .iter()
        .chain(x1.iter())
        .flatten()
        .map(|&x| Q::from_float(x).unwrap());
    let emin = all
        .filter(|q| !q.is_zero())
        .map(|q| val2(&q))
        .min()
        .unwrap_or(0);
    let s = if emin >= 0 {
        Q::new(BigInt::one(), BigInt::one() << emin as usize)
    } else {
        Q::from_integer(BigInt::one() << (-emin) as usize)
    };
    let lin = |a: f64, b: f64| -> P {
        let a = Q::from_float(a).unwrap() * &s;
        let b = Q::from_float(b).unwrap() * &s;
        trim(vec![a.clone(), b - a])
    };
    let pt = |i: usize| -> V { std::array::from_fn(|k| lin(x0[i][k], x1[i][k])) };
    let (p0, p1, p2, p3) = (pt(0), pt(1), pt(2), pt(3));
    let mut clauses = vec![];
    if vf {
        let (p, a, b, c) = (p0, p1, p2, p3);
        let (ab, ac, ap) = (vsub(&b, &a), vsub(&c, &a), vsub(&p, &a));
        let n = vcross(&ab, &ac);
        let nn = vdot(&n, &n);
        let lb = vdot(&vcross(&ap, &ac), &n);
        let lc = vdot(&vcross(&ab, &ap), &n);
        let rest = psub(&psub(&nn, &lb), &lc);
        clauses.push(vec![
            (vdot(&ap, &n), C::Z),
            (nn, C::Gt),
            (lb, C::Ge),
            (lc, C::Ge),
            (rest, C::Ge),
        ]);
        clauses.push(on_seg(&p, &a, &b));
        clauses.push(on_seg(&p, &b, &c));
        clauses.push(on_seg(&p, &a, &c));
    } else {
        let (a0, a1, b0, b1) = (p0, p1, p2, p3);
        let (u, v, w) = (vsub(&a1, &a0), vsub(&b1, &b0), vsub(&b0, &a0));
        let n = vcross(&u, &v);
        let nn = vdot(&n, &n);
        let s = vdot(&vcross(&w, &v), &n);
        let r = vdot(&vcross(&w, &u), &n);
        clauses.push(vec![
            (vdot(&w, &n), C::Z),
            (nn.clone(), C::Gt),
            (s.clone(), C::Ge),
            (psub(&nn, &s), C::Ge),
            (r.clone(), C::Ge),
            (psub(&nn, &r), C::Ge),
        ]);
        clauses.push(on_seg(&a0, &b0, &b1));
        clauses.push(on_seg(&a1, &b0, &b1));
        clauses.push(on_seg(&b0, &a0, &a1));
        clauses.push(on_seg(&b1, &a0, &a1));
    }
    clauses
}

/// The earliest contact time in [0, t_max] as an enclosure [lo, hi], or None.
fn reference(vf: bool, x0: &Pts, x1: &Pts, t_max: f64) -> Option<(Q, Q)> {
    let clauses = formula(vf, x0, x1);
    let t = Q::from_float(t_max).unwrap();
    let mut cands = vec![Root::At(Q::zero())];
    for cl in &clauses {
        for (p, _) in cl {
            cands.extend(roots(p, &t));
        }
    }
    let holds = |r: &Root| {
        clauses.iter().any(|cl| {
            cl.iter().all(|(p, c)| {
                let s = sign_at(p, r);
                match c {
                    C::Z => s == 0,
                    C::Ge => s >= 0,
                    C::Le => s <= 0,
                    C::Gt => s > 0,
                }
            })
        })
    };
    let mut best: Option<(Q, Q)> = None;
    for r in cands.iter() {
        if best.as_ref().is_some_and(|(_, hi)| lower(r) >= *hi) {
            continue;
        }
        if holds(r) {
            let (lo, hi) = (lower(r), upper(r));
            best = match best {
                None => Some((lo, hi)),
                Some((blo, bhi)) => Some((blo.min(lo), bhi.min(hi))),
            };
        }
    }
    best
}

fn compare(vf: bool, x0: &Pts, x1: &Pts, t_max: f64) -> Result<(), TestCaseError> {
    let o = CcdOptions::new(t_max, 0.0).unwrap();
    let got = if vf {
        ccd::vertex_face(x0, x1, &o)
    } else {
        ccd::edge_edge(x0, x1, &o)
    };
    let want = reference(vf, x0, x1, t_max);
    match (&got, &want) {
        (None, None) => Ok(()),
        (Some(t), Some((lo, hi))) => {
            let tq = Q::from_float(*t).unwrap();
            let tol = Q::from_float(TOI_TOLERANCE).unwrap();
            prop_assert!(tq <= *hi, "toi {t} after the reference's {hi}");
            prop_assert!(
                tq >= lo - tol,
                "toi {t} more than the tolerance before {lo}"
            );
            Ok(())
        }
        _ => Err(TestCaseError::fail(format!(
            "{} {x0:?} -> {x1:?} (t_max {t_max}): got {got:?}, reference {}",
            if vf { "vf" } else { "ee" },
            want.is_some()
        ))),
    }
}

// ------------------------------------------------------------------------------------
// Generators
// ------------------------------------------------------------------------------------

/// Small dyadic coordinates (multiples of 1/4 in [-2, 2]): exact in all the arithmetic
/// the planted constructions do.
fn small() -> impl Strategy<Value = f64> {
    (-8i32..=8).prop_map(|k| k as f64 / 4.0)
}
fn vec3() -> impl Strategy<Value = [f64; 3]> {
    [small(), small(), small()]
}

/// A motion through x* at time t*: x0 = x* - t* v, x1 = x* + (1 - t*) v.
fn through(x: [f64; 3], v: [f64; 3], t: f64) -> ([f64; 3], [f64; 3]) {
    (
        std::array::from_fn(|k| x[k] - t * v[k]),
        std::array::from_fn(|k| x[k] + (1.0 - t) * v[k]),
    )
}

#[derive(Debug, Clone)]
struct Case {
    vf: bool,
    x0: Pts,
    x1: Pts,
    t_max: f64,
}

/// Adversarial edits: flatten to z = 0 (coplanar motion), one ulp on one coordinate,
/// collapse a feature, scale by a power of two.
fn edit(
    mut c: Case,
    flat: bool,
    ulp: Option<(usize, usize, usize, bool)>,
    collapse: u8,
    scale: i32,
) -> Case {
    if flat {
        for p in c.x0.iter_mut().chain(c.x1.iter_mut()) {
            p[2] = 0.0;
        }
    }
    match collapse {
        1 => {
            // second feature point onto the first (zero-length edge / coincident corners)
            c.x0[2] = c.x0[1];
            c.x1[2] = c.x1[1];
        }
        2 => {
            // last point onto the midpoint of points 1 and 2 (collinear corners / an edge
            // degenerate with the other) at both times
            for x in [&mut c.x0, &mut c.x1] {
                x[3] = std::array::from_fn(|k| 0.5 * (x[1][k] + x[2][k]));
            }
        }
        _ => {}
    }
    if let Some((t, i, k, up)) = ulp {
        let x = if t == 0 {
            &mut c.x0[i][k]
        } else {
            &mut c.x1[i][k]
        };
        // One ulp; at 0 (whose ulp is the least subnormal, a spread of exponents the
        // rational reference takes minutes on) 2^-54 instead.
        *x = match (*x == 0.0, up) {
            (true, true) => 2f64.powi(-54),
            (true, false) => -(2f64.powi(-54)),
            (false, true) => x.next_up(),
            (false, false) => x.next_down(),
        };
    }
    let s = 2f64.powi(scale);
    for p in c.x0.iter_mut().chain(c.x1.iter_mut()) {
        for x in p.iter_mut() {
            *x *= s;
        }
    }
    c
}

fn planted_vf() -> impl Strategy<Value = Case> {
    (
        [vec3(), vec3(), vec3()],
        [vec3(), vec3(), vec3(), vec3()],
        (0u8..=4, 0u8..=4),
        0u8..=4,
    )
        .prop_map(|(tri, vel, (bi, ci), ti)| {
            let t = ti as f64 / 4.0;
            let (mut b, mut c) = (bi as f64 / 4.0, ci as f64 / 4.0);
            if b + c > 1.0 {
                (b, c) = (1.0 - b, 1.0 - c);
            }
            let p: [f64; 3] = std::array::from_fn(|k| {
                tri[0][k] + b * (tri[1][k] - tri[0][k]) + c * (tri[2][k] - tri[0][k])
            });
            let pts = [p, tri[0], tri[1], tri[2]];
            let mut x0 = [[0.0; 3]; 4];
            let mut x1 = [[0.0; 3]; 4];
            for i in 0..4 {
                (x0[i], x1[i]) = through(pts[i], vel[i], t);
            }
            Case {
                vf: true,
                x0,
                x1,
                t_max: 1.0,
            }
        })
}

fn planted_ee() -> impl Strategy<Value = Case> {
    (
        [vec3(), vec3(), vec3()],
        [vec3(), vec3(), vec3(), vec3()],
        (0u8..=4, 0u8..=4),
        0u8..=4,
        any::<bool>(),
    )
        .prop_map(|(pts, vel, (si, ri), ti, parallel)| {
            let t = ti as f64 / 4.0;
            let (s, r) = (si as f64 / 4.0, ri as f64 / 4.0);
            let (a0, a1) = (pts[0], pts[1]);
            let d = if parallel {
                std::array::from_fn(|k| a1[k] - a0[k])
            } else {
                pts[2]
            };
            let x: [f64; 3] = std::array::from_fn(|k| a0[k] + s * (a1[k] - a0[k]));
            let b0: [f64; 3] = std::array::from_fn(|k| x[k] - r * d[k]);
            let b1: [f64; 3] = std::array::from_fn(|k| x[k] + (1.0 - r) * d[k]);
            let p = [a0, a1, b0, b1];
            let mut x0 = [[0.0; 3]; 4];
            let mut x1 = [[0.0; 3]; 4];
            for i in 0..4 {
                (x0[i], x1[i]) = through(p[i], vel[i], t);
            }
            Case {
                vf: false,
                x0,
                x1,
                t_max: 1.0,
            }
        })
}

fn random_case() -> impl Strategy<Value = Case> {
    (
        any::<bool>(),
        [vec3(), vec3(), vec3(), vec3()],
        [vec3(), vec3(), vec3(), vec3()],
        0u8..=4,
    )
        .prop_map(|(vf, x0, x1, t)| Case {
            vf,
            x0,
            x1,
            t_max: if t == 0 { 1.0 } else { t as f64 / 4.0 },
        })
}

/// Arbitrary f64 coordinates of mixed magnitudes around a common centre.
fn wild_case() -> impl Strategy<Value = Case> {
    let coord = prop_oneof![
        -1.0f64..1.0,
        (-1.0f64..1.0).prop_map(|x| x * 1e-12),
        (-1.0f64..1.0).prop_map(|x| 1.0 + x * 1e-9),
        small(),
    ];
    let v = [coord.clone(), coord.clone(), coord];
    (
        any::<bool>(),
        [v.clone(), v.clone(), v.clone(), v.clone()],
        [v.clone(), v.clone(), v.clone(), v],
    )
        .prop_map(|(vf, x0, x1)| Case {
            vf,
            x0,
            x1,
            t_max: 1.0,
        })
}

fn adversarial(base: BoxedStrategy<Case>) -> impl Strategy<Value = Case> {
    (
        base,
        any::<bool>(),
        prop::option::weighted(0.3, (0usize..2, 0usize..4, 0usize..3, any::<bool>())),
        prop_oneof![4 => Just(0u8), 1 => Just(1u8), 1 => Just(2u8)],
        prop_oneof![6 => Just(0i32), 1 => Just(-300i32), 1 => Just(300i32)],
    )
        .prop_map(|(c, flat, ulp, collapse, scale)| edit(c, flat, ulp, collapse, scale))
}

proptest! {
    // The reference takes ~0.01-3 s a case (rational arithmetic): 48 cases each.
    #![proptest_config(ProptestConfig { cases: 48, ..ProptestConfig::default() })]

    #[test]
    fn planted_vertex_face_matches_reference(c in adversarial(planted_vf().boxed())) {
        compare(c.vf, &c.x0, &c.x1, c.t_max)?;
    }

    #[test]
    fn planted_edge_edge_matches_reference(c in adversarial(planted_ee().boxed())) {
        compare(c.vf, &c.x0, &c.x1, c.t_max)?;
    }

    #[test]
    fn random_motions_match_reference(c in adversarial(random_case().boxed())) {
        compare(c.vf, &c.x0, &c.x1, c.t_max)?;
    }

}

proptest! {
    // Arbitrary mantissas make the reference's rationals large: fewer cases.
    #![proptest_config(ProptestConfig { cases: 16, ..ProptestConfig::default() })]
    #[test]
    fn wild_coordinates_match_reference(c in wild_case()) {
        compare(c.vf, &c.x0, &c.x1, c.t_max)?;
    }
}

#[test]
fn planted_contacts_without_edits_are_found_in_time() {
    // Every unedited planted case collides no later than its planted time.
    let mut runner = proptest::test_runner::TestRunner::deterministic();
    for s in [planted_vf().boxed(), planted_ee().boxed()] {
        for _ in 0..100 {
            let c = s.new_tree(&mut runner).unwrap().current();
            let o = CcdOptions::default();
            let got = if c.vf {
                ccd::vertex_face(&c.x0, &c.x1, &o)
            } else {
                ccd::edge_edge(&c.x0, &c.x1, &o)
            };
            assert!(got.is_some(), "{c:?}");
        }
    }
}
