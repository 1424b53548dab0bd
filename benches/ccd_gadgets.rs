//! The worst time of one CCD query on adversarial gadgets: coordinates spanning the whole
//! `f64` exponent range (`5e-324`, `1e-300`, `1`, `3e38`, `1e300`, mixed signs, repeated
//! values that make pairs coplanar, touching or degenerate), with and without a minimum
//! distance. These are the inputs that reach the exact path with the largest integers.
//!
//! Run: `cargo bench --bench ccd_gadgets` (add `-- --quick` for fewer gadgets). It prints,
//! per family, kind and minimum distance, the number of gadgets, how many collide, and the
//! median, 99th percentile and largest time of one query; `docs/LIMITS.md` quotes the
//! largest. Not a criterion bench: the point is the worst case, not a mean.

use std::time::{Duration, Instant};

use dhcd::ccd::{self, CcdOptions};
use dhcd::shapes::splitmix64;

/// A family of coordinates: each gadget draws its 24 coordinates from `values` (with random
/// signs), so equal values (coplanar and touching configurations) are common.
struct Family {
    name: &'static str,
    values: &'static [f64],
}

const FAMILIES: [Family; 4] = [
    Family {
        name: "f32 range: 0, 5e-324, 1e-300, 1, 3e38",
        values: &[0.0, 5e-324, 1e-300, 1.0, 3e38],
    },
    Family {
        name: "f64 range: 0, 5e-324, 1e-300, 1, 1e300",
        values: &[0.0, 5e-324, 1e-300, 1.0, 1e300],
    },
    Family {
        name: "tiny: 0, 5e-324, 1e-320, 2.5e-308",
        values: &[0.0, 5e-324, 1e-320, 2.5e-308],
    },
    Family {
        name: "unit with outliers: 0, 0.5, 1, 1e-300, 3e38",
        values: &[0.0, 0.5, 1.0, 1.0, 0.5, 1e-300, 3e38],
    },
];

fn gadget(state: &mut u64, values: &[f64]) -> ([[f64; 3]; 4], [[f64; 3]; 4]) {
    let mut draw = || {
        let r = splitmix64(state);
        let v = values[(r % values.len() as u64) as usize];
        if (r >> 32) & 1 == 1 {
            -v
        } else {
            v
        }
    };
    let x0 = std::array::from_fn(|_| std::array::from_fn(|_| draw()));
    let x1 = std::array::from_fn(|_| std::array::from_fn(|_| draw()));
    (x0, x1)
}

fn main() {
    let quick = std::env::args().any(|a| a == "--quick");
    let count = if quick { 40 } else { 400 };
    println!(
        "{:<46} {:>11} {:>10} {:>7} {:>9} {:>9} {:>9}",
        "family", "kind", "delta", "hits", "median", "p99", "max"
    );
    let mut worst = Duration::ZERO;
    for family in &FAMILIES {
        for vf in [true, false] {
            for delta in [0.0, 5e-324, 1e-300] {
                let options = CcdOptions::new(1.0, delta).expect("valid options");
                let mut state = 0x9e37_79b9_7f4a_7c15 ^ family.values.len() as u64;
                let mut times = Vec::with_capacity(count);
                let mut hits = 0;
                for _ in 0..count {
                    let (x0, x1) = gadget(&mut state, family.values);
                    let start = Instant::now();
                    let r = if vf {
                        ccd::vertex_face(&x0, &x1, &options)
                    } else {
                        ccd::edge_edge(&x0, &x1, &options)
                    };
                    let took = start.elapsed();
                    if took > Duration::from_millis(50) {
                        eprintln!(
                            "slow ({took:.1?}, {} delta={delta:e}): x0={x0:?} x1={x1:?}",
                            if vf { "vf" } else { "ee" }
                        );
                    }
                    times.push(took);
                    hits += r.is_some() as usize;
                }
                times.sort_unstable();
                let at = |q: f64| times[((times.len() - 1) as f64 * q) as usize];
                worst = worst.max(at(1.0));
                println!(
                    "{:<46} {:>11} {:>10} {:>7} {:>9.1?} {:>9.1?} {:>9.1?}",
                    family.name,
                    if vf { "vertex-face" } else { "edge-edge" },
                    format!("{delta:e}"),
                    format!("{hits}/{count}"),
                    at(0.5),
                    at(0.99),
                    at(1.0)
                );
            }
        }
    }
    println!("worst single query: {worst:.1?}");
}
