//! A folded cloth sheet pushed through itself, in f64: its self-contacts, the vertex-triangle and
//! edge-edge pairs within a contact distance (what a cloth or IPC-style solver repels), and
//! continuous collision detection over the step (every pair that touches while the sheet
//! moves, and the earliest time of impact, the line-search question).
//!
//! `cargo run --release --example cloth_proximity_ccd`

use dhcd::bv::Aabb;
use dhcd::shapes::grid;
use dhcd::{self_ccd, self_collide, self_proximity, CcdQuery, Hierarchy, Mesh, Motion, Options};

fn main() -> dhcd::Result<()> {
    let sheet = grid(40, 40, 0.025, [0.0; 3]);
    let flat: Vec<[f64; 3]> = sheet.positions().iter().map(|p| p.map(f64::from)).collect();
    // The right half is folded over x = 0.5, tilted, lying 1 cm above the left half at t0,
    // and pushed through it to 1 cm below at t1 (shifted a little, so that no vertex lands
    // exactly on a grid line: exact, but degenerate contacts are the slow path).
    let fold = |dz: f64, shift: f64| -> Vec<[f64; 3]> {
        flat.iter()
            .map(|&[x, y, z]| {
                if x > 0.5 {
                    [1.0 - x + shift, y + 0.7 * shift, dz + 0.003 * x + 0.002 * y]
                } else {
                    [x, y, z]
                }
            })
            .collect()
    };
    let (above, below) = (fold(0.01, 0.0031), fold(-0.01, 0.0047));
    let mesh = Mesh::new_f64(above.clone(), sheet.triangles().to_vec())?;
    let mut h = Hierarchy::<Aabb>::new(&mesh, Options::default())?;

    h.update_positions_f64(&below)?;
    let contacts = self_collide(&h);
    let near = self_proximity(&h, 0.012)?;
    println!(
        "at t1: {} self-contacts; within 12 mm: {} vertex-triangle and {} edge-edge pairs",
        contacts.pairs.len(),
        near.vertex_face.len(),
        near.edge_edge.len()
    );
    if let Some(p) = near.vertex_face.first() {
        println!(
            "  e.g. vertex {} and triangle {}: distance {:.4} ({:?})",
            p.vertex,
            p.triangle,
            p.distance_sq.sqrt(),
            p.kind
        );
    }

    // CCD reads the motion, not the hierarchy's pose: above at t0, below at t1.
    let motion = Motion::new(&above, &below);
    let all = self_ccd(&h, motion, &CcdQuery::all())?;
    let first = self_ccd(&h, motion, &CcdQuery::earliest())?;
    println!(
        "over the step: {} vertex-triangle and {} edge-edge pairs collide; earliest time of impact {:?} ({} pairs reach it)",
        all.vertex_face.len(),
        all.edge_edge.len(),
        first.toi,
        first.counters.contacts
    );
    Ok(())
}
