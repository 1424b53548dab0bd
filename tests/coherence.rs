//! Frame-to-frame coherence (`Workspace::set_front_tracking`): a query started from the last
//! query's front finds exactly what a walk from the root finds, on deforming sequences, for
//! every kind, self and two-object queries, one and two threads; a front is only replayed on
//! the trees it was recorded on.

use dhcd::bv::BvKind;
use dhcd::narrow::{brute_force_pairs, brute_force_self_pairs};
use dhcd::scene::{ObjectId, Scene, SceneContacts};
use dhcd::shapes::{grid, icosphere, translated, wave};
use dhcd::{
    broad_phase, collide_with, for_each_kind, narrow_phase, self_broad_phase, self_collide_with,
    Contacts, Hierarchy, Mesh, Method, Options, Par, Workspace,
};

fn tracking() -> Workspace {
    let mut ws = Workspace::default();
    ws.set_front_tracking(true);
    ws
}

fn with_positions(mesh: &Mesh, positions: &[[f32; 3]]) -> Mesh {
    Mesh::new(positions.to_vec(), mesh.triangles().to_vec()).unwrap()
}

/// Small leaves, so the trees have several levels and the front lies inside them.
fn options() -> Options {
    Options {
        leaf_size: 4,
        ..Options::default()
    }
}

/// A `2n x n` grid folded over itself at x = 1 and waved by `t`: contacts come and go.
fn folded_pose(flat: &Mesh, t: f32) -> Vec<[f32; 3]> {
    let folded: Vec<[f32; 3]> = flat
        .positions()
        .iter()
        .map(|&[x, y, z]| {
            if x > 1.0 {
                [
                    2.0 - x,
                    y,
                    0.05 + 0.12 * (7.0 * y + 3.0 * (x - 1.0) + t).sin(),
                ]
            } else {
                [x, y, z]
            }
        })
        .collect();
    wave(&folded, t, 0.05, [0.0; 3])
}

/// Self queries over `poses`: from the front (one and two threads) and from the root give
/// the same contacts (brute force on every pose), the two fronts the same counters.
fn self_sequence<K: BvKind>(rest: &Mesh, poses: &[Vec<[f32; 3]>]) -> (u64, u64) {
    let build = || Hierarchy::<K>::new(rest, options()).unwrap();
    let (mut seq, mut par, mut root) = (build(), build(), build());
    let (mut ws_seq, mut ws_par) = (tracking(), tracking());
    let (mut tests_front, mut tests_root) = (0, 0);
    for (step, pose) in poses.iter().enumerate() {
        for h in [&mut seq, &mut par, &mut root] {
            h.update_positions(pose).unwrap();
        }
        let front = self_collide_with(&mut seq, &mut ws_seq, Par::Seq);
        let front_par = self_collide_with(&mut par, &mut ws_par, Par::Rayon(2));
        let fresh = self_collide_with(&mut root, &mut Workspace::default(), Par::Seq);
        let label = format!("{:?} step {step}", K::METHOD);
        assert_eq!(
            front.pairs,
            brute_force_self_pairs(&with_positions(rest, pose)),
            "{label}"
        );
        assert_eq!(front.pairs, fresh.pairs, "{label}");
        assert_eq!(front_par, front, "{label}: two threads");
        // The same front (or none: dropped when it outgrew the last fresh one) either way.
        assert_eq!(ws_par.front_len(), ws_seq.front_len(), "{label}");
        seq.validate().unwrap();
        tests_front += front.counters.bv_tests;
        tests_root += fresh.counters.bv_tests;
    }
    (tests_front, tests_root)
}

