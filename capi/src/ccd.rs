//! Continuous collision detection over a step: the results `DhcdImpacts` (`dhcd_ccd`,
//! `dhcd_self_ccd`) and `DhcdSceneImpacts` (`dhcd_scene_ccd`, in `scene`), each with its one
//! conversion from the library's result and its `*_free`; the CCD query of the C arguments;
//! and the single-pair tests `dhcd_vertex_face_ccd` and `dhcd_edge_edge_ccd`.

use std::ffi::c_int;

use dhcd::ccd::CcdOptions;
use dhcd::{CcdMode, CcdQuery, Impacts, SceneImpacts};

use crate::error::{guard, null, Fail};
use crate::hierarchy::DhcdHierarchy;
use crate::marshal::{
    c_array, c_pairs, free_array, handle, motion, par, slice, write, DhcdCounters, NO_COUNTERS,
};
use crate::{DHCD_ERR_INVALID_ARGUMENT, DHCD_OK};

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
    counters: NO_COUNTERS,
};

pub(crate) const NO_SCENE_IMPACTS: DhcdSceneImpacts = DhcdSceneImpacts {
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
    counters: NO_COUNTERS,
};

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
pub(crate) fn scene_impacts_out(p: SceneImpacts) -> DhcdSceneImpacts {
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

/// The CCD query of the C arguments (checked by the library's query).
pub(crate) fn ccd_query(t_max: f64, min_distance: f64, earliest: c_int) -> CcdQuery {
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
