//! What bounds and stops a query from outside: the most result pairs it may return, and
//! cancellation (a flag another thread sets, or a function the query calls now and then).
//!
//! A [`Control`] is part of a [`crate::Workspace`] (and of a [`crate::Scene`]); the queries
//! whose output grows with the input (proximity, CCD) read it:
//! - more than [`Control::max_pairs`] result pairs stop the query with
//!   [`Error::OutputLimit`], which names the count reached and the limit;
//! - a result buffer that cannot grow (the allocator refuses) stops it with
//!   [`Error::OutOfMemory`] instead of aborting the process;
//! - [`Control::cancel`] set, or [`Control::poll`] returning `true`, stops it with
//!   [`Error::Cancelled`].
//!
//! A stopped query returns only the error: no partial result is ever returned as if it were
//! the answer, and the hierarchies are unchanged (a query never changes a hierarchy's pose).

use std::fmt;
use std::sync::atomic::{AtomicBool, AtomicU64, AtomicU8, Ordering};
use std::sync::Arc;

use crate::error::{Error, Result};

/// Default most result pairs of one query: 2^25 (about 33.5 million, 0.8-1.1 GB of rows at
/// 24-32 bytes each), which a machine with a few GB of memory survives. A query that covers
/// most of a mesh's feature pairs (a distance larger than the mesh) reaches it long before
/// memory runs out.
pub const DEFAULT_MAX_PAIRS: u64 = 1 << 25;

/// How often a walk task calls [`Control::poll`]: once every this many leaf pairs.
pub(crate) const POLL_EVERY: u32 = 64;

/// Limits and cancellation of a query: the most result pairs, and a flag or poll function that
/// stops it (see [`Error::OutputLimit`], [`Error::OutOfMemory`], [`Error::Cancelled`]).
#[derive(Clone)]
pub struct Control {
    /// The most result pairs the query may return ([`DEFAULT_MAX_PAIRS`]; `u64::MAX`: no
    /// limit). More is [`Error::OutputLimit`].
    pub max_pairs: u64,
    /// Set by any thread to stop the query ([`Error::Cancelled`]); read between feature
    /// pairs, so the query returns within about one feature pair's time.
    pub cancel: Option<Arc<AtomicBool>>,
    /// Called by the threads doing the work, once every 64 leaf pairs each: `true` stops the
    /// query ([`Error::Cancelled`]). Keep it cheap (read a clock first); the Python module
    /// uses it to let Ctrl-C through.
    pub poll: Option<Arc<dyn Fn() -> bool + Send + Sync>>,
}

impl Default for Control {
    fn default() -> Self {
        Self {
            max_pairs: DEFAULT_MAX_PAIRS,
            cancel: None,
            poll: None,
        }
    }
}

impl fmt::Debug for Control {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("Control")
            .field("max_pairs", &self.max_pairs)
            .field("cancel", &self.cancel)
            .field("poll", &self.poll.as_ref().map(|_| "Fn() -> bool"))
            .finish()
    }
}

impl Control {
    /// The default control with a different limit on result pairs (`u64::MAX`: none).
    pub fn with_max_pairs(mut self, max_pairs: u64) -> Self {
        self.max_pairs = max_pairs;
        self
    }

    /// The default control stopped by `flag`.
    pub fn with_cancel(mut self, flag: Arc<AtomicBool>) -> Self {
        self.cancel = Some(flag);
        self
    }

    /// The default control stopped when `poll` returns `true`.
    pub fn with_poll(mut self, poll: impl Fn() -> bool + Send + Sync + 'static) -> Self {
        self.poll = Some(Arc::new(poll));
        self
    }
}

/// Why a query stopped early.
const RUNNING: u8 = 0;
const CANCELLED: u8 = 1;
const OVER_LIMIT: u8 = 2;
const NO_MEMORY: u8 = 3;

