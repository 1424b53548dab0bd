//! Procedural meshes and deformations for tests, benchmarks and examples.

use crate::mesh::Mesh;

/// An icosphere: the icosahedron subdivided `subdivisions` times (20 * 4^s triangles;
/// s = 4 gives 5,120), projected onto the sphere of `radius` around `center`.
pub fn icosphere(subdivisions: u32, radius: f32, center: [f32; 3]) -> Mesh {
    let t = (1.0 + 5.0f64.sqrt()) / 2.0;
    let mut verts: Vec<[f64; 3]> = vec![
        [-1.0, t, 0.0],
        [1.0, t, 0.0],
        [-1.0, -t, 0.0],
        [1.0, -t, 0.0],
        [0.0, -1.0, t],
        [0.0, 1.0, t],
        [0.0, -1.0, -t],
        [0.0, 1.0, -t],
        [t, 0.0, -1.0],
        [t, 0.0, 1.0],
        [-t, 0.0, -1.0],
        [-t, 0.0, 1.0],
    ];
    let mut tris: Vec<[u32; 3]> = vec![
        [0, 11, 5],
        [0, 5, 1],
        [0, 1, 7],
        [0, 7, 10],
        [0, 10, 11],
        [1, 5, 9],
        [5, 11, 4],
        [11, 10, 2],
        [10, 7, 6],
        [7, 1, 8],
        [3, 9, 4],
        [3, 4, 2],
        [3, 2, 6],
        [3, 6, 8],
        [3, 8, 9],
        [4, 9, 5],
        [2, 4, 11],
        [6, 2, 10],
        [8, 6, 7],
        [9, 8, 1],
    ];
    for _ in 0..subdivisions {
        let mut mid = std::collections::HashMap::new();
        let mut midpoint = |a: u32, b: u32, verts: &mut Vec<[f64; 3]>| -> u32 {
            *mid.entry((a.min(b), a.max(b))).or_insert_with(|| {
                let (p, q) = (verts[a as usize], verts[b as usize]);
                verts.push([0, 1, 2].map(|k| (p[k] + q[k]) / 2.0));
                (verts.len() - 1) as u32
            })
        };
        let mut next = Vec::with_capacity(tris.len() * 4);
        for [a, b, c] in tris {
            let ab = midpoint(a, b, &mut verts);
            let bc = midpoint(b, c, &mut verts);
            let ca = midpoint(c, a, &mut verts);
            next.extend([[a, ab, ca], [b, bc, ab], [c, ca, bc], [ab, bc, ca]]);
        }
        tris = next;
    }
    let positions = verts
        .iter()
        .map(|v| {
            let n = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
            [0, 1, 2].map(|k| (v[k] / n * radius as f64 + center[k] as f64) as f32)
        })
        .collect();
    Mesh::new(positions, tris).expect("icosphere is a valid mesh")
}

/// A flat `nx` x `ny` grid of unit cells in the plane z = 0 (2 * nx * ny triangles),
/// scaled by `cell` and shifted by `origin`.
pub fn grid(nx: u32, ny: u32, cell: f32, origin: [f32; 3]) -> Mesh {
    let (nx, ny) = (nx.max(1), ny.max(1));
    let mut positions = Vec::new();
    for j in 0..=ny {
        for i in 0..=nx {
            positions.push([
                origin[0] + i as f32 * cell,
                origin[1] + j as f32 * cell,
                origin[2],
            ]);
        }
    }
    let at = |i: u32, j: u32| j * (nx + 1) + i;
    let mut tris = Vec::new();
    for j in 0..ny {
        for i in 0..nx {
            tris.push([at(i, j), at(i + 1, j), at(i + 1, j + 1)]);
            tris.push([at(i, j), at(i + 1, j + 1), at(i, j + 1)]);
        }
    }
    Mesh::new(positions, tris).expect("grid is a valid mesh")
}

/// `mesh`'s positions moved by `offset`.
pub fn translated(positions: &[[f32; 3]], offset: [f32; 3]) -> Vec<[f32; 3]> {
    positions
        .iter()
        .map(|p| [p[0] + offset[0], p[1] + offset[1], p[2] + offset[2]])
        .collect()
}

/// A smooth non-rigid deformation of `rest` at time `t`: every vertex is displaced by a
/// travelling wave of amplitude `amplitude` (in the mesh's units), then the whole mesh is
/// shifted by `offset`. Deterministic; used to drive deforming test and bench sequences.
pub fn wave(rest: &[[f32; 3]], t: f32, amplitude: f32, offset: [f32; 3]) -> Vec<[f32; 3]> {
    rest.iter()
        .map(|p| {
            let s = (p[0] * 3.1 + t).sin() * (p[1] * 2.3 - 0.7 * t).cos();
            let r = (p[2] * 2.7 + 1.3 * t).sin();
            [
                p[0] + amplitude * s + offset[0],
                p[1] + amplitude * r * 0.5 + offset[1],
                p[2] + amplitude * s * r + offset[2],
            ]
        })
        .collect()
}

/// `positions` each moved by deterministic noise, uniform in `[-amplitude[k], amplitude[k]]`
/// along axis `k` (independent per vertex and axis, from a hash of `seed` and the vertex
/// index, so the same arguments always give the same positions). For noisy test and bench
/// scenes: a near-flat grid is `jitter(grid.positions(), [0.0, 0.0, 1e-4], seed)`.
pub fn jitter(positions: &[[f32; 3]], amplitude: [f32; 3], seed: u64) -> Vec<[f32; 3]> {
    positions
        .iter()
        .enumerate()
        .map(|(i, p)| {
            let mut state = seed ^ (i as u64).wrapping_mul(0xD1B5_4A32_D192_ED03);
            std::array::from_fn(|k| {
                // A uniform number in [-1, 1) from a splitmix64 draw.
                let u = (splitmix64(&mut state) >> 40) as f32 / (1u32 << 23) as f32 - 1.0;
                p[k] + amplitude[k] * u
            })
        })
        .collect()
}

/// `positions` folded across the plane `x = at`: every vertex beyond it (`x > at`) is
/// mirrored back (`x -> 2 at - x`), so a flat sheet's far part lies on its near part. With a
/// [`grid`] whose cells divide `at`, the layers' vertices coincide in `x` and `y`;
/// [`jitter`] in `z` then makes them cross everywhere (contacts grow with the area).
pub fn fold_x(positions: &[[f32; 3]], at: f32) -> Vec<[f32; 3]> {
    positions
        .iter()
        .map(|&[x, y, z]| {
            if x > at {
                [2.0 * at - x, y, z]
            } else {
                [x, y, z]
            }
        })
        .collect()
}

/// SplitMix64 (Steele, Lea, Flood 2014): advances `state` and returns its next 64-bit
/// output. The seeded generator behind [`jitter`] and the simulator's scenes.
#[doc(hidden)]
pub fn splitmix64(state: &mut u64) -> u64 {
    *state = state.wrapping_add(0x9E37_79B9_7F4A_7C15);
    let mut z = *state;
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}
