//! The contact set: every pair of features within `dhat`, once, with the IPC Toolkit's
//! collision type, the closest-point weights, and the positions its derivatives are taken at.
//!
//! Built from the proximity query's rows (decided exactly): a vertex-triangle row is a
//! point-point, point-edge or point-triangle contact by its closest sub-feature; an edge-edge
//! row is an edge-edge contact when its closest points are interior to both edges, or when
//! the edges are nearly parallel ([`mollified`](Contact::mollified): the squared norm of the
//! cross product of their vectors is below `1e-3 |a_rest|^2 |b_rest|^2`, decided exactly),
//! and otherwise the point-point or point-edge contact of its closest features. These are
//! the IPC Toolkit's rules (`NormalCollisions::build`). A point-point or point-edge contact
//! found by several rows (a vertex near an edge is near both its triangles, and near the
//! edges at its ends) is kept once.

use super::geometry::{ContactType, Formula};
use crate::bv::BoundingVolume;
use crate::counters::Counters;
use crate::distance::{edges_cross_sq_below, EdgeEdge, PointTriangle};
use crate::error::{Error, Positions, Result};
use crate::hierarchy::Hierarchy;
use crate::par::Par;
use crate::query::proximity::{self, Proximity};
use crate::walk::Workspace;

/// No vertex or edge in this slot.
pub const NONE: u32 = u32::MAX;

/// The IPC Toolkit's mollifier threshold factor: edges are nearly parallel when
/// `|a x b|^2 < MOLLIFIER_FACTOR |a_rest|^2 |b_rest|^2`.
pub const MOLLIFIER_FACTOR: f64 = 1e-3;

/// One contact of a [`ContactSet`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Contact {
    /// The type.
    pub kind: ContactType,
    /// The vertices, by type: point-point `[v, w]` (`v < w`), point-edge `[v, e0, e1]`
    /// (`e0 < e1`), point-triangle `[v, t0, t1, t2]` (the triangle's corners in its own
    /// order), edge-edge `[a0, a1, b0, b1]` (`a0 < a1`, `b0 < b1`, `a` the edge of the
    /// first hierarchy, or the smaller in a self query); [`NONE`] in unused slots.
    pub vertices: [u32; 4],
    /// The edges a row has, as edge ids ([`crate::RegionTree::edges`] of the vertex's object
    /// plus its offset): point-edge `[e, NONE]`, edge-edge `[a, b]`; `[NONE, NONE]` otherwise.
    pub edges: [u32; 2],
    /// Squared distance of the closest features (exact decision, the value within the bound
    /// of [`crate::distance`]).
    pub distance_sq: f64,
    /// Edge-edge rows only: the edges are nearly parallel (the IPC Toolkit multiplies their
    /// barrier by a mollifier).
    pub mollified: bool,
    /// Edge-edge rows: which sub-features are closest ([`EdgeEdge::EaEb`] unless mollified),
    /// and so which formula measures the row; `None` for the other types.
    pub closest: Option<EdgeEdge>,
    /// Closest-point weights: `sum_i weights[i] x[vertices[i]]` is the vector between the
    /// closest points (see [`crate::contact::geometry`]); zero in unused slots.
    pub weights: [f64; 4],
}

impl Contact {
    /// The squared distance of the row's features at `x` (its vertex slots), by the formula
    /// of its type, or of its closest features for an edge-edge row.
    pub fn distance_sq_at(&self, x: &[[f64; 3]; 4]) -> f64 {
        self.formula().distance_sq(x)
    }

    /// The gradient of [`Contact::distance_sq_at`] (slot `i`, coordinate `c` at `3 i + c`).
    pub fn gradient_at(&self, x: &[[f64; 3]; 4]) -> [f64; 12] {
        self.formula().gradient(x)
    }

    /// The Hessian of [`Contact::distance_sq_at`].
    pub fn hessian_at(&self, x: &[[f64; 3]; 4]) -> [[f64; 12]; 12] {
        self.formula().hessian(x)
    }

    pub(crate) fn formula(&self) -> Formula {
        match self.closest {
            Some(kind) => Formula::of_edge_edge(kind),
            None => Formula::of_type(self.kind),
        }
    }
}

/// The contacts within `dhat`, sorted by type then vertices, with the positions they were
/// found at.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ContactSet {
    /// The contacts, sorted by `(kind, vertices)`.
    pub contacts: Vec<Contact>,
    /// The positions of each contact's vertex slots at the query (zero in unused slots).
    pub positions: Vec<[[f64; 3]; 4]>,
    /// The proximity query's counters; `contacts` counts the contacts kept.
    pub counters: Counters,
}

