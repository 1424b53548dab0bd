//! CCD over whole meshes ([`dhcd::self_ccd`], [`dhcd::ccd_pair`]): every colliding
//! vertex-triangle and edge-edge pair equal to the brute force over every pair (the exact
//! tests of `dhcd::ccd`), for every method, 1 and 2 threads, both modes, minimum distances,
//! time limits 1 and 3/8;
//! and every labelled pair of the real simulation steps through the whole pipeline.

use dhcd::bv::BoundingVolume;
use dhcd::ccd::CcdOptions;
use dhcd::io::{load_as, Limits};
use dhcd::narrow::{brute_force_ccd, brute_force_self_ccd, earliest_of};
use dhcd::shapes::{grid, icosphere, jitter, splitmix64, wave};
use dhcd::{
    ccd_pair_with, for_each_method, self_ccd_with, CcdMode, CcdQuery, Error, Hierarchy, Impacts,
    Mesh, Motion, Options, Par, Precision, Workspace,
};

fn f64s(p: &[[f32; 3]]) -> Vec<[f64; 3]> {
    p.iter().map(|q| q.map(f64::from)).collect()
}

/// The pairs and times equal (the query tests each pair with the same inputs in the same
/// order as the brute force, so times agree to the bit).
fn assert_same(got: &Impacts, want: &Impacts, what: &str) {
    assert_eq!(got.vertex_face, want.vertex_face, "{what}: vertex-face");
    assert_eq!(got.face_vertex, want.face_vertex, "{what}: face-vertex");
    assert_eq!(got.edge_edge, want.edge_edge, "{what}: edge-edge");
    assert_eq!(got.toi, want.toi, "{what}: toi");
    assert_eq!(got.counters.contacts, want.counters.contacts, "{what}");
    assert!(got.counters.prim_tests >= got.counters.contacts, "{what}");
}

fn check_self<K: BoundingVolume>(
    m: &Mesh,
    x0: &[[f64; 3]],
    x1: &[[f64; 3]],
    deltas: &[f64],
    what: &str,
) {
    let h = Hierarchy::<K>::new(m, Options::default()).unwrap();
    let motion = Motion::new(x0, x1);
    // A time limit below 1 fits the walk's bounds up to it.
    for (&d, t_max) in deltas.iter().flat_map(|d| [(d, 1.0), (d, 0.375)]) {
        let options = CcdOptions::new(t_max, d).unwrap();
        let want = brute_force_self_ccd(m, motion, &options);
        for mode in [CcdMode::All, CcdMode::Earliest] {
            let want = match mode {
                CcdMode::All => want.clone(),
                CcdMode::Earliest => earliest_of(&want, want.toi),
            };
            for par in [Par::Seq, Par::Rayon(2)] {
                let q = CcdQuery { options, mode };
                let got = self_ccd_with(&h, motion, &q, &mut Workspace::default(), par).unwrap();
                let what = format!(
                    "{what} {:?} delta={d} t_max={t_max} {mode:?} {par:?}",
                    K::METHOD
                );
                assert_same(&got, &want, &what);
            }
        }
    }
}

#[allow(clippy::too_many_arguments)]
fn check_pair<K: BoundingVolume>(
    a: &Mesh,
    am: Motion<'_>,
    b: &Mesh,
    bm: Motion<'_>,
    deltas: &[f64],
    what: &str,
) {
    let (ha, hb) = (
        Hierarchy::<K>::new(a, Options::default()).unwrap(),
        Hierarchy::<K>::new(b, Options::default()).unwrap(),
    );
    // A time limit below 1 fits the walk's bounds up to it.
    for (&d, t_max) in deltas.iter().flat_map(|d| [(d, 1.0), (d, 0.375)]) {
        let options = CcdOptions::new(t_max, d).unwrap();
        let want = brute_force_ccd(a, am, b, bm, &options);
        for mode in [CcdMode::All, CcdMode::Earliest] {
            let want = match mode {
                CcdMode::All => want.clone(),
                CcdMode::Earliest => earliest_of(&want, want.toi),
            };
            for par in [Par::Seq, Par::Rayon(2)] {
                let q = CcdQuery { options, mode };
                let got =
                    ccd_pair_with(&ha, am, &hb, bm, &q, &mut Workspace::default(), par).unwrap();
                let what = format!(
                    "{what} {:?} delta={d} t_max={t_max} {mode:?} {par:?}",
                    K::METHOD
                );
                assert_same(&got, &want, &what);
            }
        }
    }
}

