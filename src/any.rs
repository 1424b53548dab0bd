//! [`AnyHierarchy`]: the boundary where the method is chosen at run time
//! (CLI, experiment, C ABI). Everything inside is monomorphised per method.

use std::sync::Arc;

use crate::bv::Method;
use crate::calibration::{BroadPhase, Calibration};
use crate::contact::{
    collision_free_stepsize_pair, collision_free_stepsize_with, contact_set_with,
    self_contact_set_with, ContactSet, StepOptions, StepSize,
};
use crate::error::Result;
use crate::hierarchy::{Hierarchy, InvariantError};
use crate::mesh::Mesh;
use crate::methods::{match_method, match_method_pair, methods, with_method};
use crate::options::Options;
use crate::par::Par;
use crate::precision::Precision;
use crate::query::{
    ccd_pair_with, collide_with, proximity_with, self_ccd_with, self_collide_with,
    self_proximity_with, CcdQuery, Contacts, Impacts, Motion, Proximity,
};
use crate::tree::RegionTree;
use crate::walk::Workspace;

methods!(crate::methods::method_enum {
    /// A hierarchy of a method chosen at run time: one variant per row of the table of methods
    /// (`src/methods.rs`).
    #[derive(Clone, Debug)]
    #[non_exhaustive]
    pub enum AnyHierarchy(Hierarchy)
});

macro_rules! each {
    ($self:expr, $h:ident => $e:expr) => {
        match_method!(AnyHierarchy, $self, $h => $e)
    };
}

/// Applies `$e` to two hierarchies of the same method (bound as `$a`, `$b`); a
/// [`crate::Error::MethodMismatch`] when the methods differ.
macro_rules! pairwise {
    ($x:expr, $y:expr, $a:ident, $b:ident => $e:expr) => {
        match_method_pair!(AnyHierarchy, $x, $y, $a, $b => $e)
    };
}

impl AnyHierarchy {
    /// A hierarchy of `method` over `mesh` (its positions are the rest pose); see [`Hierarchy::new`].
    pub fn new(method: Method, mesh: &Mesh, options: Options) -> Result<Self> {
        let tree = Arc::new(RegionTree::build(mesh, options.shape())?);
        Self::with_tree(method, tree, mesh, options)
    }

    /// A hierarchy over an existing region tree of `mesh` (see [`Hierarchy::with_tree`]).
    pub fn with_tree(
        method: Method,
        tree: Arc<RegionTree>,
        mesh: &Mesh,
        options: Options,
    ) -> Result<Self> {
        Ok(with_method!(method, K => Hierarchy::<K>::with_tree(tree, mesh, options)?.into()))
    }

    /// See [`Hierarchy::update_positions`]: the number of volumes refitted now.
    pub fn update_positions(&mut self, positions: &[[f32; 3]]) -> Result<u64> {
        each!(self, h => h.update_positions(positions))
    }

    /// See [`Hierarchy::update_positions_f64`].
    pub fn update_positions_f64(&mut self, positions: &[[f64; 3]]) -> Result<u64> {
        each!(self, h => h.update_positions_f64(positions))
    }

    /// The precision of the positions the hierarchy was built from and takes.
    pub fn precision(&self) -> Precision {
        each!(self, h => h.precision())
    }

    /// See [`Hierarchy::validate`].
    pub fn validate(&self) -> std::result::Result<usize, InvariantError> {
        each!(self, h => h.validate())
    }

    /// See [`Hierarchy::bytes_per_node`].
    pub fn bytes_per_node(&self) -> usize {
        each!(self, h => h.bytes_per_node())
    }

    /// See [`Hierarchy::bv_bytes`].
    pub fn bv_bytes(&self) -> usize {
        each!(self, h => h.bv_bytes())
    }

    /// See [`Hierarchy::node_count`].
    pub fn node_count(&self) -> usize {
        each!(self, h => h.node_count())
    }

    /// The region tree (shareable with hierarchies of the other methods).
    pub fn tree(&self) -> &Arc<RegionTree> {
        each!(self, h => h.tree())
    }

    /// Contacts between two hierarchies of the same method; an error if the methods differ.
    pub fn collide(&self, other: &AnyHierarchy, ws: &mut Workspace, par: Par) -> Result<Contacts> {
        pairwise!(self, other, a, b => collide_with(a, b, ws, par))
    }

    /// Self-contacts of this object (see [`self_collide`](crate::self_collide())).
    pub fn self_collide(&self, ws: &mut Workspace, par: Par) -> Contacts {
        each!(self, h => self_collide_with(h, ws, par))
    }

    /// Feature pairs within `d` between two hierarchies of the same method (see
    /// [`proximity`](crate::proximity())); an error if the methods differ or `d` is invalid.
    pub fn proximity(
        &self,
        other: &AnyHierarchy,
        d: f64,
        ws: &mut Workspace,
        par: Par,
    ) -> Result<Proximity> {
        pairwise!(self, other, a, b => proximity_with(a, b, d, ws, par)?)
    }

