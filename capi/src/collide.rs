//! Discrete collision detection (intersecting triangle pairs): the results `DhcdContacts`
//! (`dhcd_collide`, `dhcd_self_collide`) and `DhcdSceneContacts` (`dhcd_scene_contacts`,
//! `dhcd_scene_step`, in `scene`), each with its one conversion from the library's result
//! and its `*_free`, and the contact segments of a result's pairs.

use std::ffi::c_int;

use dhcd::Contacts;

use crate::error::{guard, null, Fail};
use crate::hierarchy::DhcdHierarchy;
use crate::marshal::{c_pairs, free_array, handle, par, slice, write, DhcdCounters, NO_COUNTERS};
use crate::DHCD_ERR_INVALID_ARGUMENT;

/// Contacts of `dhcd_collide` / `dhcd_self_collide`: `count` pairs, `pairs[2k]`,
/// `pairs[2k+1]` (original triangle indices), sorted. `pairs` is null when `count == 0`.
#[repr(C)]
#[derive(Debug)]
pub struct DhcdContacts {
    /// Row-major `[count][2]` array of `[tri of a, tri of b]` (self: `[ti, tj]`, `ti < tj`);
    /// freed by `dhcd_contacts_free`.
    pub pairs: *mut u32,
    /// Number of rows of `pairs`.
    pub count: usize,
    /// Work counted by the query.
    pub counters: DhcdCounters,
}

/// Contacts of `dhcd_scene_contacts`: `count` quadruples `[object_a, tri_a, object_b,
/// tri_b]` at `pairs[4k..4k+4]`, sorted. `pairs` is null when `count == 0`.
#[repr(C)]
#[derive(Debug)]
pub struct DhcdSceneContacts {
    /// Row-major `[count][4]` array of `[object_a, tri_a, object_b, tri_b]`: `object_a <
    /// object_b`, or `object_a == object_b` and `tri_a < tri_b` for a self-contact; freed by
    /// `dhcd_scene_contacts_free`.
    pub pairs: *mut u64,
    /// Number of rows of `pairs`.
    pub count: usize,
    /// Work counted by the query, summed over the object pairs queried.
    pub counters: DhcdCounters,
}

const NO_CONTACTS: DhcdContacts = DhcdContacts {
    pairs: std::ptr::null_mut(),
    count: 0,
    counters: NO_COUNTERS,
};

pub(crate) const NO_SCENE_CONTACTS: DhcdSceneContacts = DhcdSceneContacts {
    pairs: std::ptr::null_mut(),
    count: 0,
    counters: NO_COUNTERS,
};

/// The C result of a pair's or an object's contacts.
fn contacts_out(c: Contacts) -> DhcdContacts {
    DhcdContacts {
        count: c.pairs.len(),
        pairs: c_pairs(c.pairs),
        counters: c.counters.into(),
    }
}

/// A scene's contacts as the C result (the array owned by the caller until
/// `dhcd_scene_contacts_free`).
pub(crate) fn scene_contacts_out(c: dhcd::SceneContacts) -> DhcdSceneContacts {
    DhcdSceneContacts {
        count: c.pairs.len(),
        pairs: c_pairs(c.pairs),
        counters: c.counters.into(),
    }
}

/// All intersecting triangle pairs `[tri of a, tri of b]` between two hierarchies of the
/// same method, into `*out` (release with `dhcd_contacts_free`). `a` and `b` must be
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
            // SAFETY: `pairs` came from `c_pairs` of `2 * count` elements, or is null.
            unsafe { free_array(c.pairs, 2 * c.count) };
            *c = NO_CONTACTS;
        }
        Ok(())
    });
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
            // SAFETY: `pairs` came from `c_pairs` of `4 * count` elements, or is null.
            unsafe { free_array(c.pairs, 4 * c.count) };
            *c = NO_SCENE_CONTACTS;
        }
        Ok(())
    });
}
