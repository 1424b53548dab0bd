//! The contact set, contact geometry and the collision-free step size
//! (`dhcd::contact`): `dhcd_self_contact_set`, `dhcd_contact_set`, their derivatives,
//! `dhcd_distance_sq` / `_gradient` / `_hessian` on batches, `dhcd_hierarchy_edges`,
//! `dhcd_collision_free_stepsize` and its pair form.

use std::ffi::c_int;

use dhcd::contact::{Contact, ContactType, StepOptions, NONE};
use dhcd::distance::EdgeEdge;

use crate::error::{guard, null, Fail};
use crate::hierarchy::DhcdHierarchy;
use crate::marshal::{
    c_array, c_pairs, free_array, handle, motion, par, positions_f64, slice, write, DhcdCounters,
};
use crate::DHCD_ERR_INVALID_ARGUMENT;

/// No `closest` type: the row is not an edge-edge row.
pub const DHCD_CLOSEST_NONE: u8 = u8::MAX;

/// Every pair of features within `dhat`, once, with the IPC Toolkit's collision type, from
/// `dhcd_self_contact_set`, `dhcd_contact_set` or `dhcd_scene_contact_set` (release with
/// `dhcd_contact_set_free`).
/// Row `k` of each array; rows sorted by type, then vertices.
#[repr(C)]
#[derive(Debug)]
pub struct DhcdContactSet {
    /// `[count][4]` vertices, `-1` in unused slots: point-point `[v, w]` (`v < w`),
    /// point-edge `[v, e0, e1]` (`e0 < e1`), point-triangle `[v, t0, t1, t2]`, edge-edge
    /// `[a0, a1, b0, b1]`. In a pair query `b`'s vertices are offset by `a`'s vertex count.
    pub vertices: *mut i64,
    /// `[count]` types: 0 point-point, 1 point-edge, 2 point-triangle, 3 edge-edge.
    pub types: *mut u8,
    /// `[count]` squared distances of the closest features.
    pub distance_sq: *mut f64,
    /// `[count][4]` closest-point weights: `sum_i weights[4k + i] * x[vertices[4k + i]]` is
    /// the vector between the closest points (the first feature's minus the second's).
    pub weights: *mut f64,
    /// `[count]` 1 for edge-edge rows of nearly parallel edges (the IPC Toolkit mollifies
    /// their barrier), else 0.
    pub mollified: *mut u8,
    /// `[count][2]` edge ids (`dhcd_hierarchy_edges`; `b`'s offset by `a`'s edge count):
    /// point-edge `[e, -1]`, edge-edge `[a, b]`, else `[-1, -1]`.
    pub edges: *mut i64,
    /// `[count]` edge-edge rows: the closest sub-features (`DHCD_EE_*`), which choose the
    /// formula of a mollified row's distance; `DHCD_CLOSEST_NONE` for other rows.
    pub closest: *mut u8,
    /// `[count][4][3]` the positions of each row's vertex slots at the query (zero in unused
    /// slots): what `dhcd_contact_set_gradient` and `_hessian` differentiate at.
    pub positions: *mut f64,
    /// Number of rows.
    pub count: usize,
    /// Work counted by the query (`contacts`: the rows).
    pub counters: DhcdCounters,
}

pub(crate) const NO_CONTACT_SET: DhcdContactSet = DhcdContactSet {
    vertices: std::ptr::null_mut(),
    types: std::ptr::null_mut(),
    distance_sq: std::ptr::null_mut(),
    weights: std::ptr::null_mut(),
    mollified: std::ptr::null_mut(),
    edges: std::ptr::null_mut(),
    closest: std::ptr::null_mut(),
    positions: std::ptr::null_mut(),
    count: 0,
    counters: DhcdCounters {
        bv_tests: 0,
        prim_tests: 0,
        bv_updates: 0,
        contacts: 0,
    },
};

fn id(v: u32) -> i64 {
    if v == NONE {
        -1
    } else {
        i64::from(v)
    }
}

