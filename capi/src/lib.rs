//! The C ABI of dhcd (`include/dhcd.h`; see `docs/LINKING_FROM_C.md`): the only `unsafe` code
//! of the project outside the SIMD kernels.
//!
//! Conventions:
//! - every fallible function returns an `int`: [`DHCD_OK`] (0) or a negative `DHCD_ERR_*`
//!   code, and then [`dhcd_last_error_message`] describes the failure (per thread);
//! - no panic crosses the boundary: every entry runs inside `catch_unwind` and a panic
//!   becomes [`DHCD_ERR_PANIC`];
//! - null pointers, misaligned arrays, mismatched lengths and hierarchies of different kinds
//!   are errors, never undefined behaviour on the library's side;
//! - handles (`DhcdHierarchy`, `DhcdScene`) are created by `*_new` and released by
//!   `*_free`; results (`DhcdContacts`, `DhcdSceneContacts`) own library-allocated arrays
//!   released by `dhcd_contacts_free` / `dhcd_scene_contacts_free`;
//! - a handle must not be used from two threads at once (queries refit it lazily).
//!
//! - a function with a handle or result output (`*out`) empties it first (NULL handle,
//!   empty result), so it is empty after any error; scalar outputs (`dhcd_hierarchy_method`,
//!   `dhcd_scene_add`'s id, `dhcd_contact_segments`' segments) are written only on success.
//!
//! `threads` arguments: `1` runs on the calling thread, `0` on rayon's global pool (all
//! cores), `n` on a pool of `n` threads but never more than the machine's cores; above
//! `dhcd::par::MAX_THREADS` (1024) is `DHCD_ERR_INVALID_ARGUMENT`. Results never depend on it.

use std::cell::RefCell;
use std::ffi::{c_char, c_int, CString};
use std::panic::{catch_unwind, AssertUnwindSafe};

use dhcd::any::AnyHierarchy;
use dhcd::bv::Method;
use dhcd::counters::Counters;
use dhcd::error::Error;
use dhcd::hierarchy::Options;
use dhcd::mesh::Mesh;
use dhcd::par::Par;
use dhcd::scene::{ObjectId, Scene};
use dhcd::{Contacts, Workspace};

/// Success.
pub const DHCD_OK: c_int = 0;
/// A required pointer argument is null.
pub const DHCD_ERR_NULL: c_int = -1;
/// A bad argument: unknown method, levels out of range, misaligned or oversized array,
/// the same hierarchy passed twice to `dhcd_collide`, a thread count above 1024.
pub const DHCD_ERR_INVALID_ARGUMENT: c_int = -2;
/// The mesh is invalid: no vertices or triangles, an index out of range, a repeated index
/// in a triangle, a non-finite coordinate.
pub const DHCD_ERR_INVALID_MESH: c_int = -3;
/// A position update whose vertex count differs from the mesh's.
pub const DHCD_ERR_LENGTH_MISMATCH: c_int = -4;
/// Two hierarchies of different kinds.
pub const DHCD_ERR_WRONG_KIND: c_int = -5;
/// No object with this id in the scene.
pub const DHCD_ERR_UNKNOWN_OBJECT: c_int = -6;
/// A contact pair that does not intersect in the current pose (contact segments).
pub const DHCD_ERR_STALE_CONTACT: c_int = -7;
/// A bug in dhcd (a caught panic).
pub const DHCD_ERR_PANIC: c_int = -8;
/// The same object id given more than once in one `dhcd_scene_update_many`.
pub const DHCD_ERR_REPEATED_OBJECT: c_int = -9;

// The kinds' numbers (`DHCD_METHOD_DH` = 0, ...) are not constants here: they are
// `Method::code()`, from the library's table of kinds, and the header's `DHCD_METHOD_*`
// defines are generated from that table with the rest of the header (capi/tests/capi.rs).

/// Counted work of a query (the cost model's `N_V`, `N_P`, `N_U`, and the contacts).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct DhcdCounters {
    pub bv_tests: u64,
    pub prim_tests: u64,
    pub bv_updates: u64,
    pub contacts: u64,
}

