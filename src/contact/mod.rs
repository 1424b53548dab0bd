//! What a barrier solver sums over: the contact set (every pair of features within `dhat`,
//! once, with the IPC Toolkit's collision type and closest-point weights), the geometry of
//! one contact (its squared distance with gradient and Hessian), and the collision-free step
//! size of a line search.
//!
//! ```
//! use dhcd::{bv::Dh, contact::{self, ContactType}, Hierarchy, Mesh, Options};
//! // A vertex 0.1 above the middle of a triangle's edge: one point-edge contact.
//! let m = Mesh::new_f64(
//!     vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.5, -0.1, 0.0]],
//!     vec![[0, 1, 2]],
//! )?;
//! let h = Hierarchy::<Dh>::new(&m, Options::default())?;
//! let set = contact::self_contact_set(&h, 0.2)?;
//! assert_eq!(set.len(), 1);
//! let c = &set.contacts[0];
//! assert_eq!((c.kind, c.vertices), (ContactType::PointEdge, [3, 0, 1, contact::NONE]));
//! assert!((c.distance_sq - 0.01).abs() < 1e-15);
//! assert_eq!(h.tree().edges()[c.edges[0] as usize], [0, 1]);
//! # Ok::<(), dhcd::Error>(())
//! ```

mod dual;
pub mod geometry;
mod set;
pub(crate) mod step;

pub(crate) use set::{from_rows, offset, ContactScratch, Side};

pub use geometry::{distance_gradient, distance_hessian, distance_sq, ContactType};
pub use set::{
    contact_set, contact_set_with, self_contact_set, self_contact_set_with, Contact, ContactSet,
    MOLLIFIER_FACTOR, NONE,
};
pub use step::{
    collision_free_stepsize, collision_free_stepsize_pair, collision_free_stepsize_with,
    StepOptions, StepSize,
};