/// The one marshalling of a `ContactSet` into C arrays.
pub(crate) fn contact_set_out(s: dhcd::ContactSet) -> DhcdContactSet {
    let c = &s.contacts;
    DhcdContactSet {
        vertices: c_pairs(c.iter().map(|c| c.vertices.map(id)).collect()),
        types: c_array(c.iter().map(|c| c.kind as u8).collect()),
        distance_sq: c_array(c.iter().map(|c| c.distance_sq).collect()),
        weights: c_pairs(c.iter().map(|c| c.weights).collect()),
        mollified: c_array(c.iter().map(|c| u8::from(c.mollified)).collect()),
        edges: c_pairs(c.iter().map(|c| c.edges.map(id)).collect()),
        closest: c_array(
            c.iter()
                .map(|c| c.closest.map_or(DHCD_CLOSEST_NONE, |k| k as u8))
                .collect(),
        ),
        positions: c_array(s.positions.iter().flatten().flatten().copied().collect()),
        count: c.len(),
        counters: s.counters.into(),
    }
}

/// Optional rest positions: null (the handle's build positions) or `3 * count` doubles.
///
/// # Safety
/// `ptr` null or valid for `3 * count` doubles.
unsafe fn rest<'a>(ptr: *const f64, count: usize) -> Result<Option<&'a [[f64; 3]]>, Fail> {
    if ptr.is_null() {
        return Ok(None);
    }
    // SAFETY: forwarded contract.
    unsafe { positions_f64(ptr, count) }.map(Some)
}

/// Every pair of features of one mesh within `dhat` (finite, `>= 0`), once, into `*out` (see
/// `DhcdContactSet`; release with `dhcd_contact_set_free`). `rest`: null, or the rest
/// positions of the mollifier test (`3 * rest_count` doubles, `rest_count` the vertex count;
/// default: the positions the hierarchy was built with).
///
/// # Safety
/// `h` null or a live handle; `rest` null or valid for `3 * rest_count` doubles; `out` null
/// or valid for a write.
#[no_mangle]
pub unsafe extern "C" fn dhcd_self_contact_set(
    h: *mut DhcdHierarchy,
    dhat: f64,
    rest_positions: *const f64,
    rest_count: usize,
    threads: u32,
    out: *mut DhcdContactSet,
) -> c_int {
    guard(|| {
        // SAFETY: caller's contract on `out`: empty until there is a result.
        unsafe { write(out, NO_CONTACT_SET, "out")? };
        // SAFETY: caller's contract on `h` and `rest`.
        let (h, r) = unsafe { (handle(h, "hierarchy")?, rest(rest_positions, rest_count)?) };
        let s = h.h.self_contact_set(dhat, r, &mut h.ws, par(threads)?)?;
        // SAFETY: caller's contract on `out` (written above).
        unsafe { write(out, contact_set_out(s), "out") }
    })
}

/// Every pair of features of `a` and `b` (different handles of the same method) within
/// `dhat`, once; `b`'s vertices and edges numbered after `a`'s. `rest_a`, `rest_b` as in
/// `dhcd_self_contact_set`.
///
/// # Safety
/// `a`, `b` null or live handles; each `rest` null or valid for `3 * count` doubles; `out`
/// null or valid for a write.
#[no_mangle]
#[allow(clippy::too_many_arguments)]
pub unsafe extern "C" fn dhcd_contact_set(
    a: *mut DhcdHierarchy,
    b: *mut DhcdHierarchy,
    dhat: f64,
    rest_a: *const f64,
    rest_a_count: usize,
    rest_b: *const f64,
    rest_b_count: usize,
    threads: u32,
    out: *mut DhcdContactSet,
) -> c_int {
    guard(|| {
        // SAFETY: caller's contract on `out`: empty until there is a result.
        unsafe { write(out, NO_CONTACT_SET, "out")? };
        if a == b && !a.is_null() {
            return Err(Fail(
                DHCD_ERR_INVALID_ARGUMENT,
                "dhcd_contact_set needs two different hierarchies (use dhcd_self_contact_set)"
                    .into(),
            ));
        }
        // SAFETY: live, distinct handles (checked above); the rest arrays by contract.
        let (a, b, ra, rb) = unsafe {
            (
                handle(a, "a")?,
                handle(b, "b")?,
                rest(rest_a, rest_a_count)?,
                rest(rest_b, rest_b_count)?,
            )
        };
        let s =
            a.h.contact_set(&b.h, dhat, [ra, rb], &mut a.ws, par(threads)?)?;
        // SAFETY: caller's contract on `out` (written above).
        unsafe { write(out, contact_set_out(s), "out") }
    })
}