impl From<Counters> for DhcdCounters {
    fn from(c: Counters) -> Self {
        Self {
            bv_tests: c.bv_tests,
            prim_tests: c.prim_tests,
            bv_updates: c.bv_updates,
            contacts: c.contacts,
        }
    }
}

/// Contacts of `dhcd_collide` / `dhcd_self_collide`: `count` pairs, `pairs[2k]`,
/// `pairs[2k+1]` (original triangle indices), sorted. `pairs` is null when `count == 0`.
#[repr(C)]
#[derive(Debug)]
pub struct DhcdContacts {
    pub pairs: *mut u32,
    pub count: usize,
    pub counters: DhcdCounters,
}

/// Contacts of `dhcd_scene_contacts`: `count` quadruples `[object_a, tri_a, object_b,
/// tri_b]` at `pairs[4k..4k+4]`, sorted. `pairs` is null when `count == 0`.
#[repr(C)]
#[derive(Debug)]
pub struct DhcdSceneContacts {
    pub pairs: *mut u64,
    pub count: usize,
    pub counters: DhcdCounters,
}

/// Opaque: one object's hierarchy (and its query scratch).
pub struct DhcdHierarchy {
    h: AnyHierarchy,
    ws: Workspace,
}

/// Opaque: a scene of many objects.
pub struct DhcdScene {
    scene: Scene,
}

thread_local! {
    static LAST_ERROR: RefCell<CString> = RefCell::new(CString::default());
}

/// A failure: code and message.
struct Fail(c_int, String);

impl From<Error> for Fail {
    fn from(e: Error) -> Self {
        let code = match &e {
            Error::NoVertices
            | Error::NoTriangles
            | Error::TooManyVertices(_)
            | Error::TooManyTriangles(_)
            | Error::IndexOutOfRange { .. }
            | Error::RepeatedIndex { .. }
            | Error::NonFinite { .. } => DHCD_ERR_INVALID_MESH,
            Error::WrongVertexCount { .. } => DHCD_ERR_LENGTH_MISMATCH,
            Error::MethodMismatch { .. } => DHCD_ERR_WRONG_KIND,
            Error::UnknownObject(_) => DHCD_ERR_UNKNOWN_OBJECT,
            Error::RepeatedObject(_) => DHCD_ERR_REPEATED_OBJECT,
            Error::StaleContact { .. } => DHCD_ERR_STALE_CONTACT,
            Error::InvalidLevels { .. }
            | Error::UnknownMethod(_)
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
            | Error::Parse { .. } => DHCD_ERR_INVALID_ARGUMENT,
            // `Error` is non-exhaustive: a variant added later is a bad argument until it
            // gets a code of its own.
            _ => DHCD_ERR_INVALID_ARGUMENT,
        };
        Fail(code, e.to_string())
    }
}

fn null(what: &str) -> Fail {
    Fail(DHCD_ERR_NULL, format!("{what} is a null pointer"))
}

fn set_last_error(msg: String) {
    let msg = CString::new(msg.replace('\0', " ")).unwrap_or_default();
    LAST_ERROR.with(|l| *l.borrow_mut() = msg);
}

