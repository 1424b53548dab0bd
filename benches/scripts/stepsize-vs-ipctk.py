"""The collision-free step size against the IPC Toolkit's compute_collision_free_stepsize on
the real frame steps (frame -> next frame), one thread, least of --repeat calls, in one run.

usage: python benches/scripts/stepsize-vs-ipctk.py [--repeat 3] [--min-distance 0]
Needs a venv with dhcd and ipctk==1.6.1 (see contact-set-vs-ipctk.py).

Both apply the rule "keep min_distance + (1 - 0.8)(d0 - min_distance)"; ipctk caps that gap
at 1e-4 and measures it per axis (see docs/COMING_FROM_IPCTK.md), so the two steps differ;
both are printed, with dhcd's earliest impact (ccd earliest=True), which neither may pass.
"""
import argparse
import os

import numpy as np

import dhcd
from timing import least
import ipctk

ap = argparse.ArgumentParser()
ap.add_argument("--repeat", type=int, default=3)
ap.add_argument("--min-distance", type=float, default=0.0)
a = ap.parse_args()
ipctk.set_num_threads(1)
ipctk.set_logger_level(ipctk.LoggerLevel.off)
root = os.path.join(os.path.dirname(__file__), "../../../shared/data/real-frames")
steps = [
    ("armadillo-rollers", 326),
    ("rod-twist", 3036),
    ("cloth-ball", 92),
    ("n-body-simulation", 18),
]


print(
    "| step | triangles | dhcd step | ipctk step | earliest impact | dhcd | ipctk "
    "compute_collision_free_stepsize | ratio |"
)
print("|---|---:|---:|---:|---:|---:|---:|---:|")
for name, frame in steps:
    x0, faces = dhcd.load_mesh(os.path.join(root, f"{name}-{frame}.ply"), precision="f64")
    x1, _ = dhcd.load_mesh(os.path.join(root, f"{name}-{frame + 1}.ply"), precision="f64")
    h = dhcd.Hierarchy(x0, faces)
    t_ours, ours = least(
        lambda: dhcd.collision_free_stepsize(h, x0, x1, min_distance=a.min_distance), a.repeat
    )
    toi = dhcd.ccd(h, x0, x1, min_distance=a.min_distance, earliest=True).toi
    E = h.edges().astype(np.int32)
    mesh = ipctk.CollisionMesh(np.asfortranarray(x0), np.asfortranarray(E), np.asfortranarray(faces.astype(np.int32)))
    t_ipc, theirs = least(
        lambda: ipctk.compute_collision_free_stepsize(mesh, x0, x1, a.min_distance), a.repeat
    )
    print(
        f"| {name} {frame} -> {frame + 1} | {len(faces):,} | {ours:.6g} | {theirs:.6g} | "
        f"{toi:.6g} | {t_ours * 1e3:.0f} ms | {t_ipc * 1e3:.0f} ms | {t_ipc / t_ours:.2f}x |"
    )
