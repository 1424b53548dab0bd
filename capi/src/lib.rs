//! The C ABI of dhcd (`include/dhcd.h`; see `docs/LINKING_FROM_C.md`): the only `unsafe` code
//! of the project outside the SIMD kernels.
//!
//! Conventions:
//! - every fallible function returns an `int`: [`DHCD_OK`] (0) or a negative `DHCD_ERR_*`
//!   code, and then [`dhcd_last_error_message`] describes the failure (per thread); the
//!   single-pair CCD calls return 1 (collide) or 0 (do not) on success;
//! - no panic crosses the boundary: every entry runs inside `catch_unwind` and a panic
//!   becomes [`DHCD_ERR_PANIC`];
//! - null pointers, misaligned arrays, mismatched lengths and hierarchies of different methods
//!   are errors, never undefined behaviour on the library's side;
//! - handles (`DhcdHierarchy`, `DhcdScene`) are created by `*_new` and released by
//!   `*_free`; results (`DhcdContacts`, `DhcdSceneContacts`, `DhcdProximity`,
//!   `DhcdSceneProximity`, `DhcdImpacts`) own library-allocated arrays released by their
//!   `*_free` (an array is null when its count is 0);
//! - a handle must not be used from two threads at once (queries refit it lazily).
//!
//! - a function with a handle or result output (`*out`) empties it first (NULL handle,
//!   empty result), so it is empty after any error; scalar outputs (`dhcd_hierarchy_method`,
//!   `dhcd_hierarchy_precision`, `dhcd_scene_add`'s id, `dhcd_contact_segments`' segments)
//!   are written only on success, as is the `toi` of `dhcd_vertex_face_ccd` and
//!   `dhcd_edge_edge_ccd`;
//! - `*_f64` calls take `double` positions and make or update `f64` hierarchies and objects
//!   (exact for the doubles); positions of the other precision are `DHCD_ERR_PRECISION`;
//! - continuous collision detection (`dhcd_self_ccd`, `dhcd_ccd`) takes `double` positions
//!   at t0 and t1 for a hierarchy of either precision.
//!
//! `threads` arguments: `1` runs on the calling thread, `0` on rayon's global pool (all
//! cores), `n` on a pool of `n` threads but never more than the machine's cores; above
//! `dhcd::Par::MAX_THREADS` (1024) is `DHCD_ERR_INVALID_ARGUMENT`. Results never depend on it.
#![warn(missing_docs)]

mod contact;
mod control;

pub use contact::{
    dhcd_collision_free_stepsize, dhcd_collision_free_stepsize_pair, dhcd_contact_set,
    dhcd_contact_set_free, dhcd_contact_set_gradient, dhcd_contact_set_hessian,
    dhcd_distance_gradient, dhcd_distance_hessian, dhcd_distance_sq, dhcd_hierarchy_edges,
    dhcd_self_contact_set, DhcdContactSet, DHCD_CLOSEST_NONE,
};
pub use control::{
    dhcd_cancel_free, dhcd_cancel_new, dhcd_cancel_reset, dhcd_cancel_set,
    dhcd_hierarchy_set_control, dhcd_scene_set_control, DhcdCancel, DhcdPoll,
};

use std::cell::RefCell;
use std::ffi::{c_char, c_int, CString};
use std::panic::{catch_unwind, AssertUnwindSafe};

use dhcd::bv::Method;
use dhcd::ccd::CcdOptions;
use dhcd::error::Error;
use dhcd::scene::{ObjectId, Scene};
use dhcd::AnyHierarchy;
use dhcd::Counters;
use dhcd::Options;
use dhcd::Par;
use dhcd::{
    CcdMode, CcdQuery, Contacts, Impacts, Motion, Proximity, SceneImpacts, SceneProximity,
    Workspace,
};
use dhcd::{Mesh, Precision};

/// Success.
pub const DHCD_OK: c_int = 0;
/// A required pointer argument is null.
pub const DHCD_ERR_NULL: c_int = -1;
/// A bad argument: unknown method, levels out of range, misaligned or oversized array,
/// the same hierarchy passed twice to `dhcd_collide`, `dhcd_proximity` or `dhcd_ccd`, a
/// thread count above 1024, a proximity distance or CCD minimum distance that is
/// negative, NaN or infinite, a CCD time limit outside `[0, 1]` or NaN, a NaN or infinite
/// coordinate of a single CCD query (`dhcd_vertex_face_ccd`, `dhcd_edge_edge_ccd`).
pub const DHCD_ERR_INVALID_ARGUMENT: c_int = -2;
/// The mesh is invalid: no vertices or triangles, an index out of range, a repeated index
/// in a triangle, a non-finite coordinate, a `double` coordinate beyond the `float` range
/// (about 3.4e38: bounding volumes are `float`); likewise for the positions at t0 and t1
/// of `dhcd_self_ccd` and `dhcd_ccd`.
pub const DHCD_ERR_INVALID_MESH: c_int = -3;
/// A position update (or CCD positions at t0 and t1) whose vertex count differs from the
/// mesh's.
pub const DHCD_ERR_LENGTH_MISMATCH: c_int = -4;
/// Two hierarchies of different methods.
pub const DHCD_ERR_WRONG_KIND: c_int = -5;
/// No object with this id in the scene.
pub const DHCD_ERR_UNKNOWN_OBJECT: c_int = -6;
/// A contact pair that does not intersect in the current pose (contact segments).
pub const DHCD_ERR_STALE_CONTACT: c_int = -7;
/// A bug in dhcd (a caught panic).
pub const DHCD_ERR_PANIC: c_int = -8;
/// The same object id given more than once in one `dhcd_scene_update_many`.
pub const DHCD_ERR_REPEATED_OBJECT: c_int = -9;
/// Positions of the other precision: `float` positions for an `f64` hierarchy or object
/// (built by `dhcd_hierarchy_new_f64` / `dhcd_scene_add_f64`), or `double` positions for an
/// `f32` one.
pub const DHCD_ERR_PRECISION: c_int = -10;
/// A query would return more result pairs than its limit (`dhcd_hierarchy_set_control`,
/// `dhcd_scene_set_control`); the message names the count reached and the limit.
pub const DHCD_ERR_OUTPUT_LIMIT: c_int = -11;
/// A result buffer could not be allocated.
pub const DHCD_ERR_OUT_OF_MEMORY: c_int = -12;
/// The query was stopped by its cancel token or poll callback.
pub const DHCD_ERR_CANCELLED: c_int = -13;

