"""The contact set against the IPC Toolkit's NormalCollisions.build on real frames: the same
contacts (type, vertices, mollified, edge ids), every difference listed with its reason, and
both timed in one run (one thread, least of --repeat calls).

usage: python benches/scripts/contact-set-vs-ipctk.py [FRAME.ply ...] [--relative 1e-3]
       [--repeat 3]
Default frames: every frame in ../shared/data/real-frames. Needs a venv with dhcd and
ipctk==1.6.1 (bash ../shared/peers/ipctk/setup.sh target/ipctk-venv, then pip install the
dhcd wheel into it).

dhat = R x bounding-box diagonal. The frame's own positions are the rest pose of both (the
mollifier thresholds). ipctk decides distance types and activity in floating point with
`d^2 < dhat^2`; dhcd decides them exactly with `d <= dhat`: a contact found by one and not
the other is printed with the exact squared distance and both types, so each difference
can be checked to be a tie at dhat or a type decided across a region boundary by rounding.
"""
import argparse
import glob
import os

import numpy as np

import dhcd
from timing import least
import ipctk

ap = argparse.ArgumentParser()
ap.add_argument("frames", nargs="*")
ap.add_argument("--relative", type=float, default=1e-3)
ap.add_argument("--repeat", type=int, default=3)
a = ap.parse_args()
frames = a.frames or sorted(
    glob.glob(os.path.join(os.path.dirname(__file__), "../../../shared/data/real-frames/*.ply"))
)
ipctk.set_num_threads(1)
ipctk.set_logger_level(ipctk.LoggerLevel.off)
NAMES = ["PP", "PE", "PT", "EE"]


def ours_as_dict(cs):
    return {
        (int(t), *map(int, v)): (bool(m), int(e[0]), int(e[1]))
        for t, v, m, e in zip(cs.type, cs.vertices, cs.mollified, cs.edges)
    }


def theirs_as_dict(c, mesh, V):
    out = {}
    E = mesh.edges
    for kind, cols in (
        (0, c.vv_collisions),
        (1, c.ev_collisions),
        (3, c.ee_collisions),
        (2, c.fv_collisions),
    ):
        for col in cols:
            ids = [int(v) for v in col.vertex_ids(E, mesh.faces)]
            if kind == 0:
                key, val = (0, min(ids[:2]), max(ids[:2]), -1, -1), (False, -1, -1)
            elif kind == 1:
                key, val = (1, *ids[:3], -1), (False, int(col.edge_id), -1)
            elif kind == 3:
                e0, e1 = int(col.edge0_id), int(col.edge1_id)
                if e0 > e1:
                    e0, e1, ids = e1, e0, ids[2:] + ids[:2]
                moll = bool(ipctk.edge_edge_cross_squarednorm(*V[ids]) < col.eps_x)
                key, val = (3, *ids), (moll, e0, e1)
            else:
                key, val = (2, *ids), (False, -1, -1)
            out[key] = val
    return out


print(
    "| frame | triangles | dhat | contacts PP / PE / PT / EE (mollified) | ipctk | equal | "
    "dhcd self_contact_set | ipctk NormalCollisions.build | ratio |"
)
print("|---|---:|---:|---|---:|---|---:|---:|---:|")
notes = []
for path in frames:
    V, F = dhcd.load_mesh(path, precision="f64")
    F = F.astype(np.int64)
    diag = float(np.linalg.norm(V.max(0) - V.min(0)))
    dhat = a.relative * diag
    h = dhcd.Hierarchy(V, F)
    E = h.edges()
    t_ours, cs = least(lambda: dhcd.self_contact_set(h, dhat), a.repeat)
    mesh = ipctk.CollisionMesh(
        np.asfortranarray(V), np.asfortranarray(E.astype(np.int32)), np.asfortranarray(F.astype(np.int32))
    )

    def build():
        c = ipctk.NormalCollisions()
        c.build(mesh, V, dhat, broad_phase=ipctk.LBVH())
        return c

    t_ipc, c = least(build, a.repeat)
    ours, theirs = ours_as_dict(cs), theirs_as_dict(c, mesh, V)
    counts = [int((cs.type == k).sum()) for k in range(4)]
    only_ours = sorted(set(ours) - set(theirs))
    only_theirs = sorted(set(theirs) - set(ours))
    differ = sorted(k for k in set(ours) & set(theirs) if ours[k] != theirs[k])
    name = os.path.basename(path)
    equal = "yes" if not (only_ours or only_theirs or differ) else (
        f"{len(only_ours)} only dhcd, {len(only_theirs)} only ipctk, {len(differ)} differ"
    )
    print(
        f"| {name} | {len(F):,} | {dhat:.3g} | {counts[0]:,} / {counts[1]:,} / {counts[2]:,} / "
        f"{counts[3]:,} ({int(cs.mollified.sum()):,}) | {len(c):,} | {equal} | "
        f"{t_ours * 1e3:.1f} ms | {t_ipc * 1e3:.1f} ms | {t_ipc / t_ours:.2f}x |"
    )
    for k in (only_ours + only_theirs + differ)[:12]:
        t, *v = k
        used = [x for x in v if x >= 0]
        d2 = {
            0: lambda: dhcd.distance_sq([0], np.array([np.vstack([V[used], np.zeros((2, 3))])])),
            1: lambda: dhcd.distance_sq([1], np.array([np.vstack([V[used], np.zeros((1, 3))])])),
            2: lambda: dhcd.distance_sq([2], np.array([V[used]])),
            3: lambda: dhcd.distance_sq([3], np.array([V[used]])),
        }[t]()[0]
        where = "only dhcd" if k in only_ours else ("only ipctk" if k in only_theirs else "differ")
        notes.append(
            f"{name} {where}: {NAMES[t]} {used} d^2 {d2:.17g} vs dhat^2 {dhat * dhat:.17g} "
            f"dhcd {ours.get(k)} ipctk {theirs.get(k)}"
        )
for n in notes:
    print(n)
