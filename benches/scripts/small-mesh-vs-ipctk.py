"""The cost of one call on small meshes (the issue "At the floor", deliver 4), dhcd beside the
IPC Toolkit 1.6.1, one thread each, f64, least of --repeat calls through Python.

Meshes: wavy n x n sheets (2 n^2 triangles, z = 0.02 sin(6x) cos(5y) over the unit square)
for each n of --sizes, moving a small step (z += 0.001 cos(3x)); n = 1 (two triangles) is
the fixed cost of a call. dhat = --relative x the bounding-box diagonal.

Rows, dhcd against ipctk:
- `Hierarchy(v, f)` (built once per mesh in a solver; listed for scale);
- `self_proximity(h, dhat)` and `self_contact_set(h, dhat)` against
  `NormalCollisions.build(mesh, x0, dhat)`;
- `ccd(h, x0, x1, earliest=True)` and `collision_free_stepsize(h, x0, x1)` against
  `compute_collision_free_stepsize(mesh, x0, x1)`.

usage: python benches/scripts/small-mesh-vs-ipctk.py [--sizes 1 10 20 40] [--repeat 200]
           [--relative 1e-3]
Needs a venv with dhcd, numpy and ipctk==1.6.1 (bash ../shared/peers/ipctk/setup.sh
target/ipctk-venv, then pip install the dhcd wheel into it).
"""
import argparse
import sys

import numpy as np

import dhcd
import ipctk
from timing import least

ap = argparse.ArgumentParser()
ap.add_argument("--sizes", type=int, nargs="+", default=[1, 10, 20, 40])
ap.add_argument("--repeat", type=int, default=200)
ap.add_argument("--relative", type=float, default=1e-3)
a = ap.parse_args()
if a.repeat < 1 or any(n < 1 or n > 1000 for n in a.sizes):
    sys.exit("--repeat >= 1 and every size in [1, 1000]")
ipctk.set_num_threads(1)
ipctk.set_logger_level(ipctk.LoggerLevel.off)


def sheet(n):
    xs = np.linspace(0.0, 1.0, n + 1)
    x, y = np.meshgrid(xs, xs, indexing="ij")
    v = np.stack([x.ravel(), y.ravel(), 0.02 * np.sin(6 * x.ravel()) * np.cos(5 * y.ravel())], 1)
    i, j = np.meshgrid(np.arange(n), np.arange(n), indexing="ij")
    a0 = (i * (n + 1) + j).ravel()
    b0 = a0 + n + 1
    f = np.concatenate([np.stack([a0, b0, a0 + 1], 1), np.stack([a0 + 1, b0, b0 + 1], 1)])
    return np.ascontiguousarray(v, dtype=np.float64), np.ascontiguousarray(f, dtype=np.int64)


def us(seconds):
    return f"{seconds * 1e6:,.1f} us"


print(f"one thread, f64, least of {a.repeat} calls, dhat = {a.relative} x diagonal")
print("| triangles | Hierarchy() | proximity | contact set | ipctk build | ratio "
      "| earliest | step size | ipctk step size | ratio |")
print("|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|")
for n in a.sizes:
    v, f = sheet(n)
    x1 = v.copy()
    x1[:, 2] += 0.001 * np.cos(3 * v[:, 0])
    dhat = a.relative * float(np.linalg.norm(v.max(0) - v.min(0)))
    h = dhcd.Hierarchy(v, f)
    mesh = ipctk.CollisionMesh(v, ipctk.edges(f), f)

    def build():
        c = ipctk.NormalCollisions()
        c.build(mesh, v, dhat)
        return c

    t_h, _ = least(lambda: dhcd.Hierarchy(v, f), a.repeat)
    t_prox, _ = least(lambda: dhcd.self_proximity(h, dhat), a.repeat)
    t_set, _ = least(lambda: dhcd.self_contact_set(h, dhat), a.repeat)
    t_build, _ = least(build, a.repeat)
    t_early, _ = least(lambda: dhcd.ccd(h, v, x1, earliest=True), a.repeat)
    t_step, _ = least(lambda: dhcd.collision_free_stepsize(h, v, x1), a.repeat)
    t_ipc, _ = least(lambda: ipctk.compute_collision_free_stepsize(mesh, v, x1), a.repeat)
    print(f"| {len(f):,} | {us(t_h)} | {us(t_prox)} | {us(t_set)} | {us(t_build)} "
          f"| {t_build / t_prox:.2f}x | {us(t_early)} | {us(t_step)} | {us(t_ipc)} "
          f"| {t_ipc / t_step:.2f}x |")
