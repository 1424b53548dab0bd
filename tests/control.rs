//! Bounded output and cancellation ([`dhcd::Control`]): a query over its limit of result
//! pairs, or whose result buffer the allocator refuses, or cancelled by a flag or a poll
//! function, returns a typed error (never a partial answer, never an abort), for proximity
//! and CCD, pair, self and scene queries, 1 and 2 threads; under the limit nothing changes.

use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::Arc;

use dhcd::scene::Scene;
use dhcd::shapes::grid;
use dhcd::{
    bv::Dh, self_ccd_with, self_proximity_with, CcdQuery, Control, Error, Hierarchy, Method,
    Motion, Options, Par, Workspace, DEFAULT_MAX_PAIRS,
};

fn sheet(n: u32) -> Hierarchy<Dh> {
    Hierarchy::<Dh>::new(&grid(n, n, 1.0 / n as f32, [0.0; 3]), Options::default()).unwrap()
}

/// The sheet's positions (caller's order) as `f64`.
fn sheet_f64(n: u32) -> Vec<[f64; 3]> {
    let m = grid(n, n, 1.0 / n as f32, [0.0; 3]);
    m.positions().iter().map(|p| p.map(f64::from)).collect()
}

/// A distance that covers the whole sheet: every vertex-face and edge-edge pair is a result.
const COVERING: f64 = 2.0;

#[test]
fn the_default_limit_is_documented_and_a_distance_covering_the_mesh_stops_at_it() {
    assert_eq!(DEFAULT_MAX_PAIRS, 1 << 25);
    assert_eq!(Workspace::default().control.max_pairs, DEFAULT_MAX_PAIRS);
    let h = sheet(16);
    for par in [Par::Seq, Par::Rayon(2)] {
        let mut ws = Workspace::default();
        ws.control = Control::default().with_max_pairs(10_000);
        let e = self_proximity_with(&h, COVERING, &mut ws, par).unwrap_err();
        let Error::OutputLimit { reached, limit } = e else {
            panic!("{e:?}")
        };
        assert_eq!(limit, 10_000);
        assert!(reached > limit, "{reached}");
        assert!(e.to_string().contains("10000"), "{e}");
        // Under the limit, the same query answers, and the workspace still works.
        ws.control.max_pairs = u64::MAX;
        let all = self_proximity_with(&h, COVERING, &mut ws, par).unwrap();
        assert!(all.counters.contacts > 10_000);
        ws.control.max_pairs = all.counters.contacts;
        let exact = self_proximity_with(&h, COVERING, &mut ws, par).unwrap();
        assert_eq!(exact, all, "a limit equal to the count is not exceeded");
    }
}

#[test]
fn ccd_and_scene_queries_stop_at_the_limit() {
    let h = sheet(12);
    let x0 = sheet_f64(12);
    // Every vertex falls through the sheet's plane: a min distance covering the sheet makes
    // every pair collide.
    let x1: Vec<[f64; 3]> = x0.iter().map(|p| [p[0], p[1], p[2] - 0.1]).collect();
    let query = CcdQuery::all().with_min_distance(COVERING);
    for par in [Par::Seq, Par::Rayon(2)] {
        let mut ws = Workspace::default();
        ws.control.max_pairs = 500;
        let e = self_ccd_with(&h, Motion::new(&x0, &x1), &query, &mut ws, par).unwrap_err();
        assert!(matches!(e, Error::OutputLimit { limit: 500, .. }), "{e:?}");
    }
    let m = grid(12, 12, 1.0 / 12.0, [0.0; 3]);
    for method in Method::ALL {
        let mut scene = Scene::new(method, Options::default());
        let a = scene.add(&m).unwrap();
        scene.add(&m).unwrap();
        scene.set_self_collision(a, true).unwrap();
        scene.set_control(Control::default().with_max_pairs(700));
        let e = scene.proximity(COVERING, Par::Rayon(2)).unwrap_err();
        assert!(matches!(e, Error::OutputLimit { limit: 700, .. }), "{e:?}");
        let e = scene
            .ccd(&[(a, Motion::new(&x0, &x1))], &query, Par::Seq)
            .unwrap_err();
        assert!(matches!(e, Error::OutputLimit { limit: 700, .. }), "{e:?}");
        // The scene still answers under a large enough limit.
        scene.set_control(Control::default());
        assert!(scene.proximity(0.01, Par::Seq).is_ok());
    }
}