/// Two spheres flying through each other within the step: at t0 and t1 apart, so a
/// discrete test at either end sees nothing (tunnelling); every method finds the same pairs.
#[test]
fn spheres_tunnelling_through_each_other() {
    let a = icosphere(1, 0.5, [0.0; 3]);
    let b = icosphere(1, 0.4, [0.3, 0.05, 0.0]);
    let a0 = f64s(&jitter(a.positions(), [0.01; 3], 1));
    let a1: Vec<[f64; 3]> = a0.iter().map(|p| [p[0] + 0.1, p[1], p[2] + 0.02]).collect();
    // b starts to the right of a... and ends to its left.
    let b0: Vec<[f64; 3]> = f64s(b.positions())
        .iter()
        .map(|p| [p[0] + 1.0, p[1], p[2]])
        .collect();
    let b1: Vec<[f64; 3]> = b0.iter().map(|p| [p[0] - 2.6, p[1] + 0.1, p[2]]).collect();
    let (am, bm) = (Motion::new(&a0, &a1), Motion::new(&b0, &b1));
    let all = brute_force_ccd(&a, am, &b, bm, &CcdOptions::default());
    assert!(all.counters.contacts > 20 && all.toi.unwrap() > 0.0 && all.toi.unwrap() < 1.0);
    for_each_method!(K => check_pair::<K>(&a, am, &b, bm, &[0.0], "spheres"));
}

/// A sheet folding onto itself over the step, with jitter: self-CCD against the brute
/// force, neighbours (sharing a vertex) excluded.
#[test]
fn folding_sheet_self_ccd() {
    let g = grid(8, 8, 0.1, [0.0; 3]);
    let x0 = f64s(&jitter(g.positions(), [0.002; 3], 5));
    let x1 = crate::fixtures::folded_through(&x0, 1.0);
    let all = brute_force_self_ccd(&g, Motion::new(&x0, &x1), &CcdOptions::default());
    assert!(all.counters.contacts > 0);
    for_each_method!(K => check_self::<K>(&g, &x0, &x1, &[0.0], "folding sheet"));
}

/// Random motions of a deformed sphere (vertices moving far relative to the triangles), and
/// a still mesh (every pair already apart or touching stays so).
#[test]
fn random_motions_and_still_meshes() {
    let m = icosphere(1, 1.0, [0.0; 3]);
    let x0 = f64s(&wave(m.positions(), 0.7, 0.2, [0.0; 3]));
    let mut state = 17u64;
    let x1: Vec<[f64; 3]> = x0
        .iter()
        .map(|p| {
            p.map(|c| {
                let r = (splitmix64(&mut state) >> 11) as f64 / (1u64 << 53) as f64;
                c + (r - 0.5) * 0.9
            })
        })
        .collect();
    for_each_method!(K => check_self::<K>(&m, &x0, &x1, &[0.0], "random"));
    for_each_method!(K => check_self::<K>(&m, &x0, &x0, &[0.0], "still"));
}

/// Degenerate motions: grids sliding in their common plane (coplanar motion all step,
/// touching along edges), and two grids meeting exactly at t = 1.
#[test]
fn coplanar_sliding_and_contact_at_the_end() {
    let a = grid(3, 3, 0.25, [0.0; 3]);
    let b = grid(3, 3, 0.25, [0.0; 3]);
    let a0 = f64s(a.positions());
    let b0: Vec<[f64; 3]> = a0
        .iter()
        .map(|p| [p[0] + 1.0, p[1] + 0.125, p[2]])
        .collect();
    let b1: Vec<[f64; 3]> = a0
        .iter()
        .map(|p| [p[0] + 0.5, p[1] + 0.125, p[2]])
        .collect();
    let (am, bm) = (Motion::new(&a0, &a0), Motion::new(&b0, &b1));
    let all = brute_force_ccd(&a, am, &b, bm, &CcdOptions::default());
    assert!(all.counters.contacts > 0);
    for_each_method!(K => check_pair::<K>(&a, am, &b, bm, &[0.0], "coplanar"));
    // b descends onto a, touching at exactly t = 1.
    let b0: Vec<[f64; 3]> = a0.iter().map(|p| [p[0] + 0.1, p[1] + 0.1, 0.5]).collect();
    let b1: Vec<[f64; 3]> = a0.iter().map(|p| [p[0] + 0.1, p[1] + 0.1, 0.0]).collect();
    let bm = Motion::new(&b0, &b1);
    let all = brute_force_ccd(&a, am, &b, bm, &CcdOptions::default());
    assert_eq!(all.toi, Some(1.0));
    for_each_method!(K => check_pair::<K>(&a, am, &b, bm, &[0.0], "contact at t = 1"));
}

