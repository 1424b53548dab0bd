//! The clearance proof of self queries ([`dhcd`]'s `query::clearance`): a node whose
//! projection along its mean normal is one-to-one, with every height and boundary distance above
//! the query's reach, is skipped without enumerating its pairs. Checked against the brute
//! force where the proof holds (and then no candidate pair is enumerated at all) and where
//! it must fail: layers over each other in projection with the same orientation (a ramp
//! turning more than once), a distance at the sheet's least height, a vertex moving across
//! its neighbours, a fold, a cylinder rolled past a turn, and seeded sheets (proximity, CCD
//! and the step size) with a second sheet over them (two disks whose projections nest) or
//! beside them, half of them turned off the coordinate axes.

use dhcd::bv::BoundingVolume;
use dhcd::ccd::CcdOptions;
use dhcd::contact::StepOptions;
use dhcd::narrow::{brute_force_self_ccd, brute_force_self_proximity, earliest_of};
use dhcd::shapes::{grid, jitter, splitmix64, wave};
use dhcd::{
    for_each_method, self_ccd_with, self_proximity_with, CcdMode, CcdQuery, Hierarchy, Impacts,
    Mesh, Motion, Options, Par, Proximity, Workspace,
};

fn f64s(p: &[[f32; 3]]) -> Vec<[f64; 3]> {
    p.iter().map(|q| q.map(f64::from)).collect()
}

fn with_positions(m: &Mesh, p: Vec<[f32; 3]>) -> Mesh {
    Mesh::new(p, m.triangles().to_vec()).unwrap()
}

/// The leaf sizes checked: the default, small leaves (a deeper tree: more nodes tested),
/// and leaves of one triangle.
const LEAF_SIZES: [usize; 3] = [64, 8, 1];

fn assert_proximity_same(got: &Proximity, want: &Proximity, what: &str) {
    assert_eq!(got.vertex_face, want.vertex_face, "{what}: vertex-face");
    assert_eq!(got.edge_edge, want.edge_edge, "{what}: edge-edge");
}

fn assert_impacts_same(got: &Impacts, want: &Impacts, what: &str) {
    assert_eq!(got.vertex_face, want.vertex_face, "{what}: vertex-face");
    assert_eq!(got.edge_edge, want.edge_edge, "{what}: edge-edge");
    assert_eq!(got.toi, want.toi, "{what}: toi");
}

/// Self proximity at `d` equals the brute force for every method, leaf size and thread
/// count; the least number of candidate pairs any of them enumerated.
fn proximity_checked(m: &Mesh, d: f64, what: &str) -> u64 {
    let want = brute_force_self_proximity(m, d);
    let mut least = u64::MAX;
    for leaf_size in LEAF_SIZES {
        for_each_method!(K => {
            let options = Options { leaf_size, ..Options::default() };
            let h = Hierarchy::<K>::new(m, options).unwrap();
            for par in [Par::Seq, Par::Rayon(2)] {
                let got = self_proximity_with(&h, d, &mut Workspace::default(), par).unwrap();
                let what = format!("{what} d={d} {:?} leaves {leaf_size} {par:?}", K::METHOD);
                assert_proximity_same(&got, &want, &what);
                least = least.min(got.counters.prim_tests);
            }
        });
    }
    least
}

/// Self CCD from `x0` to `x1` at minimum distance `delta`, both modes, equals the brute
/// force for every method, leaf size and thread count; the least number of candidate pairs
/// any of them enumerated.
fn ccd_checked(m: &Mesh, x0: &[[f64; 3]], x1: &[[f64; 3]], delta: f64, what: &str) -> u64 {
    let motion = Motion::new(x0, x1);
    let options = CcdOptions::new(1.0, delta).unwrap();
    let all = brute_force_self_ccd(m, motion, &options);
    let mut least = u64::MAX;
    for leaf_size in LEAF_SIZES {
        for_each_method!(K => {
            let built = Options { leaf_size, ..Options::default() };
            let h = Hierarchy::<K>::new(m, built).unwrap();
            for mode in [CcdMode::All, CcdMode::Earliest] {
                let want = match mode {
                    CcdMode::All => all.clone(),
                    CcdMode::Earliest => earliest_of(&all, all.toi),
                };
                for par in [Par::Seq, Par::Rayon(2)] {
                    let q = CcdQuery { options, mode };
                    let got =
                        self_ccd_with(&h, motion, &q, &mut Workspace::default(), par).unwrap();
                    let what = format!("{what} delta={delta} {:?} leaves {leaf_size} {mode:?} {par:?}", K::METHOD);
                    assert_impacts_same(&got, &want, &what);
                    least = least.min(got.counters.prim_tests);
                }
            }
        });
    }
    least
}

