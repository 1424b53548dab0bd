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
//!
//! Layout: one module per query family (`collide`, `proximity`, `ccd`, `contact`), each with
//! its result types, the one conversion of each from the library's result, their `*_free`
//! and the family's hierarchy calls, so a new pair query touches one file; `hierarchy` and
//! `scene` hold the two handles, and a scene query's entry is in `scene`, writing its
//! family's result. The numbers of the ABI (error codes, limits, precisions) are here.
#![warn(missing_docs)]

// The modules in the order of their functions in include/dhcd.h (cbindgen follows the
// declarations; the comments keep rustfmt from sorting them).
// Failures, `guard` and the last error message.
mod error;
// C arrays in and out, the common arguments, the work counters.
mod marshal;
// The hierarchy handle.
mod hierarchy;
// Intersecting triangle pairs.
mod collide;
// Feature pairs within a distance.
mod proximity;
// Continuous collision detection.
mod ccd;
// The scene handle, its objects and its queries.
mod scene;
// The contact set, contact geometry and the collision-free step size.
mod contact;
// Limits and cancellation of the queries.
mod control;

pub use ccd::{
    dhcd_ccd, dhcd_edge_edge_ccd, dhcd_impacts_free, dhcd_scene_impacts_free, dhcd_self_ccd,
    dhcd_vertex_face_ccd, DhcdImpacts, DhcdSceneImpacts,
};
pub use collide::{
    dhcd_collide, dhcd_contact_segments, dhcd_contacts_free, dhcd_scene_contacts_free,
    dhcd_self_collide, DhcdContacts, DhcdSceneContacts,
};
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
pub use error::dhcd_last_error_message;
pub use hierarchy::{
    dhcd_hierarchy_free, dhcd_hierarchy_method, dhcd_hierarchy_new, dhcd_hierarchy_new_f64,
    dhcd_hierarchy_precision, dhcd_hierarchy_update_positions, dhcd_hierarchy_update_positions_f64,
    DhcdHierarchy,
};
pub use marshal::DhcdCounters;
pub use proximity::{
    dhcd_proximity, dhcd_proximity_free, dhcd_scene_proximity_free, dhcd_self_proximity,
    DhcdProximity, DhcdSceneProximity,
};
pub use scene::{
    dhcd_scene_add, dhcd_scene_add_f64, dhcd_scene_ccd, dhcd_scene_collision_free_stepsize,
    dhcd_scene_contact_set, dhcd_scene_contacts, dhcd_scene_edge_offset, dhcd_scene_free,
    dhcd_scene_new, dhcd_scene_proximity, dhcd_scene_remove, dhcd_scene_set_self_collision,
    dhcd_scene_step, dhcd_scene_update_many, dhcd_scene_update_positions,
    dhcd_scene_update_positions_f64, dhcd_scene_vertex_offset, DhcdScene,
};

use std::ffi::c_int;

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
