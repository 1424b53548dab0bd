"""Collision detection between deformable triangle meshes (dhcd).

Build a hierarchy once from a rest pose, hand it new vertex positions every step (it is
refitted lazily, never rebuilt) and query: every pair of faces whose closed triangles
intersect, every vertex-face and edge-edge pair within a distance (proximity), and every
vertex-face and edge-edge pair that collides while the vertices move linearly over a step
(continuous collision detection, CCD), decided exactly for the coordinates as given, as
sorted numpy arrays of the caller's indices.

Inputs: ``vertices`` is an ``(n, 3)`` array of real numbers, ``faces`` an ``(m, 3)`` integer
array of vertex indices. Precision follows the vertices' dtype (numpy's:
``numpy.asarray(vertices).dtype``, so a list of Python floats is float64): float64 builds an
``"f64"`` hierarchy, exact for the doubles (never rounded to float32); float32 and every
other real dtype (integers, float16, longdouble) an ``"f32"`` one (others converted once to
float32). Updates must then be of the same float type: float32 for ``"f32"``, float64 for
``"f64"``; the other raises ``ValueError`` (mismatched precision) and changes nothing, and
other real dtypes are converted to the hierarchy's precision. Bad input (wrong shape, a dtype
that cannot convert, NaN or infinite coordinates, float64 coordinates beyond float32's range
(bounds are float32), an index out of range, a face repeating a vertex, an empty mesh, an
unknown method, a negative, NaN or infinite distance, a file that cannot be parsed) raises
``ValueError`` with the library's message; a file that cannot be read raises ``OSError``
(``FileNotFoundError`` if missing).

CCD positions are float64 only, for hierarchies of either precision: any other dtype
raises ``ValueError`` and is never converted (the answers are exact for the doubles given;
convert explicitly, e.g. ``x.astype(numpy.float64)``).

Threads: queries and updates release the GIL, so Python threads may query different objects
at the same time. One object used by two threads at once raises ``RuntimeError`` (it is
borrowed). ``threads`` arguments: 1 runs on the calling thread, 0 on all cores, n on a pool of
n threads; results never depend on it.
"""

import os
from typing import (
    Any,
    Dict,
    Iterable,
    List,
    Literal,
    Mapping,
    Optional,
    Set,
    Tuple,
    Union,
    overload,
)

import numpy as np
import numpy.typing as npt

__all__ = [
    "EDGE_EDGE_TYPES",
    "POINT_TRIANGLE_TYPES",
    "CollisionManager",
    "ContactSet",
    "Contacts",
    "Hierarchy",
    "Impacts",
    "Proximity",
    "Scene",
    "ccd",
    "collide",
    "collision_free_stepsize",
    "contact_segments",
    "contact_set",
    "distance_gradient",
    "distance_hessian",
    "distance_sq",
    "edge_edge_ccd",
    "load_mesh",
    "max_pairs",
    "proximity",
    "self_contact_set",
    "self_proximity",
    "set_max_pairs",
    "vertex_face_ccd",
]

POINT_TRIANGLE_TYPES: List[str]
"""IPC's names of the point-triangle distance types, indexed by the numbers in
``Proximity.vf_type`` / ``fv_type``: ``["P_T0", "P_T1", "P_T2", "P_E0", "P_E1", "P_E2",
"P_T"]`` (closest to a corner, an open edge (edge ``i`` joins corners ``i`` and ``i + 1``),
the open face)."""

EDGE_EDGE_TYPES: List[str]
"""IPC's names of the edge-edge distance types, indexed by the numbers in
``Proximity.ee_type``: ``["EA0_EB0", "EA0_EB1", "EA1_EB0", "EA1_EB1", "EA_EB0", "EA_EB1",
"EA0_EB", "EA1_EB", "EA_EB"]`` (``EA0`` the end ``a0``, ``EA`` the open edge ``a``)."""

Precision = Literal["f32", "f64"]

Method = Literal["dh", "sphere", "aabb", "sbv"]
"""Method (bounding-volume hierarchy): ``"dh"`` (Distance Hierarchy, 8-byte nodes), ``"sphere"`` (16
bytes; alias ``"sbv"``), ``"aabb"`` (24 bytes). Case-insensitive."""

