//! A scene of many objects: `DhcdScene`, its objects (add, remove, position updates,
//! self-collision) and its queries. Each query's result type, its conversion from the
//! library's result and its `*_free` are in the query family's file (`collide`,
//! `proximity`, `ccd`, `contact`); a query's entry here parses the arguments ([`updates`],
//! [`motions`]), runs the library's scene query and writes that conversion.

use std::ffi::c_int;

use dhcd::contact::StepOptions;
use dhcd::scene::{ObjectId, Scene};
use dhcd::{Mesh, Motion};

use crate::ccd::{ccd_query, scene_impacts_out, DhcdSceneImpacts, NO_SCENE_IMPACTS};
use crate::collide::{scene_contacts_out, DhcdSceneContacts, NO_SCENE_CONTACTS};
use crate::contact::{contact_set_out, DhcdContactSet, NO_CONTACT_SET};
use crate::error::{guard, null, Fail};
use crate::marshal::{
    handle, mesh, mesh_f64, method_of, motion, options, par, positions, positions_f64, slice, write,
};
use crate::proximity::{scene_proximity_out, DhcdSceneProximity, NO_SCENE_PROXIMITY};

/// Opaque: a scene of many objects.
pub struct DhcdScene {
    pub(crate) scene: Scene,
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
        // SAFETY: caller's contract on the scene, the arrays and `out_id`.
        unsafe {
            scene_add(s, self_collision, out_id, || {
                mesh(positions, vertex_count, triangles, triangle_count)
            })
        }
    })
}

/// `dhcd_scene_add` for `double` positions (`3 * vertex_count` doubles): an `f64` object
/// (as `dhcd_hierarchy_new_f64`), updated only by `dhcd_scene_update_positions_f64`
/// (`dhcd_scene_update_positions`, `dhcd_scene_update_many` and `dhcd_scene_step` refuse
/// it: `DHCD_ERR_PRECISION`). A scene may hold objects of both precisions.
///
/// # Safety
/// As `dhcd_scene_add`, with `positions` holding `3 * vertex_count` doubles.
#[no_mangle]
pub unsafe extern "C" fn dhcd_scene_add_f64(
    s: *mut DhcdScene,
    positions: *const f64,
    vertex_count: usize,
    triangles: *const u32,
    triangle_count: usize,
    self_collision: c_int,
    out_id: *mut u64,
) -> c_int {
    guard(|| {
        // SAFETY: caller's contract on the scene, the arrays and `out_id`.
        unsafe {
            scene_add(s, self_collision, out_id, || {
                mesh_f64(positions, vertex_count, triangles, triangle_count)
            })
        }
    })
}

/// Adds the mesh `mesh()` to a scene; its id into `*out_id`.
///
/// # Safety
/// `s` null or a live handle; `out_id` null or valid for a write; `mesh` reads only arrays
/// valid by the caller's contract.
unsafe fn scene_add(
    s: *mut DhcdScene,
    self_collision: c_int,
    out_id: *mut u64,
    mesh: impl FnOnce() -> Result<Mesh, Fail>,
) -> Result<(), Fail> {
    // SAFETY: caller's contract.
    let s = unsafe { handle(s, "scene")? };
    if out_id.is_null() {
        return Err(null("out_id"));
    }
    let mesh = mesh()?;
    let id = s.scene.add(&mesh)?;
    s.scene.set_self_collision(id, self_collision != 0)?;
    // SAFETY: non-null, valid for a write (caller's contract).
    unsafe { write(out_id, id.0, "out_id") }
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

/// New positions of an object (`3 * vertex_count` floats; an `f64` object refuses them:
/// `DHCD_ERR_PRECISION`). On error nothing changes.
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

/// New `double` positions of an `f64` object (`3 * vertex_count` doubles; added by
/// `dhcd_scene_add_f64`; an `f32` object refuses them: `DHCD_ERR_PRECISION`). On error
/// nothing changes.
///
/// # Safety
/// `s` null or a live handle; `positions` holds `3 * vertex_count` doubles.
#[no_mangle]
pub unsafe extern "C" fn dhcd_scene_update_positions_f64(
    s: *mut DhcdScene,
    id: u64,
    positions: *const f64,
    vertex_count: usize,
) -> c_int {
    guard(|| {
        // SAFETY: caller's contract.
        let (s, p) = unsafe { (handle(s, "scene")?, positions_f64(positions, vertex_count)?) };
        Ok(s.scene.update_positions_f64(ObjectId(id), p)?)
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

/// New positions of several objects in one call: entry `k` gives object `ids[k]` the
/// `3 * vertex_counts[k]` floats at `positions[k]` (as in `dhcd_scene_update_positions`).
/// `ids`, `positions` and `vertex_counts` hold `count` elements each; each id at most once.
/// Every entry is checked before any is applied: on error (a null or misaligned array, an
/// unknown id, an id given twice (`DHCD_ERR_REPEATED_OBJECT`), a wrong vertex count, a
/// non-finite coordinate, an `f64` object (`DHCD_ERR_PRECISION`: those take
/// `dhcd_scene_update_positions_f64`)) no object changes. The result equals one
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

// The scene's queries: each parses its arguments here, runs the library's scene query and
// writes its family's result (a query over a step takes its motions from `motions`).

/// One object's motion over a step.
type ObjectMotion<'a> = (ObjectId, Motion<'a>);

/// The entries of a scene's step query (`dhcd_scene_ccd`): object `ids[k]` moves from
/// `x0[k]` (t = 0) to `x1[k]` (t = 1).
///
/// # Safety
/// `ids`, `x0`, `x1` and `vertex_counts` hold `count` elements each (any of them may be null
/// when `count == 0`: no entries), and each non-null `x0[k]`, `x1[k]` holds
/// `3 * vertex_counts[k]` doubles, alive for `'a`.
unsafe fn motions<'a>(
    ids: *const u64,
    x0: *const *const f64,
    x1: *const *const f64,
    vertex_counts: *const usize,
    count: usize,
) -> Result<Vec<ObjectMotion<'a>>, Fail> {
    if count == 0 {
        return Ok(Vec::new());
    }
    // SAFETY: the four arrays hold `count` elements (caller's contract).
    let (ids, p0, p1, counts) = unsafe {
        (
            slice(ids, count, "ids")?,
            slice(x0, count, "x0")?,
            slice(x1, count, "x1")?,
            slice(vertex_counts, count, "vertex_counts")?,
        )
    };
    (0..count)
        .map(|k| {
            // SAFETY: `x0[k]`, `x1[k]` hold `3 * vertex_counts[k]` doubles (caller's
            // contract).
            let m = unsafe { motion(p0[k], p1[k], counts[k], &format!("motion {k}"))? };
            Ok((ObjectId(ids[k]), m))
        })
        .collect()
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
        unsafe { write(out, scene_contacts_out(c), "out") }
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
        unsafe { write(out, scene_contacts_out(c), "out") }
    })
}

