"""Proximity equals an exact brute force (proximity_oracle.py) on integer-grid meshes full of
ties (points on edges, parallel edges, distances equal to d), for every method, both
precisions and thread counts; the scene's rows are the pair and self queries' with object
ids; bad distances are ValueError."""

import numpy as np
import pytest

import dhcd
from meshes import grid, icosphere, wave
from proximity_oracle import EDGE_EDGE, POINT_TRIANGLE, proximity, self_proximity

METHODS = list(dhcd._dhcd.METHODS)


def sheets():
    """Two integer grids: A (cells of 2, z = 0) and B above it (shifted by (1, 0, 1), with a
    bump of 1 on every other vertex): vertices at distance exactly 1 of A's faces and edges,
    edges parallel to A's."""
    va, fa = grid(3, 3, 2.0)
    vb = va.astype(np.float64) + (1.0, 0.0, 1.0)
    vb[::2, 2] += 1.0
    return va.astype(np.float64), fa, vb, fa.copy()


def folded():
    """An integer grid of 6 x 2 cells of 2, folded over itself at x = 6: the upper layer
    (z = 2) lies over x in [0, 4], 2 above the lower one."""
    v, f = grid(6, 2, 2.0)
    v = v.astype(np.float64)
    right = v[:, 0] > 6
    v[right, 0] = 12 - v[right, 0]
    v[right, 2] = 2.0
    return v, f


def check(got, expected, pair):
    """`got` (a dhcd.Proximity) equals the oracle's lists: rows and types exactly, squared
    distances to 1e-12 relative."""
    vf, fv, ee = expected
    for name, rows, width in [
        ("vertex_face", vf, 2),
        ("face_vertex", fv, 2),
        ("edge_edge", ee, 4),
    ]:
        prefix = {"vertex_face": "vf", "face_vertex": "fv", "edge_edge": "ee"}[name]
        idx = getattr(got, name)
        dist = getattr(got, prefix + "_distance_sq")
        kind = getattr(got, prefix + "_type")
        assert idx.dtype == np.int64 and idx.shape == (len(rows), width), name
        assert dist.dtype == np.float64 and dist.shape == (len(rows),)
        assert kind.dtype == np.uint8 and kind.shape == (len(rows),)
        want = np.array([r[:width] for r in rows], dtype=np.int64).reshape(-1, width)
        np.testing.assert_array_equal(idx, want, err_msg=name)
        names = POINT_TRIANGLE if name != "edge_edge" else EDGE_EDGE
        assert [names[k] for k in kind] == [names[r[-1]] for r in rows], name
        exact = np.array([float(r[-2]) for r in rows], dtype=np.float64)
        np.testing.assert_allclose(dist, exact, rtol=1e-12, atol=1e-12, err_msg=name)
    if not pair:
        assert got.face_vertex.shape == (0, 2)
    assert got.counters["contacts"] == len(vf) + len(fv) + len(ee) == len(got)
    assert set(got.counters) == {"bv_tests", "prim_tests", "bv_updates", "contacts"}


def arrays(p):
    """Every array of a result and its counters, for equality across thread counts."""
    names = [
        "vertex_face", "vf_distance_sq", "vf_type",
        "face_vertex", "fv_distance_sq", "fv_type",
        "edge_edge", "ee_distance_sq", "ee_type",
    ]
    return [getattr(p, n).tolist() for n in names] + [p.counters]


def test_type_names_are_ipcs():
    assert dhcd.POINT_TRIANGLE_TYPES == POINT_TRIANGLE
    assert dhcd.EDGE_EDGE_TYPES == EDGE_EDGE


@pytest.mark.parametrize("method", METHODS)
@pytest.mark.parametrize("dtype", [np.float32, np.float64])
@pytest.mark.parametrize("d", [1.0, 1.5, 0.0])
def test_pair_equals_exact_brute_force(method, dtype, d):
    va, fa, vb, fb = sheets()
    expected = proximity(va, fa, vb, fb, d)
    if d > 0:
        assert all(len(x) > 0 for x in expected)
    if d == 1.0:
        # Ties the exact decision must include: pairs at exactly d.
        assert any(r[-2] == 1 for r in expected[0]) and any(r[-2] == 1 for r in expected[2])
    runs = []
    for threads in [1, 2]:
        a = dhcd.Hierarchy(va.astype(dtype), fa, method=method)
        b = dhcd.Hierarchy(vb.astype(dtype), fb, method=method)
        assert a.precision == b.precision == np.dtype(dtype).name.replace("loat", "")
        got = dhcd.proximity(a, b, d, threads=threads)
        check(got, expected, pair=True)
        runs.append(arrays(got))
    assert runs[0] == runs[1], "threads change nothing, counters included"


@pytest.mark.parametrize("method", METHODS)
@pytest.mark.parametrize("dtype", [np.float32, np.float64])
@pytest.mark.parametrize("d", [2.0, 1.5])
def test_self_equals_exact_brute_force(method, dtype, d):
    v, f = folded()
    expected = self_proximity(v, f, d)
    assert len(expected[0]) > 0 and len(expected[2]) > 0
    runs = []
    for threads in [1, 2]:
        h = dhcd.Hierarchy(v.astype(dtype), f, method=method, levels=3)
        got = dhcd.self_proximity(h, d, threads=threads)
        check(got, expected, pair=False)
        ee = got.edge_edge
        assert np.all(ee[:, 0] < ee[:, 1]) and np.all(ee[:, 2] < ee[:, 3])
        assert all(tuple(e[:2]) < tuple(e[2:]) for e in ee.tolist())
        runs.append(arrays(got))
    assert runs[0] == runs[1]


