//! The experiment's scene: eight objects in two rows of four, pulled together.

use glam::DVec3;

use super::pawn::pawn_mesh;
use super::simulation::{bounds, SimConfig, Simulation};
use super::SimError;
use dhcd::shapes::splitmix64;
use dhcd::Mesh;

/// Number of objects in [`pawn_scene`] and [`scene_with_mesh`] (the paper's eight pawns).
pub const SCENE_OBJECTS: usize = 8;

/// Eight copies of [`pawn_mesh`] in two rows of four (see [`scene_with_mesh`]).
pub fn pawn_scene(config: &SimConfig) -> Result<Simulation, SimError> {
    scene_with_mesh(pawn_mesh(), config)
}

/// Eight copies of `mesh` in two rows of four on the `x`-`z` plane (`+y` is up), each turned
/// about its vertical axis by a seeded angle, then handed to [`Simulation::new`].
///
/// The copies are centred horizontally on their bounding boxes and spaced by the footprint
/// width `w` (the larger horizontal bounding-box extent) times `1 + config.initial_gap`, so
/// the arrangement scales with the mesh. The simulator's drive pulls every object toward
/// the scene centre: the rows press against each other and along themselves, so each
/// object ends up touching two to three neighbours. The seeded turn keeps the copies from
/// being exact translates of each other (identical, perfectly aligned tessellations would
/// make touching triangles coplanar far more often than in any real scene).
pub fn scene_with_mesh(mesh: Mesh, config: &SimConfig) -> Result<Simulation, SimError> {
    let (lo, hi) = bounds(mesh.positions());
    let centre = DVec3::new(0.5 * (lo.x + hi.x), lo.y, 0.5 * (lo.z + hi.z));
    let extent = hi - lo;
    let mut width = extent.x.max(extent.z);
    if width <= 0.0 {
        width = extent.max_element().max(1.0);
    }
    let spacing = width * (1.0 + config.initial_gap.max(0.0));
    let mut state = config.seed ^ 0x5CE7_E000_0000_0001;
    let mut objects = Vec::with_capacity(SCENE_OBJECTS);
    for k in 0..SCENE_OBJECTS {
        let (row, col) = (k / 4, k % 4);
        let offset = DVec3::new(
            (col as f64 - 1.5) * spacing,
            0.0,
            (row as f64 - 0.5) * spacing,
        );
        let angle =
            (splitmix64(&mut state) >> 11) as f64 / (1u64 << 53) as f64 * std::f64::consts::TAU;
        let (s, c) = angle.sin_cos();
        let mut positions = Vec::with_capacity(mesh.vertex_count());
        for (v, p) in mesh.positions().iter().enumerate() {
            let q = DVec3::new(f64::from(p[0]), f64::from(p[1]), f64::from(p[2])) - centre;
            let turned = DVec3::new(c * q.x + s * q.z, q.y, -s * q.x + c * q.z);
            let r = turned + offset;
            let placed = [r.x as f32, r.y as f32, r.z as f32];
            // The file's coordinates are finite (a `Mesh`); only the layout can overflow, and
            // then the message must not blame the file.
            if !placed.iter().all(|x| x.is_finite()) {
                return Err(SimError::SceneTooLarge {
                    copy: k,
                    vertex: v,
                    spacing,
                    at: r.to_array(),
                });
            }
            positions.push(placed);
        }
        objects.push(Mesh::new(positions, mesh.triangles().to_vec())?);
    }
    Simulation::new(objects, config.clone())
}