/// Two coincident sheets in one mesh, the second sliding over the first: every pair of
/// the two touches at t = 0 (the earliest time, hundreds of pairs tied there), with and
/// without a minimum distance, and with a time limit.
#[test]
fn sheets_resting_on_each_other_tie_at_the_start() {
    let (m, x0, x1) = crate::fixtures::resting_sheets();
    let all = brute_force_self_ccd(&m, Motion::new(&x0, &x1), &CcdOptions::default());
    assert_eq!(all.toi, Some(0.0));
    let tied = earliest_of(&all, all.toi).counters.contacts;
    assert!(tied > 100, "{tied} pairs tie at 0");
    for_each_method!(K => check_self::<K>(&m, &x0, &x1, &[0.0, 0.01], "resting sheets"));
}

/// A minimum distance `delta > 0` (pairs collide when they come within it): two spheres
/// passing each other and a folding sheet.
#[test]
fn minimum_distance_small_meshes() {
    let a = icosphere(0, 0.5, [0.0; 3]);
    let b = icosphere(0, 0.4, [0.0; 3]);
    let a0 = f64s(a.positions());
    let a1 = a0.clone();
    let b0: Vec<[f64; 3]> = f64s(b.positions())
        .iter()
        .map(|p| [p[0] + 1.2, p[1] + 0.3, p[2]])
        .collect();
    let b1: Vec<[f64; 3]> = b0.iter().map(|p| [p[0] - 0.5, p[1], p[2] + 0.1]).collect();
    let (am, bm) = (Motion::new(&a0, &a1), Motion::new(&b0, &b1));
    let near = brute_force_ccd(&a, am, &b, bm, &CcdOptions::new(1.0, 0.1).unwrap());
    let touch = brute_force_ccd(&a, am, &b, bm, &CcdOptions::default());
    assert!(near.counters.contacts > touch.counters.contacts);
    for_each_method!(K => check_pair::<K>(&a, am, &b, bm, &[0.05], "spheres near"));
    let g = grid(3, 3, 0.1, [0.0; 3]);
    let x0 = f64s(g.positions());
    let x1: Vec<[f64; 3]> = x0
        .iter()
        .map(|p| {
            if p[0] > 0.15 {
                [0.3 - p[0], p[1] + 0.01, 0.02]
            } else {
                *p
            }
        })
        .collect();
    for_each_method!(K => check_self::<K>(&g, &x0, &x1, &[0.03], "folding near"));
}

#[test]
fn bad_input_is_a_typed_error() {
    let m = icosphere(1, 1.0, [0.0; 3]);
    let h = Hierarchy::<dhcd::bv::Dh>::new(&m, Options::default()).unwrap();
    let x = f64s(m.positions());
    let mut ws = Workspace::default();
    let run = |x0: &[[f64; 3]], x1: &[[f64; 3]], q: CcdQuery, ws: &mut Workspace| {
        self_ccd_with(&h, Motion::new(x0, x1), &q, ws, Par::Seq)
    };
    assert!(matches!(
        run(&x[1..], &x, CcdQuery::all(), &mut ws),
        Err(Error::WrongVertexCount { .. })
    ));
    let mut bad = x.clone();
    bad[3][1] = f64::NAN;
    assert!(matches!(
        run(&x, &bad, CcdQuery::all(), &mut ws),
        Err(Error::NonFinite { vertex: 3, .. })
    ));
    assert!(matches!(
        run(&x, &x, CcdQuery::all().with_t_max(1.5), &mut ws),
        Err(Error::InvalidTimeLimit(_))
    ));
    assert!(matches!(
        run(
            &x,
            &x,
            CcdQuery::earliest().with_min_distance(-1.0),
            &mut ws
        ),
        Err(Error::InvalidMinDistance(_))
    ));
    // The workspace still works after the errors.
    let ok = run(&x, &x, CcdQuery::all(), &mut ws).unwrap();
    assert_eq!(ok.counters.contacts, 0);
    assert_eq!(ok.toi, None);
}

