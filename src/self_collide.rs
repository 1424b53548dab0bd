//! Self-collision of one deforming object: every pair of its triangles that intersect,
//! except a triangle with itself and pairs that share a vertex index (mesh neighbours touch
//! by construction).
//!
//! The same stackless, level-synchronous traversal as [`collide_with`](crate::collide_with),
//! on one hierarchy against itself. The frontier starts from the root *self pair*
//! `(root, root)`. A self pair `(x, x)` is never tested (a node always overlaps itself): an
//! internal `x` expands into the self pairs of its children and the pairs `(c_i, c_j)`,
//! `i < j`, of distinct children; a leaf `x` becomes a *leaf self pair* whose triangle
//! pairs `i < j` go to the exact test. Pairs of distinct nodes are fitted (lazy refit),
//! batch-tested and expanded exactly as in the two-object query. Every unordered pair of
//! distinct nodes appears at most once, so no contact is reported twice.
//!
//! Determinism: the rounds are cut into the same fixed chunks as the two-object query and
//! concatenated in chunk order; contacts are sorted. Contacts and counters are identical for
//! every thread count.

use crate::bv::BvKind;
use crate::counters::Counters;
use crate::hierarchy::Hierarchy;
use crate::narrow;
use crate::par::Par;
use crate::traverse::{corners, exact_tests, test_and_expand, Contacts, Workspace};
use crate::tree::RegionTree;

/// Every pair of intersecting triangles of one object, `[ti, tj]` with `ti < tj` (the
/// caller's original indices), sorted, excluding pairs that share a vertex index; on the
/// calling thread. Refits (lazily) the nodes it tests.
///
/// ```
/// use dhcd::{bv::Dh, self_collide, Hierarchy, Mesh, Options};
/// // Two triangles of one mesh crossing each other (no shared vertex), and a third one
/// // sharing an edge with the first (neighbours are never reported).
/// let mesh = Mesh::new(
///     vec![
///         [0.0, 0.0, 0.0], [2.0, 0.0, 0.0], [0.0, 2.0, 0.0],
///         [0.5, 0.5, -1.0], [0.5, 0.5, 1.0], [0.2, 0.8, 0.0],
///         [2.0, 2.0, 0.0],
///     ],
///     vec![[0, 1, 2], [3, 4, 5], [1, 6, 2]],
/// )?;
/// let mut h = Hierarchy::<Dh>::new(&mesh, Options::default())?;
/// let c = self_collide(&mut h);
/// assert_eq!(c.pairs, vec![[0, 1]]);
/// assert_eq!(c.pairs, dhcd::narrow::brute_force_self_pairs(&mesh));
/// # Ok::<(), dhcd::Error>(())
/// ```
pub fn self_collide<K: BvKind>(h: &mut Hierarchy<K>) -> Contacts {
    self_collide_with(h, &mut Workspace::default(), Par::Seq)
}

/// [`self_collide`] with caller-owned scratch and a choice of parallelism. The result does
/// not depend on `par`.
pub fn self_collide_with<K: BvKind>(
    h: &mut Hierarchy<K>,
    ws: &mut Workspace,
    par: Par,
) -> Contacts {
    par.install(|| run(h, ws, par.is_parallel()))
}

fn run<K: BvKind>(h: &mut Hierarchy<K>, ws: &mut Workspace, parallel: bool) -> Contacts {
    let mut counters = Counters::default();
    let grain = ws.grain;
    // `leaves` holds leaf pairs `[x, y]`, `x != y`, and leaf self pairs `[x, x]`.
    ws.leaves.clear();
    ws.ia.clear();
    ws.ib.clear();
    let mut selves: Vec<u32> = vec![0];
    let mut next_selves: Vec<u32> = Vec::new();
    while !selves.is_empty() || !ws.ia.is_empty() {
        // Pairs of distinct nodes: refit, test, expand (as in the two-object query).
        ws.next_a.clear();
        ws.next_b.clear();
        if !ws.ia.is_empty() {
            h.ensure_fitted(&ws.ia, parallel, &mut ws.stale);
            h.ensure_fitted(&ws.ib, parallel, &mut ws.stale);
            counters.bv_tests += test_and_expand(&*h, &*h, ws, parallel);
        }
        // Self pairs: never tested; expanded after the distinct pairs (fixed order).
        next_selves.clear();
        let t = &**h.tree();
        for &x in &selves {
            let x = x as usize;
            if t.is_leaf(x) {
                ws.leaves.push([x as u32, x as u32]);
                continue;
            }
            let children = t.children(x);
            for ci in children.clone() {
                next_selves.push(ci as u32);
                for cj in ci + 1..children.end {
                    ws.next_a.push(ci as u32);
                    ws.next_b.push(cj as u32);
                }
            }
        }
        std::mem::swap(&mut selves, &mut next_selves);
        std::mem::swap(&mut ws.ia, &mut ws.next_a);
        std::mem::swap(&mut ws.ib, &mut ws.next_b);
    }
    counters.bv_updates = h.take_updates();

    let hh = &*h;
    let exact = exact_tests(&ws.leaves, grain, parallel, |x, y, out| {
        narrow_self_leaves(hh, x, y, out)
    });
    counters.prim_tests = exact.counters.prim_tests;
    counters.contacts = exact.counters.contacts;
    Contacts {
        pairs: exact.pairs,
        counters,
    }
}

#[inline]
fn share_vertex(a: [u32; 3], b: [u32; 3]) -> bool {
    a.iter().any(|v| b.contains(v))
}

/// Exact tests of the triangle pairs of leaves `x` and `y` of one hierarchy (`x == y`: the
/// pairs `i < j` inside the leaf), skipping pairs that share a vertex; pushes the
/// intersecting ones as `[min, max]` original indices and returns the number of pairs given
/// to the exact test.
fn narrow_self_leaves<K: BvKind>(
    h: &Hierarchy<K>,
    x: usize,
    y: usize,
    out: &mut Vec<[u32; 2]>,
) -> u64 {
    let t: &RegionTree = h.tree();
    let (tris, order) = (t.triangles(), t.tri_order());
    let (rx, ry) = (t.tri_range(x), t.tri_range(y));
    let mut tested = 0u64;
    for i in rx {
        let ti = tris[i];
        let ci = corners(h.points(), ti);
        let from = if x == y { i + 1 } else { ry.start };
        for j in from..ry.end {
            let tj = tris[j];
            if share_vertex(ti, tj) {
                continue;
            }
            tested += 1;
            if narrow::triangles_intersect(&ci, &corners(h.points(), tj)) {
                let (a, b) = (order[i], order[j]);
                out.push([a.min(b), a.max(b)]);
            }
        }
    }
    tested
}
