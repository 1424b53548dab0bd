"""Collision detection between deformable triangle meshes (dhcd).

Build a hierarchy once from a rest pose, hand it new vertex positions every step (it is
refitted lazily, never rebuilt) and query: every pair of faces whose closed triangles
intersect, decided exactly for the float32 coordinates, as sorted numpy arrays of the
caller's face indices.

Inputs: ``vertices`` is an ``(n, 3)`` array of real numbers (float32 is read in place; other
dtypes are converted once to float32, the library's precision), ``faces`` an ``(m, 3)``
integer array of vertex indices. Bad input (wrong shape, a dtype that cannot convert, NaN or
infinite coordinates, an index out of range, a face repeating a vertex, an empty mesh, an
unknown method, a file that cannot be parsed) raises ``ValueError`` with the library's
message; a file that cannot be read raises ``OSError`` (``FileNotFoundError`` if missing).

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
    "CollisionManager",
    "Contacts",
    "Hierarchy",
    "Scene",
    "collide",
    "contact_segments",
    "load_mesh",
]

Method = Literal["dh", "sphere", "aabb", "sbv"]
"""Bounding-volume kind: ``"dh"`` (Distance Hierarchy, 8-byte nodes), ``"sphere"`` (16
bytes; alias ``"sbv"``), ``"aabb"`` (24 bytes). Case-insensitive."""

Vertices = npt.ArrayLike
Faces = npt.ArrayLike
# `Scene.update_many` and `Scene.step`: `{id or name: vertices}` or `[(id or name, vertices)]`.
Updates = Union[Mapping[Union[int, str], Vertices], Iterable[Tuple[Union[int, str], Vertices]]]

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

class Hierarchy:
    """The bounding-volume hierarchy of one deformable mesh; ``vertices`` is its rest pose.

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
        """New positions of the mesh's vertices (same shape). The hierarchy is refitted
        lazily by the next query, not rebuilt. On error nothing changes."""
    def self_collide(self, threads: int = 1) -> Contacts:
        """Intersecting face pairs ``[i, j]``, ``i < j``, of this mesh; pairs sharing a
        vertex index are never reported."""
    @property
    def method(self) -> str:
        """``"dh"``, ``"sphere"`` or ``"aabb"``."""
    @property
    def bytes_per_node(self) -> int:
        """Size of one node record: 8, 16 or 24."""
    @property
    def vertex_count(self) -> int: ...
    @property
    def face_count(self) -> int: ...

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

def load_mesh(
    path: Union[str, "os.PathLike[str]"],
    max_file_bytes: Optional[int] = None,
) -> Tuple[npt.NDArray[np.float32], npt.NDArray[np.int64]]:
    """``(vertices, faces)`` of an OBJ, STL (ASCII or binary) or PLY file: ``(n, 3)`` float32
    and ``(m, 3)`` int64, faces in file order (polygons split as fans). Only regular files of
    at most ``max_file_bytes`` (default 1 GiB) are read; anything else raises ``OSError``."""

class Scene:
    """Many deformable objects of one method. Object ids are ints from 0 upwards, never
    reused; an object may also be given a unique ``name`` and then be named by it wherever
    an id is expected."""

    def __init__(self, method: Method = "dh", levels: Optional[int] = None) -> None: ...
    def add(self, vertices: Vertices, faces: Faces, name: Optional[str] = None) -> int:
        """Adds an object (self-collision off); returns its id."""
    def update(self, id: Union[int, str], vertices: Vertices) -> None:
        """New vertex positions of an object; on error nothing changes."""
    def update_many(
        self,
        updates: Updates,
        threads: int = 1,
    ) -> None:
        """New vertex positions of several objects in one call: ``{id: vertices}`` or
        ``[(id, vertices), ...]`` (ids or names, each object at most once; vertices as in
        ``update``), applied in parallel with ``threads``. Every entry is checked before
        any is applied: an unknown id, an object given twice, a wrong shape or vertex count,
        a non-finite coordinate raise ``ValueError`` and nothing changes (an entry that is
        not a pair raises ``TypeError``). The result equals one ``update`` per entry."""
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
