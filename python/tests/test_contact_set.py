"""The contact set and contact geometry from Python: columns and their shapes, weights that
give the distances, derivatives against finite differences, typed errors, and (where the
IPC Toolkit is installed: CI installs it) the same set as ipctk's NormalCollisions.build and
the same derivatives as its per-type functions."""

import os

import numpy as np
import pytest

import dhcd
from meshes import folded_grid, grid


def folded(n=5):
    rest, pose, faces = folded_grid(n)
    return rest.astype(np.float64), pose.astype(np.float64), faces


def built(rest, pose, faces, method="dh"):
    h = dhcd.Hierarchy(rest, faces, method=method)
    h.update(pose)
    return h


def test_columns_shapes_and_types():
    rest, pose, faces = folded()
    h = built(rest, pose, faces)
    cs = dhcd.self_contact_set(h, 0.08)
    k = len(cs)
    assert k > 0
    assert cs.vertices.shape == (k, 4) and cs.vertices.dtype == np.int64
    assert cs.type.shape == (k,) and cs.type.dtype == np.uint8
    assert cs.distance_sq.shape == (k,) and cs.distance_sq.dtype == np.float64
    assert cs.weights.shape == (k, 4) and cs.weights.dtype == np.float64
    assert cs.mollified.shape == (k,) and cs.mollified.dtype == np.bool_
    assert cs.edges.shape == (k, 2) and cs.edges.dtype == np.int64
    assert set(np.unique(cs.type)) <= {0, 1, 2, 3}
    used = np.array([2, 3, 4, 4])[cs.type]
    for slot in range(4):
        assert np.all((cs.vertices[:, slot] >= 0) == (slot < used))
        assert np.all(cs.weights[used <= slot, slot] == 0.0)
    # Edge ids name the row's edges in Hierarchy.edges().
    edges = h.edges()
    assert edges.shape[1] == 2 and np.all(edges[:, 0] < edges[:, 1])
    pe = cs.type == 1
    assert np.all(edges[cs.edges[pe, 0]] == cs.vertices[pe, 1:3])
    assert np.all(cs.edges[pe, 1] == -1)
    ee = cs.type == 3
    assert np.all(edges[cs.edges[ee, 0]] == cs.vertices[ee, 0:2])
    assert np.all(edges[cs.edges[ee, 1]] == cs.vertices[ee, 2:4])
    assert np.all(cs.edges[~(pe | ee)] == -1)
    # Only edge-edge rows are mollified; one row per contact.
    assert not np.any(cs.mollified[~ee])
    assert len({(t, *v) for t, v in zip(cs.type, map(tuple, cs.vertices))}) == k
    assert "ContactSet(" in repr(cs)
    # The same set for every method and thread count.
    for method in ("sphere", "aabb"):
        other = dhcd.self_contact_set(built(rest, pose, faces, method), 0.08, threads=2)
        assert np.array_equal(other.vertices, cs.vertices)
        assert np.array_equal(other.mollified, cs.mollified)
        assert np.array_equal(other.distance_sq, cs.distance_sq)