#[test]
fn self_queries_from_the_front_find_what_a_walk_from_the_root_finds() {
    let flat = grid(24, 12, 1.0 / 12.0, [0.0; 3]);
    let folded: Vec<_> = (0..10)
        .map(|s| folded_pose(&flat, 0.4 * s as f32))
        .collect();
    let sphere = icosphere(3, 1.0, [0.0; 3]);
    let crumpled: Vec<_> = (0..8)
        .map(|s| wave(sphere.positions(), 0.5 * s as f32, 0.6, [0.0; 3]))
        .collect();
    for_each_kind!(K => {
        let (front, root) = self_sequence::<K>(&flat, &folded);
        // The replays did work a walk from the root repeats above the front.
        assert!(front < root, "{:?}: {front} BV tests from the front, {root} from the root", K::METHOD);
        self_sequence::<K>(&sphere, &crumpled);
    });
}

/// Two spheres passing through each other and apart again, queried from the front (one and
/// two threads) and from the root, against brute force.
fn pair_sequence<K: BvKind>() {
    let a = icosphere(2, 1.0, [0.0; 3]);
    let b = icosphere(3, 0.8, [0.0; 3]);
    let build = |m: &Mesh| Hierarchy::<K>::new(m, options()).unwrap();
    let (mut a_seq, mut b_seq) = (build(&a), build(&b));
    let (mut a_par, mut b_par) = (build(&a), build(&b));
    let (mut ws_seq, mut ws_par) = (tracking(), tracking());
    let (mut contacts_seen, mut replays) = (0, 0);
    for step in 0..14 {
        replays += usize::from(ws_seq.front_len() > 0);
        let x = -3.0 + 0.45 * step as f32;
        let pa = wave(a.positions(), 0.3 * step as f32, 0.1, [0.0; 3]);
        let pb = translated(b.positions(), [x, 0.2, 0.1]);
        for (ha, hb) in [(&mut a_seq, &mut b_seq), (&mut a_par, &mut b_par)] {
            ha.update_positions(&pa).unwrap();
            hb.update_positions(&pb).unwrap();
        }
        let front = collide_with(&mut a_seq, &mut b_seq, &mut ws_seq, Par::Seq);
        let front_par = collide_with(&mut a_par, &mut b_par, &mut ws_par, Par::Rayon(2));
        let expected = brute_force_pairs(&with_positions(&a, &pa), &with_positions(&b, &pb));
        let label = format!("{:?} step {step}", K::METHOD);
        assert_eq!(front.pairs, expected, "{label}");
        assert_eq!(front_par, front, "{label}: two threads");
        let mut fresh_a = build(&a);
        let mut fresh_b = build(&b);
        fresh_a.update_positions(&pa).unwrap();
        fresh_b.update_positions(&pb).unwrap();
        let fresh = collide_with(
            &mut fresh_a,
            &mut fresh_b,
            &mut Workspace::default(),
            Par::Seq,
        );
        assert_eq!(front.pairs, fresh.pairs, "{label}");
        assert_eq!(ws_par.front_len(), ws_seq.front_len(), "{label}");
        contacts_seen += usize::from(!expected.is_empty());
    }
    assert!(
        contacts_seen >= 3,
        "the spheres met on {contacts_seen} steps"
    );
    assert!(
        replays >= 5,
        "{:?}: {replays} queries started from a front",
        K::METHOD
    );
}

#[test]
fn pair_queries_from_the_front_find_what_a_walk_from_the_root_finds() {
    for_each_kind!(K => pair_sequence::<K>());
}

