"""Test meshes (numpy only) and an exact brute-force oracle written independently of dhcd.

The oracle decides whether two closed, non-degenerate triangles intersect with the
separating axis theorem in exact integer arithmetic: every float32 coordinate is an integer
multiple of a common power of two, so after scaling, all dot and cross products are exact
Python ints. Axes: both normals, the nine edge-edge cross products (enough when the
triangles are not coplanar) and each triangle's in-plane edge normals (enough when they
are). Disjoint iff the projections are disjoint on some axis.
"""

from fractions import Fraction
import numpy as np


def icosphere(subdivisions=1, radius=1.0, center=(0.0, 0.0, 0.0)):
    """An icosahedron subdivided `subdivisions` times, on a sphere: float32 vertices, int64
    faces (20 * 4**s triangles)."""
    t = (1.0 + 5.0**0.5) / 2.0
    v = [
        (-1, t, 0), (1, t, 0), (-1, -t, 0), (1, -t, 0),
        (0, -1, t), (0, 1, t), (0, -1, -t), (0, 1, -t),
        (t, 0, -1), (t, 0, 1), (-t, 0, -1), (-t, 0, 1),
    ]
    f = [
        (0, 11, 5), (0, 5, 1), (0, 1, 7), (0, 7, 10), (0, 10, 11),
        (1, 5, 9), (5, 11, 4), (11, 10, 2), (10, 7, 6), (7, 1, 8),
        (3, 9, 4), (3, 4, 2), (3, 2, 6), (3, 6, 8), (3, 8, 9),
        (4, 9, 5), (2, 4, 11), (6, 2, 10), (8, 6, 7), (9, 8, 1),
    ]
    verts = [np.array(p, dtype=np.float64) / np.linalg.norm(p) for p in v]
    for _ in range(subdivisions):
        mid = {}

        def midpoint(a, b):
            key = (min(a, b), max(a, b))
            if key not in mid:
                m = verts[a] + verts[b]
                verts.append(m / np.linalg.norm(m))
                mid[key] = len(verts) - 1
            return mid[key]

        f = [
            face
            for a, b, c in f
            for face in (
                (a, midpoint(a, b), midpoint(c, a)),
                (b, midpoint(b, c), midpoint(a, b)),
                (c, midpoint(c, a), midpoint(b, c)),
                (midpoint(a, b), midpoint(b, c), midpoint(c, a)),
            )
        ]
    vertices = (np.array(verts) * radius + np.asarray(center)).astype(np.float32)
    return vertices, np.array(f, dtype=np.int64)


def grid(nx, ny, cell=1.0):
    """A flat nx x ny grid of square cells in z = 0, two triangles per cell."""
    xs, ys = np.meshgrid(np.arange(nx + 1), np.arange(ny + 1), indexing="ij")
    vertices = np.stack([xs.ravel(), ys.ravel(), np.zeros(xs.size)], axis=1) * cell
    idx = lambda i, j: i * (ny + 1) + j  # noqa: E731
    faces = []
    for i in range(nx):
        for j in range(ny):
            faces.append((idx(i, j), idx(i + 1, j), idx(i + 1, j + 1)))
            faces.append((idx(i, j), idx(i + 1, j + 1), idx(i, j + 1)))
    return vertices.astype(np.float32), np.array(faces, dtype=np.int64)


def wave(vertices, t, amplitude, offset=(0.0, 0.0, 0.0)):
    """A smooth non-rigid deformation of `vertices` at time t, then a shift."""
    v = np.asarray(vertices, dtype=np.float64)
    d = amplitude * np.stack(
        [
            np.sin(3.0 * v[:, 1] + t),
            np.sin(2.0 * v[:, 2] + 1.3 * t),
            np.sin(2.5 * v[:, 0] - 0.7 * t),
        ],
        axis=1,
    )
    return (v + d + np.asarray(offset)).astype(np.float32)


