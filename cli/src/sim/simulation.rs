//! The mass-spring simulator.
//!
//! Forces on every vertex (per unit of its mass, i.e. accelerations, except springs):
//!
//! * **Edge springs** on every mesh edge and **bending springs** between the two opposite
//!   vertices of every pair of triangles sharing an edge: linear (Hooke) springs at their
//!   rest lengths. They keep the surface smooth and spread a local push into a dent rather
//!   than a spike.
//! * **Shape pull**: every vertex is pulled toward its rest position translated with the
//!   object's current centre of mass (`goal_i = com + (rest_i - rest_com)`), stiffness
//!   [`SimConfig::shape_stiffness`]. We chose the translation-only variant over rotational
//!   shape matching (polar decomposition of the moment matrix) on purpose: the pawns have no
//!   floor and no gravity, and off-centre contacts would otherwise spin and topple them;
//!   here a tilt is resisted like any other deformation, which keeps pawns upright, makes
//!   the centre-height shear show up as a lean, and costs one sum per substep. It is also
//!   what stops a closed shell of springs from collapsing or inverting.
//! * **Drive**: a horizontal pull toward the scene centre (the mean of the objects'
//!   initial centres of mass), growing linearly with height (`1 + shear * h`, `h` in 0..1)
//!   so the tops lean in, plus a small sideways wobble, also growing with height, with a
//!   seeded phase per object. This is what brings the objects together and keeps them
//!   pressed against each other.
//! * **Contacts** from the previous frame: for each triangle pair, both triangles' vertices
//!   are pushed apart along `n_b - n_a` (out of the other object and into their own), with
//!   an acceleration `contact_stiffness * (contact_offset * scale + depth)`, where `depth`
//!   is how far the triangles' corners lie behind each other's planes (clamped). The sum
//!   per vertex is clamped too. Because contacts arrive one frame late and the push is a
//!   penalty, the objects settle into a pressed, slightly interpenetrating equilibrium: the
//!   contacts persist instead of bouncing off.
//! * **Damping**: drag `-drag * v` and internal damping `-internal_damping * (v - v_com)`,
//!   both integrated implicitly (unconditionally stable).
//!
//! Integration is semi-implicit (symplectic) Euler with [`SimConfig::substeps`] substeps per
//! frame. For stability each vertex's mass is raised, if needed, so that
//! `h^2 * (sum of incident spring stiffnesses) / m <= 1/4`; on the pawn this only affects
//! the two pole vertices (109 edges each), and it makes user meshes with high-valence
//! vertices safe without shrinking the time step.
//!
//! Lengths and accelerations of the drive, contacts and speed limit are expressed in units
//! of the scene `scale` (the largest bounding-box extent of any object), so a user mesh of
//! any size behaves like the unit pawn. Spring stiffnesses are per unit mass and
//! scale-free.
//!
//! Determinism: objects are independent within a frame (contacts are frozen at the frame
//! start), so the objects are advanced in parallel, each by one thread, sequentially inside;
//! every floating-point sum has a fixed order, whatever the thread count.

use glam::DVec3;
use rayon::prelude::*;

use super::ObjectContact;
use super::{check, SimError};
use dhcd::Mesh;

