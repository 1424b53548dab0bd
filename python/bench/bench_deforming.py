"""dhcd against trimesh's CollisionManager (python-fcl) on deforming meshes.

Two cases, each a sequence of frames computed once and then replayed by every
implementation (identical meshes and poses):

- ``pair``: two icospheres (5,120 triangles each) deformed by a travelling wave (enough to
  make them non-convex: trimesh treats a convex mesh as a solid, which changes the
  question) and pushed into each other;
- ``self``: a 2n x n sheet folded back over itself and rippled (it crosses itself along many
  lines), deforming every frame.

Per frame, each implementation does what a user must do to answer the frame's query:

- ``dhcd``: ``update`` (refit, lazily) then ``collide`` / ``self_collide``: the exact list
  of intersecting face pairs;
- ``trimesh``: ``CollisionManager.remove_object`` + ``add_object`` for every object
  (python-fcl cannot refit a model from Python, so the models are rebuilt; trimesh also
  decides convexity every time; ``add_object`` alone would leave the old model registered)
  then ``in_collision_internal(return_names=True)`` (yes/no and the names);
- ``trimesh+data``: the same with ``return_data=True``: fcl's contact list, at most 100,000
  contacts (trimesh's limit), one point per contact;
- ``fcl``: python-fcl directly, the cheapest rebuild a python-fcl user can write
  (``BVHModel`` + ``DynamicAABBTreeCollisionManager``), yes/no.

Self-collision has no fcl query: the sheet is split into its two halves at the fold (two
objects), which is how a trimesh user gets an answer; pairs inside one half are not seen,
and the halves touch along the fold, so fcl reports contact there every frame.

Prints the median time per frame (milliseconds) and the ratio to dhcd, and writes JSON with
``--json FILE``. Timing figures are only meaningful on a quiet machine.

    python bench_deforming.py [--frames 40] [--subdivisions 4] [--sheet 40] [--json out.json]
"""

import argparse
import json
import os
import statistics
import sys
import time

import numpy as np

import dhcd

# The test suite's meshes: one definition of the icosphere, the grid and the wave.
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "tests"))
from meshes import grid, icosphere, wave  # noqa: E402


def pair_case(frames, subdivisions):
    """Two deforming icospheres moving through each other: (faces per object, frames)."""
    va, fa = icosphere(subdivisions)
    vb, fb = icosphere(subdivisions, 0.9)
    poses = []
    for k in range(frames):
        s = k / max(frames - 1, 1)
        poses.append(
            [wave(va, 0.3 * k, 0.12, (0.0, 0.0, 0.0)), wave(vb, -0.3 * k, 0.12, (2.1 - 1.2 * s, 0.15, 0.0))]
        )
    return [fa, fb], poses


def sheet_case(frames, n):
    """A 2n x n sheet folded over itself at x = 1 and rippled, deforming every frame."""
    rest, faces = grid(2 * n, n, 1.0 / n)
    rest = rest.astype(np.float64)
    x, y = rest[:, 0], rest[:, 1]
    right = x > 1.0
    poses = []
    for k in range(frames):
        p = rest.copy()
        p[right, 0] = 2.0 - x[right]
        p[right, 2] = 0.12 * np.sin(7.0 * y[right] + 3.0 * (x[right] - 1.0) + 0.25 * k)
        p[~right, 2] = 0.03 * np.sin(5.0 * y[~right] - 0.2 * k)
        poses.append(p.astype(np.float32))
    # The two halves at the fold (the faces left and right of x = 1 in the rest pose).
    centroid_x = rest[faces].mean(axis=1)[:, 0]
    halves = [faces[centroid_x < 1.0], faces[centroid_x > 1.0]]
    return faces, halves, poses


def median_ms(times):
    return 1000.0 * statistics.median(times)


def timed(frames, step):
    """Runs step(frame) for every frame; the first (warm-up) is not timed."""
    times, results = [], []
    for k, frame in enumerate(frames):
        t = time.perf_counter()
        r = step(frame)
        if k > 0:
            times.append(time.perf_counter() - t)
        results.append(r)
    return median_ms(times), results


def run_dhcd_pair(faces, poses, threads):
    a = dhcd.Hierarchy(poses[0][0], faces[0])
    b = dhcd.Hierarchy(poses[0][1], faces[1])

    def step(frame):
        a.update(frame[0])
        b.update(frame[1])
        return len(dhcd.collide(a, b, threads=threads))

    return timed(poses, step)


def run_dhcd_self(faces, poses, threads):
    h = dhcd.Hierarchy(poses[0], faces)

    def step(frame):
        h.update(frame)
        return len(h.self_collide(threads=threads))

    return timed(poses, step)


