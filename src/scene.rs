//! [`Scene`]: any number of deformable objects, added, removed and deformed at will; one call
//! returns every contact between every pair of objects (and, per object on request, its
//! self-contacts).
//!
//! A query runs in three phases:
//! 1. **Broad phase**: each object's root box (min/max of its live vertex positions,
//!    recomputed on every update) goes through sweep-and-prune along x; only object pairs
//!    whose closed boxes overlap are kept. Far-apart objects cost a box comparison.
//! 2. **Jobs**: the kept pairs, and the objects with self-collision on, sorted by object.
//! 3. **Narrow**: every job at once (rayon), each a two-object or a self query on the
//!    shared hierarchies, which may itself split its frontier across the pool. The lazy
//!    refit fits each sibling group once, for whichever query needs it first.
//!
//! Output is deterministic: contacts are sorted and per-pair counters listed in job order.
//! Refits are a fact of an object, not of a pair: each sibling group is fitted once per pose,
//! by whichever query needs it first, so which job fits it depends on timing, but how many
//! nodes of each object were fitted does not. Each object's refits (its lazy fits in this
//! query, and the eager refits of its updates since the last query) are credited to its first
//! job in job order, so every pair's `bv_updates`, and their sum, are the same for every
//! `Par`.

use std::borrow::Cow;

use rayon::prelude::*;

use crate::bv::swept::{box_over_step, f32_up, Step};
use crate::bv::{BoundingVolume, Method};
use crate::contact::{self, step, ContactSet, StepOptions};
use crate::control::{Budget, Control};
use crate::counters::Counters;
use crate::error::{Error, Positions, Result};
use crate::hierarchy::Hierarchy;
use crate::mesh::{check_positions, Mesh};
use crate::methods::{match_method, methods, with_method};
use crate::options::Options;
use crate::par::Par;
use crate::precision::Precision;
use crate::query::ccd::{self, checked_step, earliest_bound, keep_earliest, Swept};
use crate::query::contacts::contacts;
use crate::query::proximity::{self, check_distance};
use crate::query::{
    CcdQuery, Contacts, Impacts, Motion, NodeTest, Overlap, Posed, Proximity, Within,
};
use crate::segments::{segment, OriginalCorners, Segment};
use crate::walk::Workspace;

/// Identifies an object of a [`Scene`]. Ids are handed out in increasing order from 0 and
/// are **never reused**, even after [`Scene::remove`]: a stale id is always an
/// [`Error::UnknownObject`], never another object.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct ObjectId(pub u64);

impl std::fmt::Display for ObjectId {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        self.0.fmt(f)
    }
}

/// The work of one object pair (or one object's self-collision when `a == b`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct PairCounters {
    /// The first object.
    pub a: ObjectId,
    /// The second object (`a` itself for a self query).
    pub b: ObjectId,
    /// The pair's counted work.
    pub counters: Counters,
}

/// Result of [`Scene::contacts`].
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct SceneContacts {
    /// `[object_a, tri_a, object_b, tri_b]`, sorted ascending. Between objects
    /// `object_a < object_b`; self-contacts have `object_a == object_b` and `tri_a < tri_b`.
    /// Triangle indices are each object's original indices.
    pub pairs: Vec<[u64; 4]>,
    /// Counters of every object pair that passed the broad phase (and of every
    /// self-collision query), sorted by `(a, b)`. Pairs culled by the broad phase cost no
    /// BV work and are not listed.
    pub per_pair: Vec<PairCounters>,
    /// Sum of `per_pair`.
    pub counters: Counters,
    /// Object pairs whose root boxes were compared in the broad phase.
    pub broad_phase_tests: u64,
}

/// The proximity of one object pair that passed the broad phase (`a < b`: vertices and
/// edges of `a` first, see [`Proximity`]), or of one object with itself (`a == b`).
#[derive(Clone, Debug, PartialEq)]
pub struct PairProximity {
    /// The first object.
    pub a: ObjectId,
    /// The second object (`a` itself for a self query).
    pub b: ObjectId,
    /// Each object's original vertex, triangle and edge indices.
    pub proximity: Proximity,
}

/// Result of [`Scene::proximity`].
#[derive(Clone, Debug, Default, PartialEq)]
pub struct SceneProximity {
    /// Every object pair whose root boxes came within the distance (and every object with
    /// self-collision on), sorted by `(a, b)`, each with its pairs and counters.
    pub per_pair: Vec<PairProximity>,
    /// Sum of the pairs' counters.
    pub counters: Counters,
    /// Object pairs whose root boxes were compared in the broad phase.
    pub broad_phase_tests: u64,
}

/// The impacts of one object pair that passed the broad phase over the step (`a < b`:
/// vertices, triangles and edges of `a` first, as in [`crate::ccd_pair`]), or of one object
/// with itself (`a == b`, as in [`crate::self_ccd`]).
#[derive(Clone, Debug, PartialEq)]
pub struct PairImpacts {
    /// The first object.
    pub a: ObjectId,
    /// The second object (`a` itself for a self query).
    pub b: ObjectId,
    /// Each object's original vertex, triangle and edge indices.
    pub impacts: Impacts,
}

/// Result of [`Scene::ccd`].
#[derive(Clone, Debug, Default, PartialEq)]
pub struct SceneImpacts {
    /// Every object pair whose boxes over the step came within the minimum distance (and
    /// every object with self-collision on), sorted by `(a, b)`, each with its impacts and
    /// counters. In earliest mode only the pairs that tie with `toi` (within
    /// [`crate::ccd::TOI_TOLERANCE`]) keep their impacts; the others are listed with none.
    pub per_pair: Vec<PairImpacts>,
    /// The earliest time of impact over every pair (`None`: nothing collides).
    pub toi: Option<f64>,
    /// Sum of the pairs' counters.
    pub counters: Counters,
    /// Object pairs whose boxes over the step were compared in the broad phase.
    pub broad_phase_tests: u64,
}