/// Parameters of [`Simulation`]. The defaults are tuned for the pawn scene: the pawns touch
/// after about ten frames, dent each other and stay pressed together for hundreds of frames.
#[derive(Clone, Debug, PartialEq)]
pub struct SimConfig {
    /// Simulated seconds per [`Simulation::step`] (one frame).
    pub frame_dt: f64,
    /// Integration substeps per frame.
    pub substeps: u32,
    /// Edge spring stiffness per unit mass (1/s^2).
    pub edge_stiffness: f64,
    /// Bending spring stiffness per unit mass (1/s^2).
    pub bend_stiffness: f64,
    /// Pull toward the translated rest shape (1/s^2).
    pub shape_stiffness: f64,
    /// Damping of velocity relative to the object's centre-of-mass velocity (1/s).
    pub internal_damping: f64,
    /// Damping of absolute velocity (1/s); bounds the approach speed to `drive / drag`.
    pub drag: f64,
    /// Drive toward the scene centre at the bottom of an object (scale/s^2).
    pub drive_strength: f64,
    /// Within this horizontal distance of the scene centre (scale units) the drive fades
    /// linearly to zero, like a spring, so objects are never flung across the centre.
    pub drive_radius: f64,
    /// Relative linear growth of the drive per simulated second (0 = constant drive); a
    /// slowly growing push makes the contact area keep growing.
    pub drive_growth: f64,
    /// Extra drive at the top of an object relative to the bottom (shear, makes tops lean).
    pub shear: f64,
    /// Amplitude of the sideways wobble at the top of an object (scale/s^2).
    pub wobble: f64,
    /// Period of the wobble (s).
    pub wobble_period: f64,
    /// Contact penalty per unit of penetration depth (1/s^2).
    pub contact_stiffness: f64,
    /// Penetration-independent part of the contact push, as a depth (scale units); makes
    /// merely touching triangles push too.
    pub contact_offset: f64,
    /// Largest penetration depth the penalty takes into account (scale units).
    pub max_contact_depth: f64,
    /// Largest contact acceleration of one vertex (scale/s^2).
    pub max_contact_accel: f64,
    /// Share (0..=1) of an object's total contact push applied to all its vertices alike
    /// instead of to the touching ones: the touching ones dent, the whole object is
    /// stopped. Without it the whole push must travel through the shape pull and a fast
    /// object ploughs through the other before its dent can stop it.
    pub contact_body_share: f64,
    /// Speed limit of every vertex (scale/s).
    pub max_speed: f64,
    /// Gap between neighbouring objects in the built-in scenes, relative to their width.
    pub initial_gap: f64,
    /// Seed of the scene's turns and the wobble phases.
    pub seed: u64,
}

impl Default for SimConfig {
    fn default() -> Self {
        Self {
            frame_dt: 1.0 / 60.0,
            substeps: 8,
            edge_stiffness: 3000.0,
            bend_stiffness: 300.0,
            shape_stiffness: 1000.0,
            internal_damping: 20.0,
            drag: 2.0,
            drive_strength: 0.6,
            drive_radius: 0.5,
            drive_growth: 0.5,
            shear: 1.0,
            wobble: 0.5,
            wobble_period: 0.6,
            contact_stiffness: 1000.0,
            contact_offset: 0.005,
            max_contact_depth: 0.05,
            max_contact_accel: 300.0,
            contact_body_share: 0.5,
            max_speed: 1.0,
            initial_gap: 0.04,
            seed: 1,
        }
    }
}

impl SimConfig {
    fn validate(&self) -> Result<(), SimError> {
        let non_negative = [
            ("edge_stiffness", self.edge_stiffness),
            ("bend_stiffness", self.bend_stiffness),
            ("shape_stiffness", self.shape_stiffness),
            ("internal_damping", self.internal_damping),
            ("drag", self.drag),
            ("drive_strength", self.drive_strength),
            ("drive_growth", self.drive_growth),
            ("shear", self.shear),
            ("wobble", self.wobble),
            ("contact_stiffness", self.contact_stiffness),
            ("contact_offset", self.contact_offset),
            ("max_contact_depth", self.max_contact_depth),
            ("max_contact_accel", self.max_contact_accel),
            ("initial_gap", self.initial_gap),
            ("drive_radius", self.drive_radius),
        ];
        for (name, value) in non_negative {
            check(
                value.is_finite() && value >= 0.0,
                name,
                value,
                "finite and non-negative",
            )?;
        }
        let positive = [
            ("frame_dt", self.frame_dt),
            ("wobble_period", self.wobble_period),
            ("max_speed", self.max_speed),
        ];
        for (name, value) in positive {
            check(
                value.is_finite() && value > 0.0,
                name,
                value,
                "finite and positive",
            )?;
        }
        let share = self.contact_body_share;
        check(
            (0.0..=1.0).contains(&share),
            "contact_body_share",
            share,
            "in 0..=1",
        )?;
        let substeps = f64::from(self.substeps);
        check(self.substeps >= 1, "substeps", substeps, "at least 1")?;
        let h = self.frame_dt / substeps;
        if h * h * self.shape_stiffness > 0.5 {
            return Err(SimError::Unstable {
                stiffness: self.shape_stiffness,
                substep: h,
            });
        }
        Ok(())
    }
}

/// A linear spring between two vertices of one object.
#[derive(Clone, Copy, Debug)]
struct Spring {
    a: u32,
    b: u32,
    rest: f64,
    k: f64,
}

