"""Contacts equal an independent exact brute force, for every method, tree shape and pose;
the result types are the documented ones."""

import numpy as np
import pytest

import dhcd
from meshes import brute_force_pairs, brute_force_self_pairs, folded_grid, icosphere, wave

METHODS = list(dhcd._dhcd.METHODS)
LEVELS = [None, 1, 3, 5]


def test_methods_come_from_the_library_table():
    assert METHODS == ["dh", "sphere", "aabb"]
    sizes = {m: dhcd.Hierarchy(*icosphere(0), method=m).bytes_per_node for m in METHODS}
    assert sizes == {"dh": 8, "sphere": 16, "aabb": 24}
    assert dhcd.Hierarchy(*icosphere(0), method="SBV").method == "sphere"


@pytest.mark.parametrize("method", METHODS)
@pytest.mark.parametrize("levels", LEVELS)
def test_pair_equals_brute_force(method, levels):
    va, fa = icosphere(2)
    vb, fb = icosphere(1, 0.8)
    for t in [0.0, 0.9, 2.3]:
        pa = wave(va, t, 0.08)
        pb = wave(vb, -t, 0.1, (1.3, 0.2, -0.1))
        expected = brute_force_pairs(pa, fa, pb, fb)
        assert len(expected) > 0
        a = dhcd.Hierarchy(pa, fa, method=method, levels=levels)
        b = dhcd.Hierarchy(pb, fb, method=method, levels=levels)
        c = dhcd.collide(a, b)
        assert c.pairs.dtype == np.int64 and c.pairs.shape == expected.shape
        np.testing.assert_array_equal(c.pairs, expected)
        assert len(c) == len(expected)
        assert set(c.counters) == {"bv_tests", "prim_tests", "bv_updates", "contacts"}
        assert c.counters["contacts"] == len(expected)
        assert all(type(v) is int for v in c.counters.values())


@pytest.mark.parametrize("method", METHODS)
def test_deforming_sequence_refits_and_stays_exact(method):
    va, fa = icosphere(2)
    vb, fb = icosphere(2, 0.9)
    a = dhcd.Hierarchy(va, fa, method=method)
    b = dhcd.Hierarchy(vb, fb, method=method)
    touching = 0
    for step in range(10):
        t = 0.4 * step
        pa = wave(va, t, 0.1)
        pb = wave(vb, -t, 0.1, (2.2 - 0.12 * step, 0.2, 0.0))
        a.update(pa)
        b.update(pb)
        c = dhcd.collide(a, b)
        np.testing.assert_array_equal(c.pairs, brute_force_pairs(pa, fa, pb, fb))
        # Lazy refit: the query refits what it tests, after every update.
        assert c.counters["bv_updates"] > 0
        touching += len(c.pairs) > 0
    assert 0 < touching < 10, "the spheres start apart and then meet"


@pytest.mark.parametrize("method", METHODS)
@pytest.mark.parametrize("levels", [None, 4])
def test_self_collision_equals_brute_force(method, levels):
    for t in [0.0, 1.1]:
        rest, folded, faces = folded_grid(6, t)
        expected = brute_force_self_pairs(folded, faces)
        assert len(expected) > 0
        h = dhcd.Hierarchy(rest, faces, method=method, levels=levels)
        assert len(h.self_collide().pairs) == 0, "the flat rest pose has no self-contacts"
        h.update(folded)
        c = h.self_collide()
        np.testing.assert_array_equal(c.pairs, expected)
        assert np.all(c.pairs[:, 0] < c.pairs[:, 1])


def test_contacts_are_original_face_indices():
    # Faces listed in a scrambled order: pairs name the caller's rows.
    va, fa = icosphere(2)
    vb = wave(va, 0.5, 0.05, (1.0, 0.0, 0.0))
    perm = np.random.default_rng(7).permutation(len(fa))
    a = dhcd.Hierarchy(va, fa[perm])
    b = dhcd.Hierarchy(vb, fa)
    expected = brute_force_pairs(va, fa[perm], vb, fa)
    np.testing.assert_array_equal(dhcd.collide(a, b).pairs, expected)


