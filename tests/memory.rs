//! Memory of a query does not grow with the work (issue 8, item 3): the depth-first walk's
//! stack holds at most `depth * (MAX_CHILDREN + MAX_CHILDREN^2 / 2)` node pairs, and the
//! only allocation that grows is the contact list.
//!
//! The bound asserted (and stated in `docs/LIMITS.md`, "Memory of a query"), for a
//! sequential query measured by the counting allocator of `tests/support.rs`:
//!
//! ```text
//! peak bytes <= 2 * contacts * size_of::<[u32; 2]>() + QUERY_SCRATCH_BOUND
//! ```
//!
//! `2`: a `Vec` at most doubles its capacity when it grows (its `realloc` holds the new
//! buffer, counted once); `QUERY_SCRATCH_BOUND` = 1 MiB: the stack (a few thousand pairs at
//! most), the narrow phase's row scratch and whatever else is fixed. Before this bound, the
//! level-synchronous frontier held a whole level of node pairs: 11.9 GB for two overlapping
//! 1M-triangle grids at 8 levels.

use dhcd::shapes::{fold_x, grid, jitter, translated};
use dhcd::{AnyHierarchy, Contacts, Method, Options, Par, Workspace};

use crate::support::peak_bytes;

/// The fixed part of the bound (see the module docs).
const QUERY_SCRATCH_BOUND: usize = 1 << 20;

/// Small leaves (12 triangles, the default before it became 32): the deepest trees and the
/// most node pairs, where a frontier would be largest.
fn deep() -> Options {
    Options {
        leaf_size: 12,
        ..Options::default()
    }
}

/// Asserts the bound on one query's peak, and that the query did many node tests and
/// found many contacts (so the bound is tested where the old frontier was large).
fn assert_bounded(what: &str, c: &Contacts, peak: usize) {
    let contacts = c.pairs.len();
    let bound = 2 * contacts * std::mem::size_of::<[u32; 2]>() + QUERY_SCRATCH_BOUND;
    eprintln!(
        "{what}: N_V {} N_P {} contacts {contacts}: peak {peak} bytes, bound {bound}",
        c.counters.bv_tests, c.counters.prim_tests
    );
    // Hundreds of thousands of node tests and tens of millions of triangle pairs: the old
    // frontier held gigabytes at this scale.
    assert!(c.counters.bv_tests >= 400_000, "{what}: too little work");
    assert!(contacts >= 10_000, "{what}: the layers cross everywhere");
    assert!(peak <= bound, "{what}: {peak} bytes, bound {bound}");
}

/// A `2 cells x cells` grid over `[0, 2] x [0, 1]` and z-noise of half a cell.
fn noisy_grid(cells: u32, origin: [f32; 3], seed: u64) -> dhcd::Mesh {
    let cell = 1.0 / cells as f32;
    let g = grid(2 * cells, cells, cell, [0.0; 3]);
    let p = jitter(
        &translated(g.positions(), origin),
        [0.0, 0.0, 0.5 * cell],
        seed,
    );
    dhcd::Mesh::new(p, g.triangles().to_vec()).unwrap()
}

/// Two noisy grids on top of each other (offset by a fraction of a cell), crossing
/// everywhere: hundreds of thousands of node tests, contacts growing with the area.
#[test]
fn collide_scratch_does_not_grow_with_the_work() {
    let cells = 200; // 160,000 triangles each
    let a = noisy_grid(cells, [0.0; 3], 1);
    let b = noisy_grid(cells, [0.31 / cells as f32, 0.17 / cells as f32, 0.0], 2);
    for method in Method::ALL {
        let ha = AnyHierarchy::new(method, &a, deep()).unwrap();
        let hb = AnyHierarchy::new(method, &b, deep()).unwrap();
        let (c, peak) = peak_bytes(|| {
            ha.collide(&hb, &mut Workspace::default(), Par::Seq)
                .unwrap()
        });
        assert_bounded(&format!("collide {method}"), &c, peak);
    }
}

/// A noisy grid folded onto itself (built flat, then deformed), self-collided.
#[test]
fn self_collide_scratch_does_not_grow_with_the_work() {
    let cells = 200;
    let rest = grid(2 * cells, cells, 1.0 / cells as f32, [0.0; 3]);
    let folded = jitter(
        &fold_x(rest.positions(), 1.0),
        [0.0, 0.0, 0.5 / cells as f32],
        3,
    );
    for method in Method::ALL {
        let mut h = AnyHierarchy::new(method, &rest, deep()).unwrap();
        h.update_positions(&folded).unwrap();
        // The tree's shared-pair table is mesh data, built once per tree by its first self
        // query (docs/LIMITS.md); build it here so that every profile measures the query.
        let tree = h.tree().clone();
        let leaf = tree.leaves().next().unwrap();
        tree.shared_pairs(leaf, leaf).unwrap();
        let (c, peak) = peak_bytes(|| h.self_collide(&mut Workspace::default(), Par::Seq));
        assert_bounded(&format!("self {method}"), &c, peak);
    }
}