/// One deformable object: its topology, springs, rest shape and state.
#[derive(Clone, Debug)]
struct Body {
    triangles: Vec<[u32; 3]>,
    springs: Vec<Spring>,
    /// Rest position minus the (mass-weighted) rest centre of mass.
    rest_offset: Vec<DVec3>,
    /// Rest height in 0..1 (bottom to top of the object).
    height: Vec<f64>,
    mass: Vec<f64>,
    total_mass: f64,
    pos: Vec<DVec3>,
    vel: Vec<DVec3>,
    /// Scratch: spring forces of the current substep.
    force: Vec<DVec3>,
    /// Contact acceleration of the current frame.
    contact: Vec<DVec3>,
    /// `pos` as f32, refreshed after every frame.
    out: Vec<[f32; 3]>,
    /// Scene centre the drive pulls toward.
    centre: DVec3,
    /// Share of the frame's total contact push applied uniformly to every vertex.
    contact_mean: DVec3,
    wobble_dir: DVec3,
    phase: f64,
}

/// Per-frame constants shared by all bodies' substeps.
#[derive(Clone, Copy, Debug)]
struct Params {
    h: f64,
    substeps: u32,
    t0: f64,
    shape: f64,
    internal: f64,
    drag: f64,
    drive: f64,
    drive_radius: f64,
    shear: f64,
    wobble: f64,
    omega: f64,
    max_speed: f64,
}

/// Several deformable objects advanced by a mass-spring model (see the module docs).
#[derive(Clone, Debug)]
pub struct Simulation {
    config: SimConfig,
    bodies: Vec<Body>,
    scale: f64,
    frame: u64,
}

impl Simulation {
    /// Builds springs, masses and rest shapes for `objects` (their current positions are the
    /// rest shapes) at rest. Errors if there are no objects or the config is invalid.
    pub fn new(objects: Vec<Mesh>, config: SimConfig) -> Result<Self, SimError> {
        config.validate()?;
        if objects.is_empty() {
            return Err(SimError::NoObjects);
        }
        if objects.len() > u32::MAX as usize {
            return Err(SimError::TooManyObjects(objects.len()));
        }
        let h = config.frame_dt / f64::from(config.substeps);
        let mut scale: f64 = 0.0;
        for mesh in &objects {
            let (lo, hi) = bounds(mesh.positions());
            scale = scale.max((hi - lo).max_element());
        }
        if !(scale.is_finite() && scale > 0.0) {
            scale = 1.0;
        }
        let mut bodies: Vec<Body> = objects
            .iter()
            .map(|mesh| Body::new(mesh, &config, h))
            .collect();

        // Drive toward the mean of the initial centres of mass, horizontally.
        let centre = bodies.iter().map(Body::com).sum::<DVec3>() / bodies.len() as f64;
        let mut state = config.seed;
        for body in &mut bodies {
            let mut to_centre = centre - body.com();
            to_centre.y = 0.0;
            body.centre = centre;
            let phase = unit(splitmix64(&mut state));
            body.phase = phase * std::f64::consts::TAU;
            body.wobble_dir = if to_centre.length() <= 1e-9 * scale {
                let a = unit(splitmix64(&mut state)) * std::f64::consts::TAU;
                DVec3::new(a.cos(), 0.0, a.sin())
            } else {
                DVec3::Y.cross(to_centre.normalize())
            };
        }
        Ok(Self {
            config,
            bodies,
            scale,
            frame: 0,
        })
    }

    /// Advances one frame. `contacts` are the intersecting triangle pairs of the current
    /// positions (the collision kernel's result for the frame just produced); their order
    /// does not matter, duplicates are ignored, and pairs naming a missing object or
    /// triangle or the same object twice are skipped.
    pub fn step(&mut self, contacts: &[ObjectContact]) {
        self.apply_contacts(contacts);
        let c = &self.config;
        let h = c.frame_dt / f64::from(c.substeps);
        let t0 = self.frame as f64 * c.frame_dt;
        let growth = 1.0 + c.drive_growth * t0;
        let params = Params {
            h,
            substeps: c.substeps,
            t0,
            shape: c.shape_stiffness,
            internal: c.internal_damping,
            drag: c.drag,
            drive: c.drive_strength * growth * self.scale,
            drive_radius: (c.drive_radius * self.scale).max(1e-12),
            shear: c.shear,
            wobble: c.wobble * self.scale,
            omega: std::f64::consts::TAU / c.wobble_period,
            max_speed: c.max_speed * self.scale,
        };
        self.bodies.par_iter_mut().for_each(|body| {
            for s in 0..params.substeps {
                body.substep(&params, params.t0 + f64::from(s) * params.h);
            }
            body.refresh_out();
        });
        self.frame += 1;
    }

