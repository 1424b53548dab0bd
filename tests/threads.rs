//! Thread counts: checked in one place (`Par::threads`), never more threads than the machine
//! has, and a bounded number of pools whatever counts a host asks for (issue 9, items 1-2).

use dhcd::bv::Dh;
use dhcd::shapes::icosphere;
use dhcd::{Error, Hierarchy, Options, Par, Workspace};

#[test]
fn out_of_range_thread_counts_are_typed_one_line_errors() {
    for got in [Par::MAX_THREADS + 1, 16_384, u32::MAX as usize, usize::MAX] {
        let err = Par::threads(got).unwrap_err();
        assert_eq!(
            err,
            Error::InvalidThreads {
                got,
                max: Par::MAX_THREADS,
                cores: Par::max_threads()
            }
        );
        let text = err.to_string();
        assert!(
            text.contains(&got.to_string()) && !text.contains('\n'),
            "{text}"
        );
    }
    assert_eq!(Par::threads(0).unwrap(), Par::Ambient);
    // A pool of no threads is the calling thread, not a magic value.
    assert_eq!(Par::Rayon(0).effective(), Par::Seq);
    assert_eq!(Par::Rayon(1).effective(), Par::Seq);
    assert_eq!(Par::threads(1).unwrap(), Par::Seq);
    assert_eq!(
        Par::threads(Par::MAX_THREADS).unwrap(),
        Par::Rayon(Par::MAX_THREADS)
    );
}

#[test]
fn the_count_used_never_exceeds_the_machines_parallelism() {
    for n in [2, 3, 64, Par::MAX_THREADS, 65_535, usize::MAX] {
        let par = Par::Rayon(n);
        assert!(par.thread_count() <= Par::max_threads(), "{n}");
        let inside = par.install(rayon::current_num_threads);
        assert!(
            inside <= Par::max_threads(),
            "{n}: ran on a pool of {inside} threads"
        );
        assert_eq!(par.is_parallel(), Par::max_threads() > 1);
    }
    assert_eq!(Par::Seq.thread_count(), 1);
    assert_eq!(Par::Rayon(1).effective(), Par::Seq);
}

/// A huge count on a tiny query: before, rayon started tens of thousands of workers (or hung);
/// now it runs on at most the machine's threads, with the sequential answer.
#[test]
fn a_huge_thread_count_runs_a_tiny_query_with_the_sequential_answer() {
    let a = icosphere(1, 1.0, [0.0; 3]);
    let b = icosphere(1, 1.0, [0.5, 0.0, 0.0]);
    let query = |par| {
        let ha = Hierarchy::<Dh>::new(&a, Options::default()).unwrap();
        let hb = Hierarchy::<Dh>::new(&b, Options::default()).unwrap();
        dhcd::collide_with(&ha, &hb, &mut Workspace::default(), par)
    };
    let seq = query(Par::Seq);
    assert!(!seq.pairs.is_empty());
    for n in [u32::MAX as usize, usize::MAX] {
        assert_eq!(query(Par::Rayon(n)), seq, "{n}");
    }
}

/// Threads of this process whose name starts with `dhcd-` (the pools' threads).
#[cfg(target_os = "linux")]
fn pool_threads() -> usize {
    std::fs::read_dir("/proc/self/task")
        .unwrap()
        .filter_map(|t| std::fs::read_to_string(t.ok()?.path().join("comm")).ok())
        .filter(|name| name.starts_with("dhcd-"))
        .count()
}

/// A C host that calls with every count from 2 to 128 used to end up with one pool per count
/// (8,256 threads); now the cache keeps at most `MAX_POOLS` pools of at most `max_threads()`.
#[cfg(target_os = "linux")]
#[test]
fn pools_stay_bounded_whatever_counts_a_host_asks_for() {
    for n in 2..=128 {
        assert!(Par::Rayon(n).install(rayon::current_num_threads) <= Par::max_threads());
    }
    let bound = Par::MAX_POOLS * Par::max_threads();
    // Evicted pools end their threads asynchronously: wait for them, generously.
    let deadline = std::time::Instant::now() + std::time::Duration::from_secs(60);
    loop {
        let live = pool_threads();
        if live <= bound {
            break;
        }
        assert!(
            std::time::Instant::now() < deadline,
            "{live} pool threads alive; the bound is {bound}"
        );
        std::thread::sleep(std::time::Duration::from_millis(20));
    }
}