/// An `n` x `n` sheet of cell 1 / n, bent by a gentle wave (normals within 45 degrees of
/// the z axis).
fn wavy_sheet(n: u32) -> Mesh {
    let flat = grid(n, n, 1.0 / n as f32, [0.0; 3]);
    let p = wave(flat.positions(), 0.3, 0.05, [0.0; 3]);
    with_positions(&flat, p)
}

#[test]
fn a_smooth_sheet_is_proven_clear_and_enumerates_nothing() {
    let m = wavy_sheet(16);
    // The least height of the sheet's triangles is about 0.7 / 16 = 0.044.
    let least = proximity_checked(&m, 0.01, "wavy sheet");
    assert_eq!(least, 0, "the sheet is proven clear at 0.01");
    // A small step of the same sheet.
    let x0 = f64s(m.positions());
    let x1: Vec<[f64; 3]> = x0
        .iter()
        .map(|p| [p[0] + 0.002, p[1] - 0.001, p[2] + 0.003 * p[0]])
        .collect();
    assert_eq!(ccd_checked(&m, &x0, &x1, 0.0, "wavy step"), 0);
    assert_eq!(ccd_checked(&m, &x0, &x1, 0.005, "wavy step"), 0);
    // At a distance above the least height the proof fails and the walk finds the pairs.
    assert!(proximity_checked(&m, 0.05, "wavy sheet") > 0);
    // The step size of a smaller sheet's small step: every pair keeps its gap.
    let m = wavy_sheet(8);
    let x0 = f64s(m.positions());
    let x1: Vec<[f64; 3]> = x0
        .iter()
        .map(|p| [p[0] + 0.002, p[1], p[2] + 0.004 * p[1]])
        .collect();
    for o in [
        StepOptions::default(),
        StepOptions {
            min_distance: 0.005,
            rescaling: 0.8,
        },
    ] {
        assert_eq!(crate::step_size::brute_force_step(&m, &x0, &x1, &o), 1.0);
        for_each_method!(K => crate::step_size::check::<K>(&m, &x0, &x1, &o, 1.0));
    }
}

#[test]
fn a_flat_sheet_at_its_least_height() {
    // Cell 1 / 8: the heights over the diagonals are sqrt(2) / 16 = 0.0884, the least
    // distance between features sharing no vertex.
    let m = grid(8, 8, 0.125, [0.0; 3]);
    let h = 2f64.sqrt() / 16.0;
    assert_eq!(proximity_checked(&m, h * 0.999, "flat below"), 0);
    assert!(brute_force_self_proximity(&m, h * 1.001).counters.contacts > 0);
    proximity_checked(&m, h * 1.001, "flat above");
}

#[test]
fn a_vertex_moving_across_its_neighbours_is_found() {
    let m = grid(8, 8, 0.125, [0.0; 3]);
    let x0 = f64s(m.positions());
    // An inner vertex slides in the plane over two cells, across its ring.
    let mut x1 = x0.clone();
    x1[4 * 9 + 4][0] += 0.25;
    x1[4 * 9 + 4][1] += 0.1;
    let want = brute_force_self_ccd(&m, Motion::new(&x0, &x1), &CcdOptions::default());
    assert!(want.counters.contacts > 0);
    ccd_checked(&m, &x0, &x1, 0.0, "sliding vertex");
    ccd_checked(&m, &x0, &x1, 0.01, "sliding vertex");
}

