//! The clearance test: a node of one mesh whose feature pairs (a vertex and a triangle not
//! containing it, two edges sharing no vertex) are all farther apart than a distance,
//! proved from the node's triangles and boundary without enumerating a pair. A self query's
//! walk skips the self pair of such a node: the pairs between mesh neighbours of a smooth
//! sheet, most of the candidates of cloth, never reach the feature-pair layer.
//!
//! The proof. Let the node be a patch (disks of triangles touching at most at vertices,
//! [`crate::tree::Patches`]) and map its vertices into a plane by a linear map `P` (a
//! projection along the mean of its triangles' normals, [`Projection`]), computed with
//! roundings: the *image* is the surface whose triangles have the computed points as
//! corners. If every triangle's image has the same strict orientation, each disk's boundary
//! image is a simple closed curve, and no two loops cross, share more than one vertex, or
//! lie one inside the other, the image is one-to-one on the patch (an
//! orientation-preserving, locally one-to-one map of a disk whose boundary goes once around
//! a simple curve has degree one: a point inside has exactly one preimage; and the disks'
//! images, bounded by loops neither crossing nor nested, meet at most at the vertices the
//! disks share). In the plane, then:
//! - a segment from a vertex `v` to a point of a triangle not containing `v` leaves the
//!   image of `v`'s triangles, through an edge opposite `v` in one of them (so it is longer
//!   than that triangle's height over `v`) or, at a boundary vertex, through the outside of
//!   the patch, which it enters again across a boundary edge not at `v`;
//! - two edges sharing no vertex are disjoint, so their distance is that of an endpoint of
//!   one to the other edge: a vertex-triangle distance or a height, as above.
//!
//! So if every triangle's three heights and every boundary vertex's distance to every
//! boundary edge not at it exceed `c`, and no two boundary edges cross, every pair is more
//! than `c` apart in the image. Each computed point is within `e` of the exact `P` of its
//! vertex, and a point of a feature is the same convex combination in both, so the pair is
//! more than `c - 2e` apart under `P`, and more than `(c - 2e) / |P|` apart in space. Over a
//! step, two points of two features approach each other under `P` by at most the largest
//! difference of two vertex displacements under `P`, `D`: with `c = |P| distance + D + 2e`
//! no pair comes within `distance` during the step. A sheet translating or turning a little
//! as a whole has a small `D` however far it moves.
//!
//! Everything is computed in `f64` from the exact positions, and every comparison keeps a
//! margin of [`REL`] of the magnitudes it combines, far above their few roundings: a node
//! passes only when the proof holds for the exact positions. A node that fails is walked as
//! before, so the test changes the work, never an answer.

use crate::bv::BoundingVolume;
use crate::hierarchy::Hierarchy;
use crate::tree::{Patch, RegionTree};

/// The relative margin of every comparison (each side is a few roundings, at most `4
/// EPSILON` relative, from its exact value).
const REL: f64 = 1.0 / (1u64 << 40) as f64;

/// The most triangles whose normals choose the projection.
const NORMAL_SAMPLE: usize = 64;

/// A point of the projection plane.
type P2 = [f64; 2];

/// The most loops of a patch the test compares pairwise for nesting.
const MOST_LOOPS: usize = 16;

