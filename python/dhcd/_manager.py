"""`CollisionManager`: the part of ``trimesh.collision.CollisionManager`` that a trimesh user
with deforming meshes calls, with the same return conventions, on dhcd hierarchies."""

import numpy as np

from ._dhcd import Hierarchy, collide


def _mesh_arrays(mesh):
    """``(vertices, faces)`` of a ``trimesh.Trimesh`` (anything with ``.vertices`` and
    ``.faces``) or of a ``(vertices, faces)`` pair; trimesh itself is never imported."""
    if hasattr(mesh, "vertices") and hasattr(mesh, "faces"):
        return mesh.vertices, mesh.faces
    if isinstance(mesh, (tuple, list)) and len(mesh) == 2:
        return mesh[0], mesh[1]
    raise TypeError(
        "mesh must be a trimesh.Trimesh or a (vertices, faces) pair, "
        f"not {type(mesh).__name__}"
    )


def _posed(vertices, transform):
    """The vertices as float32 (the manager's precision: the fast path), moved by a (4, 4)
    transform."""
    if transform is None:
        return np.ascontiguousarray(vertices, dtype=np.float32)
    t = np.asarray(transform, dtype=np.float64)
    if t.shape != (4, 4):
        raise ValueError(f"transform must be (4, 4), got shape {t.shape}")
    v = np.asarray(vertices, dtype=np.float64)
    if v.ndim != 2 or v.shape[1] != 3:
        raise ValueError(f"vertices must be an (n, 3) array, got shape {v.shape}")
    return np.ascontiguousarray(v @ t[:3, :3].T + t[:3, 3], dtype=np.float32)


def _bounds(vertices32):
    """Closed box of float32 vertices: the very values the hierarchy holds, so the box test
    below never rejects two objects whose triangles touch."""
    return vertices32.min(axis=0), vertices32.max(axis=0)


def _overlap(a, b):
    return bool(np.all(a[0] <= b[1]) and np.all(b[0] <= a[1]))


class CollisionManager:
    """Deformable objects by name, queried for collisions like trimesh's manager.

    Instead of ``set_transform`` the objects deform: ``update_vertices(name, vertices)``
    hands an object its new vertex positions and its hierarchy is refitted, not rebuilt.
    Answers are exact: two objects collide iff some pair of their closed triangles
    intersects.
    """

    def __init__(self, method="dh", levels=None, threads=1):
        self._method = method
        self._levels = levels
        self._threads = threads
        # name -> [hierarchy, (lo, hi)], in insertion order.
        self._objects = {}

    def add_object(self, name, mesh, transform=None):
        """Adds an object (a ``trimesh.Trimesh`` or ``(vertices, faces)``), replacing any
        object of the same name; ``transform`` (4, 4) poses the vertices once, here.
        Returns the object's ``Hierarchy``."""
        vertices, faces = _mesh_arrays(mesh)
        v = _posed(vertices, transform)
        h = Hierarchy(v, faces, method=self._method, levels=self._levels)
        self._objects[name] = [h, _bounds(v)]
        return h

    def remove_object(self, name):
        """Removes an object; ``ValueError`` if there is none of that name."""
        if name not in self._objects:
            raise ValueError(f"{name} not in collision manager!")
        del self._objects[name]

    def update_vertices(self, name, vertices):
        """New vertex positions of an object (its vertex count); ``ValueError`` if there is
        no object of that name or the vertices are bad (the object is then unchanged)."""
        if name not in self._objects:
            raise ValueError(f"{name} not in collision manager!")
        entry = self._objects[name]
        v = np.ascontiguousarray(vertices, dtype=np.float32)
        entry[0].update(v)
        entry[1] = _bounds(v)

    def in_collision_internal(self, return_names=False):
        """Whether any two objects collide; with ``return_names`` also the set of colliding
        pairs, each a tuple of the two names in sorted order."""
        items = list(self._objects.items())
        names = set()
        for i, (name_a, (ha, box_a)) in enumerate(items):
            for name_b, (hb, box_b) in items[i + 1 :]:
                if not _overlap(box_a, box_b) or len(collide(ha, hb, self._threads)) == 0:
                    continue
                if not return_names:
                    return True
                names.add(tuple(sorted((name_a, name_b))))
        return (bool(names), names) if return_names else False

    def in_collision_single(self, mesh, transform=None, return_names=False):
        """Whether ``mesh`` (posed by ``transform``) collides with any object; with
        ``return_names`` also the set of names of the objects it collides with."""
        vertices, faces = _mesh_arrays(mesh)
        v = _posed(vertices, transform)
        # Built even when no box overlaps, so that a bad mesh is always an error.
        probe = Hierarchy(v, faces, method=self._method, levels=self._levels)
        box = _bounds(v)
        names = set()
        for name, (h, box_h) in self._objects.items():
            if not _overlap(box, box_h) or len(collide(probe, h, self._threads)) == 0:
                continue
            if not return_names:
                return True
            names.add(name)
        return (bool(names), names) if return_names else False
