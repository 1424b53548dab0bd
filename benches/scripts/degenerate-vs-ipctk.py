"""Degenerate sheet motions (../shared/data/degenerate/sheets.py) timed in one run: dhcd's
CCD of every colliding pair and its earliest impact, beside the IPC Toolkit's
compute_collision_free_stepsize, one thread, least of --repeat calls. Each motion is paired
with a non-degenerate step of the same mesh ("wavy slide": the slide with every vertex
lifted off the plane by a fixed wave, so no feature is coplanar), the yardstick of the
issue "At the floor".

usage: python benches/scripts/degenerate-vs-ipctk.py [--n 16 32 64] [--repeat 3]
           [--kinds slide fold collapse line slide2] [--no-ipctk] [--ipctk-timeout 60]
ipctk runs in a child process stopped after --ipctk-timeout seconds (its Tight Inclusion
narrow phase takes minutes on some of these motions); such a cell reads "> 60 s".
Needs a venv with dhcd, numpy and (unless --no-ipctk) ipctk==1.6.1 (see
contact-set-vs-ipctk.py). Prints one markdown table.
"""
import argparse
import importlib.util
import multiprocessing
import os

import numpy as np

import dhcd
from timing import least

ap = argparse.ArgumentParser()
ap.add_argument("--n", type=int, nargs="+", default=[16, 32, 64])
ap.add_argument("--repeat", type=int, default=3)
ap.add_argument("--kinds", nargs="+", default=["slide", "fold", "collapse", "line", "slide2"])
ap.add_argument("--no-ipctk", action="store_true")
ap.add_argument("--ipctk-timeout", type=float, default=60.0)
a = ap.parse_args()

here = os.path.dirname(os.path.abspath(__file__))
spec = importlib.util.spec_from_file_location(
    "sheets", os.path.join(here, "../../../shared/data/degenerate/sheets.py")
)
sheets = importlib.util.module_from_spec(spec)
spec.loader.exec_module(sheets)

ipctk = None
if not a.no_ipctk:
    import ipctk

    ipctk.set_num_threads(1)
    ipctk.set_logger_level(ipctk.LoggerLevel.off)


def ipctk_least(x0, x1, faces, edges, repeat, timeout):
    """Least of `repeat` compute_collision_free_stepsize calls in a child process, or None
    when it did not finish within `timeout` seconds."""

    def child(conn):
        mesh = ipctk.CollisionMesh(
            np.asfortranarray(x0),
            np.asfortranarray(edges.astype(np.int32)),
            np.asfortranarray(faces.astype(np.int32)),
        )
        t, _ = least(lambda: ipctk.compute_collision_free_stepsize(mesh, x0, x1), repeat)
        conn.send(t)

    parent, child_end = multiprocessing.Pipe()
    p = multiprocessing.get_context("fork").Process(target=child, args=(child_end,))
    p.start()
    got = parent.poll(timeout)
    t = parent.recv() if got else None
    p.terminate()
    p.join()
    return t


def motion(kind, n):
    if kind == "wavy slide":
        x0, x1, faces = sheets.make("slide", n)
        lift = 0.02 * np.sin(7.1 * x0[:, 0] + 3.3) * np.cos(5.3 * x0[:, 1] + 1.1)
        x0, x1 = x0.copy(), x1.copy()
        x0[:, 2] += lift
        x1[:, 2] += lift
        return x0, x1, faces
    return sheets.make(kind, n)


def ms(t):
    return f"{t * 1e3:.1f} ms" if t < 10 else f"{t:.1f} s"


print(
    "| motion | N | triangles | candidates | colliding pairs | dhcd all pairs | "
    "dhcd earliest | ipctk step size | ipctk / dhcd earliest |"
)
print("|---|---:|---:|---:|---:|---:|---:|---:|---:|")
for n in a.n:
    for kind in ["wavy slide"] + a.kinds:
        x0, x1, faces = motion(kind, n)
        x0 = np.ascontiguousarray(x0, dtype=np.float64)
        x1 = np.ascontiguousarray(x1, dtype=np.float64)
        faces = np.ascontiguousarray(faces, dtype=np.uint32)
        h = dhcd.Hierarchy(x0, faces)
        t_all, hits = least(lambda: dhcd.ccd(h, x0, x1, threads=1), a.repeat)
        t_first, _ = least(lambda: dhcd.ccd(h, x0, x1, earliest=True, threads=1), a.repeat)
        pairs = len(hits.vertex_face) + len(hits.face_vertex) + len(hits.edge_edge)
        cand = hits.counters["prim_tests"]
        if ipctk is not None:
            t_ipc = ipctk_least(x0, x1, faces, h.edges(), a.repeat, a.ipctk_timeout)
            if t_ipc is None:
                ipc = f"> {a.ipctk_timeout:.0f} s | > {a.ipctk_timeout / t_first:.0f}x"
            else:
                ipc = f"{ms(t_ipc)} | {t_ipc / t_first:.2f}x"
        else:
            ipc = "| "
        print(
            f"| {kind} | {n} | {len(faces):,} | {cand:,} | {pairs:,} | {ms(t_all)} | "
            f"{ms(t_first)} | {ipc} |",
            flush=True,
        )