/// Whether every feature pair of node `n` of `tree` that shares no vertex is farther apart
/// than a distance at the positions `at` (internal vertex index to position): `reach` gives,
/// for the node's projection, the distance in the plane beyond which its pairs are clear
/// (see [`Projection::stretch`]). Only patches pass.
pub(crate) fn node_is_clear(
    tree: &RegionTree,
    n: usize,
    at: &impl Fn(usize) -> [f64; 3],
    reach: impl FnOnce(&Projection) -> f64,
) -> bool {
    let tris = &tree.triangles()[tree.tri_range(n)];
    let Some(projection) = Projection::facing(tris, at) else {
        return false;
    };
    let plane = |v: u32| projection.apply(at(v as usize));
    // Most nodes that fail have a triangle facing the other way: found before the reach
    // (a pass over the node's vertices in CCD) is computed.
    let mut least_height_sq = f64::INFINITY;
    let mut farthest = 0.0f64;
    for t in tris {
        let corners = t.map(|v| at(v as usize));
        for p in &corners {
            farthest = farthest.max(p[0].abs() + p[1].abs() + p[2].abs());
        }
        match height_sq(corners.map(|p| projection.apply(p))) {
            Some(h2) => least_height_sq = least_height_sq.min(h2),
            None => return false,
        }
    }
    // Each computed point of the plane is within `REL * farthest` of the exact projection
    // of its vertex, so a pair's exact projections are farther apart than their computed
    // ones less twice that.
    let c = ((reach(&projection) + 2.0 * REL * farthest) * (1.0 + REL)).next_up();
    if !(c.is_finite() && c >= 0.0) || least_height_sq <= c * c * (1.0 + REL) {
        return false;
    }
    // The topology last: only a node whose triangles all face one way, with heights above
    // the reach, asks for its disks (computed on the first ask).
    let Some(patch) = tree.patches().patch(tree, n) else {
        return false;
    };
    patch.loops.len() <= MOST_LOOPS && boundary_is_clear(&patch, &plane, c)
}

/// Whether node `n` of `h` holds no feature pair within `distance` in its current pose.
#[inline(never)]
pub(crate) fn pose_is_clear<K: BoundingVolume>(h: &Hierarchy<K>, n: usize, distance: f64) -> bool {
    node_is_clear(h.tree(), n, &|v| h.position_f64(v), |projection| {
        projection.stretch(distance)
    })
}

/// Whether node `n` of `tree` holds no feature pair that comes within `distance` during
/// `[0, horizon]` of the linear motion from `x0` to `x1` (internal vertex order).
#[inline(never)]
pub(crate) fn motion_is_clear(
    tree: &RegionTree,
    n: usize,
    x0: &[[f64; 3]],
    x1: &[[f64; 3]],
    horizon: f64,
    distance: f64,
) -> bool {
    node_is_clear(tree, n, &|v| x0[v], |projection| {
        let approach = Moves::of(tree, n, x0, x1, projection).approach(projection);
        projection.stretch(distance) + approach * horizon * (1.0 + REL)
    })
}

/// A linear map `p -> (u . p, v . p)` from space onto a plane, with `u x v` along the
/// normals of the triangles it projects (so they turn counterclockwise), and a bound on
/// how much it can lengthen a vector. Any linear map would serve the proof: two points at
/// least `c` apart in the plane are at least `c / norm` apart in space.
pub(crate) struct Projection {
    u: [f64; 3],
    v: [f64; 3],
    /// An upper bound on the map's operator norm (1 up to roundings).
    norm: f64,
}

impl Projection {
    /// The projection along the sum of a sample of the triangles' normals, `None` when the
    /// sum vanishes or a sampled normal faces away from it (that triangle would turn
    /// clockwise: the node cannot pass).
    fn facing(tris: &[[u32; 3]], at: &impl Fn(usize) -> [f64; 3]) -> Option<Self> {
        let stride = tris.len().div_ceil(NORMAL_SAMPLE).max(1);
        let mut normals = [[0.0f64; 3]; NORMAL_SAMPLE];
        let mut sum = [0.0f64; 3];
        let mut sampled = 0;
        for t in tris.iter().step_by(stride) {
            let [a, b, c] = t.map(|v| at(v as usize));
            let e = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
            let f = [c[0] - a[0], c[1] - a[1], c[2] - a[2]];
            let normal = [
                e[1] * f[2] - e[2] * f[1],
                e[2] * f[0] - e[0] * f[2],
                e[0] * f[1] - e[1] * f[0],
            ];
            for k in 0..3 {
                sum[k] += normal[k];
            }
            normals[sampled] = normal;
            sampled += 1;
        }
        let dot = |x: [f64; 3], y: [f64; 3]| x[0] * y[0] + x[1] * y[1] + x[2] * y[2];
        let length = dot(sum, sum).sqrt();
        if !(length.is_finite() && length > 0.0)
            || normals[..sampled].iter().any(|&m| dot(m, sum) <= 0.0)
        {
            return None;
        }
        let n = sum.map(|x| x / length);
        // A right-handed orthonormal pair across `n` (Duff et al., "Building an orthonormal
        // basis, revisited", 2017): `u x v = n`, and the coordinate axes when `n` is one.
        let sign = 1.0f64.copysign(n[2]);
        let a = -1.0 / (sign + n[2]);
        let b = n[0] * n[1] * a;
        let u = [1.0 + sign * n[0] * n[0] * a, sign * b, -sign * n[0]];
        let v = [b, sign + n[1] * n[1] * a, -n[1]];
        // The operator norm's square is the largest eigenvalue of the 2x2 Gram matrix, at
        // most its largest diagonal entry plus the off-diagonal's magnitude.
        let gram = dot(u, u).max(dot(v, v)) + dot(u, v).abs();
        let norm = (gram * (1.0 + REL)).sqrt() * (1.0 + REL);
        norm.is_finite().then_some(Self { u, v, norm })
    }

