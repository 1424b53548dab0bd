//! Mass-spring simulation of deformable objects and the built-in pawn scene.
