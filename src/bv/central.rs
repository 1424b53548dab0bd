//! The DH central vertex of a region, chosen once at build from the rest pose
//! ([`CentralVertex`]): the paper's vertex closest to the rest centroid, or the vertex of
//! least rest radius.
//!
//! The least-radius vertex is the exact argmin over the region's vertices `c` of
//! `R(c) = max_v |c - v|^2` (squared distances in f64 from the f32 coordinates, ties to the
//! smallest internal index), found without the `O(m^2)` scan:
//!
//! - **lower bounds**: `R(c) >= |c - w|^2` for any region vertex `w` (a *witness*). The
//!   witnesses are first the extreme vertices along 13 directions (the axes and the face and
//!   body diagonals), then the far vertices found while evaluating candidates;
//! - **candidate order**: candidates are scanned by increasing initial bound; the scan stops
//!   when a bound exceeds the best radius so far (every later bound is larger), and a
//!   candidate whose bound, refined with the witnesses found since, exceeds it is skipped;
//! - **early exit**: `R(c)` is a farthest-point query over a small kd-tree of the region
//!   (boxes give upper bounds, the farther child first), abandoned as soon as the partial
//!   maximum exceeds the best radius so far.
//!
//! Every bound is one of the terms of the maximum or rounds monotonically above them, so the
//! pruning never changes the answer: it is the brute-force argmin (tested against it).
//!
//! Cost: on real frames (regions up to the whole 46-74K-vertex mesh) the build takes 1.9-2.7x
//! the paper's choice. The worst case is a region where every radius ties to a few ulps, as
//! a centrally symmetric sphere (every vertex has an antipode): every candidate is evaluated
//! and each query scans the vertices near its antipode, about `m^1.5` in all (an
//! icosphere of 163,842 vertices: 2.3 s against 0.15 s; `O(m^2)` would be minutes).

use super::dist2_f64;
use crate::options::CentralVertex;
use crate::points::Points;
use crate::tree::RegionTree;

/// Points per kd-tree leaf.
const BUCKET: usize = 16;
/// Most witnesses found during the scan (beyond the extremes): each costs one distance per
/// later candidate, so their number is capped.
const MAX_FOUND_WITNESSES: usize = 64;

/// The directions of the initial witnesses: the axes, the face diagonals, the body
/// diagonals (each gives the vertices of least and greatest projection).
const DIRECTIONS: [[f64; 3]; 13] = [
    [1.0, 0.0, 0.0],
    [0.0, 1.0, 0.0],
    [0.0, 0.0, 1.0],
    [1.0, 1.0, 0.0],
    [1.0, -1.0, 0.0],
    [1.0, 0.0, 1.0],
    [1.0, 0.0, -1.0],
    [0.0, 1.0, 1.0],
    [0.0, 1.0, -1.0],
    [1.0, 1.0, 1.0],
    [1.0, 1.0, -1.0],
    [1.0, -1.0, 1.0],
    [-1.0, 1.0, 1.0],
];

/// The central vertex (internal index) of every node of `tree`, by `choice`.
pub(crate) fn central_vertices(
    tree: &RegionTree,
    rest: &Points,
    choice: CentralVertex,
) -> Vec<u32> {
    let mut ids = Vec::new();
    let mut scratch = MinRadius::default();
    (0..tree.node_count())
        .map(|n| {
            ids.clear();
            ids.extend(tree.region_vertices(n));
            match choice {
                CentralVertex::RestCentroid => closest_to_centroid(&ids, rest),
                CentralVertex::MinRadius => scratch.solve(&ids, rest),
            }
        })
        .collect()
}

/// The vertex of `ids` closest to their centroid (mean) in `rest`; ties go to the smallest
/// index.
pub(crate) fn closest_to_centroid(ids: &[u32], rest: &Points) -> u32 {
    let count = ids.len() as f64;
    let mut mean = [0.0f64; 3];
    for &v in ids {
        let q = rest.get(v as usize);
        for k in 0..3 {
            mean[k] += q[k] as f64;
        }
    }
    let mean = mean.map(|s| s / count);
    let mut best = (f64::INFINITY, u32::MAX);
    for &v in ids {
        let q = rest.get(v as usize);
        let d: f64 = (0..3).map(|k| (q[k] as f64 - mean[k]).powi(2)).sum();
        if (d, v) < best {
            best = (d, v);
        }
    }
    best.1
}

