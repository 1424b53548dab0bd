"""Every kind of bad input raises ValueError (OSError for unreadable files) with the
library's message, never crashes, and leaves the object unchanged."""

import os

import numpy as np
import pytest

import dhcd
from meshes import icosphere

V, F = icosphere(1)


@pytest.mark.parametrize(
    "vertices, message",
    [
        (np.zeros((5, 2), np.float32), "(n, 3)"),
        (np.zeros((5, 3, 1), np.float32), "(n, 3)"),
        (np.zeros(9, np.float32), "(n, 3)"),
        (5.0, "(n, 3)"),
        ([[0, 0, 0], [1, 0]], "cannot convert"),
        (np.array([["a", "b", "c"]] * 42), "dtype"),
        (np.zeros((42, 3), dtype=np.complex64), "dtype"),
        (np.zeros((42, 3), dtype=bool), "dtype"),
        (np.array([[object()] * 3] * 42), "dtype"),
        (np.where(np.arange(42)[:, None] == 7, np.nan, V), "non-finite"),
        (np.where(np.arange(42)[:, None] == 3, np.inf, V), "non-finite"),
        # float64 builds an f64 hierarchy, whose bounds are float32: beyond their range.
        (V.astype(np.float64) * 1e300, "beyond the f32 range"),
        (np.where(np.arange(42)[:, None] == 7, np.nan, V.astype(np.float64)), "non-finite"),
        (np.zeros((0, 3), np.float32), "no vertices"),
    ],
)
def test_bad_vertices(vertices, message):
    assert len(V) == 42
    with pytest.raises(ValueError) as e:
        dhcd.Hierarchy(vertices, F)
    assert message in str(e.value), str(e.value)


@pytest.mark.parametrize(
    "faces, message",
    [
        (F[:, :2], "(n, 3)"),
        (F.ravel(), "(n, 3)"),
        (F.astype(np.float64), "integer"),
        (np.where(F == 5, 42, F), "uses vertex 42"),
        (np.where(F == 5, -1, F), "-1"),
        (np.where(F == 5, 2**32, F), "4294967296"),
        (np.where(F == 5, 2**64 - 1, F.astype(np.uint64)), "out of range"),
        (np.array([[0, 1, 1]]), "repeats vertex 1"),
        (np.zeros((0, 3), np.int64), "no triangles"),
        ([[0, 1]], "(n, 3)"),
        (np.array([["0", "1", "2"]]), "integer"),
    ],
)
def test_bad_faces(faces, message):
    with pytest.raises(ValueError) as e:
        dhcd.Hierarchy(V, faces)
    assert message in str(e.value), str(e.value)


@pytest.mark.parametrize("method", ["octree", "", "d h", 3])
def test_unknown_method(method):
    error = TypeError if not isinstance(method, str) else ValueError
    with pytest.raises(error):
        dhcd.Hierarchy(V, F, method=method)
    with pytest.raises(error):
        dhcd.Scene(method=method)


@pytest.mark.parametrize("levels", [0, -1, 17, 10**30])
def test_bad_levels(levels):
    with pytest.raises(ValueError, match="levels"):
        dhcd.Hierarchy(V, F, levels=levels)
    with pytest.raises(ValueError, match="levels"):
        dhcd.Scene(levels=levels)


@pytest.mark.parametrize("threads", [-1, 1025, 2**40, 2**70])
def test_bad_threads(threads):
    a = dhcd.Hierarchy(V, F)
    b = dhcd.Hierarchy(V, F)
    with pytest.raises(ValueError, match="threads"):
        dhcd.collide(a, b, threads=threads)
    with pytest.raises(ValueError, match="threads"):
        a.self_collide(threads=threads)
    with pytest.raises(ValueError, match="threads"):
        dhcd.Scene().contacts(threads=threads)
    with pytest.raises(ValueError, match="threads"):
        dhcd.Scene().update_many({}, threads=threads)


def test_bad_update_changes_nothing():
    a = dhcd.Hierarchy(V, F)
    b = dhcd.Hierarchy(V + np.float32(0.5), F)
    before = dhcd.collide(a, b).pairs
    bad = [
        V[:-1],
        np.concatenate([V, V[:1]]),
        np.where(np.arange(42)[:, None] == 0, np.nan, V),
        V[:, :2],
        "not an array",
    ]
    for vertices in bad:
        # A string is no array at all: the wrong Python type.
        error = TypeError if isinstance(vertices, str) else ValueError
        with pytest.raises(error):
            b.update(vertices)
    np.testing.assert_array_equal(dhcd.collide(a, b).pairs, before)


