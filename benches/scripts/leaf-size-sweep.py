#!/usr/bin/env python3
"""Least step time per real frame, method and leaf size, for one or more dhcd binaries.

    benches/scripts/leaf-size-sweep.py ROUNDS SIZES BIN... [--frames DIR]

e.g. `benches/scripts/leaf-size-sweep.py 4 32,48,64,80 target/release/dhcd`. Each round runs
`BIN bench self N.ply N+1.ply --method all --json --repeat 3 --leaf-size L` for every frame
pair, binary and size back to back (interleaved, so a noisy minute hits every size alike),
and keeps the least step per (frame, method, binary, size). Prints one line per frame, method
and binary: each size's least step in ms and its ratio to the line's best. How the default
leaf size was chosen (docs/notes/performance-history.md, section "default leaf size 64").
"""

import argparse
import json
import os
import subprocess
import sys

FRAMES = [
    ("cloth-ball-92", "cloth-ball-93"),
    ("rod-twist-3036", "rod-twist-3037"),
    ("n-body-simulation-18", "n-body-simulation-19"),
    ("armadillo-rollers-326", "armadillo-rollers-327"),
]
METHODS = ["dh", "sphere", "aabb"]


def main():
    here = os.path.dirname(os.path.abspath(__file__))
    default_frames = os.path.normpath(
        os.path.join(here, "..", "..", "..", "shared", "data", "real-frames")
    )
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("rounds", type=int)
    p.add_argument("sizes", help="comma-separated leaf sizes")
    p.add_argument("bins", nargs="+", help="dhcd binaries")
    p.add_argument("--frames", default=default_frames, help="the real-frames folder")
    a = p.parse_args()
    sizes = a.sizes.split(",")
    if not os.path.isdir(a.frames):
        sys.exit(f"no real frames at {a.frames} (pass --frames DIR)")

    best = {}
    for r in range(a.rounds):
        for first, second in FRAMES:
            for b in a.bins:
                for s in sizes:
                    cmd = [b, "bench", "self", f"{a.frames}/{first}.ply",
                           f"{a.frames}/{second}.ply", "--method", "all", "--json",
                           "--repeat", "3", "--leaf-size", s]
                    out = subprocess.run(cmd, capture_output=True, text=True, check=True)
                    for run in json.loads(out.stdout):
                        k = (first, run["method"], b, s)
                        best[k] = min(best.get(k, float("inf")), run["step_ms"]["min"])
        print(f"round {r + 1} of {a.rounds} done", file=sys.stderr)

    for first, _ in FRAMES:
        for m in METHODS:
            for b in a.bins:
                row = [best[(first, m, b, s)] for s in sizes]
                lo = min(row)
                cells = "  ".join(f"{s}: {v:7.2f} ({v / lo:.2f})" for s, v in zip(sizes, row))
                print(f"{first:24s} {m:6s} {os.path.basename(b):12s} {cells}")


if __name__ == "__main__":
    main()