def test_float64_int32_and_lists_are_accepted():
    va, fa = icosphere(1)
    vb = wave(va, 0.3, 0.05, (1.1, 0.0, 0.0))
    expected = brute_force_pairs(va, fa, vb, fa)
    # float64 arrays and lists of Python floats (float64 to numpy) build f64 hierarchies; the
    # float32 values are exact doubles, so the contacts are the same.
    a = dhcd.Hierarchy(va.astype(np.float64), fa.astype(np.int32))
    b = dhcd.Hierarchy(vb.tolist(), fa.astype(np.uint16).tolist())
    assert a.precision == b.precision == "f64"
    np.testing.assert_array_equal(dhcd.collide(a, b).pairs, expected)
    # A strided (non-contiguous) view of either float type reads the same values.
    for h, dtype in [(b, np.float64), (dhcd.Hierarchy(va, fa), np.float32)]:
        wide = np.zeros((len(vb), 6), dtype=dtype)
        wide[:, ::2] = vb
        h.update(wide[:, ::2])
        np.testing.assert_array_equal(dhcd.collide(a, h).pairs, expected)


def test_contact_segments_lie_on_both_triangles():
    va, fa = icosphere(2)
    vb = wave(va, 0.4, 0.05, (1.2, 0.1, 0.0))
    a, b = dhcd.Hierarchy(va, fa), dhcd.Hierarchy(vb, fa)
    pairs = dhcd.collide(a, b).pairs
    seg = dhcd.contact_segments(a, b, pairs)
    assert seg.shape == (len(pairs), 2, 3) and seg.dtype == np.float32
    for (i, j), s in zip(pairs, seg.astype(np.float64)):
        for v, f in ((va, fa[i]), (vb, fa[j])):
            p = v[f].astype(np.float64)
            n = np.cross(p[1] - p[0], p[2] - p[0])
            n /= np.linalg.norm(n)
            assert np.all(np.abs((s - p[0]) @ n) < 1e-5)
    assert dhcd.contact_segments(a, b, np.zeros((0, 2), np.int64)).shape == (0, 2, 3)
    # Self-contact segments: the same hierarchy twice.
    rest, folded, faces = folded_grid(5)
    h = dhcd.Hierarchy(folded, faces)
    sp = h.self_collide().pairs
    assert dhcd.contact_segments(h, h, sp).shape == (len(sp), 2, 3)


def test_load_mesh_round_trip(tmp_path):
    v, f = icosphere(1)
    path = tmp_path / "ball.obj"
    with open(path, "w") as out:
        for p in v:
            # float64 digits of the float32 values: exact through any parser.
            out.write("v {:.17g} {:.17g} {:.17g}\n".format(*map(float, p)))
        for t in f + 1:
            out.write("f {} {} {}\n".format(*t))
    lv, lf = dhcd.load_mesh(path)
    assert lv.dtype == np.float32 and lf.dtype == np.int64
    np.testing.assert_array_equal(lv, v)
    np.testing.assert_array_equal(lf, f)
    assert dhcd.load_mesh(str(path))[0].shape == (len(v), 3)
    # A binary STL of the same mesh: 80-byte header, count, 50 bytes a facet.
    stl = tmp_path / "ball.stl"
    facets = np.zeros(len(f), dtype=[("n", "<f4", 3), ("p", "<f4", (3, 3)), ("a", "<u2")])
    facets["p"] = v[f]
    with open(stl, "wb") as out:
        out.write(b"\0" * 80 + np.uint32(len(f)).tobytes() + facets.tobytes())
    sv, sf = dhcd.load_mesh(stl)
    np.testing.assert_array_equal(sv[sf], v[f])
