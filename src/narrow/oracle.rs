//! Brute-force oracles: every triangle pair through the exact test.

use super::triangles_intersect_reference as triangles_intersect;
use crate::mesh::Mesh;

/// Per-triangle closed boxes `[min, max]` (exact; only used to skip pairs cheaply).
fn boxes(m: &Mesh) -> Vec<[[f32; 3]; 2]> {
    (0..m.triangle_count())
        .map(|t| {
            let c = m.corners(t);
            let mut b = [c[0], c[0]];
            for p in &c[1..] {
                for k in 0..3 {
                    b[0][k] = b[0][k].min(p[k]);
                    b[1][k] = b[1][k].max(p[k]);
                }
            }
            b
        })
        .collect()
}

#[inline]
fn overlap(a: &[[f32; 3]; 2], b: &[[f32; 3]; 2]) -> bool {
    (0..3).all(|k| a[1][k] >= b[0][k] && b[1][k] >= a[0][k])
}

/// Exact brute-force oracle: every `(ta, tb)` with intersecting closed triangles, sorted
/// ascending. `O(|a| |b|)`.
pub fn brute_force_pairs(a: &Mesh, b: &Mesh) -> Vec<[u32; 2]> {
    let (ba, bb) = (boxes(a), boxes(b));
    let mut out = Vec::new();
    for (i, bi) in ba.iter().enumerate() {
        let ti = a.corners(i);
        for (j, bj) in bb.iter().enumerate() {
            if overlap(bi, bj) && triangles_intersect(&ti, &b.corners(j)) {
                out.push([i as u32, j as u32]);
            }
        }
    }
    out
}

/// Self-collision oracle: every `(ti, tj)`, `ti < tj`, intersecting, excluding pairs that
/// share a vertex index; sorted ascending. `O(n^2)`.
pub fn brute_force_self_pairs(m: &Mesh) -> Vec<[u32; 2]> {
    let bx = boxes(m);
    let tris = m.triangles();
    let mut out = Vec::new();
    for i in 0..tris.len() {
        let ti = m.corners(i);
        for j in i + 1..tris.len() {
            if tris[i].iter().any(|v| tris[j].contains(v)) || !overlap(&bx[i], &bx[j]) {
                continue;
            }
            if triangles_intersect(&ti, &m.corners(j)) {
                out.push([i as u32, j as u32]);
            }
        }
    }
    out
}
