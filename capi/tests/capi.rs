//! The C ABI from Rust: results equal the Rust API, bad arguments are error codes (null,
//! mismatched lengths, wrong method, unknown ids), and `include/dhcd.h` declares exactly the
//! exported functions and constants.

use std::ffi::CStr;
use std::ptr::{null, null_mut};

use dhcd::distance::{EdgeEdge, PointTriangle};
use dhcd::narrow::{brute_force_pairs, brute_force_self_pairs};
use dhcd::shapes::{icosphere, translated, wave};
use dhcd::{Mesh, Method};

const DHCD_METHOD_DH: i32 = Method::Dh.code();
const DHCD_METHOD_SPHERE: i32 = Method::Sphere.code();
const DHCD_METHOD_AABB: i32 = Method::Aabb.code();
use dhcd_capi::*;

fn flat(mesh: &Mesh) -> (Vec<f32>, Vec<u32>) {
    (
        mesh.positions().iter().flatten().copied().collect(),
        mesh.triangles().iter().flatten().copied().collect(),
    )
}

fn new_h(method: i32, mesh: &Mesh) -> *mut DhcdHierarchy {
    let (p, t) = flat(mesh);
    let mut h = null_mut();
    // SAFETY: arrays of the stated lengths; `h` writable.
    let rc = unsafe {
        dhcd_hierarchy_new(
            method,
            4,
            p.as_ptr(),
            mesh.vertex_count(),
            t.as_ptr(),
            mesh.triangle_count(),
            &mut h,
        )
    };
    assert_eq!(rc, DHCD_OK, "{}", last_error());
    assert!(!h.is_null());
    h
}

fn last_error() -> String {
    // SAFETY: never null, NUL-terminated.
    unsafe { CStr::from_ptr(dhcd_last_error_message()) }
        .to_string_lossy()
        .into_owned()
}

fn pairs_of(c: &DhcdContacts) -> Vec<[u32; 2]> {
    if c.count == 0 {
        assert!(c.pairs.is_null());
        return Vec::new();
    }
    // SAFETY: the library wrote `2 * count` u32 at `pairs`.
    let s = unsafe { std::slice::from_raw_parts(c.pairs, 2 * c.count) };
    s.chunks(2).map(|p| [p[0], p[1]]).collect()
}

fn empty() -> DhcdContacts {
    DhcdContacts {
        pairs: null_mut(),
        count: 0,
        counters: DhcdCounters::default(),
    }
}

#[test]
fn collide_and_self_collide_equal_brute_force() {
    let a = icosphere(2, 1.0, [0.0; 3]);
    let b_pos = wave(a.positions(), 0.7, 0.2, [1.2, 0.3, 0.0]);
    let b = Mesh::new(b_pos.clone(), a.triangles().to_vec()).unwrap();
    let crumpled = Mesh::new(
        wave(a.positions(), 1.3, 0.6, [0.0; 3]),
        a.triangles().to_vec(),
    )
    .unwrap();
    for method in [DHCD_METHOD_DH, DHCD_METHOD_SPHERE, DHCD_METHOD_AABB] {
        let ha = new_h(method, &a);
        let hb = new_h(method, &a);
        let mut m = -1;
        // SAFETY: live handles, valid out-pointers and arrays throughout.
        unsafe {
            assert_eq!(dhcd_hierarchy_method(ha, &mut m), DHCD_OK);
            assert_eq!(m, method);
            let flat_b: Vec<f32> = b_pos.iter().flatten().copied().collect();
            assert_eq!(
                dhcd_hierarchy_update_positions(hb, flat_b.as_ptr(), b_pos.len()),
                DHCD_OK
            );
            let mut c = empty();
            assert_eq!(dhcd_collide(ha, hb, 2, &mut c), DHCD_OK);
            let pairs = pairs_of(&c);
            assert_eq!(pairs, brute_force_pairs(&a, &b));
            assert!(!pairs.is_empty());
            assert_eq!(c.counters.contacts as usize, c.count);
            // Segments of every contact.
            let mut segs = vec![0.0f32; 6 * c.count];
            assert_eq!(
                dhcd_contact_segments(ha, hb, c.pairs, c.count, segs.as_mut_ptr()),
                DHCD_OK
            );
            assert!(segs.iter().all(|x| x.is_finite()));
            dhcd_contacts_free(&mut c);
            assert!(c.pairs.is_null() && c.count == 0);
            dhcd_contacts_free(&mut c); // twice: no-op
            dhcd_contacts_free(null_mut());

            let flat_c: Vec<f32> = crumpled.positions().iter().flatten().copied().collect();
            assert_eq!(
                dhcd_hierarchy_update_positions(ha, flat_c.as_ptr(), a.vertex_count()),
                DHCD_OK
            );
            let mut s = empty();
            assert_eq!(dhcd_self_collide(ha, 1, &mut s), DHCD_OK);
            assert_eq!(pairs_of(&s), brute_force_self_pairs(&crumpled));
            assert!(s.count > 0);
            let mut segs = vec![0.0f32; 6 * s.count];
            assert_eq!(
                dhcd_contact_segments(ha, ha, s.pairs, s.count, segs.as_mut_ptr()),
                DHCD_OK
            );
            dhcd_contacts_free(&mut s);
            dhcd_hierarchy_free(ha);
            dhcd_hierarchy_free(hb);
        }
    }
}

#[test]
fn scene_equals_rust_scene() {
    let m = icosphere(2, 1.0, [0.0; 3]);
    let (p, t) = flat(&m);
    let mut rust = dhcd::Scene::new(
        dhcd::Method::Sphere,
        dhcd::Options {
            levels: Some(4),
            ..Default::default()
        },
    );
    let mut s = null_mut();
    // SAFETY: live handles, valid arrays and out-pointers throughout.
    unsafe {
        assert_eq!(dhcd_scene_new(DHCD_METHOD_SPHERE, 4, &mut s), DHCD_OK);
        let mut ids = Vec::new();
        for k in 0..4 {
            let mut id = u64::MAX;
            assert_eq!(
                dhcd_scene_add(
                    s,
                    p.as_ptr(),
                    m.vertex_count(),
                    t.as_ptr(),
                    m.triangle_count(),
                    (k == 2) as i32,
                    &mut id
                ),
                DHCD_OK
            );
            let rid = rust.add(&m).unwrap();
            rust.set_self_collision(rid, k == 2).unwrap();
            assert_eq!(id, rid.0);
            ids.push(id);
        }
        for (k, &id) in ids.iter().enumerate() {
            let pos = wave(m.positions(), k as f32, 0.5, [1.4 * k as f32, 0.0, 0.0]);
            let f: Vec<f32> = pos.iter().flatten().copied().collect();
            assert_eq!(
                dhcd_scene_update_positions(s, id, f.as_ptr(), pos.len()),
                DHCD_OK
            );
            rust.update_positions(dhcd::ObjectId(id), &pos).unwrap();
        }
        let mut c = DhcdSceneContacts {
            pairs: null_mut(),
            count: 0,
            counters: DhcdCounters::default(),
        };
        assert_eq!(dhcd_scene_contacts(s, 0, &mut c), DHCD_OK);
        let expected = rust.contacts(dhcd::Par::Seq);
        assert!(c.count > 0);
        let got: Vec<[u64; 4]> = std::slice::from_raw_parts(c.pairs, 4 * c.count)
            .chunks(4)
            .map(|q| [q[0], q[1], q[2], q[3]])
            .collect();
        assert_eq!(got, expected.pairs);
        assert_eq!(c.counters, expected.counters.into());
        assert!(
            got.iter().any(|q| q[0] == 2 && q[2] == 2),
            "self-contacts of object 2"
        );
        dhcd_scene_contacts_free(&mut c);
        assert!(c.pairs.is_null());
        assert_eq!(dhcd_scene_set_self_collision(s, 2, 0), DHCD_OK);
        assert_eq!(dhcd_scene_remove(s, 1), DHCD_OK);
        assert_eq!(dhcd_scene_remove(s, 1), DHCD_ERR_UNKNOWN_OBJECT);
        assert!(
            last_error().contains("no object with id 1"),
            "{}",
            last_error()
        );
        assert_eq!(
            dhcd_scene_update_positions(s, 9, p.as_ptr(), m.vertex_count()),
            DHCD_ERR_UNKNOWN_OBJECT
        );
        assert_eq!(
            dhcd_scene_set_self_collision(s, 1, 1),
            DHCD_ERR_UNKNOWN_OBJECT
        );
        dhcd_scene_free(s);
        dhcd_scene_free(null_mut());
    }
}

/// A scene's contacts: its sorted quadruples and counters.
///
/// # Safety
/// `s` a live scene handle.
unsafe fn scene_contacts(s: *mut DhcdScene) -> (Vec<[u64; 4]>, DhcdCounters) {
    let mut c = DhcdSceneContacts {
        pairs: null_mut(),
        count: 0,
        counters: DhcdCounters::default(),
    };
    // SAFETY: live handle (caller's contract), writable output.
    unsafe {
        assert_eq!(
            dhcd_scene_contacts(s, 1, &mut c),
            DHCD_OK,
            "{}",
            last_error()
        );
        taken(&mut c)
    }
}

/// The pairs and counters of a filled result, which is released.
///
/// # Safety
/// `c` filled by the library and not released.
unsafe fn taken(c: &mut DhcdSceneContacts) -> (Vec<[u64; 4]>, DhcdCounters) {
    // SAFETY: caller's contract: `pairs` holds `4 * count` entries.
    unsafe {
        let pairs = if c.count == 0 {
            Vec::new()
        } else {
            std::slice::from_raw_parts(c.pairs, 4 * c.count)
                .chunks(4)
                .map(|q| [q[0], q[1], q[2], q[3]])
                .collect()
        };
        let counters = c.counters;
        dhcd_scene_contacts_free(c);
        (pairs, counters)
    }
}

/// `dhcd_scene_step`'s result, or its error code.
///
/// # Safety
/// As `dhcd_scene_step`.
unsafe fn scene_step(
    s: *mut DhcdScene,
    ids: &[u64],
    ptrs: &[*const f32],
    counts: &[usize],
    threads: u32,
) -> Result<(Vec<[u64; 4]>, DhcdCounters), i32> {
    let mut c = DhcdSceneContacts {
        pairs: null_mut(),
        count: 1,
        counters: DhcdCounters::default(),
    };
    // SAFETY: caller's contract.
    unsafe {
        let rc = dhcd_scene_step(
            s,
            ids.as_ptr(),
            ptrs.as_ptr(),
            counts.as_ptr(),
            ids.len(),
            threads,
            &mut c,
        );
        if rc != DHCD_OK {
            assert!(
                c.pairs.is_null() && c.count == 0,
                "an error leaves no contacts"
            );
            return Err(rc);
        }
        Ok(taken(&mut c))
    }
}

/// A new scene of `n` copies of `m` (self-collision on for the first); their ids.
fn scene_of(m: &Mesh, n: usize) -> (*mut DhcdScene, Vec<u64>) {
    let (p, t) = flat(m);
    let mut s = null_mut();
    // SAFETY: arrays of the stated lengths, writable outputs.
    unsafe {
        assert_eq!(dhcd_scene_new(DHCD_METHOD_DH, 4, &mut s), DHCD_OK);
        let ids = (0..n)
            .map(|k| {
                let mut id = u64::MAX;
                let rc = dhcd_scene_add(
                    s,
                    p.as_ptr(),
                    m.vertex_count(),
                    t.as_ptr(),
                    m.triangle_count(),
                    (k == 0) as i32,
                    &mut id,
                );
                assert_eq!(rc, DHCD_OK, "{}", last_error());
                id
            })
            .collect();
        (s, ids)
    }
}

/// `dhcd_scene_update_many` is one `dhcd_scene_update_positions` per entry, for every
/// thread count and entry order: same contacts, same counters.
#[test]
fn scene_update_many_equals_one_update_per_object() {
    let ball = icosphere(2, 1.0, [0.0; 3]);
    let n = 5;
    let (one_by_one, ids) = scene_of(&ball, n);
    let batched: Vec<(*mut DhcdScene, u32)> = [1, 2, 0]
        .into_iter()
        .map(|t| (scene_of(&ball, n).0, t))
        .collect();
    let stepped: Vec<*mut DhcdScene> = batched.iter().map(|_| scene_of(&ball, n).0).collect();
    for step in 0..3 {
        let poses: Vec<Vec<f32>> = (0..n)
            .map(|k| {
                let p = wave(
                    ball.positions(),
                    step as f32 + k as f32,
                    0.3,
                    [1.7 * k as f32, 0.0, 0.0],
                );
                p.into_iter().flatten().collect()
            })
            .collect();
        // SAFETY: live handles; every array holds the stated number of elements.
        unsafe {
            for (&id, p) in ids.iter().zip(&poses) {
                let rc =
                    dhcd_scene_update_positions(one_by_one, id, p.as_ptr(), ball.vertex_count());
                assert_eq!(rc, DHCD_OK, "{}", last_error());
            }
            let reference = scene_contacts(one_by_one);
            assert!(!reference.0.is_empty());
            // Step 1 moves only some objects (the others by single updates), given in
            // reverse order; the other steps move all of them in id order.
            let moved: Vec<usize> = if step == 1 {
                vec![3, 1, 0]
            } else {
                (0..n).collect()
            };
            let entry_ids: Vec<u64> = moved.iter().map(|&k| ids[k]).collect();
            let entry_ptrs: Vec<*const f32> = moved.iter().map(|&k| poses[k].as_ptr()).collect();
            let entry_counts = vec![ball.vertex_count(); moved.len()];
            for (&(s, threads), &stepping) in batched.iter().zip(&stepped) {
                let rc = dhcd_scene_update_many(
                    s,
                    entry_ids.as_ptr(),
                    entry_ptrs.as_ptr(),
                    entry_counts.as_ptr(),
                    moved.len(),
                    threads,
                );
                assert_eq!(rc, DHCD_OK, "{}", last_error());
                for k in (0..n).filter(|k| !moved.contains(k)) {
                    let rc = dhcd_scene_update_positions(
                        s,
                        ids[k],
                        poses[k].as_ptr(),
                        ball.vertex_count(),
                    );
                    assert_eq!(rc, DHCD_OK, "{}", last_error());
                    let rc = dhcd_scene_update_positions(
                        stepping,
                        ids[k],
                        poses[k].as_ptr(),
                        ball.vertex_count(),
                    );
                    assert_eq!(rc, DHCD_OK, "{}", last_error());
                }
                assert_eq!(
                    scene_contacts(s),
                    reference,
                    "step {step}, threads {threads}"
                );
                // `dhcd_scene_step` is the update, then the contacts.
                let got = scene_step(stepping, &entry_ids, &entry_ptrs, &entry_counts, threads);
                assert_eq!(got, Ok(reference.clone()), "step {step}, threads {threads}");
            }
        }
    }
    // SAFETY: live handles, released once.
    unsafe {
        dhcd_scene_free(one_by_one);
        for ((s, _), stepping) in batched.into_iter().zip(stepped) {
            dhcd_scene_free(s);
            dhcd_scene_free(stepping);
        }
    }
}