/// The four vertex slots of one row.
type Slots = [[f64; 3]; 4];

/// The rows of a contact set as `Contact`s with their positions.
///
/// # Safety
/// `s` a set filled by this library.
unsafe fn rows(s: &DhcdContactSet) -> Result<Vec<(Contact, Slots)>, Fail> {
    if s.count == 0 {
        return Ok(Vec::new());
    }
    // SAFETY: the arrays of a filled set hold `count` rows each.
    let (types, closest, x) = unsafe {
        (
            slice(s.types.cast_const(), s.count, "types")?,
            slice(s.closest.cast_const(), s.count, "closest")?,
            slice(
                s.positions.cast_const().cast::<[[f64; 3]; 4]>(),
                s.count,
                "positions",
            )?,
        )
    };
    types
        .iter()
        .zip(closest)
        .zip(x)
        .map(|((&t, &k), x)| {
            let kind = ContactType::from_code(t)?;
            let closest = (k != DHCD_CLOSEST_NONE)
                .then(|| EdgeEdge::ALL.get(usize::from(k)).copied())
                .flatten();
            let c = Contact {
                kind,
                vertices: [NONE; 4],
                edges: [NONE; 2],
                distance_sq: 0.0,
                mollified: false,
                closest,
                weights: [0.0; 4],
            };
            Ok((c, *x))
        })
        .collect()
}

/// The gradient of each row's squared distance with respect to its four vertex slots
/// (`12 * count` doubles into `out`: row `k`, slot `i`, coordinate `c` at `12 k + 3 i + c`;
/// zero in unused slots).
///
/// # Safety
/// `s` null or a set filled by this library; `out` null or valid for `12 * count` doubles.
#[no_mangle]
pub unsafe extern "C" fn dhcd_contact_set_gradient(
    s: *const DhcdContactSet,
    out: *mut f64,
) -> c_int {
    guard(|| {
        // SAFETY: caller's contract.
        let s = unsafe { s.as_ref() }.ok_or_else(|| null("set"))?;
        // SAFETY: a filled set (caller's contract).
        let rows = unsafe { rows(s)? };
        fill(
            out,
            12 * s.count,
            rows.iter().flat_map(|(c, x)| c.gradient_at(x)),
        )
    })
}

/// The Hessian of each row's squared distance (`144 * count` doubles into `out`, row-major
/// 12 x 12 per row).
///
/// # Safety
/// `s` null or a set filled by this library; `out` null or valid for `144 * count` doubles.
#[no_mangle]
pub unsafe extern "C" fn dhcd_contact_set_hessian(
    s: *const DhcdContactSet,
    out: *mut f64,
) -> c_int {
    guard(|| {
        // SAFETY: caller's contract.
        let s = unsafe { s.as_ref() }.ok_or_else(|| null("set"))?;
        // SAFETY: a filled set (caller's contract).
        let rows = unsafe { rows(s)? };
        fill(
            out,
            144 * s.count,
            rows.iter()
                .flat_map(|(c, x)| c.hessian_at(x).into_iter().flatten()),
        )
    })
}

/// Writes `n` values into `out` (null is an error unless `n == 0`).
fn fill(out: *mut f64, n: usize, values: impl Iterator<Item = f64>) -> Result<(), Fail> {
    if n == 0 {
        return Ok(());
    }
    if out.is_null() {
        return Err(null("out"));
    }
    if !out.is_aligned() {
        return Err(Fail(DHCD_ERR_INVALID_ARGUMENT, "out is misaligned".into()));
    }
    // SAFETY: non-null, aligned, valid for `n` doubles by the caller's contract.
    let out = unsafe { std::slice::from_raw_parts_mut(out, n) };
    for (o, v) in out.iter_mut().zip(values) {
        *o = v;
    }
    Ok(())
}

