"""Correct on every input, from Python: free points (vertices in no face) are points to
proximity and CCD; earliest mode returns every tie; a result over the module's limit raises
``ValueError`` naming the count and the limit; Ctrl-C (SIGINT) stops a long query with
``KeyboardInterrupt`` within a second, on one thread and on several, and in a batch of
single-pair queries; ``load_mesh`` reads float64 at full precision; the wrong Python type
is a ``TypeError``."""

import os
import signal
import threading
import time

import numpy as np
import pytest

import dhcd
from meshes import grid

METHODS = list(dhcd._dhcd.METHODS)


def triangle_and_point(z):
    v = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0.25, 0.25, z]], dtype=np.float64)
    return v, np.array([[0, 1, 2]], dtype=np.int64)


@pytest.mark.parametrize("method", METHODS)
def test_a_free_vertex_is_a_point(method):
    v, f = triangle_and_point(0.5)
    h = dhcd.Hierarchy(v, f, method=method)
    p = dhcd.self_proximity(h, 1.0)
    assert p.vertex_face.tolist() == [[3, 0]]
    assert p.vf_distance_sq.tolist() == [0.25]
    x1 = v.copy()
    x1[3, 2] = -0.5
    for earliest in (False, True):
        c = dhcd.ccd(h, v, x1, earliest=earliest)
        assert c.vertex_face.tolist() == [[3, 0]]
        assert 0.5 - 1e-12 <= c.toi <= 0.5
    scene = dhcd.Scene(method)
    a = scene.add(v + [0, 0, 0.0], f)
    b = scene.add(np.array([[5, 5, 5], [6, 5, 5], [5, 6, 5], [0.25, 0.25, 0.3]]), f)
    p = scene.proximity(0.31)
    assert [b, 3, a, 0] in p.vertex_face.tolist() or [a, 0, b, 3] in p.face_vertex.tolist()


def test_earliest_mode_returns_every_tie():
    # Two layers 1/8 apart closing at equal speed: every colliding pair first touches at
    # exactly t = 1/2, found by different paths (vertices on vertices and edges: exact;
    # inside faces: the float filter).
    v, f = grid(8, 8)
    v = v.astype(np.float64)
    upper = v + [1 / 64, 1 / 64, 0.125]
    verts = np.vstack([v, upper])
    faces = np.vstack([f, f + len(v)])
    x1 = verts.copy()
    x1[len(v):, 2] = -0.125
    h = dhcd.Hierarchy(verts, faces)
    every = dhcd.ccd(h, verts, x1)
    first = dhcd.ccd(h, verts, x1, earliest=True)
    assert len(first.vertex_face) + len(first.edge_edge) > 100
    keep = every.vf_toi <= first.toi + 1e-12
    assert first.vertex_face.tolist() == every.vertex_face[keep].tolist()
    keep = every.ee_toi <= first.toi + 1e-12
    assert first.edge_edge.tolist() == every.edge_edge[keep].tolist()


def test_results_over_the_limit_raise_and_the_limit_can_be_lifted():
    v, f = grid(12, 12)
    h = dhcd.Hierarchy(v, f)
    assert dhcd.max_pairs() == 2**25
    try:
        dhcd.set_max_pairs(1000)
        with pytest.raises(ValueError, match="over the limit of 1000"):
            dhcd.self_proximity(h, 10.0)
        with pytest.raises(ValueError, match="over the limit of 1000"):
            dhcd.self_proximity(h, 10.0, threads=2)
        dhcd.set_max_pairs(None)
        assert dhcd.max_pairs() is None
        assert len(dhcd.self_proximity(h, 10.0).vertex_face) > 1000
        with pytest.raises(ValueError, match="negative"):
            dhcd.set_max_pairs(-1)
    finally:
        dhcd.set_max_pairs(2**25)


