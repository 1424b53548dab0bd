//! [`LazyTiles`]: one buffer (of `f32`, or any plain `Copy` element) whose *groups* (disjoint ranges, each a tile of
//! structure-of-arrays fields) are filled lazily, at most once per *epoch*, by whichever
//! thread needs them first, and read by any number of threads afterwards.
//!
//! In `dhcd`, this is what lets the lazy refit run inside a parallel traversal: node bounds
//! are refitted one sibling group at a time (the block a wide test reads), triangle data
//! one leaf at a time, each exactly once per step whatever the thread count, so the work
//! done (and `N_U`) does not depend on scheduling. It is a `OnceLock` per group without the
//! reset: advancing the epoch (`&mut self`) makes every group stale at once.
//!
//! Protocol, per group: its state is the epoch its data belongs to, or `BUSY` while one
//! thread fills it. A thread that finds it stale claims it with a compare-exchange, fills the
//! group's entries, and publishes with a release store of the current epoch; a thread that
//! finds it `BUSY` waits. Readers only read a group after an acquire load of the current
//! epoch, and the data of a current group is not written again before `&mut self` advances
//! the epoch.
//!
//! It lives in this crate so that the API crate can forbid unsafe code: the invariants it
//! relies on are checked at construction (groups are disjoint and in range) or held by the
//! borrow checker (`&mut` for everything that writes outside a claim).

use std::cell::UnsafeCell;
use std::ops::Range;
use std::sync::atomic::{AtomicU32, Ordering};

/// The state of a group being filled.
const BUSY: u32 = u32::MAX;
/// A state no epoch ever has: stale.
const STALE: u32 = 0;

/// A lazily filled buffer of `T` (`f32` by default) split into groups (see the module doc).
pub struct LazyTiles<T = f32> {
    data: Box<[UnsafeCell<T>]>,
    /// Group `g` owns entries `groups[g]`; disjoint, inside `0..len`.
    groups: Box<[(u32, u32)]>,
    state: Box<[AtomicU32]>,
    /// The current epoch: never `STALE`, never `BUSY`.
    epoch: u32,
}

// SAFETY: the `UnsafeCell`s are written only by the thread holding a group's claim (between
// a successful compare-exchange to `BUSY` and the release store of the epoch), or through
// `&mut self`; shared references to a group's data are handed out only after an acquire load
// of the current epoch, and that data is not written again until `&mut self` advances the
// epoch. Groups are disjoint (checked in `new`), so a claim never overlaps another's data.
unsafe impl<T: Copy + Default + Send + Sync> Sync for LazyTiles<T> {}

impl<T: Copy + Default> LazyTiles<T> {
    /// A buffer of `len` zeros split into `groups` (disjoint ranges inside `0..len`; entries
    /// in no group are never filled lazily). Every group starts stale.
    ///
    /// Panics if two groups overlap or one ends past `len` (a bug in the caller).
    pub fn new(len: usize, groups: Vec<Range<usize>>) -> Self {
        assert!(len <= u32::MAX as usize, "LazyTiles: too many entries");
        let mut sorted: Vec<(usize, usize)> = groups.iter().map(|r| (r.start, r.end)).collect();
        sorted.sort_unstable();
        for w in sorted.windows(2) {
            assert!(w[0].1 <= w[1].0, "LazyTiles: groups overlap");
        }
        assert!(
            sorted.iter().all(|&(s, e)| s <= e && e <= len),
            "LazyTiles: a group ends past the buffer"
        );
        Self {
            data: (0..len).map(|_| UnsafeCell::new(T::default())).collect(),
            groups: groups
                .iter()
                .map(|r| (r.start as u32, r.end as u32))
                .collect(),
            state: groups.iter().map(|_| AtomicU32::new(STALE)).collect(),
            epoch: 1,
        }
    }

    /// Number of entries.
    #[allow(clippy::len_without_is_empty)]
    pub fn len(&self) -> usize {
        self.data.len()
    }

    /// The entries of group `g`.
    #[inline]
    pub fn range(&self, g: usize) -> Range<usize> {
        let (s, e) = self.groups[g];
        s as usize..e as usize
    }

    /// Whether group `g` holds data of the current epoch.
    #[inline]
    pub fn is_current(&self, g: usize) -> bool {
        self.state[g].load(Ordering::Acquire) == self.epoch
    }