/// The default limit on the result pairs of one query (2^25).
pub const DHCD_DEFAULT_MAX_PAIRS: u64 = 1 << 25;
/// No limit on result pairs.
pub const DHCD_NO_LIMIT: u64 = u64::MAX;

/// `dhcd_hierarchy_precision` of a hierarchy built from `float` positions.
pub const DHCD_PRECISION_F32: c_int = 32;
/// `dhcd_hierarchy_precision` of a hierarchy built from `double` positions.
pub const DHCD_PRECISION_F64: c_int = 64;

// The methods' numbers (`DHCD_METHOD_DH` = 0, ...) are not constants here: they are
// `Method::code()`, from the library's table of methods, and the header's `DHCD_METHOD_*`
// defines are generated from that table with the rest of the header (capi/tests/capi.rs).
// Likewise the distance types' numbers (`DHCD_PT_*`, `DHCD_EE_*`) are the library's
// `PointTriangle` / `EdgeEdge` discriminants (IPC's), generated from their `ALL` tables.

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

/// Feature pairs within a distance, from `dhcd_proximity` / `dhcd_self_proximity` (release
/// with `dhcd_proximity_free`). Three lists, each of `*_count` rows, sorted by its index
/// rows; every row has its squared distance (`*_distance_sq[k]`) and the type of its closest
/// sub-features (`*_type[k]`: a `DHCD_PT_*` for vertex-face and face-vertex rows, a
/// `DHCD_EE_*` for edge-edge rows, IPC's distance types). Indices are original vertex and
/// triangle indices; every array is null when its count is 0.
/// - `vertex_face`: `[vertex, triangle]` at `vertex_face[2k..2k+2]`: a vertex of `a` and a
///   triangle of `b` (self: a vertex and a triangle not containing it);
/// - `face_vertex`: `[triangle of a, vertex of b]` (pair queries only; empty for self);
/// - `edge_edge`: `[a0, a1, b0, b1]` at `edge_edge[4k..4k+4]`, an edge of `a` and one of
///   `b` (self: two edges sharing no vertex, `(a0, a1) < (b0, b1)`), each as its two
///   vertices, smaller first (`DHCD_EE_EA0_*` names `a0`).
///
/// `counters.prim_tests` counts the feature pairs given to the exact test,
/// `counters.contacts` the rows of the three lists.
#[repr(C)]
#[derive(Debug)]
pub struct DhcdProximity {
    /// Row-major `[vf_count][2]` array of `[vertex of a, triangle of b]`; freed by
    /// `dhcd_proximity_free`.
    pub vertex_face: *mut u32,
    /// Squared distance of each `vertex_face` row (`vf_count` doubles); freed by
    /// `dhcd_proximity_free`.
    pub vf_distance_sq: *mut f64,
    /// `DHCD_PT_*` distance type of each `vertex_face` row (`vf_count` bytes); freed by
    /// `dhcd_proximity_free`.
    pub vf_type: *mut u8,
    /// Number of rows of `vertex_face`.
    pub vf_count: usize,
    /// Row-major `[fv_count][2]` array of `[triangle of a, vertex of b]` (empty for self); freed
    /// by `dhcd_proximity_free`.
    pub face_vertex: *mut u32,
    /// Squared distance of each `face_vertex` row (`fv_count` doubles); freed by
    /// `dhcd_proximity_free`.
    pub fv_distance_sq: *mut f64,
    /// `DHCD_PT_*` distance type of each `face_vertex` row (`fv_count` bytes); freed by
    /// `dhcd_proximity_free`.
    pub fv_type: *mut u8,
    /// Number of rows of `face_vertex`.
    pub fv_count: usize,
    /// Row-major `[ee_count][4]` array of `[a0, a1, b0, b1]`, an edge of `a` and one of `b`;
    /// freed by `dhcd_proximity_free`.
    pub edge_edge: *mut u32,
    /// Squared distance of each `edge_edge` row (`ee_count` doubles); freed by
    /// `dhcd_proximity_free`.
    pub ee_distance_sq: *mut f64,
    /// `DHCD_EE_*` distance type of each `edge_edge` row (`ee_count` bytes); freed by
    /// `dhcd_proximity_free`.
    pub ee_type: *mut u8,
    /// Number of rows of `edge_edge`.
    pub ee_count: usize,
    /// Work counted by the query.
    pub counters: DhcdCounters,
}