impl ContactSet {
    /// Number of contacts.
    pub fn len(&self) -> usize {
        self.contacts.len()
    }

    /// Whether there are none.
    pub fn is_empty(&self) -> bool {
        self.contacts.is_empty()
    }

    /// Each contact's squared distance by its formula at its positions (the f64 formula of
    /// [`crate::contact::geometry`]; [`Contact::distance_sq`] is the proximity query's
    /// value).
    pub fn distances_sq(&self) -> Vec<f64> {
        self.rows()
            .map(|(c, x)| c.formula().distance_sq(x))
            .collect()
    }

    /// The gradient of each contact's squared distance with respect to its vertex slots
    /// (12 numbers: slot `i`, coordinate `c` at `3 i + c`; zero in unused slots).
    pub fn gradients(&self) -> Vec<[f64; 12]> {
        self.rows().map(|(c, x)| c.formula().gradient(x)).collect()
    }

    /// The Hessian of each contact's squared distance (12 x 12).
    pub fn hessians(&self) -> Vec<[[f64; 12]; 12]> {
        self.rows().map(|(c, x)| c.formula().hessian(x)).collect()
    }

    fn rows(&self) -> impl Iterator<Item = (&Contact, &[[f64; 3]; 4])> {
        self.contacts.iter().zip(&self.positions)
    }
}

/// Every contact of `h` with itself within `dhat` (finite, `>= 0`), on the calling thread,
/// with the mollifier thresholds from the positions `h` was built with.
pub fn self_contact_set<K: BoundingVolume>(h: &Hierarchy<K>, dhat: f64) -> Result<ContactSet> {
    self_contact_set_with(h, dhat, None, &mut Workspace::default(), Par::Seq)
}

/// [`self_contact_set`] with rest positions for the mollifier thresholds (`None`: those `h`
/// was built with; else one per vertex, finite), caller-owned scratch and a choice of
/// parallelism (the result does not depend on it).
pub fn self_contact_set_with<K: BoundingVolume>(
    h: &Hierarchy<K>,
    dhat: f64,
    rest: Option<&[[f64; 3]]>,
    ws: &mut Workspace,
    par: Par,
) -> Result<ContactSet> {
    let side = Side::new(h, rest, 0, 0)?;
    let rows = proximity::self_proximity_with(h, dhat, ws, par)?;
    Ok(from_rows(rows, &side, &side))
}

/// Every contact between `a` and `b` within `dhat`. Vertices are numbered `a`'s first, then
/// `b`'s (offset by `a`'s vertex count); edges likewise (offset by `a`'s edge count).
pub fn contact_set<K: BoundingVolume>(
    a: &Hierarchy<K>,
    b: &Hierarchy<K>,
    dhat: f64,
) -> Result<ContactSet> {
    contact_set_with(
        a,
        b,
        dhat,
        [None, None],
        &mut Workspace::default(),
        Par::Seq,
    )
}

/// [`contact_set`] with rest positions per hierarchy, scratch and parallelism.
pub fn contact_set_with<K: BoundingVolume>(
    a: &Hierarchy<K>,
    b: &Hierarchy<K>,
    dhat: f64,
    rest: [Option<&[[f64; 3]]>; 2],
    ws: &mut Workspace,
    par: Par,
) -> Result<ContactSet> {
    let sa = Side::new(a, rest[0], 0, 0)?;
    let sb = Side::new(
        b,
        rest[1],
        offset(a.tree().vertex_total(), b.tree().vertex_total())?,
        offset(a.tree().edges().len(), b.tree().edges().len())?,
    )?;
    let rows = proximity::proximity_with(a, b, dhat, ws, par)?;
    Ok(from_rows(rows, &sa, &sb))
}

/// An offset `first` before `then` more, if both fit the `u32` numbering.
pub(crate) fn offset(first: usize, then: usize) -> Result<u32> {
    let total = first.saturating_add(then);
    if total >= NONE as usize {
        return Err(Error::TooManyVertices(total));
    }
    Ok(first as u32)
}

/// One object of a contact set: its hierarchy, rest pose and place in the numbering.
pub(crate) struct Side<'h, K: BoundingVolume> {
    h: &'h Hierarchy<K>,
    rest: &'h [[f64; 3]],
    vertex_offset: u32,
    edge_offset: u32,
}

