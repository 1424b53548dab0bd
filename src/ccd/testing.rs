//! A small deterministic generator for the CCD modules' tests (xorshift), so they need no
//! seed handling: coordinates on a coarse grid make exact contacts and degeneracies
//! frequent.

pub(super) struct Rng(pub(super) u64);

impl Rng {
    pub(super) fn next(&mut self) -> u64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        self.0
    }

    pub(super) fn below(&mut self, n: u64) -> u64 {
        self.next() % n
    }

    /// A multiple of 1/4 in [-1, 1]: exact arithmetic, frequent degeneracies.
    pub(super) fn small(&mut self) -> f64 {
        self.below(9) as f64 / 4.0 - 1.0
    }
}
