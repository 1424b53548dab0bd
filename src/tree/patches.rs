//! Which nodes are *patches*: nodes whose triangles form one or more topological disks
//! (touching at most at vertices), with each disk's boundary loop. The clearance test of the queries on
//! features ([`crate::query::clearance`]) proves a patch free of close feature pairs from
//! its triangles and its boundary loops alone; a node that is not a patch is never proven.
//!
//! A node is a patch when the mesh is *clean* (every triangle has three distinct corners;
//! around every vertex its triangles form one fan, an arc or a cycle, each edge of it shared
//! by two triangles that run it in opposite directions) and each connected part of the
//! node's triangles (connected through shared edges) has one boundary loop and Euler
//! characteristic 1 (parts may touch at vertices). In a clean mesh those make each part a disk:
//! every vertex of a part has one fan there (the part of its mesh fan in the node is one arc
//! when exactly one boundary edge leaves and one enters it, the whole cycle when none does),
//! so the part is a connected, oriented surface with one boundary loop and `V - E + F = 1`,
//! genus 0.
//!
//! Computed per node on demand, memoized, by gluing disks along edges ([`glue`]): a leaf
//! from its triangles (disks of three edges), an internal node from its children's disks
//! (each asked in turn; a child that is no patch ends it). Gluing needs only the disks'
//! boundaries: in a clean mesh a vertex inside one disk (its whole fan there) is in no
//! other, so disks share only boundary vertices. Only nodes whose geometry the clearance
//! test has already accepted ask, so a mesh the proof never takes (a tube, a crumpled
//! cloth) pays for no topology.

use std::ops::Range;
use std::sync::OnceLock;

use super::RegionTree;

/// Per node, once asked, the boundary loops of its disks if it is a patch (internal vertex
/// indices, each edge directed as its triangle runs it); and, once a node is asked, whether
/// the mesh is clean.
#[derive(Clone, Debug, Default)]
pub(crate) struct Patches {
    /// Which vertices some triangle uses, if the mesh is clean.
    clean: OnceLock<Option<Vec<bool>>>,
    nodes: Vec<OnceLock<Option<Box<Disks>>>>,
}

/// A patch's disks: every loop's boundary edges (one run) and each loop as a range of them.
#[derive(Clone, Debug)]
struct Disks {
    edges: Vec<[u32; 2]>,
    loops: Vec<Range<usize>>,
}

/// A patch: its boundary edges (every loop's, one run) and each loop as a range of them.
pub(crate) struct Patch<'a> {
    pub(crate) edges: &'a [[u32; 2]],
    pub(crate) loops: &'a [Range<usize>],
}

impl Patches {
    /// Nothing computed yet, for the nodes of `tree`.
    pub(crate) fn new(tree: &RegionTree) -> Self {
        Self {
            clean: OnceLock::new(),
            nodes: (0..tree.node_count()).map(|_| OnceLock::new()).collect(),
        }
    }

    /// Node `n` of `tree` (the tree these patches were made for) if it is a patch: its
    /// disks, computed by the first call (with its descendants').
    pub(crate) fn patch<'s>(&'s self, tree: &RegionTree, n: usize) -> Option<Patch<'s>> {
        let disks = self.nodes[n]
            .get_or_init(|| self.glued(tree, n))
            .as_deref()?;
        Some(Patch {
            edges: &disks.edges,
            loops: &disks.loops,
        })
    }

    fn glued(&self, tree: &RegionTree, n: usize) -> Option<Box<Disks>> {
        let used = self.clean.get_or_init(|| clean_mesh(tree)).as_ref()?;
        let glued = if tree.is_leaf(n) {
            // A free point among its own vertices is a feature no triangle bounds.
            if tree.vert_run(n).any(|v| !used[v]) || tree.tri_range(n).is_empty() {
                return None;
            }
            let parts: Vec<[[u32; 2]; 3]> = tree.triangles()[tree.tri_range(n)]
                .iter()
                .map(|&[a, b, c]| [[a, b], [b, c], [c, a]])
                .collect();
            glue(parts.iter().map(|p| &p[..]))
        } else {
            let children: Vec<Patch<'_>> = tree
                .children(n)
                .map(|c| self.patch(tree, c))
                .collect::<Option<_>>()?;
            glue(
                children
                    .iter()
                    .flat_map(|p| p.loops.iter().map(|l| &p.edges[l.clone()])),
            )
        }?;
        let mut disks = Disks {
            edges: Vec::with_capacity(glued.iter().map(Vec::len).sum()),
            loops: Vec::with_capacity(glued.len()),
        };
        for edges in glued {
            let start = disks.edges.len();
            disks.edges.extend(edges);
            disks.loops.push(start..disks.edges.len());
        }
        Some(Box::new(disks))
    }

    /// Bytes held: the memo and every patch computed so far.
    pub(crate) fn bytes(&self) -> usize {
        let patches: usize = self
            .nodes
            .iter()
            .filter_map(|n| n.get()?.as_deref())
            .map(|d| {
                std::mem::size_of::<Disks>()
                    + std::mem::size_of_val(&d.edges[..])
                    + std::mem::size_of_val(&d.loops[..])
            })
            .sum();
        let clean = self
            .clean
            .get()
            .and_then(Option::as_ref)
            .map_or(0, |u| u.len());
        std::mem::size_of_val(&self.nodes[..]) + patches + clean
    }
}

