"""The collision-free step size from Python: a planted answer, never past the earliest
impact, the pair form, typed errors."""

import numpy as np
import pytest

import dhcd
from meshes import folded_grid


def falling_vertex():
    x0 = np.array(
        [[0, 0, 0], [1, 0, 0], [0, 1, 0], [0.25, 0.25, 1.0], [5, 5, 5], [6, 5, 5]],
        dtype=np.float64,
    )
    x1 = x0.copy()
    x1[3, 2] = -1.0
    faces = np.array([[0, 1, 2], [3, 4, 5]])
    return x0, x1, faces


def test_a_falling_vertex_stops_at_its_gap():
    x0, x1, faces = falling_vertex()
    h = dhcd.Hierarchy(x0, faces)
    # d0 = 1, gap 0.2: z = 0.2 at t = 0.4 (within 1e-12 below).
    assert 0.4 - 2e-12 <= dhcd.collision_free_stepsize(h, x0, x1) <= 0.4
    s = dhcd.collision_free_stepsize(h, x0, x1, min_distance=0.1, rescaling=0.8)
    assert 0.36 - 2e-12 <= s <= 0.36
    assert dhcd.collision_free_stepsize(h, x0, x0) == 1.0
    assert 0.5 - 2e-12 <= dhcd.collision_free_stepsize(h, x0, x1, rescaling=1.0) <= 0.5


def test_never_past_the_earliest_impact_on_a_folding_sheet():
    rest, a, faces = folded_grid(5, 0.0)
    _, b, _ = folded_grid(5, 2.0)
    x0 = a.astype(np.float64)
    x1 = x0 + 1.5 * (b.astype(np.float64) - x0)
    h = dhcd.Hierarchy(rest.astype(np.float64), faces)
    toi = dhcd.ccd(h, x0, x1, earliest=True).toi
    for method in ("dh", "sphere", "aabb"):
        hm = dhcd.Hierarchy(rest.astype(np.float64), faces, method=method)
        s = dhcd.collision_free_stepsize(hm, x0, x1, threads=2)
        assert 0.0 <= s <= 1.0
        assert s <= toi + 1e-12
        assert s == dhcd.collision_free_stepsize(h, x0, x1)


def test_pair_form_and_bad_input():
    x0, x1, faces = falling_vertex()
    a = dhcd.Hierarchy(x0[:3], faces[:1])
    b = dhcd.Hierarchy(x0[3:], faces[1:] - 3)
    s = dhcd.collision_free_stepsize(a, b, x0[:3], x1[:3], x0[3:], x1[3:])
    assert 0.4 - 2e-12 <= s <= 0.4
    h = dhcd.Hierarchy(x0, faces)
    for r in (0.0, 1.5, float("nan")):
        with pytest.raises(ValueError):
            dhcd.collision_free_stepsize(h, x0, x1, rescaling=r)
    with pytest.raises(ValueError):
        dhcd.collision_free_stepsize(h, x0, x1, min_distance=-1.0)
    with pytest.raises(ValueError):
        dhcd.collision_free_stepsize(h, x0, x1[:3])
    with pytest.raises(TypeError):
        dhcd.collision_free_stepsize(h, x0)
    with pytest.raises(ValueError):
        dhcd.collision_free_stepsize(a, a, x0[:3], x1[:3], x0[:3], x1[:3])


def test_scene_form_equals_the_pair_form():
    x0, x1, faces = falling_vertex()
    a = dhcd.Hierarchy(x0[:3], faces[:1])
    b = dhcd.Hierarchy(x0[3:], faces[1:] - 3)
    want = dhcd.collision_free_stepsize(a, b, x0[:3], x1[:3], x0[3:], x1[3:], rescaling=0.5)
    for method in ("dh", "sphere", "aabb"):
        scene = dhcd.Scene(method)
        tri = scene.add(x0[:3], faces[:1], name="triangle")
        falling = scene.add(x0[3:], faces[1:] - 3)
        motions = {falling: (x0[3:], x1[3:])}
        for threads in (1, 2):
            s = scene.collision_free_stepsize(motions, rescaling=0.5, threads=threads)
            assert s == want
        # d0 = 1, gap 0.5: z = 0.5 at t = 0.25.
        assert 0.25 - 2e-12 <= want <= 0.25
        # Nothing moves: 1.
        assert scene.collision_free_stepsize({}) == 1.0
        # The triangle rises to meet the vertex: both move, ids by name.
        up = x0[:3].copy()
        up[:, 2] += 1.0
        both = [("triangle", (x0[:3], up)), (falling, (x0[3:], x1[3:]))]
        s = scene.collision_free_stepsize(both)
        assert 0.0 < s < 0.4
        assert s <= scene.ccd(both, earliest=True).toi + 1e-12
        for bad in (dict(rescaling=0.0), dict(rescaling=2.0), dict(min_distance=-1.0)):
            with pytest.raises(ValueError):
                scene.collision_free_stepsize(motions, **bad)
        with pytest.raises(ValueError):
            scene.collision_free_stepsize({tri + 7: (x0[:3], x1[:3])})
        with pytest.raises(ValueError):
            scene.collision_free_stepsize({falling: (x0[3:], x1[:2])})