    /// The computed image of `p`: within `REL * |p|_1` of the exact one (two roundings of
    /// a three-term dot product whose coefficients are at most 1 up to a rounding).
    #[inline(always)]
    fn apply(&self, p: [f64; 3]) -> P2 {
        let (u, v) = (self.u, self.v);
        [
            u[0] * p[0] + u[1] * p[1] + u[2] * p[2],
            v[0] * p[0] + v[1] * p[1] + v[2] * p[2],
        ]
    }

    /// The distance in the plane that proves a distance `d` in space: `d` times the norm,
    /// rounded up.
    fn stretch(&self, d: f64) -> f64 {
        ((d * self.norm) * (1.0 + REL)).next_up()
    }
}

/// The displacements `x1 - x0` of a node's vertices, projected: the box holding them in
/// the plane, the longest in space and the largest `|x1 - x0|_1` (the projection's rounding
/// scale).
struct Moves {
    lo: P2,
    hi: P2,
    longest: f64,
    farthest: f64,
}

impl Moves {
    fn of(
        tree: &RegionTree,
        n: usize,
        x0: &[[f64; 3]],
        x1: &[[f64; 3]],
        projection: &Projection,
    ) -> Self {
        let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
        let (mut longest_sq, mut farthest) = (0.0f64, 0.0f64);
        for v in tree.region_vertices(n) {
            let (p, q) = (x0[v as usize], x1[v as usize]);
            let u = [q[0] - p[0], q[1] - p[1], q[2] - p[2]];
            longest_sq = longest_sq.max(u[0] * u[0] + u[1] * u[1] + u[2] * u[2]);
            farthest = farthest.max(u[0].abs() + u[1].abs() + u[2].abs());
            let w = projection.apply(u);
            for k in 0..2 {
                lo[k] = lo[k].min(w[k]);
                hi[k] = hi[k].max(w[k]);
            }
        }
        Self {
            lo,
            hi,
            longest: longest_sq.sqrt(),
            farthest,
        }
    }

    /// An upper bound on how much two points of the node's features can approach each
    /// other in the plane over the whole motion: the largest difference of two projected
    /// displacements (a point of a feature moves by a convex combination of its vertices'
    /// displacements), at most the norm times twice the longest displacement and at most
    /// the diagonal of their box in the plane. Each computed displacement is within a
    /// rounding of `longest` of the exact one and its computed image within `REL *
    /// farthest` of that one's: the box grows by [`REL`] of both.
    fn approach(&self, projection: &Projection) -> f64 {
        if !(self.longest.is_finite() && self.farthest.is_finite()) {
            return f64::INFINITY;
        }
        let slack = REL * (self.longest + 2.0 * self.farthest);
        let extent = |k: usize| (self.hi[k] - self.lo[k]).max(0.0) + slack;
        let diagonal = (extent(0) * extent(0) + extent(1) * extent(1)).sqrt();
        (2.0 * self.longest * projection.norm).min(diagonal) * (1.0 + REL)
    }
}

