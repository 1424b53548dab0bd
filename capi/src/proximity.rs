//! Proximity (feature pairs within a distance): the results `DhcdProximity`
//! (`dhcd_proximity`, `dhcd_self_proximity`) and `DhcdSceneProximity`
//! (`dhcd_scene_proximity`, in `scene`), each with its one conversion from the library's
//! result and its `*_free`.

use std::ffi::c_int;

use dhcd::{Proximity, SceneProximity};

use crate::error::{guard, Fail};
use crate::hierarchy::DhcdHierarchy;
use crate::marshal::{c_array, c_pairs, free_array, handle, par, write, DhcdCounters, NO_COUNTERS};
use crate::DHCD_ERR_INVALID_ARGUMENT;

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
    counters: NO_COUNTERS,
};

pub(crate) const NO_SCENE_PROXIMITY: DhcdSceneProximity = DhcdSceneProximity {
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
    counters: NO_COUNTERS,
};

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
pub(crate) fn scene_proximity_out(p: SceneProximity) -> DhcdSceneProximity {
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