/// The vertex of `ids` (non-empty) of least radius `max_v |c - v|^2` in `rest`; ties go to
/// the smallest index.
#[cfg(test)]
fn min_radius_vertex(ids: &[u32], rest: &Points) -> u32 {
    MinRadius::default().solve(ids, rest)
}

/// `(r, id)` ordered as the argmin orders candidates: by radius, then index.
#[inline]
fn worse(r: f64, id: u32, best: (f64, u32)) -> bool {
    r > best.0 || (r == best.0 && id > best.1)
}

/// A kd-tree node: the box of its points `start..end` and, if internal, its first child
/// (the second is next to it).
#[derive(Clone, Copy, Debug)]
struct KdNode {
    lo: [f32; 3],
    hi: [f32; 3],
    start: u32,
    end: u32,
    /// First child, 0 for a leaf (the root is never a child).
    left: u32,
}

/// The scratch of the least-radius search, reused from node to node.
#[derive(Default)]
struct MinRadius {
    /// The region's points and indices, in kd order.
    pts: Vec<([f32; 3], u32)>,
    kd: Vec<KdNode>,
    /// `(initial lower bound, position in pts)` per candidate.
    order: Vec<(f64, u32)>,
    witnesses: Vec<[f32; 3]>,
    /// The points' coordinates as three arrays, and their initial lower bounds.
    xyz: [Vec<f32>; 3],
    bound: Vec<f64>,
}

/// The state of one farthest-point query: the partial maximum, its vertex, and the best
/// radius it must beat.
struct Query {
    c: [f32; 3],
    id: u32,
    max: f64,
    far: [f32; 3],
    best: (f64, u32),
}

impl Query {
    /// Whether the candidate is already no better than the best.
    #[inline]
    fn lost(&self) -> bool {
        worse(self.max, self.id, self.best)
    }
}

impl MinRadius {
    fn solve(&mut self, ids: &[u32], rest: &Points) -> u32 {
        debug_assert!(!ids.is_empty());
        self.pts.clear();
        self.pts
            .extend(ids.iter().map(|&v| (rest.get(v as usize), v)));
        self.kd.clear();
        build_kd(&mut self.pts, &mut self.kd);

        self.witnesses.clear();
        extremes(&self.pts, &mut self.witnesses);
        let initial = self.witnesses.len();
        // Initial bounds, one witness at a time over the coordinate arrays (vectorises).
        self.xyz.iter_mut().for_each(Vec::clear);
        for k in 0..3 {
            self.xyz[k].extend(self.pts.iter().map(|p| p.0[k]));
        }
        self.bound.clear();
        self.bound.resize(self.pts.len(), 0.0);
        for w in &self.witnesses {
            let [xs, ys, zs] = &self.xyz;
            for (((b, &x), &y), &z) in self.bound.iter_mut().zip(xs).zip(ys).zip(zs) {
                let d = dist2_f64([x, y, z], w.map(f64::from));
                *b = if d > *b { d } else { *b };
            }
        }
        self.order.clear();
        self.order
            .extend(self.bound.iter().enumerate().map(|(i, &b)| (b, i as u32)));
        let pts = &self.pts;
        self.order.sort_unstable_by(|a, b| {
            a.0.total_cmp(&b.0)
                .then(pts[a.1 as usize].1.cmp(&pts[b.1 as usize].1))
        });

        let mut best = (f64::INFINITY, u32::MAX);
        for &(lb, i) in &self.order {
            let (c, id) = self.pts[i as usize];
            if worse(lb, id, best) {
                break; // every later candidate's bound is at least this one
            }
            let refined = self.witnesses[initial..]
                .iter()
                .any(|&w| worse(dist2_f64(c, w.map(f64::from)), id, best));
            if refined {
                continue;
            }
            let mut q = Query {
                c,
                id,
                max: f64::NEG_INFINITY,
                far: c,
                best,
            };
            farthest(&self.kd, &self.pts, 0, &mut q);
            if !q.lost() {
                best = (q.max, id);
            }
            if self.witnesses.len() < initial + MAX_FOUND_WITNESSES
                && !self.witnesses.contains(&q.far)
            {
                self.witnesses.push(q.far);
            }
        }
        best.1
    }
}

