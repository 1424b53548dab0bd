//! Seeded mutation fuzzing of every mesh parser (issue 9, item 8): each mutated file ends in
//! a parsed mesh or one printable error line, never a panic, a multi-line message, or more
//! memory than a fixed bound for a small input. The generator and the run's size
//! (`DHCD_FUZZ_CASES`, `DHCD_FUZZ_SEED`) are in `mutation.rs`; the command line is fuzzed the
//! same way in `cli/tests/fuzz.rs`.

use std::path::Path;

use dhcd::io::{self, Format};

use crate::mutation::{cases, check_message, keep, mutate, seed, Rng};
use crate::support::peak_bytes;

/// The most a parser may hold allocated for an input of `len` bytes: a mesh of 12-byte
/// positions and triangles, the STL welding table, slack for vector growth.
fn memory_bound(len: usize) -> usize {
    (1 << 20) + 96 * len
}

/// Every parser on `bytes`: a mesh or a one-line error, within the memory bound.
fn check_parsers(bytes: &[u8]) -> Result<(), String> {
    let path = Path::new("fuzz\ncase.mesh");
    let sniffed = Format::sniff(bytes);
    let parsers: [(&str, &dyn Fn() -> dhcd::Result<dhcd::Mesh>); 4] = [
        ("obj", &|| io::parse_obj_bytes(bytes, path)),
        ("stl", &|| io::parse_stl(bytes, path)),
        ("ply", &|| io::parse_ply(bytes, path)),
        ("sniffed", &|| match sniffed {
            Some(format) => io::parse(bytes, format, path),
            None => Ok(dhcd::shapes::icosphere(0, 1.0, [0.0; 3])),
        }),
    ];
    for (name, parse) in parsers {
        let (result, peak) =
            peak_bytes(|| std::panic::catch_unwind(std::panic::AssertUnwindSafe(parse)));
        let result = result.map_err(|_| format!("{name}: panicked"))?;
        if peak > memory_bound(bytes.len()) {
            return Err(format!(
                "{name}: {peak} bytes for {} bytes of input",
                bytes.len()
            ));
        }
        if let Err(e) = result {
            let text = e.to_string();
            check_message(&text).map_err(|m| format!("{name}: {m}"))?;
            if !text.starts_with("fuzz\\ncase.mesh") {
                return Err(format!(
                    "{name}: message does not start with the path: {text}"
                ));
            }
        }
    }
    Ok(())
}

#[test]
fn parsers_end_in_a_mesh_or_one_line_within_bounded_memory() {
    let seeds = crate::fixtures::seeds();
    let (seed, cases) = (seed(), cases());
    for case in 0..cases {
        let mut rng = Rng::new(seed, case);
        let mut bytes = seeds[rng.below(seeds.len())].clone();
        mutate(&mut bytes, &mut rng);
        if let Err(e) = check_parsers(&bytes) {
            let kept = keep(&format!("fuzz-{seed}-{case}.mesh"), &bytes);
            panic!(
                "DHCD_FUZZ_SEED={seed} case {case} ({}): {e}",
                kept.display()
            );
        }
    }
}

/// Random bytes, bare and behind the magic of each format.
#[test]
fn parsers_survive_random_bytes() {
    let (seed, cases) = (seed(), cases() / 4);
    let prefixes: [&[u8]; 5] = [
        b"",
        b"ply\nformat ascii 1.0\n",
        b"ply\nformat binary_little_endian 1.0\n",
        b"solid ",
        b"v 1 2 3\nf ",
    ];
    for case in 0..cases {
        let mut rng = Rng::new(seed ^ 0x5eed, case);
        let mut bytes = prefixes[rng.below(prefixes.len())].to_vec();
        let n = rng.below(600);
        bytes.extend((0..n).map(|_| rng.next() as u8));
        if let Err(e) = check_parsers(&bytes) {
            let kept = keep(&format!("fuzz-random-{seed}-{case}.mesh"), &bytes);
            panic!(
                "DHCD_FUZZ_SEED={seed} case {case} ({}): {e}",
                kept.display()
            );
        }
    }
}
