//! [`AnyHierarchy`]: the boundary where the bounding-volume kind is chosen at run time
//! (CLI, experiment, C ABI). Everything inside is monomorphised per kind.

use std::sync::Arc;

use crate::bv::{Aabb, Dh, Method, Sphere};
use crate::error::{Error, Result};
use crate::hierarchy::{Hierarchy, InvariantError, Options, Refit};
use crate::mesh::Mesh;
use crate::par::Par;
use crate::self_collide::self_collide_with;
use crate::traverse::{collide_with, Contacts, Workspace};
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
            (a, b) => Err(Error::MethodMismatch {
                a: a.method(),
                b: b.method(),
            }),
        }
    }

    /// Self-contacts of this object (see [`self_collide`](crate::self_collide)).
    pub fn self_collide(&mut self, ws: &mut Workspace, par: Par) -> Contacts {
        each!(self, h => self_collide_with(h, ws, par))
    }

    /// Intersection segments of contacts between `self` and `other` (see
    /// [`contact_segments`](crate::detail::contact_segments)); an error if the kinds differ.
    pub fn contact_segments(
        &self,
        other: &AnyHierarchy,
        pairs: &[[u32; 2]],
    ) -> Result<Vec<crate::detail::Segment>> {
        use crate::detail::contact_segments;
        match (self, other) {
            (Self::Dh(a), Self::Dh(b)) => contact_segments(a, b, pairs),
            (Self::Sphere(a), Self::Sphere(b)) => contact_segments(a, b, pairs),
            (Self::Aabb(a), Self::Aabb(b)) => contact_segments(a, b, pairs),
            (a, b) => Err(Error::MethodMismatch {
                a: a.method(),
                b: b.method(),
            }),
        }
    }
}
