"""Scene: contacts of many objects equal the pairwise queries (and self-collision when on);
ids and names."""

import numpy as np

import dhcd
from meshes import brute_force_pairs, brute_force_self_pairs, folded_grid, icosphere, wave


def test_scene_equals_pairwise_brute_force():
    v, f = icosphere(2)
    poses = [wave(v, 0.3 * k, 0.05, (1.5 * k, 0.1 * k, 0.0)) for k in range(4)]
    poses.append(wave(v, 0.0, 0.0, (50.0, 0.0, 0.0)))  # far away: culled
    for method in dhcd._dhcd.METHODS:
        s = dhcd.Scene(method=method)
        ids = [s.add(v, f, name=f"ball{k}") for k in range(len(poses))]
        assert ids == list(range(len(poses))) and len(s) == len(poses)
        for k, p in enumerate(poses):
            s.update(ids[k] if k % 2 else f"ball{k}", p)
        c = s.contacts()
        expected = []
        for i in range(len(poses)):
            for j in range(i + 1, len(poses)):
                for fa, fb in brute_force_pairs(poses[i], f, poses[j], f):
                    expected.append((i, fa, j, fb))
        expected = np.array(sorted(expected), dtype=np.int64).reshape(-1, 4)
        assert len(expected) > 0
        assert c.pairs.dtype == np.int64 and c.pairs.shape[1] == 4
        np.testing.assert_array_equal(c.pairs, expected)
        assert c.counters["contacts"] == len(expected)
        assert s.contacts(threads=2).pairs.tolist() == c.pairs.tolist()


def test_scene_self_collision_and_removal():
    rest, folded, faces = folded_grid(5)
    s = dhcd.Scene(levels=4)
    sheet = s.add(rest, faces, name="sheet")
    s.update("sheet", folded)
    assert len(s.contacts().pairs) == 0, "self-collision is off by default"
    s.set_self_collision(sheet, True)
    c = s.contacts()
    expected = brute_force_self_pairs(folded, faces)
    assert len(expected) > 0
    np.testing.assert_array_equal(c.pairs[:, [1, 3]], expected)
    assert np.all(c.pairs[:, 0] == sheet) and np.all(c.pairs[:, 2] == sheet)
    s.set_self_collision("sheet", False)
    assert len(s.contacts().pairs) == 0
    s.remove(sheet)
    assert len(s) == 0 and len(s.contacts().pairs) == 0