Vertices = npt.ArrayLike
Faces = npt.ArrayLike
Positions64 = npt.ArrayLike
"""CCD positions: an ``(n, 3)`` float64 array (numpy's dtype of ``numpy.asarray(x)``; a
list of Python floats is float64), in the mesh's vertex order."""
Queries64 = npt.ArrayLike
"""Single-pair CCD queries: an ``(N, 4, 3)`` float64 array, four points per query."""
# `Scene.update_many` and `Scene.step`: `{id or name: vertices}` or `[(id or name, vertices)]`.
Updates = Union[Mapping[Union[int, str], Vertices], Iterable[Tuple[Union[int, str], Vertices]]]
# `Scene.ccd`: `{id or name: (x0, x1)}` or `[(id or name, (x0, x1))]`.
Motions = Union[
    Mapping[Union[int, str], Tuple[Positions64, Positions64]],
    Iterable[Tuple[Union[int, str], Tuple[Positions64, Positions64]]],
]

class Contacts:
    """The result of a query."""

    @property
    def pairs(self) -> npt.NDArray[np.int64]:
        """Sorted rows of intersecting faces: ``(K, 2)`` ``[face_a, face_b]`` from
        ``collide`` (``face_a < face_b`` from ``self_collide``), ``(K, 4)``
        ``[object_a, face_a, object_b, face_b]`` from ``Scene.contacts``."""
    @property
    def counters(self) -> Dict[str, int]:
        """The work of the query: ``bv_tests`` (bounding-volume pairs tested),
        ``prim_tests`` (triangle pairs tested), ``bv_updates`` (bounding volumes refitted),
        ``contacts``."""
    def __len__(self) -> int:
        """The number of pairs."""

class Proximity:
    """The result of a proximity query: every pair of features within the distance, each
    list sorted by its rows, with its squared distance and IPC's distance type (a number:
    ``POINT_TRIANGLE_TYPES`` / ``EDGE_EDGE_TYPES`` name them). The decision "within ``d``"
    is exact for the coordinates as given; the squared distance is within a few ulps.

    From ``proximity(a, b, d)`` (``self_proximity`` likewise, ``face_vertex`` empty)::

        vertex_face  (K, 2) [vertex of a, face of b]     (self: a face not containing it)
        face_vertex  (K, 2) [face of a, vertex of b]
        edge_edge    (K, 4) [a0, a1, b0, b1]             (a0 < a1, b0 < b1; self:
                                                          (a0, a1) < (b0, b1), no shared vertex)

    From ``Scene.proximity(d)``, rows with object ids (``object_a < object_b``, or ``==``
    inside an object with self-collision on)::

        vertex_face  (K, 4) [object_a, vertex, object_b, face]
        face_vertex  (K, 4) [object_a, face, object_b, vertex]
        edge_edge    (K, 6) [object_a, a0, a1, object_b, b0, b1]
    """

    @property
    def vertex_face(self) -> npt.NDArray[np.int64]: ...
    @property
    def vf_distance_sq(self) -> npt.NDArray[np.float64]:
        """``(K,)`` squared distances of the ``vertex_face`` rows."""
    @property
    def vf_type(self) -> npt.NDArray[np.uint8]:
        """``(K,)`` point-triangle types of the ``vertex_face`` rows."""
    @property
    def face_vertex(self) -> npt.NDArray[np.int64]: ...
    @property
    def fv_distance_sq(self) -> npt.NDArray[np.float64]: ...
    @property
    def fv_type(self) -> npt.NDArray[np.uint8]: ...
    @property
    def edge_edge(self) -> npt.NDArray[np.int64]: ...
    @property
    def ee_distance_sq(self) -> npt.NDArray[np.float64]: ...
    @property
    def ee_type(self) -> npt.NDArray[np.uint8]:
        """``(K,)`` edge-edge types of the ``edge_edge`` rows."""
    @property
    def counters(self) -> Dict[str, int]:
        """``bv_tests``, ``bv_updates`` as for contacts, ``prim_tests`` the feature pairs
        given to the exact test, ``contacts`` the pairs reported."""
    def __len__(self) -> int:
        """The number of pairs of the three lists."""