/// A result buffer the allocator refuses is an error, not an abort.
#[test]
fn a_refused_result_buffer_is_out_of_memory() {
    let h = sheet(16);
    let mut ws = Workspace::default();
    ws.control.max_pairs = u64::MAX;
    let r = crate::support::refusing_above(1 << 20, || {
        self_proximity_with(&h, COVERING, &mut ws, Par::Seq)
    });
    let e = r.unwrap_err();
    assert!(
        matches!(e, Error::OutOfMemory { bytes } if bytes > 1 << 20),
        "{e:?}"
    );
    assert!(e.to_string().contains("out of memory"), "{e}");
    // Afterwards, with memory, the query answers.
    assert!(self_proximity_with(&h, 0.01, &mut ws, Par::Seq).is_ok());
}

#[test]
fn a_cancel_flag_stops_the_query() {
    let h = sheet(24);
    let flag = Arc::new(AtomicBool::new(true));
    for par in [Par::Seq, Par::Rayon(2)] {
        let mut ws = Workspace::default();
        ws.control = Control::default().with_cancel(flag.clone());
        let e = self_proximity_with(&h, COVERING, &mut ws, par).unwrap_err();
        assert_eq!(e, Error::Cancelled);
        let x0 = sheet_f64(24);
        let e =
            self_ccd_with(&h, Motion::new(&x0, &x0), &CcdQuery::all(), &mut ws, par).unwrap_err();
        assert_eq!(e, Error::Cancelled);
    }
    // Set from another thread while the query runs.
    let late = Arc::new(AtomicBool::new(false));
    let mut ws = Workspace::default();
    ws.control = Control::default()
        .with_cancel(late.clone())
        .with_max_pairs(u64::MAX);
    let setter = {
        let late = late.clone();
        std::thread::spawn(move || {
            std::thread::sleep(std::time::Duration::from_millis(20));
            late.store(true, Ordering::Relaxed);
        })
    };
    let started = std::time::Instant::now();
    let r = self_proximity_with(&sheet(48), COVERING, &mut ws, Par::Seq);
    setter.join().unwrap();
    // The full query takes many seconds; cancelled, it returns soon after the flag.
    assert_eq!(r.unwrap_err(), Error::Cancelled);
    assert!(started.elapsed().as_secs_f64() < 5.0);
}

#[test]
fn a_poll_function_stops_the_query_and_is_called_while_it_runs() {
    let calls = Arc::new(AtomicUsize::new(0));
    let polled = calls.clone();
    let mut ws = Workspace::default();
    ws.control = Control::default()
        .with_max_pairs(u64::MAX)
        .with_poll(move || polled.fetch_add(1, Ordering::Relaxed) >= 3);
    let h = sheet(48);
    let e = self_proximity_with(&h, COVERING, &mut ws, Par::Seq).unwrap_err();
    assert_eq!(e, Error::Cancelled);
    assert_eq!(calls.load(Ordering::Relaxed), 4);
    // A poll function that never stops changes nothing.
    let mut ws = Workspace::default();
    ws.control = Control::default().with_poll(|| false);
    let with = self_proximity_with(&h, 0.02, &mut ws, Par::Rayon(2)).unwrap();
    let without = self_proximity_with(&h, 0.02, &mut Workspace::default(), Par::Seq).unwrap();
    assert_eq!(with, without);
}
