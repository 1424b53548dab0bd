#!/usr/bin/env python3
"""Compare dhcd builds on the real frames: interleaved `dhcd bench QUERY N N+1 --json` runs of
each binary, the least step (ms) per frame, method and binary over ROUNDS rounds, the ratio of
the first binary to each other, and a warning when their counters differ (an optimisation
must not change N_V, N_P or N_U). Usage, from the project root, e.g. after copying the build
of the previous commit to /tmp/dhcd-before:

    benches/scripts/compare-binaries.py /tmp/dhcd-before target/release/dhcd

Environment: QUERY (`self`, every method: the default; `proximity`, f64 within 1e-3 x the
diagonal; `ccd`, every pair with its time; `earliest`, the earliest time: the last three with
DH), ROUNDS (3), REPEAT (passes per run, 6), THREADS (1), DATA (../shared/data/real-frames).
"""
import json, os, subprocess, sys
bins = sys.argv[1:]
D = os.environ.get('DATA', '../shared/data/real-frames') + '/'
pairs = [('cloth-ball-92', 'cloth-ball-93'), ('rod-twist-3036', 'rod-twist-3037'),
         ('n-body-simulation-18', 'n-body-simulation-19'), ('armadillo-rollers-326', 'armadillo-rollers-327')]
rounds = int(os.environ.get('ROUNDS', '3'))
rep = os.environ.get('REPEAT', '6')
threads = os.environ.get('THREADS', '1')
query = os.environ.get('QUERY', 'self')
extra = {'self': ['self', '--method', 'all'],
         'proximity': ['proximity', '--relative', '1e-3', '--precision', 'f64'],
         'ccd': ['ccd'], 'earliest': ['ccd', '--earliest']}[query]
best, counters = {}, {}
for f0, f1 in pairs:
    for r in range(rounds):
        for b in bins:
            out = subprocess.run([b, 'bench', extra[0], D + f0 + '.ply', D + f1 + '.ply', *extra[1:],
                                  '--json', '--repeat', rep, '--threads', threads], capture_output=True, text=True, check=True).stdout
            results = json.loads(out)
            for res in results if isinstance(results, list) else [results]:
                k = (f0, res['method'], b)
                best[k] = min(best.get(k, 1e18), res['step_ms']['min'])
                c = [dict(fr['counters'], contacts=fr.get('contacts')) for fr in res['frames']]
                counters.setdefault((f0, res['method']), {})[b] = c
for (f0, m), cb in counters.items():
    vals = list(cb.values())
    same = all(v == vals[0] for v in vals)
    row = [best[(f0, m, b)] for b in bins]
    print(f"{f0:24s} {m:7s} " + " ".join(f"{x:8.2f}" for x in row) + "  ratio " +
          " ".join(f"{row[0]/x:5.3f}" for x in row[1:]) + ("" if same else "  COUNTERS DIFFER") +
          f"  N_P {vals[0][0].get('prim_tests')}")