/// Result of [`Scene::collision_free_stepsize`].
#[derive(Clone, Debug, Default, PartialEq)]
pub struct SceneStepSize {
    /// The largest fraction of the step, in `[0, 1]`, the rule allows over the whole scene (1:
    /// no pair comes within its gap).
    pub step: f64,
    /// The pairs that reach their gap at `step`, per object pair, as
    /// [`crate::contact::StepSize::limiting`]: `toi` the least time, `counters` the work of
    /// both walks, `broad_phase_tests` the box pairs compared by both broad phases.
    pub limiting: SceneImpacts,
}

/// One object of the scene.
#[derive(Clone, Debug)]
struct Object<K: BoundingVolume> {
    id: u64,
    h: Hierarchy<K>,
    self_collision: bool,
    /// Closed box `[min, max]` of the live positions of the vertices used by triangles.
    bounds: [[f32; 3]; 2],
    /// Nodes refitted by eager updates since the last query (credited to its first job).
    refitted: u64,
}

impl<K: BoundingVolume> Object<K> {
    /// The root box of every vertex, free points included (finite: `update_positions`
    /// checks).
    ///
    /// PERF: the SIMD bounds kernel; a scalar `min`/`max` chain per axis waited on each
    /// operation's latency and was 15% of a pawns8 scene step.
    fn refresh_bounds(&mut self) {
        let n = self.h.tree().vertex_total();
        let (lo, hi) = dhcd_kernels::refit::bounds(self.h.points().soa().slice(0..n));
        self.bounds = if self.h.points().is_rounded() {
            // Rounded f64 positions: the next f32 outward holds the exact ones.
            [lo.map(f32::next_down), hi.map(f32::next_up)]
        } else {
            [lo, hi]
        };
    }
}

/// The objects of one method, sorted by id.
type Objs<K> = Vec<Object<K>>;

methods!(crate::methods::method_enum {
    #[derive(Clone, Debug)]
    enum Objects(Objs)
});

macro_rules! each {
    ($self:expr, $v:ident => $e:expr) => {
        match_method!(Objects, $self, $v => $e)
    };
}

/// A set of deformable objects of one method.
///
/// ```
/// use dhcd::{scene::Scene, shapes, Method, Options, Par};
/// let mut scene = Scene::new(Method::Dh, Options::default());
/// let ball = shapes::icosphere(2, 1.0, [0.0; 3]);
/// let a = scene.add(&ball)?;
/// let b = scene.add(&ball)?;
/// let far = scene.add(&ball)?;
/// // Deform: B overlaps A, the third object is far away.
/// scene.update_positions(b, &shapes::translated(ball.positions(), [1.5, 0.0, 0.0]))?;
/// scene.update_positions(far, &shapes::translated(ball.positions(), [50.0, 0.0, 0.0]))?;
/// let c = scene.contacts(Par::Seq);
/// assert!(!c.pairs.is_empty());
/// assert!(c.pairs.iter().all(|p| p[0] == a.0 && p[2] == b.0));
/// // Only the pair (A, B) passed the broad phase.
/// assert_eq!(c.per_pair.len(), 1);
/// scene.remove(b)?;
/// assert!(scene.contacts(Par::Seq).pairs.is_empty());
/// assert!(scene.remove(b).is_err()); // ids are never reused
/// // A simulation step in one call: new poses, then every contact.
/// let back = shapes::translated(ball.positions(), [1.5, 0.0, 0.0]);
/// let c = scene.step(&[(far, &back)], Par::Rayon(2))?;
/// assert!(c.pairs.iter().all(|p| p[0] == a.0 && p[2] == far.0));
/// assert!(!c.pairs.is_empty());
/// # Ok::<(), dhcd::Error>(())
/// ```
#[derive(Clone, Debug)]
pub struct Scene {
    options: Options,
    /// Limits and cancellation of the scene's proximity and CCD queries.
    control: Control,
    next_id: u64,
    /// Sorted by id (ids only grow, so `add` appends).
    objects: Objects,
}

impl Scene {
    /// An empty scene whose objects get hierarchies of method `method` built with `options`.
    pub fn new(method: Method, options: Options) -> Self {
        let objects = with_method!(method, K => Objs::<K>::new().into());
        Self {
            options,
            control: Control::default(),
            next_id: 0,
            objects,
        }
    }

    /// Limits and cancellation of the scene's proximity and CCD queries (the most result
    /// pairs over all object pairs together, a cancel flag, a poll function): see
    /// [`Control`].
    pub fn control(&self) -> &Control {
        &self.control
    }

    /// Replaces the scene's [`Control`].
    pub fn set_control(&mut self, control: Control) {
        self.control = control;
    }

    /// The method of every object's hierarchy.
    pub fn method(&self) -> Method {
        self.objects.method()
    }

    /// The build options of every object's hierarchy.
    pub fn options(&self) -> Options {
        self.options
    }

    /// Number of objects.
    pub fn len(&self) -> usize {
        each!(&self.objects, v => v.len())
    }

    /// Whether the scene has no objects.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The ids of the objects, ascending.
    pub fn ids(&self) -> Vec<ObjectId> {
        each!(&self.objects, v => v.iter().map(|o| ObjectId(o.id)).collect())
    }

    /// Whether `id` names an object of the scene.
    pub fn contains(&self, id: ObjectId) -> bool {
        self.index(id).is_ok()
    }

    /// Adds an object whose rest pose is `mesh` (its hierarchy is built now) with
    /// self-collision off; returns its id.
    pub fn add(&mut self, mesh: &Mesh) -> Result<ObjectId> {
        let id = self.next_id;
        let options = self.options;
        each!(&mut self.objects, v => {
            let mut o = Object {
                id,
                h: Hierarchy::new(mesh, options)?,
                self_collision: false,
                bounds: [[0.0; 3]; 2],
                refitted: 0,
            };
            o.refresh_bounds();
            v.push(o);
        });
        self.next_id += 1;
        Ok(ObjectId(id))
    }

    /// Removes an object. Its id is never handed out again.
    pub fn remove(&mut self, id: ObjectId) -> Result<()> {
        let i = self.index(id)?;
        each!(&mut self.objects, v => { v.remove(i); });
        Ok(())
    }

