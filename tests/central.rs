//! The DH central vertex options: the least-radius vertex is the brute-force argmin of every
//! region, the paper's vertex is the one closest to the rest centroid, names parse, and
//! (in `hierarchies.rs` and `self_collision.rs`) contacts do not depend on the choice.

use dhcd::bv::Dh;
use dhcd::points::Points;
use dhcd::shapes::{grid, icosphere, wave};
use dhcd::tree::TreeShape;
use dhcd::{CentralVertex, Error, Hierarchy, Mesh, Options};
use dhcd_cli::sim::{pawn_mesh_with, PAWN_HEIGHT};

/// Squared distance in f64, as the library computes it.
fn dist2(p: &Points, a: u32, b: u32) -> f64 {
    let (a, b) = (p.get(a as usize), p.get(b as usize));
    (0..3)
        .map(|k| {
            let d = a[k] as f64 - b[k] as f64;
            d * d
        })
        .sum()
}

/// The `O(m^2)` argmin of the rest radius, ties to the smallest index.
fn brute_min_radius(ids: &[u32], p: &Points) -> u32 {
    let mut best = (f64::INFINITY, u32::MAX);
    for &c in ids {
        let r = ids.iter().fold(0.0f64, |m, &v| m.max(dist2(p, c, v)));
        if r < best.0 || (r == best.0 && c < best.1) {
            best = (r, c);
        }
    }
    best.1
}

/// The vertex closest to the mean of `ids`, ties to the smallest index.
fn brute_rest_centroid(ids: &[u32], p: &Points) -> u32 {
    let mut mean = [0.0f64; 3];
    for &v in ids {
        let q = p.get(v as usize);
        for k in 0..3 {
            mean[k] += q[k] as f64;
        }
    }
    let mean = mean.map(|s| s / ids.len() as f64);
    let d = |v: u32| -> f64 {
        let q = p.get(v as usize);
        (0..3).map(|k| (q[k] as f64 - mean[k]).powi(2)).sum()
    };
    *ids.iter()
        .min_by(|&&a, &&b| d(a).total_cmp(&d(b)).then(a.cmp(&b)))
        .unwrap()
}

fn meshes() -> Vec<(&'static str, Mesh)> {
    let cloth = grid(40, 30, 0.05, [0.0; 3]);
    let waved = Mesh::new(
        wave(cloth.positions(), 0.7, 0.02, [0.0; 3]),
        cloth.triangles().to_vec(),
    )
    .unwrap();
    vec![
        ("icosphere", icosphere(4, 1.0, [0.2, 0.0, -0.1])),
        ("flat grid", cloth),
        ("waved grid", waved),
        ("pawn", pawn_mesh_with(16, 40, PAWN_HEIGHT).unwrap()),
    ]
}

#[test]
fn every_region_gets_the_brute_force_argmin() {
    for (name, mesh) in meshes() {
        for shape in [
            TreeShape::Levels(1),
            TreeShape::Levels(5),
            TreeShape::default(),
        ] {
            let options = |central| Options {
                levels: match shape {
                    TreeShape::Levels(l) => Some(l),
                    _ => None,
                },
                central,
                ..Options::default()
            };
            let min = Hierarchy::<Dh>::new(&mesh, options(CentralVertex::MinRadius)).unwrap();
            let paper = Hierarchy::<Dh>::new(&mesh, options(CentralVertex::RestCentroid)).unwrap();
            min.validate().unwrap();
            let (tree, rest) = (min.tree(), min.points());
            for n in 0..tree.node_count() {
                let ids: Vec<u32> = tree.region_vertices(n).collect();
                let (m, p) = (min.nodes().vertex[n], paper.nodes().vertex[n]);
                assert_eq!(m, brute_min_radius(&ids, rest), "{name} {shape:?} node {n}");
                assert_eq!(
                    p,
                    brute_rest_centroid(&ids, rest),
                    "{name} {shape:?} node {n}"
                );
                // The least radius is at most the paper's (f32 radii: a rounding's slack).
                let (rm, rp) = (
                    min.record(n).unwrap().radius,
                    paper.record(n).unwrap().radius,
                );
                assert!(
                    rm <= rp * (1.0 + 1e-6),
                    "{name} {shape:?} node {n}: {rm} > {rp}"
                );
            }
        }
    }
}

/// Every region of a real simulation frame (the whole 12K-vertex mesh at the root), when the
/// shared data folder is there.
#[test]
fn real_frame_regions_get_the_brute_force_argmin() {
    let Some(path) = crate::support::shared_data(
        "central::real_frame_regions_get_the_brute_force_argmin",
        "real-frames/armadillo-rollers-326.ply",
    ) else {
        return;
    };
    let mesh = dhcd::io::load(&path).unwrap();
    let options = Options {
        central: CentralVertex::MinRadius,
        ..Options::default()
    };
    let h = Hierarchy::<Dh>::new(&mesh, options).unwrap();
    let tree = h.tree();
    for n in 0..tree.node_count() {
        let ids: Vec<u32> = tree.region_vertices(n).collect();
        assert_eq!(
            h.nodes().vertex[n],
            brute_min_radius(&ids, h.points()),
            "node {n}"
        );
    }
}

#[test]
fn names_parse_and_default_is_the_papers() {
    assert_eq!(CentralVertex::default(), CentralVertex::RestCentroid);
    assert_eq!(Options::default().central, CentralVertex::RestCentroid);
    assert_eq!(Options::paper().central, CentralVertex::RestCentroid);
    for c in CentralVertex::ALL {
        assert_eq!(c.name().parse::<CentralVertex>(), Ok(c));
        assert_eq!(c.to_string(), c.name());
    }
    assert_eq!(
        "centroid".parse::<CentralVertex>(),
        Err(Error::UnknownCentral("centroid".into()))
    );
    let message = Error::UnknownCentral("x".into()).to_string();
    assert!(message.contains("rest-centroid") && message.contains("min-radius"));
}
