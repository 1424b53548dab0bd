"""Continuous collision detection: ``dhcd.ccd`` equals a brute force over every feature pair
(plain Python loops over the pairs, each tested with the single-pair ``vertex_face_ccd`` /
``edge_edge_ccd``) on meshes that tunnel through each other within the step, for every
method, hierarchies of both precisions, 1 and 2 threads, both modes, a time limit and a
minimum distance; the single-pair functions decide every labelled query of the sample set
of Wang et al. 2021 as its label; bad input raises ``ValueError`` (``TypeError`` for
arguments of the wrong Python type)."""

import math
import os
from fractions import Fraction

import numpy as np
import pytest

import dhcd
from meshes import grid, icosphere

METHODS = list(dhcd._dhcd.METHODS)

# In the repository, as for the Rust tests (`tests/data/ccd-sample-queries`, provenance in
# `tests/data/README.md`).
SAMPLES = os.path.join(
    os.path.dirname(os.path.abspath(__file__)),
    "..", "..", "tests", "data", "ccd-sample-queries",
)


# -------------------------------------------------------------------------------------------
# The brute force: every pair, in plain Python, each tested by the single-pair functions.
# -------------------------------------------------------------------------------------------


def unique_edges(faces):
    """Every edge of the faces once, smaller vertex first, ascending."""
    edges = set()
    for f in faces:
        for i in range(3):
            a, b = f[i], f[(i + 1) % 3]
            edges.add((min(a, b), max(a, b)))
    return sorted(edges)


def run_queries(test, rows, q0, q1, options):
    """The rows whose query collides, with their times: [(row, toi), ...]."""
    if not rows:
        return []
    hits, toi = test(np.array(q0, dtype=np.float64), np.array(q1, dtype=np.float64), **options)
    return [(row, t) for row, h, t in zip(rows, hits.tolist(), toi.tolist()) if h]


def brute_force_self(faces, x0, x1, **options):
    """(vertex_face, face_vertex, edge_edge) of one mesh: a vertex and a face not containing
    it, two edges sharing no vertex (the first smaller)."""
    faces, x0, x1 = faces.tolist(), x0.tolist(), x1.tolist()
    rows, q0, q1 = [], [], []
    for v in range(len(x0)):
        for t, corners in enumerate(faces):
            if v not in corners:
                rows.append([v, t])
                q0.append([x0[i] for i in [v] + corners])
                q1.append([x1[i] for i in [v] + corners])
    vf = run_queries(dhcd.vertex_face_ccd, rows, q0, q1, options)
    edges = unique_edges(faces)
    rows, q0, q1 = [], [], []
    for i, ea in enumerate(edges):
        for eb in edges[i + 1:]:
            if set(ea) & set(eb):
                continue
            rows.append(list(ea + eb))
            q0.append([x0[k] for k in ea + eb])
            q1.append([x1[k] for k in ea + eb])
    ee = run_queries(dhcd.edge_edge_ccd, rows, q0, q1, options)
    return vf, [], ee


def brute_force_pair(fa, a0, a1, fb, b0, b1, **options):
    """(vertex_face, face_vertex, edge_edge) of two meshes: vertices of a against faces of
    b, faces of a against vertices of b, edges of a against edges of b."""
    fa, fb = fa.tolist(), fb.tolist()
    a0, a1, b0, b1 = a0.tolist(), a1.tolist(), b0.tolist(), b1.tolist()

    def vertex_face(faces_v, v0, v1, faces_t, t0, t1, flip):
        rows, q0, q1 = [], [], []
        for v in range(len(v0)):
            for t, c in enumerate(faces_t):
                rows.append([t, v] if flip else [v, t])
                q0.append([v0[v]] + [t0[i] for i in c])
                q1.append([v1[v]] + [t1[i] for i in c])
        return sorted(run_queries(dhcd.vertex_face_ccd, rows, q0, q1, options))

    rows, q0, q1 = [], [], []
    for ea in unique_edges(fa):
        for eb in unique_edges(fb):
            rows.append(list(ea + eb))
            q0.append([a0[ea[0]], a0[ea[1]], b0[eb[0]], b0[eb[1]]])
            q1.append([a1[ea[0]], a1[ea[1]], b1[eb[0]], b1[eb[1]]])
    return (
        vertex_face(fa, a0, a1, fb, b0, b1, False),
        vertex_face(fb, b0, b1, fa, a0, a1, True),
        run_queries(dhcd.edge_edge_ccd, rows, q0, q1, options),
    )


