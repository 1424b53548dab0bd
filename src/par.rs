//! Parallelism as a parameter: [`Par::Seq`] or [`Par::Rayon`] with a thread count.
//! Results never depend on it: parallel work is split into fixed chunks whose outputs are
//! concatenated in chunk order.

use std::sync::{Arc, Mutex, OnceLock};

/// How a query or refit runs.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
#[non_exhaustive]
pub enum Par {
    /// On the calling thread.
    #[default]
    Seq,
    /// On a rayon pool of this many threads (`0`: rayon's global pool).
    Rayon(usize),
}

impl Par {
    pub fn is_parallel(self) -> bool {
        !matches!(self, Par::Seq | Par::Rayon(1))
    }

    /// Runs `f` inside the pool this `Par` names (pools are built once per thread count and
    /// cached), or directly for `Seq`.
    pub fn install<R: Send>(self, f: impl FnOnce() -> R + Send) -> R {
        match self {
            Par::Seq | Par::Rayon(0) => f(),
            // A pool that cannot be built (no threads to be had) runs the work here: the
            // result is the same, only slower.
            Par::Rayon(n) => match pool(n) {
                Some(p) => p.install(f),
                None => f(),
            },
        }
    }
}

/// Pools built so far, by thread count.
type PoolCache = Mutex<Vec<(usize, Arc<rayon::ThreadPool>)>>;

fn pool(threads: usize) -> Option<Arc<rayon::ThreadPool>> {
    static POOLS: OnceLock<PoolCache> = OnceLock::new();
    let mut pools = POOLS
        .get_or_init(Default::default)
        .lock()
        .unwrap_or_else(|e| e.into_inner());
    if let Some((_, p)) = pools.iter().find(|(n, _)| *n == threads) {
        return Some(Arc::clone(p));
    }
    let p = Arc::new(
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .thread_name(move |i| format!("dhcd-{threads}-{i}"))
            .build()
            .ok()?,
    );
    pools.push((threads, Arc::clone(&p)));
    Some(p)
}