class Impacts:
    """The result of a CCD query: every vertex-face, face-vertex and edge-edge pair that
    collides during the step, each list sorted by its rows, with its time of impact
    (float64, in ``[0, t_max]``). Whether a pair collides (comes within ``min_distance``,
    touching when it is 0, at some time in ``[0, t_max]``) is decided exactly for the
    float64 positions; a time of impact is never later than the pair's first contact and at
    most ``1e-12`` before it.

    From ``ccd(a, b, a0, a1, b0, b1)`` (``ccd(h, x0, x1)`` likewise, ``face_vertex``
    empty)::

        vertex_face  (K, 2) [vertex of a, face of b]     (self: a face not containing it)
        face_vertex  (K, 2) [face of a, vertex of b]
        edge_edge    (K, 4) [a0, a1, b0, b1]             (a0 < a1, b0 < b1; self:
                                                          (a0, a1) < (b0, b1), no shared vertex)

    From ``Scene.ccd(motions)``, rows with object ids (``object_a < object_b``, or ``==``
    inside an object with self-collision on)::

        vertex_face  (K, 4) [object_a, vertex, object_b, face]
        face_vertex  (K, 4) [object_a, face, object_b, vertex]
        edge_edge    (K, 6) [object_a, a0, a1, object_b, b0, b1]

    With ``earliest=True`` the lists hold only the pairs whose time of impact is ``toi``.
    """

    @property
    def vertex_face(self) -> npt.NDArray[np.int64]: ...
    @property
    def vf_toi(self) -> npt.NDArray[np.float64]:
        """``(K,)`` times of impact of the ``vertex_face`` rows."""
    @property
    def face_vertex(self) -> npt.NDArray[np.int64]: ...
    @property
    def fv_toi(self) -> npt.NDArray[np.float64]: ...
    @property
    def edge_edge(self) -> npt.NDArray[np.int64]: ...
    @property
    def ee_toi(self) -> npt.NDArray[np.float64]: ...
    @property
    def toi(self) -> float:
        """The earliest time of impact of the step (the least of the rows' times), ``inf``
        when nothing collides."""
    @property
    def counters(self) -> Dict[str, int]:
        """``bv_tests`` (node pairs tested over the step), ``bv_updates`` (bounds fitted over
        the step), ``prim_tests`` (feature pairs given to the exact test), ``contacts``
        (pairs reported)."""
    def __len__(self) -> int:
        """The number of pairs of the three lists."""

class Hierarchy:
    """The bounding-volume hierarchy of one deformable mesh; ``vertices`` is its rest pose
    (float64: an ``"f64"`` hierarchy, otherwise ``"f32"``).

    ``levels``: ``None`` for the adaptive region tree (the default), or a fixed depth
    (the paper uses 5).
    """

    def __init__(
        self,
        vertices: Vertices,
        faces: Faces,
        method: Method = "dh",
        levels: Optional[int] = None,
    ) -> None: ...
    def update(self, vertices: Vertices) -> None:
        """New positions of the mesh's vertices (same shape, the hierarchy's float type:
        the other raises ``ValueError``). The hierarchy is refitted lazily by the next
        query, not rebuilt. On error nothing changes."""
    def self_collide(self, threads: int = 1) -> Contacts:
        """Intersecting face pairs ``[i, j]``, ``i < j``, of this mesh; pairs sharing a
        vertex index are never reported."""
    @property
    def method(self) -> str:
        """``"dh"``, ``"sphere"`` or ``"aabb"``."""
    @property
    def precision(self) -> Precision:
        """``"f32"`` or ``"f64"``: the float type the hierarchy was built from and takes."""
    @property
    def bytes_per_node(self) -> int:
        """Size of one node record: 8, 16 or 24."""
    @property
    def vertex_count(self) -> int: ...
    @property
    def face_count(self) -> int: ...
    def edges(self) -> npt.NDArray[np.int64]:
        """The mesh's unique edges, ``(E, 2)`` int64, smaller vertex first, sorted: the edge
        ids of ``ContactSet.edges``."""

