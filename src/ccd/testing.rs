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

    /// A float of random sign, 53-bit mantissa and binary exponent in `[-100, 100]`
    /// (zero one time in 16): far inputs for the error-free transformations.
    pub(super) fn wide(&mut self) -> f64 {
        if self.below(16) == 0 {
            return 0.0;
        }
        let mantissa = 1.0 + (self.next() >> 11) as f64 / (1u64 << 53) as f64;
        let exponent = self.below(201) as i32 - 100;
        let sign = if self.below(2) == 0 { 1.0 } else { -1.0 };
        sign * mantissa * 2f64.powi(exponent)
    }
}
