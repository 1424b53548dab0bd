"""The cases of the issue "At the floor", shared by the scripts beside it: `sheets()` (the
three 40 x 40 sheets of benches/contact.rs), `degenerate(n)` (the motions of
../shared/data/degenerate/sheets.py beside the "wavy slide") and `real_frames()` (the frame
steps of ../shared/data/real-frames), each a list of (name, x0, x1, faces). A missing
../shared skips its cases with one line on stderr."""
import glob
import importlib.util
import os
import re
import sys

import numpy as np

import dhcd

here = os.path.dirname(os.path.abspath(__file__))
shared = os.path.join(here, "../../../shared")
MASK = (1 << 64) - 1


# --- the 40 x 40 sheets of benches/contact.rs (dhcd::shapes in float32) --------------------


def grid(nx, ny, cell):
    j, i = np.meshgrid(np.arange(ny + 1), np.arange(nx + 1), indexing="ij")
    x = np.stack([i.ravel() * cell, j.ravel() * cell, np.zeros(i.size)], 1).astype(np.float32)
    at = lambda i, j: j * (nx + 1) + i
    f = []
    for jj in range(ny):
        for ii in range(nx):
            f.append([at(ii, jj), at(ii + 1, jj), at(ii + 1, jj + 1)])
            f.append([at(ii, jj), at(ii + 1, jj + 1), at(ii, jj + 1)])
    return x, np.array(f, dtype=np.uint32)


def wave(rest, t, amplitude):
    p = rest.astype(np.float32)
    t, amplitude = np.float32(t), np.float32(amplitude)
    s = np.sin(p[:, 0] * np.float32(3.1) + t) * np.cos(p[:, 1] * np.float32(2.3) - np.float32(0.7) * t)
    r = np.sin(p[:, 2] * np.float32(2.7) + np.float32(1.3) * t)
    return np.stack(
        [p[:, 0] + amplitude * s, p[:, 1] + amplitude * r * np.float32(0.5), p[:, 2] + amplitude * s * r], 1
    )


def splitmix64(state):
    state = (state + 0x9E3779B97F4A7C15) & MASK
    z = state
    z = ((z ^ (z >> 30)) * 0xBF58476D1CE4E5B9) & MASK
    z = ((z ^ (z >> 27)) * 0x94D049BB133111EB) & MASK
    return state, z ^ (z >> 31)


def jitter(p, amplitude, seed):
    out = p.astype(np.float32).copy()
    for i in range(len(p)):
        state = seed ^ ((i * 0xD1B54A32D192ED03) & MASK)
        for k in range(3):
            state, z = splitmix64(state)
            u = np.float32(z >> 40) / np.float32(1 << 23) - np.float32(1.0)
            out[i, k] = out[i, k] + np.float32(amplitude) * u
    return out


def sheets():
    rest, faces = grid(40, 40, np.float32(1.0 / 40.0))

    def folded(h):
        p = rest.copy()
        beyond = rest[:, 0] > np.float32(0.5)
        p[beyond, 0] = np.float32(1.0) - rest[beyond, 0]
        p[beyond, 2] += np.float32(h)
        return jitter(p, 0.0005, 3)

    slid = rest.astype(np.float64) + [0.01, 0.005, 0.0]
    return [
        ("wavy 40 x 40 sheet, small step", wave(rest, 0.0, 0.02), wave(rest, 0.05, 0.02), faces),
        ("the same sheet folded, layers closing in", folded(0.03), folded(0.0), faces),
        ("flat 40 x 40 sheet sliding in its plane", rest, slid, faces),
    ]


# --- the degenerate motions ------------------------------------------------------------------


def degenerate(n):
    spec = importlib.util.spec_from_file_location(
        "sheets", os.path.join(shared, "data/degenerate/sheets.py")
    )
    if spec is None or not os.path.exists(spec.origin):
        print(f"degenerate motions SKIPPED: no {spec.origin}", file=sys.stderr)
        return []
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    out = []
    for kind in ["wavy slide", "slide", "fold", "collapse", "line", "slide2"]:
        x0, x1, faces = mod.make("slide" if kind == "wavy slide" else kind, n)
        if kind == "wavy slide":
            lift = 0.02 * np.sin(7.1 * x0[:, 0] + 3.3) * np.cos(5.3 * x0[:, 1] + 1.1)
            x0, x1 = x0.copy(), x1.copy()
            x0[:, 2] += lift
            x1[:, 2] += lift
        out.append((f"{kind}, N = {n}", x0, x1, faces))
    return out


def real_frames():
    root = os.path.join(shared, "data/real-frames")
    if not os.path.isdir(root):
        print(f"real frames SKIPPED: no folder {root}", file=sys.stderr)
        return []
    out = []
    for path in sorted(glob.glob(os.path.join(root, "*.ply"))):
        name, frame = re.match(r"(.*)-(\d+)\.ply$", os.path.basename(path)).groups()
        nxt = os.path.join(root, f"{name}-{int(frame) + 1}.ply")
        if os.path.exists(nxt):
            x0, faces = dhcd.load_mesh(path, precision="f64")
            x1, _ = dhcd.load_mesh(nxt, precision="f64")
            out.append((f"{name} {frame} -> {int(frame) + 1}", x0, x1, faces))
    return out