class ContactSet:
    """Every pair of features within ``dhat``, once, with the IPC Toolkit's collision type
    (``NormalCollisions.build``'s rules): a vertex near a vertex (PP), near the interior of an
    edge (PE) or of a face (PT), and two edges whose closest points are interior to both, or
    that are nearly parallel (EE, ``mollified``). Sorted by type, then vertices."""

    @property
    def vertices(self) -> npt.NDArray[np.int64]:
        """``(K, 4)``, ``-1``-padded: PP ``[v, w]`` (``v < w``), PE ``[v, e0, e1]``
        (``e0 < e1``), PT ``[v, t0, t1, t2]``, EE ``[a0, a1, b0, b1]``."""
    @property
    def type(self) -> npt.NDArray[np.uint8]:
        """``(K,)``: 0 PP, 1 PE, 2 PT, 3 EE."""
    @property
    def distance_sq(self) -> npt.NDArray[np.float64]:
        """``(K,)`` squared distances of the closest features."""
    @property
    def weights(self) -> npt.NDArray[np.float64]:
        """``(K, 4)``: ``sum_i weights[k, i] * x[vertices[k, i]]`` is the vector between the
        closest points (the first feature's minus the second's; ipctk's
        ``compute_coefficients``); 0 in unused slots."""
    @property
    def mollified(self) -> npt.NDArray[np.bool_]:
        """``(K,)``: EE rows of nearly parallel edges (``|a x b|^2 < 1e-3 |a|^2 |b|^2`` at
        rest, decided exactly), measured by their closest features' formula."""
    @property
    def edges(self) -> npt.NDArray[np.int64]:
        """``(K, 2)`` edge ids (``Hierarchy.edges()``; in a pair query ``b``'s are offset by
        ``len(a.edges())``): PE ``[e, -1]``, EE ``[a, b]``, else ``[-1, -1]``."""
    @property
    def counters(self) -> Dict[str, int]: ...
    def gradient(self) -> npt.NDArray[np.float64]:
        """``(K, 12)``: the gradient of each row's squared distance with respect to its
        four vertices' coordinates (slot ``i``, coordinate ``c`` at ``3 i + c``)."""
    def hessian(self) -> npt.NDArray[np.float64]:
        """``(K, 12, 12)``: the Hessian of each row's squared distance."""
    def __len__(self) -> int: ...

def self_contact_set(
    h: Hierarchy, dhat: float, rest: Optional[Vertices] = None, threads: int = 1
) -> ContactSet:
    """Every pair of features of one mesh within ``dhat`` (finite, ``>= 0``), once.
    ``rest``: the rest positions of the mollifier test (default: those ``h`` was built
    with)."""

def contact_set(
    a: Hierarchy,
    b: Hierarchy,
    dhat: float,
    rest_a: Optional[Vertices] = None,
    rest_b: Optional[Vertices] = None,
    threads: int = 1,
) -> ContactSet:
    """Every pair of features of ``a`` and ``b`` within ``dhat``, once; vertices numbered
    ``a``'s first, then ``b``'s (offset by ``a.vertex_count``), edges likewise."""

@overload
def collision_free_stepsize(
    h: Hierarchy,
    x0: Positions64,
    x1: Positions64,
    min_distance: float = 0.0,
    rescaling: float = 0.8,
    threads: int = 1,
) -> float:
    """The largest fraction of the step ``x0 -> x1`` (float64 ``(n, 3)``), in ``[0, 1]``,
    that keeps every vertex-face and edge-edge pair at least ``min_distance + (1 -
    rescaling) * (d0 - min_distance)`` apart, ``d0`` its distance at ``x0`` (the IPC
    Toolkit's rule, applied exactly to every pair; ipctk caps that gap at 1e-4). Never past
    the earliest impact at ``min_distance`` (within 1e-12 below it), 1.0 when no pair comes
    within its gap. A line search starts at ``alpha = collision_free_stepsize(...)`` and
    only shrinks it. ``rescaling`` outside ``(0, 1]`` or a bad ``min_distance`` raises
    ``ValueError``."""

@overload
def collision_free_stepsize(
    a: Hierarchy,
    b: Hierarchy,
    a0: Positions64,
    a1: Positions64,
    b0: Positions64,
    b1: Positions64,
    min_distance: float = 0.0,
    rescaling: float = 0.8,
    threads: int = 1,
) -> float:
    """The step size of the pairs between two meshes (as for one)."""

def distance_sq(
    types: npt.ArrayLike, x: npt.NDArray[np.float64]
) -> npt.NDArray[np.float64]:
    """``(K,)``: the squared distance of each row's type (0 PP, 1 PE, 2 PT, 3 EE; another
    value raises ``ValueError``) at ``x`` float64 ``(K, 4, 3)`` (unused slots ignored)."""