def interrupt_after(seconds):
    """Sends SIGINT to this process after `seconds`, from another thread. Python's own
    handler is installed first: a process started in the background by a non-interactive
    shell inherits SIGINT ignored, and Python then installs none (no KeyboardInterrupt)."""
    signal.signal(signal.SIGINT, signal.default_int_handler)

    def send():
        time.sleep(seconds)
        os.kill(os.getpid(), signal.SIGINT)

    t = threading.Thread(target=send)
    t.start()
    return t


@pytest.mark.skipif(threading.current_thread() is not threading.main_thread(),
                    reason="signals reach the main thread only")
@pytest.mark.parametrize("threads", [1, 2])
def test_ctrl_c_stops_a_long_query(threads):
    # Every pair of a 48 x 48 sheet within a distance covering it: tens of millions of
    # pairs, many seconds.
    v, f = grid(48, 48)
    h = dhcd.Hierarchy(v, f)
    dhcd.set_max_pairs(None)
    try:
        sender = interrupt_after(0.3)
        start = time.monotonic()
        with pytest.raises(KeyboardInterrupt):
            dhcd.self_proximity(h, 100.0, threads=threads)
        assert time.monotonic() - start < 0.3 + 1.0
        sender.join()
    finally:
        dhcd.set_max_pairs(2**25)
    # The hierarchy still works.
    assert len(dhcd.self_proximity(h, 0.0).vertex_face) == 0


@pytest.mark.skipif(threading.current_thread() is not threading.main_thread(),
                    reason="signals reach the main thread only")
def test_ctrl_c_stops_a_long_single_pair_query():
    # A pair whose coordinates span 5e-324 to 3e38, with a minimum distance of 5e-324: only
    # the exact path decides it, over seconds.
    x0 = np.array([[[1e-300, 3e38, 1.0], [-1.0, -5e-324, -1e-300],
                    [-0.0, -3e38, -3e38], [5e-324, -0.0, 1.0]]] * 20)
    x1 = np.array([[[-5e-324, -5e-324, 3e38], [0.0, 1.0, 1.0],
                    [0.0, 0.0, 3e38], [-3e38, 3e38, -1e-300]]] * 20)
    sender = interrupt_after(0.3)
    start = time.monotonic()
    with pytest.raises(KeyboardInterrupt):
        dhcd.vertex_face_ccd(x0, x1, min_distance=5e-324)
    assert time.monotonic() - start < 0.3 + 1.0
    sender.join()


def test_load_mesh_reads_float64_at_full_precision(tmp_path):
    path = tmp_path / "m.obj"
    path.write_text("v 0.1 0.2 0.30000000000000004\nv 1 0 0\nv 0 1 0\nf 1 2 3\n")
    v32, f = dhcd.load_mesh(path)
    assert v32.dtype == np.float32
    v64, f64 = dhcd.load_mesh(path, precision="f64")
    assert v64.dtype == np.float64
    assert v64[0].tolist() == [0.1, 0.2, 0.30000000000000004]
    assert (f64 == f).all()
    assert dhcd.Hierarchy(v64, f64).precision == "f64"
    with pytest.raises(ValueError, match="precision"):
        dhcd.load_mesh(path, precision="f16")


def test_none_positions_are_a_type_error():
    v, f = triangle_and_point(0.5)
    h = dhcd.Hierarchy(v, f)
    with pytest.raises(TypeError, match="x0"):
        dhcd.ccd(h, None, v)
    with pytest.raises(TypeError, match="x1"):
        dhcd.ccd(h, v, None)
    with pytest.raises(TypeError):
        dhcd.Hierarchy(None, f)


def test_an_update_entry_of_three_items_is_a_value_error():
    v, f = triangle_and_point(0.5)
    scene = dhcd.Scene()
    a = scene.add(v, f)
    with pytest.raises(ValueError, match="pair"):
        scene.update_many([(a, v, v)])
    with pytest.raises(TypeError):
        scene.update_many([a])