/// One workspace for queries on different trees, in turn: each query finds what a fresh
/// walk finds (a front recorded on other trees, or for the other query kind, is not used).
fn other_trees<K: BvKind>() {
    let a = icosphere(2, 1.0, [0.0; 3]);
    let b = icosphere(2, 1.0, [0.9, 0.0, 0.0]);
    let c = icosphere(3, 1.0, [0.0, 0.7, 0.0]);
    let h = |m: &Mesh| Hierarchy::<K>::new(m, options()).unwrap();
    let (mut ha, mut hb, mut hc) = (h(&a), h(&b), h(&c));
    let fresh = |x: &mut Hierarchy<K>, y: &mut Hierarchy<K>| -> Contacts {
        collide_with(x, y, &mut Workspace::default(), Par::Seq)
    };
    let mut ws = tracking();
    for round in 0..2 {
        let label = format!("{:?} round {round}", K::METHOD);
        let ab = collide_with(&mut ha, &mut hb, &mut ws, Par::Seq);
        assert_eq!(ab.pairs, fresh(&mut ha, &mut hb).pairs, "{label}: a-b");
        assert!(!ab.pairs.is_empty());
        let ac = collide_with(&mut ha, &mut hc, &mut ws, Par::Seq);
        assert_eq!(ac.pairs, fresh(&mut ha, &mut hc).pairs, "{label}: a-c");
        let ba = collide_with(&mut hb, &mut ha, &mut ws, Par::Seq);
        assert_eq!(ba.pairs, fresh(&mut hb, &mut ha).pairs, "{label}: b-a");
        let aa = self_collide_with(&mut ha, &mut ws, Par::Seq);
        assert_eq!(aa.pairs, brute_force_self_pairs(&a), "{label}: a self");
        // The same trees twice in a row: the second query replays the first one's front.
        let again = collide_with(&mut ha, &mut hc, &mut ws, Par::Seq);
        let again2 = collide_with(&mut ha, &mut hc, &mut ws, Par::Seq);
        assert_eq!(again.pairs, again2.pairs, "{label}");
        assert!(
            again2.counters.bv_tests <= again.counters.bv_tests,
            "{label}"
        );
    }
}

#[test]
fn a_front_is_only_replayed_on_its_own_trees() {
    for_each_kind!(K => other_trees::<K>());
}

/// The broad phase records and replays the front too, and a front it left serves a full
/// query (and the other way round). With boxes (a parent's box encloses its children's) the
/// leaf pairs are exactly a fresh walk's, in the same order, for one and two threads. With
/// spheres and DH a parent's volume need not enclose its children's, so which leaf pairs
/// are met depends on the path: a front and the root may each meet pairs the other does not,
/// but only pairs without contacts (two intersecting triangles make every pair of volumes
/// holding them overlap), so the narrow phase on either finds the same contacts.
fn broad_and_full<K: BvKind>() {
    let flat = grid(24, 12, 1.0 / 12.0, [0.0; 3]);
    let mut h = Hierarchy::<K>::new(&flat, options()).unwrap();
    let mut root = Hierarchy::<K>::new(&flat, options()).unwrap();
    let mut ws = tracking();
    let mut pose = Vec::new();
    for step in 0..6 {
        pose = folded_pose(&flat, 0.5 * step as f32);
        h.update_positions(&pose).unwrap();
        root.update_positions(&pose).unwrap();
        let mut fresh_ws = Workspace::default();
        let fresh = self_broad_phase(&mut root, &mut fresh_ws, Par::Seq);
        let par = if step % 2 == 0 {
            Par::Seq
        } else {
            Par::Rayon(2)
        };
        let counted = self_broad_phase(&mut h, &mut ws, par);
        let label = format!("{:?} step {step}", K::METHOD);
        check_leaf_pairs::<K>(&ws, &fresh_ws, counted.prim_tests, fresh.prim_tests);
        let expected = brute_force_self_pairs(&with_positions(&flat, &pose));
        let narrow = narrow_phase(&h, &h, ws.leaf_pairs(), Par::Seq).unwrap();
        let mut found: Vec<[u32; 2]> = narrow
            .pairs
            .iter()
            .filter(|p| p[0] != p[1] && !shares_vertex(&flat, p[0], p[1]))
            .map(|&[x, y]| [x.min(y), x.max(y)])
            .collect();
        found.sort_unstable();
        found.dedup();
        assert_eq!(
            found, expected,
            "{label}: the narrow phase on the broad phase's leaf pairs"
        );
        let full = self_collide_with(&mut h, &mut ws, par);
        assert_eq!(full.pairs, expected, "{label}");
    }
    // Two objects through the broad phase: the same leaf pairs as a fresh walk.
    let other = icosphere(2, 0.5, [0.5, 0.5, 0.0]);
    let mut ho = Hierarchy::<K>::new(&other, options()).unwrap();
    for _ in 0..2 {
        let counted = broad_phase(&mut h, &mut ho, &mut ws, Par::Seq);
        let mut fresh_ws = Workspace::default();
        let fresh = broad_phase(&mut h, &mut ho, &mut fresh_ws, Par::Seq);
        check_leaf_pairs::<K>(&ws, &fresh_ws, counted.prim_tests, fresh.prim_tests);
        let narrow = narrow_phase(&h, &ho, ws.leaf_pairs(), Par::Seq).unwrap();
        let posed = with_positions(&flat, &pose);
        assert_eq!(narrow.pairs, brute_force_pairs(&posed, &other));
    }
}