def distance_gradient(
    types: npt.ArrayLike, x: npt.NDArray[np.float64]
) -> npt.NDArray[np.float64]:
    """``(K, 12)``: the gradient of ``distance_sq``."""

def distance_hessian(
    types: npt.ArrayLike, x: npt.NDArray[np.float64]
) -> npt.NDArray[np.float64]:
    """``(K, 12, 12)``: the Hessian of ``distance_sq``."""

def collide(a: Hierarchy, b: Hierarchy, threads: int = 1) -> Contacts:
    """Every pair ``[face of a, face of b]`` of intersecting faces. ``a`` and ``b`` must be
    different hierarchies of the same method."""

def contact_segments(
    a: Hierarchy, b: Hierarchy, pairs: npt.ArrayLike
) -> npt.NDArray[np.float32]:
    """The intersection segment ``[p, q]`` of each pair (e.g. ``collide(a, b).pairs``) in the
    current poses: a ``(K, 2, 3)`` float32 array (``p == q`` for a single point). For
    self-contacts pass the same hierarchy twice. A pair that does not intersect in the
    current pose raises ``ValueError``."""

def proximity(a: Hierarchy, b: Hierarchy, d: float, threads: int = 1) -> Proximity:
    """Every vertex-face, face-vertex and edge-edge pair of ``a`` and ``b`` (different
    hierarchies of the same method, either precision) whose closed features are within
    distance ``d`` (finite, ``>= 0``), decided exactly."""

def self_proximity(h: Hierarchy, d: float, threads: int = 1) -> Proximity:
    """Every pair of one mesh within distance ``d``: a vertex and a face not containing
    it, two edges sharing no vertex."""

@overload
def ccd(
    h: Hierarchy,
    x0: Positions64,
    x1: Positions64,
    *,
    min_distance: float = 0.0,
    earliest: bool = False,
    t_max: float = 1.0,
    threads: int = 1,
) -> Impacts:
    """Continuous collision detection of one mesh over a step: every vertex moves on the
    straight line from its position in ``x0`` (t = 0) to its position in ``x1`` (t = 1);
    every vertex-face pair (the face not containing the vertex) and edge-edge pair (sharing
    no vertex) that comes within ``min_distance`` (``0``: touches) at some t in
    ``[0, t_max]``. ``x0``, ``x1``: float64 ``(n, 3)``, n the mesh's vertex count (finite,
    within float32's range), for a hierarchy of either precision (its own pose is not
    used or changed). ``earliest=True``: only the earliest time of impact and every pair
    whose own time is within 1e-12 of it (what a line search asks; every exact tie is there). Exact for the doubles (see ``Impacts``); the
    result does not depend on ``threads`` (the work counters of earliest mode may)."""

@overload
def ccd(
    a: Hierarchy,
    b: Hierarchy,
    a0: Positions64,
    a1: Positions64,
    b0: Positions64,
    b1: Positions64,
    *,
    min_distance: float = 0.0,
    earliest: bool = False,
    t_max: float = 1.0,
    threads: int = 1,
) -> Impacts:
    """Continuous collision detection between two meshes over a step, ``a`` moving from
    ``a0`` to ``a1`` and ``b`` from ``b0`` to ``b1``: every vertex of ``a`` against every
    face of ``b`` (``vertex_face``), every face of ``a`` against every vertex of ``b``
    (``face_vertex``) and every edge of ``a`` against every edge of ``b`` (``edge_edge``).
    ``a`` and ``b`` are different hierarchies of the same method, either precision; the
    rest as for one mesh."""

def vertex_face_ccd(
    x0: Queries64, x1: Queries64, *, min_distance: float = 0.0, t_max: float = 1.0
) -> Tuple[npt.NDArray[np.bool_], npt.NDArray[np.float64]]:
    """Vertex-face CCD of N single pairs: ``x0[k]`` holds the vertex and the face's three
    corners ``[v, f0, f1, f2]`` at t = 0, ``x1[k]`` at t = 1 (float64 ``(N, 4, 3)`` each;
    every point moves linearly). Returns ``(hits, toi)``: ``(N,)`` bool, whether the vertex
    lies in the closed triangle (or within ``min_distance`` of it) at some t in
    ``[0, t_max]``, decided exactly; ``(N,)`` float64, the time of impact (never later than
    the first contact, at most ``1e-12`` before it), ``inf`` where there is none. A NaN or
    infinite coordinate raises ``ValueError`` naming the query."""

