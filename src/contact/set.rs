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
//! edges at its ends) is emitted once, by the one row the rules of [`Sides`] name its
//! producer: the rows are keyed by their contact and sorted, and each run of one key keeps
//! its producer, so the other rows' contacts are never built.

use super::geometry::{ContactType, Formula};
use crate::bv::BoundingVolume;
use crate::counters::Counters;
use rayon::prelude::*;

use crate::distance::{edges_cross_sq_below, point_line_distance_sq, EdgeEdge, PointTriangle};
use crate::error::{Error, Positions, Result};
use crate::hierarchy::Hierarchy;
use crate::par::Par;
use crate::query::proximity::{self, EdgePair, Proximity, Rows};
use crate::tree::MeshTables;
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
    /// of [`crate::distance`]): a point-edge contact's is
    /// [`crate::distance::point_line_distance_sq`]`(v, e0, e1)`, whichever row found it.
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
    let rows = proximity::self_proximity_in(h, dhat, ws, par, Rows::AsFound)?;
    Ok(from_rows(rows, &side, &side, true, par, &mut ws.contact))
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
    let rows = proximity::proximity_in(a, b, dhat, ws, par, Rows::AsFound)?;
    Ok(from_rows(rows, &sa, &sb, false, par, &mut ws.contact))
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
    tables: &'h MeshTables,
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
            tables: h.tree().tables(),
            rest,
            vertex_offset,
            edge_offset,
        })
    }

    /// Vertex `v`'s exact position (`v` in the caller's indices).
    fn position(&self, v: u32) -> [f64; 3] {
        self.h
            .position_f64(self.h.tree().vert_slot()[v as usize] as usize)
    }

    /// The local index of global vertex `g`, if this side has it.
    fn local(&self, g: u32) -> Option<u32> {
        let v = g.wrapping_sub(self.vertex_offset);
        ((v as usize) < self.h.tree().vertex_total()).then_some(v)
    }

    /// Edge `e` (local vertices) in the global numbering.
    fn global(&self, e: [u32; 2]) -> [u32; 2] {
        e.map(|v| v + self.vertex_offset)
    }

    fn rest_len_sq(&self, [u, v]: [u32; 2]) -> f64 {
        let (p, q) = (self.rest[u as usize], self.rest[v as usize]);
        (0..3).map(|c| (p[c] - q[c]) * (p[c] - q[c])).sum()
    }
}

/// One side of a query.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Which {
    A,
    B,
}

/// A contact's identity: its type and global vertices ([`Contact::vertices`]).
type Key = (ContactType, [u32; 4]);

/// A proximity row keyed by its contact, as the merge sorts them: the contact, the row's
/// place in its contact's producer order ([`Sides::rank`]), the row (its index among the
/// vertex-face, then face-vertex, then edge-edge rows), whether an edge-edge row's edges
/// are nearly parallel, and what its contact takes from it: the squared distance and an
/// edge-edge row's closest features (`None` for a vertex-triangle row).
// PERF: the row's values travel with the key; read back from the rows (in key order, so
// at random) they cost a cache miss a contact, an eighth of cloth-ball's contact set.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Keyed {
    key: Key,
    rank: u64,
    row: usize,
    mollified: bool,
    closest: Option<EdgeEdge>,
    distance_sq: f64,
}

/// A proximity row by its index among the vertex-face, then face-vertex, then edge-edge rows
/// ([`Keyed::row`]).
enum Row<'r> {
    /// A vertex of side `side` and a triangle of the side its vertices are tested against.
    VertexFace {
        side: Which,
        vertex: u32,
        triangle: u32,
        kind: PointTriangle,
        distance_sq: f64,
    },
    EdgeEdge(&'r EdgePair),
}

