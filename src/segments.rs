//! Contact segments (opt-in): the intersection segment of each contact, for simulations that
//! need contact points rather than triangle pairs. The queries never compute it; call these
//! on their results, in the same pose.

use crate::bv::BoundingVolume;
use crate::error::{Error, Result};
use crate::hierarchy::Hierarchy;
use crate::narrow::intersection_segment;

/// The intersection of two closed triangles as a segment `[p, q]` (`p == q` for a single
/// point), in `f32`.
pub type Segment = [[f32; 3]; 2];

/// Corners of triangles by the caller's original index, in a hierarchy's current pose.
pub(crate) struct OriginalCorners<'h, K: BoundingVolume> {
    h: &'h Hierarchy<K>,
    slot: Vec<u32>,
}

impl<'h, K: BoundingVolume> OriginalCorners<'h, K> {
    pub(crate) fn new(h: &'h Hierarchy<K>) -> Self {
        let order = h.tree().tri_order();
        let mut slot = vec![0; order.len()];
        for (i, &o) in order.iter().enumerate() {
            slot[o as usize] = i as u32;
        }
        Self { h, slot }
    }

    pub(crate) fn get(&self, t: u32) -> Result<[[f32; 3]; 3]> {
        let i = *self.slot.get(t as usize).ok_or(Error::TriangleOutOfRange {
            triangle: t.into(),
            triangle_count: self.slot.len(),
        })?;
        let p = self.h.points();
        Ok(self.h.tree().triangles()[i as usize].map(|v| p.get(v as usize)))
    }
}

/// The intersection segment of every contact `[ta, tb]` (original indices) between `a` and
/// `b`, in their current poses, in the order of `pairs`.
///
/// Errors: [`Error::TriangleOutOfRange`] for an index the mesh does not have,
/// [`Error::StaleContact`] for a pair that does not intersect in the current pose (contacts
/// from an earlier pose).
///
/// ```
/// use dhcd::{bv::Aabb, collide, contact_segments, Hierarchy, Mesh, Options};
/// let a = Mesh::new(vec![[0.0, 0.0, 0.0], [2.0, 0.0, 0.0], [0.0, 2.0, 0.0]], vec![[0, 1, 2]])?;
/// let b = Mesh::new(vec![[0.5, 0.5, -1.0], [0.5, 0.5, 1.0], [0.2, 0.8, 0.0]], vec![[0, 1, 2]])?;
/// let (mut ha, mut hb) = (Hierarchy::<Aabb>::new(&a, Options::default())?, Hierarchy::<Aabb>::new(&b, Options::default())?);
/// let c = collide(&mut ha, &mut hb);
/// let seg = contact_segments(&ha, &hb, &c.pairs)?;
/// assert_eq!(seg.len(), 1);
/// assert!(seg[0].iter().all(|p| p[2] == 0.0)); // on A's plane z = 0
/// # Ok::<(), dhcd::Error>(())
/// ```
pub fn contact_segments<K: BoundingVolume>(
    a: &Hierarchy<K>,
    b: &Hierarchy<K>,
    pairs: &[[u32; 2]],
) -> Result<Vec<Segment>> {
    let (ca, cb) = (OriginalCorners::new(a), OriginalCorners::new(b));
    pairs
        .iter()
        .map(|&[ta, tb]| segment(&ca.get(ta)?, &cb.get(tb)?, [ta, tb]))
        .collect()
}

/// [`contact_segments`] for self-contacts of one hierarchy.
pub fn self_contact_segments<K: BoundingVolume>(
    h: &Hierarchy<K>,
    pairs: &[[u32; 2]],
) -> Result<Vec<Segment>> {
    contact_segments(h, h, pairs)
}

pub(crate) fn segment(a: &[[f32; 3]; 3], b: &[[f32; 3]; 3], pair: [u32; 2]) -> Result<Segment> {
    intersection_segment(a, b).ok_or(Error::StaleContact { pair })
}
