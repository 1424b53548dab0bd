"""Collision detection between deformable triangle meshes.

Distance Hierarchy (DH), sphere and AABB bounding-volume hierarchies over one region tree,
refitted lazily after every deformation, with exact triangle-triangle contacts, exact
proximity queries and exact continuous collision detection, for float32 or float64
coordinates. The API is documented in ``__init__.pyi`` and ``docs/PYTHON.md``.
"""

from ._dhcd import (
    EDGE_EDGE_TYPES,
    POINT_TRIANGLE_TYPES,
    Contacts,
    ContactSet,
    Hierarchy,
    Impacts,
    Proximity,
    Scene,
    ccd,
    collide,
    collision_free_stepsize,
    contact_segments,
    contact_set,
    distance_gradient,
    distance_hessian,
    distance_sq,
    edge_edge_ccd,
    load_mesh,
    max_pairs,
    proximity,
    self_contact_set,
    self_proximity,
    set_max_pairs,
    vertex_face_ccd,
)
from ._manager import CollisionManager

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