impl<'r> Row<'r> {
    fn of(rows: &'r Proximity, i: usize) -> Self {
        let (nv, nf) = (rows.vertex_face.len(), rows.face_vertex.len());
        if i < nv {
            let r = &rows.vertex_face[i];
            let (vertex, triangle, kind, distance_sq) =
                (r.vertex, r.triangle, r.kind, r.distance_sq);
            Row::VertexFace {
                side: Which::A,
                vertex,
                triangle,
                kind,
                distance_sq,
            }
        } else if i < nv + nf {
            let r = &rows.face_vertex[i - nv];
            let (vertex, triangle, kind, distance_sq) =
                (r.vertex, r.triangle, r.kind, r.distance_sq);
            Row::VertexFace {
                side: Which::B,
                vertex,
                triangle,
                kind,
                distance_sq,
            }
        } else {
            Row::EdgeEdge(&rows.edge_edge[i - nv - nf])
        }
    }
}

/// The two sides of a query (the same side twice in a self query), and the rules naming
/// each row's contact and each contact's one producer.
///
/// A point-triangle contact has one row (its vertex and triangle), an edge-edge contact one
/// row (its edges). A point-edge or point-point contact may be met by several rows, all at
/// the same exact distance: a vertex near an edge is near both of the edge's triangles, and
/// near the edges at its ends. Exactly one of them emits it, its **producer**: the first,
/// in the order below, of the rows of the query whose exact type is that contact:
///
/// - point-edge `(v, e)`: `v` against the triangles of `e` (ascending), then the edges at
///   `v` (ascending) against `e`;
/// - point-point `(v, w)`, `v < w`: `v` against the triangles at `w`, `w` against the
///   triangles at `v`, then the edges at `v` against the edges at `w`.
///
/// A row is one of the query's when the query meets it: in a self query, never a triangle
/// containing its vertex nor edges sharing a vertex. Every row of a contact measures the
/// contact's own distance (types are exact and tie-broken one way, [`crate::distance`]), so
/// all of them are among the proximity rows, and the producer is picked there
/// ([`Sides::producer`]) without testing any feature pair again.
struct Sides<'s, 'h, K: BoundingVolume> {
    a: &'s Side<'h, K>,
    b: &'s Side<'h, K>,
    self_query: bool,
}