/// Whether the mesh is clean (see the [module](self)), and which vertices some triangle uses.
fn clean_mesh(tree: &RegionTree) -> Option<Vec<bool>> {
    let tris = tree.triangles();
    let n = tree.vertex_total();
    // Each vertex's triangles as the directed edge opposite it, `(a, b)` for a triangle
    // `(v, a, b)`: its fan links `(a, b)` to the triangle whose opposite edge starts at `b`.
    let mut start = vec![0u32; n + 1];
    for t in tris {
        if t[0] == t[1] || t[1] == t[2] || t[2] == t[0] {
            return None;
        }
        for &v in t {
            start[v as usize + 1] += 1;
        }
    }
    for v in 0..n {
        start[v + 1] += start[v];
    }
    let mut fill = start.clone();
    let mut opposite = vec![[0u32; 2]; 3 * tris.len()];
    for &[a, b, c] in tris {
        for (v, e) in [(a, [b, c]), (b, [c, a]), (c, [a, b])] {
            opposite[fill[v as usize] as usize] = e;
            fill[v as usize] += 1;
        }
    }
    let mut used = vec![false; n];
    let mut ends = Vec::new();
    for v in 0..n {
        let fan = &mut opposite[start[v] as usize..start[v + 1] as usize];
        used[v] = !fan.is_empty();
        if !one_fan(fan, &mut ends) {
            return None;
        }
    }
    Some(used)
}

/// Whether the opposite edges of one vertex's triangles chain into one arc or one cycle,
/// each link shared by exactly two of them in opposite directions. Sorts `fan`.
fn one_fan(fan: &mut [[u32; 2]], ends: &mut Vec<u32>) -> bool {
    if fan.is_empty() {
        return true;
    }
    fan.sort_unstable();
    ends.clear();
    ends.extend(fan.iter().map(|e| e[1]));
    ends.sort_unstable();
    let distinct = |s: &[u32]| s.windows(2).all(|w| w[0] != w[1]);
    if !fan.windows(2).all(|w| w[0][0] != w[1][0]) || !distinct(ends) {
        // Two triangles run the same edge at this vertex the same way.
        return false;
    }
    let next = |b: u32| fan.binary_search_by_key(&b, |e| e[0]).ok();
    // The arc's first triangle: one whose start no other ends at (at most one for an arc).
    let mut first = None;
    for (i, e) in fan.iter().enumerate() {
        if ends.binary_search(&e[0]).is_err() {
            if first.is_some() {
                return false;
            }
            first = Some(i);
        }
    }
    let first = first.unwrap_or(0);
    let (mut at, mut visited) = (first, 1);
    while let Some(i) = next(fan[at][1]) {
        if i == first {
            break;
        }
        at = i;
        visited += 1;
        if visited > fan.len() {
            return false;
        }
    }
    visited == fan.len()
}