/// Runs an entry point: catches panics, records the error message, returns the code.
fn guard(f: impl FnOnce() -> Result<(), Fail>) -> c_int {
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

/// A borrowed C array of `len` elements of `T`.
///
/// # Safety
/// If `ptr` is non-null and aligned, it must point to `len` initialised `T` that stay valid
/// and unmodified for `'a`.
unsafe fn slice<'a, T>(ptr: *const T, len: usize, what: &str) -> Result<&'a [T], Fail> {
    if ptr.is_null() {
        return Err(null(what));
    }
    if !ptr.is_aligned() {
        return Err(Fail(
            DHCD_ERR_INVALID_ARGUMENT,
            format!("{what} is not aligned"),
        ));
    }
    if len
        .checked_mul(std::mem::size_of::<T>())
        .is_none_or(|b| b > isize::MAX as usize)
    {
        return Err(Fail(
            DHCD_ERR_INVALID_ARGUMENT,
            format!("{what}: {len} elements is too many"),
        ));
    }
    // SAFETY: non-null, aligned, size fits in isize (checked above); validity and lifetime
    // are the caller's contract.
    Ok(unsafe { std::slice::from_raw_parts(ptr, len) })
}

/// `count` positions (`3 * count` floats).
///
/// # Safety
/// As [`slice`], for `3 * count` floats.
unsafe fn positions<'a>(ptr: *const f32, count: usize) -> Result<&'a [[f32; 3]], Fail> {
    // SAFETY: `[f32; 3]` has the alignment of `f32` and the size of three; same contract.
    unsafe { slice(ptr.cast::<[f32; 3]>(), count, "positions") }
}

/// # Safety
/// As [`slice`], for `3 * count` `u32`.
unsafe fn triangles<'a>(ptr: *const u32, count: usize) -> Result<&'a [[u32; 3]], Fail> {
    // SAFETY: `[u32; 3]` has the alignment of `u32` and the size of three; same contract.
    unsafe { slice(ptr.cast::<[u32; 3]>(), count, "triangles") }
}

/// # Safety
/// `ptr` null or a live handle from the matching `*_new`, not used elsewhere meanwhile.
unsafe fn handle<'a, T>(ptr: *mut T, what: &str) -> Result<&'a mut T, Fail> {
    // SAFETY: the caller's contract: null or a live, exclusively used handle.
    unsafe { ptr.as_mut() }.ok_or_else(|| null(what))
}

/// # Safety
/// `ptr` null or valid for a write of `T`.
unsafe fn write<T>(ptr: *mut T, value: T, what: &str) -> Result<(), Fail> {
    if ptr.is_null() {
        return Err(null(what));
    }
    // SAFETY: non-null, and valid for writes by the caller's contract; `write` does not
    // drop the (possibly uninitialised) old value.
    unsafe { ptr.write(value) };
    Ok(())
}

fn method_of(m: c_int) -> Result<Method, Fail> {
    Method::from_code(m).ok_or_else(|| {
        let names: Vec<String> = Method::ALL
            .iter()
            .map(|m| format!("DHCD_METHOD_{}", m.name().to_uppercase()))
            .collect();
        Fail(
            DHCD_ERR_INVALID_ARGUMENT,
            format!("unknown method {m} (expected one of {})", names.join(", ")),
        )
    })
}

/// `levels == 0`: the adaptive default tree; otherwise the paper's fixed depth.
fn options(levels: u32) -> Options {
    Options {
        levels: (levels != 0).then_some(levels as usize),
        ..Options::default()
    }
}

/// A `threads` argument, checked where every thread count is (`Par::threads`).
fn par(threads: u32) -> Result<Par, Fail> {
    Ok(Par::threads(threads as usize)?)
}

/// A validated mesh from C arrays.
///
/// # Safety
/// As [`positions`] and [`triangles`].
unsafe fn mesh(
    pos: *const f32,
    vertex_count: usize,
    tris: *const u32,
    triangle_count: usize,
) -> Result<Mesh, Fail> {
    // SAFETY: forwarded contract.
    let (p, t) = unsafe {
        (
            positions(pos, vertex_count)?,
            triangles(tris, triangle_count)?,
        )
    };
    Ok(Mesh::new(p.to_vec(), t.to_vec())?)
}

/// `pairs` flattened into an array the caller owns until the matching `*_free` (which
/// rebuilds the `Box<[T]>` of `N * count` elements), or null when there are none.
fn c_pairs<T, const N: usize>(pairs: Vec<[T; N]>) -> *mut T {
    if pairs.is_empty() {
        return std::ptr::null_mut();
    }
    let flat: Box<[T]> = pairs.into_iter().flatten().collect();
    Box::into_raw(flat).cast::<T>()
}

fn contacts_out(c: Contacts) -> DhcdContacts {
    DhcdContacts {
        count: c.pairs.len(),
        pairs: c_pairs(c.pairs),
        counters: c.counters.into(),
    }
}

const NO_CONTACTS: DhcdContacts = DhcdContacts {
    pairs: std::ptr::null_mut(),
    count: 0,
    counters: DhcdCounters {
        bv_tests: 0,
        prim_tests: 0,
        bv_updates: 0,
        contacts: 0,
    },
};

const NO_SCENE_CONTACTS: DhcdSceneContacts = DhcdSceneContacts {
    pairs: std::ptr::null_mut(),
    count: 0,
    counters: NO_CONTACTS.counters,
};

/// The message of the last failed call on this thread (UTF-8, NUL-terminated; empty if
/// none). Valid until the next failing call on this thread; never null. Successful calls
/// leave it unchanged.
#[no_mangle]
pub extern "C" fn dhcd_last_error_message() -> *const c_char {
    // The pointer stays valid while the thread-local CString is not replaced, i.e. until
    // the next failure on this thread.
    catch_unwind(|| LAST_ERROR.with(|l| l.borrow().as_ptr())).unwrap_or(c"internal error".as_ptr())
}

/// Builds the hierarchy of a mesh: `positions` holds `3 * vertex_count` floats (x, y, z per
/// vertex), `triangles` `3 * triangle_count` vertex indices. `method` is a
/// `DHCD_METHOD_*`, `levels` the region tree's fixed depth (the paper's choice: 5), or 0
/// for the adaptive default tree. On success
/// `*out` is a new handle to release with `dhcd_hierarchy_free`.
///
/// # Safety
/// The arrays must hold the stated number of elements; `out` must be valid for a write.
#[no_mangle]
pub unsafe extern "C" fn dhcd_hierarchy_new(
    method: c_int,
    levels: u32,
    positions: *const f32,
    vertex_count: usize,
    triangles: *const u32,
    triangle_count: usize,
    out: *mut *mut DhcdHierarchy,
) -> c_int {
    guard(|| {
        // SAFETY: caller's contract on `out`: NULL until there is a handle.
        unsafe { write(out, std::ptr::null_mut(), "out")? };
        let m = method_of(method)?;
        // SAFETY: the caller's contract on the arrays.
        let mesh = unsafe { mesh(positions, vertex_count, triangles, triangle_count)? };
        let h = AnyHierarchy::new(m, &mesh, options(levels))?;
        let boxed = Box::new(DhcdHierarchy {
            h,
            ws: Workspace::default(),
        });
        // SAFETY: `out` is non-null and valid for a write (caller's contract).
        unsafe { write(out, Box::into_raw(boxed), "out") }
    })
}

/// Releases a hierarchy. Null is allowed (no-op).
///
/// # Safety
/// `h` is null or a handle from `dhcd_hierarchy_new` not yet released.
#[no_mangle]
pub unsafe extern "C" fn dhcd_hierarchy_free(h: *mut DhcdHierarchy) {
    let _ = guard(|| {
        if !h.is_null() {
            // SAFETY: a live handle from `Box::into_raw` (caller's contract), released once.
            drop(unsafe { Box::from_raw(h) });
        }
        Ok(())
    });
}

/// The kind of a hierarchy (`DHCD_METHOD_*`) into `*out`.
///
/// # Safety
/// `h` null or a live handle; `out` null or valid for a write.
#[no_mangle]
pub unsafe extern "C" fn dhcd_hierarchy_method(h: *const DhcdHierarchy, out: *mut c_int) -> c_int {
    guard(|| {
        // SAFETY: null or a live handle (caller's contract); only read.
        let h = unsafe { h.as_ref() }.ok_or_else(|| null("hierarchy"))?;
        // SAFETY: caller's contract on `out`.
        unsafe { write(out, h.h.method().code(), "out") }
    })
}

/// New positions of the mesh (`3 * vertex_count` floats, the mesh's vertex order and
/// count). On error the hierarchy is unchanged.
///
/// # Safety
/// `h` null or a live handle; `positions` holds `3 * vertex_count` floats.
#[no_mangle]
pub unsafe extern "C" fn dhcd_hierarchy_update_positions(
    h: *mut DhcdHierarchy,
    positions: *const f32,
    vertex_count: usize,
) -> c_int {
    guard(|| {
        // SAFETY: caller's contract.
        let (h, p) = unsafe {
            (
                handle(h, "hierarchy")?,
                self::positions(positions, vertex_count)?,
            )
        };
        h.h.update_positions(p)?;
        Ok(())
    })
}

/// All intersecting triangle pairs `[tri of a, tri of b]` between two hierarchies of the
/// same kind, into `*out` (release with `dhcd_contacts_free`). `a` and `b` must be
/// different handles (use `dhcd_self_collide` for one object).
///
/// # Safety
/// `a`, `b` null or live handles; `out` null or valid for a write.
#[no_mangle]
pub unsafe extern "C" fn dhcd_collide(
    a: *mut DhcdHierarchy,
    b: *mut DhcdHierarchy,
    threads: u32,
    out: *mut DhcdContacts,
) -> c_int {
    guard(|| {
        // SAFETY: caller's contract on `out`: empty until there are contacts.
        unsafe { write(out, NO_CONTACTS, "out")? };
        if a == b && !a.is_null() {
            return Err(Fail(
                DHCD_ERR_INVALID_ARGUMENT,
                "dhcd_collide needs two different hierarchies (use dhcd_self_collide)".into(),
            ));
        }
        // SAFETY: live, distinct handles (checked above), so the two `&mut` do not alias.
        let (a, b) = unsafe { (handle(a, "a")?, handle(b, "b")?) };
        let c = a.h.collide(&b.h, &mut a.ws, par(threads)?)?;
        // SAFETY: caller's contract on `out` (written above).
        unsafe { write(out, contacts_out(c), "out") }
    })
}

/// Self-contacts of one object: pairs `[ti, tj]`, `ti < tj`, of intersecting triangles that
/// share no vertex index, into `*out` (release with `dhcd_contacts_free`).
///
/// # Safety
/// `h` null or a live handle; `out` null or valid for a write.
#[no_mangle]
pub unsafe extern "C" fn dhcd_self_collide(
    h: *mut DhcdHierarchy,
    threads: u32,
    out: *mut DhcdContacts,
) -> c_int {
    guard(|| {
        // SAFETY: caller's contract on `out`: empty until there are contacts.
        unsafe { write(out, NO_CONTACTS, "out")? };
        // SAFETY: caller's contract on `h`.
        let h = unsafe { handle(h, "hierarchy")? };
        let c = h.h.self_collide(&mut h.ws, par(threads)?);
        // SAFETY: caller's contract on `out` (written above).
        unsafe { write(out, contacts_out(c), "out") }
    })
}

/// Contact detail: the intersection segment of each of `count` pairs `[tri of a, tri of b]`
/// (`pairs` holds `2 * count` indices, e.g. `DhcdContacts.pairs`), in the current poses,
/// into `segments` (`6 * count` floats: p.xyz, q.xyz per pair). For self-contacts pass the
/// same hierarchy as `a` and `b`. With `count == 0`, `pairs` and `segments` may be NULL.
///
/// # Safety
/// `a`, `b` null or live handles; `pairs` holds `2 * count` `u32`, `segments` room for
/// `6 * count` floats.
#[no_mangle]
pub unsafe extern "C" fn dhcd_contact_segments(
    a: *const DhcdHierarchy,
    b: *const DhcdHierarchy,
    pairs: *const u32,
    count: usize,
    segments: *mut f32,
) -> c_int {
    guard(|| {
        // SAFETY: null or live handles (caller's contract); only read.
        let (a, b) = unsafe { (a.as_ref(), b.as_ref()) };
        let (a, b) = (a.ok_or_else(|| null("a"))?, b.ok_or_else(|| null("b"))?);
        if count == 0 {
            // An empty result (`pairs == NULL`) has no segments.
            return Ok(());
        }
        // SAFETY: `pairs` holds `2 * count` u32 (caller's contract).
        let pairs = unsafe { slice(pairs.cast::<[u32; 2]>(), count, "pairs")? };
        if segments.is_null() {
            return Err(null("segments"));
        }
        let segs = a.h.contact_segments(&b.h, pairs)?;
        for (k, s) in segs.iter().enumerate() {
            let flat = [s[0][0], s[0][1], s[0][2], s[1][0], s[1][1], s[1][2]];
            // SAFETY: `segments` has room for `6 * count` floats (caller's contract) and
            // `k < count`.
            unsafe { std::ptr::copy_nonoverlapping(flat.as_ptr(), segments.add(6 * k), 6) };
        }
        Ok(())
    })
}

/// Releases the array of a `DhcdContacts` and resets it to empty. Null, or an already
/// released or empty result, is a no-op.
///
/// # Safety
/// `c` null or a `DhcdContacts` filled by this library and not modified since.
#[no_mangle]
pub unsafe extern "C" fn dhcd_contacts_free(c: *mut DhcdContacts) {
    let _ = guard(|| {
        // SAFETY: caller's contract.
        if let Some(c) = unsafe { c.as_mut() } {
            if !c.pairs.is_null() {
                let len = c.count * 2;
                // SAFETY: `pairs` came from `Box<[u32]>` of `2 * count` elements.
                drop(unsafe { Box::from_raw(std::ptr::slice_from_raw_parts_mut(c.pairs, len)) });
            }
            *c = NO_CONTACTS;
        }
        Ok(())
    });
}

/// A new empty scene whose objects get `method` hierarchies of `levels` levels.
///
/// # Safety
/// `out` null or valid for a write.
#[no_mangle]
pub unsafe extern "C" fn dhcd_scene_new(
    method: c_int,
    levels: u32,
    out: *mut *mut DhcdScene,
) -> c_int {
    guard(|| {
        // SAFETY: caller's contract on `out`: NULL until there is a handle.
        unsafe { write(out, std::ptr::null_mut(), "out")? };
        let m = method_of(method)?;
        options(levels).shape().check()?;
        let s = Box::new(DhcdScene {
            scene: Scene::new(m, options(levels)),
        });
        // SAFETY: caller's contract on `out`.
        unsafe { write(out, Box::into_raw(s), "out") }
    })
}

/// Releases a scene and all its objects. Null is a no-op.
///
/// # Safety
/// `s` null or a handle from `dhcd_scene_new` not yet released.
#[no_mangle]
pub unsafe extern "C" fn dhcd_scene_free(s: *mut DhcdScene) {
    let _ = guard(|| {
        if !s.is_null() {
            // SAFETY: a live handle from `Box::into_raw`, released once (caller's contract).
            drop(unsafe { Box::from_raw(s) });
        }
        Ok(())
    });
}

/// Adds an object (arrays as in `dhcd_hierarchy_new`; `self_collision` non-zero to report
/// its self-contacts too); its id into `*out_id`. Ids are never reused.
///
/// # Safety
/// `s` null or a live handle; arrays as in `dhcd_hierarchy_new`; `out_id` null or valid for
/// a write.
#[no_mangle]
pub unsafe extern "C" fn dhcd_scene_add(
    s: *mut DhcdScene,
    positions: *const f32,
    vertex_count: usize,
    triangles: *const u32,
    triangle_count: usize,
    self_collision: c_int,
    out_id: *mut u64,
) -> c_int {
    guard(|| {
        // SAFETY: caller's contract.
        let s = unsafe { handle(s, "scene")? };
        if out_id.is_null() {
            return Err(null("out_id"));
        }
        // SAFETY: caller's contract on the arrays.
        let mesh = unsafe { mesh(positions, vertex_count, triangles, triangle_count)? };
        let id = s.scene.add(&mesh)?;
        s.scene.set_self_collision(id, self_collision != 0)?;
        // SAFETY: non-null, valid for a write (caller's contract).
        unsafe { write(out_id, id.0, "out_id") }
    })
}

/// Removes an object.
///
/// # Safety
/// `s` null or a live handle.
#[no_mangle]
pub unsafe extern "C" fn dhcd_scene_remove(s: *mut DhcdScene, id: u64) -> c_int {
    guard(|| {
        // SAFETY: caller's contract.
        let s = unsafe { handle(s, "scene")? };
        Ok(s.scene.remove(ObjectId(id))?)
    })
}

/// New positions of an object (`3 * vertex_count` floats). On error nothing changes.
///
/// # Safety
/// `s` null or a live handle; `positions` holds `3 * vertex_count` floats.
#[no_mangle]
pub unsafe extern "C" fn dhcd_scene_update_positions(
    s: *mut DhcdScene,
    id: u64,
    positions: *const f32,
    vertex_count: usize,
) -> c_int {
    guard(|| {
        // SAFETY: caller's contract.
        let (s, p) = unsafe {
            (
                handle(s, "scene")?,
                self::positions(positions, vertex_count)?,
            )
        };
        Ok(s.scene.update_positions(ObjectId(id), p)?)
    })
}

/// One object's new positions.
type Update<'a> = (ObjectId, &'a [[f32; 3]]);

