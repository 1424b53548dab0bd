//! Limits and cancellation of the queries of a hierarchy or scene (`dhcd::Control`): the most
//! result pairs, a cancel token any thread can set, and a poll callback.

use std::ffi::{c_int, c_void};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;

use dhcd::Control;

use crate::error::{guard, null, Fail};
use crate::hierarchy::DhcdHierarchy;
use crate::marshal::{handle, write};
use crate::scene::DhcdScene;

/// Opaque: a cancel token. `dhcd_cancel_set` (from any thread) stops every query of the
/// hierarchies and scenes it is given to, which then return `DHCD_ERR_CANCELLED`, until
/// `dhcd_cancel_reset`.
pub struct DhcdCancel {
    flag: Arc<AtomicBool>,
}

/// A poll callback: called by the threads doing a query's work, once every 64 leaf pairs
/// each and between the steps of the exact CCD path; non-zero stops the query
/// (`DHCD_ERR_CANCELLED`). It may be called from several threads at once when
/// `threads != 1`, and must be cheap (read a clock first).
pub type DhcdPoll = Option<unsafe extern "C" fn(user: *mut c_void) -> c_int>;

/// The callback and its user pointer.
struct Poll {
    f: unsafe extern "C" fn(*mut c_void) -> c_int,
    user: *mut c_void,
}

impl Poll {
    /// Whether the callback says stop.
    fn stop(&self) -> bool {
        // SAFETY: the callback's contract (see `dhcd_hierarchy_set_control`): callable with
        // `user` from any thread while the handle lives.
        unsafe { (self.f)(self.user) != 0 }
    }
}

// SAFETY: the caller of `dhcd_*_set_control` promises that the callback may be called with
// `user` from any thread, concurrently (documented there).
unsafe impl Send for Poll {}
// SAFETY: as above.
unsafe impl Sync for Poll {}

/// A new cancel token, not set, into `*out` (release with `dhcd_cancel_free`).
///
/// # Safety
/// `out` null or valid for a write.
#[no_mangle]
pub unsafe extern "C" fn dhcd_cancel_new(out: *mut *mut DhcdCancel) -> c_int {
    guard(|| {
        let token = Box::new(DhcdCancel {
            flag: Arc::new(AtomicBool::new(false)),
        });
        // SAFETY: caller's contract on `out`.
        unsafe { write(out, Box::into_raw(token), "out") }
    })
}

/// Sets the token: the queries using it stop (from any thread, at any time).
///
/// # Safety
/// `c` null or a live token.
#[no_mangle]
pub unsafe extern "C" fn dhcd_cancel_set(c: *const DhcdCancel) -> c_int {
    guard(|| {
        // SAFETY: caller's contract.
        let c = unsafe { c.as_ref() }.ok_or_else(|| null("cancel token"))?;
        c.flag.store(true, Ordering::Relaxed);
        Ok(())
    })
}

/// Clears the token: later queries run again.
///
/// # Safety
/// `c` null or a live token.
#[no_mangle]
pub unsafe extern "C" fn dhcd_cancel_reset(c: *const DhcdCancel) -> c_int {
    guard(|| {
        // SAFETY: caller's contract.
        let c = unsafe { c.as_ref() }.ok_or_else(|| null("cancel token"))?;
        c.flag.store(false, Ordering::Relaxed);
        Ok(())
    })
}

/// Releases a token (the hierarchies and scenes given it keep their own reference). Null is
/// a no-op.
///
/// # Safety
/// `c` null or a token from `dhcd_cancel_new` not yet released.
#[no_mangle]
pub unsafe extern "C" fn dhcd_cancel_free(c: *mut DhcdCancel) {
    let _ = guard(|| {
        if !c.is_null() {
            // SAFETY: a live token from `Box::into_raw` (caller's contract), released once.
            drop(unsafe { Box::from_raw(c) });
        }
        Ok(())
    });
}

/// The control of the arguments.
///
/// # Safety
/// `cancel` null or a live token.
unsafe fn control(
    max_pairs: u64,
    cancel: *const DhcdCancel,
    poll: DhcdPoll,
    user: *mut c_void,
) -> Control {
    let mut c = Control::default().with_max_pairs(max_pairs);
    // SAFETY: caller's contract.
    if let Some(token) = unsafe { cancel.as_ref() } {
        c = c.with_cancel(token.flag.clone());
    }
    if let Some(f) = poll {
        let p = Poll { f, user };
        c = c.with_poll(move || p.stop());
    }
    c
}

/// Sets the limits and cancellation of the hierarchy's proximity and CCD queries (those
/// with it first): at most `max_pairs` result pairs (`DHCD_DEFAULT_MAX_PAIRS` by default,
/// `DHCD_NO_LIMIT` for none; more is `DHCD_ERR_OUTPUT_LIMIT`), stopped by `cancel` (null:
/// none) or by `poll` returning non-zero (null: none; called with `user`, possibly from
/// several threads at once: it must be thread-safe). A stopped query returns
/// `DHCD_ERR_CANCELLED` and an empty result.
///
/// # Safety
/// `h` null or a live handle; `cancel` null or a live token; `poll` null or a function safe
/// to call with `user` from any thread for as long as the hierarchy lives.
#[no_mangle]
pub unsafe extern "C" fn dhcd_hierarchy_set_control(
    h: *mut DhcdHierarchy,
    max_pairs: u64,
    cancel: *const DhcdCancel,
    poll: DhcdPoll,
    user: *mut c_void,
) -> c_int {
    guard(|| {
        // SAFETY: caller's contract.
        let h = unsafe { handle(h, "hierarchy")? };
        // SAFETY: caller's contract.
        h.ws.control = unsafe { control(max_pairs, cancel, poll, user) };
        Ok::<(), Fail>(())
    })
}

/// `dhcd_hierarchy_set_control` for a scene's proximity and CCD queries (the limit counts
/// the pairs of every object pair together).
///
/// # Safety
/// As `dhcd_hierarchy_set_control`, for a scene handle.
#[no_mangle]
pub unsafe extern "C" fn dhcd_scene_set_control(
    s: *mut DhcdScene,
    max_pairs: u64,
    cancel: *const DhcdCancel,
    poll: DhcdPoll,
    user: *mut c_void,
) -> c_int {
    guard(|| {
        // SAFETY: caller's contract.
        let s = unsafe { handle(s, "scene")? };
        // SAFETY: caller's contract.
        s.scene
            .set_control(unsafe { control(max_pairs, cancel, poll, user) });
        Ok::<(), Fail>(())
    })
}
