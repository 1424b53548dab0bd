//! Values across the boundary: C arrays in (positions, triangles, motions, with their null,
//! alignment and size checks), handles and output pointers, the common arguments (`method`,
//! `levels`, `threads`), and result arrays out ([`c_array`], [`c_pairs`], released by
//! [`free_array`]) with the work counters every result carries ([`DhcdCounters`]).

use std::ffi::c_int;

use dhcd::bv::Method;
use dhcd::Counters;
use dhcd::Mesh;
use dhcd::Motion;
use dhcd::Options;
use dhcd::Par;

use crate::error::{null, Fail};
use crate::DHCD_ERR_INVALID_ARGUMENT;

/// Counted work of a query (the cost model's `N_V`, `N_P`, `N_U`, and the contacts).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct DhcdCounters {
    /// `N_V`: bounding-volume pairs tested for overlap (CCD: node pairs tested over the step).
    pub bv_tests: u64,
    /// `N_P`: pairs given to the exact test (triangle pairs; feature pairs for proximity and
    /// CCD).
    pub prim_tests: u64,
    /// `N_U`: bounding volumes refitted (CCD: bounds fitted over the step).
    pub bv_updates: u64,
    /// Pairs reported: intersecting triangle pairs, or the rows of a proximity or CCD result.
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

/// The counters of no work: those of an empty result.
pub(crate) const NO_COUNTERS: DhcdCounters = DhcdCounters {
    bv_tests: 0,
    prim_tests: 0,
    bv_updates: 0,
    contacts: 0,
};

/// A borrowed C array of `len` elements of `T`.
///
/// # Safety
/// If `ptr` is non-null and aligned, it must point to `len` initialised `T` that stay valid
/// and unmodified for `'a`.
pub(crate) unsafe fn slice<'a, T>(ptr: *const T, len: usize, what: &str) -> Result<&'a [T], Fail> {
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
pub(crate) unsafe fn positions<'a>(ptr: *const f32, count: usize) -> Result<&'a [[f32; 3]], Fail> {
    // SAFETY: `[f32; 3]` has the alignment of `f32` and the size of three; same contract.
    unsafe { slice(ptr.cast::<[f32; 3]>(), count, "positions") }
}

/// `count` `double` positions (`3 * count` doubles).
///
/// # Safety
/// As [`slice`], for `3 * count` doubles.
pub(crate) unsafe fn positions_f64<'a>(
    ptr: *const f64,
    count: usize,
) -> Result<&'a [[f64; 3]], Fail> {
    // SAFETY: `[f64; 3]` has the alignment of `f64` and the size of three; same contract.
    unsafe { slice(ptr.cast::<[f64; 3]>(), count, "positions") }
}

/// # Safety
/// As [`slice`], for `3 * count` `u32`.
pub(crate) unsafe fn triangles<'a>(ptr: *const u32, count: usize) -> Result<&'a [[u32; 3]], Fail> {
    // SAFETY: `[u32; 3]` has the alignment of `u32` and the size of three; same contract.
    unsafe { slice(ptr.cast::<[u32; 3]>(), count, "triangles") }
}

/// # Safety
/// `ptr` null or a live handle from the matching `*_new`, not used elsewhere meanwhile.
pub(crate) unsafe fn handle<'a, T>(ptr: *mut T, what: &str) -> Result<&'a mut T, Fail> {
    // SAFETY: the caller's contract: null or a live, exclusively used handle.
    unsafe { ptr.as_mut() }.ok_or_else(|| null(what))
}

/// # Safety
/// `ptr` null or valid for a write of `T`.
pub(crate) unsafe fn write<T>(ptr: *mut T, value: T, what: &str) -> Result<(), Fail> {
    if ptr.is_null() {
        return Err(null(what));
    }
    // SAFETY: non-null, and valid for writes by the caller's contract; `write` does not
    // drop the (possibly uninitialised) old value.
    unsafe { ptr.write(value) };
    Ok(())
}

pub(crate) fn method_of(m: c_int) -> Result<Method, Fail> {
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
pub(crate) fn options(levels: u32) -> Options {
    Options {
        levels: (levels != 0).then_some(levels as usize),
        ..Options::default()
    }
}

/// A `threads` argument, checked where every thread count is (`Par::threads`).
pub(crate) fn par(threads: u32) -> Result<Par, Fail> {
    Ok(Par::threads(threads as usize)?)
}

/// A validated mesh from C arrays.
///
/// # Safety
/// As [`positions`] and [`triangles`].
pub(crate) unsafe fn mesh(
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

/// A validated `f64` mesh from C arrays.
///
/// # Safety
/// As [`positions_f64`] and [`triangles`].
pub(crate) unsafe fn mesh_f64(
    pos: *const f64,
    vertex_count: usize,
    tris: *const u32,
    triangle_count: usize,
) -> Result<Mesh, Fail> {
    // SAFETY: forwarded contract.
    let (p, t) = unsafe {
        (
            positions_f64(pos, vertex_count)?,
            triangles(tris, triangle_count)?,
        )
    };
    Ok(Mesh::new_f64(p.to_vec(), t.to_vec())?)
}

/// The motion of `vertex_count` vertices from `x0` (t = 0) to `x1` (t = 1), `3 *
/// vertex_count` doubles each.
///
/// # Safety
/// As [`positions_f64`], for both arrays.
pub(crate) unsafe fn motion<'a>(
    x0: *const f64,
    x1: *const f64,
    vertex_count: usize,
    what: &str,
) -> Result<Motion<'a>, Fail> {
    let named = |Fail(code, msg): Fail| Fail(code, format!("{what}: {msg}"));
    // SAFETY: forwarded contract.
    let (p0, p1) = unsafe {
        (
            positions_f64(x0, vertex_count).map_err(named)?,
            positions_f64(x1, vertex_count).map_err(named)?,
        )
    };
    Ok(Motion::new(p0, p1))
}

/// `items` as an array the caller owns until the matching `*_free` (which rebuilds the
/// `Box<[T]>` of `items.len()` elements with [`free_array`]), or null when there are none.
pub(crate) fn c_array<T>(items: Vec<T>) -> *mut T {
    if items.is_empty() {
        return std::ptr::null_mut();
    }
    Box::into_raw(items.into_boxed_slice()).cast::<T>()
}

/// `pairs` flattened into an array the caller owns until the matching `*_free` (which
/// rebuilds the `Box<[T]>` of `N * count` elements), or null when there are none.
pub(crate) fn c_pairs<T, const N: usize>(pairs: Vec<[T; N]>) -> *mut T {
    c_array(pairs.into_iter().flatten().collect())
}

/// Releases an array made by [`c_array`] (or [`c_pairs`]) of `len` elements; null is a
/// no-op.
///
/// # Safety
/// `ptr` null or from `c_array` of exactly `len` elements, not released yet.
pub(crate) unsafe fn free_array<T>(ptr: *mut T, len: usize) {
    if !ptr.is_null() {
        // SAFETY: `ptr` came from a `Box<[T]>` of `len` elements (caller's contract).
        drop(unsafe { Box::from_raw(std::ptr::slice_from_raw_parts_mut(ptr, len)) });
    }
}