/// A bad entry anywhere in a `dhcd_scene_update_many`, or a bad argument, is its error
/// code and no object moves; `count == 0` is a no-op, whatever the arrays.
#[test]
fn scene_update_many_bad_entry_changes_nothing() {
    let ball = icosphere(1, 1.0, [0.0; 3]);
    let nv = ball.vertex_count();
    let (s, ids) = scene_of(&ball, 2);
    let (a, b) = (ids[0], ids[1]);
    // Moving either object this far ends every contact between them.
    let far: Vec<f32> = translated(ball.positions(), [10.0, 0.0, 0.0])
        .into_iter()
        .flatten()
        .collect();
    let mut nan = far.clone();
    nan[3 * 5 + 1] = f32::NAN;
    let bytes = [0u8; 64];
    // SAFETY: live handle; arrays hold the stated number of elements or are null (or, for
    // the misaligned one, are rejected before being read).
    unsafe {
        let before = scene_contacts(s);
        assert!(before.0.iter().any(|q| q[0] == a && q[2] == b));
        let odd = bytes.as_ptr().add(1).cast::<f32>();
        type Entry = (u64, *const f32, usize);
        let f = far.as_ptr();
        let cases: [(&[Entry], u32, i32, &str); 9] = [
            (
                &[(a, f, nv), (9, f, nv)],
                1,
                DHCD_ERR_UNKNOWN_OBJECT,
                "no object with id 9",
            ),
            (
                &[(b, f, nv), (a, f, nv), (b, f, nv)],
                2,
                DHCD_ERR_REPEATED_OBJECT,
                "object 1 is given more than once",
            ),
            (
                &[(a, f, nv), (b, f, nv - 1)],
                1,
                DHCD_ERR_LENGTH_MISMATCH,
                "vertices",
            ),
            (
                &[(a, f, nv), (b, nan.as_ptr(), nv)],
                2,
                DHCD_ERR_INVALID_MESH,
                "non-finite",
            ),
            (
                &[(a, f, nv), (b, null(), nv)],
                1,
                DHCD_ERR_NULL,
                "update 1: positions",
            ),
            (
                &[(a, f, nv), (b, odd, 1)],
                1,
                DHCD_ERR_INVALID_ARGUMENT,
                "aligned",
            ),
            (
                &[(a, f, nv), (b, f, usize::MAX / 2)],
                1,
                DHCD_ERR_INVALID_ARGUMENT,
                "too many",
            ),
            (
                &[(a, f, nv)],
                u32::MAX,
                DHCD_ERR_INVALID_ARGUMENT,
                "thread count",
            ),
            (
                &[(a, f, nv), (a, nan.as_ptr(), nv - 1)],
                1,
                DHCD_ERR_REPEATED_OBJECT,
                "object 0",
            ),
        ];
        for (entries, threads, code, message) in cases {
            let ids: Vec<u64> = entries.iter().map(|e| e.0).collect();
            let ptrs: Vec<*const f32> = entries.iter().map(|e| e.1).collect();
            let counts: Vec<usize> = entries.iter().map(|e| e.2).collect();
            let rc = dhcd_scene_update_many(
                s,
                ids.as_ptr(),
                ptrs.as_ptr(),
                counts.as_ptr(),
                entries.len(),
                threads,
            );
            assert_eq!(rc, code, "{message}: {}", last_error());
            assert!(
                last_error().contains(message),
                "{message}: {}",
                last_error()
            );
            assert_eq!(scene_contacts(s).0, before.0, "nothing moved ({message})");
            assert_eq!(
                scene_step(s, &ids, &ptrs, &counts, threads),
                Err(code),
                "{message}"
            );
            assert!(last_error().contains(message), "step: {}", last_error());
            assert_eq!(
                scene_contacts(s).0,
                before.0,
                "step: nothing moved ({message})"
            );
        }
        // Null arrays with entries, a null scene.
        let (id, ptr, count) = ([a], [far.as_ptr()], [nv]);
        for (ids, ptrs, counts, what) in [
            (null(), ptr.as_ptr(), count.as_ptr(), "ids"),
            (id.as_ptr(), null(), count.as_ptr(), "positions"),
            (id.as_ptr(), ptr.as_ptr(), null(), "vertex_counts"),
        ] {
            assert_eq!(
                dhcd_scene_update_many(s, ids, ptrs, counts, 1, 1),
                DHCD_ERR_NULL
            );
            assert!(last_error().starts_with(what), "{}", last_error());
        }
        assert_eq!(
            dhcd_scene_update_many(null_mut(), id.as_ptr(), ptr.as_ptr(), count.as_ptr(), 1, 1),
            DHCD_ERR_NULL
        );
        assert_eq!(scene_contacts(s).0, before.0, "nothing moved");
        // No entries: nothing to do, whatever the arrays.
        assert_eq!(
            dhcd_scene_update_many(s, null(), null(), null(), 0, 2),
            DHCD_OK
        );
        assert_eq!(
            dhcd_scene_update_many(null_mut(), null(), null(), null(), 0, 1),
            DHCD_ERR_NULL
        );
        assert_eq!(scene_contacts(s).0, before.0);
        // A good call still works after the errors.
        assert_eq!(
            dhcd_scene_update_many(s, id.as_ptr(), ptr.as_ptr(), count.as_ptr(), 1, 2),
            DHCD_OK
        );
        assert!(
            scene_contacts(s).0.iter().all(|q| q[0] == q[2]),
            "a moved away"
        );
        dhcd_scene_free(s);
    }
}

#[test]
fn bad_arguments_are_error_codes() {
    let m = icosphere(1, 1.0, [0.0; 3]);
    let (p, t) = flat(&m);
    let (nv, nt) = (m.vertex_count(), m.triangle_count());
    let a = new_h(DHCD_METHOD_DH, &m);
    let b = new_h(DHCD_METHOD_AABB, &m);
    let mut h = null_mut();
    let mut c = empty();
    // SAFETY: every pointer is null, a live handle, or valid for its stated length.
    unsafe {
        // Null pointers.
        assert_eq!(
            dhcd_hierarchy_new(DHCD_METHOD_DH, 4, null(), nv, t.as_ptr(), nt, &mut h),
            DHCD_ERR_NULL
        );
        assert!(last_error().contains("positions"));
        assert_eq!(
            dhcd_hierarchy_new(DHCD_METHOD_DH, 4, p.as_ptr(), nv, null(), nt, &mut h),
            DHCD_ERR_NULL
        );
        assert_eq!(
            dhcd_hierarchy_new(
                DHCD_METHOD_DH,
                4,
                p.as_ptr(),
                nv,
                t.as_ptr(),
                nt,
                null_mut()
            ),
            DHCD_ERR_NULL
        );
        assert!(h.is_null());
        assert_eq!(dhcd_collide(null_mut(), b, 1, &mut c), DHCD_ERR_NULL);
        assert_eq!(dhcd_collide(a, b, 1, null_mut()), DHCD_ERR_NULL);
        assert_eq!(dhcd_self_collide(null_mut(), 1, &mut c), DHCD_ERR_NULL);
        assert_eq!(
            dhcd_hierarchy_update_positions(null_mut(), p.as_ptr(), nv),
            DHCD_ERR_NULL
        );
        assert_eq!(
            dhcd_hierarchy_update_positions(a, null(), nv),
            DHCD_ERR_NULL
        );
        assert_eq!(dhcd_hierarchy_method(null(), &mut 0), DHCD_ERR_NULL);
        assert_eq!(
            dhcd_contact_segments(a, a, null(), 0, null_mut()),
            DHCD_OK,
            "empty result"
        );
        assert_eq!(
            dhcd_contact_segments(a, a, null(), 1, [0.0f32; 6].as_mut_ptr()),
            DHCD_ERR_NULL
        );
        assert_eq!(
            dhcd_contact_segments(a, a, [0u32, 0].as_ptr(), 1, null_mut()),
            DHCD_ERR_NULL
        );
        assert_eq!(
            dhcd_contact_segments(null(), a, null(), 0, null_mut()),
            DHCD_ERR_NULL
        );
        assert_eq!(
            dhcd_scene_add(null_mut(), p.as_ptr(), nv, t.as_ptr(), nt, 0, &mut 0),
            DHCD_ERR_NULL
        );
        assert_eq!(
            dhcd_scene_contacts(null_mut(), 1, null_mut()),
            DHCD_ERR_NULL
        );
        assert_eq!(dhcd_scene_new(DHCD_METHOD_DH, 5, null_mut()), DHCD_ERR_NULL);
        // Mismatched lengths and bad meshes.
        assert_eq!(
            dhcd_hierarchy_update_positions(a, p.as_ptr(), nv - 1),
            DHCD_ERR_LENGTH_MISMATCH
        );
        assert!(last_error().contains("vertices"), "{}", last_error());
        assert_eq!(
            dhcd_hierarchy_new(DHCD_METHOD_DH, 4, p.as_ptr(), 0, t.as_ptr(), nt, &mut h),
            DHCD_ERR_INVALID_MESH
        );
        assert_eq!(
            dhcd_hierarchy_new(DHCD_METHOD_DH, 4, p.as_ptr(), 3, t.as_ptr(), nt, &mut h),
            DHCD_ERR_INVALID_MESH
        );
        let mut nan = p.clone();
        nan[4] = f32::NAN;
        assert_eq!(
            dhcd_hierarchy_new(DHCD_METHOD_DH, 4, nan.as_ptr(), nv, t.as_ptr(), nt, &mut h),
            DHCD_ERR_INVALID_MESH
        );
        assert_eq!(
            dhcd_hierarchy_update_positions(a, nan.as_ptr(), nv),
            DHCD_ERR_INVALID_MESH
        );
        assert_eq!(
            dhcd_hierarchy_new(
                DHCD_METHOD_DH,
                4,
                p.as_ptr(),
                usize::MAX / 2,
                t.as_ptr(),
                nt,
                &mut h
            ),
            DHCD_ERR_INVALID_ARGUMENT
        );
        // Misaligned array.
        let bytes = [0u8; 64];
        let odd = bytes.as_ptr().add(1).cast::<f32>();
        assert_eq!(
            dhcd_hierarchy_update_positions(a, odd, 1),
            DHCD_ERR_INVALID_ARGUMENT
        );
        // Bad method, bad levels.
        assert_eq!(
            dhcd_hierarchy_new(7, 4, p.as_ptr(), nv, t.as_ptr(), nt, &mut h),
            DHCD_ERR_INVALID_ARGUMENT
        );
        assert_eq!(
            dhcd_hierarchy_new(DHCD_METHOD_DH, 17, p.as_ptr(), nv, t.as_ptr(), nt, &mut h),
            DHCD_ERR_INVALID_ARGUMENT
        );
        let mut s = null_mut();
        assert_eq!(dhcd_scene_new(-1, 5, &mut s), DHCD_ERR_INVALID_ARGUMENT);
        assert!(
            last_error().contains("DHCD_METHOD_AABB"),
            "{}",
            last_error()
        );
        assert_eq!(
            dhcd_scene_new(DHCD_METHOD_DH, 99, &mut s),
            DHCD_ERR_INVALID_ARGUMENT
        );
        assert!(h.is_null() && s.is_null());
        // Wrong method; the same handle twice.
        assert_eq!(dhcd_collide(a, b, 1, &mut c), DHCD_ERR_WRONG_KIND);
        assert!(last_error().contains("dh") && last_error().contains("aabb"));
        assert_eq!(
            dhcd_contact_segments(a, b, [0u32, 0].as_ptr(), 1, [0.0f32; 6].as_mut_ptr()),
            DHCD_ERR_WRONG_KIND
        );
        assert_eq!(dhcd_collide(a, a, 1, &mut c), DHCD_ERR_INVALID_ARGUMENT);
        assert!(
            c.pairs.is_null() && c.count == 0,
            "failed calls leave an empty result"
        );
        // Segments: out of range, stale.
        let mut seg = [0.0f32; 6];
        assert_eq!(
            dhcd_contact_segments(a, a, [0u32, 100_000].as_ptr(), 1, seg.as_mut_ptr()),
            DHCD_ERR_INVALID_ARGUMENT
        );
        let far = translated(m.positions(), [10.0, 0.0, 0.0]);
        let other = new_h(
            DHCD_METHOD_DH,
            &Mesh::new(far, m.triangles().to_vec()).unwrap(),
        );
        assert_eq!(
            dhcd_contact_segments(a, other, [0u32, 0].as_ptr(), 1, seg.as_mut_ptr()),
            DHCD_ERR_STALE_CONTACT
        );
        // Everything still works after the errors.
        assert_eq!(dhcd_collide(a, other, 1, &mut c), DHCD_OK);
        assert_eq!(c.count, 0);
        dhcd_hierarchy_free(other);
        dhcd_hierarchy_free(a);
        dhcd_hierarchy_free(b);
        dhcd_hierarchy_free(null_mut());
    }
}

#[test]
fn last_error_is_per_thread() {
    // SAFETY: null handles are allowed arguments (they are errors).
    unsafe {
        assert_eq!(dhcd_scene_remove(null_mut(), 0), DHCD_ERR_NULL);
    }
    let msg = last_error();
    assert!(msg.contains("null"), "{msg}");
    let other = std::thread::spawn(last_error).join().unwrap();
    assert_eq!(other, "");
}

/// `include/dhcd.h` is exactly what cbindgen generates from `src/lib.rs` with
/// `cbindgen.toml`. After an ABI change, regenerate it with
/// `DHCD_BLESS_HEADER=1 cargo test -p dhcd-capi --test capi header` and commit it.
#[test]
fn header_is_generated() {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut config = cbindgen::Config::from_file(root.join("cbindgen.toml")).unwrap();
    // The methods' numbers, from the library's table of methods.
    let mut kinds = String::from("\n/**\n * Hierarchy methods (`method` arguments).\n */");
    for m in Method::ALL {
        let name = m.name().to_uppercase();
        kinds += &format!("\n#define DHCD_METHOD_{name} {}", m.code());
    }
    // The distance types' numbers, from the library's enums (IPC's names and numbers).
    kinds += "\n\n/**\n * Point-triangle distance types (`vf_type`, `fv_type` of proximity results):\n * \
              IPC's PointTriangleDistanceType.\n */";
    for t in PointTriangle::ALL {
        kinds += &format!("\n#define DHCD_PT_{} {}", t.ipc_name(), t as u8);
    }
    kinds += "\n\n/**\n * Edge-edge distance types (`ee_type` of proximity results): IPC's\n * \
              EdgeEdgeDistanceType.\n */";
    for t in EdgeEdge::ALL {
        kinds += &format!("\n#define DHCD_EE_{} {}", t.ipc_name(), t as u8);
    }
    config.after_includes = Some(kinds);
    let mut generated = Vec::new();
    cbindgen::Builder::new()
        .with_config(config)
        .with_src(root.join("src/lib.rs"))
        .generate()
        .expect("cbindgen parses the C ABI")
        .write(&mut generated);
    let generated = String::from_utf8(generated).unwrap();
    let path = root.join("../include/dhcd.h");
    if std::env::var_os("DHCD_BLESS_HEADER").is_some() {
        std::fs::write(&path, &generated).unwrap();
    }
    let committed = std::fs::read_to_string(&path).unwrap();
    assert!(
        committed == generated,
        "include/dhcd.h differs from the header cbindgen generates; regenerate it with \
         DHCD_BLESS_HEADER=1 cargo test -p dhcd-capi --test capi header"
    );
}

#[test]
fn struct_layouts() {
    // Struct layouts the header assumes (LP64 / LLP64: size_t is pointer-sized).
    assert_eq!(std::mem::size_of::<DhcdCounters>(), 32);
    assert_eq!(
        std::mem::size_of::<DhcdContacts>(),
        2 * std::mem::size_of::<usize>() + 32
    );
    // Nine pointers and three counts, then the counters.
    for size in [
        std::mem::size_of::<DhcdProximity>(),
        std::mem::size_of::<DhcdSceneProximity>(),
    ] {
        assert_eq!(size, 12 * std::mem::size_of::<usize>() + 32);
    }
    // Six pointers and three counts, the earliest time, then the counters.
    for size in [
        std::mem::size_of::<DhcdImpacts>(),
        std::mem::size_of::<DhcdSceneImpacts>(),
    ] {
        assert_eq!(size, 9 * std::mem::size_of::<usize>() + 8 + 32);
    }
}

/// A pointer no valid handle or array has: what a C caller's uninitialised variable holds.
fn garbage<T>() -> *mut T {
    std::ptr::dangling_mut::<T>().wrapping_add(7)
}

fn garbage_contacts() -> DhcdContacts {
    DhcdContacts {
        pairs: garbage(),
        count: 99,
        counters: DhcdCounters {
            bv_tests: 1,
            prim_tests: 2,
            bv_updates: 3,
            contacts: 99,
        },
    }
}

/// Every entry point with a handle or result output empties it on error, whatever the
/// error (issue 9: `dhcd_hierarchy_new` and `dhcd_scene_new` left `*out` unchanged).
#[test]
fn every_output_is_empty_after_an_error() {
    let m = icosphere(1, 1.0, [0.0; 3]);
    let (p, t) = flat(&m);
    let ha = new_h(DHCD_METHOD_DH, &m);
    let hb = new_h(DHCD_METHOD_DH, &m);
    let hs = new_h(DHCD_METHOD_SPHERE, &m);
    let mut scene = null_mut();
    // SAFETY: live handles; arrays of the stated lengths or null; writable outputs.
    unsafe {
        assert_eq!(dhcd_scene_new(DHCD_METHOD_DH, 4, &mut scene), DHCD_OK);
        for (method, levels, positions, vertices) in [
            (99, 4, p.as_ptr(), m.vertex_count()),
            (DHCD_METHOD_DH, 99, p.as_ptr(), m.vertex_count()),
            (DHCD_METHOD_DH, 4, null(), m.vertex_count()),
            (DHCD_METHOD_DH, 4, p.as_ptr(), 0),
        ] {
            let mut h = garbage();
            let rc = dhcd_hierarchy_new(
                method,
                levels,
                positions,
                vertices,
                t.as_ptr(),
                m.triangle_count(),
                &mut h,
            );
            assert_ne!(rc, DHCD_OK);
            assert!(h.is_null(), "dhcd_hierarchy_new: {}", last_error());
        }
        for (method, levels) in [(99, 4), (DHCD_METHOD_DH, 99)] {
            let mut s = garbage();
            assert_ne!(dhcd_scene_new(method, levels, &mut s), DHCD_OK);
            assert!(s.is_null(), "dhcd_scene_new: {}", last_error());
        }
        let bad_collides: [(*mut DhcdHierarchy, *mut DhcdHierarchy, u32); 5] = [
            (ha, ha, 1),
            (ha, null_mut(), 1),
            (ha, hs, 1),
            (ha, hb, u32::MAX),
            (ha, hb, 16_384),
        ];
        for (a, b, threads) in bad_collides {
            let mut c = garbage_contacts();
            assert_ne!(dhcd_collide(a, b, threads, &mut c), DHCD_OK);
            assert!(
                c.pairs.is_null() && c.count == 0,
                "dhcd_collide: {}",
                last_error()
            );
            assert_eq!(c.counters, DhcdCounters::default());
        }
        for (h, threads) in [(null_mut(), 1), (ha, u32::MAX)] {
            let mut c = garbage_contacts();
            assert_ne!(dhcd_self_collide(h, threads, &mut c), DHCD_OK);
            assert!(c.pairs.is_null() && c.count == 0, "dhcd_self_collide");
        }
        for (s, threads) in [(null_mut(), 1), (scene, u32::MAX)] {
            let mut c = DhcdSceneContacts {
                pairs: garbage(),
                count: 99,
                counters: DhcdCounters::default(),
            };
            assert_ne!(dhcd_scene_contacts(s, threads, &mut c), DHCD_OK);
            assert!(c.pairs.is_null() && c.count == 0, "dhcd_scene_contacts");
        }
        dhcd_scene_free(scene);
        for h in [ha, hb, hs] {
            dhcd_hierarchy_free(h);
        }
    }
}

