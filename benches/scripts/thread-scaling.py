#!/usr/bin/env python3
"""Thread scaling on the real frames: `dhcd bench self N N+1 --method all --json --repeat 6`
on 1 and 2 threads, interleaved, ROUNDS (3) rounds; prints the least step (ms) per method and
thread count and their ratio. Interleaving and the least of several rounds matter on a shared
machine: a single pair of runs once showed 1.27x where this shows 1.9x. From the project root:

    cargo build --release -p dhcd-cli && benches/scripts/thread-scaling.py

Environment: DHCD (target/release/dhcd), DATA (../shared/data/real-frames), ROUNDS (3).
"""
import json, os, subprocess

D = os.environ.get('DATA', '../shared/data/real-frames') + '/'
B = os.environ.get('DHCD', 'target/release/dhcd')
ROUNDS = int(os.environ.get('ROUNDS', '3'))
PAIRS = [('cloth-ball-92', 'cloth-ball-93'), ('rod-twist-3036', 'rod-twist-3037'),
         ('n-body-simulation-18', 'n-body-simulation-19'),
         ('armadillo-rollers-326', 'armadillo-rollers-327')]
for f0, f1 in PAIRS:
    best = {}
    for _ in range(ROUNDS):
        for t in ('1', '2'):
            out = subprocess.run([B, 'bench', 'self', D + f0 + '.ply', D + f1 + '.ply', '--method', 'all',
                                  '--json', '--repeat', '6', '--threads', t],
                                 capture_output=True, text=True, check=True).stdout
            for res in json.loads(out):
                k = (res['method'], t)
                best[k] = min(best.get(k, 1e18), res['step_ms']['min'])
    print(f0, ' '.join(f"{m}: {best[(m, '1')]:.1f} -> {best[(m, '2')]:.1f} ({best[(m, '1')] / best[(m, '2')]:.2f}x)"
                       for m in ('dh', 'sphere', 'aabb')))
