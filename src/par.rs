//! Parallelism as a parameter: [`Par::Seq`], [`Par::Rayon`] with a thread count, or
//! [`Par::Ambient`]. Results never depend on it: parallel work is split into fixed chunks
//! whose outputs are concatenated in chunk order.
//!
//! Thread counts are bounded here, in one place (`docs/LIMITS.md`):
//!
//! - A count a user gives (command line, C ABI, Python, experiment) enters through
//!   [`Par::threads`], which rejects counts above [`Par::MAX_THREADS`] with
//!   [`Error::InvalidThreads`].
//! - The count actually used never exceeds [`Par::max_threads`], the machine's available
//!   parallelism: [`Par::Rayon`]`(n)` with a larger `n` runs on `max_threads()` threads.
//! - Pools are cached, at most [`Par::MAX_POOLS`] of them (least recently used evicted), so
//!   a host that asks for many different counts holds at most `MAX_POOLS * max_threads()`
//!   threads.

use std::sync::{Arc, Mutex, OnceLock};

use crate::error::{Error, Result};

/// How a query or refit runs.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
#[non_exhaustive]
pub enum Par {
    /// On the calling thread.
    #[default]
    Seq,
    /// On a pool of `n` threads, at most [`Par::max_threads`]; `n <= 1` is [`Par::Seq`].
    Rayon(usize),
    /// On rayon's ambient pool: the pool the caller already runs in, else rayon's global
    /// pool (all cores unless the host configured it).
    Ambient,
}

impl Par {
    /// The largest thread count [`Par::threads`] accepts; larger counts are typos or
    /// garbage (`UINT32_MAX` from C), not machines. Counts up to it are clamped to
    /// [`Par::max_threads`].
    pub const MAX_THREADS: usize = 1024;

    /// The most thread pools kept alive at once.
    #[doc(hidden)]
    pub const MAX_POOLS: usize = 4;

    /// The machine's available parallelism (at least 1): no [`Par`] runs on more threads.
    pub fn max_threads() -> usize {
        static MAX: OnceLock<usize> = OnceLock::new();
        *MAX.get_or_init(|| std::thread::available_parallelism().map_or(1, |n| n.get()))
    }

    /// The parallelism for a thread count a user gave (command line, C, Python): `0` all
    /// cores ([`Par::Ambient`]), `1` the calling thread, `n` a pool of
    /// `min(n, max_threads())` threads. Counts above [`Par::MAX_THREADS`] are an
    /// [`Error::InvalidThreads`].
    pub fn threads(n: usize) -> Result<Par> {
        match n {
            0 => Ok(Par::Ambient),
            1 => Ok(Par::Seq),
            n if n <= Par::MAX_THREADS => Ok(Par::Rayon(n)),
            got => Err(Error::InvalidThreads {
                got,
                max: Par::MAX_THREADS,
                cores: Par::max_threads(),
            }),
        }
    }

    /// What actually runs: `Rayon(n)` clamped to [`Par::max_threads`], and [`Par::Seq`]
    /// when that leaves one thread.
    #[doc(hidden)]
    pub fn effective(self) -> Par {
        match self {
            Par::Seq | Par::Ambient => self,
            Par::Rayon(n) => match n.min(Par::max_threads()) {
                0 | 1 => Par::Seq,
                n => Par::Rayon(n),
            },
        }
    }

    /// The number of threads the work runs on.
    pub fn thread_count(self) -> usize {
        match self.effective() {
            Par::Seq => 1,
            Par::Ambient => rayon::current_num_threads(),
            Par::Rayon(n) => n,
        }
    }

    /// Whether the work runs on more than the calling thread (as far as this `Par` decides:
    /// [`Par::Ambient`] counts as parallel).
    #[doc(hidden)]
    pub fn is_parallel(self) -> bool {
        self.effective() != Par::Seq
    }

    /// Runs `f` inside the pool this `Par` names (see the module docs for the cache), or
    /// directly for `Seq` and `Ambient`.
    #[doc(hidden)]
    pub fn install<R: Send>(self, f: impl FnOnce() -> R + Send) -> R {
        match self.effective() {
            Par::Seq | Par::Ambient => f(),
            // A pool that cannot be built (no threads to be had) runs the work here: the
            // result is the same, only slower.
            Par::Rayon(n) => match pool(n) {
                Some(p) => p.install(f),
                None => f(),
            },
        }
    }
}

/// Pools built so far, by thread count, least recently used first.
#[derive(Default)]
struct PoolCache {
    pools: Vec<(usize, Arc<rayon::ThreadPool>)>,
}

impl PoolCache {
    /// The pool of `threads` threads, built if needed; evicts the least recently used pool
    /// beyond [`Par::MAX_POOLS`]. An evicted pool's threads end once the work already running on
    /// it (which holds its own `Arc`) is done.
    fn get(&mut self, threads: usize) -> Option<Arc<rayon::ThreadPool>> {
        if let Some(i) = self.pools.iter().position(|(n, _)| *n == threads) {
            let hit = self.pools.remove(i);
            self.pools.push(hit);
        } else {
            let p = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .thread_name(move |i| format!("dhcd-{threads}-{i}"))
                .build()
                .ok()?;
            if self.pools.len() == Par::MAX_POOLS {
                self.pools.remove(0);
            }
            self.pools.push((threads, Arc::new(p)));
        }
        self.pools.last().map(|(_, p)| Arc::clone(p))
    }
}

fn pool(threads: usize) -> Option<Arc<rayon::ThreadPool>> {
    static POOLS: OnceLock<Mutex<PoolCache>> = OnceLock::new();
    POOLS
        .get_or_init(Default::default)
        .lock()
        .unwrap_or_else(|e| e.into_inner())
        .get(threads)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_cache_keeps_at_most_max_pools_most_recent_first() {
        let mut cache = PoolCache::default();
        for n in [1, 2, 3, 1, 4, 5, 6] {
            let p = cache.get(n).unwrap();
            assert_eq!(p.current_num_threads(), n);
            assert!(cache.pools.len() <= Par::MAX_POOLS);
        }
        // 1 was used again after 2 and 3, so 2 and 3 went first.
        let kept: Vec<usize> = cache.pools.iter().map(|(n, _)| *n).collect();
        assert_eq!(kept, [1, 4, 5, 6]);
        let again = cache.get(5).unwrap();
        assert!(
            Arc::ptr_eq(&again, &cache.pools[3].1),
            "a hit reuses the pool"
        );
    }
}