/// The real simulation steps of `../shared/data/real-frames` through the whole pipeline
/// (loader at f64, DH walk over the step, feature culling, exact test): every labelled pair
/// of `../shared/data/ccd/frame-truth` is reported iff its label is 1. The rod-twist step
/// also runs every method and 1 thread against 2.
#[test]
fn frame_truth_through_the_pipeline() {
    let Some(data) = crate::support::shared_data("ccd_query::frame_truth_through_the_pipeline", "")
    else {
        return;
    };
    for (name, next) in [
        ("rod-twist-3036", "rod-twist-3037"),
        ("armadillo-rollers-326", "armadillo-rollers-327"),
        ("n-body-simulation-18", "n-body-simulation-19"),
        ("cloth-ball-92", "cloth-ball-93"),
    ] {
        let load = |f: &str| {
            let path = data.join(format!("real-frames/{f}.ply"));
            load_as(&path, &Limits::default(), Precision::F64).unwrap()
        };
        let (m0, m1) = (load(name), load(next));
        let (x0, x1) = (m0.positions_f64().unwrap(), m1.positions_f64().unwrap());
        let motion = Motion::new(x0, x1);
        let h = Hierarchy::<dhcd::bv::Dh>::new(&m0, Options::default()).unwrap();
        let got = self_ccd_with(
            &h,
            motion,
            &CcdQuery::all(),
            &mut Workspace::default(),
            Par::Rayon(2),
        )
        .unwrap();
        let vf: std::collections::HashSet<(u32, u32)> = got
            .vertex_face
            .iter()
            .map(|x| (x.vertex, x.triangle))
            .collect();
        let ee: std::collections::HashSet<([u32; 2], [u32; 2])> =
            got.edge_edge.iter().map(|x| (x.a, x.b)).collect();
        let text =
            std::fs::read_to_string(data.join(format!("ccd/frame-truth/{name}.tsv"))).unwrap();
        let (mut labels, mut wrong) = (0usize, Vec::new());
        for line in text.lines().filter(|l| !l.trim().is_empty()) {
            let w: Vec<&str> = line.split_whitespace().collect();
            let n = |i: usize| w[i].parse::<u32>().unwrap();
            let (found, label) = match w[0] {
                "vf" => (vf.contains(&(n(1), n(2))), w[3] == "1"),
                "ee" => (ee.contains(&([n(1), n(2)], [n(3), n(4)])), w[5] == "1"),
                k => panic!("unknown label kind {k}"),
            };
            labels += 1;
            if found != label {
                wrong.push(format!("{name}: {line}: reported {found}"));
            }
        }
        println!(
            "{name}: {} vf + {} ee colliding, toi {:?}, {labels} labels checked, {:?}",
            got.vertex_face.len(),
            got.edge_edge.len(),
            got.toi,
            got.counters
        );
        assert!(
            wrong.is_empty(),
            "{} wrong:\n{}",
            wrong.len(),
            wrong[..wrong.len().min(20)].join("\n")
        );
        if name.starts_with("rod") {
            for_each_method!(K => {
                let hk = Hierarchy::<K>::new(&m0, Options::default()).unwrap();
                for (par, mode) in [(Par::Seq, CcdMode::All), (Par::Rayon(2), CcdMode::Earliest)] {
                    let q = CcdQuery { mode, ..CcdQuery::default() };
                    let other = self_ccd_with(&hk, motion, &q, &mut Workspace::default(), par).unwrap();
                    let want = if mode == CcdMode::All { got.clone() } else { earliest_of(&got, got.toi) };
                    assert_same(&other, &want, &format!("{name} {:?} {par:?} {mode:?}", K::METHOD));
                }
            });
        }
    }
}