/// Releases the arrays of a `DhcdContactSet` and resets it to empty. Null, or an already
/// released or empty set, is a no-op.
///
/// # Safety
/// `s` null or a set filled by this library and not modified since.
#[no_mangle]
pub unsafe extern "C" fn dhcd_contact_set_free(s: *mut DhcdContactSet) {
    let _ = guard(|| {
        // SAFETY: caller's contract.
        if let Some(s) = unsafe { s.as_mut() } {
            let n = s.count;
            // SAFETY: each array came from `c_array` with the lengths below, or is null.
            unsafe {
                free_array(s.vertices, 4 * n);
                free_array(s.types, n);
                free_array(s.distance_sq, n);
                free_array(s.weights, 4 * n);
                free_array(s.mollified, n);
                free_array(s.edges, 2 * n);
                free_array(s.closest, n);
                free_array(s.positions, 12 * n);
            }
            *s = NO_CONTACT_SET;
        }
        Ok(())
    });
}

/// The types and positions of a batch.
///
/// # Safety
/// `types` valid for `count` bytes, `x` for `12 * count` doubles (or null when `count` is 0).
unsafe fn batch<'a>(
    types: *const u8,
    x: *const f64,
    count: usize,
) -> Result<(Vec<ContactType>, &'a [Slots]), Fail> {
    if count == 0 {
        return Ok((Vec::new(), &[]));
    }
    // SAFETY: forwarded contract.
    let (t, x) = unsafe {
        (
            slice(types, count, "types")?,
            slice(x.cast::<Slots>(), count, "x")?,
        )
    };
    let t = t
        .iter()
        .map(|&c| ContactType::from_code(c))
        .collect::<dhcd::Result<Vec<_>>>()?;
    Ok((t, x))
}

/// The squared distance of each row's type (0 point-point, 1 point-edge, 2 point-triangle, 3
/// edge-edge; another is `DHCD_ERR_INVALID_ARGUMENT`) at `x` (`[count][4][3]` doubles, unused
/// slots ignored), into `out` (`count` doubles).
///
/// # Safety
/// `types` valid for `count` bytes, `x` for `12 * count` doubles, `out` for `count` doubles.
#[no_mangle]
pub unsafe extern "C" fn dhcd_distance_sq(
    types: *const u8,
    x: *const f64,
    count: usize,
    out: *mut f64,
) -> c_int {
    guard(|| {
        // SAFETY: caller's contract.
        let (t, x) = unsafe { batch(types, x, count)? };
        fill(out, count, t.iter().zip(x).map(|(t, x)| t.distance_sq(x)))
    })
}

/// The gradient of `dhcd_distance_sq` of each row (`12 * count` doubles into `out`).
///
/// # Safety
/// As `dhcd_distance_sq`, `out` valid for `12 * count` doubles.
#[no_mangle]
pub unsafe extern "C" fn dhcd_distance_gradient(
    types: *const u8,
    x: *const f64,
    count: usize,
    out: *mut f64,
) -> c_int {
    guard(|| {
        // SAFETY: caller's contract.
        let (t, x) = unsafe { batch(types, x, count)? };
        fill(
            out,
            12 * count,
            t.iter().zip(x).flat_map(|(t, x)| t.distance_gradient(x)),
        )
    })
}

/// The Hessian of `dhcd_distance_sq` of each row (`144 * count` doubles into `out`).
///
/// # Safety
/// As `dhcd_distance_sq`, `out` valid for `144 * count` doubles.
#[no_mangle]
pub unsafe extern "C" fn dhcd_distance_hessian(
    types: *const u8,
    x: *const f64,
    count: usize,
    out: *mut f64,
) -> c_int {
    guard(|| {
        // SAFETY: caller's contract.
        let (t, x) = unsafe { batch(types, x, count)? };
        fill(
            out,
            144 * count,
            t.iter()
                .zip(x)
                .flat_map(|(t, x)| t.distance_hessian(x).into_iter().flatten()),
        )
    })
}