/// `threads` above `MAX_THREADS` is an invalid argument (it used to start up to 65,535
/// rayon workers, or hang); any accepted count runs on at most the machine's threads and
/// gives the sequential answer.
#[test]
fn thread_counts_are_checked() {
    let a = icosphere(1, 1.0, [0.0; 3]);
    let b = Mesh::new(
        translated(a.positions(), [0.5, 0.0, 0.0]),
        a.triangles().to_vec(),
    )
    .unwrap();
    let (ha, hb) = (new_h(DHCD_METHOD_AABB, &a), new_h(DHCD_METHOD_AABB, &b));
    // SAFETY: live handles, writable outputs.
    unsafe {
        for threads in [u32::MAX, dhcd::Par::MAX_THREADS as u32 + 1] {
            let mut c = empty();
            assert_eq!(
                dhcd_collide(ha, hb, threads, &mut c),
                DHCD_ERR_INVALID_ARGUMENT
            );
            let message = last_error();
            assert!(message.contains(&threads.to_string()), "{message}");
        }
        for threads in [0, 1, 2, dhcd::Par::MAX_THREADS as u32] {
            let mut c = empty();
            assert_eq!(dhcd_collide(ha, hb, threads, &mut c), DHCD_OK);
            assert_eq!(pairs_of(&c), brute_force_pairs(&a, &b), "{threads}");
            dhcd_contacts_free(&mut c);
        }
        dhcd_hierarchy_free(ha);
        dhcd_hierarchy_free(hb);
    }
}

// ---------------------------------------------------------------------------------------------
// f64 geometry and proximity
// ---------------------------------------------------------------------------------------------

use dhcd::query::{EdgePair, FaceVertex, VertexFace};
use dhcd::{AnyHierarchy, Counters, Options, Par, Proximity, Workspace};

const METHODS: [i32; 3] = [DHCD_METHOD_DH, DHCD_METHOD_SPHERE, DHCD_METHOD_AABB];

fn options4() -> Options {
    Options {
        levels: Some(4),
        ..Options::default()
    }
}

fn method_of(code: i32) -> Method {
    Method::from_code(code).unwrap()
}

/// `positions` as `f64`, each coordinate moved off the `f32` grid by a few 1e-9 (so the
/// `f64` hierarchy has something to be exact about).
fn off_grid(positions: &[[f32; 3]]) -> Vec<[f64; 3]> {
    positions
        .iter()
        .enumerate()
        .map(|(k, p)| {
            let nudge = 1e-9 * ((k * 7 % 13) as f64 - 6.0);
            p.map(|x| f64::from(x) + nudge)
        })
        .collect()
}

fn mesh64(positions: Vec<[f64; 3]>, like: &Mesh) -> Mesh {
    Mesh::new_f64(positions, like.triangles().to_vec()).unwrap()
}

/// A C hierarchy of `mesh` (of either precision) with 4 levels.
fn new_any(method: i32, mesh: &Mesh) -> *mut DhcdHierarchy {
    let Some(p) = mesh.positions_f64() else {
        return new_h(method, mesh);
    };
    let p: Vec<f64> = p.iter().flatten().copied().collect();
    let t: Vec<u32> = mesh.triangles().iter().flatten().copied().collect();
    let mut h = garbage();
    // SAFETY: arrays of the stated lengths; `h` writable.
    let rc = unsafe {
        dhcd_hierarchy_new_f64(
            method,
            4,
            p.as_ptr(),
            mesh.vertex_count(),
            t.as_ptr(),
            mesh.triangle_count(),
            &mut h,
        )
    };
    assert_eq!(rc, DHCD_OK, "{}", last_error());
    h
}

/// Gives a C hierarchy and its Rust twin the positions of `mesh` (either precision).
fn update_both(h: *mut DhcdHierarchy, rust: &mut AnyHierarchy, mesh: &Mesh) {
    // SAFETY: a live handle; arrays of the stated lengths.
    let rc = unsafe {
        match mesh.positions_f64() {
            Some(p) => {
                rust.update_positions_f64(p).unwrap();
                let f: Vec<f64> = p.iter().flatten().copied().collect();
                dhcd_hierarchy_update_positions_f64(h, f.as_ptr(), p.len())
            }
            None => {
                rust.update_positions(mesh.positions()).unwrap();
                let f: Vec<f32> = mesh.positions().iter().flatten().copied().collect();
                dhcd_hierarchy_update_positions(h, f.as_ptr(), mesh.vertex_count())
            }
        }
    };
    assert_eq!(rc, DHCD_OK, "{}", last_error());
}

/// `n` elements at `ptr`; a count of 0 must come with a null pointer.
///
/// # Safety
/// `ptr` holds `n` elements when `n > 0`.
unsafe fn part<'a, T>(ptr: *const T, n: usize) -> &'a [T] {
    if n == 0 {
        assert!(ptr.is_null(), "an empty array is null");
        return &[];
    }
    assert!(!ptr.is_null());
    // SAFETY: caller's contract.
    unsafe { std::slice::from_raw_parts(ptr, n) }
}

fn counters_of(c: DhcdCounters) -> Counters {
    Counters {
        bv_tests: c.bv_tests,
        prim_tests: c.prim_tests,
        bv_updates: c.bv_updates,
        contacts: c.contacts,
    }
}

fn no_proximity() -> DhcdProximity {
    DhcdProximity {
        vertex_face: garbage(),
        vf_distance_sq: garbage(),
        vf_type: garbage(),
        vf_count: 9,
        face_vertex: garbage(),
        fv_distance_sq: garbage(),
        fv_type: garbage(),
        fv_count: 9,
        edge_edge: garbage(),
        ee_distance_sq: garbage(),
        ee_type: garbage(),
        ee_count: 9,
        counters: DhcdCounters {
            bv_tests: 1,
            prim_tests: 2,
            bv_updates: 3,
            contacts: 4,
        },
    }
}

fn is_empty(p: &DhcdProximity) -> bool {
    p.vertex_face.is_null()
        && p.vf_distance_sq.is_null()
        && p.vf_type.is_null()
        && p.face_vertex.is_null()
        && p.fv_distance_sq.is_null()
        && p.fv_type.is_null()
        && p.edge_edge.is_null()
        && p.ee_distance_sq.is_null()
        && p.ee_type.is_null()
        && p.vf_count == 0
        && p.fv_count == 0
        && p.ee_count == 0
        && p.counters == DhcdCounters::default()
}

fn is_empty_scene(p: &DhcdSceneProximity) -> bool {
    p.vertex_face.is_null()
        && p.vf_distance_sq.is_null()
        && p.vf_type.is_null()
        && p.face_vertex.is_null()
        && p.fv_distance_sq.is_null()
        && p.fv_type.is_null()
        && p.edge_edge.is_null()
        && p.ee_distance_sq.is_null()
        && p.ee_type.is_null()
        && p.vf_count == 0
        && p.fv_count == 0
        && p.ee_count == 0
        && p.counters == DhcdCounters::default()
}

/// A filled `DhcdProximity` as the library's `Proximity`; the C result is released (and
/// then empty).
///
/// # Safety
/// `p` filled by the library and not released.
unsafe fn taken_proximity(p: &mut DhcdProximity) -> Proximity {
    let pt = |t: u8| PointTriangle::ALL[t as usize];
    // SAFETY: the library wrote the stated number of elements at each array.
    let out = unsafe {
        let (vf, vd, vt) = (
            part(p.vertex_face, 2 * p.vf_count),
            part(p.vf_distance_sq, p.vf_count),
            part(p.vf_type, p.vf_count),
        );
        let (fv, fd, ft) = (
            part(p.face_vertex, 2 * p.fv_count),
            part(p.fv_distance_sq, p.fv_count),
            part(p.fv_type, p.fv_count),
        );
        let (ee, ed, et) = (
            part(p.edge_edge, 4 * p.ee_count),
            part(p.ee_distance_sq, p.ee_count),
            part(p.ee_type, p.ee_count),
        );
        Proximity {
            vertex_face: (0..p.vf_count)
                .map(|k| VertexFace {
                    vertex: vf[2 * k],
                    triangle: vf[2 * k + 1],
                    distance_sq: vd[k],
                    kind: pt(vt[k]),
                })
                .collect(),
            face_vertex: (0..p.fv_count)
                .map(|k| FaceVertex {
                    triangle: fv[2 * k],
                    vertex: fv[2 * k + 1],
                    distance_sq: fd[k],
                    kind: pt(ft[k]),
                })
                .collect(),
            edge_edge: (0..p.ee_count)
                .map(|k| EdgePair {
                    a: [ee[4 * k], ee[4 * k + 1]],
                    b: [ee[4 * k + 2], ee[4 * k + 3]],
                    distance_sq: ed[k],
                    kind: EdgeEdge::ALL[et[k] as usize],
                })
                .collect(),
            counters: counters_of(p.counters),
        }
    };
    // SAFETY: filled by the library, released once (the second call is a no-op).
    unsafe {
        dhcd_proximity_free(p);
        assert!(is_empty(p), "released");
        dhcd_proximity_free(p);
    }
    out
}

/// `dhcd_proximity(a, b, d, threads)` as the library's type.
fn c_proximity(a: *mut DhcdHierarchy, b: *mut DhcdHierarchy, d: f64, threads: u32) -> Proximity {
    let mut p = no_proximity();
    // SAFETY: live handles, writable output.
    unsafe {
        let rc = dhcd_proximity(a, b, d, threads, &mut p);
        assert_eq!(rc, DHCD_OK, "{}", last_error());
        taken_proximity(&mut p)
    }
}

fn c_self_proximity(h: *mut DhcdHierarchy, d: f64, threads: u32) -> Proximity {
    let mut p = no_proximity();
    // SAFETY: a live handle, writable output.
    unsafe {
        let rc = dhcd_self_proximity(h, d, threads, &mut p);
        assert_eq!(rc, DHCD_OK, "{}", last_error());
        taken_proximity(&mut p)
    }
}

/// The meshes of the proximity tests: a ball, a second one rippled beside it (within
/// `0.05` of the first in places), the second in another pose, and the first crumpled (so
/// it comes within the distance of itself); in `f32`, or `f64` off the `f32` grid.
fn proximity_meshes(f64_positions: bool) -> [Mesh; 4] {
    let a = icosphere(2, 1.0, [0.0; 3]);
    let poses = [
        a.positions().to_vec(),
        wave(a.positions(), 0.7, 0.05, [2.0, 0.1, 0.0]),
        wave(a.positions(), 1.9, 0.08, [1.95, -0.1, 0.05]),
        wave(a.positions(), 1.3, 0.6, [0.0; 3]),
    ];
    poses.map(|p| {
        if f64_positions {
            mesh64(off_grid(&p), &a)
        } else {
            Mesh::new(p, a.triangles().to_vec()).unwrap()
        }
    })
}

/// `dhcd_proximity` and `dhcd_self_proximity` equal the Rust API, every field (indices,
/// distances to the bit, types, counters), for every method, both precisions (and a pair of
/// one of each), after an update, on 1 and 2 threads.
#[test]
fn proximity_equals_the_rust_api() {
    let d = 0.06;
    let f32s = proximity_meshes(false);
    let f64s = proximity_meshes(true);
    let cases: [(&str, &[Mesh; 4], &[Mesh; 4]); 3] = [
        ("f32", &f32s, &f32s),
        ("f64", &f64s, &f64s),
        ("f32 with f64", &f32s, &f64s),
    ];
    for method in METHODS {
        let m = method_of(method);
        for (name, ma, mb) in cases {
            for threads in [1u32, 2] {
                let what = format!("{m:?}, {name}, threads {threads}");
                let par = Par::threads(threads as usize).unwrap();
                let mut ws = Workspace::default();
                let (ha, hb) = (new_any(method, &ma[0]), new_any(method, &mb[1]));
                let mut ra = AnyHierarchy::new(m, &ma[0], options4()).unwrap();
                let mut rb = AnyHierarchy::new(m, &mb[1], options4()).unwrap();
                let expected = ra.proximity(&rb, d, &mut ws, par).unwrap();
                let got = c_proximity(ha, hb, d, threads);
                assert_eq!(got, expected, "{what}");
                assert!(
                    !got.vertex_face.is_empty()
                        && !got.face_vertex.is_empty()
                        && !got.edge_edge.is_empty(),
                    "{what}: {} {} {}",
                    got.vertex_face.len(),
                    got.face_vertex.len(),
                    got.edge_edge.len()
                );
                // Another pose of b: refits counted alike.
                update_both(hb, &mut rb, &mb[2]);
                let expected = ra.proximity(&rb, d, &mut ws, par).unwrap();
                assert_eq!(c_proximity(ha, hb, d, threads), expected, "{what}, moved");
                // Self-proximity of a crumpled a.
                update_both(ha, &mut ra, &ma[3]);
                let expected = ra.self_proximity(d, &mut ws, par).unwrap();
                let got = c_self_proximity(ha, d, threads);
                assert_eq!(got, expected, "{what}, self");
                assert!(!got.vertex_face.is_empty() && !got.edge_edge.is_empty());
                assert!(got.face_vertex.is_empty());
                assert!(got.edge_edge.iter().all(|e| e.a < e.b && e.a[0] < e.a[1]));
                // SAFETY: live handles, released once.
                unsafe {
                    dhcd_hierarchy_free(ha);
                    dhcd_hierarchy_free(hb);
                }
            }
        }
    }
}

/// Rows of a scene result, each with its distance and type.
type SceneRows = (
    Vec<([u64; 4], f64, u8)>,
    Vec<([u64; 4], f64, u8)>,
    Vec<([u64; 6], f64, u8)>,
    DhcdCounters,
);

/// A filled `DhcdSceneProximity` as rows; the C result is released.
///
/// # Safety
/// `p` filled by the library and not released.
unsafe fn taken_scene_proximity(p: &mut DhcdSceneProximity) -> SceneRows {
    fn rows<const N: usize>(idx: &[u64], d: &[f64], t: &[u8]) -> Vec<([u64; N], f64, u8)> {
        (0..d.len())
            .map(|k| (std::array::from_fn(|i| idx[N * k + i]), d[k], t[k]))
            .collect()
    }
    // SAFETY: the library wrote the stated number of elements at each array.
    let out = unsafe {
        (
            rows(
                part(p.vertex_face, 4 * p.vf_count),
                part(p.vf_distance_sq, p.vf_count),
                part(p.vf_type, p.vf_count),
            ),
            rows(
                part(p.face_vertex, 4 * p.fv_count),
                part(p.fv_distance_sq, p.fv_count),
                part(p.fv_type, p.fv_count),
            ),
            rows(
                part(p.edge_edge, 6 * p.ee_count),
                part(p.ee_distance_sq, p.ee_count),
                part(p.ee_type, p.ee_count),
            ),
            p.counters,
        )
    };
    // SAFETY: filled by the library, released once (the second call is a no-op).
    unsafe {
        dhcd_scene_proximity_free(p);
        assert!(is_empty_scene(p), "released");
        dhcd_scene_proximity_free(p);
    }
    out
}