/// Appends to `out` the points of least and greatest projection on each of [`DIRECTIONS`]
/// (the first such point; no duplicates).
fn extremes(pts: &[([f32; 3], u32)], out: &mut Vec<[f32; 3]>) {
    let proj = |p: [f32; 3]| {
        DIRECTIONS.map(|d| d[0] * p[0] as f64 + d[1] * p[1] as f64 + d[2] * p[2] as f64)
    };
    let Some(&(first, _)) = pts.first() else {
        return;
    };
    let mut lo = proj(first).map(|v| (v, first));
    let mut hi = lo;
    for &(p, _) in &pts[1..] {
        for (j, v) in proj(p).into_iter().enumerate() {
            if v < lo[j].0 {
                lo[j] = (v, p);
            }
            if v > hi[j].0 {
                hi[j] = (v, p);
            }
        }
    }
    for (_, p) in lo.into_iter().chain(hi) {
        if !out.contains(&p) {
            out.push(p);
        }
    }
}

/// Upper bound of `dist2_f64(c, p)` over the points `p` of a box: per axis the farther face,
/// summed in the same order (rounding is monotonic, so the bound holds in floating point).
#[inline]
fn box_bound(c: [f32; 3], lo: [f32; 3], hi: [f32; 3]) -> f64 {
    (0..3)
        .map(|k| {
            let a = c[k] as f64 - lo[k] as f64;
            let b = hi[k] as f64 - c[k] as f64;
            a.abs().max(b.abs()).powi(2)
        })
        .sum()
}

/// Raises `q.max` to the farthest distance from `q.c` within kd node `k`, farther child
/// first, skipping subtrees that cannot raise it and stopping once the candidate has lost.
fn farthest(kd: &[KdNode], pts: &[([f32; 3], u32)], k: usize, q: &mut Query) {
    let node = kd[k];
    if node.left == 0 {
        for &(p, _) in &pts[node.start as usize..node.end as usize] {
            let d = dist2_f64(q.c, p.map(f64::from));
            if d > q.max {
                q.max = d;
                q.far = p;
                if q.lost() {
                    return;
                }
            }
        }
        return;
    }
    let (l, r) = (node.left as usize, node.left as usize + 1);
    let bl = box_bound(q.c, kd[l].lo, kd[l].hi);
    let br = box_bound(q.c, kd[r].lo, kd[r].hi);
    let visits = if bl >= br {
        [(l, bl), (r, br)]
    } else {
        [(r, br), (l, bl)]
    };
    for (child, b) in visits {
        if b > q.max && !q.lost() {
            farthest(kd, pts, child, q);
        }
    }
}

/// Builds a kd-tree over `pts` (reordered): median splits along the longest axis of each
/// node's box until at most [`BUCKET`] points; node 0 is the root.
fn build_kd(pts: &mut [([f32; 3], u32)], kd: &mut Vec<KdNode>) {
    kd.push(leaf(pts, 0, pts.len()));
    let mut k = 0;
    while k < kd.len() {
        let KdNode {
            lo, hi, start, end, ..
        } = kd[k];
        let (s, e) = (start as usize, end as usize);
        if e - s > BUCKET {
            let axis = (0..3)
                .max_by(|&a, &b| {
                    (hi[a] as f64 - lo[a] as f64)
                        .total_cmp(&(hi[b] as f64 - lo[b] as f64))
                        .then(b.cmp(&a))
                })
                .unwrap_or(0);
            let mid = (e - s) / 2;
            pts[s..e].select_nth_unstable_by(mid, |a, b| {
                a.0[axis].total_cmp(&b.0[axis]).then(a.1.cmp(&b.1))
            });
            kd[k].left = kd.len() as u32;
            let (l, r) = (leaf(pts, s, s + mid), leaf(pts, s + mid, e));
            kd.push(l);
            kd.push(r);
        }
        k += 1;
    }
}