/// A strip of `turns` turns of a ramp around the z axis, rising `rise` a turn, `k` cells
/// around and 2 across: every triangle faces up, and the turns lie over each other.
fn ramp(turns: f32, rise: f32, k: u32) -> Mesh {
    let mut p = Vec::new();
    for i in 0..=k {
        let a = turns * std::f32::consts::TAU * i as f32 / k as f32;
        let z = rise * a / std::f32::consts::TAU;
        for r in [1.0f32, 1.25, 1.5] {
            p.push([r * a.cos(), r * a.sin(), z]);
        }
    }
    let mut t = Vec::new();
    for i in 0..k {
        for j in 0..2 {
            let (a, b) = (3 * i + j, 3 * (i + 1) + j);
            t.push([a, a + 1, b + 1]);
            t.push([a, b + 1, b]);
        }
    }
    Mesh::new(p, t).unwrap()
}

#[test]
fn turns_of_a_ramp_over_each_other_are_never_clear() {
    // Every triangle's projection on the plane z = 0 has the same orientation, but the
    // second turn covers the first: the boundary loop is not simple there.
    let m = ramp(1.5, 0.02, 96);
    let least = proximity_checked(&m, 0.021, "ramp");
    assert!(least > 0);
    assert!(brute_force_self_proximity(&m, 0.021).counters.contacts > 0);
    // The upper turn pressed down through the lower one.
    let x0 = f64s(m.positions());
    let x1: Vec<[f64; 3]> = x0.iter().map(|p| [p[0], p[1], p[2] * 0.25]).collect();
    ccd_checked(&m, &x0, &x1, 0.0, "ramp pressed");
}

#[test]
fn a_fold_is_walked() {
    let flat = grid(12, 12, 1.0 / 12.0, [0.0; 3]);
    let x0 = f64s(flat.positions());
    // Folded along x = 0.5 with the upper half 0.02 above the lower.
    let folded: Vec<[f32; 3]> = flat
        .positions()
        .iter()
        .map(|p| {
            if p[0] > 0.5 {
                [1.0 - p[0], p[1], 0.02 + 0.04 * (p[0] - 0.5)]
            } else {
                *p
            }
        })
        .collect();
    let m = with_positions(&flat, folded);
    assert!(proximity_checked(&m, 0.03, "fold") > 0);
    let x1 = f64s(m.positions());
    ccd_checked(&flat, &x0, &x1, 0.0, "folding");
}

/// `a` and `b` as one mesh (`b`'s vertices numbered after `a`'s).
fn stacked(a: &Mesh, b_positions: &[[f32; 3]], b: &Mesh) -> Mesh {
    let n = a.positions().len() as u32;
    let mut p = a.positions().to_vec();
    p.extend_from_slice(b_positions);
    let mut t = a.triangles().to_vec();
    t.extend(b.triangles().iter().map(|f| f.map(|v| v + n)));
    Mesh::new(p, t).unwrap()
}