/// The Rust scene's proximity flattened as the C ABI documents it: rows with object ids,
/// each list sorted.
fn flattened(p: &dhcd::SceneProximity) -> SceneRows {
    let (mut vf, mut fv, mut ee) = (Vec::new(), Vec::new(), Vec::new());
    for pair in &p.per_pair {
        let (a, b) = (pair.a.0, pair.b.0);
        for x in &pair.proximity.vertex_face {
            let row = [a, x.vertex.into(), b, x.triangle.into()];
            vf.push((row, x.distance_sq, x.kind as u8));
        }
        for x in &pair.proximity.face_vertex {
            let row = [a, x.triangle.into(), b, x.vertex.into()];
            fv.push((row, x.distance_sq, x.kind as u8));
        }
        for x in &pair.proximity.edge_edge {
            let row = [
                a,
                x.a[0].into(),
                x.a[1].into(),
                b,
                x.b[0].into(),
                x.b[1].into(),
            ];
            ee.push((row, x.distance_sq, x.kind as u8));
        }
    }
    vf.sort_by_key(|r| r.0);
    fv.sort_by_key(|r| r.0);
    ee.sort_by_key(|r| r.0);
    (vf, fv, ee, p.counters.into())
}

/// `dhcd_scene_proximity` equals the Rust scene's, flattened: objects of both precisions, one
/// with self-collision on, one far away; every method, 1 and 2 threads.
#[test]
fn scene_proximity_equals_the_rust_scene() {
    let d = 0.06;
    let [a, b, _, _] = proximity_meshes(false);
    let [_, b64, _, crumpled64] = proximity_meshes(true);
    let far = Mesh::new(
        translated(a.positions(), [40.0, 0.0, 0.0]),
        a.triangles().to_vec(),
    )
    .unwrap();
    // (rest pose, pose, self-collision)
    let objects: [(&Mesh, &Mesh, bool); 4] = [
        (&a, &a, false),
        (&b64, &crumpled64, true),
        (&a, &b, false),
        (&a, &far, false),
    ];
    for method in METHODS {
        for threads in [1u32, 2] {
            let mut rust = dhcd::Scene::new(method_of(method), options4());
            let mut s = null_mut();
            // SAFETY: live handles, arrays of the stated lengths, writable outputs.
            unsafe {
                assert_eq!(dhcd_scene_new(method, 4, &mut s), DHCD_OK);
                for (rest, pose, self_collision) in objects {
                    let t: Vec<u32> = rest.triangles().iter().flatten().copied().collect();
                    let (nv, nt) = (rest.vertex_count(), rest.triangle_count());
                    let mut id = u64::MAX;
                    let rid = rust.add(rest).unwrap();
                    rust.set_self_collision(rid, self_collision).unwrap();
                    let rc = match (rest.positions_f64(), pose.positions_f64()) {
                        (Some(p), Some(q)) => {
                            let p: Vec<f64> = p.iter().flatten().copied().collect();
                            let rc = dhcd_scene_add_f64(
                                s,
                                p.as_ptr(),
                                nv,
                                t.as_ptr(),
                                nt,
                                self_collision.into(),
                                &mut id,
                            );
                            assert_eq!(rc, DHCD_OK, "{}", last_error());
                            rust.update_positions_f64(rid, q).unwrap();
                            let q: Vec<f64> = q.iter().flatten().copied().collect();
                            dhcd_scene_update_positions_f64(s, id, q.as_ptr(), nv)
                        }
                        _ => {
                            let (p, _) = flat(rest);
                            let rc = dhcd_scene_add(
                                s,
                                p.as_ptr(),
                                nv,
                                t.as_ptr(),
                                nt,
                                self_collision.into(),
                                &mut id,
                            );
                            assert_eq!(rc, DHCD_OK, "{}", last_error());
                            rust.update_positions(rid, pose.positions()).unwrap();
                            let (q, _) = flat(pose);
                            dhcd_scene_update_positions(s, id, q.as_ptr(), nv)
                        }
                    };
                    assert_eq!(rc, DHCD_OK, "{}", last_error());
                    assert_eq!(id, rid.0);
                }
                let expected = rust
                    .proximity(d, Par::threads(threads as usize).unwrap())
                    .unwrap();
                let mut p = DhcdSceneProximity {
                    vertex_face: garbage(),
                    vf_count: 3,
                    ..std::mem::zeroed()
                };
                let rc = dhcd_scene_proximity(s, d, threads, &mut p);
                assert_eq!(rc, DHCD_OK, "{}", last_error());
                let got = taken_scene_proximity(&mut p);
                assert_eq!(got, flattened(&expected), "{method}, {threads}");
                let (vf, fv, ee, counters) = got;
                assert!(!vf.is_empty() && !fv.is_empty() && !ee.is_empty());
                assert_eq!(counters.contacts as usize, vf.len() + fv.len() + ee.len());
                // Pairs between objects and inside object 1; nothing of the far object 3.
                for q in [1, 2] {
                    assert!(vf.iter().any(|r| r.0[0] == 0 && r.0[2] == q));
                }
                assert!(vf.iter().any(|r| r.0[0] == 1 && r.0[2] == 1));
                assert!(ee.iter().any(|r| r.0[0] == 1 && r.0[3] == 1));
                assert!(fv.iter().all(|r| r.0[0] < r.0[2]));
                assert!(vf.iter().all(|r| r.0[0] != 3 && r.0[2] != 3));
                dhcd_scene_free(s);
            }
        }
    }
}

/// Triangle A in the plane z = 1; triangle B above it with its lowest corner `gap` above A's
/// interior (`1 + gap` in `f64`, which rounds to `1.0f32` for a gap below 3e-8).
fn near_pair(gap: f64) -> ([f64; 9], [f64; 9]) {
    let a = [0.0, 0.0, 1.0, 2.0, 0.0, 1.0, 0.0, 2.0, 1.0];
    let b = [0.5, 0.5, 1.0 + gap, 0.5, 0.5, 2.0, 0.2, 0.8, 2.0];
    (a, b)
}

fn as_f32(p: &[f64]) -> Vec<f32> {
    p.iter().map(|&x| x as f32).collect()
}

/// An `f64` hierarchy decides for the `double` coordinates: B 1e-9 above A touches nothing
/// (its `float` rounding touches A), and comes within 2e-9 (not 5e-10) of it; updates in
/// `double` move it across A's plane and back.
#[test]
fn f64_hierarchies_are_exact_for_doubles() {
    let tri = [0u32, 1, 2];
    let (a, b) = near_pair(1e-9);
    for method in METHODS {
        // SAFETY: arrays of the stated lengths, live handles, writable outputs.
        unsafe {
            let (mut ha, mut hb, mut ha32, mut hb32) = (garbage(), garbage(), garbage(), garbage());
            for (h, p) in [(&mut ha, &a), (&mut hb, &b)] {
                let rc = dhcd_hierarchy_new_f64(method, 0, p.as_ptr(), 3, tri.as_ptr(), 1, h);
                assert_eq!(rc, DHCD_OK, "{}", last_error());
            }
            for (h, p) in [(&mut ha32, &a), (&mut hb32, &b)] {
                let p = as_f32(p);
                let rc = dhcd_hierarchy_new(method, 0, p.as_ptr(), 3, tri.as_ptr(), 1, h);
                assert_eq!(rc, DHCD_OK, "{}", last_error());
            }
            let mut precision = 0;
            assert_eq!(dhcd_hierarchy_precision(ha, &mut precision), DHCD_OK);
            assert_eq!(precision, DHCD_PRECISION_F64);
            assert_eq!(precision, 64);
            assert_eq!(dhcd_hierarchy_precision(ha32, &mut precision), DHCD_OK);
            assert_eq!(precision, DHCD_PRECISION_F32);
            assert_eq!(precision, 32);

            let collide = |x, y| -> Vec<[u32; 2]> {
                let mut c = empty();
                assert_eq!(dhcd_collide(x, y, 1, &mut c), DHCD_OK, "{}", last_error());
                let pairs = pairs_of(&c);
                dhcd_contacts_free(&mut c);
                pairs
            };
            // Rounded to float, B's corner lies on A; in double it is above.
            assert_eq!(collide(ha32, hb32), vec![[0, 0]]);
            assert!(collide(ha, hb).is_empty());
            let gap = (1.0 + 1e-9) - 1.0; // exact in f64
            let p = c_proximity(ha, hb, 2e-9, 1);
            assert!(p.vertex_face.is_empty() && p.edge_edge.is_empty());
            assert_eq!(p.face_vertex.len(), 1);
            let fv = p.face_vertex[0];
            assert_eq!(
                (fv.triangle, fv.vertex, fv.kind),
                (0, 0, PointTriangle::Face)
            );
            assert_eq!(fv.distance_sq, gap * gap);
            let none = c_proximity(ha, hb, 5e-10, 2);
            assert!(none.vertex_face.is_empty() && none.face_vertex.is_empty());
            assert!(none.edge_edge.is_empty());
            let p32 = c_proximity(ha32, hb32, 5e-10, 1);
            assert_eq!(p32.face_vertex.len(), 1);
            assert_eq!(p32.face_vertex[0].distance_sq, 0.0);
            // Round trip: below A's plane (B crosses A), then back above.
            let (_, down) = near_pair(-1e-9);
            assert_eq!(
                dhcd_hierarchy_update_positions_f64(hb, down.as_ptr(), 3),
                DHCD_OK
            );
            assert_eq!(collide(ha, hb), vec![[0, 0]]);
            assert_eq!(
                dhcd_hierarchy_update_positions_f64(hb, b.as_ptr(), 3),
                DHCD_OK
            );
            assert!(collide(ha, hb).is_empty());
            // A mixed pair: each side exact for its own coordinates.
            assert!(collide(ha32, hb).is_empty());
            assert_eq!(collide(ha, hb32), vec![[0, 0]]);
            for h in [ha, hb, ha32, hb32] {
                dhcd_hierarchy_free(h);
            }
        }
    }
}

/// Positions of the other precision are `DHCD_ERR_PRECISION` with the library's message, and
/// change nothing; `double` coordinates beyond the `float` range are an invalid mesh.
#[test]
fn precision_mismatches_are_errors_and_change_nothing() {
    let m = icosphere(1, 1.0, [0.0; 3]);
    let (p32, t) = flat(&m);
    let nv = m.vertex_count();
    let p64: Vec<f64> = p32.iter().map(|&x| f64::from(x)).collect();
    let far64: Vec<f64> = p64.iter().map(|x| x + 10.0).collect();
    let far32 = as_f32(&far64);
    let h64 = new_any(DHCD_METHOD_DH, &mesh64(off_grid(m.positions()), &m));
    let h32 = new_h(DHCD_METHOD_DH, &m);
    let other = new_h(DHCD_METHOD_DH, &m);
    // SAFETY: live handles; arrays of the stated lengths; writable outputs.
    unsafe {
        let count = |h| {
            let mut c = empty();
            assert_eq!(dhcd_collide(h, other, 1, &mut c), DHCD_OK);
            let n = c.count;
            dhcd_contacts_free(&mut c);
            n
        };
        let before = (count(h64), count(h32));
        assert!(before.0 > 0 && before.1 > 0);
        assert_eq!(
            dhcd_hierarchy_update_positions(h64, far32.as_ptr(), nv),
            DHCD_ERR_PRECISION
        );
        assert!(
            last_error().contains("positions are f32, but the mesh or hierarchy is f64"),
            "{}",
            last_error()
        );
        assert_eq!(
            dhcd_hierarchy_update_positions_f64(h32, far64.as_ptr(), nv),
            DHCD_ERR_PRECISION
        );
        assert!(
            last_error().contains("positions are f64"),
            "{}",
            last_error()
        );
        assert_eq!((count(h64), count(h32)), before, "nothing moved");

        // Out of float range, NaN: invalid meshes, at build and update.
        let mut big = p64.clone();
        big[4] = 1e39;
        let mut nan = p64.clone();
        nan[4] = f64::NAN;
        for (bad, message) in [(&big, "f32 range"), (&nan, "non-finite")] {
            let mut h = garbage();
            let rc = dhcd_hierarchy_new_f64(
                DHCD_METHOD_DH,
                4,
                bad.as_ptr(),
                nv,
                t.as_ptr(),
                m.triangle_count(),
                &mut h,
            );
            assert_eq!(rc, DHCD_ERR_INVALID_MESH);
            assert!(h.is_null());
            assert!(last_error().contains(message), "{}", last_error());
            assert_eq!(
                dhcd_hierarchy_update_positions_f64(h64, bad.as_ptr(), nv),
                DHCD_ERR_INVALID_MESH
            );
            assert!(last_error().contains(message), "{}", last_error());
        }
        assert_eq!(
            dhcd_hierarchy_update_positions_f64(h64, far64.as_ptr(), nv - 1),
            DHCD_ERR_LENGTH_MISMATCH
        );
        assert_eq!((count(h64), count(h32)), before, "nothing moved");

        // A scene of one f32 and one f64 object.
        let mut s = null_mut();
        assert_eq!(dhcd_scene_new(DHCD_METHOD_AABB, 4, &mut s), DHCD_OK);
        let (mut a, mut b) = (u64::MAX, u64::MAX);
        let nt = m.triangle_count();
        assert_eq!(
            dhcd_scene_add(s, p32.as_ptr(), nv, t.as_ptr(), nt, 0, &mut a),
            DHCD_OK
        );
        assert_eq!(
            dhcd_scene_add_f64(s, p64.as_ptr(), nv, t.as_ptr(), nt, 0, &mut b),
            DHCD_OK
        );
        let mut id = 7;
        assert_eq!(
            dhcd_scene_add_f64(s, big.as_ptr(), nv, t.as_ptr(), nt, 0, &mut id),
            DHCD_ERR_INVALID_MESH
        );
        assert_eq!(id, 7, "no id on error");
        let before = scene_contacts(s).0;
        assert!(!before.is_empty());
        assert_eq!(
            dhcd_scene_update_positions(s, b, far32.as_ptr(), nv),
            DHCD_ERR_PRECISION
        );
        assert_eq!(
            dhcd_scene_update_positions_f64(s, a, far64.as_ptr(), nv),
            DHCD_ERR_PRECISION
        );
        assert_eq!(
            dhcd_scene_update_positions_f64(s, 9, far64.as_ptr(), nv),
            DHCD_ERR_UNKNOWN_OBJECT
        );
        // The batch calls take floats: an f64 object in them changes nothing.
        let (ids, ptrs, counts) = ([a, b], [far32.as_ptr(), far32.as_ptr()], [nv, nv]);
        assert_eq!(
            dhcd_scene_update_many(s, ids.as_ptr(), ptrs.as_ptr(), counts.as_ptr(), 2, 2),
            DHCD_ERR_PRECISION
        );
        assert!(last_error().contains("f64"), "{}", last_error());
        assert_eq!(
            scene_step(s, &ids, &ptrs, &counts, 1),
            Err(DHCD_ERR_PRECISION)
        );
        assert_eq!(scene_contacts(s).0, before, "nothing moved");
        // The right precision works.
        assert_eq!(
            dhcd_scene_update_positions_f64(s, b, far64.as_ptr(), nv),
            DHCD_OK
        );
        assert!(scene_contacts(s).0.is_empty());
        dhcd_scene_free(s);
        for h in [h64, h32, other] {
            dhcd_hierarchy_free(h);
        }
    }
}

/// A distance that is negative, NaN or infinite is `DHCD_ERR_INVALID_ARGUMENT` with the
/// library's message, and the output is empty; 0 and -0 are distances.
#[test]
fn bad_distances_are_invalid_arguments() {
    let m = icosphere(1, 1.0, [0.0; 3]);
    let (ha, hb) = (new_h(DHCD_METHOD_DH, &m), new_h(DHCD_METHOD_DH, &m));
    let (p, t) = flat(&m);
    let mut s = null_mut();
    // SAFETY: live handles; writable outputs.
    unsafe {
        assert_eq!(dhcd_scene_new(DHCD_METHOD_DH, 4, &mut s), DHCD_OK);
        let mut id = 0;
        let (nv, nt) = (m.vertex_count(), m.triangle_count());
        assert_eq!(
            dhcd_scene_add(s, p.as_ptr(), nv, t.as_ptr(), nt, 1, &mut id),
            DHCD_OK
        );
        for d in [-1.0, -1e-300, f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
            let mut out = no_proximity();
            assert_eq!(
                dhcd_proximity(ha, hb, d, 1, &mut out),
                DHCD_ERR_INVALID_ARGUMENT
            );
            assert!(is_empty(&out));
            assert!(
                last_error().contains("is not a finite number >= 0"),
                "{}",
                last_error()
            );
            let mut out = no_proximity();
            assert_eq!(
                dhcd_self_proximity(ha, d, 2, &mut out),
                DHCD_ERR_INVALID_ARGUMENT
            );
            assert!(is_empty(&out));
            assert!(last_error().contains("distance"), "{}", last_error());
            let mut out = DhcdSceneProximity {
                edge_edge: garbage(),
                ee_count: 5,
                ..std::mem::zeroed()
            };
            assert_eq!(
                dhcd_scene_proximity(s, d, 1, &mut out),
                DHCD_ERR_INVALID_ARGUMENT
            );
            assert!(is_empty_scene(&out));
            assert!(last_error().contains("distance"), "{}", last_error());
        }
        for d in [0.0, -0.0] {
            let touching = c_proximity(ha, hb, d, 1);
            assert!(!touching.vertex_face.is_empty(), "identical balls touch");
            assert!(touching.vertex_face.iter().all(|x| x.distance_sq == 0.0));
            c_self_proximity(ha, d, 1);
        }
        dhcd_scene_free(s);
        dhcd_hierarchy_free(ha);
        dhcd_hierarchy_free(hb);
    }
}

