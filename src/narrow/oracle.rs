//! Brute-force oracles: every triangle pair through the exact test.

use super::predicates::Coordinate;
use super::tritri::{tri_tri, Decide};
use crate::mesh::{Mesh, Precision};

/// The triangles of a mesh as corner coordinates of type `C`, with their closed boxes.
struct Tris<C> {
    corners: Vec<[[C; 3]; 3]>,
    boxes: Vec<[[C; 3]; 2]>,
}

impl<C: Coordinate> Tris<C> {
    fn new(m: &Mesh, positions: &[[C; 3]]) -> Self {
        let corners: Vec<[[C; 3]; 3]> = m
            .triangles()
            .iter()
            .map(|t| t.map(|v| positions[v as usize]))
            .collect();
        let boxes = corners
            .iter()
            .map(|c| {
                let mut b = [c[0], c[0]];
                for p in &c[1..] {
                    for k in 0..3 {
                        if p[k] < b[0][k] {
                            b[0][k] = p[k];
                        }
                        if p[k] > b[1][k] {
                            b[1][k] = p[k];
                        }
                    }
                }
                b
            })
            .collect();
        Self { corners, boxes }
    }

    #[inline]
    fn meet(&self, i: usize, other: &Self, j: usize) -> bool {
        let (a, b) = (&self.boxes[i], &other.boxes[j]);
        (0..3).all(|k| a[1][k] >= b[0][k] && b[1][k] >= a[0][k])
    }

    #[inline]
    fn intersect(&self, i: usize, other: &Self, j: usize) -> bool {
        self.meet(i, other, j) && tri_tri(&self.corners[i], &other.corners[j], &mut Decide)
    }
}

/// Exact brute-force oracle: every `(ta, tb)` with intersecting closed triangles, sorted
/// ascending, exact for the meshes' precision (`f64` when either mesh is `f64`). `O(|a| |b|)`.
pub fn brute_force_pairs(a: &Mesh, b: &Mesh) -> Vec<[u32; 2]> {
    if a.precision() == Precision::F64 || b.precision() == Precision::F64 {
        let (pa, pb) = (a.to_f64_positions(), b.to_f64_positions());
        pairs(&Tris::new(a, &pa), &Tris::new(b, &pb))
    } else {
        pairs(&Tris::new(a, a.positions()), &Tris::new(b, b.positions()))
    }
}

fn pairs<C: Coordinate>(a: &Tris<C>, b: &Tris<C>) -> Vec<[u32; 2]> {
    let mut out = Vec::new();
    for i in 0..a.corners.len() {
        for j in 0..b.corners.len() {
            if a.intersect(i, b, j) {
                out.push([i as u32, j as u32]);
            }
        }
    }
    out
}

/// Self-collision oracle: every `(ti, tj)`, `ti < tj`, intersecting, excluding pairs that
/// share a vertex index; sorted ascending; exact for the mesh's precision. `O(n^2)`.
pub fn brute_force_self_pairs(m: &Mesh) -> Vec<[u32; 2]> {
    match m.positions_f64() {
        Some(p) => self_pairs(m, &Tris::new(m, p)),
        None => self_pairs(m, &Tris::new(m, m.positions())),
    }
}

fn self_pairs<C: Coordinate>(m: &Mesh, t: &Tris<C>) -> Vec<[u32; 2]> {
    let tris = m.triangles();
    let mut out = Vec::new();
    for i in 0..tris.len() {
        for j in i + 1..tris.len() {
            if tris[i].iter().any(|v| tris[j].contains(v)) {
                continue;
            }
            if t.intersect(i, t, j) {
                out.push([i as u32, j as u32]);
            }
        }
    }
    out
}
