"""CollisionManager: trimesh's conventions (bool, or (bool, set of names)), exact answers,
deformation by update_vertices; compared with trimesh's own manager when it is installed."""

import numpy as np
import pytest

import dhcd
from meshes import brute_force_pairs, icosphere, wave

V, F = icosphere(2)


def posed(offset, t=0.0):
    return wave(V, t, 0.05, offset)


def test_internal_and_single():
    m = dhcd.CollisionManager()
    assert m.in_collision_internal() is False
    assert m.in_collision_internal(return_names=True) == (False, set())
    m.add_object("a", (posed((0.0, 0.0, 0.0)), F))
    m.add_object("b", (posed((1.5, 0.0, 0.0)), F))
    m.add_object("c", (posed((10.0, 0.0, 0.0)), F))
    assert m.in_collision_internal() is True
    assert m.in_collision_internal(return_names=True) == (True, {("a", "b")})
    probe = (posed((0.0, 1.5, 0.0)), F)
    assert m.in_collision_single(probe) is True
    assert m.in_collision_single(probe, return_names=True) == (True, {"a"})
    far = (posed((0.0, 40.0, 0.0)), F)
    assert m.in_collision_single(far, return_names=True) == (False, set())
    # A transform poses the probe: moved onto "c".
    t = np.eye(4)
    t[:3, 3] = (10.0, -40.0, 0.5)
    assert m.in_collision_single(far, transform=t, return_names=True) == (True, {"c"})


def test_deformation_and_replacement():
    m = dhcd.CollisionManager(method="aabb", threads=2)
    m.add_object("a", (V, F))
    m.add_object("b", (posed((5.0, 0.0, 0.0)), F))
    assert not m.in_collision_internal()
    # "b" deforms and moves into "a": exact, decided on triangles.
    for step in range(8):
        pb = posed((5.0 - 0.5 * step, 0.0, 0.0), 0.3 * step)
        m.update_vertices("b", pb)
        exact = len(brute_force_pairs(V, F, pb, F)) > 0
        assert m.in_collision_internal() is exact
    assert m.in_collision_internal()
    # Same name: replaced, as in trimesh.
    m.add_object("b", (posed((5.0, 0.0, 0.0)), F))
    assert not m.in_collision_internal()
    m.remove_object("b")
    assert m.in_collision_internal(return_names=True) == (False, set())


def test_bad_input():
    m = dhcd.CollisionManager()
    m.add_object("a", (V, F))
    with pytest.raises(ValueError, match="not in collision manager"):
        m.remove_object("zzz")
    with pytest.raises(ValueError, match="not in collision manager"):
        m.update_vertices("zzz", V)
    with pytest.raises(ValueError):
        m.update_vertices("a", V[:5])
    with pytest.raises(ValueError):
        m.update_vertices("a", np.full_like(V, np.nan))
    with pytest.raises(ValueError):
        m.add_object("b", (V, F[:, :2]))
    with pytest.raises(TypeError):
        m.add_object("b", "not a mesh")
    with pytest.raises(ValueError):
        m.in_collision_single((V, F), transform=np.eye(3))
    with pytest.raises(ValueError):
        m.in_collision_single((V[:0], F))
    with pytest.raises(ValueError):
        dhcd.CollisionManager(method="octree").add_object("x", (V, F))
    assert m.in_collision_internal(return_names=True) == (False, set()), "unchanged"


def test_same_answers_as_trimesh():
    trimesh = pytest.importorskip("trimesh")
    pytest.importorskip("fcl")
    pytest.importorskip("scipy")  # trimesh's manager asks scipy whether a mesh is convex
    ours = dhcd.CollisionManager()
    theirs = trimesh.collision.CollisionManager()
    rng = np.random.default_rng(3)
    for k in range(6):
        mesh = trimesh.Trimesh(posed(tuple(rng.uniform(-2.5, 2.5, 3))), F, process=False)
        ours.add_object(f"o{k}", mesh)
        theirs.add_object(f"o{k}", mesh)
    assert ours.in_collision_internal(return_names=True) == theirs.in_collision_internal(
        return_names=True
    )
    probe = trimesh.Trimesh(posed((0.0, 0.0, 0.0)), F, process=False)
    assert ours.in_collision_single(probe, return_names=True) == theirs.in_collision_single(
        probe, return_names=True
    )
