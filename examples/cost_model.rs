//! The cost model `T = N_V*C_V + N_P*C_P + N_U*C_U` read from the counters every query
//! returns: `N_V` BV pairs tested, `N_P` triangle pairs tested, `N_U` BVs refitted. A small
//! waving sphere moves from the centre of a large waving sphere out through its shell; every
//! step hands both hierarchies their new positions and times `collide_with` (whose lazy
//! refit happens inside) for the three methods: DH, sphere, AABB. The constants `C_V`, `C_P`,
//! `C_U` and a fixed cost per query are then fitted per method by least squares on these same
//! steps, so "model ms" is a fit, not a prediction: it shows how much of the measured time the
//! three counts explain ("worst step": the largest relative miss on one step). Fitted on
//! whole queries, each constant also absorbs the work that grows with its count but is not
//! counted (`C_U`, for instance, the refill of the leaves' cached triangles after a position
//! update), and timings vary from run to run; the paper's experiment (`cargo run --release --
//! experiment`, docs/RESULTS.md) calibrates each term apart instead, so its constants differ.
//!
//! `cargo run --release --example cost_model`

use std::time::Instant;

use dhcd::bv::{Aabb, BoundingVolume, Dh, Sphere};
use dhcd::shapes::{icosphere, wave};
use dhcd::{collide_with, Counters, Hierarchy, Mesh, Options, Par, Workspace};

const STEPS: usize = 40;
/// Each step is replayed this many times and the least time kept (the machine may be busy).
const REPS: usize = 5;

/// One timed query: its counters and its time in ms.
type Row = (Counters, f64);

/// Every step's two timed queries for method `K`: `[step, again]`.
fn measure<K: BoundingVolume>(a: &Mesh, b: &Mesh) -> dhcd::Result<Vec<[Row; 2]>> {
    // The paper's fixed 5-level tree, as in docs/RESULTS.md.
    let mut ha = Hierarchy::<K>::new(a, Options::paper())?;
    let mut hb = Hierarchy::<K>::new(b, Options::paper())?;
    // One workspace for every query: its scratch is reused, as a simulation loop would.
    let mut ws = Workspace::default();
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
                let counters = collide_with(&ha, &hb, &mut ws, Par::Seq).counters;
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

/// The regressors of one query: `N_V`, `N_P`, `N_U` and 1 (the fixed cost of a query).
fn regressors(c: &Counters) -> [f64; 4] {
    [
        c.bv_tests as f64,
        c.prim_tests as f64,
        c.bv_updates as f64,
        1.0,
    ]
}

/// `[C_V, C_P, C_U, fixed]` (ms per operation, ms per query) from the first `n` regressors
/// (3: no fixed cost; 4: with it), minimising the squared *relative* error over the rows
/// (weight 1/ms², else the largest steps alone decide): the normal equations
/// `(XᵀWX) c = XᵀWy`, with every column scaled to at most 1 first (the counts span four orders
/// of magnitude), solved by Gaussian elimination with partial pivoting. `None` if the rows do
/// not determine the constants (e.g. a count that is 0 on every row).
fn fit(rows: &[Row], n: usize) -> Option<[f64; 4]> {
    let scale: [f64; 4] = std::array::from_fn(|k| {
        rows.iter()
            .map(|(c, _)| regressors(c)[k])
            .fold(0.0, f64::max)
    });
    if scale[..n].contains(&0.0) {
        return None;
    }
    // The augmented system [XᵀWX | XᵀWy] in the scaled columns (the first n rows and columns,
    // the right-hand side in column 4).
    let mut m = [[0.0; 5]; 4];
    for (c, ms) in rows {
        let x: [f64; 4] = std::array::from_fn(|k| regressors(c)[k] / scale[k]);
        let w = 1.0 / (ms * ms);
        for i in 0..n {
            for j in 0..n {
                m[i][j] += w * x[i] * x[j];
            }
            m[i][4] += w * x[i] * ms;
        }
    }
    for col in 0..n {
        let pivot = (col..n).max_by(|&i, &j| m[i][col].abs().total_cmp(&m[j][col].abs()))?;
        m.swap(col, pivot);
        if m[col][col].abs() < 1e-12 * m[col].iter().map(|x| x.abs()).fold(0.0, f64::max) {
            return None;
        }
        let pivot_row = m[col];
        for row in &mut m[col + 1..n] {
            let f = row[col] / pivot_row[col];
            for (x, p) in row[col..].iter_mut().zip(&pivot_row[col..]) {
                *x -= f * p;
            }
        }
    }
    let mut c = [0.0; 4];
    for row in (0..n).rev() {
        let known: f64 = (row + 1..n).map(|k| m[row][k] * c[k]).sum();
        c[row] = (m[row][4] - known) / m[row][row];
    }
    Some(std::array::from_fn(|k| c[k] / scale[k]))
}

fn main() -> dhcd::Result<()> {
    let (a, b) = (icosphere(4, 1.0, [0.0; 3]), icosphere(4, 0.5, [0.0; 3]));
    let n = a.triangle_count() + b.triangle_count();
    println!("{n} triangles, {STEPS} steps (least of {REPS} replays), C fitted on the same steps");
    println!(
        "method        N_V       N_P      N_U  contacts  measured ms  model ms  \
         worst step  C_V ns  C_P ns  C_U ns  fixed us"
    );
    type Measure = fn(&Mesh, &Mesh) -> dhcd::Result<Vec<[Row; 2]>>;
    let methods: [(&str, Measure); 3] = [
        ("DH", measure::<Dh>),
        ("sphere", measure::<Sphere>),
        ("AABB", measure::<Aabb>),
    ];
    for (name, measure) in methods {
        let steps = measure(&a, &b)?;
        // A fixed cost per query if the fit finds one, else none (a negative one is noise).
        let rows = steps.concat();
        let Some(c) = fit(&rows, 4)
            .filter(|c| c[3] >= 0.0)
            .or_else(|| fit(&rows, 3))
        else {
            println!("{name:<8} the steps do not determine the constants");
            continue;
        };
        let model = |(n, _): &Row| (0..4).map(|k| regressors(n)[k] * c[k]).sum::<f64>();
        // The table is about the steps (the first query of each); the repeats only fitted C.
        let t: Counters = steps.iter().map(|s| s[0].0).sum();
        let measured: f64 = steps.iter().map(|s| s[0].1).sum();
        let modelled: f64 = steps.iter().map(|s| model(&s[0])).sum();
        let worst = steps
            .iter()
            .map(|s| 100.0 * (model(&s[0]) - s[0].1) / s[0].1)
            .fold(0.0, |w: f64, e| if e.abs() > w.abs() { e } else { w });
        let (nv, np, nu, hits) = (t.bv_tests, t.prim_tests, t.bv_updates, t.contacts);
        let [cv, cp, cu, fixed] = [c[0] * 1e6, c[1] * 1e6, c[2] * 1e6, c[3] * 1e3];
        println!(
            "{name:<8} {nv:>8} {np:>9} {nu:>8} {hits:>9} {measured:>12.2} {modelled:>9.2} \
             {worst:>10.1}% {cv:>7.1} {cp:>7.1} {cu:>7.1} {fixed:>9.1}"
        );
        if c.iter().any(|&x| x < 0.0) {
            println!("         a negative constant: these steps do not separate the counts' costs");
        }
    }
    Ok(())
}
