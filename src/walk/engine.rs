//! The walk of one task: depth-first from given overlapping pairs, with the query's group
//! fetches, node tests and leaf action inlined.
//!
//! PERF (compile time): everything a walk does per pair is `#[inline(always)]` so that it
//! compiles inside each backend's `target_feature` context; every call site is therefore a
//! full copy, per backend and query. [`Task::descend`] is the one place the engine is
//! instantiated for the walk proper (the breadth-first start only splits pairs), and
//! `parallel.rs` dispatches each operation through one non-inlined function.

use pulp::Simd;

use super::{push_bits, Query, Side};
use crate::control::POLL_EVERY;
use crate::counters::Counters;

/// The state of one walk task: the query, and the work counted so far.
pub(super) struct Task<'q, Q: Query> {
    pub(super) query: &'q Q,
    pub(super) counters: Counters,
    pub(super) fitted: [u64; 2],
}

impl<'q, Q: Query> Task<'q, Q> {
    pub(super) fn new(query: &'q Q) -> Self {
        Self {
            query,
            counters: Counters::default(),
            fitted: [0; 2],
        }
    }

    /// Sibling group `g` of `side`, fitted first if stale on `simd` (the fit counted for the
    /// side).
    #[inline(always)]
    fn group<S: Simd>(&mut self, simd: S, side: Side, g: usize) -> Q::Block {
        let (block, fitted) = self.query.group(simd, side, g);
        if fitted {
            self.fitted[side as usize] += self.query.tree(side).group_nodes(g).len() as u64;
        }
        block
    }

    /// The root entry: the roots' test (two hierarchies) or the root self pair.
    #[inline(always)]
    pub(super) fn root<S: Simd>(&mut self, simd: S) -> Option<[u32; 2]> {
        if self.query.is_self() {
            return Some([0, 0]);
        }
        let (a, b) = (self.group(simd, Side::A, 0), self.group(simd, Side::B, 0));
        self.counters.bv_tests += 1;
        (self.query.test(simd, a, 0, b, 1) != 0).then_some([0, 0])
    }

    /// Depth-first until `stack` (overlapping pairs) is empty.
    #[inline(always)]
    pub(super) fn descend<S: Simd>(
        &mut self,
        simd: S,
        stack: &mut Vec<[u32; 2]>,
        out: &mut Q::Out,
    ) {
        let mut since_poll = 0;
        while let Some(pair) = stack.pop() {
            if !self.split(simd, pair, stack) {
                let [x, y] = pair;
                let q = self.query;
                q.leaf_pair(simd, x as usize, y as usize, &mut self.counters, out);
                since_poll += 1;
                let poll = since_poll == POLL_EVERY;
                if poll {
                    since_poll = 0;
                }
                if q.stopped(poll) {
                    stack.clear();
                    return;
                }
            }
        }
    }

    /// Pushes the overlapping children pairs of the overlapping pair `[x, y]` to `next`;
    /// false (nothing pushed) for a leaf pair. An internal self pair the query proves clear
    /// pushes nothing and is done (true).
    #[inline(always)]
    pub(super) fn split<S: Simd>(
        &mut self,
        simd: S,
        [x, y]: [u32; 2],
        next: &mut Vec<[u32; 2]>,
    ) -> bool {
        let (x, y) = (x as usize, y as usize);
        let q = self.query;
        let (ta, tb) = (q.tree(Side::A), q.tree(Side::B));
        if q.is_self() && x == y {
            let Some(g) = ta.child_group(x) else {
                return false;
            };
            // A leaf's self pair is cheap to enumerate: only internal nodes, whose proof
            // also saves the pairs between their children, are asked.
            if q.clear(x) {
                return true;
            }
            let block = self.group(simd, Side::A, g);
            let nodes = ta.group_nodes(g);
            let m = nodes.len();
            for i in 0..m {
                let ci = (nodes.start + i) as u32;
                next.push([ci, ci]);
                if i + 1 < m {
                    // The whole group in one test (aligned loads); the pairs j <= i are
                    // masked off and not counted.
                    self.counters.bv_tests += (m - i - 1) as u64;
                    let bits = q.test(simd, block, i, block, m) & !((2u32 << i) - 1);
                    push_bits(next, bits, ci, nodes.start, true);
                }
            }
            return true;
        }
        let (cx, cy) = (ta.child_group(x), tb.child_group(y));
        if cx.is_none() && cy.is_none() {
            // A leaf pair: decided before reading the groups (a call each, lazy fit check).
            return false;
        }
        let (gx, gy) = (ta.group_of(x), tb.group_of(y));
        let (bx, by) = (self.group(simd, Side::A, gx), self.group(simd, Side::B, gy));
        let (ix, iy) = (x - ta.group_nodes(gx).start, y - tb.group_nodes(gy).start);
        let descend_x = match (cx, cy) {
            (Some(_), None) => true,
            (None, _) => false,
            (Some(_), Some(_)) => q.extent(bx, ix) >= q.extent(by, iy),
        };
        if descend_x {
            let g = cx.unwrap_or_default();
            let children = self.group(simd, Side::A, g);
            let nodes = ta.group_nodes(g);
            self.counters.bv_tests += nodes.len() as u64;
            let bits = q.test(simd, by, iy, children, nodes.len());
            push_bits(next, bits, y as u32, nodes.start, false);
        } else {
            let g = cy.unwrap_or_default();
            let children = self.group(simd, Side::B, g);
            let nodes = tb.group_nodes(g);
            self.counters.bv_tests += nodes.len() as u64;
            let bits = q.test(simd, bx, ix, children, nodes.len());
            push_bits(next, bits, x as u32, nodes.start, true);
        }
        true
    }
}
