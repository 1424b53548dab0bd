//! Long library calls from Python: Ctrl-C stops them, and their results are bounded.
//!
//! A query runs with the GIL released. Python runs signal handlers (the one that raises
//! `KeyboardInterrupt`) only on its main thread and only when asked, so the thread that
//! called asks, at most every [`CHECK_EVERY`]:
//! - a query on the calling thread (`threads=1`) asks from the library's poll function
//!   ([`dhcd::Control::poll`]), which the walk calls between leaf pairs and the exact CCD
//!   path between its steps;
//! - a parallel query runs on a helper thread while the calling thread waits, asking in
//!   between.
//!
//! A handler's exception stops the query through its cancel flag and is raised once the
//! query has returned. The result limit is the module's [`max_pairs`] (`set_max_pairs`).

use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::{Arc, Mutex};
use std::thread::ThreadId;
use std::time::{Duration, Instant};

use dhcd::{Control, Par};
use pyo3::prelude::*;

/// How often the calling thread runs Python's signal handlers during a query.
const CHECK_EVERY: Duration = Duration::from_millis(50);

/// The most result pairs of one query from Python (`dhcd.set_max_pairs`).
static MAX_PAIRS: AtomicU64 = AtomicU64::new(dhcd::DEFAULT_MAX_PAIRS);

/// The module's limit on result pairs.
pub fn max_pairs() -> u64 {
    MAX_PAIRS.load(Ordering::Relaxed)
}

/// Sets the module's limit on result pairs.
pub fn set_max_pairs(n: u64) {
    MAX_PAIRS.store(n, Ordering::Relaxed);
}

/// One query's link to Python's signal handlers.
struct Interrupt {
    caller: ThreadId,
    cancel: Arc<AtomicBool>,
    /// The exception a signal handler raised (`KeyboardInterrupt`).
    raised: Arc<Mutex<Option<PyErr>>>,
    /// Nanoseconds after `start` of the last check.
    last: Arc<AtomicU64>,
    start: Instant,
}

impl Interrupt {
    fn new() -> Self {
        Self {
            caller: std::thread::current().id(),
            cancel: Arc::new(AtomicBool::new(false)),
            raised: Arc::new(Mutex::new(None)),
            last: Arc::new(AtomicU64::new(0)),
            start: Instant::now(),
        }
    }

    /// Runs the signal handlers (with the GIL) if this is the calling thread and the last
    /// check is at least [`CHECK_EVERY`] old; `true` once one raised.
    fn check(
        caller: ThreadId,
        start: Instant,
        last: &AtomicU64,
        cancel: &AtomicBool,
        raised: &Mutex<Option<PyErr>>,
    ) -> bool {
        if cancel.load(Ordering::Relaxed) {
            return true;
        }
        if std::thread::current().id() != caller {
            return false;
        }
        let now = start.elapsed().as_nanos() as u64;
        if now - last.load(Ordering::Relaxed) < CHECK_EVERY.as_nanos() as u64 {
            return false;
        }
        last.store(now, Ordering::Relaxed);
        if let Err(e) = Python::attach(|py| py.check_signals()) {
            *raised.lock().unwrap_or_else(|p| p.into_inner()) = Some(e);
            cancel.store(true, Ordering::Relaxed);
            return true;
        }
        false
    }

    /// The control of the query: the module's limit, this cancel flag, and a poll function
    /// that checks from the calling thread.
    fn control(&self) -> Control {
        let (caller, start) = (self.caller, self.start);
        let (last, cancel, raised) = (self.last.clone(), self.cancel.clone(), self.raised.clone());
        Control::default()
            .with_max_pairs(max_pairs())
            .with_cancel(self.cancel.clone())
            .with_poll(move || Interrupt::check(caller, start, &last, &cancel, &raised))
    }

    fn check_now(&self) -> bool {
        Interrupt::check(
            self.caller,
            self.start,
            &self.last,
            &self.cancel,
            &self.raised,
        )
    }

    /// The query's result, the exception a signal handler raised taking precedence.
    fn finish<T>(self, r: dhcd::Result<T>) -> PyResult<T> {
        if let Some(e) = self.raised.lock().unwrap_or_else(|p| p.into_inner()).take() {
            return Err(e);
        }
        r.map_err(crate::to_py)
    }
}

/// Runs `query` (given the [`Control`] to use) with the GIL released, stoppable by Ctrl-C
/// (see the module docs); `par` says whether it runs on the calling thread.
pub fn run<T: Send>(
    py: Python<'_>,
    par: Par,
    query: impl FnOnce(&Control) -> dhcd::Result<T> + Send,
) -> PyResult<T> {
    let interrupt = Interrupt::new();
    let control = interrupt.control();
    let r = if !par.is_parallel() {
        py.detach(|| query(&control))
    } else {
        py.detach(|| {
            let me = std::thread::current();
            std::thread::scope(|s| {
                let worker = s.spawn(|| {
                    let r = query(&control);
                    me.unpark();
                    r
                });
                while !worker.is_finished() {
                    std::thread::park_timeout(CHECK_EVERY);
                    interrupt.check_now();
                }
                worker
                    .join()
                    .unwrap_or_else(|p| std::panic::resume_unwind(p))
            })
        })
    };
    interrupt.finish(r)
}

/// Runs `work` on the calling thread with the GIL released, giving it a stop function that
/// runs Python's signal handlers at most every [`CHECK_EVERY`] (single-pair CCD batches).
/// A handler's exception is raised in place of `work`'s error; other errors are
/// `ValueError`s with `work`'s message.
pub fn batch<T: Send>(
    py: Python<'_>,
    work: impl FnOnce(&dyn Fn() -> bool) -> Result<T, String> + Send,
) -> PyResult<T> {
    let interrupt = Interrupt::new();
    let r = py.detach(|| work(&|| interrupt.check_now()));
    if let Some(e) = interrupt
        .raised
        .lock()
        .unwrap_or_else(|p| p.into_inner())
        .take()
    {
        return Err(e);
    }
    r.map_err(crate::value_error)
}