def earliest_of(expected):
    """What earliest mode returns: the pairs whose time is the least one."""
    toi = min((t for rows in expected for _, t in rows), default=math.inf)
    return tuple([(r, t) for r, t in rows if t == toi] for rows in expected)


def check(got, expected, pair):
    """`got` (a dhcd.Impacts) has exactly the expected rows and times (the query and the
    brute force give each pair the same points in the same order, so the times agree to
    the bit)."""
    assert isinstance(got, dhcd.Impacts)
    for (name, width, prefix), rows in zip(
        [("vertex_face", 2, "vf"), ("face_vertex", 2, "fv"), ("edge_edge", 4, "ee")], expected
    ):
        idx, toi = getattr(got, name), getattr(got, prefix + "_toi")
        assert idx.dtype == np.int64 and idx.shape == (len(rows), width), name
        assert toi.dtype == np.float64 and toi.shape == (len(rows),), name
        assert idx.tolist() == [r for r, _ in rows], name
        assert toi.tolist() == [t for _, t in rows], name
        assert all(0.0 <= t <= 1.0 for _, t in rows)
    if not pair:
        assert got.face_vertex.shape == (0, 2) and got.fv_toi.shape == (0,)
    least = min((t for rows in expected for _, t in rows), default=math.inf)
    assert isinstance(got.toi, float) and got.toi == least
    n = sum(len(rows) for rows in expected)
    assert got.counters["contacts"] == n == len(got)
    assert set(got.counters) == {"bv_tests", "prim_tests", "bv_updates", "contacts"}
    assert got.counters["prim_tests"] >= n


def arrays(r):
    """Every array of a result, its earliest time and its counters."""
    names = ["vertex_face", "vf_toi", "face_vertex", "fv_toi", "edge_edge", "ee_toi"]
    return [getattr(r, n).tolist() for n in names] + [r.toi, r.counters]


# -------------------------------------------------------------------------------------------
# Test cases
# -------------------------------------------------------------------------------------------


def tunnelling_layers():
    """One mesh of two 4 x 4 sheets (the second's vertices after the first's): the lower
    one still, the upper one moving from 0.3 above it to 0.3 below it. Neither end pose
    has a contact; the layers pass through each other during the step."""
    v, f = grid(4, 4, 0.25)
    lower = v.astype(np.float64)
    lower[:, 2] = 0.02 * np.sin(7.0 * lower[:, 0] + 3.0 * lower[:, 1])
    upper0 = lower + (0.07, 0.05, 0.3)
    upper1 = upper0 + (0.02, -0.03, -0.6)
    faces = np.concatenate([f, f + len(v)])
    return faces, np.concatenate([lower, upper0]), np.concatenate([lower, upper1])


def tunnelling_balls():
    """Two balls flying through each other within the step (apart at both ends)."""
    va, fa = icosphere(1, 0.5)
    vb, fb = icosphere(1, 0.4, (0.3, 0.05, 0.0))
    a0 = va.astype(np.float64)
    a1 = a0 + (0.1, 0.0, 0.02)
    b0 = vb.astype(np.float64) + (1.0, 0.0, 0.0)
    b1 = b0 + (-2.6, 0.1, 0.0)
    return fa, a0, a1, fb, b0, b1


def hierarchy(x, faces, method, precision):
    """A hierarchy of the mesh in pose `x`, of the given precision (the CCD positions are
    float64 either way)."""
    return dhcd.Hierarchy(x.astype(precision), faces, method=method)