#[test]
fn seeded_sheets_with_a_sheet_over_or_beside_them_equal_the_brute_force() {
    let mut proven = 0;
    for seed in 0..12u64 {
        let mut state = seed;
        let mut draw = || (splitmix64(&mut state) >> 11) as f64 / (1u64 << 53) as f64;
        let n = 6 + (seed % 3) as u32;
        let cell = 1.0 / n as f32;
        let base = grid(n, n, cell, [0.0; 3]);
        let bent = wave(base.positions(), draw() as f32, 0.3 * cell, [0.0; 3]);
        let bent = jitter(&bent, [0.2 * cell, 0.2 * cell, 0.1 * cell], seed);
        // A smaller sheet over the middle (its projection inside the base's) or beside it.
        let small = grid(3, 3, cell, [0.0; 3]);
        let over = seed % 2 == 0;
        let lift = (0.05 + 0.5 * draw()) as f32 * cell;
        let at = if over {
            [0.3, 0.3, lift]
        } else {
            [1.2, 0.2, lift]
        };
        let top: Vec<[f32; 3]> = small
            .positions()
            .iter()
            .map(|p| [p[0] + at[0], p[1] + at[1], p[2] + at[2]])
            .collect();
        let mut m = stacked(&with_positions(&base, bent), &top, &small);
        // Half the seeds turned as a whole: projected along a direction off the axes.
        let turn = seed >= 6;
        if turn {
            let angles = [draw(), draw(), draw()].map(|x| x * std::f64::consts::TAU);
            m = with_positions(&m, f32s(&turned(m.positions(), angles, [0.0; 3])));
        }
        let what = format!("seed {seed} over {over} turned {turn}");
        for d in [0.02, 0.3, 0.6, 1.2].map(|f| f * cell as f64) {
            if proximity_checked(&m, d, &what) == 0 {
                proven += 1;
            }
        }
        // The upper sheet comes down by twice its lift (through the base when over it),
        // the base drifts and bends a little.
        let x0 = f64s(m.positions());
        let drift = [0.1 * draw(), 0.1 * draw(), 0.05 * draw()].map(|x| x * cell as f64);
        let x1: Vec<[f64; 3]> = x0
            .iter()
            .enumerate()
            .map(|(v, p)| {
                let wobble = 0.02 * cell as f64 * (7.0 * p[0] + 3.0 * p[1]).sin();
                if v >= base.positions().len() {
                    [p[0], p[1], p[2] - 2.0 * lift as f64]
                } else {
                    [p[0] + drift[0], p[1] + drift[1], p[2] + drift[2] + wobble]
                }
            })
            .collect();
        for delta in [0.0, 0.1 * cell as f64] {
            ccd_checked(&m, &x0, &x1, delta, &what);
        }
        if seed < 4 {
            for min_distance in [0.0, 0.05 * cell as f64] {
                let o = StepOptions {
                    min_distance,
                    rescaling: 0.8,
                };
                let want = crate::step_size::brute_force_step(&m, &x0, &x1, &o);
                for_each_method!(K => crate::step_size::check::<K>(&m, &x0, &x1, &o, want));
            }
        }
    }
    // The proof held somewhere (a sheet beside the base, at a small distance).
    assert!(proven > 0);
}

/// `p` turned by the rotation of Euler angles `[a, b, c]` (about z, then y, then z), and
/// moved by `shift`.
fn turned(p: &[[f32; 3]], [a, b, c]: [f64; 3], shift: [f64; 3]) -> Vec<[f64; 3]> {
    let about_z = |t: f64, q: [f64; 3]| {
        let (s, k) = t.sin_cos();
        [k * q[0] - s * q[1], s * q[0] + k * q[1], q[2]]
    };
    let about_y = |t: f64, q: [f64; 3]| {
        let (s, k) = t.sin_cos();
        [k * q[0] + s * q[2], q[1], -s * q[0] + k * q[2]]
    };
    p.iter()
        .map(|q| {
            let r = about_z(c, about_y(b, about_z(a, q.map(f64::from))));
            [r[0] + shift[0], r[1] + shift[1], r[2] + shift[2]]
        })
        .collect()
}

fn f32s(p: &[[f64; 3]]) -> Vec<[f32; 3]> {
    p.iter().map(|q| q.map(|x| x as f32)).collect()
}

/// A generic rotation: no coordinate axis near the z axis it turns.
const TURN: [f64; 3] = [0.7, 1.1, 0.3];

#[test]
fn a_turned_flat_sheet_at_its_least_height() {
    // The flat sheet of the test above, turned: no coordinate plane holds it, and the
    // proof projects it along its normal with roundings.
    let flat = grid(8, 8, 0.125, [0.0; 3]);
    let m = with_positions(&flat, f32s(&turned(flat.positions(), TURN, [0.3; 3])));
    let h = 2f64.sqrt() / 16.0;
    assert_eq!(proximity_checked(&m, h * 0.999, "turned flat below"), 0);
    assert!(brute_force_self_proximity(&m, h * 1.001).counters.contacts > 0);
    proximity_checked(&m, h * 1.001, "turned flat above");
}