def test_deformed_pair_and_update():
    # Off the grid: a rippled pair, after an update, against the oracle.
    va, fa = icosphere(1)
    vb = wave(va, 0.4, 0.05, (1.9, 0.1, 0.0))
    a = dhcd.Hierarchy(va, fa)
    b = dhcd.Hierarchy(va, fa)
    b.update(vb)
    got = dhcd.proximity(a, b, 0.1)
    expected = proximity(va, fa, vb, fa, 0.1)
    assert all(len(x) > 0 for x in expected)
    check(got, expected, pair=True)


def test_scene_rows_are_the_pair_and_self_queries():
    va, fa, vb, fb = sheets()
    v, f = folded()
    far = va + 100.0
    meshes = [(va, fa), (vb.astype(np.float32), fb), (v + (0.0, 0.0, 3.5), f), (far, fa)]
    for method in METHODS:
        scenes = [dhcd.Scene(method=method) for _ in range(2)]
        for s in scenes:
            for k, (x, y) in enumerate(meshes):
                s.add(x, y, name=f"m{k}")
            s.set_self_collision("m2", True)
        d = 1.5
        hs = [dhcd.Hierarchy(x, y, method=method) for x, y in meshes]
        expected = {"vertex_face": [], "face_vertex": [], "edge_edge": []}
        dist = {"vertex_face": [], "face_vertex": [], "edge_edge": []}
        kinds = {"vertex_face": [], "face_vertex": [], "edge_edge": []}

        def add(i, j, p):
            for name, pre, split in [
                ("vertex_face", "vf", 1), ("face_vertex", "fv", 1), ("edge_edge", "ee", 2)
            ]:
                for row, x, t in zip(
                    getattr(p, name).tolist(),
                    getattr(p, pre + "_distance_sq").tolist(),
                    getattr(p, pre + "_type").tolist(),
                ):
                    expected[name].append(([i] + row[:split] + [j] + row[split:], x, t))

        for i in range(len(hs)):
            for j in range(i + 1, len(hs)):
                add(i, j, dhcd.proximity(hs[i], hs[j], d))
        add(2, 2, dhcd.self_proximity(hs[2], d))
        results = [s.proximity(d, threads=t) for s, t in zip(scenes, [1, 2])]
        for got in results:
            for name, pre, width in [
                ("vertex_face", "vf", 4), ("face_vertex", "fv", 4), ("edge_edge", "ee", 6)
            ]:
                rows = sorted(expected[name])
                assert len(rows) > 0, name
                idx = getattr(got, name)
                assert idx.dtype == np.int64 and idx.shape == (len(rows), width)
                assert idx.tolist() == [r[0] for r in rows], name
                assert getattr(got, pre + "_distance_sq").tolist() == [r[1] for r in rows]
                assert getattr(got, pre + "_type").tolist() == [r[2] for r in rows]
            assert not np.any(got.vertex_face[:, [0, 2]] == 3), "the far object"
            assert np.any(got.vertex_face[:, 0] == got.vertex_face[:, 2]), "self rows"
        assert arrays(results[0]) == arrays(results[1])


@pytest.mark.parametrize("d", [-1.0, -1e-300, float("nan"), float("inf"), -float("inf"), 1e400])
def test_bad_distances(d):
    v, f = icosphere(0)
    a, b = dhcd.Hierarchy(v, f), dhcd.Hierarchy(v, f)
    s = dhcd.Scene()
    s.add(v, f)
    for call in [
        lambda: dhcd.proximity(a, b, d),
        lambda: dhcd.self_proximity(a, d, threads=2),
        lambda: s.proximity(d),
    ]:
        with pytest.raises(ValueError, match="distance"):
            call()
    with pytest.raises(ValueError, match="distance .*10{400}|out of range|not a finite"):
        dhcd.proximity(a, b, 10**400)


def test_bad_arguments():
    v, f = icosphere(0)
    a = dhcd.Hierarchy(v, f)
    box = dhcd.Hierarchy(v, f, method="aabb")
    with pytest.raises(ValueError, match="self_proximity"):
        dhcd.proximity(a, a, 0.1)
    with pytest.raises(ValueError, match="dh.*aabb"):
        dhcd.proximity(a, box, 0.1)
    with pytest.raises(ValueError, match="threads"):
        dhcd.proximity(a, box, 0.1, threads=-1)
    with pytest.raises(ValueError, match="threads"):
        dhcd.self_proximity(a, 0.1, threads=2**20)
    with pytest.raises(ValueError, match="threads"):
        dhcd.Scene().proximity(0.1, threads=5000)
    with pytest.raises(TypeError):
        dhcd.self_proximity(a, "0.1")
    with pytest.raises(TypeError):
        dhcd.self_proximity((v, f), 0.1)
    # Integers are distances; an empty scene has nothing.
    assert len(dhcd.self_proximity(a, 0)) == len(dhcd.self_proximity(a, 0.0))
    empty = dhcd.Scene().proximity(1)
    assert empty.vertex_face.shape == (0, 4) and empty.edge_edge.shape == (0, 6)
    assert "Proximity(" in repr(empty)