/// The entries of an update call (`dhcd_scene_update_many`, `dhcd_scene_step`).
///
/// # Safety
/// `ids`, `positions` and `vertex_counts` hold `count` elements each (any of them may be
/// null when `count == 0`: no entries), and each non-null `positions[k]` holds
/// `3 * vertex_counts[k]` floats, alive for `'a`.
unsafe fn updates<'a>(
    ids: *const u64,
    positions: *const *const f32,
    vertex_counts: *const usize,
    count: usize,
) -> Result<Vec<Update<'a>>, Fail> {
    if count == 0 {
        return Ok(Vec::new());
    }
    // SAFETY: the three arrays hold `count` elements (caller's contract).
    let (ids, ptrs, counts) = unsafe {
        (
            slice(ids, count, "ids")?,
            slice(positions, count, "positions")?,
            slice(vertex_counts, count, "vertex_counts")?,
        )
    };
    ids.iter()
        .zip(ptrs.iter().zip(counts))
        .enumerate()
        .map(|(k, (&id, (&p, &n)))| {
            // SAFETY: `positions[k]` holds `3 * vertex_counts[k]` floats (caller's contract).
            let p = unsafe { self::positions(p, n) }
                .map_err(|Fail(code, msg)| Fail(code, format!("update {k}: {msg}")))?;
            Ok((ObjectId(id), p))
        })
        .collect()
}

