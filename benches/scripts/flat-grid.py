#!/usr/bin/env python3
"""Writes a square grid mesh as OBJ: the flat-sheet case of docs/PERFORMANCE.md.

usage: flat-grid.py N NOISE OUT.obj [same|alt]

(N + 1)^2 vertices (i/N, j/N, z) with z = 0, or uniform in [-NOISE, NOISE] (seed 1), and
2 N^2 triangles, each cell split along one diagonal ("same") or alternating ones ("alt").
Then e.g. `dhcd bench self OUT.obj OUT.obj --method aabb --repeat 3 --threads 1`.
"""
import random
import sys


def main():
    if len(sys.argv) not in (4, 5) or sys.argv[4:] not in ([], ["same"], ["alt"]):
        sys.exit(__doc__)
    n, noise, out = int(sys.argv[1]), float(sys.argv[2]), sys.argv[3]
    alt = sys.argv[4:] == ["alt"]
    if n < 1 or noise < 0:
        sys.exit("N must be >= 1 and NOISE >= 0")
    random.seed(1)
    with open(out, "w") as f:
        for j in range(n + 1):
            for i in range(n + 1):
                z = random.uniform(-noise, noise) if noise > 0 else 0.0
                f.write(f"v {i / n:.7f} {j / n:.7f} {z:.9f}\n")
        for j in range(n):
            for i in range(n):
                a = j * (n + 1) + i + 1
                b, c = a + 1, a + n + 1
                d = c + 1
                if alt and (i + j) % 2:
                    f.write(f"f {a} {b} {c}\nf {b} {d} {c}\n")
                else:
                    f.write(f"f {a} {b} {d}\nf {a} {d} {c}\n")


if __name__ == "__main__":
    main()