impl<K: BoundingVolume> Sides<'_, '_, K> {
    fn side(&self, w: Which) -> &Side<'_, K> {
        match w {
            Which::A => self.a,
            Which::B => self.b,
        }
    }

    /// The side of the triangles a vertex of side `w` is tested against.
    fn faces_of(&self, w: Which) -> Which {
        match (self.self_query, w) {
            (true, _) | (false, Which::B) => Which::A,
            (false, Which::A) => Which::B,
        }
    }

    /// The side and local index of global vertex `g`.
    fn local(&self, g: u32) -> (Which, u32) {
        match self.a.local(g) {
            Some(v) => (Which::A, v),
            None => (Which::B, self.b.local(g).expect("a vertex of the query")),
        }
    }

    /// The vertices of the query: one side's in a self query, else both sides'.
    fn vertex_count(&self) -> usize {
        let total = |s: &Side<'_, K>| s.h.tree().vertex_total();
        total(self.a) + if self.self_query { 0 } else { total(self.b) }
    }

    /// Global vertex `g` as a dense index below [`Sides::vertex_count`].
    fn dense(&self, g: u32) -> usize {
        match self.local(g) {
            (Which::A, v) => v as usize,
            (Which::B, v) => self.a.h.tree().vertex_total() + v as usize,
        }
    }

    fn position(&self, g: u32) -> [f64; 3] {
        let (w, v) = self.local(g);
        self.side(w).position(v)
    }

    /// The global id of the edge joining global vertices `g0` and `g1` (one side's).
    fn edge(&self, g0: u32, g1: u32) -> u32 {
        let ((w, u), (_, v)) = (self.local(g0), self.local(g1));
        let s = self.side(w);
        s.tables.edge_id(u, v).expect("an edge of a triangle") + s.edge_offset
    }

    /// The contact of vertex `v` of side `p` and triangle `t`, whose closest features are
    /// `kind`.
    fn vertex_face_key(&self, p: Which, v: u32, t: u32, kind: PointTriangle) -> Key {
        let (sp, sf) = (self.side(p), self.side(self.faces_of(p)));
        let gv = v + sp.vertex_offset;
        let g = sf.tables.triangles[t as usize].map(|w| w + sf.vertex_offset);
        let k = kind as usize;
        match kind {
            PointTriangle::Vertex0 | PointTriangle::Vertex1 | PointTriangle::Vertex2 => (
                ContactType::PointPoint,
                [gv.min(g[k]), gv.max(g[k]), NONE, NONE],
            ),
            PointTriangle::Edge0 | PointTriangle::Edge1 | PointTriangle::Edge2 => {
                let (i, j) = (g[k - 3], g[(k - 2) % 3]);
                (ContactType::PointEdge, [gv, i.min(j), i.max(j), NONE])
            }
            PointTriangle::Face => (ContactType::PointTriangle, [gv, g[0], g[1], g[2]]),
        }
    }

    /// Edge `ea` of side `sa` and `eb` of side `sb` (local vertices), in the global numbering.
    fn global_edges(sa: &Side<'_, K>, ea: [u32; 2], sb: &Side<'_, K>, eb: [u32; 2]) -> [u32; 4] {
        let ([a0, a1], [b0, b1]) = (sa.global(ea), sb.global(eb));
        [a0, a1, b0, b1]
    }

    /// The contact of edges `g` (global vertices, each edge's smaller first, in row order)
    /// whose closest features are `kind`, `mollified` or not.
    fn edge_edge_key(g: [u32; 4], kind: EdgeEdge, mollified: bool) -> Key {
        let point_point = |i: usize, j: usize| {
            (
                ContactType::PointPoint,
                [g[i].min(g[j]), g[i].max(g[j]), NONE, NONE],
            )
        };
        let point_edge =
            |p: usize, e: usize| (ContactType::PointEdge, [g[p], g[e], g[e + 1], NONE]);
        if mollified {
            return (ContactType::EdgeEdge, g);
        }
        match kind {
            EdgeEdge::EaEb => (ContactType::EdgeEdge, g),
            EdgeEdge::Ea0Eb0 => point_point(0, 2),
            EdgeEdge::Ea0Eb1 => point_point(0, 3),
            EdgeEdge::Ea1Eb0 => point_point(1, 2),
            EdgeEdge::Ea1Eb1 => point_point(1, 3),
            EdgeEdge::EaEb0 => point_edge(2, 0),
            EdgeEdge::EaEb1 => point_edge(3, 0),
            EdgeEdge::Ea0Eb => point_edge(0, 2),
            EdgeEdge::Ea1Eb => point_edge(1, 2),
        }
    }

    /// Edges `a` and `b` (global vertices, each edge's smaller first, in row order) at
    /// positions `x` are nearly parallel by IPC's rest-length threshold.
    fn mollified(&self, g: [u32; 4], x: [[f64; 3]; 4]) -> bool {
        let rest = |i: usize| {
            let ((w, u), (_, v)) = (self.local(g[i]), self.local(g[i + 1]));
            self.side(w).rest_len_sq([u, v])
        };
        edges_cross_sq_below(x, MOLLIFIER_FACTOR * rest(0) * rest(2))
    }

    /// The contact of `key` emitted by its producer row, at squared distance `distance_sq`
    /// (`closest`: an edge-edge row's type).
    fn contact(
        &self,
        key: Key,
        distance_sq: f64,
        mollified: bool,
        closest: Option<EdgeEdge>,
    ) -> (Contact, [[f64; 3]; 4]) {
        let (kind, vertices) = key;
        let positions = vertices.map(|g| {
            if g == NONE {
                [0.0; 3]
            } else {
                self.position(g)
            }
        });
        let edges = match kind {
            ContactType::PointEdge => [self.edge(vertices[1], vertices[2]), NONE],
            ContactType::EdgeEdge => [
                self.edge(vertices[0], vertices[1]),
                self.edge(vertices[2], vertices[3]),
            ],
            ContactType::PointPoint | ContactType::PointTriangle => [NONE; 2],
        };
        // A point-edge contact's rows measure it from different ends of the edge; its value
        // is one formula's, whichever row emits it.
        let distance_sq = match kind {
            ContactType::PointEdge => {
                let [p, e0, e1, _] = positions;
                point_line_distance_sq(p, e0, e1)
            }
            _ => distance_sq,
        };
        let mut c = Contact {
            kind,
            vertices,
            edges,
            distance_sq,
            mollified,
            closest: closest.filter(|_| kind == ContactType::EdgeEdge),
            weights: [0.0; 4],
        };
        c.weights = c.formula().weights(&positions);
        (c, positions)
    }

    /// Row `i` of `rows` keyed by its contact.
    fn keyed(&self, rows: &Proximity, i: usize) -> Keyed {
        match Row::of(rows, i) {
            Row::VertexFace {
                side,
                vertex,
                triangle,
                kind,
                distance_sq,
            } => {
                let key = self.vertex_face_key(side, vertex, triangle, kind);
                let g = vertex + self.side(side).vertex_offset;
                Keyed {
                    key,
                    rank: Self::rank(&key, Some((g, triangle))),
                    row: i,
                    mollified: false,
                    closest: None,
                    distance_sq,
                }
            }
            Row::EdgeEdge(r) => {
                let (sa, sb) = (self.a, self.b);
                let g = Self::global_edges(sa, r.a, sb, r.b);
                let x = [
                    sa.position(r.a[0]),
                    sa.position(r.a[1]),
                    sb.position(r.b[0]),
                    sb.position(r.b[1]),
                ];
                let mollified = self.mollified(g, x);
                let key = Self::edge_edge_key(g, r.kind, mollified);
                Keyed {
                    key,
                    rank: Self::rank(&key, None),
                    row: i,
                    mollified,
                    closest: Some(r.kind),
                    distance_sq: r.distance_sq,
                }
            }
        }
    }

    /// A row's place in the producer order of its contact `key` (see [`Sides`]), but among
    /// edge-edge rows (all ranked last, ordered by [`Sides::producer`]): a vertex-triangle
    /// row (global vertex `g`, triangle `t` of the other side) ranks by whether `g` is the
    /// contact's second vertex (`w` of a point-point contact `(v, w)`), then by `t`.
    fn rank(key: &Key, vertex_face: Option<(u32, u32)>) -> u64 {
        match vertex_face {
            Some((g, t)) => u64::from(g != key.1[0]) << 32 | u64::from(t),
            None => 2 << 32,
        }
    }

    /// The producer among `run`, the rows of one contact sorted by rank (see [`Sides`]): the
    /// first if it is a vertex-triangle row or alone; else, among edge-edge rows, the least
    /// by the edge at `v` (then at `w`): edge ids are in the order of their vertex pairs
    /// ([`crate::tree::MeshTables`]), so the pairs are compared.
    fn producer(&self, rows: &Proximity, run: &[Keyed]) -> Keyed {
        let first = run[0];
        if run.len() == 1 || first.closest.is_none() {
            return first;
        }
        debug_assert!(
            matches!(
                first.key.0,
                ContactType::PointPoint | ContactType::PointEdge
            ),
            "one row per point-triangle and edge-edge contact"
        );
        let [v, w, ..] = first.key.1;
        // The edges of an edge-edge row at global vertices `v` and, for a point-point
        // contact, `w` (local vertex pairs of the one side each is on).
        let at = |k: &Keyed| {
            let Row::EdgeEdge(r) = Row::of(rows, k.row) else {
                unreachable!("rows after an edge-edge row in rank order are edge-edge rows")
            };
            let [a0, a1] = self.a.global(r.a);
            let on_a = |g: u32| g == a0 || g == a1;
            let at_w = match first.key.0 {
                ContactType::PointPoint if on_a(w) => r.a,
                ContactType::PointPoint => r.b,
                _ => [0; 2],
            };
            (if on_a(v) { r.a } else { r.b }, at_w)
        };
        *run.iter().min_by_key(|k| at(k)).expect("a run has a row")
    }

    /// The contact of row `k`.
    fn contact_of(&self, k: &Keyed) -> (Contact, [[f64; 3]; 4]) {
        self.contact(k.key, k.distance_sq, k.mollified, k.closest)
    }
}

