//! The table of methods: names, aliases and numbers map both ways, and the methods agree with
//! their `BoundingVolume` implementations.

use std::collections::HashSet;

use dhcd::bv::BoundingVolume;
use dhcd::{for_each_method, AnyHierarchy, Error, Hierarchy, Method, Options};

#[test]
fn names_and_numbers_round_trip() {
    let mut names = HashSet::new();
    let mut codes = HashSet::new();
    for m in Method::ALL {
        assert!(names.insert(m.name()), "{m}: name used twice");
        assert!(codes.insert(m.code()), "{m}: number used twice");
        assert_eq!(Method::from_code(m.code()), Some(m));
        assert_eq!(m.name().parse::<Method>(), Ok(m));
        assert_eq!(m.name().to_uppercase().parse::<Method>(), Ok(m));
        for alias in m.aliases() {
            assert!(names.insert(alias), "{m}: alias {alias} used twice");
            assert_eq!(alias.parse::<Method>(), Ok(m));
        }
        assert_eq!(Method::ALL[m.index()], m);
        assert_eq!(m.to_string(), m.name());
    }
    assert_eq!(Method::from_code(-1), None);
    assert_eq!(Method::from_code(Method::ALL.len() as i32), None);
    assert_eq!("sbv".parse::<Method>(), Ok(Method::Sphere));
    let err = "octree".parse::<Method>().unwrap_err();
    assert_eq!(
        err,
        Error::UnknownMethod {
            got: "octree".into(),
            expected: "dh, sphere, aabb".into()
        }
    );
    assert_eq!(
        err.to_string(),
        "unknown method \"octree\" (expected one of dh, sphere, aabb)"
    );
}

#[test]
fn every_kind_matches_its_row() {
    let mesh = dhcd::shapes::icosphere(1, 1.0, [0.0; 3]);
    let mut seen = Vec::new();
    for_each_method!(K => {
        let h = Hierarchy::<K>::new(&mesh, Options::default()).unwrap();
        assert_eq!(h.method(), K::METHOD);
        assert_eq!(h.bytes_per_node(), K::METHOD.bytes_per_node());
        let any = AnyHierarchy::new(K::METHOD, &mesh, Options::default()).unwrap();
        assert_eq!(any.method(), K::METHOD);
        assert_eq!(any.bytes_per_node(), K::METHOD.bytes_per_node());
        seen.push(K::METHOD);
    });
    assert_eq!(seen, Method::ALL);
    let bytes: Vec<usize> = Method::ALL.iter().map(|m| m.bytes_per_node()).collect();
    assert_eq!(bytes, [8, 16, 24]);
}
