"""``Scene.ccd``: a small ball tunnelling through a big one within the step (no discrete
contact at either end) is found, with rows and times equal to ``dhcd.ccd`` on the pair; a
far ball is culled; still objects stay at their stored pose; self-collision adds the object's
own pairs; ``earliest`` keeps the least time; 1 and 2 threads agree; bad input raises
``ValueError`` and changes nothing."""

import numpy as np
import pytest

import dhcd
from meshes import icosphere

METHODS = list(dhcd._dhcd.METHODS)


def setup(method):
    wall_v, wall_f = icosphere(2, 1.0)
    bullet_v, bullet_f = icosphere(1, 0.3, (-3.0, 0.0, 0.0))
    far_v, far_f = icosphere(1, 0.5, (50.0, 0.0, 0.0))
    scene = dhcd.Scene(method)
    wall = scene.add(wall_v, wall_f, name="wall")
    bullet = scene.add(bullet_v, bullet_f)
    far = scene.add(far_v, far_f)
    b0 = bullet_v.astype(np.float64)
    b1 = b0 + np.array([6.0, 0.0, 0.0])
    return scene, (wall, bullet, far), (wall_v, wall_f, bullet_v, bullet_f), (b0, b1)


def rows_with_ids(impacts, a, b):
    """A pair result's rows with the object ids in front of each side."""
    vf = [[a, v, b, t] for v, t in impacts.vertex_face.tolist()]
    fv = [[a, t, b, v] for t, v in impacts.face_vertex.tolist()]
    ee = [[a, a0, a1, b, b0, b1] for a0, a1, b0, b1 in impacts.edge_edge.tolist()]
    return vf, fv, ee


@pytest.mark.parametrize("method", METHODS)
def test_tunnelling_equals_the_pair_query(method):
    scene, (wall, bullet, far), (wv, wf, bv, bf), (b0, b1) = setup(method)
    assert len(scene.contacts().pairs) == 0
    for threads in (1, 2):
        r = scene.ccd({bullet: (b0, b1)}, threads=threads)
        w = wv.astype(np.float64)
        want = dhcd.ccd(
            dhcd.Hierarchy(wv, wf, method=method),
            dhcd.Hierarchy(bv, bf, method=method),
            w, w, b0, b1,
        )
        assert len(want) > 0
        vf, fv, ee = rows_with_ids(want, wall, bullet)
        assert r.vertex_face.tolist() == vf
        assert r.face_vertex.tolist() == fv
        assert r.edge_edge.tolist() == ee
        assert r.vf_toi.tolist() == want.vf_toi.tolist()
        assert r.ee_toi.tolist() == want.ee_toi.tolist()
        assert r.toi == want.toi
        assert 0.28 < r.toi < 0.30
        # The far ball is in no row.
        assert far not in r.vertex_face[:, [0, 2]]
        # Earliest: the same time, only the pairs reaching it.
        e = scene.ccd([(bullet, (b0, b1))], earliest=True, threads=threads)
        assert e.toi == r.toi
        assert len(e) >= 1
        assert set(e.vf_toi.tolist()) | set(e.ee_toi.tolist()) | set(e.fv_toi.tolist()) == {r.toi}
    # By name; a still bullet (listed with x0 == x1) and no motion at all touch nothing.
    assert scene.ccd({"wall": (w, w), bullet: (b0, b0)}).toi == float("inf")
    assert len(scene.ccd({})) == 0


def test_self_collision_adds_the_objects_own_pairs():
    scene, (wall, bullet, far), (wv, wf, bv, bf), (b0, b1) = setup("dh")
    # The bullet squashed flat through its own centre: its own faces cross.
    squashed = b0.copy()
    squashed[:, 0] = -3.0 - (b0[:, 0] + 3.0)
    off = scene.ccd({bullet: (b0, squashed)})
    scene.set_self_collision(bullet, True)
    on = scene.ccd({bullet: (b0, squashed)})
    own = dhcd.ccd(dhcd.Hierarchy(bv, bf), b0, squashed)
    assert len(off) == 0
    assert len(own) > 0
    vf = [[bullet, v, bullet, t] for v, t in own.vertex_face.tolist()]
    assert on.vertex_face.tolist() == vf
    assert on.toi == own.toi


def test_bad_motions_raise_and_change_nothing():
    scene, (wall, bullet, far), _, (b0, b1) = setup("aabb")
    before = scene.contacts().pairs.tolist()
    bad = [
        ({99: (b0, b1)}, {}),
        ([(bullet, (b0, b1)), (bullet, (b0, b1))], {}),
        ({bullet: (b0[:-1], b1)}, {}),
        ({bullet: (b0, np.where(np.arange(len(b1))[:, None] == 3, np.nan, b1))}, {}),
        ({bullet: (b0.astype(np.float32), b1)}, {}),
        ({bullet: (b0, b1)}, {"min_distance": -1.0}),
        ({bullet: (b0, b1)}, {"t_max": 2.0}),
        ({bullet: (b0, b1, b1)}, {}),
    ]
    for motions, kw in bad:
        with pytest.raises(ValueError):
            scene.ccd(motions, **kw)
    with pytest.raises(TypeError):
        scene.ccd([(bullet, 3)])
    assert scene.contacts().pairs.tolist() == before
    assert 0.28 < scene.ccd({bullet: (b0, b1)}).toi < 0.30