impl<'h, K: BoundingVolume> Side<'h, K> {
    pub(crate) fn new(
        h: &'h Hierarchy<K>,
        rest: Option<&'h [[f64; 3]]>,
        vertex_offset: u32,
        edge_offset: u32,
    ) -> Result<Self> {
        let rest = match rest {
            None => h.rest_positions(),
            Some(r) => {
                crate::mesh::check_positions_f64(r, h.tree().vertex_total(), Positions::Rest)?;
                r
            }
        };
        Ok(Self {
            h,
            rest,
            vertex_offset,
            edge_offset,
        })
    }

    fn position(&self, v: u32) -> [f64; 3] {
        self.h
            .position_f64(self.h.tree().vert_slot()[v as usize] as usize)
    }

    fn corners(&self, t: u32) -> [u32; 3] {
        self.h.tree().tables().triangles[t as usize]
    }

    fn edge(&self, u: u32, v: u32) -> u32 {
        self.h.tree().edge_id(u, v).expect("an edge of a triangle") + self.edge_offset
    }

    fn rest_len_sq(&self, u: u32, v: u32) -> f64 {
        let (p, q) = (self.rest[u as usize], self.rest[v as usize]);
        (0..3).map(|c| (p[c] - q[c]) * (p[c] - q[c])).sum()
    }
}

/// A contact under construction: the type, the vertices as (side, index) and what the row
/// knew.
struct Draft {
    kind: ContactType,
    /// Global vertex numbers (offsets applied).
    vertices: [u32; 4],
    edges: [u32; 2],
    distance_sq: f64,
    mollified: bool,
    closest: Option<EdgeEdge>,
    positions: [[f64; 3]; 4],
}

/// The contact of a vertex `v` of side `p` near triangle `t` of side `f`.
fn vertex_face<K: BoundingVolume>(
    p: &Side<'_, K>,
    v: u32,
    f: &Side<'_, K>,
    t: u32,
    distance_sq: f64,
    kind: PointTriangle,
) -> Draft {
    let c = f.corners(t);
    let gv = v + p.vertex_offset;
    let g = c.map(|w| w + f.vertex_offset);
    let mut d = Draft {
        kind: ContactType::PointTriangle,
        vertices: [gv, g[0], g[1], g[2]],
        edges: [NONE; 2],
        distance_sq,
        mollified: false,
        closest: None,
        positions: [
            p.position(v),
            f.position(c[0]),
            f.position(c[1]),
            f.position(c[2]),
        ],
    };
    let k = kind as usize;
    match kind {
        PointTriangle::Vertex0 | PointTriangle::Vertex1 | PointTriangle::Vertex2 => {
            let (p, q) = (d.positions[0], d.positions[1 + k]);
            d.kind = ContactType::PointPoint;
            (d.vertices, d.positions) = if gv < g[k] {
                ([gv, g[k], NONE, NONE], [p, q, [0.0; 3], [0.0; 3]])
            } else {
                ([g[k], gv, NONE, NONE], [q, p, [0.0; 3], [0.0; 3]])
            };
        }
        PointTriangle::Edge0 | PointTriangle::Edge1 | PointTriangle::Edge2 => {
            let (i, j) = (k - 3, (k - 2) % 3);
            let (i, j) = if g[i] < g[j] { (i, j) } else { (j, i) };
            d.kind = ContactType::PointEdge;
            d.vertices = [gv, g[i], g[j], NONE];
            d.edges = [f.edge(c[i], c[j]), NONE];
            d.positions = [
                d.positions[0],
                d.positions[1 + i],
                d.positions[1 + j],
                [0.0; 3],
            ];
        }
        PointTriangle::Face => {}
    }
    d
}