def folded_grid(n=6, t=0.0):
    """A 2n x n grid folded back over itself and rippled, so it crosses itself: returns the
    flat rest pose, the folded pose and the faces."""
    rest, faces = grid(2 * n, n, 1.0 / n)
    x, y = rest[:, 0].astype(np.float64), rest[:, 1].astype(np.float64)
    folded = rest.astype(np.float64).copy()
    right = x > 1.0
    folded[right, 0] = 2.0 - x[right]
    folded[right, 2] = 0.12 * np.sin(7.0 * y[right] + 3.0 * (x[right] - 1.0) + t)
    return rest, folded.astype(np.float32), faces


def _scaled(points32):
    """Exact integer coordinates: float32 values times a common power of two."""
    fr = [Fraction(float(x)) for x in np.asarray(points32, dtype=np.float32).ravel()]
    scale = 1
    for f in fr:
        scale = max(scale, f.denominator)
    ints = [int(f * scale) for f in fr]
    return np.array(ints, dtype=object).reshape(-1, 3)


def _sub(a, b):
    return (a[0] - b[0], a[1] - b[1], a[2] - b[2])


def _cross(a, b):
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


def _dot(a, b):
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


def _triangles_intersect(p, q):
    """Exact: do closed non-degenerate triangles p and q (3 int points each) meet?"""
    ep = [_sub(p[1], p[0]), _sub(p[2], p[1]), _sub(p[0], p[2])]
    eq = [_sub(q[1], q[0]), _sub(q[2], q[1]), _sub(q[0], q[2])]
    np_, nq = _cross(ep[0], ep[1]), _cross(eq[0], eq[1])
    assert np_ != (0, 0, 0) and nq != (0, 0, 0), "the oracle needs non-degenerate triangles"
    axes = [np_, nq]
    axes += [_cross(a, b) for a in ep for b in eq]
    axes += [_cross(np_, a) for a in ep] + [_cross(nq, b) for b in eq]
    for axis in axes:
        if axis == (0, 0, 0):
            continue
        sp = [_dot(axis, x) for x in p]
        sq = [_dot(axis, x) for x in q]
        if max(sp) < min(sq) or max(sq) < min(sp):
            return False
    return True


def _candidates(va, fa, vb, fb):
    """Face pairs whose closed float32 boxes overlap (exact comparisons)."""
    ta, tb = va[fa], vb[fb]  # (m, 3, 3)
    lo_a, hi_a = ta.min(axis=1), ta.max(axis=1)
    lo_b, hi_b = tb.min(axis=1), tb.max(axis=1)
    overlap = np.all(
        (lo_a[:, None, :] <= hi_b[None, :, :]) & (lo_b[None, :, :] <= hi_a[:, None, :]),
        axis=2,
    )
    return np.argwhere(overlap)


def brute_force_pairs(va, fa, vb, fb):
    """Every [i, j] such that face i of A and face j of B intersect, sorted."""
    va = np.asarray(va, dtype=np.float32)
    vb = np.asarray(vb, dtype=np.float32)
    s = _scaled(np.concatenate([va, vb]))
    sa, sb = s[: len(va)], s[len(va) :]
    out = []
    for i, j in _candidates(va, fa, vb, fb):
        p = [tuple(sa[k]) for k in fa[i]]
        q = [tuple(sb[k]) for k in fb[j]]
        if _triangles_intersect(p, q):
            out.append((int(i), int(j)))
    return np.array(sorted(out), dtype=np.int64).reshape(-1, 2)


def brute_force_self_pairs(v, f):
    """Every [i, j], i < j, of intersecting faces of one mesh sharing no vertex index."""
    v = np.asarray(v, dtype=np.float32)
    s = _scaled(v)
    out = []
    for i, j in _candidates(v, f, v, f):
        if i >= j or set(f[i].tolist()) & set(f[j].tolist()):
            continue
        p = [tuple(s[k]) for k in f[i]]
        q = [tuple(s[k]) for k in f[j]]
        if _triangles_intersect(p, q):
            out.append((int(i), int(j)))
    return np.array(sorted(out), dtype=np.int64).reshape(-1, 2)