/// `u x v` in the plane and the sum of its two products' magnitudes (its rounding scale).
#[inline(always)]
fn cross(u: P2, v: P2) -> (f64, f64) {
    let (x, y) = (u[0] * v[1], u[1] * v[0]);
    (x - y, x.abs() + y.abs())
}

#[inline(always)]
fn sub(a: P2, b: P2) -> P2 {
    [a[0] - b[0], a[1] - b[1]]
}

#[inline(always)]
fn norm_sq(u: P2) -> f64 {
    u[0] * u[0] + u[1] * u[1]
}

/// A lower bound on the square of a projected triangle's least height if it certainly
/// turns counterclockwise: `((b - a) x (c - a))_low^2 / |longest edge|^2`, rounded down by
/// [`REL`].
#[inline(always)]
fn height_sq([a, b, c]: [P2; 3]) -> Option<f64> {
    let (e, f) = (sub(b, a), sub(c, a));
    let (o, scale) = cross(e, f);
    let low = o - REL * scale;
    if low <= 0.0 {
        return None;
    }
    let longest = norm_sq(e).max(norm_sq(f)).max(norm_sq(sub(c, b)));
    Some(low * low / longest * (1.0 - REL))
}

/// Whether `v` is farther than `c` from the segment `p q` (`c2`: `c^2` rounded up): beyond
/// `c` from its line, or past one end and beyond `c` from that end.
#[inline(always)]
fn point_clear_of_segment(v: P2, p: P2, q: P2, c2: f64) -> bool {
    let (d, w) = (sub(q, p), sub(v, p));
    let (o, scale) = cross(d, w);
    let low = o.abs() - REL * scale;
    if low > 0.0 && low * low * (1.0 - REL) > c2 * norm_sq(d) {
        return true;
    }
    let dot = |x: P2, y: P2| {
        (
            x[0] * y[0] + x[1] * y[1],
            (x[0] * y[0]).abs() + (x[1] * y[1]).abs(),
        )
    };
    let (before, scale) = dot(w, d);
    if before < -REL * scale {
        // Closest to `p`.
        return norm_sq(w) * (1.0 - REL) > c2;
    }
    let u = sub(v, q);
    let (after, scale) = dot(u, d);
    after > REL * scale && norm_sq(u) * (1.0 - REL) > c2
}

/// Whether `p` and `q` lie strictly on one side of the line through `a` and `b`.
#[inline(always)]
fn one_side(a: P2, b: P2, p: P2, q: P2) -> bool {
    let d = sub(b, a);
    let side = |x: P2| {
        let (o, scale) = cross(d, sub(x, a));
        if o > REL * scale {
            1
        } else if o < -REL * scale {
            -1
        } else {
            0
        }
    };
    let s = side(p);
    s != 0 && s == side(q)
}

