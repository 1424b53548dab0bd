//! The hierarchy of one mesh: `DhcdHierarchy` and its `dhcd_hierarchy_*` calls (build from
//! `float` or `double` positions, release, method, precision, position updates). Its
//! queries are in the families' files (`collide`, `proximity`, `ccd`, `contact`).

use std::ffi::c_int;

use dhcd::AnyHierarchy;
use dhcd::{Mesh, Precision, Workspace};

use crate::error::{guard, null, Fail};
use crate::marshal::{handle, mesh, mesh_f64, method_of, options, positions, positions_f64, write};
use crate::{DHCD_ERR_INVALID_ARGUMENT, DHCD_PRECISION_F32, DHCD_PRECISION_F64};

/// Opaque: one object's hierarchy (and its query scratch).
pub struct DhcdHierarchy {
    pub(crate) h: AnyHierarchy,
    pub(crate) ws: Workspace,
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
        // SAFETY: the caller's contract on `out` and on the arrays.
        unsafe {
            new_hierarchy(method, levels, out, || {
                mesh(positions, vertex_count, triangles, triangle_count)
            })
        }
    })
}

/// `dhcd_hierarchy_new` for `double` positions (`3 * vertex_count` doubles): an `f64`
/// hierarchy, whose answers (contacts, proximity) are exact for the `double` coordinates as
/// given. Bounding volumes stay `float` records rounded outward, so every coordinate must
/// round to a finite `float` (magnitude below about 3.4e38; else `DHCD_ERR_INVALID_MESH`).
/// It takes only `double` updates (`dhcd_hierarchy_update_positions_f64`).
///
/// # Safety
/// As `dhcd_hierarchy_new`, with `positions` holding `3 * vertex_count` doubles.
#[no_mangle]
pub unsafe extern "C" fn dhcd_hierarchy_new_f64(
    method: c_int,
    levels: u32,
    positions: *const f64,
    vertex_count: usize,
    triangles: *const u32,
    triangle_count: usize,
    out: *mut *mut DhcdHierarchy,
) -> c_int {
    guard(|| {
        // SAFETY: the caller's contract on `out` and on the arrays.
        unsafe {
            new_hierarchy(method, levels, out, || {
                mesh_f64(positions, vertex_count, triangles, triangle_count)
            })
        }
    })
}

/// A new hierarchy of the mesh `mesh()` into `*out` (NULL until there is one).
///
/// # Safety
/// `out` null or valid for a write; `mesh` reads only arrays valid by the caller's contract.
unsafe fn new_hierarchy(
    method: c_int,
    levels: u32,
    out: *mut *mut DhcdHierarchy,
    mesh: impl FnOnce() -> Result<Mesh, Fail>,
) -> Result<(), Fail> {
    // SAFETY: caller's contract on `out`: NULL until there is a handle.
    unsafe { write(out, std::ptr::null_mut(), "out")? };
    let m = method_of(method)?;
    let mesh = mesh()?;
    let h = AnyHierarchy::new(m, &mesh, options(levels))?;
    let boxed = Box::new(DhcdHierarchy {
        h,
        ws: Workspace::default(),
    });
    // SAFETY: `out` is non-null and valid for a write (caller's contract).
    unsafe { write(out, Box::into_raw(boxed), "out") }
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

/// The method of a hierarchy (`DHCD_METHOD_*`) into `*out`.
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
/// count). An `f64` hierarchy refuses them (`DHCD_ERR_PRECISION`: rounding its positions
/// would change its answers; see `dhcd_hierarchy_update_positions_f64`). On error the
/// hierarchy is unchanged.
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

/// New `double` positions of an `f64` hierarchy (`3 * vertex_count` doubles; see
/// `dhcd_hierarchy_new_f64`). An `f32` hierarchy refuses them (`DHCD_ERR_PRECISION`), as an
/// `f64` one refuses `dhcd_hierarchy_update_positions`. On error the hierarchy is unchanged.
///
/// # Safety
/// `h` null or a live handle; `positions` holds `3 * vertex_count` doubles.
#[no_mangle]
pub unsafe extern "C" fn dhcd_hierarchy_update_positions_f64(
    h: *mut DhcdHierarchy,
    positions: *const f64,
    vertex_count: usize,
) -> c_int {
    guard(|| {
        // SAFETY: caller's contract.
        let (h, p) = unsafe {
            (
                handle(h, "hierarchy")?,
                positions_f64(positions, vertex_count)?,
            )
        };
        h.h.update_positions_f64(p)?;
        Ok(())
    })
}

/// The precision of a hierarchy's positions into `*out`: `DHCD_PRECISION_F32` (32, built by
/// `dhcd_hierarchy_new`) or `DHCD_PRECISION_F64` (64, built by `dhcd_hierarchy_new_f64`).
///
/// # Safety
/// `h` null or a live handle; `out` null or valid for a write.
#[no_mangle]
pub unsafe extern "C" fn dhcd_hierarchy_precision(
    h: *const DhcdHierarchy,
    out: *mut c_int,
) -> c_int {
    guard(|| {
        // SAFETY: null or a live handle (caller's contract); only read.
        let h = unsafe { h.as_ref() }.ok_or_else(|| null("hierarchy"))?;
        let code = precision_code(h.h.precision())?;
        // SAFETY: caller's contract on `out`.
        unsafe { write(out, code, "out") }
    })
}

/// The C number of a precision (`DHCD_PRECISION_*`).
fn precision_code(p: Precision) -> Result<c_int, Fail> {
    match p {
        Precision::F32 => Ok(DHCD_PRECISION_F32),
        Precision::F64 => Ok(DHCD_PRECISION_F64),
        // `Precision` is non-exhaustive: a precision added later has no C number yet.
        other => Err(Fail(
            DHCD_ERR_INVALID_ARGUMENT,
            format!("precision {other} has no C ABI number"),
        )),
    }
}