/// The scratch of [`from_rows`], kept in the caller's [`Workspace`] so that a contact set
/// built again reuses its memory: the keyed rows as found, the same sorted, and the
/// counting sort's starts.
#[derive(Clone, Debug, Default)]
pub(crate) struct ContactScratch {
    found: Vec<Keyed>,
    sorted: Vec<Keyed>,
    starts: Vec<usize>,
}

/// The contact set of proximity `rows` between sides `a` and `b` (the same side, and
/// `self_query`, for a self query): each row's contact, once (from its producer, see
/// [`Sides`]), sorted by `(kind, vertices)`. The rows are keyed, sorted and their contacts
/// built in parallel if `par` says so (the result does not depend on it).
pub(crate) fn from_rows<K: BoundingVolume>(
    rows: Proximity,
    a: &Side<'_, K>,
    b: &Side<'_, K>,
    self_query: bool,
    par: Par,
    scratch: &mut ContactScratch,
) -> ContactSet {
    let sides = Sides { a, b, self_query };
    let n = rows.vertex_face.len() + rows.face_vertex.len() + rows.edge_edge.len();
    let ContactScratch {
        found,
        sorted: keyed,
        starts,
    } = scratch;
    found.clear();
    if par.is_parallel() {
        par.install(|| {
            found.par_extend(
                (0..n)
                    .into_par_iter()
                    .with_min_len(1024)
                    .map(|i| sides.keyed(&rows, i)),
            )
        });
    } else {
        found.extend((0..n).map(|i| sides.keyed(&rows, i)));
    }
    // By contact, then producer order (`Sides::rank`); the row makes the order total.
    let vertices = sides.vertex_count();
    crate::sort::by_group_into(
        found,
        keyed,
        starts,
        ContactType::ALL.len() * vertices,
        |k| k.key.0 as usize * vertices + sides.dense(k.key.1[0]),
        |k| (k.key.0, crate::sort::as_one(k.key.1), k.rank, k.row),
    );
    // Each contact's rows are one run of the sorted keys; keep its producer, in place.
    let mut kept = 0;
    let mut start = 0;
    while start < keyed.len() {
        let key = keyed[start].key;
        // PERF: a scan, not a binary search of the rest: runs are one to a few rows.
        let end = start
            + 1
            + keyed[start + 1..]
                .iter()
                .take_while(|k| k.key == key)
                .count();
        keyed[kept] = sides.producer(&rows, &keyed[start..end]);
        kept += 1;
        start = end;
    }
    keyed.truncate(kept);
    let (contacts, positions): (Vec<Contact>, Vec<[[f64; 3]; 4]>) = if par.is_parallel() {
        par.install(|| {
            keyed
                .par_iter()
                .with_min_len(1024)
                .map(|k| sides.contact_of(k))
                .unzip()
        })
    } else {
        keyed.iter().map(|k| sides.contact_of(k)).unzip()
    };
    let mut counters = rows.counters;
    counters.contacts = contacts.len() as u64;
    ContactSet {
        contacts,
        positions,
        counters,
    }
}