    /// Current vertex positions of `object` (same order as its mesh). Panics if `object` is
    /// out of range.
    pub fn positions(&self, object: usize) -> &[[f32; 3]] {
        &self.bodies[object].out
    }

    /// Triangles of `object` (its mesh's, unchanged). Panics if `object` is out of range.
    pub fn triangles(&self, object: usize) -> &[[u32; 3]] {
        &self.bodies[object].triangles
    }

    /// Number of objects.
    pub fn object_count(&self) -> usize {
        self.bodies.len()
    }

    /// Frames simulated so far.
    pub fn frame(&self) -> u64 {
        self.frame
    }

    /// The configuration in use.
    pub fn config(&self) -> &SimConfig {
        &self.config
    }

    /// The scene's length unit: the largest bounding-box extent of any initial object.
    pub fn scale(&self) -> f64 {
        self.scale
    }

    /// The current state of `object` as a mesh (e.g. for export). Panics if out of range.
    pub fn mesh(&self, object: usize) -> Mesh {
        let body = &self.bodies[object];
        Mesh::new(body.out.clone(), body.triangles.clone())
            .expect("simulated positions are always finite and the topology was validated")
    }

    /// Total kinetic energy `sum m v^2 / 2` (mass units as in the spring stiffnesses).
    pub fn kinetic_energy(&self) -> f64 {
        self.bodies
            .iter()
            .map(|b| {
                b.vel
                    .iter()
                    .zip(&b.mass)
                    .map(|(v, m)| 0.5 * m * v.length_squared())
                    .sum::<f64>()
            })
            .sum()
    }

    /// Total elastic energy: edge and bending springs plus the shape pull.
    pub fn potential_energy(&self) -> f64 {
        let shape = self.config.shape_stiffness;
        self.bodies
            .iter()
            .map(|b| {
                let springs: f64 = b
                    .springs
                    .iter()
                    .map(|s| {
                        let len = (b.pos[s.b as usize] - b.pos[s.a as usize]).length();
                        0.5 * s.k * (len - s.rest) * (len - s.rest)
                    })
                    .sum();
                let com = b.com();
                let pull: f64 = (0..b.pos.len())
                    .map(|i| {
                        let d = com + b.rest_offset[i] - b.pos[i];
                        0.5 * shape * b.mass[i] * d.length_squared()
                    })
                    .sum();
                springs + pull
            })
            .sum()
    }

    /// Turns the contact list into per-vertex contact accelerations for this frame.
    fn apply_contacts(&mut self, contacts: &[ObjectContact]) {
        for body in &mut self.bodies {
            body.contact.fill(DVec3::ZERO);
        }
        let bodies = &self.bodies;
        let valid = |c: &ObjectContact| {
            c.object_a != c.object_b
                && bodies
                    .get(c.object_a as usize)
                    .is_some_and(|b| (c.triangle_a as usize) < b.triangles.len())
                && bodies
                    .get(c.object_b as usize)
                    .is_some_and(|b| (c.triangle_b as usize) < b.triangles.len())
        };
        let mut list: Vec<ObjectContact> = contacts.iter().copied().filter(valid).collect();
        list.sort_unstable();
        list.dedup();

        let c = &self.config;
        let max_depth = c.max_contact_depth * self.scale;
        let offset = c.contact_offset * self.scale;
        let mut pushes = Vec::with_capacity(list.len());
        for contact in &list {
            let body_a = &bodies[contact.object_a as usize];
            let body_b = &bodies[contact.object_b as usize];
            let ta = body_a.triangle(contact.triangle_a);
            let tb = body_b.triangle(contact.triangle_b);
            let na = normal(&ta);
            let nb = normal(&tb);
            let ca = (ta[0] + ta[1] + ta[2]) / 3.0;
            let cb = (tb[0] + tb[1] + tb[2]) / 3.0;
            let mut dir = nb - na;
            if dir.length_squared() < 1e-12 {
                dir = ca - cb;
            }
            if dir.length_squared() < 1e-24 {
                dir = body_a.com() - body_b.com();
            }
            let dir = dir.normalize_or_zero();
            if dir == DVec3::ZERO {
                continue;
            }
            let behind = |t: &[DVec3; 3], n: DVec3, c: DVec3| {
                t.iter()
                    .map(|&v| (c - v).dot(n).max(0.0))
                    .fold(0.0, f64::max)
            };
            let depth = (behind(&ta, nb, cb) + behind(&tb, na, ca)).min(max_depth);
            let push = dir * (c.contact_stiffness * (offset + depth));
            if push.is_finite() {
                pushes.push((*contact, push));
            }
        }
        for (contact, push) in pushes {
            let body = &mut self.bodies[contact.object_a as usize];
            for v in body.triangles[contact.triangle_a as usize] {
                body.contact[v as usize] += push;
            }
            let body = &mut self.bodies[contact.object_b as usize];
            for v in body.triangles[contact.triangle_b as usize] {
                body.contact[v as usize] -= push;
            }
        }
        let limit = c.max_contact_accel * self.scale;
        let share = c.contact_body_share;
        for body in &mut self.bodies {
            let mut total = DVec3::ZERO;
            for (a, m) in body.contact.iter_mut().zip(&body.mass) {
                *a = a.clamp_length_max(limit);
                total += *a * *m;
            }
            body.contact_mean = total * (share / body.total_mass);
            for a in &mut body.contact {
                *a *= 1.0 - share;
            }
        }
    }
}