    /// The object's new vertex positions (its mesh's vertex order and count, finite).
    /// On error nothing changes.
    pub fn update_positions(&mut self, id: ObjectId, positions: &[[f32; 3]]) -> Result<()> {
        let i = self.index(id)?;
        each!(&mut self.objects, v => {
            v[i].refitted += v[i].h.update_positions(positions).map_err(|e| e.in_object(id.0))?;
            v[i].refresh_bounds();
        });
        Ok(())
    }

    /// The new `f64` positions of an object built from an `f64` mesh (see
    /// [`Hierarchy::update_positions_f64`]). On error nothing changes.
    pub fn update_positions_f64(&mut self, id: ObjectId, positions: &[[f64; 3]]) -> Result<()> {
        let i = self.index(id)?;
        each!(&mut self.objects, v => {
            v[i].refitted += v[i]
                .h
                .update_positions_f64(positions)
                .map_err(|e| e.in_object(id.0))?;
            v[i].refresh_bounds();
        });
        Ok(())
    }

    /// New positions for several objects at once (each id at most once; each its mesh's
    /// vertex order and count, finite), applied in parallel with `par`. Every update is
    /// checked before any is applied: on error (an unknown or repeated id, a wrong count, a
    /// non-finite position) nothing changes. The result is the same as one
    /// [`Scene::update_positions`] per object, for every `par`.
    pub fn update_many(&mut self, updates: &[(ObjectId, &[[f32; 3]])], par: Par) -> Result<()> {
        let slot = self.slots(updates)?;
        // One trip to the pool for the checks and the gathers (each trip wakes its threads).
        each!(&mut self.objects, v => par.install(|| update_objects(v, &slot, par.is_parallel())))
    }

    /// One simulation step: [`Scene::update_many`] then [`Scene::contacts`], in one trip to
    /// the thread pool (on two threads of a small scene, each trip costs about a tenth of the
    /// step: `docs/PERFORMANCE.md`). On error nothing changes and there are no contacts.
    pub fn step(&mut self, updates: &[(ObjectId, &[[f32; 3]])], par: Par) -> Result<SceneContacts> {
        let slot = self.slots(updates)?;
        let parallel = par.is_parallel();
        each!(&mut self.objects, v => par.install(|| {
            update_objects(v, &slot, parallel)?;
            Ok(contacts_of(v, parallel))
        }))
    }

    /// Each object's item (new positions, a motion) by scene index, or an unknown or
    /// repeated id.
    fn slots<T: Copy>(&self, items: &[(ObjectId, T)]) -> Result<Vec<Option<T>>> {
        let mut slot = vec![None; self.len()];
        for &(id, item) in items {
            let i = self.index(id)?;
            if slot[i].replace(item).is_some() {
                return Err(Error::RepeatedObject(id.0));
            }
        }
        Ok(slot)
    }

    /// Turns the object's self-collision on or off (off when added). With it on,
    /// [`Scene::contacts`] also reports the object's self-contacts.
    pub fn set_self_collision(&mut self, id: ObjectId, on: bool) -> Result<()> {
        let i = self.index(id)?;
        each!(&mut self.objects, v => v[i].self_collision = on);
        Ok(())
    }

    /// Whether object `id`'s self-collision is on.
    pub fn self_collision(&self, id: ObjectId) -> Result<bool> {
        let i = self.index(id)?;
        Ok(each!(&self.objects, v => v[i].self_collision))
    }

    /// The object's region tree.
    pub fn tree(&self, id: ObjectId) -> Result<&std::sync::Arc<crate::tree::RegionTree>> {
        let i = self.index(id)?;
        Ok(each!(&self.objects, v => v[i].h.tree()))
    }

    /// Root box `[min, max]` of the object's current pose (what the broad phase compares).
    pub fn bounds(&self, id: ObjectId) -> Result<[[f32; 3]; 2]> {
        let i = self.index(id)?;
        Ok(each!(&self.objects, v => v[i].bounds))
    }

    /// Every contact of the current poses: between all object pairs, and inside objects with
    /// self-collision on. The result does not depend on `par`.
    pub fn contacts(&mut self, par: Par) -> SceneContacts {
        each!(&mut self.objects, v => par.install(|| contacts_of(v, par.is_parallel())))
    }

    /// Every vertex-triangle and edge-edge pair within distance `d` (finite, `>= 0`, else
    /// [`Error::InvalidDistance`]) between every two objects whose root boxes come within
    /// `d`, and inside every object with self-collision on ([`crate::self_proximity`]). The
    /// result does not depend on `par`; refits are credited as in [`Scene::contacts`].
    pub fn proximity(&mut self, d: f64, par: Par) -> Result<SceneProximity> {
        check_distance(d)?;
        let parallel = par.is_parallel();
        let budget = Budget::new(&self.control);
        each!(&mut self.objects, v => par.install(|| proximity_of(v, d, &budget, parallel)))
    }