/// The contact of edge `a` of side `sa` and edge `b` of side `sb`.
fn edge_edge<K: BoundingVolume>(
    sa: &Side<'_, K>,
    a: [u32; 2],
    sb: &Side<'_, K>,
    b: [u32; 2],
    distance_sq: f64,
    kind: EdgeEdge,
) -> Draft {
    let x = [
        sa.position(a[0]),
        sa.position(a[1]),
        sb.position(b[0]),
        sb.position(b[1]),
    ];
    let g = [
        a[0] + sa.vertex_offset,
        a[1] + sa.vertex_offset,
        b[0] + sb.vertex_offset,
        b[1] + sb.vertex_offset,
    ];
    let threshold = MOLLIFIER_FACTOR * sa.rest_len_sq(a[0], a[1]) * sb.rest_len_sq(b[0], b[1]);
    let mollified = edges_cross_sq_below(x, threshold);
    let mut d = Draft {
        kind: ContactType::EdgeEdge,
        vertices: g,
        edges: [sa.edge(a[0], a[1]), sb.edge(b[0], b[1])],
        distance_sq,
        mollified,
        closest: Some(kind),
        positions: x,
    };
    if mollified || kind == EdgeEdge::EaEb {
        return d;
    }
    // The closest features: a corner pair, or a corner and the other edge.
    let point_point = |i: usize, j: usize, d: &mut Draft| {
        let (i, j) = if g[i] < g[j] { (i, j) } else { (j, i) };
        d.kind = ContactType::PointPoint;
        d.vertices = [g[i], g[j], NONE, NONE];
        d.positions = [x[i], x[j], [0.0; 3], [0.0; 3]];
        d.edges = [NONE; 2];
    };
    let point_edge = |p: usize, e: [usize; 2], edge: u32, d: &mut Draft| {
        d.kind = ContactType::PointEdge;
        d.vertices = [g[p], g[e[0]], g[e[1]], NONE];
        d.positions = [x[p], x[e[0]], x[e[1]], [0.0; 3]];
        d.edges = [edge, NONE];
    };
    let (ea, eb) = (d.edges[0], d.edges[1]);
    match kind {
        EdgeEdge::Ea0Eb0 => point_point(0, 2, &mut d),
        EdgeEdge::Ea0Eb1 => point_point(0, 3, &mut d),
        EdgeEdge::Ea1Eb0 => point_point(1, 2, &mut d),
        EdgeEdge::Ea1Eb1 => point_point(1, 3, &mut d),
        EdgeEdge::EaEb0 => point_edge(2, [0, 1], ea, &mut d),
        EdgeEdge::EaEb1 => point_edge(3, [0, 1], ea, &mut d),
        EdgeEdge::Ea0Eb => point_edge(0, [2, 3], eb, &mut d),
        EdgeEdge::Ea1Eb => point_edge(1, [2, 3], eb, &mut d),
        EdgeEdge::EaEb => unreachable!("returned above"),
    }
    d.closest = None;
    d
}

/// The contact set of proximity `rows` between sides `a` and `b` (the same side for a self
/// query).
pub(crate) fn from_rows<K: BoundingVolume>(
    rows: Proximity,
    a: &Side<'_, K>,
    b: &Side<'_, K>,
) -> ContactSet {
    let mut drafts: Vec<Draft> =
        Vec::with_capacity(rows.vertex_face.len() + rows.face_vertex.len() + rows.edge_edge.len());
    for r in &rows.vertex_face {
        drafts.push(vertex_face(
            a,
            r.vertex,
            b,
            r.triangle,
            r.distance_sq,
            r.kind,
        ));
    }
    for r in &rows.face_vertex {
        drafts.push(vertex_face(
            b,
            r.vertex,
            a,
            r.triangle,
            r.distance_sq,
            r.kind,
        ));
    }
    for r in &rows.edge_edge {
        drafts.push(edge_edge(a, r.a, b, r.b, r.distance_sq, r.kind));
    }
    // One contact per (type, vertices): the duplicates are the point-point and point-edge
    // contacts several rows found; they are the same features, so the same distance up to
    // the rounding of the formula each row used (the least is kept).
    drafts.sort_unstable_by(|x, y| {
        (x.kind, x.vertices)
            .cmp(&(y.kind, y.vertices))
            .then(x.distance_sq.total_cmp(&y.distance_sq))
    });
    drafts.dedup_by(|later, kept| later.kind == kept.kind && later.vertices == kept.vertices);
    let mut set = ContactSet {
        contacts: Vec::with_capacity(drafts.len()),
        positions: Vec::with_capacity(drafts.len()),
        counters: rows.counters,
    };
    for d in drafts {
        let mut c = Contact {
            kind: d.kind,
            vertices: d.vertices,
            edges: d.edges,
            distance_sq: d.distance_sq,
            mollified: d.mollified,
            closest: d.closest,
            weights: [0.0; 4],
        };
        c.weights = c.formula().weights(&d.positions);
        set.contacts.push(c);
        set.positions.push(d.positions);
    }
    set.counters.contacts = set.contacts.len() as u64;
    set
}
