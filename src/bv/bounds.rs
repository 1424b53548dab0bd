//! The lazily fitted node bounds of every method: one buffer, one tile per sibling group.
//! (A `pub` type in a private module: it appears in the sealed [`super::BoundingVolume`]'s
//! associated types, and is not nameable outside the crate.)

use crate::tree::RegionTree;
use dhcd_kernels::lazy::LazyTiles;
use dhcd_kernels::Tile;

/// The lazily fitted bounds of one method, `F` fields of `T` per node, one tile per sibling
/// group: the group's `F` fields over its padded slots (`tree.group_slots(g)`, its nodes
/// first in order; see [`crate::tree::BLOCK`]), side by side in one buffer. This is the one
/// place that knows the layout (`f32` for the bounds of a pose, `f64` for the moving
/// spheres of a step, `swept.rs`).
#[derive(Clone, Debug)]
pub struct Bounds<const F: usize, T: Copy + Default = f32> {
    tiles: LazyTiles<T>,
}

impl<const F: usize> Bounds<F, f32> {
    /// Group `g`'s tile, filled first with `fit(n)` for each of its nodes if stale.
    #[inline]
    pub(crate) fn group(
        &self,
        tree: &RegionTree,
        g: usize,
        fit: impl Fn(usize) -> [f32; F],
    ) -> (Tile<'_>, bool) {
        let (data, stride, fitted) = self.group_data(tree, g, fit);
        (Tile::new(data, stride), fitted)
    }
}

impl<const F: usize, T: Copy + Default> Bounds<F, T> {
    pub(crate) fn new(tree: &RegionTree) -> Self {
        let groups = (0..tree.group_count())
            .map(|g| {
                let s = tree.group_slots(g);
                F * s.start..F * s.end
            })
            .collect();
        Self {
            tiles: LazyTiles::new(F * tree.slot_count(), groups),
        }
    }

    /// Group `g`'s `F` fields side by side and their stride (the group's slots), filled
    /// first with `fit(n)` for each of its nodes if stale; whether this call filled them.
    #[inline]
    pub(crate) fn group_data(
        &self,
        tree: &RegionTree,
        g: usize,
        fit: impl Fn(usize) -> [T; F],
    ) -> (&[T], usize, bool) {
        let stride = tree.group_slots(g).len();
        let (data, fitted) = self.tiles.get_or_fill(g, |tile| {
            for (i, n) in tree.group_nodes(g).enumerate() {
                for (f, v) in fit(n).into_iter().enumerate() {
                    tile[f * stride + i] = v;
                }
            }
        });
        (data, stride, fitted)
    }

    #[inline]
    pub(crate) fn is_current(&self, g: usize) -> bool {
        self.tiles.is_current(g)
    }

    /// Node `n`'s fields if its group is current.
    pub(crate) fn get(&self, tree: &RegionTree, n: usize) -> Option<[T; F]> {
        let g = tree.group_of(n);
        let tile = self.tiles.get(g)?;
        let (stride, i) = (tree.group_slots(g).len(), n - tree.group_nodes(g).start);
        Some(std::array::from_fn(|f| tile[f * stride + i]))
    }

    pub(crate) fn invalidate(&mut self) {
        self.tiles.invalidate();
    }

    /// Fits every stale group now, deepest groups first, with `fit(n, child)` for each node
    /// (`child(c)` reads a child's fields: its group is deeper, so already current); returns
    /// the number of nodes fitted.
    pub(crate) fn refit_all(
        &mut self,
        tree: &RegionTree,
        fit: impl Fn(usize, &dyn Fn(usize) -> [T; F]) -> [T; F],
    ) -> u64 {
        let mut fitted = 0;
        for g in (0..tree.group_count()).rev() {
            if self.tiles.is_current(g) {
                continue;
            }
            let values: Vec<[T; F]> = {
                let data: &[T] = self.tiles.data_mut();
                let child = |c: usize| {
                    let g = tree.group_of(c);
                    let s = tree.group_slots(g);
                    let i = c - tree.group_nodes(g).start;
                    std::array::from_fn(|f| data[F * s.start + f * s.len() + i])
                };
                tree.group_nodes(g).map(|n| fit(n, &child)).collect()
            };
            let s = tree.group_slots(g);
            let tile = &mut self.tiles.data_mut()[F * s.start..F * s.end];
            for (i, v) in values.iter().enumerate() {
                for (f, &x) in v.iter().enumerate() {
                    tile[f * s.len() + i] = x;
                }
            }
            self.tiles.set_current(g);
            fitted += values.len() as u64;
        }
        fitted
    }
}