/// The projected boundary loops are simple, do not cross and are not nested, and each
/// boundary vertex is farther than `c` from each boundary edge not at it. Edges whose boxes
/// are more than `c` apart on an axis are never compared (a sweep along the first axis).
fn boundary_is_clear(patch: &Patch<'_>, plane: &impl Fn(u32) -> P2, c: f64) -> bool {
    let boundary = patch.edges;
    let c2 = c * c * (1.0 + REL);
    let reach = c * (1.0 + REL);
    let ends: Vec<[P2; 2]> = boundary.iter().map(|e| e.map(plane)).collect();
    let boxes: Vec<[P2; 2]> = ends
        .iter()
        .map(|[p, q]| {
            [
                [p[0].min(q[0]), p[1].min(q[1])],
                [p[0].max(q[0]), p[1].max(q[1])],
            ]
        })
        .collect();
    let mut order: Vec<u32> = (0..boundary.len() as u32).collect();
    order.sort_unstable_by(|&x, &y| boxes[x as usize][0][0].total_cmp(&boxes[y as usize][0][0]));
    for (s, &x) in order.iter().enumerate() {
        let x = x as usize;
        for &y in &order[s + 1..] {
            let y = y as usize;
            if boxes[y][0][0] - boxes[x][1][0] > reach {
                break;
            }
            let gap_y = (boxes[y][0][1] - boxes[x][1][1]).max(boxes[x][0][1] - boxes[y][1][1]);
            if gap_y > reach {
                continue;
            }
            if !edges_clear(boundary[x], ends[x], boundary[y], ends[y], c2) {
                return false;
            }
        }
    }
    // Two loops that neither cross nor touch but at one shared vertex are nested or apart:
    // the rest of one is a connected curve off the other, so one of its vertices tells
    // which. Loops sharing two vertices or more are refused: the arcs between those
    // vertices could lie on either side.
    patch.loops.iter().enumerate().all(|(a, la)| {
        patch.loops.iter().enumerate().all(|(b, lb)| {
            if a == b {
                return true;
            }
            let mut on_b: Vec<u32> = boundary[lb.clone()].iter().map(|e| e[0]).collect();
            on_b.sort_unstable();
            let off_b: Vec<usize> = la
                .clone()
                .filter(|&e| on_b.binary_search(&boundary[e][0]).is_err())
                .collect();
            off_b.len() + 1 >= la.len()
                && off_b
                    .first()
                    .is_some_and(|&x| winding(ends[x][0], &ends[lb.clone()]) == Some(0))
        })
    })
}

/// The winding number of the closed polygon `edges` around `x`, `None` when an edge passes
/// too close to `x` to tell the side: crossings of the ray from `x` along the first axis,
/// each edge taken half-open in the second coordinate (exact comparisons of the points).
fn winding(x: P2, edges: &[[P2; 2]]) -> Option<i32> {
    let mut w = 0;
    for &[p, q] in edges {
        let (up, down) = (p[1] <= x[1] && q[1] > x[1], q[1] <= x[1] && p[1] > x[1]);
        if !(up || down) {
            continue;
        }
        // The side of `x` from the edge: left of an upward edge is a crossing to the right.
        let (o, scale) = cross(sub(q, p), sub(x, p));
        if o.abs() <= REL * scale {
            return None;
        }
        if up && o > 0.0 {
            w += 1;
        } else if down && o < 0.0 {
            w -= 1;
        }
    }
    Some(w)
}