/// The disks `parts` (each given by its boundary loop, in a clean mesh) glued along their
/// shared edges: each resulting disk's boundary loop, if every connected part of the union
/// is a disk (connected parts may touch at vertices). A shared edge is run in opposite directions
/// by two parts; a connected part of `k` parts with `m` shared edges, whose boundary
/// vertices have `s` extra copies among its parts, has Euler characteristic `k - s + m`.
fn glue<'a>(parts: impl Iterator<Item = &'a [[u32; 2]]>) -> Option<Vec<Vec<[u32; 2]>>> {
    // Every boundary edge: its undirected key, its direction, its part.
    let mut edges: Vec<([u32; 2], [u32; 2], u32)> = Vec::new();
    let mut k = 0usize;
    for (p, part) in parts.enumerate() {
        k += 1;
        for &[a, b] in part {
            edges.push(([a.min(b), a.max(b)], [a, b], p as u32));
        }
    }
    edges.sort_unstable();
    let mut parent: Vec<u32> = (0..k as u32).collect();
    fn root(parent: &mut [u32], mut x: u32) -> u32 {
        while parent[x as usize] != x {
            parent[x as usize] = parent[parent[x as usize] as usize];
            x = parent[x as usize];
        }
        x
    }
    // The shared edges (by the part of one side) and the outer ones.
    let mut shared: Vec<u32> = Vec::new();
    let mut outer: Vec<([u32; 2], u32)> = Vec::new();
    let mut i = 0;
    while i < edges.len() {
        let mut j = i + 1;
        while j < edges.len() && edges[j].0 == edges[i].0 {
            j += 1;
        }
        match j - i {
            1 => outer.push((edges[i].1, edges[i].2)),
            2 => {
                let (x, y) = (edges[i], edges[i + 1]);
                if x.1 != [y.1[1], y.1[0]] {
                    return None;
                }
                shared.push(x.2);
                let (rx, ry) = (root(&mut parent, x.2), root(&mut parent, y.2));
                if rx != ry {
                    parent[rx as usize] = ry;
                }
            }
            _ => return None,
        }
        i = j;
    }
    // Per connected part (by its root): parts, shared edges, boundary vertex copies.
    let roots: Vec<u32> = (0..k as u32).map(|p| root(&mut parent, p)).collect();
    let mut count = vec![(0usize, 0usize); k];
    for r in &roots {
        count[*r as usize].0 += 1;
    }
    for &p in &shared {
        count[roots[p as usize] as usize].1 += 1;
    }
    // Each part's loop starts each of its boundary vertices' edges once: a vertex held by
    // several parts of one connected part is an extra copy (a vertex where two connected
    // parts touch is theirs alike, a pinch between disks).
    let mut starts: Vec<(u32, u32)> = edges
        .iter()
        .map(|e| (roots[e.2 as usize], e.1[0]))
        .collect();
    starts.sort_unstable();
    let mut extra = vec![0usize; k];
    for w in starts.windows(2) {
        if w[0] == w[1] {
            extra[w[0].0 as usize] += 1;
        }
    }
    for r in 0..k {
        let (parts, shared) = count[r];
        if parts > 0 && parts + shared != 1 + extra[r] {
            return None;
        }
    }
    // One loop per connected part: one edge of it leaves and one enters each of its
    // boundary vertices, and following them from one visits all of them.
    let mut outer: Vec<(u32, [u32; 2])> =
        outer.iter().map(|&(e, p)| (roots[p as usize], e)).collect();
    outer.sort_unstable();
    let mut loops: Vec<Vec<[u32; 2]>> = Vec::new();
    let mut from = 0;
    while from < outer.len() {
        let r = outer[from].0;
        let mut to = from + 1;
        while to < outer.len() && outer[to].0 == r {
            to += 1;
        }
        let group = &outer[from..to];
        from = to;
        if !group.windows(2).all(|w| w[0].1[0] != w[1].1[0]) {
            return None;
        }
        let mut ends: Vec<u32> = group.iter().map(|e| e.1[1]).collect();
        ends.sort_unstable();
        if !ends.iter().zip(group).all(|(&e, o)| e == o.1[0]) || group.len() < 3 {
            return None;
        }
        let mut chain = Vec::with_capacity(group.len());
        let mut at = 0;
        loop {
            chain.push(group[at].1);
            let b = group[at].1[1];
            at = group.binary_search_by_key(&b, |e| e.1[0]).ok()?;
            if at == 0 || chain.len() > group.len() {
                break;
            }
        }
        if chain.len() != group.len() {
            return None;
        }
        loops.push(chain);
    }
    // Every connected part has its loop (a closed one, without a boundary, is no disk).
    let with_loops = loops.len();
    if with_loops != (0..k).filter(|&r| count[r].0 > 0).count() {
        return None;
    }
    Some(loops)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tri_loops(tris: &[[u32; 3]]) -> Vec<[[u32; 2]; 3]> {
        tris.iter()
            .map(|&[a, b, c]| [[a, b], [b, c], [c, a]])
            .collect()
    }

    /// The boundary loop lengths of the triangles glued, if they make disks.
    fn glued(tris: &[[u32; 3]]) -> Option<Vec<usize>> {
        let loops = tri_loops(tris);
        glue(loops.iter().map(|l| &l[..])).map(|d| d.iter().map(Vec::len).collect())
    }

    #[test]
    fn triangles_glue_into_disks_and_nothing_else() {
        // A square of two triangles: one loop of four edges.
        assert_eq!(glued(&[[0, 1, 2], [0, 2, 3]]), Some(vec![4]));
        // A fan closed around vertex 0: a hexagon.
        let hexagon: Vec<[u32; 3]> = (0..6).map(|i| [0, 1 + i, 1 + (i + 1) % 6]).collect();
        assert_eq!(glued(&hexagon), Some(vec![6]));
        // Opposite orientations across the shared edge.
        assert!(glued(&[[0, 1, 2], [0, 3, 2]]).is_none());
        // Two triangles touching at a vertex only: two disks.
        assert_eq!(glued(&[[0, 1, 2], [0, 3, 4]]), Some(vec![3, 3]));
        // A disk touching itself at a vertex: not a disk.
        assert!(glued(&[[0, 1, 2], [0, 2, 3], [3, 2, 4], [3, 4, 5], [5, 4, 0]]).is_none());
        // An annulus: a ring of eight triangles around a square hole.
        let ring: Vec<[u32; 3]> = (0..4)
            .flat_map(|i| {
                let (a, b) = (i, (i + 1) % 4);
                [[a, b, 4 + b], [a, 4 + b, 4 + a]]
            })
            .collect();
        assert!(glued(&ring).is_none());
        // A closed tetrahedron: no boundary.
        assert!(glued(&[[0, 2, 1], [0, 1, 3], [1, 2, 3], [0, 3, 2]]).is_none());
        // Two triangles touching at a vertex become a disk once a third joins them.
        assert_eq!(glued(&[[0, 1, 2], [0, 3, 4], [0, 2, 3]]), Some(vec![5]));
        // Apart: two disks.
        assert_eq!(glued(&[[0, 1, 2], [0, 2, 3], [5, 6, 7]]), Some(vec![4, 3]));
        // A disk and an annulus apart: not all disks.
        let mut with_ring = ring.clone();
        with_ring.push([10, 11, 12]);
        assert!(glued(&with_ring).is_none());
    }

    /// Node 0 of the tree of `mesh` (leaves of at most 8 triangles): its loops' lengths
    /// if it is a patch.
    fn root_loops(mesh: &crate::Mesh) -> Option<Vec<usize>> {
        let tree =
            RegionTree::build(mesh, crate::tree::TreeShape::Adaptive { leaf_size: 8 }).unwrap();
        assert!(tree.node_count() > 1);
        let patches = tree.patches();
        let p = patches.patch(&tree, 0)?;
        // The memo answers the same the second time.
        assert_eq!(patches.patch(&tree, 0).unwrap().edges, p.edges);
        Some(p.loops.iter().map(|l| l.len()).collect())
    }

    #[test]
    fn nodes_are_patches_on_demand() {
        // A 6 x 6 grid: one loop of 24 edges around it.
        let sheet = crate::shapes::grid(6, 6, 1.0, [0.0; 3]);
        assert_eq!(root_loops(&sheet), Some(vec![24]));
        // Rolled into a tube (the last column of vertices is the first): no disk.
        let n = 6u32;
        let at = |i: u32, j: u32| j * n + i % n;
        let positions: Vec<[f32; 3]> = (0..=n)
            .flat_map(|j| {
                (0..n).map(move |i| {
                    let a = std::f32::consts::TAU * i as f32 / n as f32;
                    [a.cos(), a.sin(), j as f32]
                })
            })
            .collect();
        let triangles: Vec<[u32; 3]> = (0..n)
            .flat_map(|j| {
                (0..n).flat_map(move |i| {
                    let [a, b, c, d] = [at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1)];
                    [[a, b, c], [a, c, d]]
                })
            })
            .collect();
        let tube = crate::Mesh::new(positions, triangles).unwrap();
        assert_eq!(root_loops(&tube), None);
        // The sheet with a point no triangle uses: its leaf is no patch, nor the root.
        let mut p = sheet.positions().to_vec();
        p.push([2.5, 2.5, 1.0]);
        let with_point = crate::Mesh::new(p, sheet.triangles().to_vec()).unwrap();
        assert_eq!(root_loops(&with_point), None);
    }

    #[test]
    fn a_vertex_fan_is_one_arc_or_one_cycle() {
        let mut ends = Vec::new();
        let mut cycle = [[1, 2], [2, 3], [3, 1]];
        assert!(one_fan(&mut cycle, &mut ends));
        let mut arc = [[1, 2], [2, 3]];
        assert!(one_fan(&mut arc, &mut ends));
        let mut two_arcs = [[1, 2], [3, 4]];
        assert!(!one_fan(&mut two_arcs, &mut ends));
        let mut two_cycles = [[1, 2], [2, 3], [3, 1], [4, 5], [5, 6], [6, 4]];
        assert!(!one_fan(&mut two_cycles, &mut ends));
        let mut flipped = [[1, 2], [1, 3]];
        assert!(!one_fan(&mut flipped, &mut ends));
    }
}
