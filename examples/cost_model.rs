//! The cost model `T = N_V*C_V + N_P*C_P + N_U*C_U` read from the counters every query
//! returns: `N_V` BV pairs tested, `N_P` triangle pairs tested, `N_U` BVs refitted. A small
//! waving sphere moves from the centre of a large waving sphere out through its shell; every
//! step hands both hierarchies their new positions and times `collide` (whose lazy refit
//! happens inside) for the three methods: DH, sphere, AABB. The constants `C_V`, `C_P`, `C_U`
//! are then fitted per method by least squares on these same steps, so "model ms" is a fit, not
//! a prediction: it shows how much of the measured time the three counts explain ("worst
//! step": the largest relative miss on one step). Fitted on whole queries, each constant also
//! absorbs the overheads that grow with its count, and timings vary from run to run; the
//! paper's experiment (`cargo run --release -- experiment`, docs/RESULTS.md) calibrates
//! each term apart instead.
//!
//! `cargo run --release --example cost_model`

use std::time::Instant;

use dhcd::bv::{Aabb, BoundingVolume, Dh, Sphere};
use dhcd::shapes::{icosphere, wave};
use dhcd::{collide, Counters, Hierarchy, Mesh, Options};

const STEPS: usize = 40;
/// Each step is replayed this many times and the least time kept (the machine may be busy).
const REPS: usize = 5;

/// One timed query: its counters and its time in ms.
type Row = (Counters, f64);

/// Every step's two timed queries for method `K`: `[step, again]`.
fn measure<K: BoundingVolume>(a: &Mesh, b: &Mesh) -> dhcd::Result<Vec<[Row; 2]>> {
    // The paper's fixed 5-level tree, as in docs/RESULTS.md, so the constants compare.
    let mut ha = Hierarchy::<K>::new(a, Options::paper())?;
    let mut hb = Hierarchy::<K>::new(b, Options::paper())?;
    let mut steps = Vec::with_capacity(STEPS);
    for step in 0..STEPS {
        let t = step as f32 / (STEPS - 1) as f32;
        let pa = wave(a.positions(), 3.0 * t, 0.03, [0.0; 3]);
        // Inside the shell (no triangle pairs, only BV tests) for the first half of the run.
        let pb = wave(b.positions(), 3.0 * t + 1.0, 0.03, [1.2 * t * t, 0.0, 0.0]);
        let mut best = [(Counters::default(), f64::INFINITY); 2];
        for _ in 0..REPS {
            // New positions: every bound is stale again, refitted when the query first tests it.
            ha.update_positions(&pa)?;
            hb.update_positions(&pb)?;
            // The same query twice: the second finds everything fitted (N_U = 0), the same
            // N_V and N_P. N_U then varies apart from N_V and N_P, which the fit needs:
            // along the motion alone the three counts rise and fall together.
            for slot in &mut best {
                let clock = Instant::now();
                let counters = collide(&ha, &hb).counters;
                let ms = clock.elapsed().as_secs_f64() * 1e3;
                if ms < slot.1 {
                    *slot = (counters, ms);
                }
            }
        }
        steps.push(best);
    }
    Ok(steps)
}

fn counts(c: &Counters) -> [f64; 3] {
    [c.bv_tests, c.prim_tests, c.bv_updates].map(|n| n as f64)
}

/// `[C_V, C_P, C_U]` (ms per operation) minimising the squared *relative* error over the rows
/// (weight 1/ms², else the largest steps alone decide): the 3x3 normal equations
/// `(XᵀWX) c = XᵀWy`, solved by Cramer's rule.
fn fit(rows: &[Row]) -> [f64; 3] {
    let (mut m, mut r) = ([[0.0; 3]; 3], [0.0; 3]);
    for (c, ms) in rows {
        let (x, w) = (counts(c), 1.0 / (ms * ms));
        for i in 0..3 {
            r[i] += w * x[i] * ms;
            for j in 0..3 {
                m[i][j] += w * x[i] * x[j];
            }
        }
    }
    let det = |m: [[f64; 3]; 3]| {
        m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1])
            - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])
            + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0])
    };
    std::array::from_fn(|k| {
        let mut mk = m;
        for (row, ri) in mk.iter_mut().zip(r) {
            row[k] = ri;
        }
        det(mk) / det(m)
    })
}

fn main() -> dhcd::Result<()> {
    let (a, b) = (icosphere(4, 1.0, [0.0; 3]), icosphere(4, 0.5, [0.0; 3]));
    let n = a.triangle_count() + b.triangle_count();
    println!("{n} triangles, {STEPS} steps (least of {REPS} replays), C fitted on the same steps");
    println!(
        "method        N_V       N_P      N_U  contacts  measured ms  model ms  \
         worst step  C_V ns  C_P ns  C_U ns"
    );
    type Measure = fn(&Mesh, &Mesh) -> dhcd::Result<Vec<[Row; 2]>>;
    let methods: [(&str, Measure); 3] = [
        ("DH", measure::<Dh>),
        ("sphere", measure::<Sphere>),
        ("AABB", measure::<Aabb>),
    ];
    for (name, measure) in methods {
        let steps = measure(&a, &b)?;
        let c = fit(&steps.concat());
        let model = |(n, _): &Row| (0..3).map(|k| counts(n)[k] * c[k]).sum::<f64>();
        // The table is about the steps (the first query of each); the repeats only fitted C.
        let t: Counters = steps.iter().map(|s| s[0].0).sum();
        let measured: f64 = steps.iter().map(|s| s[0].1).sum();
        let modelled: f64 = steps.iter().map(|s| model(&s[0])).sum();
        let worst = steps
            .iter()
            .map(|s| 100.0 * (model(&s[0]) - s[0].1) / s[0].1)
            .fold(0.0, |w: f64, e| if e.abs() > w.abs() { e } else { w });
        let (nv, np, nu, hits) = (t.bv_tests, t.prim_tests, t.bv_updates, t.contacts);
        let [cv, cp, cu] = c.map(|x| x * 1e6);
        println!(
            "{name:<8} {nv:>8} {np:>9} {nu:>8} {hits:>9} {measured:>12.2} {modelled:>9.2} \
             {worst:>10.1}% {cv:>7.1} {cp:>7.1} {cu:>7.1}"
        );
    }
    Ok(())
}