/// A scene's contacts as the C result (the array owned by the caller until
/// `dhcd_scene_contacts_free`).
fn scene_contacts_result(c: dhcd::SceneContacts) -> DhcdSceneContacts {
    DhcdSceneContacts {
        count: c.pairs.len(),
        pairs: c_pairs(c.pairs),
        counters: c.counters.into(),
    }
}

/// New positions of several objects in one call: entry `k` gives object `ids[k]` the
/// `3 * vertex_counts[k]` floats at `positions[k]` (as in `dhcd_scene_update_positions`).
/// `ids`, `positions` and `vertex_counts` hold `count` elements each; each id at most once.
/// Every entry is checked before any is applied: on error (a null or misaligned array, an
/// unknown id, an id given twice (`DHCD_ERR_REPEATED_OBJECT`), a wrong vertex count, a
/// non-finite coordinate) no object changes. The result equals one
/// `dhcd_scene_update_positions` per entry, for every `threads`. With `count == 0` it does
/// nothing and the arrays may be NULL.
///
/// # Safety
/// `s` null or a live handle; `ids`, `positions` and `vertex_counts` hold `count` elements
/// each, and each non-null `positions[k]` holds `3 * vertex_counts[k]` floats.
#[no_mangle]
pub unsafe extern "C" fn dhcd_scene_update_many(
    s: *mut DhcdScene,
    ids: *const u64,
    positions: *const *const f32,
    vertex_counts: *const usize,
    count: usize,
    threads: u32,
) -> c_int {
    guard(|| {
        // SAFETY: caller's contract.
        let s = unsafe { handle(s, "scene")? };
        let par = par(threads)?;
        if count == 0 {
            return Ok(());
        }
        // SAFETY: caller's contract.
        let updates = unsafe { updates(ids, positions, vertex_counts, count)? };
        Ok(s.scene.update_many(&updates, par)?)
    })
}

