"""Compare dhcd Python extension builds on the cases of the issue "At the floor" (the sheets,
the degenerate motions at N = 32 and, with --real, the real frame steps; floor_cases.py):
each build in its own child process, the builds alternated in --rounds rounds, the least
time of --repeat calls per case, query and build, and the ratio of the first build's time
to each other's (> 1: faster). A case whose answers differ between builds is flagged.

Each build is a folder holding a `dhcd` package, e.g. after `cargo build --release -p
dhcd-python` on each commit:

    mkdir -p /tmp/mod-old && cp -r python/dhcd /tmp/mod-old/
    cp target/release/libdhcd_python.so /tmp/mod-old/dhcd/_dhcd.abi3.so

usage: target/ipctk-venv/bin/python benches/scripts/compare-modules.py /tmp/mod-old
           /tmp/mod-new [--queries step,earliest] [--only 'wavy;folded'] [--real]
           [--rounds 2] [--repeat 3]
Queries (one thread, f64, dhat = 1e-3 x the bounding-box diagonal): step
(`collision_free_stepsize`), earliest (`ccd(earliest=True)`), all (`ccd`), prox
(`self_proximity`), set (`self_contact_set`).
"""
import argparse
import json
import os
import subprocess
import sys

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
here = os.path.dirname(os.path.abspath(__file__))

ap = argparse.ArgumentParser()
ap.add_argument("builds", nargs="*")
ap.add_argument("--queries", default="step,earliest")
ap.add_argument("--only", help="';'-separated parts of case names")
ap.add_argument("--real", action="store_true")
ap.add_argument("--rounds", type=int, default=2)
ap.add_argument("--repeat", type=int, default=3)
ap.add_argument("--child", action="store_true", help=argparse.SUPPRESS)
a = ap.parse_args()


def child():
    import numpy as np

    import dhcd
    from floor_cases import degenerate, real_frames, sheets
    from timing import least

    out = {}
    for name, x0, x1, faces in sheets() + degenerate(32) + (real_frames() if a.real else []):
        if a.only and not any(o in name for o in a.only.split(";")):
            continue
        x0 = np.ascontiguousarray(x0, dtype=np.float64)
        x1 = np.ascontiguousarray(x1, dtype=np.float64)
        h = dhcd.Hierarchy(x0, np.ascontiguousarray(faces, dtype=np.uint32))
        dhat = 1e-3 * float(np.linalg.norm(x0.max(0) - x0.min(0)))
        calls = {
            "step": lambda: dhcd.collision_free_stepsize(h, x0, x1),
            "earliest": lambda: dhcd.ccd(h, x0, x1, earliest=True).toi,
            "all": lambda: len(dhcd.ccd(h, x0, x1)),
            "prox": lambda: len(dhcd.self_proximity(h, dhat)),
            "set": lambda: len(dhcd.self_contact_set(h, dhat)),
        }
        for q in a.queries.split(","):
            t, r = least(calls[q], a.repeat)
            out[f"{name} | {q}"] = [t, repr(r)]
    print(json.dumps(out))


if a.child:
    child()
    sys.exit(0)
if len(a.builds) < 2 or a.rounds < 1 or a.repeat < 1:
    sys.exit("two builds or more, --rounds >= 1 and --repeat >= 1")
args = [sys.executable, os.path.abspath(__file__), "--child", "--queries", a.queries,
        "--repeat", str(a.repeat)] + (["--only", a.only] if a.only else []) + (["--real"] if a.real else [])
best, answers = {}, {}
for _ in range(a.rounds):
    for b in a.builds:
        env = dict(os.environ, PYTHONPATH=os.pathsep.join([b, here]))
        run = subprocess.run(args, env=env, capture_output=True, text=True)
        if run.returncode:
            sys.exit(f"{b}: {run.stderr[-2000:]}")
        for k, (t, r) in json.loads(run.stdout.strip().splitlines()[-1]).items():
            best[k, b] = min(best.get((k, b), float("inf")), t)
            answers.setdefault(k, {})[b] = r
print("| case | query | " + " | ".join(a.builds) + " | " + " | ".join(f"ratio {b}" for b in a.builds[1:]) + " |")
print("|---|---|" + "---:|" * (2 * len(a.builds) - 1))
for k, by in answers.items():
    case, q = k.split(" | ")
    ts = [best[k, b] for b in a.builds]
    flag = "" if len(set(by.values())) == 1 else f" (answers differ: {by})"
    print(f"| {case} | {q} | " + " | ".join(f"{t * 1e3:.3g} ms" for t in ts) + " | "
          + " | ".join(f"{ts[0] / t:.2f}x" for t in ts[1:]) + f" |{flag}")
