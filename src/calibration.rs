//! Calibration and cost-model hooks: a query taken apart into its refit, its traversal and
//! its narrow phase, so each can be timed and counted alone.
//!
//! The cost model `T = N_V*C_V + N_P*C_P + N_U*C_U` is calibrated by timing each part with
//! known counts (`dhcd experiment` does, in `cli/src/experiment/cost.rs`): refit every node
//! ([`Calibration::refit_all`] after [`Calibration::invalidate`]) for `C_U`, the traversal
//! down to the overlapping leaf pairs ([`Calibration::broad_phase`]) for `C_V`, and the exact
//! triangle tests of those leaf pairs ([`Calibration::narrow_phase`]) for `C_P`. The queries
//! themselves ([`collide`](crate::collide) and the rest) never need these.
//!
//! ```
//! use dhcd::calibration::Calibration;
//! use dhcd::{bv::Dh, shapes, Hierarchy, Options, Par, Workspace};
//! let mesh = shapes::icosphere(2, 1.0, [0.0; 3]);
//! let mut a = Hierarchy::<Dh>::new(&mesh, Options::default())?;
//! let b = Hierarchy::<Dh>::new(&mesh, Options::default())?;
//! a.invalidate();
//! let n_u = a.refit_all(); // every node refitted now: N_U of a full refit
//! let broad = a.broad_phase(&b, &mut Workspace::default(), Par::Seq)?;
//! let narrow = a.narrow_phase(&b, &broad.leaf_pairs, Par::Seq)?;
//! assert_eq!(n_u as usize, a.node_count());
//! assert_eq!(narrow.pairs, dhcd::collide(&a, &b).pairs);
//! # Ok::<(), dhcd::Error>(())
//! ```

use crate::bv::BoundingVolume;
use crate::error::Result;
use crate::hierarchy::Hierarchy;
use crate::par::Par;
use crate::query::{contacts, Contacts};
use crate::walk::Workspace;

pub use crate::query::contacts::BroadPhase;

/// The parts of a query and the refit, one at a time: implemented by
/// [`Hierarchy`] and [`AnyHierarchy`](crate::AnyHierarchy).
pub trait Calibration {
    /// Marks every bounding volume stale without moving anything (the next query refits
    /// what it tests), to repeat a step's refit work.
    fn invalidate(&mut self);

    /// Refits the stale sibling groups of the nodes `ids` (each group once), as the lazy
    /// traversal does; returns the number of nodes fitted. A node id out of range is an
    /// [`Error::NodeOutOfRange`](crate::Error::NodeOutOfRange) and nothing is refitted.
    fn refit_nodes(&mut self, ids: &[u32], par: Par) -> Result<u64>;

    /// Refits every stale node exactly; returns the number of nodes fitted.
    fn refit_all(&mut self) -> u64;

    /// Refits every stale node bottom-up: leaves exactly, internal nodes from their
    /// children. Returns the number of nodes fitted.
    fn refit_bottom_up(&mut self) -> u64;

    /// The nodes fitted to the current positions (after a lazy query: the sibling groups it
    /// refitted or found fresh), in increasing order.
    fn fitted_nodes(&self) -> Vec<u32>;

    /// The lazy refit and traversal of [`collide_with`](crate::collide_with) down to the
    /// overlapping leaf pairs; no triangle is tested. The counters hold `bv_tests`,
    /// `bv_updates`, and `prim_tests` as [`narrow_phase`](Self::narrow_phase) will count
    /// the leaf pairs. An error only if the two hierarchies are of different methods (so
    /// never for [`Hierarchy`]).
    fn broad_phase(&self, other: &Self, ws: &mut Workspace, par: Par) -> Result<BroadPhase>;

    /// [`broad_phase`](Self::broad_phase) of one object against itself: what a self query
    /// costs besides its narrow phase (`dhcd bench --broad-only`).
    fn self_broad_phase(&self, ws: &mut Workspace, par: Par) -> BroadPhase;

    /// The exact triangle tests of the leaf pairs `leaves` (`[leaf of self, leaf of
    /// other]`, as [`BroadPhase::leaf_pairs`] gives them) in the current pose; the contacts
    /// of a whole query when given its broad phase's pairs. A node out of range or not a
    /// leaf, or hierarchies of different methods, are an error.
    fn narrow_phase(&self, other: &Self, leaves: &[[u32; 2]], par: Par) -> Result<Contacts>;
}

impl<K: BoundingVolume> Calibration for Hierarchy<K> {
    fn invalidate(&mut self) {
        Hierarchy::invalidate(self)
    }

    fn refit_nodes(&mut self, ids: &[u32], par: Par) -> Result<u64> {
        Hierarchy::refit_nodes(self, ids, par)
    }

    fn refit_all(&mut self) -> u64 {
        Hierarchy::refit_all(self)
    }

    fn refit_bottom_up(&mut self) -> u64 {
        Hierarchy::refit_bottom_up(self)
    }

    fn fitted_nodes(&self) -> Vec<u32> {
        Hierarchy::fitted_nodes(self)
    }

    fn broad_phase(&self, other: &Self, ws: &mut Workspace, par: Par) -> Result<BroadPhase> {
        Ok(contacts::broad_phase(self, other, ws, par))
    }

    fn self_broad_phase(&self, ws: &mut Workspace, par: Par) -> BroadPhase {
        contacts::self_broad_phase(self, ws, par)
    }

    fn narrow_phase(&self, other: &Self, leaves: &[[u32; 2]], par: Par) -> Result<Contacts> {
        contacts::narrow_phase(self, other, leaves, par)
    }
}