/// Turns an object's self-collision on (non-zero) or off.
///
/// # Safety
/// `s` null or a live handle.
#[no_mangle]
pub unsafe extern "C" fn dhcd_scene_set_self_collision(
    s: *mut DhcdScene,
    id: u64,
    on: c_int,
) -> c_int {
    guard(|| {
        // SAFETY: caller's contract.
        let s = unsafe { handle(s, "scene")? };
        Ok(s.scene.set_self_collision(ObjectId(id), on != 0)?)
    })
}

/// Every contact of the scene's current poses into `*out` (release with
/// `dhcd_scene_contacts_free`): quadruples `[object_a, tri_a, object_b, tri_b]`, sorted,
/// `object_a < object_b` (`==` for self-contacts); `counters` are the totals.
///
/// # Safety
/// `s` null or a live handle; `out` null or valid for a write.
#[no_mangle]
pub unsafe extern "C" fn dhcd_scene_contacts(
    s: *mut DhcdScene,
    threads: u32,
    out: *mut DhcdSceneContacts,
) -> c_int {
    guard(|| {
        // SAFETY: caller's contract on `out`: empty until there are contacts.
        unsafe { write(out, NO_SCENE_CONTACTS, "out")? };
        // SAFETY: caller's contract.
        let s = unsafe { handle(s, "scene")? };
        let c = s.scene.contacts(par(threads)?);
        // SAFETY: as above.
        unsafe { write(out, scene_contacts_result(c), "out") }
    })
}

