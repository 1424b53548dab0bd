//! What a barrier solver calls each Newton iteration and line search: the contact set
//! (`self_contact_set`) and the collision-free step size (`collision_free_stepsize`), `f64`,
//! one thread, DH (the methods are within a few percent of each other on these queries), at
//! IPC's default contact distance `dhat` = 1e-3 x the bounding-box diagonal. Beside each, the
//! raw self-proximity at the same `dhat` (what the contact set types), the earliest impact
//! (the first of the step size's two walks), and the gradients and Hessians of every
//! contact's squared distance (sets of at most 50,000 contacts).
//!
//! Cases:
//! - the real frame steps of `../shared/data/real-frames/` (N -> N+1), when the folder is
//!   there (else one line says they are skipped);
//! - procedural 40 x 40 sheets (3,200 triangles), always: a wavy sheet moving a small step,
//!   the same sheet folded over itself with its layers closing in, and a flat sheet sliding
//!   in its own plane (coplanar all step: decided by the planar filter of `src/ccd`);
//! - the degenerate motions of `../shared/data/degenerate/` on a 16 x 16 sheet, always:
//!   `fold-16`, `collapse-16`, `line-16` (thousands of pairs tied at the earliest impact
//!   and at the step size).
//!
//! Ids: `contact/<query>/<case>`, `<query>` one of `contact_set`, `proximity`, `gradients`,
//! `hessians`, `step_size`, `earliest`. The setup checks what it times (the step size is in
//! `[0, 1]` and never past the earliest impact) and prints each case's contact count.
//!
//! `cargo bench --bench contact` (all); `cargo bench --bench contact -- 'contact/.*/sheet'`.

mod frames;

use std::hint::black_box;
use std::path::{Path, PathBuf};

use criterion::{criterion_group, criterion_main, Criterion};
use dhcd::bv::Dh;
use dhcd::contact::{self, StepOptions};
use dhcd::shapes::{fold_x, grid, jitter, wave};
use dhcd::{CcdQuery, Hierarchy, Mesh, Motion, Options, Par, Workspace};
use frames::{diagonal, frame_pairs, load_f64, RELATIVE_DHAT};

fn f64s(p: &[[f32; 3]]) -> Vec<[f64; 3]> {
    p.iter().map(|q| q.map(f64::from)).collect()
}

/// One case: the rest mesh, the step's two poses, and whether its step size is timed.
struct Case {
    name: String,
    rest: Mesh,
    x0: Vec<[f64; 3]>,
    x1: Vec<[f64; 3]>,
    step_size: bool,
}

fn sheets() -> Vec<Case> {
    let rest = grid(40, 40, 1.0 / 40.0, [0.0; 3]);
    let wavy = |t: f32| f64s(&wave(rest.positions(), t, 0.02, [0.0; 3]));
    // Folded at x = 0.5 with the upper layer lifted by `h`: the layers close in over the step.
    let folded = |h: f32| {
        let p: Vec<[f32; 3]> = fold_x(rest.positions(), 0.5)
            .iter()
            .zip(rest.positions())
            .map(|(f, r)| {
                if r[0] > 0.5 {
                    [f[0], f[1], f[2] + h]
                } else {
                    *f
                }
            })
            .collect();
        f64s(&jitter(&p, [0.0005; 3], 3))
    };
    let flat = f64s(rest.positions());
    let slid: Vec<[f64; 3]> = flat
        .iter()
        .map(|p| [p[0] + 0.01, p[1] + 0.005, p[2]])
        .collect();
    let mesh =
        |x: &[[f64; 3]]| Mesh::new_f64(x.to_vec(), rest.triangles().to_vec()).expect("a sheet");
    let mut cases = vec![
        Case {
            name: "wavy-sheet".into(),
            rest: mesh(&wavy(0.0)),
            x0: wavy(0.0),
            x1: wavy(0.05),
            step_size: true,
        },
        Case {
            name: "folded-sheet".into(),
            rest: mesh(&folded(0.03)),
            x0: folded(0.03),
            x1: folded(0.0),
            step_size: true,
        },
        Case {
            name: "flat-sheet-sliding".into(),
            rest: mesh(&flat),
            x0: flat.clone(),
            x1: slid,
            step_size: true,
        },
    ];
    cases.extend(degenerate_sheets());
    cases
}

