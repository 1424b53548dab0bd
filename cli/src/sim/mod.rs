//! Mass-spring simulation of deformable objects and the built-in pawn scene.
//!
//! The paper's experiment (eight deformable chess pawns, 100 time steps) needs frames in
//! which the objects really deform against each other and stay in contact, so that the
//! collision work grows and persists. This module provides:
//!
//! * [`pawn_mesh`]: the 6,976-triangle pawn (closed surface of revolution, `+y` up);
//! * [`Simulation`]: a deterministic mass-spring simulator (edge + bending springs, a soft
//!   pull toward the translated rest shape, damping, semi-implicit Euler with substeps),
//!   driven toward the scene centre and pushed apart by the collision kernel's contacts;
//! * [`pawn_scene`] / [`scene_with_mesh`]: eight objects in two rows of four.
//!
//! The simulator never looks for collisions itself: the caller runs the collision kernel on
//! the current positions and hands the resulting [`ObjectContact`]s to the next
//! [`Simulation::step`]. Frames are therefore the same for every method as long as the same
//! contacts are supplied (the experiment simulates once and replays the frames).

mod pawn;
mod scene;
mod simulation;

pub use pawn::{pawn_mesh, pawn_mesh_with, PAWN_HEIGHT, PAWN_RINGS, PAWN_SEGMENTS};
pub use scene::{pawn_scene, scene_with_mesh, SCENE_OBJECTS};
pub use simulation::{SimConfig, Simulation};

/// What the simulator rejects: a parameter out of its range, an unstable configuration, an
/// empty scene, or a mesh the library rejects.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum SimError {
    #[error("{name} must be {expected}, got {value}")]
    InvalidParameter {
        name: &'static str,
        value: f64,
        expected: &'static str,
    },
    #[error("shape_stiffness {stiffness} is unstable at substep {substep} s; use more substeps")]
    Unstable { stiffness: f64, substep: f64 },
    #[error("a simulation needs at least one object")]
    NoObjects,
    /// The copies of a mesh laid out side by side leave the f32 range: the file's
    /// coordinates are finite, the scene's are not.
    #[error(
        "the mesh is too large for the experiment's scene: placed as copy {copy} \
         (spacing {spacing:.3e}), its vertex {vertex} lands at ({:.3e} {:.3e} {:.3e}), beyond \
         the f32 range; the file's coordinates are finite: scale the mesh down",
        at[0], at[1], at[2]
    )]
    SceneTooLarge {
        copy: usize,
        vertex: usize,
        spacing: f64,
        at: [f64; 3],
    },
    #[error("too many objects ({0})")]
    TooManyObjects(usize),
    #[error(transparent)]
    Mesh(#[from] dhcd::Error),
}

/// A [`SimError::InvalidParameter`] unless `ok`.
pub(crate) fn check(
    ok: bool,
    name: &'static str,
    value: f64,
    expected: &'static str,
) -> Result<(), SimError> {
    if ok {
        Ok(())
    } else {
        Err(SimError::InvalidParameter {
            name,
            value,
            expected,
        })
    }
}

/// One intersecting triangle pair between two objects, as reported by the collision kernel.
///
/// Triangle indices are indices into the objects' original meshes. The order of a list of
/// contacts does not matter: [`Simulation::step`] sorts and deduplicates them (that is why
/// this type is `Ord`), so a kernel that reports contacts in a thread-dependent order still
/// yields bit-identical frames.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct ObjectContact {
    pub object_a: u32,
    pub triangle_a: u32,
    pub object_b: u32,
    pub triangle_b: u32,
}