def run_trimesh(faces, poses, return_data):
    import trimesh

    manager = trimesh.collision.CollisionManager()

    def step(frame):
        for k, (v, f) in enumerate(zip(frame, faces)):
            # remove, then add: add_object alone leaves the old fcl object registered
            # (trimesh passes its dict, not the object, to unregisterObject).
            if f"o{k}" in manager._objs:
                manager.remove_object(f"o{k}")
            manager.add_object(f"o{k}", trimesh.Trimesh(v, f, process=False))
        if return_data:
            hit, names, data = manager.in_collision_internal(return_names=True, return_data=True)
            return len(data)
        hit, names = manager.in_collision_internal(return_names=True)
        return int(hit)

    return timed(poses, step)


def run_fcl(faces, poses):
    import fcl

    def step(frame):
        objects = []
        for v, f in zip(frame, faces):
            m = fcl.BVHModel()
            m.beginModel(len(v), len(f))
            m.addSubModel(v.astype(np.float64), f)
            m.endModel()
            objects.append(fcl.CollisionObject(m, fcl.Transform()))
        manager = fcl.DynamicAABBTreeCollisionManager()
        manager.registerObjects(objects)
        manager.setup()
        data = fcl.CollisionData()
        manager.collide(data, fcl.defaultCollisionCallback)
        return int(data.result.is_collision)

    return timed(poses, step)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--frames", type=int, default=40)
    ap.add_argument("--subdivisions", type=int, default=4, help="icosphere level (4: 5,120 triangles)")
    ap.add_argument("--sheet", type=int, default=40, help="sheet of 2n x n cells (40: 6,400 triangles)")
    ap.add_argument("--threads", type=int, default=1, help="dhcd threads per query")
    ap.add_argument("--json", help="write the results here")
    args = ap.parse_args()
    if args.frames < 2:
        ap.error("--frames must be at least 2 (the first frame is a warm-up)")

    try:
        import fcl  # noqa: F401
        import trimesh  # noqa: F401
        peers = True
    except ImportError:
        print("trimesh or python-fcl not installed: timing dhcd only", file=sys.stderr)
        peers = False

    rows = []
    faces, poses = pair_case(args.frames, args.subdivisions)
    ms, contacts = run_dhcd_pair(faces, poses, args.threads)
    case = {"case": "pair", "triangles": [len(f) for f in faces], "frames": args.frames}
    case["dhcd"] = {"median_ms": ms, "returns": "exact face pairs", "contacts": contacts}
    if peers:
        for name, fn, what in [
            ("trimesh", lambda: run_trimesh(faces, poses, False), "yes/no and object names"),
            ("trimesh+data", lambda: run_trimesh(faces, poses, True), "fcl contacts (<= 100,000)"),
            ("fcl", lambda: run_fcl(faces, poses), "yes/no"),
        ]:
            t, r = fn()
            case[name] = {"median_ms": t, "returns": what, "contacts": r}
    rows.append(case)

    sheet_faces, halves, sheet_poses = sheet_case(args.frames, args.sheet)
    ms, contacts = run_dhcd_self(sheet_faces, sheet_poses, args.threads)
    case = {"case": "self", "triangles": [len(sheet_faces)], "frames": args.frames}
    case["dhcd"] = {"median_ms": ms, "returns": "exact face pairs", "contacts": contacts}
    if peers:
        # The halves as separate objects: the vertex arrays are shared, faces split.
        halves_poses = [[p, p] for p in sheet_poses]
        for name, fn, what in [
            ("trimesh", lambda: run_trimesh(halves, halves_poses, False), "yes/no (halves)"),
            ("trimesh+data", lambda: run_trimesh(halves, halves_poses, True), "fcl contacts between halves (<= 100,000)"),
            ("fcl", lambda: run_fcl(halves, halves_poses), "yes/no (halves)"),
        ]:
            t, r = fn()
            case[name] = {"median_ms": t, "returns": what, "contacts": r}
    rows.append(case)

    print(f"median time per frame over {args.frames - 1} frames (ms); ratio = time / dhcd's")
    print(f"{'case':6} {'implementation':14} {'ms/frame':>10} {'ratio':>8}  returns (contacts in the last frame)")
    for case in rows:
        base = case["dhcd"]["median_ms"]
        for name in ["dhcd", "trimesh", "trimesh+data", "fcl"]:
            if name in case:
                r = case[name]
                last = r["contacts"][-1]
                print(
                    f"{case['case']:6} {name:14} {r['median_ms']:10.2f} {r['median_ms'] / base:8.1f}  "
                    f"{r['returns']} ({last})"
                )
    if args.json:
        for case in rows:
            for name in ["dhcd", "trimesh", "trimesh+data", "fcl"]:
                if name in case:
                    case[name]["contacts_last_frame"] = case[name].pop("contacts")[-1]
        with open(args.json, "w") as out:
            json.dump(rows, out, indent=2)


if __name__ == "__main__":
    main()