/// Every vertex-triangle and edge-edge pair within distance `d` (finite, `>= 0`; else
/// `DHCD_ERR_INVALID_ARGUMENT`) between every two objects, and inside every object with
/// self-collision on, into `*out` (see `DhcdSceneProximity`; release with
/// `dhcd_scene_proximity_free`). Objects whose root boxes are farther apart than `d` cost
/// one box test.
///
/// # Safety
/// `s` null or a live handle; `out` null or valid for a write.
#[no_mangle]
pub unsafe extern "C" fn dhcd_scene_proximity(
    s: *mut DhcdScene,
    d: f64,
    threads: u32,
    out: *mut DhcdSceneProximity,
) -> c_int {
    guard(|| {
        // SAFETY: caller's contract on `out`: empty until there is a result.
        unsafe { write(out, NO_SCENE_PROXIMITY, "out")? };
        // SAFETY: caller's contract.
        let s = unsafe { handle(s, "scene")? };
        let p = s.scene.proximity(d, par(threads)?)?;
        // SAFETY: as above.
        unsafe { write(out, scene_proximity_out(p), "out") }
    })
}

/// Continuous collision detection of the whole scene over one step: entry `k` moves object
/// `ids[k]` from `x0[k]` (t = 0) to `x1[k]` (t = 1), `3 * vertex_counts[k]` doubles each (as
/// in `dhcd_ccd`; the object's stored pose is not read and the scene does not change); every
/// object not listed stays at its stored pose. Every object pair whose boxes over the step
/// come within `min_distance`, and every object with self-collision on, is queried as by
/// `dhcd_ccd` / `dhcd_self_ccd`, into `*out` (see `DhcdSceneImpacts`; release with
/// `dhcd_scene_impacts_free`). `earliest` non-zero: only the earliest time of impact over
/// the scene and every pair whose own time is within 1e-12 of it. Everything is checked before any work: an unknown
/// id (`DHCD_ERR_UNKNOWN_OBJECT`), an id given twice (`DHCD_ERR_REPEATED_OBJECT`), a bad
/// `t_max` or `min_distance` (`DHCD_ERR_INVALID_ARGUMENT`), a wrong vertex count
/// (`DHCD_ERR_LENGTH_MISMATCH`), a non-finite coordinate (`DHCD_ERR_INVALID_MESH`). The
/// result does not depend on `threads` (the work counters of earliest mode may). With
/// `count == 0` the arrays may be NULL (every object still).
///
/// # Safety
/// `s` null or a live handle; `ids`, `x0`, `x1` and `vertex_counts` hold `count` elements
/// each, and each non-null `x0[k]`, `x1[k]` holds `3 * vertex_counts[k]` doubles; `out`
/// null or valid for a write.
#[no_mangle]
pub unsafe extern "C" fn dhcd_scene_ccd(
    s: *mut DhcdScene,
    ids: *const u64,
    x0: *const *const f64,
    x1: *const *const f64,
    vertex_counts: *const usize,
    count: usize,
    t_max: f64,
    min_distance: f64,
    earliest: c_int,
    threads: u32,
    out: *mut DhcdSceneImpacts,
) -> c_int {
    guard(|| {
        // SAFETY: caller's contract on `out`: empty until there is a result.
        unsafe { write(out, NO_SCENE_IMPACTS, "out")? };
        // SAFETY: caller's contract.
        let s = unsafe { handle(s, "scene")? };
        let par = par(threads)?;
        // SAFETY: caller's contract on the arrays.
        let motions = unsafe { motions(ids, x0, x1, vertex_counts, count)? };
        let q = ccd_query(t_max, min_distance, earliest);
        let p = s.scene.ccd(&motions, &q, par)?;
        // SAFETY: caller's contract on `out` (written above).
        unsafe { write(out, scene_impacts_out(p), "out") }
    })
}