def test_mismatched_and_repeated_hierarchies():
    a = dhcd.Hierarchy(V, F, method="dh")
    box = dhcd.Hierarchy(V, F, method="aabb")
    with pytest.raises(ValueError, match="dh.*aabb"):
        dhcd.collide(a, box)
    with pytest.raises(ValueError, match="self_collide"):
        dhcd.collide(a, a)
    with pytest.raises(TypeError):
        dhcd.collide(a, (V, F))
    with pytest.raises(ValueError, match="dh.*aabb"):
        dhcd.contact_segments(a, box, [[0, 0]])


def test_bad_contact_pairs():
    a = dhcd.Hierarchy(V, F)
    b = dhcd.Hierarchy(V + np.float32(0.3), F)
    pairs = dhcd.collide(a, b).pairs
    assert len(pairs) > 0
    for bad, message in [
        ([[0, len(F)]], "triangle 80"),
        ([[-1, 0]], "-1"),
        ([[0, 2**40]], "out of range"),
        (np.array([[0, 2**63]], dtype=np.uint64), "above"),
        ([[0.5, 1]], "integers"),
        ([0, 1], "(K, 2)"),
        (np.zeros((3, 3), np.int64), "(K, 2)"),
    ]:
        with pytest.raises(ValueError) as e:
            dhcd.contact_segments(a, b, bad)
        assert message in str(e.value), (bad, str(e.value))
    # Contacts of an earlier pose are stale.
    b.update(V + np.float32(10.0))
    with pytest.raises(ValueError, match="do not intersect"):
        dhcd.contact_segments(a, b, pairs)


def test_files(tmp_path):
    with pytest.raises(FileNotFoundError) as e:
        dhcd.load_mesh(tmp_path / "missing.obj")
    assert e.value.filename.endswith("missing.obj")
    with pytest.raises(OSError):
        dhcd.load_mesh(tmp_path)  # a directory
    # Files that never end, and the size limit (issue 9).
    for endless in ["/dev/zero", "/dev/urandom"]:
        if os.path.exists(endless):
            with pytest.raises(OSError, match="not a regular file"):
                dhcd.load_mesh(endless)
    small = tmp_path / "small.obj"
    small.write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n")
    with pytest.raises(OSError, match="limit of 10 bytes"):
        dhcd.load_mesh(small, max_file_bytes=10)
    assert dhcd.load_mesh(small, max_file_bytes=1000)[1].tolist() == [[0, 1, 2]]
    for bad in [-1, 2**70]:
        with pytest.raises(ValueError, match="max_file_bytes"):
            dhcd.load_mesh(small, max_file_bytes=bad)
    for name, text in [
        ("bad.obj", "v 0 0 0\nv 1 0 0\nf 1 2 9\n"),
        ("garbage.obj", "v 0 0 zero\n"),
        ("empty.obj", ""),
        ("bad.ply", "ply\nformat ascii 1.0\nelement vertex 3\nend_header\n"),
        ("short.stl", "solid x\nfacet normal 0 0 1\n"),
        ("mystery.xyz", "hello"),
    ]:
        path = tmp_path / name
        path.write_text(text)
        with pytest.raises(ValueError) as e:
            dhcd.load_mesh(path)
        assert name in str(e.value), str(e.value)


def test_scene_bad_ids_and_names():
    s = dhcd.Scene()
    i = s.add(V, F, name="ball")
    with pytest.raises(ValueError, match="already named"):
        s.add(V, F, name="ball")
    assert len(s) == 1, "a rejected add adds nothing"
    with pytest.raises(ValueError):
        s.add(V, F[:, :2])
    for bad in [i + 1, -1, 2**63 - 1, 2**64, "nobody"]:
        with pytest.raises(ValueError):
            s.update(bad, V)
        with pytest.raises(ValueError):
            s.update_many({bad: V})
        with pytest.raises(ValueError):
            s.remove(bad)
        with pytest.raises(ValueError):
            s.set_self_collision(bad, True)
    with pytest.raises(TypeError):
        s.remove(1.5)
    with pytest.raises(ValueError):
        s.update("ball", V[:3])
    with pytest.raises(ValueError):
        s.update_many([("ball", V[:3])])
    with pytest.raises(ValueError, match="more than once"):
        s.update_many([("ball", V), (i, V)])
    s.remove("ball")
    with pytest.raises(ValueError):
        s.update(i, V)
    assert s.add(V, F, name="ball") == i + 1, "ids are never reused; names are"
