"""Scene: contacts of many objects equal the pairwise queries (and self-collision when on);
ids and names."""

import numpy as np
import pytest

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


def test_update_many_equals_separate_updates():
    v, f = icosphere(2)
    n = 5
    for method in dhcd._dhcd.METHODS:
        one_by_one = dhcd.Scene(method=method)
        batched = [(dhcd.Scene(method=method), t) for t in [None, 1, 2, 0]]
        for s in [one_by_one] + [s for s, _ in batched]:
            for k in range(n):
                s.add(v, f, name=f"ball{k}")
            s.set_self_collision(0, True)
        for step in range(4):
            poses = [wave(v, step + k, 0.3, (1.7 * k, 0.0, 0.0)) for k in range(n)]
            # Step 1 moves only some objects, the others by single updates.
            moved = [3, 1, 0] if step == 1 else list(range(n))
            for k in range(n):
                one_by_one.update(k, poses[k])
            expected = one_by_one.contacts()
            assert len(expected.pairs) > 0
            for s, threads in batched:
                if step == 0:  # a dict by id
                    updates = {k: poses[k] for k in moved}
                elif step == 1:  # a list of pairs, by id and by name, in any order
                    updates = [(k if k % 2 else f"ball{k}", poses[k]) for k in moved]
                elif step == 2:  # a generator of pairs, strided float32 views
                    updates = ((k, np.repeat(poses[k], 2, axis=0)[::2]) for k in moved)
                else:  # a dict by name, vertices as lists of float32 rows
                    updates = {f"ball{k}": list(poses[k]) for k in moved}
                s.update_many(updates, threads=threads)
                for k in set(range(n)) - set(moved):
                    s.update(k, poses[k])
                got = s.contacts()
                np.testing.assert_array_equal(got.pairs, expected.pairs)
                assert got.counters == expected.counters, (method, step, threads)
        # No updates: nothing changes.
        for s, threads in batched:
            before = s.contacts().pairs
            s.update_many({}, threads=threads)
            s.update_many([])
            np.testing.assert_array_equal(s.contacts().pairs, before)


def test_step_is_update_many_then_contacts():
    v, f = icosphere(2)
    n = 4
    for method in dhcd._dhcd.METHODS:
        reference = dhcd.Scene(method=method)
        stepped = [(dhcd.Scene(method=method), t) for t in [None, 1, 2]]
        for s in [reference] + [s for s, _ in stepped]:
            for k in range(n):
                s.add(v, f, name=f"ball{k}")
            s.set_self_collision(0, True)
        for step in range(3):
            poses = {k: wave(v, step + k, 0.3, (1.7 * k, 0.0, 0.0)) for k in range(n)}
            reference.update_many(poses)
            expected = reference.contacts()
            assert len(expected.pairs) > 0
            for s, threads in stepped:
                got = s.step(poses, threads=threads)
                np.testing.assert_array_equal(got.pairs, expected.pairs)
                assert got.counters == expected.counters, (method, step, threads)


def test_update_many_bad_entry_changes_nothing():
    v, f = icosphere(1)
    s = dhcd.Scene()
    a = s.add(v, f, name="a")
    b = s.add(v, f, name="b")
    before = s.contacts().pairs
    assert len(before) > 0
    far = v + np.float32(10.0)  # moving either object this far ends every contact
    nan = far.copy()
    nan[5, 1] = np.nan
    bad_entries = [
        (9, far),
        ("nobody", far),
        (-1, far),
        (2**64, far),
        (b, far[:-1]),
        (b, nan),
        (b, far[:, :2]),
        (b, "not an array"),
    ]
    for entry in bad_entries:
        # The same exception as `update` with that entry, and nothing moved (a string is no
        # array at all: the wrong Python type).
        error = TypeError if isinstance(entry[1], str) else ValueError
        with pytest.raises(error) as single:
            s.update(*entry)
        with pytest.raises(error) as many:
            s.update_many([(a, far), entry])
        assert str(many.value) == str(single.value)
        with pytest.raises(error):
            s.update_many([(a, far), entry], threads=2)
        with pytest.raises(error) as stepped:
            s.step([(a, far), entry])
        assert str(stepped.value) == str(single.value)
        np.testing.assert_array_equal(s.contacts().pairs, before)
    # An object given twice, also by id and by name.
    for updates in [[(a, far), (b, far), (a, far)], {b: far, "b": far}, [("a", far), (0, nan)]]:
        with pytest.raises(ValueError, match="more than once"):
            s.update_many(updates)
        np.testing.assert_array_equal(s.contacts().pairs, before)
    # Entries that are not (id, vertices) pairs; bad thread counts.
    with pytest.raises(TypeError):
        s.update_many([(a, far), a])
    with pytest.raises(TypeError):
        s.update_many(a)
    with pytest.raises(ValueError, match="pair"):
        s.update_many([(a, far, far)])
    with pytest.raises(ValueError, match="threads"):
        s.update_many({a: far}, threads=-1)
    np.testing.assert_array_equal(s.contacts().pairs, before)
    # A good update still works.
    s.update_many([(a, far)], threads=2)
    assert len(s.contacts().pairs) == 0


