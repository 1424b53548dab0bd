//! The C ABI from Rust: results equal the Rust API, bad arguments are error codes (null,
//! mismatched lengths, wrong kind, unknown ids), and `include/dhcd.h` declares exactly the
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
        // Wrong kind; the same handle twice.
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
    // The kinds' numbers, from the library's table of kinds.
    let mut kinds = String::from("\n/**\n * Hierarchy kinds (`method` arguments).\n */");
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
        for threads in [u32::MAX, dhcd::par::MAX_THREADS as u32 + 1] {
            let mut c = empty();
            assert_eq!(
                dhcd_collide(ha, hb, threads, &mut c),
                DHCD_ERR_INVALID_ARGUMENT
            );
            let message = last_error();
            assert!(message.contains(&threads.to_string()), "{message}");
        }
        for threads in [0, 1, 2, dhcd::par::MAX_THREADS as u32] {
            let mut c = empty();
            assert_eq!(dhcd_collide(ha, hb, threads, &mut c), DHCD_OK);
            assert_eq!(pairs_of(&c), brute_force_pairs(&a, &b), "{threads}");
            dhcd_contacts_free(&mut c);
        }
        dhcd_hierarchy_free(ha);
        dhcd_hierarchy_free(hb);
    }
}