/// An `n` x `n` sheet of side 1 rolled `degrees` around the y axis, its radius shrinking
/// from 1 by `shrink` over the roll (a spiral), then turned by [`TURN`].
fn rolled_sheet(n: u32, degrees: f64, shrink: f64) -> Mesh {
    let flat = grid(n, n, 1.0 / n as f32, [0.0; 3]);
    let spread = degrees.to_radians();
    let rolled: Vec<[f32; 3]> = flat
        .positions()
        .iter()
        .map(|p| {
            let a = spread * (f64::from(p[0]) - 0.5);
            let r = 1.0 - shrink * a / spread;
            [(r * a.sin()) as f32, p[1], (r * a.cos()) as f32]
        })
        .collect();
    with_positions(&flat, f32s(&turned(&rolled, TURN, [0.0; 3])))
}

/// A quarter-and-more of a cylinder of radius 1 (150 degrees around, `n` cells, and 1 long,
/// `n` cells), turned by [`TURN`]: its normals spread 75 degrees either side of their
/// mean, so no coordinate axis sees every triangle face one way, while the mean does.
fn turned_cylinder(n: u32) -> Mesh {
    rolled_sheet(n, 150.0, 0.0)
}

#[test]
fn a_turned_cylinder_is_proven_clear_along_its_mean_normal() {
    let m = turned_cylinder(12);
    // Cells 0.22 around by 0.083 long; at the rims the projection shortens them to a
    // quarter: the least projected height is about 0.05.
    assert_eq!(proximity_checked(&m, 0.005, "cylinder"), 0);
    assert!(proximity_checked(&m, 0.1, "cylinder") > 0);
    // A step turning it by 0.005 radians about its axis and moving it by 0.05: the
    // displacements differ by at most about 0.01.
    let x0 = f64s(m.positions());
    let x1 = turned(m.positions(), [0.0, 0.0, 0.005], [0.05, -0.02, 0.03]);
    assert_eq!(ccd_checked(&m, &x0, &x1, 0.0, "cylinder step"), 0);
    assert_eq!(ccd_checked(&m, &x0, &x1, 0.005, "cylinder step"), 0);
    let o = StepOptions {
        min_distance: 0.005,
        rescaling: 0.8,
    };
    assert_eq!(crate::step_size::brute_force_step(&m, &x0, &x1, &o), 1.0);
    for_each_method!(K => crate::step_size::check::<K>(&m, &x0, &x1, &o, 1.0));
    // The same step 10^4 away from the origin (in f64): each projected point now rounds by
    // about 10^-12, still far below the heights, so the proof holds and stays exact.
    let far = |x: &[[f64; 3]]| -> Vec<[f64; 3]> {
        x.iter()
            .map(|p| [p[0] + 1.0e4, p[1] - 2.0e4, p[2] + 0.5e4])
            .collect()
    };
    assert_eq!(
        ccd_checked(&m, &far(&x0), &far(&x1), 0.0, "cylinder step far away"),
        0
    );
    // Rolled up into a spiral past a turn, its rims come within 0.02 of each other.
    let rolled_mesh = rolled_sheet(12, 375.0, 0.02);
    assert!(
        brute_force_self_proximity(&rolled_mesh, 0.1)
            .counters
            .contacts
            > 0
    );
    proximity_checked(&rolled_mesh, 0.1, "rolled");
    // Rolling up, at a distance below the least projected height: the proof would pass at
    // the start, but the motion moves the rims by about 1.
    let x1 = f64s(rolled_mesh.positions());
    let options = CcdOptions::new(1.0, 0.03).unwrap();
    let want = brute_force_self_ccd(&m, Motion::new(&x0, &x1), &options);
    assert!(want.counters.contacts > 0);
    ccd_checked(&m, &x0, &x1, 0.03, "rolling up");
}