def test_weights_give_the_distances_and_derivatives_match_finite_differences():
    rest, pose, faces = folded()
    h = built(rest, pose, faces)
    cs = dhcd.self_contact_set(h, 0.08)
    x = pose[np.maximum(cs.vertices, 0)] * (cs.vertices >= 0)[:, :, None]
    v = np.einsum("ki,kic->kc", cs.weights, x)
    d = np.einsum("kc,kc->k", v, v)
    assert np.allclose(d, cs.distance_sq, rtol=1e-9, atol=1e-15)
    g = cs.gradient()
    hess = cs.hessian()
    assert g.shape == (len(cs), 12) and hess.shape == (len(cs), 12, 12)
    assert np.allclose(hess, np.transpose(hess, (0, 2, 1)))
    # The free functions on rows that are not mollified give the same values.
    plain = ~cs.mollified
    types = cs.type[plain]
    xs = np.ascontiguousarray(x[plain])
    assert np.allclose(dhcd.distance_sq(types, xs), cs.distance_sq[plain], rtol=1e-9, atol=1e-15)
    assert np.array_equal(dhcd.distance_gradient(types, xs), g[plain])
    assert np.array_equal(dhcd.distance_hessian(types, xs), hess[plain])
    # Central differences on a sample of rows.
    eps = 1e-6
    rows = np.flatnonzero(plain)[:: max(1, plain.sum() // 40)]
    for k in rows:
        t = cs.type[k : k + 1]
        for j in range(3 * [2, 3, 4, 4][t[0]]):
            xp, xm = x[k : k + 1].copy(), x[k : k + 1].copy()
            xp[0, j // 3, j % 3] += eps
            xm[0, j // 3, j % 3] -= eps
            fd = (dhcd.distance_sq(t, xp) - dhcd.distance_sq(t, xm))[0] / (2 * eps)
            assert abs(fd - g[k, j]) < 1e-6, (k, j)
            gd = (dhcd.distance_gradient(t, xp) - dhcd.distance_gradient(t, xm))[0] / (2 * eps)
            assert np.allclose(gd, hess[k, :, j], atol=1e-5), (k, j)


def test_pair_numbering_and_bad_input():
    va, fa = grid(4, 4, 0.25)
    vb, fb = grid(3, 3, 0.3)
    vb = vb.astype(np.float64) + np.array([0.05, 0.05, 0.02])
    a = dhcd.Hierarchy(va.astype(np.float64), fa)
    b = dhcd.Hierarchy(vb, fb)
    cs = dhcd.contact_set(a, b, 0.05)
    assert len(cs) > 0
    na = a.vertex_count
    # Every contact joins a feature of a and one of b.
    for t, v in zip(cs.type, cs.vertices):
        used = v[: [2, 3, 4, 4][t]]
        sides = used >= na
        assert sides.any() and not sides.all()
    with pytest.raises(ValueError):
        dhcd.contact_set(a, a, 0.05)
    for bad in (-1.0, float("nan"), float("inf")):
        with pytest.raises(ValueError):
            dhcd.self_contact_set(a, bad)
    with pytest.raises(ValueError):
        dhcd.self_contact_set(a, 0.1, rest=np.zeros((3, 3)))
    with pytest.raises(ValueError):
        dhcd.self_contact_set(a, 0.1, rest=np.zeros((na, 2)))
    with pytest.raises(TypeError):
        dhcd.self_contact_set(a, 0.1, rest="no")
    x = np.zeros((2, 4, 3))
    with pytest.raises(ValueError):
        dhcd.distance_sq([0, 4], x)
    with pytest.raises(ValueError):
        dhcd.distance_sq([-1, 0], x)
    with pytest.raises(ValueError):
        dhcd.distance_gradient([0], x)
    with pytest.raises(ValueError):
        dhcd.distance_hessian([0, 1], np.zeros((2, 3, 3)))


def ipctk_or_skip():
    try:
        import ipctk
    except ImportError:
        if os.environ.get("DHCD_REQUIRE_IPCTK") == "1":
            raise
        pytest.skip("ipctk is not installed (CI installs it; pip install ipctk==1.6.1)")
    return ipctk


def as_dict(cs):
    """A contact set as (type, vertices) -> (mollified, edge ids), the form of ipctk_set."""
    return {
        (int(t), *map(int, v)): (bool(m), int(e[0]), int(e[1]))
        for t, v, m, e in zip(cs.type, cs.vertices, cs.mollified, cs.edges)
    }


def ipctk_row(ipctk, c, i, mesh, pose):
    """Collision `i` of ipctk's NormalCollisions `c` as ((type, vertices), (mollified, edge
    ids)). Its own frame: `c[i]` refers into `c`'s storage, so it must be released while `c`
    is alive (a local of the caller's frame could outlive `c` when the frame is cleared)."""
    col = c[i]
    ids = [int(v) for v in col.vertex_ids(mesh.edges, mesh.faces)]
    if c.is_vertex_vertex(i):
        return (0, min(ids[:2]), max(ids[:2]), -1, -1), (False, -1, -1)
    if c.is_edge_vertex(i):
        return (1, *ids[:3], -1), (False, col.edge_id, -1)
    if c.is_edge_edge(i):
        e0, e1 = col.edge0_id, col.edge1_id
        if e0 > e1:
            e0, e1, ids = e1, e0, ids[2:] + ids[:2]
        moll = bool(ipctk.edge_edge_cross_squarednorm(*pose[ids]) < col.eps_x)
        return (3, *ids), (moll, e0, e1)
    return (2, *ids), (False, -1, -1)


def ipctk_set(ipctk, rest, pose, faces, edges, dhat):
    """ipctk's NormalCollisions as (type, vertices) -> (mollified, edge ids)."""
    mesh = ipctk.CollisionMesh(rest, edges.astype(np.int32), faces.astype(np.int32))
    c = ipctk.NormalCollisions()
    c.build(mesh, pose, dhat)
    return dict(ipctk_row(ipctk, c, i, mesh, pose) for i in range(len(c)))


def test_equals_ipctk_on_a_folded_sheet():
    ipctk = ipctk_or_skip()
    rest, pose, faces = folded(6)
    h = built(rest, pose, faces)
    edges = h.edges()
    for dhat in (0.03, 0.08, 0.15):
        cs = dhcd.self_contact_set(h, dhat)
        ours = as_dict(cs)
        theirs = ipctk_set(ipctk, rest, pose, faces, edges, dhat)
        # ipctk decides types and activity in floating point (strict < dhat); dhcd exactly
        # (<= dhat). On this sheet no pair is within rounding of a boundary.
        assert ours == theirs, (
            sorted(set(ours.items()) - set(theirs.items()))[:5],
            sorted(set(theirs.items()) - set(ours.items()))[:5],
        )


REAL_FRAMES = os.path.join(os.path.dirname(__file__), "../../../shared/data/real-frames")


def test_equals_ipctk_on_the_real_frames():
    """Every real frame, dhat = 1e-3 x the bounding-box diagonal, the frame as its own rest
    pose: the same contacts, types, mollified flags and edge ids as NormalCollisions.build
    (benches/scripts/contact-set-vs-ipctk.py times the same comparison)."""
    ipctk = ipctk_or_skip()
    if not os.path.isdir(REAL_FRAMES):
        pytest.skip(f"no real frames at {REAL_FRAMES} (they come with ../shared)")
    paths = sorted(p for p in os.listdir(REAL_FRAMES) if p.endswith(".ply"))
    assert paths
    for name in paths:
        pose, faces = dhcd.load_mesh(os.path.join(REAL_FRAMES, name), precision="f64")
        dhat = 1e-3 * float(np.linalg.norm(pose.max(0) - pose.min(0)))
        h = dhcd.Hierarchy(pose, faces)
        cs = dhcd.self_contact_set(h, dhat, threads=2)
        ours = as_dict(cs)
        theirs = ipctk_set(ipctk, pose, pose, faces, h.edges(), dhat)
        # No pair of these frames is within rounding of dhat or of a type boundary.
        assert ours == theirs, (
            name,
            sorted(set(ours.items()) - set(theirs.items()))[:5],
            sorted(set(theirs.items()) - set(ours.items()))[:5],
        )


def test_derivatives_equal_ipctk_per_type_functions():
    ipctk = ipctk_or_skip()
    rng = np.random.default_rng(3)
    x = rng.normal(size=(20, 4, 3))
    fns = [
        (0, lambda p: ipctk.point_point_distance_gradient(p[0], p[1]),
         lambda p: ipctk.point_point_distance_hessian(p[0], p[1])),
        (1, lambda p: ipctk.point_line_distance_gradient(p[0], p[1], p[2]),
         lambda p: ipctk.point_line_distance_hessian(p[0], p[1], p[2])),
        (2, lambda p: ipctk.point_plane_distance_gradient(p[0], p[1], p[2], p[3]),
         lambda p: ipctk.point_plane_distance_hessian(p[0], p[1], p[2], p[3])),
        (3, lambda p: ipctk.line_line_distance_gradient(p[0], p[1], p[2], p[3]),
         lambda p: ipctk.line_line_distance_hessian(p[0], p[1], p[2], p[3])),
    ]
    for t, grad, hess in fns:
        n = 3 * [2, 3, 4, 4][t]
        types = np.full(len(x), t)
        g = dhcd.distance_gradient(types, x)
        h = dhcd.distance_hessian(types, x)
        for k in range(len(x)):
            want_g = np.asarray(grad(x[k]))
            want_h = np.asarray(hess(x[k]))
            assert np.allclose(g[k, :n], want_g, rtol=1e-9, atol=1e-12), (t, k)
            assert np.allclose(h[k, :n, :n], want_h, rtol=1e-8, atol=1e-10), (t, k)


def test_scene_contact_set_is_the_pair_set_in_global_numbering():
    va, fa = grid(4, 4, 0.25)
    vb, fb = grid(3, 3, 0.3)
    va = va.astype(np.float64)
    vb = vb.astype(np.float64) + np.array([0.05, 0.05, 0.02])
    scene = dhcd.Scene()
    ia = scene.add(va, fa, name="a")
    ib = scene.add(vb, fb)
    got = scene.contact_set(0.05, threads=2)
    want = dhcd.contact_set(dhcd.Hierarchy(va, fa), dhcd.Hierarchy(vb, fb), 0.05)
    assert len(got) == len(want) > 0
    for col in ("vertices", "type", "distance_sq", "weights", "mollified", "edges"):
        assert np.array_equal(getattr(got, col), getattr(want, col)), col
    assert scene.vertex_offset("a") == 0
    assert scene.vertex_offset(ib) == len(va)
    assert scene.edge_offset(ib) == len(dhcd.Hierarchy(va, fa).edges())
    with pytest.raises(ValueError):
        scene.vertex_offset(99)
    with pytest.raises(ValueError):
        scene.contact_set(-1.0)
    assert ia == 0
