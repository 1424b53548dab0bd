"""An exact brute force of proximity, written independently of dhcd: every vertex-triangle
and edge-edge pair within a distance, its squared distance and IPC's distance type, in
rational arithmetic (Fractions of the float coordinates, which are exact), so the decision
"distance <= d" is exact for any float input.

The type of a pair is the sub-feature pair (corner, open edge, open face) holding a closest
pair of points, of least dimension, then first in IPC's order (dhcd's documented rule): the
candidates below are listed in that order, each with the least distance between its two
sub-features when that least distance is attained inside them.
"""

from fractions import Fraction

import numpy as np

POINT_TRIANGLE = ["P_T0", "P_T1", "P_T2", "P_E0", "P_E1", "P_E2", "P_T"]
EDGE_EDGE = [
    "EA0_EB0", "EA0_EB1", "EA1_EB0", "EA1_EB1",
    "EA_EB0", "EA_EB1", "EA0_EB", "EA1_EB", "EA_EB",
]


def _sub(a, b):
    return (a[0] - b[0], a[1] - b[1], a[2] - b[2])


def _dot(a, b):
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


def _cross(a, b):
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


def _points(vertices):
    return [tuple(Fraction(float(x)) for x in p) for p in np.asarray(vertices)]


def _to_open_segment(p, a, b):
    """Squared distance from p to the open segment (a, b) if its foot is strictly inside."""
    e = _sub(b, a)
    length = _dot(e, e)
    if length == 0:
        return None
    t = _dot(_sub(p, a), e) / length
    if not 0 < t < 1:
        return None
    w = _sub(p, a)
    return _dot(w, w) - t * t * length


def point_triangle(p, t):
    """(squared distance, type number) of point p and the closed triangle t."""
    cands = [_dot(_sub(p, c), _sub(p, c)) for c in t]
    cands += [_to_open_segment(p, t[i], t[(i + 1) % 3]) for i in range(3)]
    n = _cross(_sub(t[1], t[0]), _sub(t[2], t[0]))
    face = None
    if n != (0, 0, 0):
        inside = all(
            _dot(n, _cross(_sub(t[(i + 1) % 3], t[i]), _sub(p, t[i]))) > 0 for i in range(3)
        )
        if inside:
            s = _dot(n, _sub(p, t[0]))
            face = s * s / _dot(n, n)
    cands.append(face)
    best = min(c for c in cands if c is not None)
    return best, next(k for k, c in enumerate(cands) if c == best)


def edge_edge(a0, a1, b0, b1):
    """(squared distance, type number) of the closed segments [a0, a1] and [b0, b1]."""
    sq = lambda x, y: _dot(_sub(x, y), _sub(x, y))  # noqa: E731
    cands = [sq(a0, b0), sq(a0, b1), sq(a1, b0), sq(a1, b1)]
    cands += [
        _to_open_segment(b0, a0, a1),
        _to_open_segment(b1, a0, a1),
        _to_open_segment(a0, b0, b1),
        _to_open_segment(a1, b0, b1),
    ]
    u, v, w = _sub(a1, a0), _sub(b1, b0), _sub(a0, b0)
    n = _cross(u, v)
    both = None
    if n != (0, 0, 0):
        uu, uv, vv, uw, vw = _dot(u, u), _dot(u, v), _dot(v, v), _dot(u, w), _dot(v, w)
        den = uu * vv - uv * uv
        s = (uv * vw - vv * uw) / den
        t = (uu * vw - uv * uw) / den
        if 0 < s < 1 and 0 < t < 1:
            k = _dot(n, w)
            both = k * k / _dot(n, n)
    cands.append(both)
    best = min(c for c in cands if c is not None)
    return best, next(k for k, c in enumerate(cands) if c == best)


def edges(faces):
    """The unique edges of the faces, each as (smaller, larger) vertex index, sorted."""
    out = set()
    for f in np.asarray(faces).tolist():
        for i in range(3):
            a, b = f[i], f[(i + 1) % 3]
            out.add((min(a, b), max(a, b)))
    return sorted(out)


def _near(lo_a, hi_a, lo_b, hi_b, d):
    """Whether two boxes (float64 bounds of exact values) come within d on every axis."""
    return bool(np.all(lo_a - d <= hi_b) and np.all(lo_b - d <= hi_a))


def _vertex_face(pv, used, pt, faces, d2, dbox, skip_own):
    out = []
    tris = [tuple(pt[k] for k in f) for f in faces]
    boxes = [
        (np.array([min(c[i] for c in t) for i in range(3)], dtype=float),
         np.array([max(c[i] for c in t) for i in range(3)], dtype=float))
        for t in tris
    ]
    for v in used:
        p = pv[v]
        fp = np.array(p, dtype=float)
        for j, t in enumerate(tris):
            if skip_own and v in faces[j]:
                continue
            if not _near(fp, fp, boxes[j][0], boxes[j][1], dbox):
                continue
            dist, kind = point_triangle(p, t)
            if dist <= d2:
                out.append((v, j, dist, kind))
    return out


def _edge_pairs(pa, ea, pb, eb, d2, dbox, same):
    out = []
    boxes_b = [
        (np.minimum(np.array(pb[x], float), np.array(pb[y], float)),
         np.maximum(np.array(pb[x], float), np.array(pb[y], float)))
        for x, y in eb
    ]
    for i, (a0, a1) in enumerate(ea):
        lo = np.minimum(np.array(pa[a0], float), np.array(pa[a1], float))
        hi = np.maximum(np.array(pa[a0], float), np.array(pa[a1], float))
        for j, (b0, b1) in enumerate(eb):
            if same and (j <= i or {a0, a1} & {b0, b1}):
                continue
            if not _near(lo, hi, boxes_b[j][0], boxes_b[j][1], dbox):
                continue
            dist, kind = edge_edge(pa[a0], pa[a1], pb[b0], pb[b1])
            if dist <= d2:
                out.append((a0, a1, b0, b1, dist, kind))
    return out


def proximity(va, fa, vb, fb, d):
    """The pairs of mesh A and mesh B within d: (vertex_face, face_vertex, edge_edge), each a
    sorted list of tuples (indices..., exact squared distance, type number)."""
    pa, pb = _points(va), _points(vb)
    fa, fb = np.asarray(fa).tolist(), np.asarray(fb).tolist()
    d2 = Fraction(d) ** 2
    dbox = float(d) * (1 + 1e-9) + 1e-300  # a box filter that never drops a pair
    vf = _vertex_face(pa, range(len(pa)), pb, fb, d2, dbox, False)
    fv = [(t, v, x, k) for v, t, x, k in _vertex_face(pb, range(len(pb)), pa, fa, d2, dbox, False)]
    ee = _edge_pairs(pa, edges(fa), pb, edges(fb), d2, dbox, False)
    return sorted(vf), sorted(fv), sorted(ee)


def self_proximity(v, f, d):
    """The pairs of one mesh within d: a vertex and a face not containing it, two edges
    sharing no vertex (smaller edge first)."""
    p = _points(v)
    f = np.asarray(f).tolist()
    d2 = Fraction(d) ** 2
    dbox = float(d) * (1 + 1e-9) + 1e-300
    vf = _vertex_face(p, range(len(p)), p, f, d2, dbox, True)
    e = edges(f)
    ee = _edge_pairs(p, e, p, e, d2, dbox, True)
    return sorted(vf), [], sorted(ee)