def edge_edge_ccd(
    x0: Queries64, x1: Queries64, *, min_distance: float = 0.0, t_max: float = 1.0
) -> Tuple[npt.NDArray[np.bool_], npt.NDArray[np.float64]]:
    """Edge-edge CCD of N single pairs: ``x0[k]`` holds the two edges' endpoints
    ``[a0, a1, b0, b1]`` at t = 0, ``x1[k]`` at t = 1. Whether the closed segments meet (or
    come within ``min_distance``) at some t in ``[0, t_max]``, and when, as
    ``vertex_face_ccd``."""

def set_max_pairs(n: Optional[int]) -> None:
    """Sets the most result pairs one proximity or CCD query may return (``None``: no limit;
    the default is ``2**25``, about 33.5 million, which a machine with a few GB survives). A
    query that would return more raises ``ValueError`` naming the count reached and the
    limit; one whose result the allocator refuses raises ``MemoryError``. Applies to every
    later query of the module."""

def max_pairs() -> Optional[int]:
    """The most result pairs one query may return (``None``: no limit)."""

def load_mesh(
    path: Union[str, "os.PathLike[str]"],
    max_file_bytes: Optional[int] = None,
    precision: str = "f32",
) -> Tuple[npt.NDArray[np.floating[Any]], npt.NDArray[np.int64]]:
    """``(vertices, faces)`` of an OBJ, STL (ASCII or binary) or PLY file: ``(n, 3)`` vertices
    and ``(m, 3)`` int64 faces in file order (polygons split as fans). Vertices are float32
    with ``precision="f32"`` (the default) and float64 at full precision with
    ``precision="f64"`` (PLY doubles and OBJ decimals as written; float32 values widen
    exactly): a float64 array builds an ``"f64"`` hierarchy. An unknown precision raises
    ``ValueError``. Only regular files of at most ``max_file_bytes`` (default 1 GiB) are
    read; anything else raises ``OSError``."""