impl Body {
    fn new(mesh: &Mesh, config: &SimConfig, h: f64) -> Self {
        let pos: Vec<DVec3> = mesh
            .positions()
            .iter()
            .map(|p| DVec3::new(f64::from(p[0]), f64::from(p[1]), f64::from(p[2])))
            .collect();
        let triangles = mesh.triangles().to_vec();
        let n = pos.len();

        // Edges: every (min, max) vertex pair with the vertex opposite it in each triangle.
        // Sorted, never hashed, so springs are built in the same order on every run.
        let mut edges: Vec<(u32, u32, u32)> = Vec::with_capacity(3 * triangles.len());
        for t in &triangles {
            for k in 0..3 {
                let (a, b, o) = (t[k], t[(k + 1) % 3], t[(k + 2) % 3]);
                edges.push((a.min(b), a.max(b), o));
            }
        }
        edges.sort_unstable();
        let mut springs = Vec::with_capacity(2 * edges.len());
        let rest = |a: u32, b: u32| (pos[b as usize] - pos[a as usize]).length();
        let mut bends: Vec<(u32, u32)> = Vec::new();
        let mut i = 0;
        while i < edges.len() {
            let (a, b, _) = edges[i];
            let mut j = i;
            while j < edges.len() && edges[j].0 == a && edges[j].1 == b {
                j += 1;
            }
            springs.push(Spring {
                a,
                b,
                rest: rest(a, b),
                k: config.edge_stiffness,
            });
            // Bending only across manifold edges (exactly two triangles).
            if j - i == 2 {
                let (o1, o2) = (edges[i].2, edges[i + 1].2);
                if o1 != o2 {
                    bends.push((o1.min(o2), o1.max(o2)));
                }
            }
            i = j;
        }
        bends.sort_unstable();
        bends.dedup();
        for (a, b) in bends {
            springs.push(Spring {
                a,
                b,
                rest: rest(a, b),
                k: config.bend_stiffness,
            });
        }

        // Mass scaling for stability of the explicit spring forces (see module docs).
        let mut stiffness = vec![0.0; n];
        for s in &springs {
            stiffness[s.a as usize] += s.k;
            stiffness[s.b as usize] += s.k;
        }
        let mass: Vec<f64> = stiffness
            .iter()
            .map(|&k| (4.0 * h * h * k).max(1.0))
            .collect();
        let total_mass: f64 = mass.iter().sum();
        let com = pos.iter().zip(&mass).map(|(p, m)| *p * *m).sum::<DVec3>() / total_mass;
        let rest_offset = pos.iter().map(|p| *p - com).collect();
        let (lo, hi) = pos
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), p| {
                (lo.min(p.y), hi.max(p.y))
            });
        let height = pos
            .iter()
            .map(|p| if hi > lo { (p.y - lo) / (hi - lo) } else { 0.5 })
            .collect();
        let out = mesh.positions().to_vec();
        Self {
            triangles,
            springs,
            rest_offset,
            height,
            mass,
            total_mass,
            vel: vec![DVec3::ZERO; n],
            force: vec![DVec3::ZERO; n],
            contact: vec![DVec3::ZERO; n],
            pos,
            out,
            centre: DVec3::ZERO,
            contact_mean: DVec3::ZERO,
            wobble_dir: DVec3::ZERO,
            phase: 0.0,
        }
    }

    fn com(&self) -> DVec3 {
        self.pos
            .iter()
            .zip(&self.mass)
            .map(|(p, m)| *p * *m)
            .sum::<DVec3>()
            / self.total_mass
    }

    fn com_velocity(&self) -> DVec3 {
        self.vel
            .iter()
            .zip(&self.mass)
            .map(|(v, m)| *v * *m)
            .sum::<DVec3>()
            / self.total_mass
    }

    fn triangle(&self, t: u32) -> [DVec3; 3] {
        self.triangles[t as usize].map(|v| self.pos[v as usize])
    }

    /// One semi-implicit Euler substep at time `t`.
    fn substep(&mut self, p: &Params, t: f64) {
        let com = self.com();
        let vcom = self.com_velocity();
        self.force.fill(DVec3::ZERO);
        for s in &self.springs {
            let (a, b) = (s.a as usize, s.b as usize);
            let d = self.pos[b] - self.pos[a];
            let len = d.length();
            if len > 1e-12 {
                let f = d * (s.k * (len - s.rest) / len);
                self.force[a] += f;
                self.force[b] -= f;
            }
        }
        let wobble = self.wobble_dir * (p.wobble * (p.omega * t + self.phase).sin());
        // Toward the centre from where the object is now (so an overshoot is pulled back),
        // fading linearly within `drive_radius` of it instead of flipping direction.
        let mut to_centre = self.centre - com;
        to_centre.y = 0.0;
        let drive = to_centre * (p.drive / to_centre.length().max(p.drive_radius));
        let denom = 1.0 + p.h * (p.internal + p.drag);
        for i in 0..self.pos.len() {
            let goal = com + self.rest_offset[i];
            let hgt = self.height[i];
            let accel = self.force[i] / self.mass[i]
                + (goal - self.pos[i]) * p.shape
                + self.contact[i]
                + drive * (1.0 + p.shear * hgt)
                + self.contact_mean
                + wobble * hgt;
            let v = ((self.vel[i] + accel * p.h + vcom * (p.h * p.internal)) / denom)
                .clamp_length_max(p.max_speed);
            let x = self.pos[i] + v * p.h;
            if v.is_finite() && x.is_finite() {
                self.vel[i] = v;
                self.pos[i] = x;
            } else {
                // Cannot happen with a valid config; recover rather than spread NaN.
                self.vel[i] = DVec3::ZERO;
                self.pos[i] = if goal.is_finite() {
                    goal
                } else {
                    self.rest_offset[i]
                };
            }
        }
    }

    fn refresh_out(&mut self) {
        for (o, p) in self.out.iter_mut().zip(&self.pos) {
            *o = [p.x as f32, p.y as f32, p.z as f32];
        }
    }
}

/// Unit normal of a triangle (zero if degenerate).
fn normal(t: &[DVec3; 3]) -> DVec3 {
    (t[1] - t[0]).cross(t[2] - t[0]).normalize_or_zero()
}

/// A uniform number in [0, 1) from a splitmix64 draw.
fn unit(x: u64) -> f64 {
    (x >> 11) as f64 / (1u64 << 53) as f64
}

/// SplitMix64: a tiny, well-mixed, dependency-free generator; all we need for seeded
/// phases and turns.
pub(crate) use dhcd::shapes::splitmix64;

/// Axis-aligned bounds of a point set, in f64.
pub(crate) fn bounds(points: &[[f32; 3]]) -> (DVec3, DVec3) {
    let mut lo = DVec3::splat(f64::INFINITY);
    let mut hi = DVec3::splat(f64::NEG_INFINITY);
    for p in points {
        let q = DVec3::new(f64::from(p[0]), f64::from(p[1]), f64::from(p[2]));
        lo = lo.min(q);
        hi = hi.max(q);
    }
    (lo, hi)
}
