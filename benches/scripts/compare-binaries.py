#!/usr/bin/env python3
"""Compare dhcd builds on the real frames: interleaved `dhcd bench self N N+1 --method all
--json` runs of each binary, the least step (ms) per frame, method and binary over ROUNDS
rounds, the ratio of the first binary to each other, and a warning when their counters differ
(an optimisation must not change N_V, N_P or N_U). Usage, from the project root, e.g. after
copying the build of the previous commit to /tmp/dhcd-before:

    benches/scripts/compare-binaries.py /tmp/dhcd-before target/release/dhcd

Environment: ROUNDS (3), REPEAT (passes per run, 6), THREADS (1), DATA (../shared/data/real-frames).
"""
import json, os, subprocess, sys
bins = sys.argv[1:]
D = os.environ.get('DATA', '../shared/data/real-frames') + '/'
pairs = [('cloth-ball-92', 'cloth-ball-93'), ('rod-twist-3036', 'rod-twist-3037'),
         ('n-body-simulation-18', 'n-body-simulation-19'), ('armadillo-rollers-326', 'armadillo-rollers-327')]
rounds = int(os.environ.get('ROUNDS', '3'))
rep = os.environ.get('REPEAT', '6')
threads = os.environ.get('THREADS', '1')
best, counters = {}, {}
for f0, f1 in pairs:
    for r in range(rounds):
        for b in bins:
            out = subprocess.run([b, 'bench', 'self', D + f0 + '.ply', D + f1 + '.ply', '--method', 'all',
                                  '--json', '--repeat', rep, '--threads', threads], capture_output=True, text=True, check=True).stdout
            for res in json.loads(out):
                k = (f0, res['method'], b)
                best[k] = min(best.get(k, 1e18), res['step_ms']['min'])
                c = [fr['counters'] for fr in res['frames']]
                counters.setdefault((f0, res['method']), {})[b] = c
for (f0, m), cb in counters.items():
    vals = list(cb.values())
    same = all(v == vals[0] for v in vals)
    row = [best[(f0, m, b)] for b in bins]
    print(f"{f0:24s} {m:7s} " + " ".join(f"{x:8.2f}" for x in row) + "  ratio " +
          " ".join(f"{row[0]/x:5.3f}" for x in row[1:]) + ("" if same else "  COUNTERS DIFFER") +
          f"  N_P {vals[0][0].get('prim_tests')}")