/// Feature pairs within a distance in a scene, from `dhcd_scene_proximity` (release with
/// `dhcd_scene_proximity_free`): every object pair's results (`object_a < object_b`) and
/// every self-collision object's own (`object_a == object_b`), flattened with object ids,
/// each list sorted by its rows; distances and types as in `DhcdProximity`:
/// - `vertex_face`: `[object_a, vertex, object_b, triangle]` at `vertex_face[4k..4k+4]`;
/// - `face_vertex`: `[object_a, triangle, object_b, vertex]` (between two objects only);
/// - `edge_edge`: `[object_a, a0, a1, object_b, b0, b1]` at `edge_edge[6k..6k+6]`.
///
/// `counters` are the totals over the object pairs.
#[repr(C)]
#[derive(Debug)]
pub struct DhcdSceneProximity {
    /// Row-major `[vf_count][4]` array of `[object_a, vertex, object_b, triangle]`; freed by
    /// `dhcd_scene_proximity_free`.
    pub vertex_face: *mut u64,
    /// Squared distance of each `vertex_face` row (`vf_count` doubles); freed by
    /// `dhcd_scene_proximity_free`.
    pub vf_distance_sq: *mut f64,
    /// `DHCD_PT_*` distance type of each `vertex_face` row (`vf_count` bytes); freed by
    /// `dhcd_scene_proximity_free`.
    pub vf_type: *mut u8,
    /// Number of rows of `vertex_face`.
    pub vf_count: usize,
    /// Row-major `[fv_count][4]` array of `[object_a, triangle, object_b, vertex]` (between two
    /// objects only); freed by `dhcd_scene_proximity_free`.
    pub face_vertex: *mut u64,
    /// Squared distance of each `face_vertex` row (`fv_count` doubles); freed by
    /// `dhcd_scene_proximity_free`.
    pub fv_distance_sq: *mut f64,
    /// `DHCD_PT_*` distance type of each `face_vertex` row (`fv_count` bytes); freed by
    /// `dhcd_scene_proximity_free`.
    pub fv_type: *mut u8,
    /// Number of rows of `face_vertex`.
    pub fv_count: usize,
    /// Row-major `[ee_count][6]` array of `[object_a, a0, a1, object_b, b0, b1]`; freed by
    /// `dhcd_scene_proximity_free`.
    pub edge_edge: *mut u64,
    /// Squared distance of each `edge_edge` row (`ee_count` doubles); freed by
    /// `dhcd_scene_proximity_free`.
    pub ee_distance_sq: *mut f64,
    /// `DHCD_EE_*` distance type of each `edge_edge` row (`ee_count` bytes); freed by
    /// `dhcd_scene_proximity_free`.
    pub ee_type: *mut u8,
    /// Number of rows of `edge_edge`.
    pub ee_count: usize,
    /// Work counted by the query, summed over the object pairs queried.
    pub counters: DhcdCounters,
}

/// Colliding feature pairs over a step, from `dhcd_ccd` / `dhcd_self_ccd` (release with
/// `dhcd_impacts_free`). Three lists, each of `*_count` rows sorted by its index rows, every
/// row with its time of impact (`*_toi[k]`, in `[0, t_max]`); indices are original vertex
/// and triangle indices; every array is null when its count is 0.
/// - `vertex_face`: `[vertex, triangle]` at `vertex_face[2k..2k+2]`: a vertex of `a` and a
///   triangle of `b` (self: a vertex and a triangle not containing it);
/// - `face_vertex`: `[triangle of a, vertex of b]` (pair queries only; empty for self);
/// - `edge_edge`: `[a0, a1, b0, b1]` at `edge_edge[4k..4k+4]`, an edge of `a` and one of
///   `b` (self: two edges sharing no vertex, `(a0, a1) < (b0, b1)`), each as its two
///   vertices, smaller first.
///
/// `toi` is the earliest time of impact of the step (the least of the rows' times), or
/// `+inf` when nothing collides. In earliest mode the lists hold only the pairs reaching
/// it. Whether a pair collides is decided exactly for the `double` input; a time of impact
/// is never later than the pair's first contact and at most 1e-12 earlier.
///
/// `counters.bv_tests` counts the node pairs tested over the step, `bv_updates` the bounds
/// fitted over the step, `prim_tests` the feature pairs given to the exact test,
/// `contacts` the rows of the three lists.
#[repr(C)]
#[derive(Debug)]
pub struct DhcdImpacts {
    /// Row-major `[vf_count][2]` array of `[vertex of a, triangle of b]`; freed by
    /// `dhcd_impacts_free`.
    pub vertex_face: *mut u32,
    /// Time of impact of each `vertex_face` row, in `[0, t_max]` (`vf_count` doubles); freed
    /// by `dhcd_impacts_free`.
    pub vf_toi: *mut f64,
    /// Number of rows of `vertex_face`.
    pub vf_count: usize,
    /// Row-major `[fv_count][2]` array of `[triangle of a, vertex of b]` (empty for self); freed
    /// by `dhcd_impacts_free`.
    pub face_vertex: *mut u32,
    /// Time of impact of each `face_vertex` row, in `[0, t_max]` (`fv_count` doubles); freed
    /// by `dhcd_impacts_free`.
    pub fv_toi: *mut f64,
    /// Number of rows of `face_vertex`.
    pub fv_count: usize,
    /// Row-major `[ee_count][4]` array of `[a0, a1, b0, b1]`, an edge of `a` and one of `b`;
    /// freed by `dhcd_impacts_free`.
    pub edge_edge: *mut u32,
    /// Time of impact of each `edge_edge` row, in `[0, t_max]` (`ee_count` doubles); freed
    /// by `dhcd_impacts_free`.
    pub ee_toi: *mut f64,
    /// Number of rows of `edge_edge`.
    pub ee_count: usize,
    /// Earliest time of impact of the step, in `[0, t_max]`; `+inf` when nothing collides.
    pub toi: f64,
    /// Work counted over the step.
    pub counters: DhcdCounters,
}

