//! [`AnyHierarchy`]: the boundary where the bounding-volume kind is chosen at run time
//! (CLI, experiment, C ABI). Everything inside is monomorphised per kind.

use std::sync::Arc;

use crate::bv::{Aabb, Dh, Method, Sphere};
use crate::counters::Counters;
use crate::error::{Error, Result};
use crate::hierarchy::{Hierarchy, InvariantError, Options, Refit};
use crate::mesh::Mesh;
use crate::par::Par;
use crate::traverse::{broad_phase, collide_with, narrow_phase, Contacts, Workspace};
use crate::tree::RegionTree;

/// A hierarchy of a kind chosen at run time.
#[derive(Clone, Debug)]
pub enum AnyHierarchy {
    Dh(Hierarchy<Dh>),
    Sphere(Hierarchy<Sphere>),
    Aabb(Hierarchy<Aabb>),
}

macro_rules! each {
    ($self:expr, $h:ident => $e:expr) => {
        match $self {
            AnyHierarchy::Dh($h) => $e,
            AnyHierarchy::Sphere($h) => $e,
            AnyHierarchy::Aabb($h) => $e,
        }
    };
}

impl AnyHierarchy {
    pub fn new(method: Method, mesh: &Mesh, options: Options) -> Result<Self> {
        let tree = Arc::new(RegionTree::build(mesh, options.levels)?);
        Self::with_tree(method, tree, mesh, options.refit)
    }

    pub fn with_tree(
        method: Method,
        tree: Arc<RegionTree>,
        mesh: &Mesh,
        refit: Refit,
    ) -> Result<Self> {
        Ok(match method {
            Method::Dh => Self::Dh(Hierarchy::with_tree(tree, mesh, refit)?),
            Method::Sphere => Self::Sphere(Hierarchy::with_tree(tree, mesh, refit)?),
            Method::Aabb => Self::Aabb(Hierarchy::with_tree(tree, mesh, refit)?),
        })
    }

    pub fn method(&self) -> Method {
        each!(self, h => h.method())
    }

    pub fn update_positions(&mut self, positions: &[[f32; 3]]) -> Result<()> {
        each!(self, h => h.update_positions(positions))
    }

    pub fn validate(&self) -> std::result::Result<usize, InvariantError> {
        each!(self, h => h.validate())
    }

    pub fn bytes_per_node(&self) -> usize {
        each!(self, h => h.bytes_per_node())
    }

    pub fn bv_bytes(&self) -> usize {
        each!(self, h => h.bv_bytes())
    }

    pub fn node_count(&self) -> usize {
        each!(self, h => h.node_count())
    }

    pub fn tree(&self) -> &Arc<RegionTree> {
        each!(self, h => h.tree())
    }

    /// Contacts between two hierarchies of the same kind; an error if the kinds differ.
    pub fn collide(
        &mut self,
        other: &mut AnyHierarchy,
        ws: &mut Workspace,
        par: Par,
    ) -> Result<Contacts> {
        match (self, other) {
            (Self::Dh(a), Self::Dh(b)) => Ok(collide_with(a, b, ws, par)),
            (Self::Sphere(a), Self::Sphere(b)) => Ok(collide_with(a, b, ws, par)),
            (Self::Aabb(a), Self::Aabb(b)) => Ok(collide_with(a, b, ws, par)),
            (a, b) => Err(Error::InvalidOption(format!(
                "cannot collide a {} hierarchy with a {} hierarchy",
                a.method(),
                b.method()
            ))),
        }
    }
    /// Marks every bounding volume stale (see [`Hierarchy::invalidate`]).
    pub fn invalidate(&mut self) {
        each!(self, h => h.invalidate())
    }

    /// Refits the stale nodes among `ids` (see [`Hierarchy::refit_nodes`]).
    pub fn refit_nodes(&mut self, ids: &[u32], par: Par) {
        each!(self, h => h.refit_nodes(ids, par))
    }

    /// The nodes fitted to the current positions (see [`Hierarchy::fitted_nodes`]).
    pub fn fitted_nodes(&self) -> Vec<u32> {
        each!(self, h => h.fitted_nodes())
    }

    /// The BV updates done since the last call (see [`Hierarchy::take_updates`]).
    pub fn take_updates(&mut self) -> u64 {
        each!(self, h => h.take_updates())
    }

    /// [`broad_phase`] between two hierarchies of the same kind; an error if the kinds differ.
    pub fn broad_phase(
        &mut self,
        other: &mut AnyHierarchy,
        ws: &mut Workspace,
        par: Par,
    ) -> Result<Counters> {
        match (self, other) {
            (Self::Dh(a), Self::Dh(b)) => Ok(broad_phase(a, b, ws, par)),
            (Self::Sphere(a), Self::Sphere(b)) => Ok(broad_phase(a, b, ws, par)),
            (Self::Aabb(a), Self::Aabb(b)) => Ok(broad_phase(a, b, ws, par)),
            (a, b) => Err(mismatch(a, b)),
        }
    }

    /// [`narrow_phase`] on leaf pairs of two hierarchies of the same kind; an error if the
    /// kinds differ.
    pub fn narrow_phase(
        &self,
        other: &AnyHierarchy,
        leaves: &[[u32; 2]],
        par: Par,
    ) -> Result<Contacts> {
        match (self, other) {
            (Self::Dh(a), Self::Dh(b)) => Ok(narrow_phase(a, b, leaves, par)),
            (Self::Sphere(a), Self::Sphere(b)) => Ok(narrow_phase(a, b, leaves, par)),
            (Self::Aabb(a), Self::Aabb(b)) => Ok(narrow_phase(a, b, leaves, par)),
            (a, b) => Err(mismatch(a, b)),
        }
    }
}

fn mismatch(a: &AnyHierarchy, b: &AnyHierarchy) -> Error {
    Error::InvalidOption(format!(
        "cannot collide a {} hierarchy with a {} hierarchy",
        a.method(),
        b.method()
    ))
}