    /// Feature pairs within `d` of this object (see
    /// [`self_proximity`](crate::self_proximity())).
    pub fn self_proximity(&self, d: f64, ws: &mut Workspace, par: Par) -> Result<Proximity> {
        each!(self, h => self_proximity_with(h, d, ws, par))
    }

    /// The contact set of two hierarchies of the same method within `dhat` (see
    /// [`contact_set`](crate::contact_set())); `rest` the rest positions of each (`None`: its
    /// build positions).
    pub fn contact_set(
        &self,
        other: &AnyHierarchy,
        dhat: f64,
        rest: [Option<&[[f64; 3]]>; 2],
        ws: &mut Workspace,
        par: Par,
    ) -> Result<ContactSet> {
        pairwise!(self, other, a, b => contact_set_with(a, b, dhat, rest, ws, par)?)
    }

    /// The contact set of this object within `dhat` (see
    /// [`self_contact_set`](crate::self_contact_set())).
    pub fn self_contact_set(
        &self,
        dhat: f64,
        rest: Option<&[[f64; 3]]>,
        ws: &mut Workspace,
        par: Par,
    ) -> Result<ContactSet> {
        each!(self, h => self_contact_set_with(h, dhat, rest, ws, par))
    }

    /// The collision-free step size of this object moving by `motion` (see
    /// [`collision_free_stepsize`](crate::contact::collision_free_stepsize())).
    pub fn collision_free_stepsize(
        &self,
        motion: Motion<'_>,
        options: &StepOptions,
        ws: &mut Workspace,
        par: Par,
    ) -> Result<StepSize> {
        each!(self, h => collision_free_stepsize_with(h, motion, options, ws, par))
    }

    /// The collision-free step size of this object and `other` (pairs between them only);
    /// an error if the methods differ.
    pub fn collision_free_stepsize_pair(
        &self,
        motion: Motion<'_>,
        other: &AnyHierarchy,
        other_motion: Motion<'_>,
        options: &StepOptions,
        ws: &mut Workspace,
        par: Par,
    ) -> Result<StepSize> {
        pairwise!(self, other, a, b => collision_free_stepsize_pair(a, motion, b, other_motion, options, ws, par)?)
    }

    /// Colliding feature pairs between this object moving by `motion` and `other` moving by
    /// `other_motion` over a step (see [`ccd_pair`](crate::ccd_pair())); an error if the
    /// methods differ or the input is invalid.
    pub fn ccd_pair(
        &self,
        motion: Motion<'_>,
        other: &AnyHierarchy,
        other_motion: Motion<'_>,
        query: &CcdQuery,
        ws: &mut Workspace,
        par: Par,
    ) -> Result<Impacts> {
        pairwise!(self, other, a, b => ccd_pair_with(a, motion, b, other_motion, query, ws, par)?)
    }

    /// Colliding feature pairs of this object moving by `motion` over a step (see
    /// [`self_ccd`](crate::self_ccd())).
    pub fn self_ccd(
        &self,
        motion: Motion<'_>,
        query: &CcdQuery,
        ws: &mut Workspace,
        par: Par,
    ) -> Result<Impacts> {
        each!(self, h => self_ccd_with(h, motion, query, ws, par))
    }

    /// Intersection segments of contacts between `self` and `other` (see
    /// [`contact_segments`](crate::segments::contact_segments)); an error if the methods differ.
    pub fn contact_segments(
        &self,
        other: &AnyHierarchy,
        pairs: &[[u32; 2]],
    ) -> Result<Vec<crate::segments::Segment>> {
        use crate::segments::contact_segments;
        pairwise!(self, other, a, b => contact_segments(a, b, pairs)?)
    }
}

impl Calibration for AnyHierarchy {
    fn invalidate(&mut self) {
        each!(self, h => h.invalidate())
    }

    fn refit_nodes(&mut self, ids: &[u32], par: Par) -> Result<u64> {
        each!(self, h => h.refit_nodes(ids, par))
    }

    fn refit_all(&mut self) -> u64 {
        each!(self, h => h.refit_all())
    }

    fn refit_bottom_up(&mut self) -> u64 {
        each!(self, h => h.refit_bottom_up())
    }

    fn fitted_nodes(&self) -> Vec<u32> {
        each!(self, h => h.fitted_nodes())
    }

    fn broad_phase(&self, other: &Self, ws: &mut Workspace, par: Par) -> Result<BroadPhase> {
        pairwise!(self, other, a, b => a.broad_phase(b, ws, par)?)
    }

    fn self_broad_phase(&self, ws: &mut Workspace, par: Par) -> BroadPhase {
        each!(self, h => h.self_broad_phase(ws, par))
    }

    fn narrow_phase(&self, other: &Self, leaves: &[[u32; 2]], par: Par) -> Result<Contacts> {
        pairwise!(self, other, a, b => a.narrow_phase(b, leaves, par)?)
    }
}