/// Every pair of features within `dhat` (finite, `>= 0`) between every two objects, and
/// inside every object with self-collision on, once, into `*out` (see `DhcdContactSet`;
/// release with `dhcd_contact_set_free`), in one global numbering: each object's vertices
/// and edges follow those of the objects added before it and still in the scene
/// (`dhcd_scene_vertex_offset`, `dhcd_scene_edge_offset`). The mollifier thresholds come
/// from each object's positions when it was added.
///
/// # Safety
/// `s` null or a live handle; `out` null or valid for a write.
#[no_mangle]
pub unsafe extern "C" fn dhcd_scene_contact_set(
    s: *mut DhcdScene,
    dhat: f64,
    threads: u32,
    out: *mut DhcdContactSet,
) -> c_int {
    guard(|| {
        // SAFETY: caller's contract on `out`: empty until there is a result.
        unsafe { write(out, NO_CONTACT_SET, "out")? };
        // SAFETY: caller's contract.
        let s = unsafe { handle(s, "scene")? };
        let c = s.scene.contact_set(dhat, par(threads)?)?;
        // SAFETY: as above.
        unsafe { write(out, contact_set_out(c), "out") }
    })
}

/// Where object `id`'s vertices start in the scene's global numbering (that of
/// `dhcd_scene_contact_set`), into `*out`.
///
/// # Safety
/// `s` null or a live handle; `out` null or valid for a write.
#[no_mangle]
pub unsafe extern "C" fn dhcd_scene_vertex_offset(
    s: *const DhcdScene,
    id: u64,
    out: *mut u64,
) -> c_int {
    guard(|| {
        // SAFETY: null or a live handle (caller's contract); only read.
        let s = unsafe { s.as_ref() }.ok_or_else(|| null("scene"))?;
        let offset = s.scene.vertex_offset(ObjectId(id))?;
        // SAFETY: caller's contract on `out`.
        unsafe { write(out, offset, "out") }
    })
}

/// Where object `id`'s edge ids start in the scene's global numbering: the edge count
/// (`dhcd_hierarchy_edges`) of the objects before it, into `*out`.
///
/// # Safety
/// `s` null or a live handle; `out` null or valid for a write.
#[no_mangle]
pub unsafe extern "C" fn dhcd_scene_edge_offset(
    s: *const DhcdScene,
    id: u64,
    out: *mut u64,
) -> c_int {
    guard(|| {
        // SAFETY: null or a live handle (caller's contract); only read.
        let s = unsafe { s.as_ref() }.ok_or_else(|| null("scene"))?;
        let offset = s.scene.edge_offset(ObjectId(id))?;
        // SAFETY: caller's contract on `out`.
        unsafe { write(out, offset, "out") }
    })
}

/// The collision-free step size of the whole scene over one step, into `*step`: the largest
/// fraction in `[0, 1]` of the step that keeps every pair (between two objects, and inside
/// every object with self-collision on) at least `min_distance + (1 - rescaling) (d0 -
/// min_distance)` apart, `d0` its distance at t0 (`dhcd_collision_free_stepsize`'s rule).
/// The motions are as in `dhcd_scene_ccd` (entry `k` moves object `ids[k]`; every other
/// object stays at its stored pose; the scene does not change). Everything is checked
/// before any work, as in `dhcd_scene_ccd`; `rescaling` outside `(0, 1]` or a bad
/// `min_distance` is `DHCD_ERR_INVALID_ARGUMENT`. The step does not depend on `threads`.
///
/// # Safety
/// As `dhcd_scene_ccd` for `s`, `ids`, `x0`, `x1`, `vertex_counts` and `count`; `step` null
/// or valid for a write.
#[no_mangle]
#[allow(clippy::too_many_arguments)]
pub unsafe extern "C" fn dhcd_scene_collision_free_stepsize(
    s: *mut DhcdScene,
    ids: *const u64,
    x0: *const *const f64,
    x1: *const *const f64,
    vertex_counts: *const usize,
    count: usize,
    min_distance: f64,
    rescaling: f64,
    threads: u32,
    step: *mut f64,
) -> c_int {
    guard(|| {
        // SAFETY: caller's contract.
        let s = unsafe { handle(s, "scene")? };
        let par = par(threads)?;
        // SAFETY: caller's contract on the arrays.
        let motions = unsafe { motions(ids, x0, x1, vertex_counts, count)? };
        let o = StepOptions {
            min_distance,
            rescaling,
        };
        let r = s.scene.collision_free_stepsize(&motions, &o, par)?;
        // SAFETY: caller's contract on `step`.
        unsafe { write(step, r.step, "step") }
    })
}