/// One simulation step: `dhcd_scene_update_many` with the same arguments, then
/// `dhcd_scene_contacts` into `*out`, in one trip to the thread pool (with several threads,
/// cheaper than the two calls: docs/PERFORMANCE.md). On error no object changes and `*out`
/// is empty. With `count == 0` the arrays may be NULL (no object moves).
///
/// # Safety
/// As `dhcd_scene_update_many` and `dhcd_scene_contacts`.
#[no_mangle]
pub unsafe extern "C" fn dhcd_scene_step(
    s: *mut DhcdScene,
    ids: *const u64,
    positions: *const *const f32,
    vertex_counts: *const usize,
    count: usize,
    threads: u32,
    out: *mut DhcdSceneContacts,
) -> c_int {
    guard(|| {
        // SAFETY: caller's contract on `out`: empty until there are contacts.
        unsafe { write(out, NO_SCENE_CONTACTS, "out")? };
        // SAFETY: caller's contract.
        let s = unsafe { handle(s, "scene")? };
        let par = par(threads)?;
        // SAFETY: caller's contract.
        let updates = unsafe { updates(ids, positions, vertex_counts, count)? };
        let c = s.scene.step(&updates, par)?;
        // SAFETY: as above.
        unsafe { write(out, scene_contacts_result(c), "out") }
    })
}

/// Releases the array of a `DhcdSceneContacts` and resets it to empty. Null, or an already
/// released or empty result, is a no-op.
///
/// # Safety
/// `c` null or a `DhcdSceneContacts` filled by this library and not modified since.
#[no_mangle]
pub unsafe extern "C" fn dhcd_scene_contacts_free(c: *mut DhcdSceneContacts) {
    let _ = guard(|| {
        // SAFETY: caller's contract.
        if let Some(c) = unsafe { c.as_mut() } {
            if !c.pairs.is_null() {
                let len = c.count * 4;
                // SAFETY: `pairs` came from `Box<[u64]>` of `4 * count` elements.
                drop(unsafe { Box::from_raw(std::ptr::slice_from_raw_parts_mut(c.pairs, len)) });
            }
            *c = NO_SCENE_CONTACTS;
        }
        Ok(())
    });
}
