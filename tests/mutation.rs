//! The mutation fuzzer shared by `tests/fuzz.rs` (every parser) and `cli/tests/fuzz.rs` (the
//! command line): a seeded generator, the mutations, and the run's size.
//!
//! A run is reproducible: `DHCD_FUZZ_SEED` (default 9) seeds it and `DHCD_FUZZ_CASES`
//! (default 3,000) sizes it. A failure names its seed and case and leaves the input in the
//! target's tmp directory. For a long run:
//! `DHCD_FUZZ_CASES=1000000 cargo test --release --workspace fuzz::`.

#![allow(dead_code)]

use std::path::{Path, PathBuf};

pub fn env_or(name: &str, default: u64) -> u64 {
    std::env::var(name)
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(default)
}

pub fn cases() -> u64 {
    env_or("DHCD_FUZZ_CASES", 3000)
}

pub fn seed() -> u64 {
    env_or("DHCD_FUZZ_SEED", 9)
}

/// SplitMix64: small, seeded, and the same on every platform.
pub struct Rng(u64);

impl Rng {
    pub fn new(seed: u64, case: u64) -> Self {
        Rng(seed ^ case.wrapping_mul(0xd1b5_4a32_d192_ed03))
    }

    pub fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    }

    pub fn below(&mut self, n: usize) -> usize {
        (self.next() % n.max(1) as u64) as usize
    }
}

/// Text worth splicing into mesh files: numbers at the edges, keywords of every format,
/// line ends of every kind (LF, CRLF, CR), control bytes, header lines that declare huge counts.
pub const TOKENS: &[&str] = &[
    "-1",
    "0",
    "4294967295",
    "4294967294",
    "99999999999999999999",
    "nan",
    "inf",
    "-0",
    "1e39",
    "3.4e38",
    "/",
    "//",
    "\n",
    "\r\n",
    "\r",
    " ",
    "\t",
    "\\",
    "\\\n",
    "#",
    "\0",
    "\u{1b}[2J",
    "\u{feff}",
    "\u{2028}",
    "f ",
    "v ",
    "f 1 2 3\n",
    "facet",
    "endloop",
    "endsolid",
    "solid",
    "vertex",
    "element face 4294967295\n",
    "element vertex 4000000000\n",
    "element e 0\nproperty uchar p\n",
    "property list uint uint vertex_indices\n",
    "property list uchar float vertex_indices\n",
    "format binary_big_endian 1.0\n",
    "end_header\n",
    "\u{7f}",
    "\u{ff}",
    "255",
    "-128",
];

pub fn mutate(bytes: &mut Vec<u8>, rng: &mut Rng) {
    for _ in 0..1 + rng.below(6) {
        let n = bytes.len();
        match rng.below(7) {
            0 if n > 0 => {
                let i = rng.below(n);
                bytes[i] = rng.next() as u8;
            }
            1 => bytes.insert(rng.below(n + 1), rng.next() as u8),
            2 if n > 0 => {
                bytes.remove(rng.below(n));
            }
            3 => bytes.truncate(rng.below(n + 1)),
            4 | 5 => {
                let at = rng.below(n + 1);
                let t = TOKENS[rng.below(TOKENS.len())];
                bytes.splice(at..at, t.bytes());
            }
            // Repeat a short run many times (long headers, many faces, deep fans).
            _ if n > 0 => {
                let from = rng.below(n);
                let len = 1 + rng.below(40.min(n - from));
                let run = bytes[from..from + len].to_vec();
                let times = 1 + rng.below(200);
                let at = rng.below(n + 1);
                bytes.splice(at..at, run.iter().copied().cycle().take(len * times));
            }
            _ => {}
        }
    }
}

/// Writes a failing input where it can be found again.
pub fn keep(name: &str, bytes: &[u8]) -> PathBuf {
    let path = Path::new(env!("CARGO_TARGET_TMPDIR")).join(name);
    let _ = std::fs::write(&path, bytes);
    path
}

/// A one-line message that echoes nothing unprintable.
pub fn check_message(text: &str) -> Result<(), String> {
    if text.is_empty() || text.chars().any(|c| c.is_control()) {
        return Err(format!("message is not one printable line: {text:?}"));
    }
    Ok(())
}