/// Leaf pairs from a front against a fresh walk's (see [`broad_and_full`]).
fn check_leaf_pairs<K: BvKind>(
    front: &Workspace,
    fresh: &Workspace,
    front_prim_tests: u64,
    fresh_prim_tests: u64,
) {
    let sorted = |ws: &Workspace| {
        let mut v = ws.leaf_pairs().to_vec();
        v.sort_unstable();
        v
    };
    let (got, want) = (sorted(front), sorted(fresh));
    // With spheres and DH each walk may meet leaf pairs the other's path does not (only
    // pairs without contacts: the narrow phase on each finds the same contacts).
    if K::METHOD == Method::Aabb {
        assert_eq!(got, want);
        assert_eq!(front_prim_tests, fresh_prim_tests);
    }
}

fn shares_vertex(m: &Mesh, x: u32, y: u32) -> bool {
    let (tx, ty) = (m.triangles()[x as usize], m.triangles()[y as usize]);
    tx.iter().any(|v| ty.contains(v))
}

#[test]
fn the_broad_phase_replays_a_front_and_leaves_the_same_leaf_pairs() {
    for_each_kind!(K => broad_and_full::<K>());
}

#[test]
fn turning_tracking_off_drops_the_front() {
    let m = icosphere(3, 1.0, [0.0; 3]);
    let mut h = Hierarchy::<dhcd::bv::Aabb>::new(&m, options()).unwrap();
    let mut ws = Workspace::default();
    assert!(!ws.front_tracking());
    self_collide_with(&mut h, &mut ws, Par::Seq);
    assert_eq!(ws.front_len(), 0, "no front without tracking");
    ws.set_front_tracking(true);
    let first = self_collide_with(&mut h, &mut ws, Par::Seq);
    assert!(ws.front_tracking() && ws.front_len() > 0);
    ws.set_front_tracking(false);
    assert_eq!(ws.front_len(), 0);
    let off = self_collide_with(&mut h, &mut ws, Par::Seq);
    assert_eq!(off.pairs, first.pairs);
    assert_eq!(off.counters.bv_tests, first.counters.bv_tests);
}