/// Planted ties: a 16 x 16 sheet (left half `x <= 1/2` flat, in the plane `z = 0`) and a
/// vertical flap (the plane `x = 1`, `z` in `[-1/4, 1/4]`) that moves to `x = 0` over the
/// step, so it reaches the line `x = 1/2`, the sheet's edge, at exactly `t = 1/2`; and a
/// second layer over the sheet (`x` in `[1/64, 25/64]`, `z = 1/8`) falling to `z = -1/8`,
/// which meets it at exactly `t = 1/2` too (and the flap only after `t = 0.6`). Hundreds of pairs first touch at `1/2`: vertices on edges, collinear edges,
/// coplanar faces (exact path) and plain crossings (float filter). Earliest mode returns
/// exactly the pairs of all mode whose time is `<= 1/2` (the next contacts are `1/32` later),
/// for every method and thread count, self and pair queries.
///
/// `speed` multiplies every displacement (a power of two: the positions stay exact), so the
/// ties are at `1 / (2 speed)`. At 32 they are at `1/64`: the walk finds one and starts
/// again on bounds fitted up to that time, which must still reach every other tie.
fn check_planted_ties(speed: f64) {
    let sheet = grid(8, 16, 1.0 / 16.0, [0.0; 3]);
    let flap = grid(8, 16, 1.0 / 16.0, [0.0; 3]);
    let layer = grid(6, 16, 1.0 / 16.0, [0.0; 3]);
    // One mesh: the sheet, the flap (x, y, z) = (1, y, x - 1/4), the layer over the sheet.
    let mut p0: Vec<[f64; 3]> = f64s(sheet.positions());
    let mut tris: Vec<[u32; 3]> = sheet.triangles().to_vec();
    let mut add = |m: &Mesh, at: &dyn Fn([f64; 3]) -> [f64; 3], p: &mut Vec<[f64; 3]>| {
        let base = p.len() as u32;
        p.extend(f64s(m.positions()).into_iter().map(at));
        tris.extend(m.triangles().iter().map(|t| t.map(|v| v + base)));
    };
    let flap_at = |q: [f64; 3]| [1.0, q[1], q[0] - 0.25];
    let layer_at = |q: [f64; 3]| [q[0] + 1.0 / 64.0, q[1] + 1.0 / 64.0, 0.125];
    add(&flap, &flap_at, &mut p0);
    let layer_start = p0.len();
    add(&layer, &layer_at, &mut p0);
    let flap_range = sheet.vertex_count()..layer_start;
    let p1: Vec<[f64; 3]> = p0
        .iter()
        .enumerate()
        .map(|(i, q)| {
            let end = if flap_range.contains(&i) {
                [0.0, q[1], q[2]]
            } else if i >= layer_start {
                [q[0], q[1], -0.125]
            } else {
                *q
            };
            std::array::from_fn(|k| q[k] + speed * (end[k] - q[k]))
        })
        .collect();
    let m = Mesh::new_f64(p0.clone(), tris).unwrap();
    let all = brute_force_self_ccd(&m, Motion::new(&p0, &p1), &CcdOptions::default());
    let want = earliest_of(&all, all.toi);
    let tied = want.counters.contacts;
    let tie = 0.5 / speed;
    assert!(tied > 500, "{tied} pairs tie at {tie}");
    assert_eq!(
        all.toi.map(|t| tie - t <= dhcd::ccd::TOI_TOLERANCE),
        Some(true)
    );
    let later = all
        .vertex_face
        .iter()
        .map(|x| x.toi)
        .chain(all.edge_edge.iter().map(|x| x.toi));
    assert!(later
        .filter(|&t| t > tie)
        .all(|t| t >= tie + 1.0 / 32.0 / speed - 1e-12));
    for_each_method!(K => {
        let h = Hierarchy::<K>::new(&m, Options::default()).unwrap();
        for par in [Par::Seq, Par::Rayon(2)] {
            let got = self_ccd_with(
                &h,
                Motion::new(&p0, &p1),
                &CcdQuery::earliest(),
                &mut Workspace::default(),
                par,
            )
            .unwrap();
            assert_same(&got, &want, &format!("speed {speed} {:?} {par:?}", K::METHOD));
        }
    });
    // The pair form: the sheet still, the flap and the layer as the second mesh.
    let n = sheet.vertex_count();
    let a = Mesh::new_f64(p0[..n].to_vec(), sheet.triangles().to_vec()).unwrap();
    let b_tris: Vec<[u32; 3]> = m.triangles()[sheet.triangle_count()..]
        .iter()
        .map(|t| t.map(|v| v - n as u32))
        .collect();
    let b = Mesh::new_f64(p0[n..].to_vec(), b_tris).unwrap();
    let (am, bm) = (
        Motion::new(&p0[..n], &p1[..n]),
        Motion::new(&p0[n..], &p1[n..]),
    );
    check_pair::<dhcd::bv::Dh>(&a, am, &b, bm, &[0.0], "tied sheet and flap");
    check_pair::<dhcd::bv::Aabb>(&a, am, &b, bm, &[0.0], "tied sheet and flap");
}

#[test]
fn earliest_mode_returns_every_pair_tied_at_the_earliest_time() {
    check_planted_ties(1.0);
}

/// The ties early in the step: the walk restarts on bounds fitted up to them.
#[test]
fn earliest_ties_near_the_start_survive_the_walks_restart() {
    check_planted_ties(32.0);
}

/// The ties at the end of the step (`t = t_max = 1`).
#[test]
fn earliest_ties_at_the_end_of_the_step() {
    check_planted_ties(0.5);
}