class Scene:
    """Many deformable objects of one method. Object ids are ints from 0 upwards, never
    reused; an object may also be given a unique ``name`` and then be named by it wherever
    an id is expected."""

    def __init__(self, method: Method = "dh", levels: Optional[int] = None) -> None: ...
    def add(self, vertices: Vertices, faces: Faces, name: Optional[str] = None) -> int:
        """Adds an object (self-collision off; float64 vertices make an ``"f64"`` object,
        as ``Hierarchy``); returns its id. A scene may hold objects of both precisions."""
    def update(self, id: Union[int, str], vertices: Vertices) -> None:
        """New vertex positions of an object (its float type, as ``Hierarchy.update``); on
        error nothing changes."""
    def update_many(
        self,
        updates: Updates,
        threads: int = 1,
    ) -> None:
        """New vertex positions of several objects in one call: ``{id: vertices}`` or
        ``[(id, vertices), ...]`` (ids or names, each object at most once; vertices as in
        ``update``), applied in parallel with ``threads`` (``"f64"`` objects one after the
        other). Every entry is checked before any is applied: an unknown id, an object given
        twice, a wrong shape, float type or vertex count, a non-finite coordinate raise
        ``ValueError`` and nothing changes (an entry that is not a tuple or list raises
        ``TypeError``; a tuple or list of other than two items, ``ValueError``, as unpacking
        it would). The result equals one ``update`` per entry."""
    def step(
        self,
        updates: Updates,
        threads: int = 1,
    ) -> Contacts:
        """One simulation step: ``update_many(updates)`` then ``contacts()``, in one trip
        to the thread pool (cheaper than the two calls with several threads). The same
        errors as ``update_many``, and then nothing moves."""
    def remove(self, id: Union[int, str]) -> None: ...
    def set_self_collision(self, id: Union[int, str], on: bool) -> None:
        """With ``on``, ``contacts`` also reports the object's own intersecting faces."""
    def contacts(self, threads: int = 1) -> Contacts:
        """Every contact: rows ``[object_a, face_a, object_b, face_b]``, sorted,
        ``object_a < object_b`` (``==`` for self-contacts, then ``face_a < face_b``)."""
    def proximity(self, d: float, threads: int = 1) -> Proximity:
        """Every vertex-face, face-vertex and edge-edge pair within distance ``d`` between
        two objects, and inside each object with self-collision on: rows with object ids
        (see ``Proximity``), sorted. Objects farther apart than ``d`` cost one box test."""
    def contact_set(self, dhat: float, threads: int = 1) -> ContactSet:
        """Every pair of features within ``dhat`` between objects and inside objects with
        self-collision on, once (see ``ContactSet``), in one global numbering: each object's
        vertices and edges follow those of the objects added before it (``vertex_offset``,
        ``edge_offset``)."""
    def vertex_offset(self, id: Union[int, str]) -> int:
        """Where the object's vertices start in the global numbering of ``contact_set``."""
    def edge_offset(self, id: Union[int, str]) -> int:
        """Where the object's edge ids start in the global numbering of ``contact_set``."""
    def ccd(
        self,
        motions: Motions,
        *,
        min_distance: float = 0.0,
        earliest: bool = False,
        t_max: float = 1.0,
        threads: int = 1,
    ) -> Impacts:
        """Continuous collision detection of the whole scene over one step (as ``ccd`` for
        each object pair and each object with self-collision on): each object in
        ``motions`` (``{id: (x0, x1)}`` or ``[(id, (x0, x1))]``, ids or names, each at most
        once; float64 ``(n, 3)`` arrays) moves from ``x0`` to ``x1`` (its stored pose is not
        read, and nothing in the scene changes); every other object stays at its stored
        pose. Objects whose boxes over the step do not come within ``min_distance`` cost one
        box test. Rows with object ids (see ``Impacts``); ``earliest=True``: the earliest
        time over the whole scene and every pair whose own time is within 1e-12 of it. Bad input (an unknown or
        repeated id, a wrong shape, dtype or vertex count, a non-finite coordinate, a
        negative ``min_distance``) raises ``ValueError`` before any work. The result does not
        depend on ``threads`` (the work counters of earliest mode may)."""
    def collision_free_stepsize(
        self,
        motions: Motions,
        *,
        min_distance: float = 0.0,
        rescaling: float = 0.8,
        threads: int = 1,
    ) -> float:
        """The collision-free step size of the whole scene over one step
        (``collision_free_stepsize``'s rule, for every pair between two objects and inside
        every object with self-collision on): ``motions`` as in ``ccd``. Never past the
        scene's earliest impact at ``min_distance``; 1.0 when no pair comes within its gap.
        Bad input raises ``ValueError`` before any work, as in ``ccd``, and for
        ``rescaling`` outside ``(0, 1]``."""
    def __len__(self) -> int: ...

MeshLike = Union[Any, Tuple[Vertices, Faces]]
"""A ``trimesh.Trimesh`` (anything with ``.vertices`` and ``.faces``) or ``(vertices, faces)``."""

class CollisionManager:
    """The part of ``trimesh.collision.CollisionManager`` a trimesh user with deforming
    meshes calls, with the same return conventions; ``update_vertices`` replaces
    ``set_transform``. Exact: two objects collide iff two of their closed triangles
    intersect. trimesh is not needed (meshes may be ``(vertices, faces)`` pairs)."""

    def __init__(
        self, method: Method = "dh", levels: Optional[int] = None, threads: int = 1
    ) -> None: ...
    def add_object(
        self, name: str, mesh: MeshLike, transform: Optional[npt.ArrayLike] = None
    ) -> Hierarchy:
        """Adds (or replaces) an object; ``transform`` (4, 4) poses its vertices once."""
    def remove_object(self, name: str) -> None:
        """``ValueError`` if there is no such object."""
    def update_vertices(self, name: str, vertices: Vertices) -> None:
        """The object's new vertex positions (same count); refit, not rebuild."""
    @overload
    def in_collision_internal(self, return_names: Literal[False] = False) -> bool: ...
    @overload
    def in_collision_internal(
        self, return_names: Literal[True]
    ) -> Tuple[bool, Set[Tuple[str, str]]]: ...
    @overload
    def in_collision_single(
        self,
        mesh: MeshLike,
        transform: Optional[npt.ArrayLike] = None,
        return_names: Literal[False] = False,
    ) -> bool: ...
    @overload
    def in_collision_single(
        self,
        mesh: MeshLike,
        transform: Optional[npt.ArrayLike] = None,
        *,
        return_names: Literal[True],
    ) -> Tuple[bool, Set[str]]: ...
