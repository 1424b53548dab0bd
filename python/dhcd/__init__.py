"""Collision detection between deformable triangle meshes.

Distance Hierarchy (DH), sphere and AABB bounding-volume hierarchies over one region tree,
refitted lazily after every deformation, with exact triangle-triangle contacts and exact
proximity queries, for float32 or float64 coordinates. The API is documented in
``__init__.pyi`` and ``docs/PYTHON.md``.
"""

from ._dhcd import (
    EDGE_EDGE_TYPES,
    POINT_TRIANGLE_TYPES,
    Contacts,
    Hierarchy,
    Proximity,
    Scene,
    collide,
    contact_segments,
    load_mesh,
    proximity,
    self_proximity,
)
from ._manager import CollisionManager

__all__ = [
    "EDGE_EDGE_TYPES",
    "POINT_TRIANGLE_TYPES",
    "CollisionManager",
    "Contacts",
    "Hierarchy",
    "Proximity",
    "Scene",
    "collide",
    "contact_segments",
    "load_mesh",
    "proximity",
    "self_proximity",
]