/// Null handles or outputs, the same handle twice, methods that differ, misaligned or null
/// `double` arrays, thread counts out of range: error codes, and outputs left empty.
#[test]
fn proximity_and_f64_bad_arguments() {
    let m = icosphere(1, 1.0, [0.0; 3]);
    let (p, t) = flat(&m);
    let p64: Vec<f64> = p.iter().map(|&x| f64::from(x)).collect();
    let (nv, nt) = (m.vertex_count(), m.triangle_count());
    let a = new_h(DHCD_METHOD_DH, &m);
    let box_ = new_h(DHCD_METHOD_AABB, &m);
    let bytes = [0u64; 16];
    // SAFETY: every pointer is null, a live handle, or valid for its stated length (the
    // misaligned one is rejected before it is read).
    unsafe {
        let odd = bytes.as_ptr().cast::<u8>().add(4).cast::<f64>();
        let check = |rc: i32, code: i32, out: &DhcdProximity| {
            assert_eq!(rc, code, "{}", last_error());
            assert!(is_empty(out));
        };
        let mut out = no_proximity();
        check(
            dhcd_proximity(null_mut(), a, 0.1, 1, &mut out),
            DHCD_ERR_NULL,
            &out,
        );
        let mut out = no_proximity();
        check(
            dhcd_proximity(a, null_mut(), 0.1, 1, &mut out),
            DHCD_ERR_NULL,
            &out,
        );
        let mut out = no_proximity();
        check(
            dhcd_proximity(a, a, 0.1, 1, &mut out),
            DHCD_ERR_INVALID_ARGUMENT,
            &out,
        );
        assert!(last_error().contains("dhcd_self_proximity"));
        let mut out = no_proximity();
        check(
            dhcd_proximity(a, box_, 0.1, 1, &mut out),
            DHCD_ERR_WRONG_KIND,
            &out,
        );
        let mut out = no_proximity();
        check(
            dhcd_proximity(a, box_, 0.1, u32::MAX, &mut out),
            DHCD_ERR_INVALID_ARGUMENT,
            &out,
        );
        let mut out = no_proximity();
        check(
            dhcd_self_proximity(a, 0.1, 4096, &mut out),
            DHCD_ERR_INVALID_ARGUMENT,
            &out,
        );
        let mut out = no_proximity();
        check(
            dhcd_self_proximity(null_mut(), 0.1, 1, &mut out),
            DHCD_ERR_NULL,
            &out,
        );
        assert_eq!(dhcd_proximity(a, box_, 0.1, 1, null_mut()), DHCD_ERR_NULL);
        assert_eq!(dhcd_self_proximity(a, 0.1, 1, null_mut()), DHCD_ERR_NULL);
        assert_eq!(
            dhcd_scene_proximity(null_mut(), 0.1, 1, null_mut()),
            DHCD_ERR_NULL
        );
        let mut sp = DhcdSceneProximity {
            vertex_face: garbage(),
            vf_count: 2,
            ..std::mem::zeroed()
        };
        assert_eq!(
            dhcd_scene_proximity(null_mut(), 0.1, 1, &mut sp),
            DHCD_ERR_NULL
        );
        assert!(is_empty_scene(&sp));

        // f64 builds and updates.
        let mut h = garbage();
        let rc = dhcd_hierarchy_new_f64(DHCD_METHOD_DH, 4, null(), nv, t.as_ptr(), nt, &mut h);
        assert_eq!(rc, DHCD_ERR_NULL);
        assert!(h.is_null() && last_error().contains("positions"));
        let mut h = garbage();
        let rc = dhcd_hierarchy_new_f64(DHCD_METHOD_DH, 4, odd, 1, t.as_ptr(), nt, &mut h);
        assert_eq!(rc, DHCD_ERR_INVALID_ARGUMENT);
        assert!(h.is_null() && last_error().contains("aligned"));
        let mut h = garbage();
        let rc = dhcd_hierarchy_new_f64(99, 4, p64.as_ptr(), nv, t.as_ptr(), nt, &mut h);
        assert_eq!(rc, DHCD_ERR_INVALID_ARGUMENT);
        assert!(h.is_null());
        let rc = dhcd_hierarchy_new_f64(
            DHCD_METHOD_DH,
            4,
            p64.as_ptr(),
            nv,
            t.as_ptr(),
            nt,
            null_mut(),
        );
        assert_eq!(rc, DHCD_ERR_NULL);
        let rc = dhcd_hierarchy_new_f64(
            DHCD_METHOD_DH,
            4,
            p64.as_ptr(),
            usize::MAX / 4,
            t.as_ptr(),
            nt,
            &mut h,
        );
        assert_eq!(rc, DHCD_ERR_INVALID_ARGUMENT);
        assert_eq!(
            dhcd_hierarchy_update_positions_f64(null_mut(), p64.as_ptr(), nv),
            DHCD_ERR_NULL
        );
        assert_eq!(
            dhcd_hierarchy_update_positions_f64(a, null(), nv),
            DHCD_ERR_NULL
        );
        assert_eq!(
            dhcd_hierarchy_update_positions_f64(a, odd, 1),
            DHCD_ERR_INVALID_ARGUMENT
        );
        let mut precision = -1;
        assert_eq!(
            dhcd_hierarchy_precision(null(), &mut precision),
            DHCD_ERR_NULL
        );
        assert_eq!(dhcd_hierarchy_precision(a, null_mut()), DHCD_ERR_NULL);
        assert_eq!(precision, -1, "written only on success");

        // Scene f64 calls.
        let mut s = null_mut();
        assert_eq!(dhcd_scene_new(DHCD_METHOD_DH, 4, &mut s), DHCD_OK);
        let mut id = 5;
        assert_eq!(
            dhcd_scene_add_f64(null_mut(), p64.as_ptr(), nv, t.as_ptr(), nt, 0, &mut id),
            DHCD_ERR_NULL
        );
        assert_eq!(
            dhcd_scene_add_f64(s, null(), nv, t.as_ptr(), nt, 0, &mut id),
            DHCD_ERR_NULL
        );
        assert_eq!(
            dhcd_scene_add_f64(s, p64.as_ptr(), nv, null(), nt, 0, &mut id),
            DHCD_ERR_NULL
        );
        assert_eq!(
            dhcd_scene_add_f64(s, p64.as_ptr(), nv, t.as_ptr(), nt, 0, null_mut()),
            DHCD_ERR_NULL
        );
        assert_eq!(id, 5);
        assert_eq!(
            dhcd_scene_add_f64(s, p64.as_ptr(), nv, t.as_ptr(), nt, 0, &mut id),
            DHCD_OK
        );
        assert_eq!(id, 0, "failed adds used no id");
        assert_eq!(
            dhcd_scene_update_positions_f64(null_mut(), id, p64.as_ptr(), nv),
            DHCD_ERR_NULL
        );
        assert_eq!(
            dhcd_scene_update_positions_f64(s, id, null(), nv),
            DHCD_ERR_NULL
        );
        assert_eq!(
            dhcd_scene_update_positions_f64(s, id, odd, 1),
            DHCD_ERR_INVALID_ARGUMENT
        );
        assert_eq!(
            dhcd_scene_update_positions_f64(s, id, p64.as_ptr(), nv + 1),
            DHCD_ERR_LENGTH_MISMATCH
        );
        let mut sp = DhcdSceneProximity {
            face_vertex: garbage(),
            fv_count: 2,
            ..std::mem::zeroed()
        };
        assert_eq!(
            dhcd_scene_proximity(s, 0.1, u32::MAX, &mut sp),
            DHCD_ERR_INVALID_ARGUMENT
        );
        assert!(is_empty_scene(&sp));
        dhcd_scene_free(s);
        dhcd_hierarchy_free(a);
        dhcd_hierarchy_free(box_);
    }
}

/// Results with nothing in them have null arrays, and every free function takes them (and
/// null, and a result twice).
#[test]
fn empty_proximity_results_free() {
    let m = icosphere(1, 1.0, [0.0; 3]);
    let far = Mesh::new(
        translated(m.positions(), [10.0, 0.0, 0.0]),
        m.triangles().to_vec(),
    )
    .unwrap();
    let (a, b) = (
        new_h(DHCD_METHOD_SPHERE, &m),
        new_h(DHCD_METHOD_SPHERE, &far),
    );
    let (p, t) = flat(&m);
    // SAFETY: live handles, writable outputs; results released once (then no-ops).
    unsafe {
        let mut out = no_proximity();
        assert_eq!(dhcd_proximity(a, b, 0.5, 1, &mut out), DHCD_OK);
        assert!(out.vf_count == 0 && out.fv_count == 0 && out.ee_count == 0);
        assert!(out.vertex_face.is_null() && out.vf_distance_sq.is_null() && out.ee_type.is_null());
        assert!(out.counters.bv_tests > 0, "counters are filled");
        dhcd_proximity_free(&mut out);
        assert!(is_empty(&out));
        dhcd_proximity_free(&mut out);
        dhcd_proximity_free(null_mut());
        let mut zero: DhcdProximity = std::mem::zeroed();
        dhcd_proximity_free(&mut zero);

        let mut s = null_mut();
        assert_eq!(dhcd_scene_new(DHCD_METHOD_SPHERE, 0, &mut s), DHCD_OK);
        let mut sp: DhcdSceneProximity = std::mem::zeroed();
        assert_eq!(
            dhcd_scene_proximity(s, 0.5, 2, &mut sp),
            DHCD_OK,
            "an empty scene"
        );
        assert!(is_empty_scene(&sp));
        let mut id = 0;
        let (nv, nt) = (m.vertex_count(), m.triangle_count());
        assert_eq!(
            dhcd_scene_add(s, p.as_ptr(), nv, t.as_ptr(), nt, 0, &mut id),
            DHCD_OK
        );
        assert_eq!(dhcd_scene_proximity(s, 0.5, 1, &mut sp), DHCD_OK);
        assert!(is_empty_scene(&sp), "one object, self-collision off");
        dhcd_scene_proximity_free(&mut sp);
        dhcd_scene_proximity_free(&mut sp);
        dhcd_scene_proximity_free(null_mut());
        dhcd_scene_free(s);
        dhcd_hierarchy_free(a);
        dhcd_hierarchy_free(b);
    }
}

/// The distance types' C numbers are the library's enums' (IPC's), in `ALL` order, and the
/// header defines each of them.
#[test]
fn distance_type_numbers_are_the_library_enums() {
    let header = include_str!("../../include/dhcd.h");
    for (k, t) in PointTriangle::ALL.into_iter().enumerate() {
        assert_eq!(t as usize, k);
        let define = format!("#define DHCD_PT_{} {k}\n", t.ipc_name());
        assert!(header.contains(&define), "{define}");
    }
    for (k, t) in EdgeEdge::ALL.into_iter().enumerate() {
        assert_eq!(t as usize, k);
        let define = format!("#define DHCD_EE_{} {k}\n", t.ipc_name());
        assert!(header.contains(&define), "{define}");
    }
    assert!(header.contains("#define DHCD_PT_P_T 6\n"));
    assert!(header.contains("#define DHCD_EE_EA_EB 8\n"));
    assert_eq!(DHCD_ERR_PRECISION, -10);
}

// ---------------------------------------------------------------------------------------------
// Continuous collision detection
// ---------------------------------------------------------------------------------------------

use dhcd::ccd::CcdOptions;
use dhcd::narrow::{brute_force_ccd, brute_force_self_ccd, earliest_of};
use dhcd::query::{EdgeImpact, FaceImpact, VertexImpact};
use dhcd::shapes::{grid, jitter};
use dhcd::{CcdMode, CcdQuery, Impacts, Motion};

fn f64s(p: &[[f32; 3]]) -> Vec<[f64; 3]> {
    p.iter().map(|q| q.map(f64::from)).collect()
}

fn flat64(p: &[[f64; 3]]) -> Vec<f64> {
    p.iter().flatten().copied().collect()
}

/// A result no call wrote: what a C caller's uninitialised variable holds.
fn garbage_impacts() -> DhcdImpacts {
    DhcdImpacts {
        vertex_face: garbage(),
        vf_toi: garbage(),
        vf_count: 9,
        face_vertex: garbage(),
        fv_toi: garbage(),
        fv_count: 9,
        edge_edge: garbage(),
        ee_toi: garbage(),
        ee_count: 9,
        toi: 0.25,
        counters: DhcdCounters {
            bv_tests: 1,
            prim_tests: 2,
            bv_updates: 3,
            contacts: 4,
        },
    }
}

fn is_empty_impacts(p: &DhcdImpacts) -> bool {
    p.vertex_face.is_null()
        && p.vf_toi.is_null()
        && p.face_vertex.is_null()
        && p.fv_toi.is_null()
        && p.edge_edge.is_null()
        && p.ee_toi.is_null()
        && p.vf_count == 0
        && p.fv_count == 0
        && p.ee_count == 0
        && p.toi == f64::INFINITY
        && p.counters == DhcdCounters::default()
}

/// A filled `DhcdImpacts` as the library's `Impacts`; the C result is released (and then
/// empty).
///
/// # Safety
/// `p` filled by the library and not released.
unsafe fn taken_impacts(p: &mut DhcdImpacts) -> Impacts {
    // SAFETY: the library wrote the stated number of elements at each array.
    let out = unsafe {
        let (vf, vt) = (
            part(p.vertex_face, 2 * p.vf_count),
            part(p.vf_toi, p.vf_count),
        );
        let (fv, ft) = (
            part(p.face_vertex, 2 * p.fv_count),
            part(p.fv_toi, p.fv_count),
        );
        let (ee, et) = (
            part(p.edge_edge, 4 * p.ee_count),
            part(p.ee_toi, p.ee_count),
        );
        Impacts {
            vertex_face: (0..p.vf_count)
                .map(|k| VertexImpact {
                    vertex: vf[2 * k],
                    triangle: vf[2 * k + 1],
                    toi: vt[k],
                })
                .collect(),
            face_vertex: (0..p.fv_count)
                .map(|k| FaceImpact {
                    triangle: fv[2 * k],
                    vertex: fv[2 * k + 1],
                    toi: ft[k],
                })
                .collect(),
            edge_edge: (0..p.ee_count)
                .map(|k| EdgeImpact {
                    a: [ee[4 * k], ee[4 * k + 1]],
                    b: [ee[4 * k + 2], ee[4 * k + 3]],
                    toi: et[k],
                })
                .collect(),
            toi: (p.toi != f64::INFINITY).then_some(p.toi),
            counters: counters_of(p.counters),
        }
    };
    // SAFETY: filled by the library, released once (the second call is a no-op).
    unsafe {
        dhcd_impacts_free(p);
        assert!(is_empty_impacts(p), "released");
        dhcd_impacts_free(p);
    }
    out
}

/// `dhcd_self_ccd` as the library's type.
fn c_self_ccd(
    h: *mut DhcdHierarchy,
    x0: &[[f64; 3]],
    x1: &[[f64; 3]],
    q: CcdQuery,
    threads: u32,
) -> Impacts {
    assert_eq!(x0.len(), x1.len());
    let (f0, f1) = (flat64(x0), flat64(x1));
    let mut p = garbage_impacts();
    let earliest = i32::from(q.mode == CcdMode::Earliest);
    let o = q.options;
    // SAFETY: a live handle, arrays of the stated lengths, a writable output.
    unsafe {
        let rc = dhcd_self_ccd(
            h,
            f0.as_ptr(),
            f1.as_ptr(),
            x0.len(),
            o.t_max,
            o.min_distance,
            earliest,
            threads,
            &mut p,
        );
        assert_eq!(rc, DHCD_OK, "{}", last_error());
        taken_impacts(&mut p)
    }
}

/// `dhcd_ccd` as the library's type.
fn c_ccd(
    a: *mut DhcdHierarchy,
    am: Motion<'_>,
    b: *mut DhcdHierarchy,
    bm: Motion<'_>,
    q: CcdQuery,
    threads: u32,
) -> Impacts {
    let [a0, a1, b0, b1] = [am.x0, am.x1, bm.x0, bm.x1].map(flat64);
    let mut p = garbage_impacts();
    let earliest = i32::from(q.mode == CcdMode::Earliest);
    let o = q.options;
    // SAFETY: live handles, arrays of the stated lengths, a writable output.
    unsafe {
        let rc = dhcd_ccd(
            a,
            a0.as_ptr(),
            a1.as_ptr(),
            am.x0.len(),
            b,
            b0.as_ptr(),
            b1.as_ptr(),
            bm.x0.len(),
            o.t_max,
            o.min_distance,
            earliest,
            threads,
            &mut p,
        );
        assert_eq!(rc, DHCD_OK, "{}", last_error());
        taken_impacts(&mut p)
    }
}

