//! Batch overlap tests for the three bounding-volume kinds, over pairs of node indices.
//!
//! Each entry tests pairs `(ia[k], ib[k])` for `k in 0..ia.len()`, writes `out[k] = 1` when
//! the two volumes overlap (closed volumes: touching counts) and `0` otherwise, and returns
//! the number of overlapping pairs. Node data is read by index (a gather).

/// Sphere nodes (the SBV hierarchy) in SoA form.
#[derive(Clone, Copy, Debug)]
pub struct SphereSoa<'a> {
    pub cx: &'a [f32],
    pub cy: &'a [f32],
    pub cz: &'a [f32],
    pub r: &'a [f32],
}

/// Distance-hierarchy nodes in SoA form: the centre is the live position of vertex
/// `vertex[n]` in `points`.
#[derive(Clone, Copy, Debug)]
pub struct DhSoa<'a> {
    pub vertex: &'a [u32],
    pub r: &'a [f32],
    pub points: crate::Soa3<'a>,
}

/// Axis-aligned boxes in SoA form.
#[derive(Clone, Copy, Debug)]
pub struct AabbSoa<'a> {
    pub min_x: &'a [f32],
    pub min_y: &'a [f32],
    pub min_z: &'a [f32],
    pub max_x: &'a [f32],
    pub max_y: &'a [f32],
    pub max_z: &'a [f32],
}

#[inline(always)]
fn spheres_overlap(a: [f32; 3], ra: f32, b: [f32; 3], rb: f32) -> bool {
    let dx = a[0] - b[0];
    let dy = a[1] - b[1];
    let dz = a[2] - b[2];
    let d2 = dx * dx + dy * dy + dz * dz;
    let rs = ra + rb;
    d2 <= rs * rs
}

fn check_lengths(ia: &[u32], ib: &[u32], out: &[u32]) {
    assert_eq!(ia.len(), ib.len(), "overlap: ia and ib differ in length");
    assert!(
        out.len() >= ia.len(),
        "overlap: out is shorter than the pair list"
    );
}

/// Scalar reference of [`sphere_pairs`].
pub fn sphere_pairs_scalar(
    a: SphereSoa,
    b: SphereSoa,
    ia: &[u32],
    ib: &[u32],
    out: &mut [u32],
) -> usize {
    check_lengths(ia, ib, out);
    let mut hits = 0;
    for k in 0..ia.len() {
        let (i, j) = (ia[k] as usize, ib[k] as usize);
        let hit = spheres_overlap(
            [a.cx[i], a.cy[i], a.cz[i]],
            a.r[i],
            [b.cx[j], b.cy[j], b.cz[j]],
            b.r[j],
        );
        out[k] = hit as u32;
        hits += hit as usize;
    }
    hits
}

/// Sphere-sphere overlap `|c_a - c_b|^2 <= (r_a + r_b)^2` for each pair.
pub fn sphere_pairs(a: SphereSoa, b: SphereSoa, ia: &[u32], ib: &[u32], out: &mut [u32]) -> usize {
    sphere_pairs_scalar(a, b, ia, ib, out)
}

/// Scalar reference of [`dh_pairs`].
pub fn dh_pairs_scalar(a: DhSoa, b: DhSoa, ia: &[u32], ib: &[u32], out: &mut [u32]) -> usize {
    check_lengths(ia, ib, out);
    let mut hits = 0;
    for k in 0..ia.len() {
        let (i, j) = (ia[k] as usize, ib[k] as usize);
        let ca = a.points.get(a.vertex[i] as usize);
        let cb = b.points.get(b.vertex[j] as usize);
        let hit = spheres_overlap(ca, a.r[i], cb, b.r[j]);
        out[k] = hit as u32;
        hits += hit as usize;
    }
    hits
}

/// Distance-hierarchy overlap: the sphere test with centres read from the live vertex
/// positions, `|P_a[c_a] - P_b[c_b]|^2 <= (r_a + r_b)^2`.
pub fn dh_pairs(a: DhSoa, b: DhSoa, ia: &[u32], ib: &[u32], out: &mut [u32]) -> usize {
    dh_pairs_scalar(a, b, ia, ib, out)
}

/// Scalar reference of [`aabb_pairs`].
pub fn aabb_pairs_scalar(a: AabbSoa, b: AabbSoa, ia: &[u32], ib: &[u32], out: &mut [u32]) -> usize {
    check_lengths(ia, ib, out);
    let mut hits = 0;
    for k in 0..ia.len() {
        let (i, j) = (ia[k] as usize, ib[k] as usize);
        let hit = a.min_x[i] <= b.max_x[j]
            && b.min_x[j] <= a.max_x[i]
            && a.min_y[i] <= b.max_y[j]
            && b.min_y[j] <= a.max_y[i]
            && a.min_z[i] <= b.max_z[j]
            && b.min_z[j] <= a.max_z[i];
        out[k] = hit as u32;
        hits += hit as usize;
    }
    hits
}

/// Box-box overlap: six interval comparisons per pair.
pub fn aabb_pairs(a: AabbSoa, b: AabbSoa, ia: &[u32], ib: &[u32], out: &mut [u32]) -> usize {
    aabb_pairs_scalar(a, b, ia, ib, out)
}
