"""The cases of the issue "At the floor" in one run, dhcd beside the IPC Toolkit 1.6.1, one
thread each, f64, least of --repeat calls, dhat = --relative x the bounding-box diagonal:

- the real frame steps of ../shared/data/real-frames (frame N -> N+1), when it is there;
- three 40 x 40 sheets (3,200 triangles, the cases of benches/contact.rs): a wavy sheet
  moving a small step, the same sheet folded over itself with its layers closing in, and a
  flat sheet sliding in its own plane;
- the degenerate motions of ../shared/data/degenerate/sheets.py at --n (slide, fold,
  collapse, line, slide2), each beside the "wavy slide": the slide with every vertex lifted
  off the plane by a fixed wave, a non-degenerate step of the same mesh.

Columns, dhcd against ipctk:
- proximity: `self_proximity(h, dhat)` and `self_contact_set(h, dhat)` against
  `NormalCollisions.build(mesh, x0, dhat)` (LBVH);
- CCD: `ccd(h, x0, x1, earliest=True)` (the earliest impact), `collision_free_stepsize(h, x0,
  x1)` and `ccd(h, x0, x1)` (every colliding pair with its time) against
  `compute_collision_free_stepsize(mesh, x0, x1)` (LBVH + Tight Inclusion).
Each call runs in a child process stopped after --timeout seconds (ipctk's narrow phase
takes minutes on some degenerate motions); such a cell reads "> T s".

usage: python benches/scripts/floor-vs-ipctk.py [--repeat 3] [--n 64] [--timeout 120]
           [--relative 1e-3] [--no-real] [--write docs/PERFORMANCE.md]
--write replaces the text between the markers `<!-- floor-vs-ipctk: begin -->` and
`<!-- floor-vs-ipctk: end -->` of that file with the tables (and the date, commit, load and
command); without it the tables are printed. Needs a venv with dhcd, numpy and ipctk==1.6.1
(bash ../shared/peers/ipctk/setup.sh target/ipctk-venv, then pip install the dhcd wheel
into it).
"""
import argparse
import datetime
import multiprocessing
import os
import re
import subprocess
import sys

# numpy's BLAS threads spin after a call and take a core from the one-thread timings.
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
import numpy as np

import dhcd
import ipctk
from floor_cases import degenerate, real_frames, sheets
from timing import least

ap = argparse.ArgumentParser()
ap.add_argument("--repeat", type=int, default=3)
ap.add_argument("--n", type=int, default=64)
ap.add_argument("--timeout", type=float, default=120.0)
ap.add_argument("--relative", type=float, default=1e-3)
ap.add_argument("--no-real", action="store_true")
ap.add_argument("--write")
a = ap.parse_args()
if a.repeat < 1 or a.n < 2 or a.timeout <= 0:
    sys.exit("--repeat >= 1, --n >= 2 and --timeout > 0")

ipctk.set_num_threads(1)
ipctk.set_logger_level(ipctk.LoggerLevel.off)


# --- timing ----------------------------------------------------------------------------------


def in_child(f, timeout):
    """(least time of --repeat calls of f, f's last result) from a forked child, or None when
    it did not finish within `timeout` seconds."""

    def child(conn):
        conn.send(least(f, a.repeat))

    parent, child_end = multiprocessing.Pipe()
    p = multiprocessing.get_context("fork").Process(target=child, args=(child_end,))
    p.start()
    out = parent.recv() if parent.poll(timeout) else None
    p.terminate()
    p.join()
    return out


def ms(t):
    return f"{t * 1e3:.3g} ms" if t < 1 else f"{t:.3g} s"


def cell(ours, theirs):
    """"dhcd / ipctk | ratio" with ratio = ipctk time / dhcd time (> 1: dhcd faster)."""
    o = ms(ours[0]) if ours else f"> {a.timeout:.0f} s"
    t = ms(theirs[0]) if theirs else f"> {a.timeout:.0f} s"
    if ours and theirs:
        r = f"{theirs[0] / ours[0]:.2f}x"
    elif ours:
        r = f"> {a.timeout / ours[0]:.0f}x"
    elif theirs:
        r = f"< {theirs[0] / a.timeout:.2g}x"
    else:
        r = "?"
    return f"{o} | {t} | {r}"


