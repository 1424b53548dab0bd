//! Helpers shared by the library's suites.

pub use crate::temp_dir::temp_dir;

/// Counts the bytes each thread has allocated and not freed, so that a test can bound the
/// memory a call takes ([`peak_bytes`]) without depending on what other tests do meanwhile.
struct CountingAllocator;

thread_local! {
    static LIVE: std::cell::Cell<isize> = const { std::cell::Cell::new(0) };
    static PEAK: std::cell::Cell<isize> = const { std::cell::Cell::new(0) };
    /// Allocations larger than this fail on this thread ([`refusing_above`]).
    static REFUSE_ABOVE: std::cell::Cell<usize> = const { std::cell::Cell::new(usize::MAX) };
}

fn refused(layout: std::alloc::Layout) -> bool {
    REFUSE_ABOVE
        .try_with(|r| layout.size() > r.get())
        .unwrap_or(false)
}

fn count(delta: isize) {
    let _ = LIVE.try_with(|live| {
        let now = live.get() + delta;
        live.set(now);
        let _ = PEAK.try_with(|peak| peak.set(peak.get().max(now)));
    });
}

// SAFETY: every call is forwarded unchanged to the system allocator; counting only touches
// const-initialised thread-locals (no allocation, no destructor).
unsafe impl std::alloc::GlobalAlloc for CountingAllocator {
    unsafe fn alloc(&self, layout: std::alloc::Layout) -> *mut u8 {
        if refused(layout) {
            return std::ptr::null_mut();
        }
        count(layout.size() as isize);
        // SAFETY: the caller's contract is the system allocator's.
        unsafe { std::alloc::System.alloc(layout) }
    }

    unsafe fn dealloc(&self, ptr: *mut u8, layout: std::alloc::Layout) {
        count(-(layout.size() as isize));
        // SAFETY: as above.
        unsafe { std::alloc::System.dealloc(ptr, layout) }
    }

    unsafe fn alloc_zeroed(&self, layout: std::alloc::Layout) -> *mut u8 {
        if refused(layout) {
            return std::ptr::null_mut();
        }
        count(layout.size() as isize);
        // SAFETY: as above.
        unsafe { std::alloc::System.alloc_zeroed(layout) }
    }

    unsafe fn realloc(&self, ptr: *mut u8, layout: std::alloc::Layout, new: usize) -> *mut u8 {
        if new > layout.size() && REFUSE_ABOVE.try_with(|r| new > r.get()).unwrap_or(false) {
            return std::ptr::null_mut();
        }
        count(new as isize - layout.size() as isize);
        // SAFETY: as above.
        unsafe { std::alloc::System.realloc(ptr, layout, new) }
    }
}

#[global_allocator]
static ALLOCATOR: CountingAllocator = CountingAllocator;

/// Runs `f` and returns its result and the most bytes it held allocated at once on this
/// thread (work `f` hands to other threads is not counted).
pub fn peak_bytes<R>(f: impl FnOnce() -> R) -> (R, usize) {
    let start = LIVE.with(|l| l.get());
    PEAK.with(|p| p.set(start));
    let r = f();
    let peak = PEAK.with(|p| p.get()) - start;
    (r, peak.max(0) as usize)
}

/// Runs `f` with every allocation of more than `bytes` on this thread refused (the allocator
/// returns null, as a system out of memory does).
pub fn refusing_above<R>(bytes: usize, f: impl FnOnce() -> R) -> R {
    let before = REFUSE_ABOVE.with(|r| r.replace(bytes));
    let r = f();
    REFUSE_ABOVE.with(|r| r.set(before));
    r
}

/// The folder `data/<rel>` of the project's shared data (`../shared/data` beside the
/// checkout, or the folder named by `DHCD_SHARED_DATA`), or `None` after one line on stderr
/// saying that `test` is skipped: a clone without the shared data passes.
///
/// The line is written to stderr directly, not through `eprintln!`, so the test harness
/// does not swallow it. With `DHCD_REQUIRE_SHARED_DATA=1` a missing folder fails the test
/// instead: CI, which has the data, sets it so that nothing is skipped there.
pub fn shared_data(test: &str, rel: &str) -> Option<std::path::PathBuf> {
    use std::io::Write;
    let root = match std::env::var_os("DHCD_SHARED_DATA") {
        Some(dir) => std::path::PathBuf::from(dir),
        None => std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../shared/data"),
    };
    let dir = root.join(rel);
    if dir.exists() {
        return Some(dir);
    }
    let required = std::env::var_os("DHCD_REQUIRE_SHARED_DATA").is_some_and(|v| v == "1");
    assert!(
        !required,
        "{test}: {} is missing and DHCD_REQUIRE_SHARED_DATA=1",
        dir.display()
    );
    let _ = writeln!(
        std::io::stderr(),
        "SKIPPED {test}: no shared data at {}",
        dir.display()
    );
    None
}

/// The folder `tests/data/<rel>`: data that travels with the repository (`tests/data/README.md`).
pub fn repo_data(rel: &str) -> std::path::PathBuf {
    std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data")
        .join(rel)
}