@pytest.mark.parametrize("method", METHODS)
def test_self_ccd_equals_the_brute_force(method):
    faces, x0, x1 = tunnelling_layers()
    expected = brute_force_self(faces, x0, x1)
    assert len(expected[0]) > 0 and len(expected[2]) > 0
    assert 0.0 < min(t for rows in expected for _, t in rows) < 1.0
    # The discrete test sees nothing at either end.
    h = dhcd.Hierarchy(x0, faces, method=method)
    assert len(h.self_collide()) == 0
    h.update(x1)
    assert len(h.self_collide()) == 0
    runs = []
    for precision in [np.float64, np.float32]:
        h = hierarchy(x0, faces, method, precision)
        for threads in [1, 2]:
            got = dhcd.ccd(h, x0, x1, threads=threads)
            check(got, expected, pair=False)
            ee = got.edge_edge
            assert np.all(ee[:, 0] < ee[:, 1]) and np.all(ee[:, 2] < ee[:, 3])
            assert all(tuple(e[:2]) < tuple(e[2:]) for e in ee.tolist())
            runs.append(arrays(got))
            early = dhcd.ccd(h, x0, x1, earliest=True, threads=threads)
            check(early, earliest_of(expected), pair=False)
            assert early.toi == got.toi
    assert runs[0] == runs[1], "threads change nothing, counters included"
    assert runs[2] == runs[3]


def test_pair_ccd_equals_the_brute_force_for_every_kind():
    fa, a0, a1, fb, b0, b1 = tunnelling_balls()
    expected = brute_force_pair(fa, a0, a1, fb, b0, b1)
    assert all(len(rows) > 0 for rows in expected)
    toi = min(t for rows in expected for _, t in rows)
    assert 0.0 < toi < 1.0
    t_max = 0.5 * toi + 0.25
    part = brute_force_pair(fa, a0, a1, fb, b0, b1, t_max=t_max)
    assert 0 < sum(map(len, part)) < sum(map(len, expected))
    results = {}
    for method in METHODS:
        for pa, pb in [(np.float64, np.float64), (np.float32, np.float64)]:
            a = hierarchy(a0, fa, method, pa)
            b = hierarchy(b0, fb, method, pb)
            runs = []
            for threads in [1, 2]:
                got = dhcd.ccd(a, b, a0, a1, b0, b1, threads=threads)
                check(got, expected, pair=True)
                runs.append(arrays(got))
                early = dhcd.ccd(a, b, a0, a1, b0, b1, earliest=True, threads=threads)
                check(early, earliest_of(expected), pair=True)
                limited = dhcd.ccd(a, b, a0, a1, b0, b1, t_max=t_max, threads=threads)
                check(limited, part, pair=True)
            assert runs[0] == runs[1], "threads change nothing, counters included"
            results[(method, np.dtype(pa).name)] = runs[0][:-1]
    # Every kind and precision: the same pairs and times.
    assert all(r == results[("dh", "float64")] for r in results.values())


def test_minimum_distance():
    # Small meshes: pairs passing within the distance take the exact path.
    va, fa = icosphere(0, 0.5)
    vb, fb = icosphere(0, 0.4)
    a0 = va.astype(np.float64)
    b0 = vb.astype(np.float64) + (1.2, 0.3, 0.0)
    b1 = b0 + (-0.5, 0.0, 0.1)
    near = brute_force_pair(fa, a0, a0, fb, b0, b1, min_distance=0.05)
    touch = brute_force_pair(fa, a0, a0, fb, b0, b1)
    assert sum(map(len, near)) > sum(map(len, touch))
    a = dhcd.Hierarchy(va, fa, method="sphere")
    b = dhcd.Hierarchy(vb, fb, method="sphere")
    check(dhcd.ccd(a, b, a0, a0, b0, b1, min_distance=0.05, threads=2), near, pair=True)
    check(dhcd.ccd(a, b, a0, a0, b0, b1, min_distance=0), touch, pair=True)
    early = dhcd.ccd(a, b, a0, a0, b0, b1, min_distance=0.05, earliest=True)
    check(early, earliest_of(near), pair=True)


