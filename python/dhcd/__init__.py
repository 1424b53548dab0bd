"""Collision detection between deformable triangle meshes.

Distance Hierarchy (DH), sphere and AABB bounding-volume hierarchies over one region tree,
refitted lazily after every deformation, with exact triangle-triangle contacts. The API is
documented in ``__init__.pyi`` and ``docs/PYTHON.md``.
"""

from ._dhcd import Contacts, Hierarchy, Scene, collide, contact_segments, load_mesh
from ._manager import CollisionManager

__all__ = [
    "CollisionManager",
    "Contacts",
    "Hierarchy",
    "Scene",
    "collide",
    "contact_segments",
    "load_mesh",
]