/// Colliding feature pairs over a step in a scene, from `dhcd_scene_ccd` (release with
/// `dhcd_scene_impacts_free`): every object pair's results (`object_a < object_b`) and every
/// self-collision object's own (`object_a == object_b`), flattened with object ids, each
/// list sorted by its rows; times of impact as in `DhcdImpacts`:
/// - `vertex_face`: `[object_a, vertex, object_b, triangle]` at `vertex_face[4k..4k+4]`;
/// - `face_vertex`: `[object_a, triangle, object_b, vertex]` (between two objects only);
/// - `edge_edge`: `[object_a, a0, a1, object_b, b0, b1]` at `edge_edge[6k..6k+6]`.
///
/// `toi` is the earliest time of impact over the scene (`+inf`: nothing collides);
/// `counters` are the totals over the object pairs.
#[repr(C)]
#[derive(Debug)]
pub struct DhcdSceneImpacts {
    /// Row-major `[vf_count][4]` array of `[object_a, vertex, object_b, triangle]`; freed by
    /// `dhcd_scene_impacts_free`.
    pub vertex_face: *mut u64,
    /// Time of impact of each `vertex_face` row, in `[0, t_max]` (`vf_count` doubles); freed
    /// by `dhcd_scene_impacts_free`.
    pub vf_toi: *mut f64,
    /// Number of rows of `vertex_face`.
    pub vf_count: usize,
    /// Row-major `[fv_count][4]` array of `[object_a, triangle, object_b, vertex]` (between two
    /// objects only); freed by `dhcd_scene_impacts_free`.
    pub face_vertex: *mut u64,
    /// Time of impact of each `face_vertex` row, in `[0, t_max]` (`fv_count` doubles); freed
    /// by `dhcd_scene_impacts_free`.
    pub fv_toi: *mut f64,
    /// Number of rows of `face_vertex`.
    pub fv_count: usize,
    /// Row-major `[ee_count][6]` array of `[object_a, a0, a1, object_b, b0, b1]`; freed by
    /// `dhcd_scene_impacts_free`.
    pub edge_edge: *mut u64,
    /// Time of impact of each `edge_edge` row, in `[0, t_max]` (`ee_count` doubles); freed
    /// by `dhcd_scene_impacts_free`.
    pub ee_toi: *mut f64,
    /// Number of rows of `edge_edge`.
    pub ee_count: usize,
    /// Earliest time of impact over the scene, in `[0, t_max]`; `+inf` when nothing collides.
    pub toi: f64,
    /// Work counted over the step, summed over the object pairs queried.
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

/// `count` `double` positions (`3 * count` doubles).
///
/// # Safety
/// As [`slice`], for `3 * count` doubles.
unsafe fn positions_f64<'a>(ptr: *const f64, count: usize) -> Result<&'a [[f64; 3]], Fail> {
    // SAFETY: `[f64; 3]` has the alignment of `f64` and the size of three; same contract.
    unsafe { slice(ptr.cast::<[f64; 3]>(), count, "positions") }
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

/// A validated `f64` mesh from C arrays.
///
/// # Safety
/// As [`positions_f64`] and [`triangles`].
unsafe fn mesh_f64(
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

/// `items` as an array the caller owns until the matching `*_free` (which rebuilds the
/// `Box<[T]>` of `items.len()` elements with [`free_array`]), or null when there are none.
fn c_array<T>(items: Vec<T>) -> *mut T {
    if items.is_empty() {
        return std::ptr::null_mut();
    }
    Box::into_raw(items.into_boxed_slice()).cast::<T>()
}

/// `pairs` flattened into an array the caller owns until the matching `*_free` (which
/// rebuilds the `Box<[T]>` of `N * count` elements), or null when there are none.
fn c_pairs<T, const N: usize>(pairs: Vec<[T; N]>) -> *mut T {
    c_array(pairs.into_iter().flatten().collect())
}

/// Releases an array made by [`c_array`] (or [`c_pairs`]) of `len` elements; null is a
/// no-op.
///
/// # Safety
/// `ptr` null or from `c_array` of exactly `len` elements, not released yet.
unsafe fn free_array<T>(ptr: *mut T, len: usize) {
    if !ptr.is_null() {
        // SAFETY: `ptr` came from a `Box<[T]>` of `len` elements (caller's contract).
        drop(unsafe { Box::from_raw(std::ptr::slice_from_raw_parts_mut(ptr, len)) });
    }
}

/// The C result of a CCD query.
fn impacts_out(p: Impacts) -> DhcdImpacts {
    let vf = &p.vertex_face;
    let fv = &p.face_vertex;
    let ee = &p.edge_edge;
    DhcdImpacts {
        vertex_face: c_pairs(vf.iter().map(|x| [x.vertex, x.triangle]).collect()),
        vf_toi: c_array(vf.iter().map(|x| x.toi).collect()),
        vf_count: vf.len(),
        face_vertex: c_pairs(fv.iter().map(|x| [x.triangle, x.vertex]).collect()),
        fv_toi: c_array(fv.iter().map(|x| x.toi).collect()),
        fv_count: fv.len(),
        edge_edge: c_pairs(
            ee.iter()
                .map(|x| [x.a[0], x.a[1], x.b[0], x.b[1]])
                .collect(),
        ),
        ee_toi: c_array(ee.iter().map(|x| x.toi).collect()),
        ee_count: ee.len(),
        toi: p.toi.unwrap_or(f64::INFINITY),
        counters: p.counters.into(),
    }
}

/// Rows of `N` indices with their times of impact, sorted by the rows: the index array
/// (flattened), the times and the count.
fn toi_rows<const N: usize>(mut rows: Vec<([u64; N], f64)>) -> (*mut u64, *mut f64, usize) {
    // Rows are unique (one per feature pair of one object pair): the order is total.
    rows.sort_unstable_by_key(|r| r.0);
    let n = rows.len();
    (
        c_pairs(rows.iter().map(|r| r.0).collect()),
        c_array(rows.iter().map(|r| r.1).collect()),
        n,
    )
}

/// The C result of a scene's CCD: every pair's rows with their object ids.
fn scene_impacts_out(p: SceneImpacts) -> DhcdSceneImpacts {
    let (mut vf, mut fv, mut ee) = (Vec::new(), Vec::new(), Vec::new());
    let i = u64::from;
    for pair in &p.per_pair {
        let (a, b, q) = (pair.a.0, pair.b.0, &pair.impacts);
        vf.extend(
            q.vertex_face
                .iter()
                .map(|x| ([a, i(x.vertex), b, i(x.triangle)], x.toi)),
        );
        fv.extend(
            q.face_vertex
                .iter()
                .map(|x| ([a, i(x.triangle), b, i(x.vertex)], x.toi)),
        );
        ee.extend(q.edge_edge.iter().map(|x| {
            let row = [a, i(x.a[0]), i(x.a[1]), b, i(x.b[0]), i(x.b[1])];
            (row, x.toi)
        }));
    }
    let (vertex_face, vf_toi, vf_count) = toi_rows(vf);
    let (face_vertex, fv_toi, fv_count) = toi_rows(fv);
    let (edge_edge, ee_toi, ee_count) = toi_rows(ee);
    DhcdSceneImpacts {
        vertex_face,
        vf_toi,
        vf_count,
        face_vertex,
        fv_toi,
        fv_count,
        edge_edge,
        ee_toi,
        ee_count,
        toi: p.toi.unwrap_or(f64::INFINITY),
        counters: p.counters.into(),
    }
}

/// The C result of a proximity query.
fn proximity_out(p: Proximity) -> DhcdProximity {
    let vf = &p.vertex_face;
    let fv = &p.face_vertex;
    let ee = &p.edge_edge;
    DhcdProximity {
        vertex_face: c_pairs(vf.iter().map(|x| [x.vertex, x.triangle]).collect()),
        vf_distance_sq: c_array(vf.iter().map(|x| x.distance_sq).collect()),
        vf_type: c_array(vf.iter().map(|x| x.kind as u8).collect()),
        vf_count: vf.len(),
        face_vertex: c_pairs(fv.iter().map(|x| [x.triangle, x.vertex]).collect()),
        fv_distance_sq: c_array(fv.iter().map(|x| x.distance_sq).collect()),
        fv_type: c_array(fv.iter().map(|x| x.kind as u8).collect()),
        fv_count: fv.len(),
        edge_edge: c_pairs(
            ee.iter()
                .map(|x| [x.a[0], x.a[1], x.b[0], x.b[1]])
                .collect(),
        ),
        ee_distance_sq: c_array(ee.iter().map(|x| x.distance_sq).collect()),
        ee_type: c_array(ee.iter().map(|x| x.kind as u8).collect()),
        ee_count: ee.len(),
        counters: p.counters.into(),
    }
}

/// Rows of `N` indices with their squared distances and types, sorted by the rows.
struct Rows<const N: usize>(Vec<([u64; N], f64, u8)>);

impl<const N: usize> Rows<N> {
    /// The three arrays (index rows flattened) and the count.
    fn into_c(mut self) -> (*mut u64, *mut f64, *mut u8, usize) {
        // Rows are unique (one per feature pair of one object pair): the order is total.
        self.0.sort_unstable_by_key(|r| r.0);
        let n = self.0.len();
        (
            c_pairs(self.0.iter().map(|r| r.0).collect()),
            c_array(self.0.iter().map(|r| r.1).collect()),
            c_array(self.0.iter().map(|r| r.2).collect()),
            n,
        )
    }
}

/// The C result of a scene's proximity: every pair's rows with their object ids.
fn scene_proximity_out(p: SceneProximity) -> DhcdSceneProximity {
    let (mut vf, mut fv, mut ee) = (Rows(Vec::new()), Rows(Vec::new()), Rows(Vec::new()));
    for pair in &p.per_pair {
        let (a, b, q) = (pair.a.0, pair.b.0, &pair.proximity);
        let i = u64::from;
        vf.0.extend(q.vertex_face.iter().map(|x| {
            (
                [a, i(x.vertex), b, i(x.triangle)],
                x.distance_sq,
                x.kind as u8,
            )
        }));
        fv.0.extend(q.face_vertex.iter().map(|x| {
            (
                [a, i(x.triangle), b, i(x.vertex)],
                x.distance_sq,
                x.kind as u8,
            )
        }));
        ee.0.extend(q.edge_edge.iter().map(|x| {
            let row = [a, i(x.a[0]), i(x.a[1]), b, i(x.b[0]), i(x.b[1])];
            (row, x.distance_sq, x.kind as u8)
        }));
    }
    let (vertex_face, vf_distance_sq, vf_type, vf_count) = vf.into_c();
    let (face_vertex, fv_distance_sq, fv_type, fv_count) = fv.into_c();
    let (edge_edge, ee_distance_sq, ee_type, ee_count) = ee.into_c();
    DhcdSceneProximity {
        vertex_face,
        vf_distance_sq,
        vf_type,
        vf_count,
        face_vertex,
        fv_distance_sq,
        fv_type,
        fv_count,
        edge_edge,
        ee_distance_sq,
        ee_type,
        ee_count,
        counters: p.counters.into(),
    }
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

const NO_PROXIMITY: DhcdProximity = DhcdProximity {
    vertex_face: std::ptr::null_mut(),
    vf_distance_sq: std::ptr::null_mut(),
    vf_type: std::ptr::null_mut(),
    vf_count: 0,
    face_vertex: std::ptr::null_mut(),
    fv_distance_sq: std::ptr::null_mut(),
    fv_type: std::ptr::null_mut(),
    fv_count: 0,
    edge_edge: std::ptr::null_mut(),
    ee_distance_sq: std::ptr::null_mut(),
    ee_type: std::ptr::null_mut(),
    ee_count: 0,
    counters: NO_CONTACTS.counters,
};

const NO_SCENE_PROXIMITY: DhcdSceneProximity = DhcdSceneProximity {
    vertex_face: std::ptr::null_mut(),
    vf_distance_sq: std::ptr::null_mut(),
    vf_type: std::ptr::null_mut(),
    vf_count: 0,
    face_vertex: std::ptr::null_mut(),
    fv_distance_sq: std::ptr::null_mut(),
    fv_type: std::ptr::null_mut(),
    fv_count: 0,
    edge_edge: std::ptr::null_mut(),
    ee_distance_sq: std::ptr::null_mut(),
    ee_type: std::ptr::null_mut(),
    ee_count: 0,
    counters: NO_CONTACTS.counters,
};

const NO_SCENE_IMPACTS: DhcdSceneImpacts = DhcdSceneImpacts {
    vertex_face: std::ptr::null_mut(),
    vf_toi: std::ptr::null_mut(),
    vf_count: 0,
    face_vertex: std::ptr::null_mut(),
    fv_toi: std::ptr::null_mut(),
    fv_count: 0,
    edge_edge: std::ptr::null_mut(),
    ee_toi: std::ptr::null_mut(),
    ee_count: 0,
    toi: f64::INFINITY,
    counters: NO_CONTACTS.counters,
};

const NO_IMPACTS: DhcdImpacts = DhcdImpacts {
    vertex_face: std::ptr::null_mut(),
    vf_toi: std::ptr::null_mut(),
    vf_count: 0,
    face_vertex: std::ptr::null_mut(),
    fv_toi: std::ptr::null_mut(),
    fv_count: 0,
    edge_edge: std::ptr::null_mut(),
    ee_toi: std::ptr::null_mut(),
    ee_count: 0,
    toi: f64::INFINITY,
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

/// Every vertex-triangle and edge-edge pair of `a` and `b` (two hierarchies of the same
/// method) whose closed features are within distance `d` (finite, `>= 0`; else
/// `DHCD_ERR_INVALID_ARGUMENT`), decided exactly, into `*out` (see `DhcdProximity`; release
/// with `dhcd_proximity_free`). `a` and `b` must be different handles (use
/// `dhcd_self_proximity` for one object); they may differ in precision (each is exact for
/// its own coordinates).
///
/// # Safety
/// `a`, `b` null or live handles; `out` null or valid for a write.
#[no_mangle]
pub unsafe extern "C" fn dhcd_proximity(
    a: *mut DhcdHierarchy,
    b: *mut DhcdHierarchy,
    d: f64,
    threads: u32,
    out: *mut DhcdProximity,
) -> c_int {
    guard(|| {
        // SAFETY: caller's contract on `out`: empty until there is a result.
        unsafe { write(out, NO_PROXIMITY, "out")? };
        if a == b && !a.is_null() {
            return Err(Fail(
                DHCD_ERR_INVALID_ARGUMENT,
                "dhcd_proximity needs two different hierarchies (use dhcd_self_proximity)".into(),
            ));
        }
        // SAFETY: live, distinct handles (checked above), so the two `&mut` do not alias.
        let (a, b) = unsafe { (handle(a, "a")?, handle(b, "b")?) };
        let p = a.h.proximity(&b.h, d, &mut a.ws, par(threads)?)?;
        // SAFETY: caller's contract on `out` (written above).
        unsafe { write(out, proximity_out(p), "out") }
    })
}

/// Every vertex-triangle pair (the triangle not containing the vertex) and edge-edge pair
/// (sharing no vertex) of one mesh within distance `d`, into `*out` (see `DhcdProximity`;
/// `face_vertex` is empty; release with `dhcd_proximity_free`).
///
/// # Safety
/// `h` null or a live handle; `out` null or valid for a write.
#[no_mangle]
pub unsafe extern "C" fn dhcd_self_proximity(
    h: *mut DhcdHierarchy,
    d: f64,
    threads: u32,
    out: *mut DhcdProximity,
) -> c_int {
    guard(|| {
        // SAFETY: caller's contract on `out`: empty until there is a result.
        unsafe { write(out, NO_PROXIMITY, "out")? };
        // SAFETY: caller's contract on `h`.
        let h = unsafe { handle(h, "hierarchy")? };
        let p = h.h.self_proximity(d, &mut h.ws, par(threads)?)?;
        // SAFETY: caller's contract on `out` (written above).
        unsafe { write(out, proximity_out(p), "out") }
    })
}

/// Releases the arrays of a `DhcdProximity` and resets it to empty. Null, or an already
/// released or empty result, is a no-op.
///
/// # Safety
/// `p` null or a `DhcdProximity` filled by this library and not modified since.
#[no_mangle]
pub unsafe extern "C" fn dhcd_proximity_free(p: *mut DhcdProximity) {
    let _ = guard(|| {
        // SAFETY: caller's contract.
        if let Some(p) = unsafe { p.as_mut() } {
            // SAFETY: each array came from `c_array` with the lengths below, or is null.
            unsafe {
                free_array(p.vertex_face, 2 * p.vf_count);
                free_array(p.vf_distance_sq, p.vf_count);
                free_array(p.vf_type, p.vf_count);
                free_array(p.face_vertex, 2 * p.fv_count);
                free_array(p.fv_distance_sq, p.fv_count);
                free_array(p.fv_type, p.fv_count);
                free_array(p.edge_edge, 4 * p.ee_count);
                free_array(p.ee_distance_sq, p.ee_count);
                free_array(p.ee_type, p.ee_count);
            }
            *p = NO_PROXIMITY;
        }
        Ok(())
    });
}

/// The CCD query of the C arguments (checked by the library's query).
fn ccd_query(t_max: f64, min_distance: f64, earliest: c_int) -> CcdQuery {
    CcdQuery {
        options: CcdOptions {
            t_max,
            min_distance,
        },
        mode: if earliest != 0 {
            CcdMode::Earliest
        } else {
            CcdMode::All
        },
    }
}

/// The motion of `vertex_count` vertices from `x0` (t = 0) to `x1` (t = 1), `3 *
/// vertex_count` doubles each.
///
/// # Safety
/// As [`positions_f64`], for both arrays.
unsafe fn motion<'a>(
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

/// Continuous collision detection of one mesh over a step: every vertex-triangle pair (the
/// triangle not containing the vertex) and edge-edge pair (sharing no vertex) that touches
/// at some time `t` in `[0, t_max]` while every vertex moves on the straight line from its
/// position in `x0` (t = 0) to its position in `x1` (t = 1), into `*out` (see
/// `DhcdImpacts`; `face_vertex` is empty; release with `dhcd_impacts_free`).
///
/// `x0` and `x1` hold `3 * vertex_count` doubles each, in the mesh's vertex order, for a
/// hierarchy of either precision (finite, within the `float` range: else
/// `DHCD_ERR_INVALID_MESH`; another vertex count: `DHCD_ERR_LENGTH_MISMATCH`); the pairs
/// found depend on `x0` and `x1` alone, and the hierarchy's pose is not changed. `t_max` in
/// `[0, 1]`; pairs collide when they come within `min_distance` (finite, `>= 0`; 0: when
/// they touch). `earliest` non-zero: only the earliest time of impact and every pair
/// whose own time is within 1e-12 of it (what a line search asks; every exact tie is there; pairs are tested only up to the best time found so
/// far), else every colliding pair. Decided exactly for the doubles; times of impact never
/// later than the first contact and at most 1e-12 earlier. The result does not depend on
/// `threads` (the work counters of earliest mode may).
///
/// # Safety
/// `h` null or a live handle; `x0`, `x1` hold `3 * vertex_count` doubles; `out` null or
/// valid for a write.
#[no_mangle]
pub unsafe extern "C" fn dhcd_self_ccd(
    h: *mut DhcdHierarchy,
    x0: *const f64,
    x1: *const f64,
    vertex_count: usize,
    t_max: f64,
    min_distance: f64,
    earliest: c_int,
    threads: u32,
    out: *mut DhcdImpacts,
) -> c_int {
    guard(|| {
        // SAFETY: caller's contract on `out`: empty until there is a result.
        unsafe { write(out, NO_IMPACTS, "out")? };
        // SAFETY: caller's contract on `h` and the arrays.
        let (h, m) = unsafe {
            (
                handle(h, "hierarchy")?,
                motion(x0, x1, vertex_count, "x0, x1")?,
            )
        };
        let q = ccd_query(t_max, min_distance, earliest);
        let p = h.h.self_ccd(m, &q, &mut h.ws, par(threads)?)?;
        // SAFETY: caller's contract on `out` (written above).
        unsafe { write(out, impacts_out(p), "out") }
    })
}

/// Continuous collision detection between two meshes over a step: every vertex of `a`
/// against every triangle of `b` (`vertex_face`), every triangle of `a` against every
/// vertex of `b` (`face_vertex`) and every edge of `a` against every edge of `b`
/// (`edge_edge`) that touches during the step, `a` moving from `a0` to `a1` (`3 *
/// a_vertex_count` doubles each) and `b` from `b0` to `b1`, into `*out` (see `DhcdImpacts`;
/// release with `dhcd_impacts_free`). `a` and `b` are different handles of the same method
/// (use `dhcd_self_ccd` for one mesh), of either precision; the other arguments as in
/// `dhcd_self_ccd`.
///
/// # Safety
/// `a`, `b` null or live handles; `a0`, `a1` hold `3 * a_vertex_count` doubles, `b0`, `b1`
/// `3 * b_vertex_count`; `out` null or valid for a write.
#[no_mangle]
pub unsafe extern "C" fn dhcd_ccd(
    a: *mut DhcdHierarchy,
    a0: *const f64,
    a1: *const f64,
    a_vertex_count: usize,
    b: *mut DhcdHierarchy,
    b0: *const f64,
    b1: *const f64,
    b_vertex_count: usize,
    t_max: f64,
    min_distance: f64,
    earliest: c_int,
    threads: u32,
    out: *mut DhcdImpacts,
) -> c_int {
    guard(|| {
        // SAFETY: caller's contract on `out`: empty until there is a result.
        unsafe { write(out, NO_IMPACTS, "out")? };
        if a == b && !a.is_null() {
            return Err(Fail(
                DHCD_ERR_INVALID_ARGUMENT,
                "dhcd_ccd needs two different hierarchies (use dhcd_self_ccd)".into(),
            ));
        }
        // SAFETY: live, distinct handles (checked above), so the two `&mut` do not alias;
        // the arrays by the caller's contract.
        let (a, b, ma, mb) = unsafe {
            (
                handle(a, "a")?,
                handle(b, "b")?,
                motion(a0, a1, a_vertex_count, "a0, a1")?,
                motion(b0, b1, b_vertex_count, "b0, b1")?,
            )
        };
        let q = ccd_query(t_max, min_distance, earliest);
        let p = a.h.ccd_pair(ma, &b.h, mb, &q, &mut a.ws, par(threads)?)?;
        // SAFETY: caller's contract on `out` (written above).
        unsafe { write(out, impacts_out(p), "out") }
    })
}

/// Releases the arrays of a `DhcdImpacts` and resets it to empty (`toi` `+inf`). Null, or
/// an already released or empty result, is a no-op.
///
/// # Safety
/// `p` null or a `DhcdImpacts` filled by this library and not modified since.
#[no_mangle]
pub unsafe extern "C" fn dhcd_impacts_free(p: *mut DhcdImpacts) {
    let _ = guard(|| {
        // SAFETY: caller's contract.
        if let Some(p) = unsafe { p.as_mut() } {
            // SAFETY: each array came from `c_array` with the lengths below, or is null.
            unsafe {
                free_array(p.vertex_face, 2 * p.vf_count);
                free_array(p.vf_toi, p.vf_count);
                free_array(p.face_vertex, 2 * p.fv_count);
                free_array(p.fv_toi, p.fv_count);
                free_array(p.edge_edge, 4 * p.ee_count);
                free_array(p.ee_toi, p.ee_count);
            }
            *p = NO_IMPACTS;
        }
        Ok(())
    });
}

/// One CCD query of four points: `x0` and `x1` hold 12 doubles each, the points at t = 0
/// and t = 1 (x, y, z each).
type CcdTest = fn(&[[f64; 3]; 4], &[[f64; 3]; 4], &CcdOptions) -> dhcd::Result<Option<f64>>;

/// Runs a single CCD query: 1 (collide, `*toi` the time of impact) or 0 (`*toi` `+inf`),
/// or a negative error code with `*toi` unchanged.
///
/// # Safety
/// `x0`, `x1` null or 12 doubles each; `toi` null or valid for a write.
unsafe fn single_ccd(
    test: CcdTest,
    x0: *const f64,
    x1: *const f64,
    t_max: f64,
    min_distance: f64,
    toi: *mut f64,
) -> c_int {
    let mut hit = false;
    let rc = guard(|| {
        // SAFETY: 12 doubles each (caller's contract); `[[f64; 3]; 4]` has the alignment
        // of `f64` and the size of twelve.
        let (p0, p1) = unsafe {
            (
                slice(x0.cast::<[[f64; 3]; 4]>(), 1, "x0")?,
                slice(x1.cast::<[[f64; 3]; 4]>(), 1, "x1")?,
            )
        };
        if toi.is_null() {
            return Err(null("toi"));
        }
        let options = CcdOptions {
            t_max,
            min_distance,
        };
        let t = test(&p0[0], &p1[0], &options)?;
        hit = t.is_some();
        // SAFETY: non-null, valid for a write (caller's contract).
        unsafe { write(toi, t.unwrap_or(f64::INFINITY), "toi") }
    });
    if rc == DHCD_OK {
        c_int::from(hit)
    } else {
        rc
    }
}

/// Vertex-face CCD of one pair: `x0` holds the vertex and the triangle's three corners at
/// t = 0 (`[v, f0, f1, f2]`, 12 doubles), `x1` the same points at t = 1; every point moves
/// on the straight line between them. Returns 1 when the vertex lies in the closed
/// triangle (or within `min_distance` of it) at some t in `[0, t_max]`, and writes the time
/// of impact into `*toi`; returns 0 otherwise, with `*toi = +inf`. Decided exactly for the
/// doubles (no tolerance; degenerate and coplanar cases included); the time of impact is
/// never later than the first contact and at most 1e-12 earlier. Errors (negative codes,
/// `*toi` unchanged): a NaN or infinite coordinate, `t_max` outside `[0, 1]`, a negative or
/// non-finite `min_distance` (`DHCD_ERR_INVALID_ARGUMENT`), a null pointer
/// (`DHCD_ERR_NULL`).
///
/// # Safety
/// `x0`, `x1` null or 12 doubles each; `toi` null or valid for a write.
#[no_mangle]
pub unsafe extern "C" fn dhcd_vertex_face_ccd(
    x0: *const f64,
    x1: *const f64,
    t_max: f64,
    min_distance: f64,
    toi: *mut f64,
) -> c_int {
    // SAFETY: forwarded contract.
    unsafe { single_ccd(dhcd::ccd::try_vertex_face, x0, x1, t_max, min_distance, toi) }
}

/// Edge-edge CCD of one pair: `x0` holds the two edges' endpoints at t = 0
/// (`[a0, a1, b0, b1]`, 12 doubles), `x1` at t = 1. Returns 1 when the closed segments meet
/// (or come within `min_distance`) at some t in `[0, t_max]`, with the time of impact in
/// `*toi`, else 0 with `*toi = +inf`; exactness and errors as `dhcd_vertex_face_ccd`.
///
/// # Safety
/// `x0`, `x1` null or 12 doubles each; `toi` null or valid for a write.
#[no_mangle]
pub unsafe extern "C" fn dhcd_edge_edge_ccd(
    x0: *const f64,
    x1: *const f64,
    t_max: f64,
    min_distance: f64,
    toi: *mut f64,
) -> c_int {
    // SAFETY: forwarded contract.
    unsafe { single_ccd(dhcd::ccd::try_edge_edge, x0, x1, t_max, min_distance, toi) }
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
            // SAFETY: `pairs` came from `c_pairs` of `4 * count` elements, or is null.
            unsafe { free_array(c.pairs, 4 * c.count) };
            *c = NO_SCENE_CONTACTS;
        }
        Ok(())
    });
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

/// Releases the arrays of a `DhcdSceneProximity` and resets it to empty. Null, or an
/// already released or empty result, is a no-op.
///
/// # Safety
/// `p` null or a `DhcdSceneProximity` filled by this library and not modified since.
#[no_mangle]
pub unsafe extern "C" fn dhcd_scene_proximity_free(p: *mut DhcdSceneProximity) {
    let _ = guard(|| {
        // SAFETY: caller's contract.
        if let Some(p) = unsafe { p.as_mut() } {
            // SAFETY: each array came from `c_array` with the lengths below, or is null.
            unsafe {
                free_array(p.vertex_face, 4 * p.vf_count);
                free_array(p.vf_distance_sq, p.vf_count);
                free_array(p.vf_type, p.vf_count);
                free_array(p.face_vertex, 4 * p.fv_count);
                free_array(p.fv_distance_sq, p.fv_count);
                free_array(p.fv_type, p.fv_count);
                free_array(p.edge_edge, 6 * p.ee_count);
                free_array(p.ee_distance_sq, p.ee_count);
                free_array(p.ee_type, p.ee_count);
            }
            *p = NO_SCENE_PROXIMITY;
        }
        Ok(())
    });
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
        let motions: Vec<(ObjectId, Motion<'_>)> = if count == 0 {
            Vec::new()
        } else {
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
                .collect::<Result<_, Fail>>()?
        };
        let q = ccd_query(t_max, min_distance, earliest);
        let p = s.scene.ccd(&motions, &q, par)?;
        // SAFETY: caller's contract on `out` (written above).
        unsafe { write(out, scene_impacts_out(p), "out") }
    })
}

/// Releases the arrays of a `DhcdSceneImpacts` and resets it to empty (`toi` `+inf`). Null,
/// or an already released or empty result, is a no-op.
///
/// # Safety
/// `p` null or a `DhcdSceneImpacts` filled by this library and not modified since.
#[no_mangle]
pub unsafe extern "C" fn dhcd_scene_impacts_free(p: *mut DhcdSceneImpacts) {
    let _ = guard(|| {
        // SAFETY: caller's contract.
        if let Some(p) = unsafe { p.as_mut() } {
            // SAFETY: each array came from `c_array` with the lengths below, or is null.
            unsafe {
                free_array(p.vertex_face, 4 * p.vf_count);
                free_array(p.vf_toi, p.vf_count);
                free_array(p.face_vertex, 4 * p.fv_count);
                free_array(p.fv_toi, p.fv_count);
                free_array(p.edge_edge, 6 * p.ee_count);
                free_array(p.ee_toi, p.ee_count);
            }
            *p = NO_SCENE_IMPACTS;
        }
        Ok(())
    });
}
