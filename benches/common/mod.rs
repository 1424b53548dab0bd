//! Self-collision steps on a cycle of frames, shared by the `real` and `scale` benches: one
//! step = new positions (refit) + self-collision, on one thread, default options, for dhcd's
//! methods and for parry3d as a user of its deformable `TriMesh` would run it.
//!
//! parry3d: one `Bvh` leaf per triangle, built once on the first frame (`Binned`, as
//! `TriMesh` does); per step every leaf box is updated from the new positions and the tree
//! refitted without re-optimisation (what `TriMesh::set_vertices` does), self pairs come
//! from its own single-tree BVTT traversal (`traverse_bvtt_single_tree`), pairs sharing a
//! vertex are dropped, and dhcd's exact triangle test decides the rest: only the hierarchy
//! differs from dhcd.
//!
//! Setup is lazy: a sequence is made, and every implementation built and checked, the first
//! time one of its ids passes criterion's filter. The check steps every implementation
//! through every frame and asserts identical pair lists (so the comparison is of equal
//! work), printing the contacts and dhcd's counters.

use std::hint::black_box;

use criterion::Criterion;
use dhcd::{AnyHierarchy, Method, Options, Par, Workspace};
use parry3d::bounding_volume::Aabb as PAabb;
use parry3d::math::Vector;
use parry3d::partitioning::{Bvh, BvhBuildStrategy, BvhWorkspace};

/// A rest mesh (the hierarchies are built on it) and the frames a step cycles through.
pub struct Sequence {
    pub rest: dhcd::Mesh,
    pub frames: Vec<Vec<[f32; 3]>>,
}

/// One implementation of the step.
#[derive(Clone, Copy, Debug)]
pub enum Impl {
    Dhcd(Method),
    Parry,
}

impl Impl {
    /// The last part of a bench id.
    pub fn id(self) -> String {
        match self {
            Impl::Dhcd(m) => format!("dhcd-{}", m.name()),
            Impl::Parry => "parry3d".into(),
        }
    }
}

/// parry3d's deformable self-collision (see the module docs).
pub struct ParrySelf {
    bvh: Bvh,
    ws: BvhWorkspace,
    tris: Vec<[u32; 3]>,
}

fn tri_aabb(p: &[[f32; 3]], t: [u32; 3]) -> PAabb {
    let c = t.map(|v| Vector::from(p[v as usize]));
    PAabb::new(c[0].min(c[1]).min(c[2]), c[0].max(c[1]).max(c[2]))
}

impl ParrySelf {
    pub fn new(rest: &dhcd::Mesh) -> Self {
        let tris = rest.triangles().to_vec();
        let leaves: Vec<PAabb> = tris
            .iter()
            .map(|&t| tri_aabb(rest.positions(), t))
            .collect();
        Self {
            bvh: Bvh::from_leaves(BvhBuildStrategy::Binned, &leaves),
            ws: BvhWorkspace::default(),
            tris,
        }
    }

    /// Refit to `p`, then every intersecting pair `[ti, tj]`, `ti < tj`, sharing no vertex
    /// (unsorted).
    pub fn step(&mut self, p: &[[f32; 3]]) -> Vec<[u32; 2]> {
        for (i, &t) in self.tris.iter().enumerate() {
            self.bvh
                .insert_or_update_partially(tri_aabb(p, t), i as u32, 0.0);
        }
        self.bvh.refit_without_opt();
        let tris = &self.tris;
        let mut pairs = Vec::new();
        self.bvh
            .traverse_bvtt_single_tree::<false>(&mut self.ws, &mut |a, b| {
                let (ta, tb) = (tris[a as usize], tris[b as usize]);
                if ta.iter().any(|v| tb.contains(v)) {
                    return;
                }
                let c = |t: [u32; 3]| t.map(|v| p[v as usize]);
                if dhcd::narrow::triangles_intersect(&c(ta), &c(tb)) {
                    pairs.push([a.min(b), a.max(b)]);
                }
            });
        pairs
    }
}