/// The degenerate motions of `../shared/data/degenerate/sheets.py` on a 16 x 16 sheet of the
/// unit square (512 triangles): the right half folding flat onto the left (`x -> 1 - x`),
/// the right half collapsing onto the line `x = 0.5`, the whole sheet collapsing onto the x
/// axis. Every feature stays in the plane z = 0 (the planar filter), and thousands of pairs
/// tie at the earliest impact and at the step size (the minimum-distance filter at each
/// pair's gap).
fn degenerate_sheets() -> Vec<Case> {
    let n = 16;
    let rest = grid(n, n, 1.0 / n as f32, [0.0; 3]);
    let x0 = f64s(rest.positions());
    let moved = |motion: fn([f64; 3]) -> [f64; 3]| x0.iter().map(|&p| motion(p)).collect();
    let motions: [(&str, Vec<[f64; 3]>); 3] = [
        (
            "fold",
            moved(|p| {
                if p[0] > 0.5 {
                    [1.0 - p[0], p[1], p[2]]
                } else {
                    p
                }
            }),
        ),
        (
            "collapse",
            moved(|p| if p[0] > 0.5 { [0.5, p[1], p[2]] } else { p }),
        ),
        ("line", moved(|p| [p[0], 0.0, p[2]])),
    ];
    motions
        .into_iter()
        .map(|(name, x1)| Case {
            name: format!("{name}-16"),
            rest: Mesh::new_f64(x0.clone(), rest.triangles().to_vec()).expect("a sheet"),
            x0: x0.clone(),
            x1,
            step_size: true,
        })
        .collect()
}

fn real_frames() -> Vec<Case> {
    let dir: PathBuf = Path::new(env!("CARGO_MANIFEST_DIR")).join("../shared/data/real-frames");
    if !dir.is_dir() {
        eprintln!(
            "contact bench: real frames SKIPPED: no data folder at {}",
            dir.display()
        );
        return Vec::new();
    }
    frame_pairs(&dir)
        .into_iter()
        .map(|(first, second)| {
            let (m0, m1) = (load_f64(&dir, &first), load_f64(&dir, &second));
            Case {
                x0: m0.positions_f64().expect("f64").to_vec(),
                x1: m1.positions_f64().expect("f64").to_vec(),
                rest: m0,
                name: first,
                step_size: true,
            }
        })
        .collect()
}

fn contact(c: &mut Criterion) {
    for case in sheets().into_iter().chain(real_frames()) {
        let dhat = RELATIVE_DHAT * diagonal(&case.x0);
        let mut h = Hierarchy::<Dh>::new(&case.rest, Options::default()).expect("hierarchy");
        h.update_positions_f64(&case.x0).expect("a pose");
        let mut ws = Workspace::default();
        let set = contact::self_contact_set_with(&h, dhat, None, &mut ws, Par::Seq).expect("set");
        eprintln!("{}: {} contacts at dhat {dhat:.3e}", case.name, set.len());
        let name = &case.name;
        c.bench_function(&format!("contact/contact_set/{name}"), |b| {
            b.iter(|| {
                let s =
                    contact::self_contact_set_with(&h, dhat, None, &mut ws, Par::Seq).expect("set");
                black_box(s.len())
            })
        });
        c.bench_function(&format!("contact/proximity/{name}"), |b| {
            b.iter(|| {
                let p = dhcd::self_proximity_with(&h, dhat, &mut ws, Par::Seq).expect("rows");
                black_box(p.counters.contacts)
            })
        });
        // The derivatives of every contact (a Hessian is 1,152 bytes: only sets that fit
        // a few tens of MB).
        if !set.is_empty() && set.len() <= 50_000 {
            c.bench_function(&format!("contact/gradients/{name}"), |b| {
                b.iter(|| black_box(set.gradients().len()))
            });
            c.bench_function(&format!("contact/hessians/{name}"), |b| {
                b.iter(|| black_box(set.hessians().len()))
            });
        }
        if !case.step_size {
            continue;
        }
        let motion = Motion::new(&case.x0, &case.x1);
        let o = StepOptions::default();
        let step = contact::collision_free_stepsize_with(&h, motion, &o, &mut ws, Par::Seq)
            .expect("a step");
        let toi = dhcd::self_ccd_with(&h, motion, &CcdQuery::earliest(), &mut ws, Par::Seq)
            .expect("a step")
            .toi;
        assert!((0.0..=1.0).contains(&step.step));
        assert!(toi.is_none_or(|t| step.step <= t + dhcd::ccd::TOI_TOLERANCE));
        eprintln!("{name}: step {} (earliest impact {toi:?})", step.step);
        c.bench_function(&format!("contact/step_size/{name}"), |b| {
            b.iter(|| {
                let s = contact::collision_free_stepsize_with(&h, motion, &o, &mut ws, Par::Seq)
                    .expect("a step");
                black_box(s.step)
            })
        });
        c.bench_function(&format!("contact/earliest/{name}"), |b| {
            b.iter(|| {
                let i = dhcd::self_ccd_with(&h, motion, &CcdQuery::earliest(), &mut ws, Par::Seq)
                    .expect("a step");
                black_box(i.toi)
            })
        });
    }
}

criterion_group! {
    name = benches;
    config = Criterion::default().sample_size(10);
    targets = contact
}
criterion_main!(benches);
