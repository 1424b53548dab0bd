//! # dhcd — Distance Hierarchy collision detection for deformable triangle meshes
//!
//! Three bounding-volume hierarchies over one shared region tree (the paper's Distance
//! Hierarchy, spheres, axis-aligned boxes), lazily refitted after every deformation, one
//! depth-first traversal with wide SIMD node tests and a bounded explicit stack, generic
//! over the query: exact contacts ([`collide`], [`self_collide`]), feature pairs within a
//! distance ([`proximity`], [`self_proximity`]) and continuous collision detection over a
//! step ([`self_ccd`], [`ccd_pair`]), all exact for the input as given (`f32` or `f64`).
//! Every query counts its work (`N_V`, `N_P`, `N_U`) for the cost model
//! `T = N_V*C_V + N_P*C_P + N_U*C_U`.
//!
//! Examples (in `examples/`, each run in CI): `deforming_step` (the step loop on a real
//! frame pair, with the counters), `scene` (several objects), `cloth_proximity_ccd`
//! (self-contacts, proximity and CCD of a folding sheet in `f64`), `cost_model` (the
//! counters of each step and the cost constants fitted to them).
//!
//! ```
//! use dhcd::{bv::Dh, collide, Hierarchy, Mesh, Options};
//! let tri = |dx: f32| Mesh::new(
//!     vec![[dx, 0.0, 0.0], [dx + 1.0, 0.0, 0.0], [dx, 1.0, 0.0]],
//!     vec![[0, 1, 2]],
//! ).unwrap();
//! let a = Hierarchy::<Dh>::new(&tri(0.0), Options::default())?;
//! let mut b = Hierarchy::<Dh>::new(&tri(0.5), Options::default())?;
//! assert_eq!(collide(&a, &b).pairs, vec![[0, 0]]);
//! // Deform: move B away; the lazy refit follows.
//! b.update_positions(&[[5.0, 0.0, 0.0], [6.0, 0.0, 0.0], [5.0, 1.0, 0.0]])?;
//! assert!(collide(&a, &b).pairs.is_empty());
//! # Ok::<(), dhcd::Error>(())
//! ```
//!
//! Where things are: the hierarchies, queries, results, [`Scene`] and errors at the root;
//! the methods as types in [`bv`]; loading meshes in [`io`]; one feature pair at a time in
//! [`distance`] and [`ccd`]; the cost-model hooks in [`calibration`]. What is public and
//! stable: `docs/ARCHITECTURE.md`, "The public API".
//!
//! This crate is the kernel library only; the C ABI (`dhcd-capi`), the command line with the
//! paper's experiment and its simulator (`dhcd-cli`) and the Python package are crates of
//! their own on top of it.
#![forbid(unsafe_code)]
#![warn(missing_docs)]

mod any;
pub mod bv;
pub mod calibration;
pub mod ccd;
pub mod contact;
mod control;
mod counters;
pub mod distance;
pub mod error;
pub mod hierarchy;
pub mod io;
mod mesh;
mod methods;
#[doc(hidden)]
pub mod narrow;
mod options;
mod par;
#[doc(hidden)]
pub mod points;
mod precision;
pub mod query;
pub mod scene;
pub mod segments;
pub mod shapes;
mod sort;
pub mod tree;
mod walk;

pub use any::AnyHierarchy;
pub use bv::Method;
pub use contact::{contact_set, self_contact_set, ContactSet};
pub use control::{Control, DEFAULT_MAX_PAIRS};
pub use counters::Counters;
pub use error::{Error, Positions, Result};
pub use hierarchy::{Hierarchy, InvariantError};
pub use mesh::Mesh;
pub use options::{CentralVertex, Options, Refit};
pub use par::Par;
pub use precision::Precision;
pub use scene::{
    ObjectId, PairImpacts, PairProximity, Scene, SceneContacts, SceneImpacts, SceneProximity,
    SceneStepSize,
};
pub use segments::{contact_segments, self_contact_segments, Segment};

pub use query::{
    ccd_pair, ccd_pair_with, collide, collide_with, proximity, proximity_with, self_ccd,
    self_ccd_with, self_collide, self_collide_with, self_proximity, self_proximity_with, CcdMode,
    CcdQuery, Contacts, Impacts, Motion, Proximity,
};
pub use tree::RegionTree;
pub use walk::{Workspace, DEFAULT_GRAIN};

#[doc(hidden)]
pub use mesh::{check_positions, check_positions_f64};