    /// Continuous collision detection over one step of the whole scene: every
    /// vertex-triangle and edge-edge pair that collides during the step between two objects,
    /// and inside every object with self-collision on, with its time of impact (or, with
    /// [`CcdMode::Earliest`](crate::CcdMode::Earliest), only the earliest), as
    /// [`crate::ccd_pair`] and [`crate::self_ccd`] find them.
    ///
    /// Each object in `motions` (at most once) moves from its `x0` to its `x1`; as in
    /// [`crate::ccd_pair`], its stored pose is **not read** (it need not equal `x0`), and the
    /// scene is not changed (a simulator updates the poses once it has chosen the step).
    /// Every other object stays still at its stored pose for the whole step (`f32` positions
    /// converted exactly, `f64` ones as stored).
    ///
    /// Broad phase: each object's box over the step (of its vertices at t0 and t1, rounded
    /// outward to `f32`; the stored root box for a still object), grown by the query's
    /// minimum distance, goes through the sweep-and-prune of [`Scene::contacts`]. Each
    /// object's bounds over the step are fitted once and shared by all its jobs; refits are
    /// credited to each object's first job, as in [`Scene::contacts`] (eager refits of
    /// updates wait for the next query of the current pose).
    ///
    /// In earliest mode every job prunes with one shared bound (the earliest time found so
    /// far by any job), and `toi` is the least over all jobs; every job keeps the pairs that
    /// tie with it (their own time within [`crate::ccd::TOI_TOLERANCE`] of it). The impacts and `toi` do not depend on `par` (in all mode neither do the
    /// counters; in earliest mode the work counters do, as for [`crate::ccd_pair`]).
    ///
    /// Everything is checked before any work; on error nothing is computed:
    /// [`Error::UnknownObject`], [`Error::RepeatedObject`], the query's options
    /// ([`Error::InvalidTimeLimit`], [`Error::InvalidMinDistance`]), then each listed
    /// object's positions in scene order ([`Error::WrongVertexCount`],
    /// [`Error::NonFinite`], [`Error::OutOfRange`]).
    ///
    /// ```
    /// use dhcd::{scene::Scene, shapes, CcdQuery, Method, Motion, Options, Par};
    /// let mut scene = Scene::new(Method::Dh, Options::default());
    /// let ball = shapes::icosphere(2, 0.5, [0.0; 3]);
    /// let wall = scene.add(&ball)?;
    /// let bullet = scene.add(&shapes::icosphere(1, 0.1, [-3.0, 0.0, 0.0]))?;
    /// let far = scene.add(&shapes::icosphere(1, 0.5, [50.0, 0.0, 0.0]))?;
    /// // The bullet crosses the ball within the step: it is apart from it at t0 and t1.
    /// let x0: Vec<[f64; 3]> = scene.positions_f64(bullet)?;
    /// let x1: Vec<[f64; 3]> = x0.iter().map(|p| [p[0] + 6.0, p[1], p[2]]).collect();
    /// let hits = scene.ccd(&[(bullet, Motion::new(&x0, &x1))], &CcdQuery::all(), Par::Seq)?;
    /// // Only (wall, bullet) passed the broad phase; the far ball was culled.
    /// assert_eq!(hits.per_pair.len(), 1);
    /// assert_eq!((hits.per_pair[0].a, hits.per_pair[0].b), (wall, bullet));
    /// let toi = hits.toi.unwrap();
    /// assert!(toi > 0.3 && toi < 0.5); // the bullet meets the ball at x = -0.5 - 0.1
    /// let first = scene.ccd(&[(bullet, Motion::new(&x0, &x1))], &CcdQuery::earliest(), Par::Rayon(2))?;
    /// assert_eq!(first.toi, hits.toi);
    /// # let _ = far;
    /// # Ok::<(), dhcd::Error>(())
    /// ```
    pub fn ccd(
        &self,
        motions: &[(ObjectId, Motion<'_>)],
        query: &CcdQuery,
        par: Par,
    ) -> Result<SceneImpacts> {
        let slot = self.slots(motions)?;
        query.options.validate()?;
        let parallel = par.is_parallel();
        let budget = Budget::new(&self.control);
        each!(&self.objects, v => par.install(|| ccd_of(v, &slot, query, &budget, parallel)))
    }

    /// The collision-free step size of the whole scene over one step
    /// ([`crate::contact::collision_free_stepsize`]'s rule, for every pair between two
    /// objects and inside every object with self-collision on): the largest fraction of the
    /// step, in `[0, 1]`, that keeps every pair at least `min_distance + (1 - rescaling)
    /// (d0 - min_distance)` apart, `d0` its distance at t0. Never past the scene's exact
    /// earliest impact at `min_distance` ([`Scene::ccd`]); 1 when no pair comes within its gap.
    ///
    /// Motions are as in [`Scene::ccd`]: each listed object moves from its `x0` to its `x1`
    /// (its stored pose is not read), every other object stays at its stored pose, and the
    /// scene is not changed. The step does not depend on `par`.
    ///
    /// Everything is checked before any work: [`Error::UnknownObject`],
    /// [`Error::RepeatedObject`], the options ([`Error::InvalidMinDistance`],
    /// [`Error::InvalidRescaling`]), then each listed object's positions in scene order.
    ///
    /// ```
    /// use dhcd::{contact::StepOptions, scene::Scene, shapes, Method, Motion, Options, Par};
    /// let mut scene = Scene::new(Method::Dh, Options::default());
    /// let wall = scene.add(&shapes::icosphere(2, 0.5, [0.0; 3]))?;
    /// let bullet = scene.add(&shapes::icosphere(1, 0.1, [-3.0, 0.0, 0.0]))?;
    /// let x0 = scene.positions_f64(bullet)?;
    /// let x1: Vec<[f64; 3]> = x0.iter().map(|p| [p[0] + 6.0, p[1], p[2]]).collect();
    /// let motion = [(bullet, Motion::new(&x0, &x1))];
    /// let safe = scene.collision_free_stepsize(&motion, &StepOptions::default(), Par::Seq)?;
    /// let first = scene.ccd(&motion, &dhcd::CcdQuery::earliest(), Par::Seq)?;
    /// // The bullet stops short of the wall: it keeps a fifth of its distance at t0.
    /// assert!(safe.step > 0.0 && safe.step < first.toi.unwrap());
    /// # let _ = wall;
    /// # Ok::<(), dhcd::Error>(())
    /// ```
    pub fn collision_free_stepsize(
        &self,
        motions: &[(ObjectId, Motion<'_>)],
        options: &StepOptions,
        par: Par,
    ) -> Result<SceneStepSize> {
        let slot = self.slots(motions)?;
        options.validate()?;
        let parallel = par.is_parallel();
        let budget = Budget::new(&self.control);
        each!(&self.objects, v => par.install(|| step_size_of(v, &slot, options, &budget, parallel)))
    }

    /// The object's current positions in its mesh's vertex order, as `f64` (the `f32`
    /// positions converted exactly, or the `f64` ones as stored): the `x0` of a step that
    /// starts from the stored pose.
    pub fn positions_f64(&self, id: ObjectId) -> Result<Vec<[f64; 3]>> {
        let i = self.index(id)?;
        Ok(each!(&self.objects, v => {
            let h = &v[i].h;
            h.tree().vert_slot().iter().map(|&s| h.position_f64(s as usize)).collect()
        }))
    }

    /// Intersection segments of `contacts` (from [`Scene::contacts`] in the current poses),
    /// in the order of `contacts.pairs`. Errors if an object is gone, an index is out of
    /// range, or a pair no longer intersects.
    pub fn contact_segments(&self, contacts: &SceneContacts) -> Result<Vec<Segment>> {
        each!(&self.objects, v => {
            let mut cache: Vec<Option<OriginalCorners<'_, _>>> = (0..v.len()).map(|_| None).collect();
            let mut out = Vec::with_capacity(contacts.pairs.len());
            for &[oa, ta, ob, tb] in &contacts.pairs {
                let (ia, ib) = (self.index(ObjectId(oa))?, self.index(ObjectId(ob))?);
                let tri = |t: u64, i: usize| {
                    u32::try_from(t).map_err(|_| Error::TriangleOutOfRange {
                        triangle: t,
                        triangle_count: v[i].h.tree().triangle_total(),
                    })
                };
                let (ta, tb) = (tri(ta, ia)?, tri(tb, ib)?);
                for i in [ia, ib] {
                    if cache[i].is_none() {
                        cache[i] = Some(OriginalCorners::new(&v[i].h));
                    }
                }
                let ca = cache[ia].as_ref().map(|c| c.get(ta)).transpose()?;
                let cb = cache[ib].as_ref().map(|c| c.get(tb)).transpose()?;
                match (ca, cb) {
                    (Some(ca), Some(cb)) => out.push(segment(&ca, &cb, [ta, tb])?),
                    _ => unreachable!("both caches were filled above"),
                }
            }
            Ok(out)
        })
    }

    /// Every pair of features within `dhat` between every two objects, and inside every
    /// object with self-collision on, once, as [`crate::contact::self_contact_set`] types
    /// them, in one global numbering: each object's vertices and edges follow those of the
    /// objects added before it ([`Scene::vertex_offset`], [`Scene::edge_offset`]). Sorted by
    /// type, then vertices; every row's columns in the same order whichever object owns a
    /// vertex. The result does not depend on `par`.
    pub fn contact_set(&mut self, dhat: f64, par: Par) -> Result<ContactSet> {
        let rows = self.proximity(dhat, par)?;
        each!(&self.objects, v => contact_set_of(v, rows, par))
    }

    /// Where object `id`'s vertices start in the scene's global numbering (the contact
    /// set's): the vertex count of the objects added before it and still in the scene.
    pub fn vertex_offset(&self, id: ObjectId) -> Result<u64> {
        let i = self.index(id)?;
        Ok(each!(&self.objects, v => v[..i].iter().map(|o| o.h.tree().vertex_total() as u64).sum()))
    }

    /// Where object `id`'s edge ids start in the global numbering: the edge count
    /// ([`crate::RegionTree::edges`]) of the objects before it.
    pub fn edge_offset(&self, id: ObjectId) -> Result<u64> {
        let i = self.index(id)?;
        Ok(each!(&self.objects, v => v[..i].iter().map(|o| o.h.tree().edges().len() as u64).sum()))
    }

    fn index(&self, id: ObjectId) -> Result<usize> {
        each!(&self.objects, v => v.binary_search_by_key(&id.0, |o| o.id))
            .map_err(|_| Error::UnknownObject(id.0))
    }
}

/// [`Scene::contact_set`] of the proximity `rows` of `objects`.
fn contact_set_of<K: BoundingVolume>(
    objects: &[Object<K>],
    rows: SceneProximity,
    par: Par,
) -> Result<ContactSet> {
    let (mut vertex_offsets, mut edge_offsets) = (Vec::new(), Vec::new());
    let (mut vo, mut eo) = (0usize, 0usize);
    for o in objects {
        vertex_offsets.push(contact::offset(vo, o.h.tree().vertex_total())?);
        edge_offsets.push(contact::offset(eo, o.h.tree().edges().len())?);
        vo += o.h.tree().vertex_total();
        eo += o.h.tree().edges().len();
    }
    let index = |id: ObjectId| {
        objects
            .binary_search_by_key(&id.0, |o| o.id)
            .expect("an object of the scene")
    };
    let side =
        |i: usize| contact::Side::new(&objects[i].h, None, vertex_offsets[i], edge_offsets[i]);
    let mut set = ContactSet::default();
    let mut scratch = contact::ContactScratch::default();
    for pair in rows.per_pair {
        let (ia, ib) = (index(pair.a), index(pair.b));
        let (sa, sb) = (side(ia)?, side(ib)?);
        let part = contact::from_rows(pair.proximity, &sa, &sb, ia == ib, par, &mut scratch);
        set.contacts.extend(part.contacts);
        set.positions.extend(part.positions);
    }
    // Object pairs hold disjoint vertices: one global order by (type, vertices).
    let mut order: Vec<usize> = (0..set.contacts.len()).collect();
    order.sort_unstable_by_key(|&k| (set.contacts[k].kind, set.contacts[k].vertices));
    set.contacts = order.iter().map(|&k| set.contacts[k]).collect();
    set.positions = order.iter().map(|&k| set.positions[k]).collect();
    set.counters = rows.counters;
    set.counters.contacts = set.contacts.len() as u64;
    Ok(set)
}

/// [`Scene::proximity`] once the distance is checked: every job counted against `budget`.
fn proximity_of<K: BoundingVolume>(
    objects: &mut [Object<K>],
    d: f64,
    budget: &Budget<'_>,
    parallel: bool,
) -> Result<SceneProximity> {
    let within = Within::distance(d);
    let (jobs, results, broad_phase_tests) = posed_walks(
        objects,
        within,
        within.margin,
        parallel,
        // A job stopped by the budget gives nothing; `finish` below says why.
        |posed, ws, par| {
            proximity::run(posed, d, budget, ws, par, proximity::Rows::Sorted).unwrap_or_default()
        },
        |p: &mut Proximity| &mut p.counters,
    );
    budget.finish()?;
    let mut out = SceneProximity {
        broad_phase_tests,
        ..SceneProximity::default()
    };
    for (&(a, b), p) in jobs.iter().zip(results) {
        out.counters += p.counters;
        out.per_pair.push(PairProximity {
            a: ObjectId(objects[a].id),
            b: ObjectId(objects[b].id),
            proximity: p,
        });
    }
    Ok(out)
}

/// Sweep-and-prune on the root boxes along x: the index pairs `(i, j)`, `i < j`, of objects
/// whose closed boxes overlap, sorted; and the number of box pairs compared.
fn broad_phase(bounds: &[[[f32; 3]; 2]]) -> (Vec<(usize, usize)>, u64) {
    let mut order: Vec<usize> = (0..bounds.len()).collect();
    order.sort_by(|&i, &j| bounds[i][0][0].total_cmp(&bounds[j][0][0]).then(i.cmp(&j)));
    let mut active: Vec<usize> = Vec::new();
    let mut out = Vec::new();
    let mut tests = 0u64;
    for &i in &order {
        let b = &bounds[i];
        // Closed intervals: an object whose max x equals this min x still touches it.
        active.retain(|&j| bounds[j][1][0] >= b[0][0]);
        for &j in &active {
            tests += 1;
            let c = &bounds[j];
            if (1..3).all(|k| b[0][k] <= c[1][k] && c[0][k] <= b[1][k]) {
                out.push((i.min(j), i.max(j)));
            }
        }
        active.push(i);
    }
    out.sort_unstable();
    (out, tests)
}

/// Applies `slot[i]` to object `i` (in parallel in the ambient pool if `parallel`), after
/// checking every one: on error (the first failing object in scene order, whatever
/// `parallel`) nothing changes.
fn update_objects<K: BoundingVolume>(
    objects: &mut [Object<K>],
    slot: &[Option<&[[f32; 3]]>],
    parallel: bool,
) -> Result<()> {
    let check = |(o, p): (&Object<K>, &Option<&[[f32; 3]]>)| match p {
        Some(_) if o.h.precision() != Precision::F32 => Err(Error::PrecisionMismatch {
            expected: o.h.precision(),
            got: Precision::F32,
        }),
        Some(p) => check_positions(p, o.h.tree().vertex_total(), Positions::Update)
            .map_err(|e| e.in_object(o.id)),
        None => Ok(()),
    };
    map_objects(objects.len(), parallel, |i| check((&objects[i], &slot[i])))
        .into_iter()
        .collect::<Result<()>>()?;
    let apply = |(o, p): (&mut Object<K>, &Option<&[[f32; 3]]>)| {
        if let Some(p) = p {
            o.refitted += o.h.apply_positions(p);
            o.refresh_bounds();
        }
    };
    if parallel {
        objects
            .par_iter_mut()
            .zip(slot)
            .with_max_len(1)
            .for_each(apply);
    } else {
        objects.iter_mut().zip(slot).for_each(apply);
    }
    Ok(())
}

/// `f(i)` for each object index `i < n`, one object per task in the ambient pool if
/// `parallel`: results in object order.
fn map_objects<R: Send>(n: usize, parallel: bool, f: impl Fn(usize) -> R + Sync + Send) -> Vec<R> {
    if parallel {
        (0..n).into_par_iter().with_max_len(1).map(f).collect()
    } else {
        (0..n).map(f).collect()
    }
}

/// The jobs of a query: the object pairs whose boxes (`boxes`, one per object: the root
/// boxes of the pose, or the boxes over a step), grown by `margin`, overlap, and the objects
/// with self-collision on (`(a, a)`), sorted; and the broad phase's box tests.
fn jobs_of<K: BoundingVolume>(
    objects: &[Object<K>],
    boxes: impl Iterator<Item = [[f32; 3]; 2]>,
    margin: f32,
) -> (Vec<(usize, usize)>, u64) {
    let bounds: Vec<_> = boxes
        .map(|b| {
            if margin == 0.0 {
                b
            } else {
                [
                    b[0].map(|x| (x - margin).next_down()),
                    b[1].map(|x| (x + margin).next_up()),
                ]
            }
        })
        .collect();
    let (mut jobs, tests) = broad_phase(&bounds);
    jobs.extend(
        objects
            .iter()
            .enumerate()
            .filter(|(_, o)| o.self_collision)
            .map(|(i, _)| (i, i)),
    );
    jobs.sort_unstable();
    (jobs, tests)
}

/// The jobs of a query on the current poses (the objects' root boxes grown by `margin`)
/// and `query`'s result on each job's posed hierarchies (`node_test` deciding which nodes
/// go on), by [`run_jobs`]: the jobs, their results in job order, and the broad phase's
/// box tests. Every query on the poses (contacts, proximity, and through it the contact
/// set) is one `query` here.
fn posed_walks<K: BoundingVolume, T: NodeTest + Copy + Sync, R: Send>(
    objects: &mut [Object<K>],
    node_test: T,
    margin: f32,
    parallel: bool,
    query: impl Fn(Posed<'_, K, T>, &mut Workspace, Par) -> (R, [u64; 2]) + Sync,
    counters: impl Fn(&mut R) -> &mut Counters,
) -> (Vec<(usize, usize)>, Vec<R>, u64) {
    let boxes = objects.iter().map(|o| o.bounds);
    let (jobs, broad_phase_tests) = jobs_of(objects, boxes, margin);
    let results = run_jobs(
        objects,
        &jobs,
        parallel,
        |ws, a, b, par| {
            let posed = match b {
                None => Posed::single(a, node_test),
                Some(b) => Posed::pair(a, b, node_test),
            };
            query(posed, ws, par)
        },
        counters,
    );
    (jobs, results, broad_phase_tests)
}

/// Runs `query` on every job at once on the shared hierarchies (the lazy refit fits each
/// group once, whoever needs it first; each query may also split its own walk on the same
/// pool), and credits each object's refits (the nodes fitted on it in every job, plus its
/// eager refits) to its first job: results in job order, each with its counters.
fn run_jobs<K: BoundingVolume, R: Send>(
    objects: &mut [Object<K>],
    jobs: &[(usize, usize)],
    parallel: bool,
    query: impl Fn(&mut Workspace, &Hierarchy<K>, Option<&Hierarchy<K>>, Par) -> (R, [u64; 2]) + Sync,
    counters: impl Fn(&mut R) -> &mut Counters,
) -> Vec<R> {
    let results = run_walks(objects, jobs, parallel, |ws, a, b, par| {
        query(ws, &a.h, b.map(|b| &b.h), par)
    });
    credit_refits(results, jobs, objects.len(), counters, |i| {
        std::mem::take(&mut objects[i].refitted)
    })
}

/// Runs `query` on every job at once, each on its objects' `sides` (`None` as the second
/// for a self job), in the ambient pool if `parallel` (each query may also split its own
/// walk on the same pool): results in job order, with the nodes fitted on each side.
fn run_walks<T: Sync, R: Send>(
    sides: &[T],
    jobs: &[(usize, usize)],
    parallel: bool,
    query: impl Fn(&mut Workspace, &T, Option<&T>, Par) -> (R, [u64; 2]) + Sync,
) -> Vec<(R, [u64; 2])> {
    let inner = if parallel { Par::Ambient } else { Par::Seq };
    let run = |ws: &mut Workspace, (a, b): (usize, usize)| {
        let other = (a != b).then(|| &sides[b]);
        query(ws, &sides[a], other, inner)
    };
    if parallel && jobs.len() > 1 {
        // One workspace per worker thread, reused across jobs.
        jobs.par_iter()
            .map_init(Workspace::default, |ws, &job| run(ws, job))
            .collect()
    } else {
        let mut ws = Workspace::default();
        jobs.iter().map(|&job| run(&mut ws, job)).collect()
    }
}

/// Credits each object's refits to its first job in job order: the sum over jobs of the
/// nodes fitted on it (whichever job fitted them), plus `eager(i)`, its refits outside the
/// walks. Objects in no job were not touched (`eager` is not called for them: their eager
/// refits wait for their next job). The results in job order.
fn credit_refits<R>(
    mut results: Vec<(R, [u64; 2])>,
    jobs: &[(usize, usize)],
    objects: usize,
    counters: impl Fn(&mut R) -> &mut Counters,
    mut eager: impl FnMut(usize) -> u64,
) -> Vec<R> {
    let mut refitted = vec![0u64; objects];
    for (&(a, b), (_, fitted)) in jobs.iter().zip(&results) {
        refitted[a] += fitted[0];
        refitted[b] += fitted[1];
    }
    let mut first_job = vec![None; objects];
    for (k, &(a, b)) in jobs.iter().enumerate().rev() {
        first_job[a] = Some(k);
        first_job[b] = Some(k);
    }
    for (r, _) in &mut results {
        counters(r).bv_updates = 0;
    }
    for (i, (first, lazy)) in first_job.into_iter().zip(refitted).enumerate() {
        if let Some(k) = first {
            counters(&mut results[k].0).bv_updates += lazy + eager(i);
        }
    }
    results.into_iter().map(|(r, _)| r).collect()
}

fn contacts_of<K: BoundingVolume>(objects: &mut [Object<K>], parallel: bool) -> SceneContacts {
    let (jobs, results, broad_phase_tests) = posed_walks(
        objects,
        Overlap,
        0.0,
        parallel,
        |posed, ws, par| contacts(posed, ws, par),
        |c: &mut Contacts| &mut c.counters,
    );
    let mut out = SceneContacts {
        broad_phase_tests,
        ..SceneContacts::default()
    };
    for (&(a, b), c) in jobs.iter().zip(results) {
        let (ida, idb) = (objects[a].id, objects[b].id);
        out.pairs.extend(
            c.pairs
                .iter()
                .map(|&[ta, tb]| [ida, ta as u64, idb, tb as u64]),
        );
        out.per_pair.push(PairCounters {
            a: ObjectId(ida),
            b: ObjectId(idb),
            counters: c.counters,
        });
        out.counters += c.counters;
    }
    out.pairs.sort_unstable();
    out
}

/// Each object's step over a query (`None`: still) and its box over the step.
type ObjectStep = (Option<Step>, [[f32; 3]; 2]);

/// Each object's step (checked, in internal order; `None`: still) and box over the step (the
/// stored root box for a still object), from `motions[i]`, object `i`'s motion: the first
/// error in scene order.
fn steps_of<K: BoundingVolume>(
    objects: &[Object<K>],
    motions: &[Option<Motion<'_>>],
    parallel: bool,
) -> Result<Vec<ObjectStep>> {
    map_objects(objects.len(), parallel, |i| {
        let o = &objects[i];
        let Some(motion) = motions[i] else {
            return Ok((None, o.bounds));
        };
        let step = checked_step(o.h.tree(), motion).map_err(|e| e.in_object(o.id))?;
        let b = box_over_step(o.h.tree(), &step, 0);
        Ok((Some(step), [[b[0], b[1], b[2]], [b[3], b[4], b[5]]]))
    })
    .into_iter()
    .collect()
}

/// The bounds over the step of every object in `jobs` that has none in `sweeps` yet (fitted
/// once, shared by all its jobs); a still object's step is its stored pose at both ends.
fn sweep_jobs<'h, K: BoundingVolume>(
    objects: &'h [Object<K>],
    steps: &'h [ObjectStep],
    jobs: &[(usize, usize)],
    sweeps: &mut Vec<Option<Swept<'h, K>>>,
    parallel: bool,
) {
    sweeps.resize_with(objects.len(), || None);
    let mut wanted = vec![false; objects.len()];
    for &(a, b) in jobs {
        wanted[a] = sweeps[a].is_none();
        wanted[b] = sweeps[b].is_none();
    }
    let fitted = map_objects(objects.len(), parallel, |i| {
        wanted[i].then(|| {
            let h = &objects[i].h;
            let step = match &steps[i].0 {
                Some(step) => Cow::Borrowed(step),
                None => Cow::Owned(Step::still(
                    (0..h.tree().vertex_total())
                        .map(|v| h.position_f64(v))
                        .collect(),
                )),
            };
            Swept::of_step(h, step)
        })
    });
    for (slot, new) in sweeps.iter_mut().zip(fitted) {
        if new.is_some() {
            *slot = new;
        }
    }
}

/// `walk` on every job over the step (`sweeps` holds the bounds of every object in a job):
/// its impacts in job order, refits credited to each object's first job. A job stopped by
/// the budget gives nothing; the caller's `budget.finish()` says why.
fn swept_walks<K: BoundingVolume>(
    sweeps: &[Option<Swept<'_, K>>],
    jobs: &[(usize, usize)],
    parallel: bool,
    walk: impl Fn(&mut Workspace, &Swept<'_, K>, &Swept<'_, K>, bool, Par) -> Result<(Impacts, [u64; 2])>
        + Sync,
) -> Vec<Impacts> {
    let results = run_walks(sweeps, jobs, parallel, |ws, a, b, par| {
        let bounds = "an object in a job has its bounds over the step";
        let a = a.as_ref().expect(bounds);
        let (b, self_job) = match b {
            None => (a, true),
            Some(b) => (b.as_ref().expect(bounds), false),
        };
        walk(ws, a, b, self_job, par).unwrap_or_default()
    });
    credit_refits(
        results,
        jobs,
        sweeps.len(),
        |i: &mut Impacts| &mut i.counters,
        |_| 0,
    )
}

/// The scene result of per-job `impacts` (in job order) with the least time `toi`.
fn scene_impacts<K: BoundingVolume>(
    objects: &[Object<K>],
    jobs: &[(usize, usize)],
    impacts: Vec<Impacts>,
    toi: Option<f64>,
    broad_phase_tests: u64,
) -> SceneImpacts {
    let mut out = SceneImpacts {
        toi,
        broad_phase_tests,
        ..SceneImpacts::default()
    };
    for (&(a, b), i) in jobs.iter().zip(impacts) {
        out.counters += i.counters;
        out.per_pair.push(PairImpacts {
            a: ObjectId(objects[a].id),
            b: ObjectId(objects[b].id),
            impacts: i,
        });
    }
    out
}

/// [`Scene::ccd`] once the ids and options are checked: `motions[i]` is object `i`'s motion
/// (`None`: still).
fn ccd_of<K: BoundingVolume>(
    objects: &[Object<K>],
    motions: &[Option<Motion<'_>>],
    query: &CcdQuery,
    budget: &Budget<'_>,
    parallel: bool,
) -> Result<SceneImpacts> {
    let steps = steps_of(objects, motions, parallel)?;
    let margin = f32_up(query.options.min_distance);
    let (jobs, broad_phase_tests) = jobs_of(objects, steps.iter().map(|s| s.1), margin);
    let mut sweeps = Vec::new();
    sweep_jobs(objects, &steps, &jobs, &mut sweeps, parallel);
    let best = earliest_bound(query);
    let mut impacts = swept_walks(&sweeps, &jobs, parallel, |ws, a, b, self_job, par| {
        ccd::run(a, b, self_job, query, best.as_ref(), budget, None, ws, par)
    });
    budget.finish()?;
    let toi = match best {
        Some(_) => keep_earliest(&mut impacts),
        None => impacts.iter().filter_map(|i| i.toi).reduce(f64::min),
    };
    Ok(scene_impacts(
        objects,
        &jobs,
        impacts,
        toi,
        broad_phase_tests,
    ))
}

/// [`Scene::collision_free_stepsize`] once the ids and options are checked: the first
/// impact at the minimum distance over every job (one shared bound), then the gap walk over
/// the jobs whose boxes come within the culling distance, bounded by it (see
/// [`crate::contact::collision_free_stepsize`]).
fn step_size_of<K: BoundingVolume>(
    objects: &[Object<K>],
    motions: &[Option<Motion<'_>>],
    options: &StepOptions,
    budget: &Budget<'_>,
    parallel: bool,
) -> Result<SceneStepSize> {
    let steps = steps_of(objects, motions, parallel)?;
    let boxes = || steps.iter().map(|s| s.1);
    let first = step::first_impact_query(options);
    let (jobs, first_tests) = jobs_of(objects, boxes(), f32_up(first.options.min_distance));
    let mut sweeps = Vec::new();
    sweep_jobs(objects, &steps, &jobs, &mut sweeps, parallel);
    let best = earliest_bound(&first);
    let mut impacts = swept_walks(&sweeps, &jobs, parallel, |ws, a, b, self_job, par| {
        ccd::run(a, b, self_job, &first, best.as_ref(), budget, None, ws, par)
    });
    budget.finish()?;
    let first_work: Counters = impacts.iter().map(|i| i.counters).sum();
    let best = step::bound_at(keep_earliest(&mut impacts));
    let moving: Vec<Motion<'_>> = motions.iter().flatten().copied().collect();
    // A still object's vertices have displacement zero: it counts in the relative motion.
    let still = motions.iter().any(Option::is_none);
    let by = step::by(&best);
    let (query, gap) = step::query_for(options, &moving, still, by);
    let (jobs, broad_phase_tests) = jobs_of(objects, boxes(), f32_up(query.options.min_distance));
    sweep_jobs(objects, &steps, &jobs, &mut sweeps, parallel);
    // The gap walk's bounds over `[0, by]` only (see `contact::step`), fitted here once per
    // object in its jobs rather than by `ccd::run` once per job (which then finds them fitted
    // up to `by` and grows the margin by their rounding).
    let mut in_jobs = vec![false; objects.len()];
    for &(a, b) in &jobs {
        in_jobs[a] = true;
        in_jobs[b] = true;
    }
    let horizon: Vec<Option<Swept<'_, K>>> = if by < 1.0 {
        let fitted = sweeps.iter().zip(&in_jobs);
        let until = fitted.map(|(s, &used)| s.as_ref().filter(|_| used).map(|s| s.until(by)));
        until.collect()
    } else {
        Vec::new()
    };
    let walked = if by < 1.0 { &horizon } else { &sweeps };
    let mut limiting = swept_walks(walked, &jobs, parallel, |ws, a, b, self_job, par| {
        ccd::run(
            a,
            b,
            self_job,
            &query,
            Some(&best),
            budget,
            Some(gap),
            ws,
            par,
        )
    });
    budget.finish()?;
    let toi = keep_earliest(&mut limiting);
    let tests = first_tests + broad_phase_tests;
    let mut limiting = scene_impacts(objects, &jobs, limiting, toi, tests);
    step::add_first_walk(&mut limiting.counters, first_work);
    Ok(SceneStepSize {
        step: step::step_at(toi),
        limiting,
    })
}
