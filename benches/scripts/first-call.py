"""The one-time cost of a fresh hierarchy's first query: `self_proximity` called twice on
each of three fresh hierarchies of two real frames, the first call's time less the second's
(the lazily built caches: leaf edges, feature boxes, the patches of the clearance proof,
the workspace's first allocations).

usage: PYTHONPATH=<folder holding the dhcd package> target/ipctk-venv/bin/python
           benches/scripts/first-call.py [--frames ../shared/data/real-frames]
"""
import argparse
import os
import time

import numpy as np

import dhcd

here = os.path.dirname(os.path.abspath(__file__))
ap = argparse.ArgumentParser()
ap.add_argument("--frames", default=os.path.join(here, "../../../shared/data/real-frames"))
a = ap.parse_args()

for name in ["cloth-ball-92", "n-body-simulation-18"]:
    x, f = dhcd.load_mesh(os.path.join(a.frames, f"{name}.ply"), precision="f64")
    dhat = 1e-3 * float(np.linalg.norm(x.max(0) - x.min(0)))
    extra = []
    for _ in range(3):
        h = dhcd.Hierarchy(x, f)
        t = time.perf_counter()
        dhcd.self_proximity(h, dhat)
        first = time.perf_counter() - t
        t = time.perf_counter()
        dhcd.self_proximity(h, dhat)
        second = time.perf_counter() - t
        extra.append((first - second) * 1e3)
    print(name, "first call's extra ms:", " ".join(f"{e:.1f}" for e in extra))