/// A scene tracking fronts (one and two threads) finds what a scene without them finds,
/// step after step, while pairs enter and leave the broad phase and an object is removed;
/// its later steps start from the fronts; turning tracking off gives a walk from the roots.
#[test]
fn a_scene_tracking_fronts_finds_what_an_untracked_scene_finds() {
    let ball = icosphere(2, 1.0, [0.0; 3]);
    let small = icosphere(3, 0.8, [0.0; 3]);
    for method in Method::ALL {
        let new_scene = || {
            let mut s = Scene::new(method, options());
            let ids = [&ball, &small, &ball].map(|m| s.add(m).unwrap());
            s.set_self_collision(ids[0], true).unwrap();
            (s, ids)
        };
        let (mut seq, ids) = new_scene();
        let (mut par, _) = new_scene();
        let (mut root, _) = new_scene();
        assert!(!seq.front_tracking());
        seq.set_front_tracking(true);
        par.set_front_tracking(true);
        let (mut replays, mut third_met, mut small_jobs) = (0, false, Vec::<bool>::new());
        for step in 0..14 {
            let t = 0.3 * step as f32;
            // The ball folds onto itself, the small one swings through it, out, back in and
            // out again; the third comes from far away, touches, and is removed at step 8.
            let poses = [
                wave(ball.positions(), t, 0.6, [0.0; 3]),
                translated(
                    small.positions(),
                    [3.2 * (0.45 * step as f32).cos(), 0.2, 0.1],
                ),
                translated(ball.positions(), [12.0 - 1.6 * step as f32, 0.0, 0.0]),
            ];
            for s in [&mut seq, &mut par, &mut root] {
                if step == 8 {
                    s.remove(ids[2]).unwrap();
                }
                for (id, p) in ids.iter().zip(&poses) {
                    if s.contains(*id) {
                        s.update_positions(*id, p).unwrap();
                    }
                }
            }
            let tracked = seq.contacts(Par::Seq);
            let fresh = root.contacts(Par::Seq);
            let label = format!("{method:?} step {step}");
            assert_eq!(tracked.pairs, fresh.pairs, "{label}");
            let jobs =
                |c: &SceneContacts| c.per_pair.iter().map(|p| (p.a, p.b)).collect::<Vec<_>>();
            assert_eq!(jobs(&tracked), jobs(&fresh), "{label}");
            assert_eq!(par.contacts(Par::Rayon(2)), tracked, "{label}: two threads");
            replays += usize::from(tracked.counters.bv_tests != fresh.counters.bv_tests);
            let in_job = |id: ObjectId| tracked.per_pair.iter().any(|p| p.a != p.b && p.b == id);
            third_met |= step < 8 && in_job(ids[2]);
            small_jobs.push(in_job(ids[1]));
        }
        assert!(
            replays >= 5,
            "{method:?}: {replays} steps started from fronts"
        );
        assert!(third_met, "{method:?}: the removed object had a job");
        // The small ball's pair with the big one leaves the broad phase and comes back.
        let changes = small_jobs.windows(2).filter(|w| w[0] != w[1]).count();
        assert!(
            changes >= 3,
            "{method:?}: the pair entered and left {changes} times"
        );
        seq.set_front_tracking(false);
        assert!(!seq.front_tracking());
        assert_eq!(
            seq.contacts(Par::Seq),
            root.contacts(Par::Seq),
            "{method:?}: off"
        );
    }
}

/// Objects that move apart: the deep front of their contact is replayed once, found idle
/// (nothing overlaps) and dropped; from then on each query is the roots' one test, from the
/// root or from the one-entry front it records; when they meet again the contacts are back.
fn apart_again<K: BvKind>() {
    let a = icosphere(2, 1.0, [0.0; 3]);
    let b = icosphere(2, 1.0, [0.0; 3]);
    let (mut ha, mut hb) = (
        Hierarchy::<K>::new(&a, options()).unwrap(),
        Hierarchy::<K>::new(&b, options()).unwrap(),
    );
    let mut ws = tracking();
    let label = format!("{:?}", K::METHOD);
    let mut at = |x: f32, ws: &mut Workspace| {
        hb.update_positions(&translated(b.positions(), [x, 0.1, 0.0]))
            .unwrap();
        collide_with(&mut ha, &mut hb, ws, Par::Seq)
    };
    let touching = at(1.2, &mut ws);
    assert!(!touching.pairs.is_empty(), "{label}");
    assert!(ws.front_len() > 1, "{label}");
    let idle = at(10.0, &mut ws);
    assert!(
        idle.pairs.is_empty() && idle.counters.bv_tests > 1,
        "{label}"
    );
    assert_eq!(ws.front_len(), 0, "{label}: an idle replay drops its front");
    for step in 0..3 {
        let apart = at(10.0 + step as f32, &mut ws);
        assert!(apart.pairs.is_empty(), "{label}");
        assert_eq!(apart.counters.bv_tests, 1, "{label}: the roots' test");
        assert_eq!(ws.front_len(), 1, "{label}: the roots' entry is kept");
    }
    let again = at(1.2, &mut ws);
    assert_eq!(again.pairs, touching.pairs, "{label}");
}

#[test]
fn objects_apart_cost_one_test_after_one_idle_replay() {
    for_each_kind!(K => apart_again::<K>());
}