/// Pairs, times (to the bit) and contact count equal.
fn assert_same_impacts(got: &Impacts, want: &Impacts, what: &str) {
    assert_eq!(got.vertex_face, want.vertex_face, "{what}: vertex-face");
    assert_eq!(got.face_vertex, want.face_vertex, "{what}: face-vertex");
    assert_eq!(got.edge_edge, want.edge_edge, "{what}: edge-edge");
    assert_eq!(got.toi, want.toi, "{what}: toi");
    assert_eq!(got.counters.contacts, want.counters.contacts, "{what}");
    assert!(got.counters.prim_tests >= got.counters.contacts, "{what}");
}

/// Two parallel 4 x 4 sheets in one mesh (the upper one's indices after the lower's); over
/// the step the upper one passes right through the lower one, from 0.3 above to 0.3
/// below, so neither end pose has a self-contact (tunnelling).
fn tunnelling_sheets() -> (Mesh, Vec<[f64; 3]>, Vec<[f64; 3]>) {
    let g = grid(4, 4, 0.25, [0.0; 3]);
    let n = g.vertex_count() as u32;
    let lower = f64s(&jitter(g.positions(), [0.01, 0.01, 0.02], 3));
    let upper: Vec<[f64; 3]> = lower
        .iter()
        .map(|p| [p[0] + 0.07, p[1] + 0.05, p[2] + 0.3])
        .collect();
    let below: Vec<[f64; 3]> = upper
        .iter()
        .map(|p| [p[0] + 0.02, p[1] - 0.03, p[2] - 0.6])
        .collect();
    let mut triangles = g.triangles().to_vec();
    triangles.extend(g.triangles().iter().map(|t| t.map(|v| v + n)));
    let x0: Vec<[f64; 3]> = lower.iter().chain(&upper).copied().collect();
    let x1: Vec<[f64; 3]> = lower.iter().chain(&below).copied().collect();
    (Mesh::new_f64(x0.clone(), triangles).unwrap(), x0, x1)
}

/// A C hierarchy of `mesh` in `f64`, or rounded to `f32`.
fn new_ccd_h(method: i32, mesh: &Mesh, f32_hierarchy: bool) -> *mut DhcdHierarchy {
    if f32_hierarchy {
        let p: Vec<[f32; 3]> = mesh
            .to_f64_positions()
            .iter()
            .map(|p| p.map(|x| x as f32))
            .collect();
        new_h(method, &Mesh::new(p, mesh.triangles().to_vec()).unwrap())
    } else {
        new_any(method, mesh)
    }
}

/// `dhcd_self_ccd` equals the brute force over every pair (`dhcd::narrow::brute_force_self_ccd`)
/// on a tunnelling case the discrete test misses at both ends: every method, hierarchies of
/// both precisions (the positions are `double` either way), 1 and 2 threads, both modes.
#[test]
fn self_ccd_equals_the_brute_force() {
    let (mesh, x0, x1) = tunnelling_sheets();
    let all = brute_force_self_ccd(&mesh, Motion::new(&x0, &x1), &CcdOptions::default());
    assert!(!all.vertex_face.is_empty() && !all.edge_edge.is_empty());
    assert!(all.face_vertex.is_empty());
    let toi = all.toi.unwrap();
    assert!(toi > 0.0 && toi < 1.0, "{toi}");
    for method in METHODS {
        for f32_hierarchy in [false, true] {
            let h = new_ccd_h(method, &mesh, f32_hierarchy);
            // Neither end pose collides: the discrete test misses the whole step.
            for x in [&x0, &x1] {
                // SAFETY: a live handle, arrays of the stated lengths, a writable output.
                unsafe {
                    if !f32_hierarchy {
                        let f = flat64(x);
                        let rc = dhcd_hierarchy_update_positions_f64(h, f.as_ptr(), x.len());
                        assert_eq!(rc, DHCD_OK);
                        let mut c = empty();
                        assert_eq!(dhcd_self_collide(h, 1, &mut c), DHCD_OK);
                        assert_eq!(c.count, 0);
                        dhcd_contacts_free(&mut c);
                    }
                }
            }
            for threads in [1, 2] {
                let what = format!(
                    "{:?} f32={f32_hierarchy} threads={threads}",
                    method_of(method)
                );
                let got = c_self_ccd(h, &x0, &x1, CcdQuery::all(), threads);
                assert_same_impacts(&got, &all, &what);
                let got = c_self_ccd(h, &x0, &x1, CcdQuery::earliest(), threads);
                assert_same_impacts(
                    &got,
                    &earliest_of(&all, all.toi),
                    &format!("{what}, earliest"),
                );
            }
            // The same as the Rust API, counters included.
            let rust = AnyHierarchy::new(method_of(method), &mesh, options4()).unwrap();
            if !f32_hierarchy {
                let want = rust
                    .self_ccd(
                        Motion::new(&x0, &x1),
                        &CcdQuery::all(),
                        &mut Workspace::default(),
                        Par::Seq,
                    )
                    .unwrap();
                assert_eq!(c_self_ccd(h, &x0, &x1, CcdQuery::all(), 1), want);
            }
            // SAFETY: a live handle, released once.
            unsafe { dhcd_hierarchy_free(h) };
        }
    }
}

/// Two balls flying through each other within the step (apart at both ends).
fn tunnelling_balls() -> (Mesh, Mesh, [Vec<[f64; 3]>; 4]) {
    let a = icosphere(1, 0.5, [0.0; 3]);
    let b = icosphere(1, 0.4, [0.3, 0.05, 0.0]);
    let a0 = f64s(&jitter(a.positions(), [0.01; 3], 1));
    let a1: Vec<[f64; 3]> = a0.iter().map(|p| [p[0] + 0.1, p[1], p[2] + 0.02]).collect();
    let b0: Vec<[f64; 3]> = f64s(b.positions())
        .iter()
        .map(|p| [p[0] + 1.0, p[1], p[2]])
        .collect();
    let b1: Vec<[f64; 3]> = b0.iter().map(|p| [p[0] - 2.6, p[1] + 0.1, p[2]]).collect();
    (a, b, [a0, a1, b0, b1])
}

/// `dhcd_ccd` equals `dhcd::narrow::brute_force_ccd` (all three lists) and the Rust API:
/// every method, mixed precisions, 1 and 2 threads, both modes, a time limit.
#[test]
fn pair_ccd_equals_the_brute_force() {
    let (a, b, [a0, a1, b0, b1]) = tunnelling_balls();
    let (am, bm) = (Motion::new(&a0, &a1), Motion::new(&b0, &b1));
    let all = brute_force_ccd(&a, am, &b, bm, &CcdOptions::default());
    assert!(!all.vertex_face.is_empty() && !all.face_vertex.is_empty());
    assert!(!all.edge_edge.is_empty());
    let toi = all.toi.unwrap();
    assert!(toi > 0.0 && toi < 1.0);
    let early = CcdOptions::new(0.5 * toi + 0.25, 0.0).unwrap();
    let part = brute_force_ccd(&a, am, &b, bm, &early);
    assert!(part.counters.contacts > 0 && part.counters.contacts < all.counters.contacts);
    let ma = Mesh::new_f64(a0.clone(), a.triangles().to_vec()).unwrap();
    let mb = Mesh::new_f64(b0.clone(), b.triangles().to_vec()).unwrap();
    for method in METHODS {
        for (fa, fb) in [(false, false), (true, false), (true, true)] {
            let (ha, hb) = (new_ccd_h(method, &ma, fa), new_ccd_h(method, &mb, fb));
            for threads in [1, 2] {
                let what = format!("{:?} f32=({fa}, {fb}) threads={threads}", method_of(method));
                let got = c_ccd(ha, am, hb, bm, CcdQuery::all(), threads);
                assert_same_impacts(&got, &all, &what);
                let got = c_ccd(ha, am, hb, bm, CcdQuery::earliest(), threads);
                assert_same_impacts(
                    &got,
                    &earliest_of(&all, all.toi),
                    &format!("{what}, earliest"),
                );
                let q = CcdQuery::all().with_t_max(early.t_max);
                let got = c_ccd(ha, am, hb, bm, q, threads);
                assert_same_impacts(&got, &part, &format!("{what}, t_max"));
                assert!(got.vertex_face.iter().all(|x| x.toi <= early.t_max));
            }
            if !fa && !fb {
                // The Rust API on the same meshes, counters included.
                let m = method_of(method);
                let ra = AnyHierarchy::new(m, &ma, options4()).unwrap();
                let rb = AnyHierarchy::new(m, &mb, options4()).unwrap();
                let q = CcdQuery::earliest();
                let want = ra
                    .ccd_pair(am, &rb, bm, &q, &mut Workspace::default(), Par::Seq)
                    .unwrap();
                assert_eq!(c_ccd(ha, am, hb, bm, q, 1), want, "{m:?}: counters too");
            }
            // SAFETY: live handles, released once.
            unsafe {
                dhcd_hierarchy_free(ha);
                dhcd_hierarchy_free(hb);
            }
        }
    }
}

/// A minimum distance: pairs passing within it collide too (small meshes: such pairs take
/// the exact path).
#[test]
fn ccd_minimum_distance() {
    let a = icosphere(0, 0.5, [0.0; 3]);
    let b = icosphere(0, 0.4, [0.0; 3]);
    let a0 = f64s(a.positions());
    let b0: Vec<[f64; 3]> = f64s(b.positions())
        .iter()
        .map(|p| [p[0] + 1.2, p[1] + 0.3, p[2]])
        .collect();
    let b1: Vec<[f64; 3]> = b0.iter().map(|p| [p[0] - 0.5, p[1], p[2] + 0.1]).collect();
    let (am, bm) = (Motion::new(&a0, &a0), Motion::new(&b0, &b1));
    let options = CcdOptions::new(1.0, 0.05).unwrap();
    let near = brute_force_ccd(&a, am, &b, bm, &options);
    let touch = brute_force_ccd(&a, am, &b, bm, &CcdOptions::default());
    assert!(near.counters.contacts > touch.counters.contacts);
    let (ha, hb) = (new_h(DHCD_METHOD_SPHERE, &a), new_h(DHCD_METHOD_SPHERE, &b));
    let q = CcdQuery::all().with_min_distance(0.05);
    assert_same_impacts(&c_ccd(ha, am, hb, bm, q, 2), &near, "min distance");
    assert_same_impacts(&c_ccd(ha, am, hb, bm, CcdQuery::all(), 1), &touch, "touch");
    // SAFETY: live handles, released once.
    unsafe {
        dhcd_hierarchy_free(ha);
        dhcd_hierarchy_free(hb);
    }
}

/// `dhcd_vertex_face_ccd` and `dhcd_edge_edge_ccd` equal `dhcd::ccd`'s queries: 1 with the
/// time, or 0 with `+inf`.
#[test]
fn single_ccd_queries_equal_the_library() {
    // A vertex falling through a triangle at t = 0.5; an edge sweeping through another.
    let vf0 = [
        [0.25, 0.25, 1.0],
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
    ];
    let vf1 = [
        [0.25, 0.25, -1.0],
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
    ];
    let ee0 = [
        [-1.0, 0.0, 1.0],
        [1.0, 0.0, 1.0],
        [0.0, -1.0, 0.0],
        [0.0, 1.0, 0.0],
    ];
    let ee1 = [
        [-1.0, 0.0, -3.0],
        [1.0, 0.0, -3.0],
        [0.0, -1.0, 0.0],
        [0.0, 1.0, 0.0],
    ];
    let flat12 = |p: &[[f64; 3]; 4]| -> [f64; 12] { std::array::from_fn(|k| p[k / 3][k % 3]) };
    type Lib = fn(&[[f64; 3]; 4], &[[f64; 3]; 4], &CcdOptions) -> Option<f64>;
    type C = unsafe extern "C" fn(*const f64, *const f64, f64, f64, *mut f64) -> i32;
    let cases: [(&str, Lib, C, _, _, f64); 2] = [
        (
            "vertex-face",
            dhcd::ccd::vertex_face,
            dhcd_vertex_face_ccd,
            vf0,
            vf1,
            0.5,
        ),
        (
            "edge-edge",
            dhcd::ccd::edge_edge,
            dhcd_edge_edge_ccd,
            ee0,
            ee1,
            0.25,
        ),
    ];
    for (what, lib, c, x0, x1, t_star) in cases {
        let (f0, f1) = (flat12(&x0), flat12(&x1));
        for (t_max, d) in [
            (1.0, 0.0),
            (t_star, 0.0),
            (0.9 * t_star, 0.0),
            (1.0, 0.1),
            (0.0, 0.0),
        ] {
            let want = lib(&x0, &x1, &CcdOptions::new(t_max, d).unwrap());
            let mut toi = -1.0;
            // SAFETY: 12 doubles each, a writable `toi`.
            let rc = unsafe { c(f0.as_ptr(), f1.as_ptr(), t_max, d, &mut toi) };
            assert_eq!(rc, i32::from(want.is_some()), "{what} {t_max} {d}");
            assert_eq!(toi, want.unwrap_or(f64::INFINITY), "{what} {t_max} {d}");
            if d == 0.0 && t_max >= t_star {
                assert!(toi <= t_star && t_star - toi <= 1e-12, "{what}: {toi}");
            }
        }
    }
}

/// Which CCD calls an error test makes: `dhcd_self_ccd`, `dhcd_ccd` or both.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Calls {
    Own,
    Pair,
    Both,
}

/// The arguments of a CCD call, changed one at a time by the error tests.
#[derive(Clone, Copy)]
struct CcdCall {
    a: *mut DhcdHierarchy,
    a0: *const f64,
    a1: *const f64,
    na: usize,
    /// The second mesh of `dhcd_ccd` (unused by `dhcd_self_ccd`).
    b: *mut DhcdHierarchy,
    b0: *const f64,
    b1: *const f64,
    nb: usize,
    t_max: f64,
    d: f64,
    threads: u32,
}

impl CcdCall {
    fn with(mut self, change: impl FnOnce(&mut Self)) -> Self {
        change(&mut self);
        self
    }

    /// The calls `which` (`dhcd_self_ccd` on `a`, `dhcd_ccd`) fail with `code` and a
    /// message containing `message`, in both modes, and leave their output empty whatever
    /// it held.
    ///
    /// # Safety
    /// Every pointer null, a live handle, or valid for its stated length.
    unsafe fn fails(self, which: Calls, code: i32, message: &str) {
        let c = self;
        for earliest in [0, 1] {
            // Only the pair call reads `b`.
            if which != Calls::Pair {
                let mut out = garbage_impacts();
                // SAFETY: the caller's contract.
                let rc = unsafe {
                    dhcd_self_ccd(
                        c.a, c.a0, c.a1, c.na, c.t_max, c.d, earliest, c.threads, &mut out,
                    )
                };
                let what = format!("self, {message}: {}", last_error());
                assert_eq!(rc, code, "{what}");
                assert!(last_error().contains(message), "{what}");
                assert!(is_empty_impacts(&out), "{what}");
            }
            if which == Calls::Own {
                continue;
            }
            let mut out = garbage_impacts();
            // SAFETY: the caller's contract.
            let rc = unsafe {
                dhcd_ccd(
                    c.a, c.a0, c.a1, c.na, c.b, c.b0, c.b1, c.nb, c.t_max, c.d, earliest,
                    c.threads, &mut out,
                )
            };
            let what = format!("pair, {message}: {}", last_error());
            assert_eq!(rc, code, "{what}");
            assert!(last_error().contains(message), "{what}");
            assert!(is_empty_impacts(&out), "{what}");
        }
    }
}