/// One query's account against its [`Control`], shared by its walk tasks (and by the jobs of
/// a scene query): result pairs so far and why the query stopped, if it did.
pub(crate) struct Budget<'c> {
    control: &'c Control,
    pairs: AtomicU64,
    stop: AtomicU8,
    /// The bytes a result buffer failed to get.
    refused: AtomicU64,
}

impl<'c> Budget<'c> {
    pub(crate) fn new(control: &'c Control) -> Self {
        Self {
            control,
            pairs: AtomicU64::new(0),
            stop: AtomicU8::new(RUNNING),
            refused: AtomicU64::new(0),
        }
    }

    /// Whether the query must stop now (cheap: two relaxed loads).
    #[inline(always)]
    pub(crate) fn stopped(&self) -> bool {
        if self.stop.load(Ordering::Relaxed) != RUNNING {
            return true;
        }
        if self
            .control
            .cancel
            .as_ref()
            .is_some_and(|c| c.load(Ordering::Relaxed))
        {
            self.halt(CANCELLED);
            return true;
        }
        false
    }

    /// [`Budget::stopped`], after asking [`Control::poll`].
    pub(crate) fn poll(&self) -> bool {
        if let Some(poll) = &self.control.poll {
            if poll() {
                self.halt(CANCELLED);
            }
        }
        self.stopped()
    }

    fn halt(&self, why: u8) {
        let _ = self
            .stop
            .compare_exchange(RUNNING, why, Ordering::Relaxed, Ordering::Relaxed);
    }

    /// Counts `n` more result pairs; past the limit the query stops.
    #[inline]
    pub(crate) fn add(&self, n: usize) {
        if n == 0 {
            return;
        }
        let total = self.pairs.fetch_add(n as u64, Ordering::Relaxed) + n as u64;
        if total > self.control.max_pairs {
            self.halt(OVER_LIMIT);
        }
    }

    /// Takes back `n` result pairs counted by [`Budget::add`] and dropped since (a walk
    /// started again finds them anew).
    pub(crate) fn release(&self, n: usize) {
        self.pairs.fetch_sub(n as u64, Ordering::Relaxed);
    }

    /// Appends `x` to `v`, or stops the query if `v` cannot grow.
    #[inline(always)]
    pub(crate) fn push<T>(&self, v: &mut Vec<T>, x: T) {
        if v.len() == v.capacity() && !self.grow(v, 1) {
            return;
        }
        v.push(x);
    }

    /// Appends `xs` to `v`, or stops the query if `v` cannot grow.
    pub(crate) fn extend<T: Clone>(&self, v: &mut Vec<T>, xs: &[T]) {
        if self.grow(v, xs.len()) {
            v.extend_from_slice(xs);
        }
    }

    /// Room for `n` more in `v` (doubling, or just `n` when doubling is refused); `false`
    /// (the query stopped) if the allocator refuses.
    fn grow<T>(&self, v: &mut Vec<T>, n: usize) -> bool {
        if v.try_reserve(n.max(v.len()).max(16)).is_ok() || v.try_reserve(n).is_ok() {
            return true;
        }
        let bytes = (v.len() + n).saturating_mul(std::mem::size_of::<T>()) as u64;
        self.refused.fetch_max(bytes, Ordering::Relaxed);
        self.halt(NO_MEMORY);
        false
    }

    /// `Ok` if the query ran to the end, else why it stopped. A cancel flag set by now
    /// cancels the query however little work it had (a walk that proved every node clear
    /// never stops to look).
    pub(crate) fn finish(&self) -> Result<()> {
        self.stopped();
        match self.stop.load(Ordering::Relaxed) {
            RUNNING => Ok(()),
            CANCELLED => Err(Error::Cancelled),
            OVER_LIMIT => Err(Error::OutputLimit {
                reached: self.pairs.load(Ordering::Relaxed),
                limit: self.control.max_pairs,
            }),
            _ => Err(Error::OutOfMemory {
                bytes: self.refused.load(Ordering::Relaxed),
            }),
        }
    }
}