/// A leaf node over `pts[s..e]` with its box.
fn leaf(pts: &[([f32; 3], u32)], s: usize, e: usize) -> KdNode {
    let mut lo = [f32::INFINITY; 3];
    let mut hi = [f32::NEG_INFINITY; 3];
    for (p, _) in &pts[s..e] {
        for k in 0..3 {
            lo[k] = lo[k].min(p[k]);
            hi[k] = hi[k].max(p[k]);
        }
    }
    KdNode {
        lo,
        hi,
        start: s as u32,
        end: e as u32,
        left: 0,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    /// The `O(m^2)` argmin.
    fn brute(ids: &[u32], rest: &Points) -> u32 {
        let radius = |c: u32| {
            ids.iter().fold(0.0f64, |m, &v| {
                m.max(dist2_f64(
                    rest.get(c as usize),
                    rest.get(v as usize).map(f64::from),
                ))
            })
        };
        ids.iter()
            .map(|&c| (radius(c), c))
            .min_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)))
            .unwrap()
            .1
    }

    fn points(ps: &[[f32; 3]]) -> Points {
        let mut p = Points::zeros(ps.len());
        p.gather_from(ps, &(0..ps.len() as u32).collect::<Vec<_>>());
        p
    }

    fn check(ps: &[[f32; 3]]) {
        let rest = points(ps);
        let ids: Vec<u32> = (0..ps.len() as u32).collect();
        assert_eq!(min_radius_vertex(&ids, &rest), brute(&ids, &rest), "{ps:?}");
        // A subset in a scrambled order: the answer does not depend on the order of `ids`.
        let mut sub: Vec<u32> = ids.iter().copied().filter(|v| v % 3 != 1).collect();
        sub.reverse();
        if !sub.is_empty() {
            assert_eq!(min_radius_vertex(&sub, &rest), brute(&sub, &rest));
        }
    }

    /// A small deterministic generator (xorshift), so the tests need no seed handling.
    fn noise(seed: u64) -> impl FnMut() -> f32 {
        let mut s = seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) | 1;
        move || {
            s ^= s << 13;
            s ^= s >> 7;
            s ^= s << 17;
            (s >> 40) as f32 / (1u64 << 24) as f32
        }
    }

    #[test]
    fn structured_regions() {
        // One point, two points, all coincident, collinear.
        check(&[[1.0, 2.0, 3.0]]);
        check(&[[0.0; 3], [1.0, 0.0, 0.0]]);
        check(&[[0.5; 3]; 40]);
        check(&(0..100).map(|i| [i as f32, 0.0, 0.0]).collect::<Vec<_>>());
        // Regular grids (many ties), flat and solid.
        let grid2: Vec<[f32; 3]> = (0..30 * 30)
            .map(|i| [(i % 30) as f32, (i / 30) as f32, 0.0])
            .collect();
        check(&grid2);
        let grid3: Vec<[f32; 3]> = (0..12 * 12 * 12)
            .map(|i| [(i % 12) as f32, (i / 12 % 12) as f32, (i / 144) as f32])
            .collect();
        check(&grid3);
        // Points on a sphere (every radius nearly the diameter), and a closed mesh's vertices.
        let ico = crate::shapes::icosphere(3, 1.0, [0.1, -0.2, 0.3]);
        check(ico.positions());
        // A thin rod and a noisy cloth.
        let mut r = noise(7);
        let rod: Vec<[f32; 3]> = (0..2000)
            .map(|i| {
                let t = i as f32 * 0.01;
                [
                    t,
                    0.05 * (t * 9.0).cos(),
                    0.05 * (t * 9.0).sin() + 1e-3 * r(),
                ]
            })
            .collect();
        check(&rod);
        let cloth: Vec<[f32; 3]> = (0..3000)
            .map(|i| [(i % 60) as f32 * 0.1, (i / 60) as f32 * 0.1, 0.01 * r()])
            .collect();
        check(&cloth);
        // Far-away outliers and a huge coordinate range.
        let mut far = grid2.clone();
        far.push([1e6, -1e6, 3e5]);
        far.push([-1e-20, 1e-20, 0.0]);
        check(&far);
    }

    #[test]
    fn random_regions() {
        for seed in 0..40 {
            let mut r = noise(seed);
            let n = 1 + (seed as usize * 37) % 700;
            let ps: Vec<[f32; 3]> = (0..n).map(|_| [r(), r() * 0.3, r() * 2.0]).collect();
            check(&ps);
            // Coarsely quantised: exact ties in the radii.
            let q: Vec<[f32; 3]> = ps.iter().map(|p| p.map(|x| (x * 4.0).round())).collect();
            check(&q);
        }
    }

    proptest! {
        #[test]
        fn matches_brute_force(ps in prop::collection::vec(
            prop::array::uniform3(-8i32..8).prop_map(|a| a.map(|x| x as f32 * 0.25)), 1..120)) {
            check(&ps);
        }
    }

    #[test]
    fn closest_to_centroid_ties_to_smallest_index() {
        let rest = points(&[
            [1.0, 0.0, 0.0],
            [-1.0, 0.0, 0.0],
            [0.0, 5.0, 0.0],
            [0.0, -5.0, 0.0],
        ]);
        assert_eq!(closest_to_centroid(&[3, 2, 1, 0], &rest), 0);
        // The least radius: the ends of the long axis reach 5^2 + 1 from either x point.
        assert_eq!(min_radius_vertex(&[3, 2, 1, 0], &rest), 0);
    }
}