def measure(name, x0, x1, faces):
    x0 = np.ascontiguousarray(x0, dtype=np.float64)
    x1 = np.ascontiguousarray(x1, dtype=np.float64)
    faces = np.ascontiguousarray(faces, dtype=np.uint32)
    h = dhcd.Hierarchy(x0, faces)
    dhat = a.relative * float(np.linalg.norm(x0.max(0) - x0.min(0)))
    mesh = ipctk.CollisionMesh(
        np.asfortranarray(x0),
        np.asfortranarray(h.edges().astype(np.int32)),
        np.asfortranarray(faces.astype(np.int32)),
    )

    def build():
        c = ipctk.NormalCollisions()
        c.build(mesh, x0, dhat, broad_phase=ipctk.LBVH())
        return len(c)

    t = a.timeout
    r = {
        "prox": in_child(lambda: len(dhcd.self_proximity(h, dhat)), t),
        "set": in_child(lambda: len(dhcd.self_contact_set(h, dhat)), t),
        "build": in_child(build, t),
        "earliest": in_child(lambda: dhcd.ccd(h, x0, x1, earliest=True).toi, t),
        "step": in_child(lambda: dhcd.collision_free_stepsize(h, x0, x1), t),
        "all": in_child(lambda: len(dhcd.ccd(h, x0, x1)), t),
        "ipc": in_child(lambda: ipctk.compute_collision_free_stepsize(mesh, x0, x1), t),
    }
    print(f"{name}: " + ", ".join(f"{k} {v[0]:.4g} s" if v else f"{k} timeout" for k, v in r.items()),
          file=sys.stderr, flush=True)
    return name, len(faces), dhat, r


def tables(rows):
    out = [
        "| case | triangles | dhat | contacts (ipctk) | dhcd proximity | ipctk build | ratio | "
        "dhcd contact set | ipctk build | ratio |",
        "|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|",
    ]
    for name, tris, dhat, r in rows:
        contacts = f"{r['build'][1]:,}" if r["build"] else "?"
        out.append(
            f"| {name} | {tris:,} | {dhat:.3g} | {contacts} | {cell(r['prox'], r['build'])} | "
            f"{cell(r['set'], r['build'])} |"
        )
    out += [
        "",
        "| case | colliding pairs | earliest impact | dhcd earliest | ipctk step size | ratio | "
        "dhcd step size | ipctk | ratio | dhcd all pairs | ipctk earliest | ratio |",
        "|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|",
    ]
    for name, tris, dhat, r in rows:
        colliding = f"{r['all'][1]:,}" if r["all"] else "?"
        toi = r["earliest"][1] if r["earliest"] else None
        toi = "?" if toi is None else ("none" if np.isinf(toi) else f"{toi:.6g}")
        out.append(
            f"| {name} | {colliding} | {toi} | {cell(r['earliest'], r['ipc'])} | "
            f"{cell(r['step'], r['ipc'])} | {cell(r['all'], r['ipc'])} |"
        )
    wavy = next((r for name, _, _, r in rows if name.startswith("wavy slide")), None)
    if wavy:
        out += [
            "",
            "Degenerate motions against the wavy slide of the same mesh (dhcd time / wavy "
            "slide's; the target is at most 3x where the output is small):",
            "",
            "| motion | proximity | earliest impact | step size | all pairs |",
            "|---|---:|---:|---:|---:|",
        ]
        for name, _, _, r in rows:
            if not re.match(r"(slide|fold|collapse|line|slide2), N", name):
                continue
            f = lambda k: f"{r[k][0] / wavy[k][0]:.2f}x" if r[k] and wavy[k] else "?"
            out.append(f"| {name} | {f('prox')} | {f('earliest')} | {f('step')} | {f('all')} |")
    return out


rows = [measure(*c) for c in (([] if a.no_real else real_frames()) + sheets() + degenerate(a.n))]
commit = subprocess.run(["git", "rev-parse", "--short", "HEAD"], capture_output=True, text=True,
                        cwd=os.path.dirname(os.path.abspath(__file__))).stdout.strip()
load = open("/proc/loadavg").read().split()[:3]


def machine():
    """The CPU model, its core count and its widest SIMD (the figures move between machines)."""
    try:
        info = open("/proc/cpuinfo").read()
    except OSError:
        return "unknown machine"
    model = re.search(r"^model name\s*:\s*(.*)$", info, re.M)
    flags = set((re.search(r"^flags\s*:\s*(.*)$", info, re.M) or [None, ""])[1].split())
    simd = "AVX-512" if "avx512f" in flags else "AVX2" if "avx2" in flags else "no AVX2"
    return f"{os.cpu_count()}-core {model[1].strip() if model else 'CPU'} ({simd})"


header = (
    f"{datetime.datetime.now(datetime.timezone.utc):%Y-%m-%d %H:%M} UTC, commit {commit}, "
    f"{machine()}, load {' '.join(load)}, `python benches/scripts/floor-vs-ipctk.py --repeat {a.repeat} --n {a.n} "
    f"--timeout {a.timeout:g}`; one thread, f64, least of {a.repeat}, dhat = {a.relative:g} x "
    "diagonal; ratio = ipctk time / dhcd time:"
)
text = [header, ""] + tables(rows)
if a.write:
    begin, end = "<!-- floor-vs-ipctk: begin -->", "<!-- floor-vs-ipctk: end -->"
    doc = open(a.write).read()
    if begin not in doc or end not in doc:
        sys.exit(f"{a.write} has no markers {begin} ... {end}")
    head, rest = doc.split(begin, 1)
    _, tail = rest.split(end, 1)
    open(a.write, "w").write(head + begin + "\n" + "\n".join(text) + "\n" + end + tail)
    print(f"wrote {a.write}")
else:
    print("\n".join(text))
