"""float64 input builds f64 hierarchies and objects whose answers are exact for the doubles;
the dtype rules; an update of the other float type is a ValueError and changes nothing."""

import numpy as np
import pytest

import dhcd
from meshes import icosphere, wave

METHODS = list(dhcd._dhcd.METHODS)
ONE = np.array([[0, 1, 2]])
MISMATCH = "positions are {}, but the mesh or hierarchy is {}"


def near_pair(gap):
    """Triangle A in the plane z = 1, triangle B above it with its lowest corner `gap` above
    A's interior: 1 + gap in float64 (rounded to float32, 1.0 for a gap below 3e-8)."""
    a = np.array([[0, 0, 1], [2, 0, 1], [0, 2, 1]], dtype=np.float64)
    b = np.array([[0.5, 0.5, 1 + gap], [0.5, 0.5, 2], [0.2, 0.8, 2]], dtype=np.float64)
    return a, b


@pytest.mark.parametrize("method", METHODS)
def test_float64_answers_are_exact_for_the_doubles(method):
    a, b = near_pair(1e-9)
    ha, hb = dhcd.Hierarchy(a, ONE, method=method), dhcd.Hierarchy(b, ONE, method=method)
    assert ha.precision == hb.precision == "f64"
    # Rounded to float32, B's corner lies on A: a contact, at distance 0.
    ha32 = dhcd.Hierarchy(a.astype(np.float32), ONE, method=method)
    hb32 = dhcd.Hierarchy(b.astype(np.float32), ONE, method=method)
    assert ha32.precision == "f32"
    assert dhcd.collide(ha32, hb32).pairs.tolist() == [[0, 0]]
    assert dhcd.proximity(ha32, hb32, 5e-10).fv_distance_sq.tolist() == [0.0]
    # As doubles, B is 1e-9 above: no contact, within 2e-9 but not 5e-10.
    assert len(dhcd.collide(ha, hb)) == 0
    gap = (1 + 1e-9) - 1
    p = dhcd.proximity(ha, hb, 2e-9)
    assert p.face_vertex.tolist() == [[0, 0]] and len(p) == 1
    assert p.fv_distance_sq.tolist() == [gap * gap]
    assert dhcd.POINT_TRIANGLE_TYPES[p.fv_type[0]] == "P_T"
    assert len(dhcd.proximity(ha, hb, 5e-10, threads=2)) == 0
    # Updates in float64: below A's plane (crossing), then back.
    hb.update(near_pair(-1e-9)[1])
    assert dhcd.collide(ha, hb).pairs.tolist() == [[0, 0]]
    hb.update(b)
    assert len(dhcd.collide(ha, hb)) == 0
    # Mixed pairs: each side exact for its own coordinates.
    assert len(dhcd.collide(ha32, hb)) == 0
    assert dhcd.collide(ha, hb32).pairs.tolist() == [[0, 0]]


def test_dtype_rules():
    v, f = icosphere(0)
    cases = [
        (v, "f32"),
        (v.astype(np.float64), "f64"),
        (v.astype(">f8"), "f64"),  # float64 in any byte order
        (v.astype(np.float64).tolist(), "f64"),  # Python floats are float64 to numpy
        (v.astype(np.float16), "f32"),  # other real dtypes: float32, as before
        (np.round(v * 4).astype(np.int64), "f32"),
        (np.round(v * 4).astype(np.int32).tolist(), "f32"),
        (v.astype(np.longdouble), "f32"),
    ]
    for vertices, precision in cases:
        assert dhcd.Hierarchy(vertices, f).precision == precision, np.asarray(vertices).dtype
        s = dhcd.Scene()
        s.add(vertices, f)
    # Updates: the hierarchy's float type, or other real dtypes converted to it.
    h64 = dhcd.Hierarchy(v.astype(np.float64), f)
    h32 = dhcd.Hierarchy(v, f)
    ints = np.round(v * 4).astype(np.int16)
    for h, same in [(h64, v.astype(np.float64)), (h32, v)]:
        h.update(same)
        h.update(ints)
        h.update(ints.tolist())
        h.update(v.astype(np.float16))
    h64.update(v.astype(np.float64).tolist())
    h64.update(v.astype(">f8"))