/// Two boundary edges (vertex ids and projected ends): each endpoint not on the other edge
/// farther than `c` from it, and, sharing no vertex, not crossing.
#[inline(always)]
fn edges_clear(e: [u32; 2], [a, b]: [P2; 2], f: [u32; 2], [p, q]: [P2; 2], c2: f64) -> bool {
    let on = |v: u32, g: [u32; 2]| v == g[0] || v == g[1];
    let shared = on(e[0], f) || on(e[1], f);
    let ends_clear = [(e[0], a), (e[1], b)]
        .iter()
        .all(|&(v, x)| on(v, f) || point_clear_of_segment(x, p, q, c2))
        && [(f[0], p), (f[1], q)]
            .iter()
            .all(|&(v, x)| on(v, e) || point_clear_of_segment(x, a, b, c2));
    ends_clear && (shared || one_side(a, b, p, q) || one_side(p, q, a, b))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_point_is_clear_of_a_segment_only_beyond_the_distance() {
        let c2 = |c: f64| c * c * (1.0 + REL);
        let (p, q) = ([0.0, 0.0], [1.0, 0.0]);
        // Above the middle at 0.5.
        assert!(point_clear_of_segment([0.5, 0.5], p, q, c2(0.49)));
        assert!(!point_clear_of_segment([0.5, 0.5], p, q, c2(0.5)));
        // Past an end: its distance to that end.
        let v = [-0.3, 0.4];
        assert!(point_clear_of_segment(v, p, q, c2(0.49)));
        assert!(!point_clear_of_segment(v, p, q, c2(0.5)));
        assert!(point_clear_of_segment([1.3, -0.4], p, q, c2(0.49)));
        assert!(!point_clear_of_segment([1.3, -0.4], p, q, c2(0.5)));
        // On the line, past the end by 0.25.
        assert!(point_clear_of_segment([1.25, 0.0], p, q, c2(0.24)));
        assert!(!point_clear_of_segment([1.25, 0.0], p, q, c2(0.25)));
        // On the segment.
        assert!(!point_clear_of_segment([0.5, 0.0], p, q, 0.0));
    }

    #[test]
    fn a_triangle_is_clear_when_its_least_height_exceeds_the_distance() {
        // Right triangle with legs 1: heights 1, 1 and sqrt(2) / 2.
        let t = [[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]];
        let h2 = height_sq(t).unwrap();
        assert!(h2 <= 0.5 && h2 > 0.5 * (1.0 - 4.0 * REL));
        assert!(height_sq([t[0], t[2], t[1]]).is_none());
        // Degenerate: no orientation.
        assert!(height_sq([[0.0, 0.0], [1.0, 0.0], [2.0, 0.0]]).is_none());
    }

    #[test]
    fn the_winding_number_of_a_square() {
        let sq = [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]];
        let ccw: Vec<[P2; 2]> = (0..4).map(|i| [sq[i], sq[(i + 1) % 4]]).collect();
        let cw: Vec<[P2; 2]> = ccw.iter().rev().map(|&[p, q]| [q, p]).collect();
        assert_eq!(winding([0.5, 0.5], &ccw), Some(1));
        assert_eq!(winding([0.5, 0.5], &cw), Some(-1));
        assert_eq!(winding([1.5, 0.5], &ccw), Some(0));
        assert_eq!(winding([-0.5, 0.0], &ccw), Some(0));
        assert_eq!(winding([1.0, 0.5], &ccw), None);
    }

    #[test]
    fn loops_sharing_two_vertices_are_refused() {
        // A square, and a loop through its corners 0 and 2: one arc inside the square (by
        // vertex 4), one outside (by vertex 5); listed from the outside arc.
        let at = [
            [0.0, 0.0],
            [2.0, 0.0],
            [2.0, 2.0],
            [0.0, 2.0],
            [1.2, 0.8],
            [-1.0, 3.0],
        ];
        let edges = [
            [0, 1],
            [1, 2],
            [2, 3],
            [3, 0],
            [2, 5],
            [5, 0],
            [0, 4],
            [4, 2],
        ];
        let plane = |v: u32| at[v as usize];
        let both = Patch {
            edges: &edges,
            loops: &[0..4, 4..8],
        };
        assert!(!boundary_is_clear(&both, &plane, 0.01));
        // Each loop alone is simple and clear.
        for edges in [&edges[..4], &edges[4..]] {
            let one_loop = [std::ops::Range { start: 0, end: 4 }];
            let alone = Patch {
                edges,
                loops: &one_loop,
            };
            assert!(boundary_is_clear(&alone, &plane, 0.01));
        }
        // The square beside a triangle sharing its corner 1 only: apart.
        let at2 = [
            [0.0, 0.0],
            [2.0, 0.0],
            [2.0, 2.0],
            [0.0, 2.0],
            [3.0, -1.0],
            [3.0, 1.0],
        ];
        let plane2 = |v: u32| at2[v as usize];
        let edges2 = [[0, 1], [1, 2], [2, 3], [3, 0], [1, 4], [4, 5], [5, 1]];
        let touching = Patch {
            edges: &edges2,
            loops: &[0..4, 4..7],
        };
        assert!(boundary_is_clear(&touching, &plane2, 0.01));
    }

    #[test]
    fn crossing_boundary_edges_are_never_clear() {
        let e = [[0.0, 0.0], [2.0, 2.0]];
        let f = [[0.0, 2.0], [2.0, 0.0]];
        assert!(!edges_clear([0, 1], e, [2, 3], f, 0.0));
        let g = [[3.0, 0.0], [3.0, 2.0]];
        assert!(edges_clear([0, 1], e, [2, 3], g, 0.5));
        assert!(!edges_clear([0, 1], e, [2, 3], g, 1.0));
    }
}
