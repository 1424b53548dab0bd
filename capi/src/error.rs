//! Failures of the C ABI: [`Fail`] (a `DHCD_ERR_*` code and its message), [`guard`] (every
//! entry point runs inside it: no panic crosses the boundary) and the per-thread last error
//! message (`dhcd_last_error_message`).

use std::cell::RefCell;
use std::ffi::{c_char, c_int, CString};
use std::panic::{catch_unwind, AssertUnwindSafe};

use dhcd::error::Error;

use crate::{
    DHCD_ERR_CANCELLED, DHCD_ERR_INVALID_ARGUMENT, DHCD_ERR_INVALID_MESH, DHCD_ERR_LENGTH_MISMATCH,
    DHCD_ERR_NULL, DHCD_ERR_OUTPUT_LIMIT, DHCD_ERR_OUT_OF_MEMORY, DHCD_ERR_PANIC,
    DHCD_ERR_PRECISION, DHCD_ERR_REPEATED_OBJECT, DHCD_ERR_STALE_CONTACT, DHCD_ERR_UNKNOWN_OBJECT,
    DHCD_ERR_WRONG_KIND, DHCD_OK,
};

thread_local! {
    static LAST_ERROR: RefCell<CString> = RefCell::new(CString::default());
}

/// A failure: code and message.
pub(crate) struct Fail(pub(crate) c_int, pub(crate) String);

impl From<Error> for Fail {
    fn from(e: Error) -> Self {
        let code = match &e {
            Error::NoVertices
            | Error::NoTriangles
            | Error::TooManyVertices(_)
            | Error::TooManyTriangles(_)
            | Error::IndexOutOfRange { .. }
            | Error::RepeatedIndex { .. }
            | Error::NonFinite { .. }
            | Error::OutOfRange { .. } => DHCD_ERR_INVALID_MESH,
            Error::PrecisionMismatch { .. } => DHCD_ERR_PRECISION,
            Error::OutputLimit { .. } => DHCD_ERR_OUTPUT_LIMIT,
            Error::OutOfMemory { .. } => DHCD_ERR_OUT_OF_MEMORY,
            Error::Cancelled => DHCD_ERR_CANCELLED,
            Error::WrongVertexCount { .. } | Error::LengthMismatch { .. } => {
                DHCD_ERR_LENGTH_MISMATCH
            }
            Error::MethodMismatch { .. } => DHCD_ERR_WRONG_KIND,
            Error::UnknownObject(_) => DHCD_ERR_UNKNOWN_OBJECT,
            Error::RepeatedObject(_) => DHCD_ERR_REPEATED_OBJECT,
            Error::StaleContact { .. } => DHCD_ERR_STALE_CONTACT,
            Error::InvalidLevels { .. }
            | Error::UnknownMethod { .. }
            | Error::UnknownRefit(_)
            | Error::UnknownCentral(_)
            | Error::NodeOutOfRange { .. }
            | Error::NotALeaf { .. }
            | Error::TreeMismatch { .. }
            | Error::TriangleOutOfRange { .. }
            | Error::InvalidLeafSize { .. }
            | Error::InvalidThreads { .. }
            | Error::Io { .. }
            | Error::FileTooLarge { .. }
            | Error::Parse { .. }
            | Error::InvalidDistance(_)
            | Error::InvalidTimeLimit(_)
            | Error::InvalidMinDistance(_)
            | Error::NonFiniteCcdPoint { .. }
            | Error::UnknownContactType(_)
            | Error::InvalidRescaling(_)
            | Error::UnknownPrecision(_) => DHCD_ERR_INVALID_ARGUMENT,
            // `Error` is non-exhaustive: a variant added later is a bad argument until it
            // gets a code of its own.
            _ => DHCD_ERR_INVALID_ARGUMENT,
        };
        Fail(code, e.to_string())
    }
}

pub(crate) fn null(what: &str) -> Fail {
    Fail(DHCD_ERR_NULL, format!("{what} is a null pointer"))
}

fn set_last_error(msg: String) {
    let msg = CString::new(msg.replace('\0', " ")).unwrap_or_default();
    LAST_ERROR.with(|l| *l.borrow_mut() = msg);
}

/// Runs an entry point: catches panics, records the error message, returns the code.
pub(crate) fn guard(f: impl FnOnce() -> Result<(), Fail>) -> c_int {
    match catch_unwind(AssertUnwindSafe(f)) {
        Ok(Ok(())) => DHCD_OK,
        Ok(Err(Fail(code, msg))) => {
            set_last_error(msg);
            code
        }
        Err(panic) => {
            let what = panic
                .downcast_ref::<&str>()
                .map(|s| s.to_string())
                .or_else(|| panic.downcast_ref::<String>().cloned())
                .unwrap_or_default();
            set_last_error(format!("internal error (a bug in dhcd): {what}"));
            DHCD_ERR_PANIC
        }
    }
}

/// The message of the last failed call on this thread (UTF-8, NUL-terminated; empty if
/// none). Valid until the next failing call on this thread; never null. Successful calls
/// leave it unchanged.
#[no_mangle]
pub extern "C" fn dhcd_last_error_message() -> *const c_char {
    // The pointer stays valid while the thread-local CString is not replaced, i.e. until
    // the next failure on this thread.
    catch_unwind(|| LAST_ERROR.with(|l| l.borrow().as_ptr())).unwrap_or(c"internal error".as_ptr())
}