    /// Group `g`'s entries, or `None` if it is not current.
    #[inline]
    pub fn get(&self, g: usize) -> Option<&[T]> {
        self.is_current(g).then(|| self.read(g))
    }

    /// Group `g`'s entries of the current epoch, filling them first with `fill` if they are
    /// stale (once per epoch, whichever thread comes first; others wait). Returns the
    /// entries and whether this call did the fill.
    ///
    /// `fill` must not wait for another group or run work on a thread pool: a thread waiting
    /// for this group could be the one that has to run that work.
    #[inline]
    pub fn get_or_fill(&self, g: usize, fill: impl FnOnce(&mut [T])) -> (&[T], bool) {
        let state = &self.state[g];
        let mut seen = state.load(Ordering::Acquire);
        if seen == self.epoch {
            return (self.read(g), false);
        }
        self.claim_and_fill(g, state, &mut seen, fill)
    }

    #[inline(never)]
    fn claim_and_fill(
        &self,
        g: usize,
        state: &AtomicU32,
        seen: &mut u32,
        fill: impl FnOnce(&mut [T]),
    ) -> (&[T], bool) {
        let mut spins = 0u32;
        loop {
            if *seen == self.epoch {
                return (self.read(g), false);
            }
            if *seen == BUSY {
                // Another thread is filling it: a fill is short, spin a little, then yield.
                spins += 1;
                if spins < 64 {
                    std::hint::spin_loop();
                } else {
                    std::thread::yield_now();
                }
                *seen = state.load(Ordering::Acquire);
                continue;
            }
            match state.compare_exchange_weak(*seen, BUSY, Ordering::Acquire, Ordering::Acquire) {
                Ok(_) => break,
                Err(now) => *seen = now,
            }
        }
        // This thread holds the claim. If `fill` panics, hand the group back stale so that
        // nobody waits forever.
        struct Release<'a> {
            state: &'a AtomicU32,
            to: u32,
        }
        impl Drop for Release<'_> {
            fn drop(&mut self) {
                self.state.store(self.to, Ordering::Release);
            }
        }
        let mut release = Release { state, to: *seen };
        let range = self.range(g);
        // SAFETY: the claim gives this thread exclusive access to the group's entries: no
        // other thread writes them (a writer needs the claim) or reads them (readers need
        // the state to equal the epoch). Groups are disjoint, so the slice aliases nothing.
        // `UnsafeCell<T>` has the layout of `T`.
        let entries = unsafe {
            std::slice::from_raw_parts_mut(
                UnsafeCell::raw_get(self.data.as_ptr().add(range.start)),
                range.len(),
            )
        };
        fill(entries);
        release.to = self.epoch;
        drop(release);
        (self.read(g), true)
    }

    /// The entries of a group known to be current.
    #[inline]
    fn read(&self, g: usize) -> &[T] {
        let range = self.range(g);
        // SAFETY: the caller observed (acquire) the group's state equal to the current
        // epoch, so its writer has published; nothing writes a current group before
        // `&mut self` advances the epoch, which ends this borrow.
        unsafe {
            std::slice::from_raw_parts(
                UnsafeCell::raw_get(self.data.as_ptr().add(range.start)).cast_const(),
                range.len(),
            )
        }
    }

    /// Makes every group stale (a new epoch).
    pub fn invalidate(&mut self) {
        if self.epoch + 1 == BUSY {
            for s in self.state.iter_mut() {
                *s.get_mut() = STALE;
            }
            self.epoch = 1;
        } else {
            self.epoch += 1;
        }
    }

    /// Exclusive access to the whole buffer (eager refits); mark what was filled with
    /// [`LazyTiles::set_current`].
    pub fn data_mut(&mut self) -> &mut [T] {
        let cells: &mut [UnsafeCell<T>] = &mut self.data;
        // SAFETY: `&mut self` excludes every other access; `UnsafeCell<T>` has the layout
        // of `T`.
        unsafe {
            std::slice::from_raw_parts_mut(UnsafeCell::raw_get(cells.as_mut_ptr()), cells.len())
        }
    }

    /// Marks group `g` current (after filling it through [`LazyTiles::data_mut`]).
    pub fn set_current(&mut self, g: usize) {
        *self.state[g].get_mut() = self.epoch;
    }
}