/// Every bad input of the CCD calls is a typed error code, with the result output emptied
/// (whatever it held) and the single queries' `toi` unwritten.
#[test]
fn ccd_bad_input_is_an_error_code_and_writes_nothing() {
    use Calls::{Both, Own, Pair};
    use {
        DHCD_ERR_INVALID_ARGUMENT as ARGUMENT, DHCD_ERR_INVALID_MESH as MESH,
        DHCD_ERR_LENGTH_MISMATCH as LENGTH, DHCD_ERR_NULL as NULL,
    };
    let m = icosphere(1, 1.0, [0.0; 3]);
    let x = f64s(m.positions());
    let (nv, fx) = (m.vertex_count(), flat64(&x));
    let a = new_h(DHCD_METHOD_DH, &m);
    let b = new_h(DHCD_METHOD_DH, &m);
    let box_ = new_h(DHCD_METHOD_AABB, &m);
    let mut nan = fx.clone();
    nan[7] = f64::NAN;
    let mut big = fx.clone();
    big[5] = 1e39;
    let bytes = [0u64; 16];
    let odd = bytes.as_ptr().cast::<u8>().wrapping_add(4).cast::<f64>();
    let p = fx.as_ptr();
    let ok = CcdCall {
        a,
        a0: p,
        a1: p,
        na: nv,
        b,
        b0: p,
        b1: p,
        nb: nv,
        t_max: 1.0,
        d: 0.0,
        threads: 1,
    };
    // SAFETY: every pointer is null, a live handle, or valid for its stated length (the
    // misaligned one is rejected before it is read).
    unsafe {
        ok.with(|c| c.a = null_mut())
            .fails(Both, NULL, "null pointer");
        ok.with(|c| c.b = null_mut())
            .fails(Pair, NULL, "b is a null");
        ok.with(|c| c.b = a).fails(Pair, ARGUMENT, "dhcd_self_ccd");
        ok.with(|c| c.b = box_)
            .fails(Pair, DHCD_ERR_WRONG_KIND, "aabb");
        ok.with(|c| c.a0 = null())
            .fails(Own, NULL, "x0, x1: positions");
        ok.with(|c| c.a0 = null())
            .fails(Pair, NULL, "a0, a1: positions");
        ok.with(|c| c.a1 = null())
            .fails(Both, NULL, "positions is a null");
        ok.with(|c| c.b1 = null())
            .fails(Pair, NULL, "b0, b1: positions");
        ok.with(|c| (c.a0, c.na) = (odd, 1))
            .fails(Both, ARGUMENT, "aligned");
        ok.with(|c| c.na = nv - 1).fails(Both, LENGTH, "vertices");
        ok.with(|c| c.nb = nv + 1).fails(Pair, LENGTH, "vertices");
        ok.with(|c| c.a1 = nan.as_ptr())
            .fails(Both, MESH, "non-finite");
        ok.with(|c| c.b0 = nan.as_ptr())
            .fails(Pair, MESH, "non-finite");
        ok.with(|c| c.a0 = big.as_ptr())
            .fails(Both, MESH, "f32 range");
        for t_max in [1.5, -1e-300, f64::NAN, f64::INFINITY] {
            ok.with(|c| c.t_max = t_max).fails(Both, ARGUMENT, "t_max");
        }
        for d in [-1.0, -1e-300, f64::NAN, f64::INFINITY] {
            ok.with(|c| c.d = d).fails(Both, ARGUMENT, "min_distance");
        }
        for threads in [4096, u32::MAX] {
            ok.with(|c| c.threads = threads)
                .fails(Both, ARGUMENT, "threads");
        }
        assert_eq!(
            dhcd_self_ccd(a, p, p, nv, 1.0, 0.0, 0, 1, null_mut()),
            DHCD_ERR_NULL
        );
        assert_eq!(
            dhcd_ccd(a, p, p, nv, b, p, p, nv, 1.0, 0.0, 0, 1, null_mut()),
            DHCD_ERR_NULL
        );
        // The handles still work.
        let ok = c_self_ccd(a, &x, &x, CcdQuery::all(), 1);
        assert_eq!(ok.counters.contacts, 0);
        assert_eq!(ok.toi, None);

        // Single queries.
        let q = [0.0f64; 12];
        let mut inf = [0.0f64; 12];
        inf[11] = f64::INFINITY;
        let (q, inf) = (q.as_ptr(), inf.as_ptr());
        type Single<'a> = (*const f64, *const f64, f64, f64, i32, &'a str);
        let single: [Single; 8] = [
            (null(), q, 1.0, 0.0, NULL, "x0"),
            (q, null(), 1.0, 0.0, NULL, "x1"),
            (odd, q, 1.0, 0.0, ARGUMENT, "aligned"),
            (q, inf, 1.0, 0.0, ARGUMENT, "point 7"),
            (q, q, 2.0, 0.0, ARGUMENT, "t_max"),
            (q, q, -1e-9, 0.0, ARGUMENT, "t_max"),
            (q, q, 1.0, f64::NAN, ARGUMENT, "min_distance"),
            (q, q, 1.0, -0.5, ARGUMENT, "min_distance"),
        ];
        for f in [dhcd_vertex_face_ccd, dhcd_edge_edge_ccd] {
            for (x0, x1, t_max, d, code, message) in single {
                let mut toi = 42.0;
                let rc = f(x0, x1, t_max, d, &mut toi);
                assert_eq!(rc, code, "{message}: {}", last_error());
                let what = format!("{message}: {}", last_error());
                assert!(last_error().contains(message), "{what}");
                assert_eq!(toi, 42.0, "{what}: toi unwritten");
            }
            assert_eq!(f(q, q, 1.0, 0.0, null_mut()), NULL);
            assert!(last_error().contains("toi"));
            // Points that do not move and all coincide touch at t = 0.
            let mut toi = 42.0;
            assert_eq!(f(q, q, 1.0, 0.0, &mut toi), 1);
            assert_eq!(toi, 0.0);
        }
        for h in [a, b, box_] {
            dhcd_hierarchy_free(h);
        }
    }
}

/// A step with nothing colliding: null arrays, `toi = +inf`, counters filled; every free
/// takes it (and null, and a result twice); the layout the header assumes.
#[test]
fn empty_impacts_free() {
    assert_eq!(
        std::mem::size_of::<DhcdImpacts>(),
        9 * std::mem::size_of::<usize>() + 8 + 32
    );
    let m = icosphere(1, 1.0, [0.0; 3]);
    let x0 = f64s(m.positions());
    let x1: Vec<[f64; 3]> = x0.iter().map(|p| [p[0] + 0.5, p[1], p[2]]).collect();
    let far: Vec<[f64; 3]> = x0.iter().map(|p| [p[0] + 10.0, p[1], p[2]]).collect();
    let (a, b) = (new_h(DHCD_METHOD_SPHERE, &m), new_h(DHCD_METHOD_SPHERE, &m));
    // SAFETY: live handles, arrays of the stated lengths, writable outputs; results released
    // once (then no-ops).
    unsafe {
        let (f0, f1, ff) = (flat64(&x0), flat64(&x1), flat64(&far));
        let mut out = garbage_impacts();
        let rc = dhcd_ccd(
            a,
            f0.as_ptr(),
            f1.as_ptr(),
            x0.len(),
            b,
            ff.as_ptr(),
            ff.as_ptr(),
            x0.len(),
            1.0,
            0.0,
            0,
            1,
            &mut out,
        );
        assert_eq!(rc, DHCD_OK, "{}", last_error());
        assert!(out.vf_count == 0 && out.fv_count == 0 && out.ee_count == 0);
        assert!(out.vertex_face.is_null() && out.fv_toi.is_null() && out.ee_toi.is_null());
        assert_eq!(out.toi, f64::INFINITY);
        assert!(out.counters.bv_tests > 0, "counters are filled");
        dhcd_impacts_free(&mut out);
        assert!(is_empty_impacts(&out));
        dhcd_impacts_free(&mut out);
        dhcd_impacts_free(null_mut());
        let mut zero: DhcdImpacts = std::mem::zeroed();
        dhcd_impacts_free(&mut zero);
        // A rigid motion of one mesh: nothing collides with itself.
        let mut out = garbage_impacts();
        let rc = dhcd_self_ccd(
            a,
            f0.as_ptr(),
            f1.as_ptr(),
            x0.len(),
            1.0,
            0.0,
            1,
            2,
            &mut out,
        );
        assert_eq!(rc, DHCD_OK);
        assert!(out.vertex_face.is_null() && out.edge_edge.is_null());
        assert_eq!(out.toi, f64::INFINITY);
        dhcd_impacts_free(&mut out);
        dhcd_hierarchy_free(a);
        dhcd_hierarchy_free(b);
    }
}

/// `dhcd_scene_ccd` equals the Rust scene's `ccd` flattened with object ids (a small ball
/// tunnelling through a still one, a far ball culled), in both modes and for 1 and 2
/// threads; bad input is the documented error code with `out` left empty.
#[test]
fn scene_ccd_equals_the_rust_scene() {
    let wall = icosphere(2, 1.0, [0.0; 3]);
    let bullet = icosphere(1, 0.3, [-3.0, 0.0, 0.0]);
    let far = icosphere(1, 0.5, [50.0, 0.0, 0.0]);
    let b0: Vec<f64> = bullet
        .positions()
        .iter()
        .flatten()
        .map(|&c| f64::from(c))
        .collect();
    let b1: Vec<f64> = b0
        .chunks(3)
        .flat_map(|p| [p[0] + 6.0, p[1], p[2]])
        .collect();
    let nv = bullet.vertex_count();
    type Rows<const N: usize> = Vec<([u64; N], f64)>;
    /// A filled `DhcdSceneImpacts` as rows and its time; the C result is released.
    unsafe fn taken(p: &mut DhcdSceneImpacts) -> (Rows<4>, Rows<4>, Rows<6>, f64) {
        fn rows<const N: usize>(idx: &[u64], t: &[f64]) -> Rows<N> {
            (0..t.len())
                .map(|k| (std::array::from_fn(|i| idx[N * k + i]), t[k]))
                .collect()
        }
        // SAFETY: the library wrote the stated number of elements at each array.
        let out = unsafe {
            (
                rows(
                    part(p.vertex_face, 4 * p.vf_count),
                    part(p.vf_toi, p.vf_count),
                ),
                rows(
                    part(p.face_vertex, 4 * p.fv_count),
                    part(p.fv_toi, p.fv_count),
                ),
                rows(
                    part(p.edge_edge, 6 * p.ee_count),
                    part(p.ee_toi, p.ee_count),
                ),
                p.toi,
            )
        };
        // SAFETY: filled by the library, released once (the second call is a no-op).
        unsafe {
            dhcd_scene_impacts_free(p);
            assert!(p.vertex_face.is_null() && p.vf_count == 0 && p.toi == f64::INFINITY);
            dhcd_scene_impacts_free(p);
        }
        out
    }
    for method in METHODS {
        let mut rust = dhcd::Scene::new(method_of(method), options4());
        let mut s = null_mut();
        // SAFETY: live handles, arrays of the stated lengths, writable outputs.
        unsafe {
            assert_eq!(dhcd_scene_new(method, 4, &mut s), DHCD_OK);
            for m in [&wall, &bullet, &far] {
                let p: Vec<f32> = m.positions().iter().flatten().copied().collect();
                let t: Vec<u32> = m.triangles().iter().flatten().copied().collect();
                let mut id = u64::MAX;
                let rc = dhcd_scene_add(
                    s,
                    p.as_ptr(),
                    m.vertex_count(),
                    t.as_ptr(),
                    m.triangle_count(),
                    0,
                    &mut id,
                );
                assert_eq!(rc, DHCD_OK, "{}", last_error());
                assert_eq!(id, rust.add(m).unwrap().0);
            }
            let rows =
                |f: &[f64]| -> Vec<[f64; 3]> { f.chunks(3).map(|p| [p[0], p[1], p[2]]).collect() };
            let (x0, x1) = (rows(&b0), rows(&b1));
            for earliest in [0, 1] {
                let q = CcdQuery {
                    mode: if earliest == 1 {
                        CcdMode::Earliest
                    } else {
                        CcdMode::All
                    },
                    ..CcdQuery::all()
                };
                let want = rust
                    .ccd(&[(dhcd::ObjectId(1), Motion::new(&x0, &x1))], &q, Par::Seq)
                    .unwrap();
                for threads in [1u32, 2] {
                    let mut p = std::mem::zeroed::<DhcdSceneImpacts>();
                    let rc = dhcd_scene_ccd(
                        s,
                        &1,
                        &b0.as_ptr(),
                        &b1.as_ptr(),
                        &nv,
                        1,
                        1.0,
                        0.0,
                        earliest,
                        threads,
                        &mut p,
                    );
                    assert_eq!(rc, DHCD_OK, "{}", last_error());
                    let (vf, fv, ee, toi) = taken(&mut p);
                    assert_eq!(Some(toi), want.toi);
                    assert!(toi > 0.28 && toi < 0.30);
                    let pair = &want.per_pair[0].impacts;
                    assert_eq!(want.per_pair.len(), 1, "the far ball is culled");
                    let wvf: Rows<4> = pair
                        .vertex_face
                        .iter()
                        .map(|x| ([0, x.vertex.into(), 1, x.triangle.into()], x.toi))
                        .collect();
                    let wfv: Rows<4> = pair
                        .face_vertex
                        .iter()
                        .map(|x| ([0, x.triangle.into(), 1, x.vertex.into()], x.toi))
                        .collect();
                    let wee: Rows<6> = pair
                        .edge_edge
                        .iter()
                        .map(|x| {
                            let [a0, a1] = x.a.map(u64::from);
                            let [c0, c1] = x.b.map(u64::from);
                            ([0, a0, a1, 1, c0, c1], x.toi)
                        })
                        .collect();
                    assert_eq!(
                        (vf, fv, ee),
                        (wvf, wfv, wee),
                        "{method} {earliest} {threads}"
                    );
                }
            }
            // Errors: the documented codes, `out` empty.
            let (p0, p1) = (b0.as_ptr(), b1.as_ptr());
            let short = nv - 1;
            let cases: [(&[u64], &[usize], f64, i32); 4] = [
                (&[7], &[nv], 0.0, DHCD_ERR_UNKNOWN_OBJECT),
                (&[1, 1], &[nv, nv], 0.0, DHCD_ERR_REPEATED_OBJECT),
                (&[1], &[short], 0.0, DHCD_ERR_LENGTH_MISMATCH),
                (&[1], &[nv], -1.0, DHCD_ERR_INVALID_ARGUMENT),
            ];
            for (ids, counts, d, code) in cases {
                let (x0s, x1s) = (vec![p0; ids.len()], vec![p1; ids.len()]);
                let mut p = DhcdSceneImpacts {
                    vertex_face: garbage(),
                    vf_count: 3,
                    ..std::mem::zeroed()
                };
                let rc = dhcd_scene_ccd(
                    s,
                    ids.as_ptr(),
                    x0s.as_ptr(),
                    x1s.as_ptr(),
                    counts.as_ptr(),
                    ids.len(),
                    1.0,
                    d,
                    0,
                    1,
                    &mut p,
                );
                assert_eq!(rc, code, "{}", last_error());
                assert!(p.vertex_face.is_null() && p.vf_count == 0 && p.toi == f64::INFINITY);
            }
            // No motion: nothing moves, nothing collides.
            let mut p = std::mem::zeroed::<DhcdSceneImpacts>();
            let rc = dhcd_scene_ccd(s, null(), null(), null(), null(), 0, 1.0, 0.0, 0, 1, &mut p);
            assert_eq!(rc, DHCD_OK, "{}", last_error());
            assert_eq!((p.vf_count, p.fv_count, p.ee_count), (0, 0, 0));
            assert_eq!(p.toi, f64::INFINITY);
            dhcd_scene_free(s);
        }
    }
}