def test_single_pairs_and_the_time_bound():
    # A vertex falling through a face at t = 0.5; an edge sweeping through another at 0.25.
    vf0 = [[[0.25, 0.25, 1.0], [0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]]
    vf1 = [[[0.25, 0.25, -1.0], [0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]]
    ee0 = [[[-1.0, 0.0, 1.0], [1.0, 0.0, 1.0], [0.0, -1.0, 0.0], [0.0, 1.0, 0.0]]]
    ee1 = [[[-1.0, 0.0, -3.0], [1.0, 0.0, -3.0], [0.0, -1.0, 0.0], [0.0, 1.0, 0.0]]]
    for f, x0, x1, t_star in [
        (dhcd.vertex_face_ccd, vf0, vf1, 0.5),
        (dhcd.edge_edge_ccd, ee0, ee1, 0.25),
    ]:
        hits, toi = f(x0, x1)  # lists of Python floats are float64
        assert hits.dtype == np.bool_ and hits.shape == (1,) and toi.dtype == np.float64
        assert hits[0] and t_star - 1e-12 <= toi[0] <= t_star
        hits, toi = f(x0, x1, t_max=t_star)
        assert hits[0] and toi[0] <= t_star
        hits, toi = f(x0, x1, t_max=0.9 * t_star)
        assert not hits[0] and toi[0] == math.inf
        # Within 0.1 of each other before they touch.
        hits, toi = f(np.array(x0), np.array(x1), min_distance=0.1, t_max=0.9 * t_star)
        assert hits[0] and toi[0] < t_star
        # Several at once, and none.
        hits, toi = f(np.array(x0 * 3), np.array(x1 * 3))
        assert hits.tolist() == [True] * 3 and len(set(toi.tolist())) == 1
        hits, toi = f(np.zeros((0, 4, 3)), np.zeros((0, 4, 3)))
        assert hits.shape == (0,) and toi.shape == (0,)


def rational(num, den):
    """num/den as a float64 (exact: every value of the sample set is one)."""
    x = int(num) / int(den)  # int / int is correctly rounded
    assert Fraction(x) == Fraction(int(num), int(den)), f"{num}/{den} is not a float64"
    return x


def load_queries(path):
    """The queries of one CSV file: x0 (N, 4, 3), x1 (N, 4, 3), labels (N,)."""
    with open(path) as f:
        rows = [line.strip().split(",") for line in f if line.strip()]
    assert len(rows) % 8 == 0, path
    x0, x1, labels = [], [], []
    for k in range(0, len(rows), 8):
        q = rows[k:k + 8]
        points = [[rational(r[0], r[1]), rational(r[2], r[3]), rational(r[4], r[5])] for r in q]
        assert len({r[6] for r in q}) == 1, (path, k)
        x0.append(points[:4])
        x1.append(points[4:])
        labels.append(q[0][6] == "1")
    return x0, x1, labels


@pytest.mark.parametrize("kind", ["vertex-face", "edge-edge"])
def test_sample_queries_match_their_labels(kind):
    f = dhcd.vertex_face_ccd if kind == "vertex-face" else dhcd.edge_edge_ccd
    total = positives = 0
    for folder in sorted(os.listdir(SAMPLES)):
        directory = os.path.join(SAMPLES, folder, kind)
        if not os.path.isdir(directory):
            continue
        for name in sorted(os.listdir(directory)):
            x0, x1, labels = load_queries(os.path.join(directory, name))
            hits, toi = f(np.array(x0), np.array(x1))
            wrong = [k for k, (h, y) in enumerate(zip(hits.tolist(), labels)) if h != y]
            assert not wrong, f"{folder}/{kind}/{name}: queries {wrong[:10]} disagree"
            assert np.all(np.isfinite(toi) == hits)
            assert np.all((toi[hits] >= 0.0) & (toi[hits] <= 1.0))
            total += len(labels)
            positives += sum(labels)
    assert total > 1000 and 0 < positives < total, (total, positives)


# -------------------------------------------------------------------------------------------
# Bad input
# -------------------------------------------------------------------------------------------


@pytest.fixture
def ball():
    v, f = icosphere(1)
    x = v.astype(np.float64)
    return dhcd.Hierarchy(v, f), dhcd.Hierarchy(v, f), x


@pytest.mark.parametrize(
    "bad, message",
    [
        (lambda x: x.astype(np.float32), "dtype float32; CCD positions must be float64"),
        (lambda x: x.astype(np.int64), "dtype int64"),
        (lambda x: x.astype(np.longdouble), "must be float64"),
        (lambda x: x.tolist() + [[0.0, 0.0]], "cannot convert"),
        (lambda x: x[:, :2], "(n, 3)"),
        (lambda x: x.ravel(), "(n, 3)"),
        (lambda x: x[:-1], "vertices"),
        (lambda x: np.where(np.arange(len(x))[:, None] == 7, np.nan, x), "non-finite"),
        (lambda x: np.where(np.arange(len(x))[:, None] == 3, -np.inf, x), "non-finite"),
        (lambda x: x * 1e300, "f32 range"),
    ],
)
def test_bad_positions(ball, bad, message):
    a, b, x = ball
    y = bad(x)
    for call in [
        lambda: dhcd.ccd(a, x, y),
        lambda: dhcd.ccd(a, y, x, earliest=True),
        lambda: dhcd.ccd(a, b, x, x, x, y),
        lambda: dhcd.ccd(a, b, y, x, x, x, threads=2),
    ]:
        with pytest.raises(ValueError) as e:
            call()
        assert message in str(e.value), str(e.value)


def test_positions_that_are_float64_values_are_taken(ball):
    a, _, x = ball
    still = dhcd.ccd(a, x, x)
    assert len(still) == 0 and still.toi == math.inf
    assert arrays(dhcd.ccd(a, x.tolist(), x[::-1][::-1])) == arrays(still)
    assert arrays(dhcd.ccd(a, x.astype(">f8"), np.asfortranarray(x))) == arrays(still)
    assert "Impacts(0 vertex-face" in repr(still)


@pytest.mark.parametrize(
    "options, message",
    [
        ({"t_max": 1.5}, "t_max"),
        ({"t_max": -1e-300}, "t_max"),
        ({"t_max": float("nan")}, "t_max"),
        ({"t_max": 10**400}, "t_max"),
        ({"min_distance": -1.0}, "min_distance"),
        ({"min_distance": float("inf")}, "min_distance"),
        ({"min_distance": float("nan")}, "min_distance"),
        ({"threads": -1}, "threads"),
        ({"threads": 2**20}, "threads"),
    ],
)
def test_bad_options(ball, options, message):
    a, b, x = ball
    calls = [lambda: dhcd.ccd(a, x, x, **options), lambda: dhcd.ccd(a, b, x, x, x, x, **options)]
    if "threads" not in options:
        q = np.zeros((2, 4, 3))
        calls += [
            lambda: dhcd.vertex_face_ccd(q, q, **options),
            lambda: dhcd.edge_edge_ccd(q, q, **options),
        ]
    for call in calls:
        with pytest.raises(ValueError, match=message):
            call()


def test_bad_arguments(ball):
    a, b, x = ball
    v, f = icosphere(1)
    box = dhcd.Hierarchy(v, f, method="aabb")
    with pytest.raises(ValueError, match="two different hierarchies"):
        dhcd.ccd(a, a, x, x, x, x)
    with pytest.raises(ValueError, match="dh.*aabb"):
        dhcd.ccd(a, box, x, x, x, x)
    for args in [(a, x), (a, x, x, x), (a, b, x, x, x), ()]:
        with pytest.raises(TypeError, match="positional arguments"):
            dhcd.ccd(*args)
    with pytest.raises(TypeError, match="Hierarchy"):
        dhcd.ccd((v, f), x, x)
    with pytest.raises(TypeError, match="Hierarchy"):
        dhcd.ccd(a, x, x, x, x, x)
    with pytest.raises(TypeError):
        dhcd.ccd(a, x, x, min_distance="0.1")
    with pytest.raises(TypeError):
        dhcd.ccd(a, x, x, 0.1)
    with pytest.raises(TypeError):
        dhcd.vertex_face_ccd(np.zeros((1, 4, 3)), np.zeros((1, 4, 3)), 0.1)
    # The hierarchies still work.
    assert len(dhcd.ccd(a, b, x, x, x, x)) > 0, "identical balls touch"


@pytest.mark.parametrize("f", [dhcd.vertex_face_ccd, dhcd.edge_edge_ccd])
def test_bad_single_pair_queries(f):
    q = np.zeros((3, 4, 3))
    for x0, x1, message in [
        (q.astype(np.float32), q, "x0 has dtype float32"),
        (q, q.astype(np.int32), "x1 has dtype int32"),
        (q[:, :3], q, r"\(n, 4, 3\)"),
        (q, q[0], r"\(n, 4, 3\)"),
        (q.reshape(3, 12), q, r"\(n, 4, 3\)"),
        (q, q[:2], "same number of queries"),
        (q, np.where(np.arange(3)[:, None, None] == 2, np.nan, q), "query 2: CCD point 4"),
        (np.where(np.arange(12).reshape(1, 4, 3) == 5, np.inf, q), q, "query 0: CCD point 1"),
    ]:
        with pytest.raises(ValueError, match=message):
            f(x0, x1)