impl<T: Copy + Default> Clone for LazyTiles<T> {
    /// Copies the current groups; the others are stale in the copy (their entries may be
    /// mid-fill in another thread, so they are not read).
    fn clone(&self) -> Self {
        let mut copy = Self {
            data: (0..self.len())
                .map(|_| UnsafeCell::new(T::default()))
                .collect(),
            groups: self.groups.clone(),
            state: self.groups.iter().map(|_| AtomicU32::new(STALE)).collect(),
            epoch: self.epoch,
        };
        for g in 0..self.groups.len() {
            if let Some(src) = self.get(g) {
                let range = self.range(g);
                copy.data_mut()[range].copy_from_slice(src);
                copy.set_current(g);
            }
        }
        copy
    }
}

impl<T: Copy + Default> std::fmt::Debug for LazyTiles<T> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let current = (0..self.groups.len())
            .filter(|&g| self.is_current(g))
            .count();
        f.debug_struct("LazyTiles")
            .field("len", &self.len())
            .field("groups", &self.groups.len())
            .field("current", &current)
            .field("epoch", &self.epoch)
            .finish()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rayon::prelude::*;

    fn tiles() -> LazyTiles {
        LazyTiles::new(10, vec![0..3, 3..4, 6..10])
    }

    #[test]
    fn fills_once_per_epoch() {
        let mut s = tiles();
        let mut fills = 0;
        for epoch in 1..4 {
            for _ in 0..3 {
                let (f, _) = s.get_or_fill(2, |t| {
                    fills += 1;
                    assert_eq!(t.len(), 4);
                    t.copy_from_slice(&[epoch as f32, 2.0, 3.0, 4.0]);
                });
                assert_eq!(f, &[epoch as f32, 2.0, 3.0, 4.0]);
            }
            assert!(s.is_current(2) && !s.is_current(0));
            assert!(s.get(0).is_none());
            s.invalidate();
            assert!(!s.is_current(2));
        }
        assert_eq!(fills, 3);
    }

    #[test]
    fn parallel_fills_happen_once_and_are_seen_whole() {
        let s = LazyTiles::new(4096, (0..512).map(|g| g * 8..g * 8 + 8).collect());
        let filled: usize = (0..64 * 512)
            .into_par_iter()
            .map(|k| {
                let g = (k * 7919) % 512;
                let (f, did) = s.get_or_fill(g, |t| {
                    for (i, v) in t.iter_mut().enumerate() {
                        *v = (g * 8 + i) as f32;
                    }
                });
                let want: Vec<f32> = (g * 8..g * 8 + 8).map(|i| i as f32).collect();
                assert_eq!(f, &want[..]);
                did as usize
            })
            .sum();
        assert_eq!(filled, 512);
    }

    #[test]
    fn a_panicking_fill_leaves_the_group_stale() {
        let s = tiles();
        let r = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
            s.get_or_fill(0, |_| panic!("boom"));
        }));
        assert!(r.is_err());
        assert!(!s.is_current(0));
        let (f, did) = s.get_or_fill(0, |t| t.fill(5.0));
        assert!(did);
        assert_eq!(f, &[5.0; 3]);
    }

    #[test]
    fn clone_copies_current_groups_only() {
        let s = tiles();
        s.get_or_fill(1, |t| t.fill(9.0));
        let c = s.clone();
        assert_eq!(c.get(1).unwrap(), &[9.0]);
        assert!(c.get(0).is_none());
    }

    #[test]
    fn epoch_wrap_keeps_states_consistent() {
        let mut s = tiles();
        s.epoch = BUSY - 2;
        s.get_or_fill(0, |t| t.fill(1.0));
        s.invalidate(); // BUSY - 1
        s.invalidate(); // wraps to 1, every state reset
        assert_eq!(s.epoch, 1);
        assert!((0..3).all(|g| !s.is_current(g)));
        for g in 0..3 {
            s.set_current(g);
        }
        assert!((0..3).all(|g| s.is_current(g)));
    }

    #[test]
    #[should_panic(expected = "overlap")]
    fn overlapping_groups_are_refused() {
        LazyTiles::<f32>::new(10, vec![0..5, 4..6]);
    }
}