/// Limits and cancellation from C: a result over the hierarchy's limit is
/// `DHCD_ERR_OUTPUT_LIMIT` with an empty result, a set cancel token or a poll callback that
/// says stop is `DHCD_ERR_CANCELLED`, and once reset the same query answers; the scene's
/// control likewise; the default limit is the library's. A vertex no face uses is a point.
#[test]
fn limits_cancellation_and_free_points() {
    use std::ffi::{c_int, c_void};
    use std::sync::atomic::{AtomicUsize, Ordering};
    assert_eq!(DHCD_DEFAULT_MAX_PAIRS, dhcd::DEFAULT_MAX_PAIRS);
    let sheet = dhcd::shapes::grid(12, 12, 1.0 / 12.0, [0.0; 3]);
    let h = new_h(DHCD_METHOD_DH, &sheet);
    let run = |threads: u32| {
        let mut p = no_proximity();
        // SAFETY: a live handle, writable output.
        let rc = unsafe { dhcd_self_proximity(h, 2.0, threads, &mut p) };
        // SAFETY: filled (or emptied) by the library.
        (rc, unsafe { taken_proximity(&mut p) })
    };
    // SAFETY: a live handle; null token and callback.
    let rc = unsafe { dhcd_hierarchy_set_control(h, 100, null(), None, null_mut()) };
    assert_eq!(rc, DHCD_OK);
    for threads in [1, 2] {
        let (rc, p) = run(threads);
        assert_eq!(rc, DHCD_ERR_OUTPUT_LIMIT, "{}", last_error());
        assert!(
            last_error().contains("over the limit of 100"),
            "{}",
            last_error()
        );
        assert_eq!(p.counters.contacts, 0);
    }
    let mut token = null_mut();
    // SAFETY: writable output; then a live token and handle.
    unsafe {
        assert_eq!(dhcd_cancel_new(&mut token), DHCD_OK);
        assert_eq!(dhcd_cancel_set(token), DHCD_OK);
        let rc = dhcd_hierarchy_set_control(h, DHCD_NO_LIMIT, token, None, null_mut());
        assert_eq!(rc, DHCD_OK);
    }
    assert_eq!(run(1).0, DHCD_ERR_CANCELLED, "{}", last_error());
    // SAFETY: a live token.
    unsafe { assert_eq!(dhcd_cancel_reset(token), DHCD_OK) };
    let (rc, all) = run(2);
    assert_eq!(rc, DHCD_OK, "{}", last_error());
    assert!(all.counters.contacts > 100);
    // A poll callback that stops at its third call.
    static CALLS: AtomicUsize = AtomicUsize::new(0);
    unsafe extern "C" fn third(_: *mut c_void) -> c_int {
        (CALLS.fetch_add(1, Ordering::Relaxed) >= 2) as c_int
    }
    let big = dhcd::shapes::grid(40, 40, 1.0 / 40.0, [0.0; 3]);
    let hb = new_h(DHCD_METHOD_AABB, &big);
    let mut p = no_proximity();
    // SAFETY: live handles and token, writable output; the callback is thread-safe.
    unsafe {
        let rc = dhcd_hierarchy_set_control(hb, DHCD_NO_LIMIT, token, Some(third), null_mut());
        assert_eq!(rc, DHCD_OK);
        assert_eq!(dhcd_self_proximity(hb, 2.0, 1, &mut p), DHCD_ERR_CANCELLED);
        assert!(is_empty(&p));
        dhcd_cancel_free(token);
        dhcd_hierarchy_free(hb);
    }
    assert_eq!(CALLS.load(Ordering::Relaxed), 3);
    // The scene's control.
    let (scene, _) = scene_of(&sheet, 2);
    // SAFETY: a live scene.
    unsafe {
        assert_eq!(
            dhcd_scene_set_control(scene, 50, null(), None, null_mut()),
            DHCD_OK
        );
        let mut sp = std::mem::zeroed::<DhcdSceneProximity>();
        assert_eq!(
            dhcd_scene_proximity(scene, 2.0, 1, &mut sp),
            DHCD_ERR_OUTPUT_LIMIT
        );
        dhcd_scene_free(scene);
        dhcd_hierarchy_free(h);
    }
    // A free vertex 0.5 above the only face.
    let m = Mesh::new(
        vec![
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [0.25, 0.25, 0.5],
        ],
        vec![[0, 1, 2]],
    )
    .unwrap();
    for method in [DHCD_METHOD_DH, DHCD_METHOD_SPHERE, DHCD_METHOD_AABB] {
        let hf = new_h(method, &m);
        let p = c_self_proximity(hf, 1.0, 1);
        assert_eq!(
            p.vertex_face
                .iter()
                .map(|x| (x.vertex, x.triangle))
                .collect::<Vec<_>>(),
            [(3, 0)]
        );
        // SAFETY: a live handle.
        unsafe { dhcd_hierarchy_free(hf) };
    }
}

/// The contact set, its derivatives, the batch geometry, the edge table and the step size
/// through the C ABI equal the Rust API's; bad arguments are error codes.
#[test]
fn contact_set_geometry_and_step_size() {
    use dhcd::contact::{self, ContactType, StepOptions};
    let rest = dhcd::shapes::grid(6, 6, 0.1, [0.0; 3]);
    let folded = dhcd::shapes::fold_x(rest.positions(), 0.3);
    let pose: Vec<[f64; 3]> = dhcd::shapes::jitter(&folded, [0.004; 3], 2)
        .iter()
        .map(|p| p.map(f64::from))
        .collect();
    let rest64: Vec<[f64; 3]> = rest.positions().iter().map(|p| p.map(f64::from)).collect();
    let m = Mesh::new_f64(rest64.clone(), rest.triangles().to_vec()).unwrap();
    let t: Vec<u32> = m.triangles().iter().flatten().copied().collect();
    let flat_rest: Vec<f64> = rest64.iter().flatten().copied().collect();
    let mut h = null_mut();
    // SAFETY: arrays of the stated lengths; writable output.
    let rc = unsafe {
        dhcd_hierarchy_new_f64(
            DHCD_METHOD_DH,
            4,
            flat_rest.as_ptr(),
            m.vertex_count(),
            t.as_ptr(),
            m.triangle_count(),
            &mut h,
        )
    };
    assert_eq!(rc, DHCD_OK, "{}", last_error());
    let flat_pose: Vec<f64> = pose.iter().flatten().copied().collect();
    // SAFETY: a live handle and an array of its vertex count.
    let rc =
        unsafe { dhcd_hierarchy_update_positions_f64(h, flat_pose.as_ptr(), m.vertex_count()) };
    assert_eq!(rc, DHCD_OK, "{}", last_error());
    let mut rh = dhcd::Hierarchy::<dhcd::bv::Dh>::new(&m, dhcd::Options::default()).unwrap();
    rh.update_positions_f64(&pose).unwrap();
    let want = contact::self_contact_set(&rh, 0.06).unwrap();
    assert!(want.len() > 10);
    let mut s = DhcdContactSet {
        vertices: null_mut(),
        types: null_mut(),
        distance_sq: null_mut(),
        weights: null_mut(),
        mollified: null_mut(),
        edges: null_mut(),
        closest: null_mut(),
        positions: null_mut(),
        count: 7,
        counters: no_proximity().counters,
    };
    // SAFETY: a live handle, no rest array, writable output.
    let rc = unsafe { dhcd_self_contact_set(h, 0.06, null(), 0, 2, &mut s) };
    assert_eq!(rc, DHCD_OK, "{}", last_error());
    assert_eq!(s.count, want.len());
    let n = s.count;
    // SAFETY: the arrays of a filled set hold `count` rows.
    let (vertices, types, dist, moll, edges) = unsafe {
        (
            std::slice::from_raw_parts(s.vertices, 4 * n),
            std::slice::from_raw_parts(s.types, n),
            std::slice::from_raw_parts(s.distance_sq, n),
            std::slice::from_raw_parts(s.mollified, n),
            std::slice::from_raw_parts(s.edges, 2 * n),
        )
    };
    for (k, c) in want.contacts.iter().enumerate() {
        let v: Vec<i64> = c
            .vertices
            .iter()
            .map(|&v| if v == contact::NONE { -1 } else { v as i64 })
            .collect();
        assert_eq!(&vertices[4 * k..4 * k + 4], &v[..]);
        assert_eq!(types[k], c.kind as u8);
        assert_eq!(dist[k], c.distance_sq);
        assert_eq!(moll[k], c.mollified as u8);
        let e: Vec<i64> = c
            .edges
            .iter()
            .map(|&e| if e == contact::NONE { -1 } else { e as i64 })
            .collect();
        assert_eq!(&edges[2 * k..2 * k + 2], &e[..]);
    }
    let mut g = vec![0.0; 12 * n];
    let mut hs = vec![0.0; 144 * n];
    // SAFETY: a filled set and outputs of the stated sizes.
    unsafe {
        assert_eq!(dhcd_contact_set_gradient(&s, g.as_mut_ptr()), DHCD_OK);
        assert_eq!(dhcd_contact_set_hessian(&s, hs.as_mut_ptr()), DHCD_OK);
    }
    let wg: Vec<f64> = want.gradients().into_iter().flatten().collect();
    let wh: Vec<f64> = want.hessians().into_iter().flatten().flatten().collect();
    assert_eq!(g, wg);
    assert_eq!(hs, wh);
    // The edge table.
    let (mut ep, mut ec) = (null(), 0usize);
    // SAFETY: a live handle and writable outputs; the table lives with the handle.
    let table = unsafe {
        assert_eq!(dhcd_hierarchy_edges(h, &mut ep, &mut ec), DHCD_OK);
        std::slice::from_raw_parts(ep, 2 * ec)
    };
    let want_edges: Vec<u32> = rh.tree().edges().iter().flatten().copied().collect();
    assert_eq!(table, &want_edges[..]);
    // SAFETY: a filled set, released twice (the second a no-op), then null.
    unsafe {
        dhcd_contact_set_free(&mut s);
        assert!(s.vertices.is_null() && s.count == 0);
        dhcd_contact_set_free(&mut s);
        dhcd_contact_set_free(null_mut());
    }
    // Bad arguments: negative dhat, a rest array of the wrong length is caught by count.
    // SAFETY: as above.
    unsafe {
        assert_eq!(
            dhcd_self_contact_set(h, -1.0, null(), 0, 1, &mut s),
            DHCD_ERR_INVALID_ARGUMENT
        );
        let short = [0.0f64; 9];
        assert_eq!(
            dhcd_self_contact_set(h, 0.06, short.as_ptr(), 3, 1, &mut s),
            DHCD_ERR_LENGTH_MISMATCH
        );
        assert_eq!(
            dhcd_self_contact_set(h, 0.06, null(), 0, 1, null_mut()),
            DHCD_ERR_NULL
        );
    }
    // Batch geometry: a point above a triangle.
    let x = [0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0];
    let (mut d, mut gr) = (0.0f64, [0.0f64; 12]);
    // SAFETY: arrays of one row.
    unsafe {
        assert_eq!(
            dhcd_distance_sq([2u8].as_ptr(), x.as_ptr(), 1, &mut d),
            DHCD_OK
        );
        assert_eq!(
            dhcd_distance_gradient([2u8].as_ptr(), x.as_ptr(), 1, gr.as_mut_ptr()),
            DHCD_OK
        );
        assert_eq!(
            dhcd_distance_sq([9u8].as_ptr(), x.as_ptr(), 1, &mut d),
            DHCD_ERR_INVALID_ARGUMENT
        );
    }
    assert_eq!(d, 1.0);
    assert_eq!(&gr[..3], &[0.0, 0.0, 2.0]);
    let _ = ContactType::PointTriangle;
    // The step size of the fold closing: equal to Rust's.
    let later: Vec<[f64; 3]> = dhcd::shapes::fold_x(rest.positions(), 0.25)
        .iter()
        .map(|p| p.map(f64::from))
        .collect();
    let flat_later: Vec<f64> = later.iter().flatten().copied().collect();
    let want = contact::collision_free_stepsize(
        &rh,
        dhcd::Motion::new(&pose, &later),
        &StepOptions::default(),
    )
    .unwrap();
    let mut step = -1.0;
    // SAFETY: a live handle, arrays of its vertex count, writable output.
    unsafe {
        let rc = dhcd_collision_free_stepsize(
            h,
            flat_pose.as_ptr(),
            flat_later.as_ptr(),
            m.vertex_count(),
            0.0,
            0.8,
            1,
            &mut step,
        );
        assert_eq!(rc, DHCD_OK, "{}", last_error());
        assert_eq!(step, want.step);
        let rc = dhcd_collision_free_stepsize(
            h,
            flat_pose.as_ptr(),
            flat_later.as_ptr(),
            m.vertex_count(),
            0.0,
            1.5,
            1,
            &mut step,
        );
        assert_eq!(rc, DHCD_ERR_INVALID_ARGUMENT);
        dhcd_hierarchy_free(h);
    }
}

/// The scene's contact set, offsets and step size through the C ABI equal the Rust scene's:
/// a folded sheet with self-collision on and a small sheet falling onto it.
#[test]
fn scene_contact_set_offsets_and_step_size() {
    use dhcd::contact::StepOptions;
    let rest = dhcd::shapes::grid(6, 6, 0.1, [0.0; 3]);
    let sheet: Vec<[f64; 3]> =
        dhcd::shapes::jitter(&dhcd::shapes::fold_x(rest.positions(), 0.3), [0.004; 3], 2)
            .iter()
            .map(|p| p.map(f64::from))
            .collect();
    let small = dhcd::shapes::grid(2, 2, 0.1, [0.05, 0.15, 0.02]);
    let drop0: Vec<[f64; 3]> = f64s(small.positions());
    let drop1: Vec<[f64; 3]> = drop0.iter().map(|p| [p[0], p[1], p[2] - 1.0]).collect();
    let meshes = [
        Mesh::new_f64(sheet.clone(), rest.triangles().to_vec()).unwrap(),
        Mesh::new_f64(drop0.clone(), small.triangles().to_vec()).unwrap(),
    ];
    for method in METHODS {
        let mut rust = dhcd::Scene::new(method_of(method), options4());
        let mut s = null_mut();
        // SAFETY: live handles, arrays of the stated lengths, writable outputs.
        unsafe {
            assert_eq!(dhcd_scene_new(method, 4, &mut s), DHCD_OK);
            for (k, m) in meshes.iter().enumerate() {
                let p: Vec<f64> = m
                    .positions_f64()
                    .unwrap()
                    .iter()
                    .flatten()
                    .copied()
                    .collect();
                let t: Vec<u32> = m.triangles().iter().flatten().copied().collect();
                let mut id = u64::MAX;
                let on = i32::from(k == 0);
                let rc = dhcd_scene_add_f64(
                    s,
                    p.as_ptr(),
                    m.vertex_count(),
                    t.as_ptr(),
                    m.triangle_count(),
                    on,
                    &mut id,
                );
                assert_eq!(rc, DHCD_OK, "{}", last_error());
                let rid = rust.add(m).unwrap();
                rust.set_self_collision(rid, k == 0).unwrap();
                assert_eq!(id, rid.0);
            }
            // Offsets: the second object's vertices and edges follow the first's.
            for (id, vertices, edges) in [
                (0u64, 0u64, 0u64),
                (
                    1,
                    49,
                    rust.tree(dhcd::ObjectId(0)).unwrap().edges().len() as u64,
                ),
            ] {
                let (mut v, mut e) = (u64::MAX, u64::MAX);
                assert_eq!(dhcd_scene_vertex_offset(s, id, &mut v), DHCD_OK);
                assert_eq!(dhcd_scene_edge_offset(s, id, &mut e), DHCD_OK);
                assert_eq!((v, e), (vertices, edges));
            }
            let mut v = 7u64;
            assert_eq!(
                dhcd_scene_vertex_offset(s, 9, &mut v),
                DHCD_ERR_UNKNOWN_OBJECT
            );
            assert_eq!(v, 7, "written only on success");
            // The contact set.
            let want = rust.contact_set(0.05, dhcd::Par::Seq).unwrap();
            assert!(want.len() > 10);
            let mut c = std::mem::zeroed::<DhcdContactSet>();
            let rc = dhcd_scene_contact_set(s, 0.05, 2, &mut c);
            assert_eq!(rc, DHCD_OK, "{}", last_error());
            assert_eq!(c.count, want.len());
            let (vertices, types) = (part(c.vertices, 4 * c.count), part(c.types, c.count));
            for (k, w) in want.contacts.iter().enumerate() {
                let wv = w.vertices.map(|v| {
                    if v == dhcd::contact::NONE {
                        -1
                    } else {
                        i64::from(v)
                    }
                });
                assert_eq!(&vertices[4 * k..4 * k + 4], &wv[..]);
                assert_eq!(types[k], w.kind as u8);
            }
            // Rows between the objects name the second object's vertices from 49 on.
            assert!(vertices.iter().any(|&v| v >= 49));
            dhcd_contact_set_free(&mut c);
            assert!(c.vertices.is_null() && c.count == 0);
            assert_eq!(
                dhcd_scene_contact_set(s, -1.0, 1, &mut c),
                DHCD_ERR_INVALID_ARGUMENT
            );
            // The step size: the falling sheet limits it.
            let (b0, b1) = (flat64(&drop0), flat64(&drop1));
            let motion = [(dhcd::ObjectId(1), dhcd::Motion::new(&drop0, &drop1))];
            for (d, r) in [(0.0, 0.8), (1e-3, 0.5)] {
                let o = StepOptions {
                    min_distance: d,
                    rescaling: r,
                };
                let want = rust
                    .collision_free_stepsize(&motion, &o, dhcd::Par::Seq)
                    .unwrap();
                assert!(want.step < 1.0);
                for threads in [1u32, 2] {
                    let mut step = -1.0;
                    let rc = dhcd_scene_collision_free_stepsize(
                        s,
                        &1,
                        &b0.as_ptr(),
                        &b1.as_ptr(),
                        &drop0.len(),
                        1,
                        d,
                        r,
                        threads,
                        &mut step,
                    );
                    assert_eq!(rc, DHCD_OK, "{}", last_error());
                    assert_eq!(step, want.step);
                }
            }
            let mut step = -1.0;
            for (ids, r, code) in [
                ([1u64, 1], 0.8, DHCD_ERR_REPEATED_OBJECT),
                ([1, 5], 0.8, DHCD_ERR_UNKNOWN_OBJECT),
                ([1, 0], 0.0, DHCD_ERR_INVALID_ARGUMENT),
            ] {
                let x0s = [b0.as_ptr(), b0.as_ptr()];
                let x1s = [b1.as_ptr(), b1.as_ptr()];
                let counts = [drop0.len(), drop0.len()];
                let one = usize::from(code == DHCD_ERR_INVALID_ARGUMENT);
                let rc = dhcd_scene_collision_free_stepsize(
                    s,
                    ids.as_ptr(),
                    x0s.as_ptr(),
                    x1s.as_ptr(),
                    counts.as_ptr(),
                    2 - one,
                    0.0,
                    r,
                    1,
                    &mut step,
                );
                assert_eq!(rc, code, "{}", last_error());
                assert_eq!(step, -1.0, "written only on success");
            }
            dhcd_scene_free(s);
        }
    }
}