def test_an_update_of_the_other_precision_raises_and_changes_nothing():
    va, fa = icosphere(1)
    vb = wave(va, 0.3, 0.05, (1.2, 0.0, 0.0))
    far = (vb + np.float32(10)).astype(np.float32)
    for dtype, other in [(np.float64, np.float32), (np.float32, np.float64)]:
        a = dhcd.Hierarchy(va.astype(dtype), fa)
        b = dhcd.Hierarchy(vb.astype(dtype), fa)
        before = dhcd.collide(a, b).pairs
        assert len(before) > 0
        mine, theirs = ("f64", "f32") if dtype == np.float64 else ("f32", "f64")
        bad = [far.astype(other), far.astype(other)[:-1]]
        if dtype == np.float32:
            bad.append(far.astype(np.float64).tolist())
        for vertices in bad:
            with pytest.raises(ValueError) as e:
                b.update(vertices)
            assert str(e.value) == MISMATCH.format(theirs, mine)
        np.testing.assert_array_equal(dhcd.collide(a, b).pairs, before)
        assert b.precision == mine
    # float64 beyond float32's range: refused by an f64 hierarchy, which is unchanged.
    a = dhcd.Hierarchy(va.astype(np.float64), fa)
    b = dhcd.Hierarchy(vb.astype(np.float64), fa)
    before = dhcd.collide(a, b).pairs
    huge = vb.astype(np.float64)
    huge[3, 1] = 1e39
    with pytest.raises(ValueError, match="beyond the f32 range"):
        b.update(huge)
    with pytest.raises(ValueError, match="beyond the f32 range"):
        dhcd.Hierarchy(huge, fa)
    np.testing.assert_array_equal(dhcd.collide(a, b).pairs, before)


def scene_of(meshes, method="dh"):
    s = dhcd.Scene(method=method)
    for k, (v, f) in enumerate(meshes):
        s.add(v, f, name=f"o{k}")
    s.set_self_collision(1, True)
    return s


def test_scene_objects_keep_their_precision():
    v, f = icosphere(2)
    v64 = v.astype(np.float64)
    meshes = [(v, f), (v64, f), (v, f), (v64, f)]
    poses = [wave(v, k, 0.3, (1.6 * k, 0.0, 0.0)) for k in range(4)]
    poses = [p.astype(np.float64) if k % 2 else p for k, p in enumerate(poses)]
    for method in METHODS:
        one_by_one = scene_of(meshes, method)
        for k, p in enumerate(poses):
            one_by_one.update(k, p)
        expected = one_by_one.contacts()
        assert len(expected.pairs) > 0
        for threads in [1, 2]:
            # update_many with both precisions in one call equals one update per object.
            s = scene_of(meshes, method)
            s.update_many({f"o{k}": p for k, p in enumerate(poses)}, threads=threads)
            got = s.contacts()
            np.testing.assert_array_equal(got.pairs, expected.pairs)
            assert got.counters == expected.counters
            # step likewise.
            s = scene_of(meshes, method)
            got = s.step(list(enumerate(poses)), threads=threads)
            np.testing.assert_array_equal(got.pairs, expected.pairs)
            assert got.counters == expected.counters
            # Only the f64 objects in one call.
            s = scene_of(meshes, method)
            for k in [0, 2]:
                s.update(k, poses[k])
            s.update_many([(3, poses[3]), (1, poses[1])], threads=threads)
            np.testing.assert_array_equal(s.contacts().pairs, expected.pairs)


def test_scene_precision_errors_change_nothing():
    v, f = icosphere(1)
    s = scene_of([(v, f), (v.astype(np.float64), f)])
    before = s.contacts().pairs
    assert len(before) > 0
    far32 = v + np.float32(10)
    far64 = far32.astype(np.float64)
    huge = far64.copy()
    huge[0, 0] = 1e39
    cases = [
        ((1, far32), MISMATCH.format("f32", "f64")),
        ((0, far64), MISMATCH.format("f64", "f32")),
        (("o1", far64[:-1]), "vertices"),
        (("o1", huge), "beyond the f32 range"),
    ]
    for entry, message in cases:
        with pytest.raises(ValueError) as single:
            s.update(*entry)
        assert message in str(single.value)
        # The same error from the batch calls, after a good entry for the other object.
        good = (0, far32) if entry[0] in (1, "o1") else ("o1", far64)
        for call in [s.update_many, s.step]:
            with pytest.raises(ValueError) as many:
                call([good, entry], threads=2)
            assert str(many.value) == str(single.value)
        np.testing.assert_array_equal(s.contacts().pairs, before, err_msg=message)
    with pytest.raises(ValueError, match="more than once"):
        s.update_many([(1, far64), (0, far32), ("o1", far64)])
    with pytest.raises(ValueError, match="more than once"):
        s.step({0: far32, 1: far64, "o1": far64})
    np.testing.assert_array_equal(s.contacts().pairs, before)
    s.update_many({1: far64})
    assert all(r[0] == r[2] == 1 for r in s.contacts().pairs.tolist()), "moved apart"
    assert len(dhcd.Scene().step({})) == 0