/// A built implementation, ready to step (dhcd's workspace boxed: it is several times the
/// size of parry's state).
enum Runner {
    Dhcd(AnyHierarchy, Box<Workspace>),
    Parry(ParrySelf),
}

impl Runner {
    fn new(imp: Impl, rest: &dhcd::Mesh) -> Self {
        match imp {
            Impl::Dhcd(m) => Runner::Dhcd(
                AnyHierarchy::new(m, rest, Options::default()).expect("a valid mesh"),
                Box::default(),
            ),
            Impl::Parry => Runner::Parry(ParrySelf::new(rest)),
        }
    }

    /// One step to `p`: the contacts (dhcd's sorted, parry's as found) and dhcd's counters.
    fn step(&mut self, p: &[[f32; 3]]) -> (Vec<[u32; 2]>, Option<dhcd::Counters>) {
        match self {
            Runner::Dhcd(h, ws) => {
                h.update_positions(p).expect("valid positions");
                let c = h.self_collide(ws, Par::Seq);
                (c.pairs, Some(c.counters))
            }
            Runner::Parry(p2) => (p2.step(p), None),
        }
    }
}

/// A sequence with its implementations built, checked, and where each is in the cycle.
struct Prepared {
    seq: Sequence,
    runners: Vec<Runner>,
    next: Vec<usize>,
}

/// Builds every implementation on `seq.rest`, steps each through every frame, and asserts
/// that they find identical pairs on each (printing contacts and dhcd's counters).
fn prepare(label: &str, seq: Sequence, impls: &[Impl]) -> Prepared {
    let mut runners: Vec<Runner> = impls.iter().map(|&i| Runner::new(i, &seq.rest)).collect();
    for (f, p) in seq.frames.iter().enumerate() {
        let mut reference: Option<Vec<[u32; 2]>> = None;
        for (imp, r) in impls.iter().zip(&mut runners) {
            let (mut pairs, counters) = r.step(p);
            pairs.sort_unstable();
            eprintln!(
                "[{label}] frame {f}: {:<12} {} contacts{}",
                imp.id(),
                pairs.len(),
                counters.map_or(String::new(), |c| format!(
                    ", N_V {} N_P {} N_U {}",
                    c.bv_tests, c.prim_tests, c.bv_updates
                ))
            );
            match &reference {
                None => reference = Some(pairs),
                Some(r) => assert!(
                    *r == pairs,
                    "[{label}] frame {f}: {} found {} pairs, {} found {} (not the same pairs)",
                    impls[0].id(),
                    r.len(),
                    imp.id(),
                    pairs.len()
                ),
            }
        }
    }
    // Every runner is at the last frame: the first timed step moves to frame 0.
    let next = vec![seq.frames.len() - 1; impls.len()];
    Prepared { seq, runners, next }
}

/// Registers `<group>/<name>/<impl>` for every implementation: each iteration steps to the
/// next frame of the cycle. `make` runs (once) only if one of the ids is selected.
pub fn bench_steps(
    c: &mut Criterion,
    group: &str,
    name: &str,
    impls: &[Impl],
    make: impl FnOnce() -> Sequence,
) {
    let label = format!("{group}/{name}");
    let mut make = Some(make);
    let mut prepared: Option<Prepared> = None;
    for (k, imp) in impls.iter().enumerate() {
        c.bench_function(&format!("{label}/{}", imp.id()), |b| {
            let p = prepared.get_or_insert_with(|| {
                let make = make.take().expect("made once");
                prepare(&label, make(), impls)
            });
            let (frames, runner, next) = (&p.seq.frames, &mut p.runners[k], &mut p.next[k]);
            b.iter(|| {
                *next = (*next + 1) % frames.len();
                black_box(runner.step(&frames[*next]).0.len())
            })
        });
    }
}