/// The mesh's unique edges (`*count` of them, `2 * *count` `uint32_t` at `*edges`, smaller
/// vertex first, sorted): the edge ids of `DhcdContactSet.edges`. The array belongs to the
/// handle and lives as long as it.
///
/// # Safety
/// `h` null or a live handle; `edges`, `count` null or valid for a write.
#[no_mangle]
pub unsafe extern "C" fn dhcd_hierarchy_edges(
    h: *mut DhcdHierarchy,
    edges: *mut *const u32,
    count: *mut usize,
) -> c_int {
    guard(|| {
        // SAFETY: caller's contract on `h`.
        let h = unsafe { handle(h, "hierarchy")? };
        let e = h.h.tree().edges();
        // SAFETY: caller's contract on the outputs.
        unsafe {
            write(edges, e.as_ptr().cast::<u32>(), "edges")?;
            write(count, e.len(), "count")
        }
    })
}

/// The largest fraction of the step `x0 -> x1` (`3 * vertex_count` doubles each), in `[0,
/// 1]`, that keeps every vertex-triangle and edge-edge pair at least `min_distance + (1 -
/// rescaling) (d0 - min_distance)` apart, `d0` its distance at `x0` (the IPC Toolkit's rule,
/// exactly; `rescaling` in `(0, 1]`, 0.8 in ipctk), into `*step`. Never past the earliest
/// impact at `min_distance`; 1 when no pair comes within its gap.
///
/// # Safety
/// `h` null or a live handle; `x0`, `x1` valid for `3 * vertex_count` doubles; `step` null or
/// valid for a write.
#[no_mangle]
#[allow(clippy::too_many_arguments)]
pub unsafe extern "C" fn dhcd_collision_free_stepsize(
    h: *mut DhcdHierarchy,
    x0: *const f64,
    x1: *const f64,
    vertex_count: usize,
    min_distance: f64,
    rescaling: f64,
    threads: u32,
    step: *mut f64,
) -> c_int {
    guard(|| {
        // SAFETY: caller's contract on `h` and the arrays.
        let (h, m) = unsafe {
            (
                handle(h, "hierarchy")?,
                motion(x0, x1, vertex_count, "x0, x1")?,
            )
        };
        let o = StepOptions {
            min_distance,
            rescaling,
        };
        let s =
            h.h.collision_free_stepsize(m, &o, &mut h.ws, par(threads)?)?;
        // SAFETY: caller's contract on `step`.
        unsafe { write(step, s.step, "step") }
    })
}

/// `dhcd_collision_free_stepsize` of the pairs between `a` (moving `a0 -> a1`) and `b`
/// (`b0 -> b1`), different handles of the same method.
///
/// # Safety
/// `a`, `b` null or live handles; `a0`, `a1` valid for `3 * a_vertex_count` doubles, `b0`,
/// `b1` for `3 * b_vertex_count`; `step` null or valid for a write.
#[no_mangle]
#[allow(clippy::too_many_arguments)]
pub unsafe extern "C" fn dhcd_collision_free_stepsize_pair(
    a: *mut DhcdHierarchy,
    a0: *const f64,
    a1: *const f64,
    a_vertex_count: usize,
    b: *mut DhcdHierarchy,
    b0: *const f64,
    b1: *const f64,
    b_vertex_count: usize,
    min_distance: f64,
    rescaling: f64,
    threads: u32,
    step: *mut f64,
) -> c_int {
    guard(|| {
        if a == b && !a.is_null() {
            return Err(Fail(
                DHCD_ERR_INVALID_ARGUMENT,
                "dhcd_collision_free_stepsize_pair needs two different hierarchies".into(),
            ));
        }
        // SAFETY: live, distinct handles (checked above); the arrays by contract.
        let (a, b, ma, mb) = unsafe {
            (
                handle(a, "a")?,
                handle(b, "b")?,
                motion(a0, a1, a_vertex_count, "a0, a1")?,
                motion(b0, b1, b_vertex_count, "b0, b1")?,
            )
        };
        let o = StepOptions {
            min_distance,
            rescaling,
        };
        let s =
            a.h.collision_free_stepsize_pair(ma, &b.h, mb, &o, &mut a.ws, par(threads)?)?;
        // SAFETY: caller's contract on `step`.
        unsafe { write(step, s.step, "step") }
    })
}
