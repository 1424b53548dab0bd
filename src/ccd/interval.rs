//! Sound interval arithmetic on `f64` without rounding-mode control: every operation is done
//! in round-to-nearest and its result widened by one ulp each way (`next_down`/`next_up`).
//! Round-to-nearest is within half an ulp of the exact result (subnormals included, and an
//! overflow to infinity only widens), so the widened interval contains it. A NaN bound
//! (infinity times zero) makes every comparison false, so it certifies nothing.

use super::ring::Ring;

#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Iv {
    pub lo: f64,
    pub hi: f64,
}

impl Iv {
    #[inline(always)]
    pub fn point(x: f64) -> Iv {
        Iv { lo: x, hi: x }
    }

    /// Encloses the exact `a - b` of two floats.
    #[inline(always)]
    pub fn diff(a: f64, b: f64) -> Iv {
        let d = a - b;
        Iv {
            lo: d.next_down(),
            hi: d.next_up(),
        }
    }

    /// `[x - e, x + e]`, widened.
    #[inline(always)]
    pub fn around(x: f64, e: f64) -> Iv {
        Iv {
            lo: (x - e).next_down(),
            hi: (x + e).next_up(),
        }
    }

    /// Certainly > 0.
    #[inline(always)]
    pub fn pos(self) -> bool {
        self.lo > 0.0
    }

    /// Certainly < 0.
    #[inline(always)]
    pub fn neg(self) -> bool {
        self.hi < 0.0
    }

    /// -1 / +1 when the sign is certain, 0 when the interval holds 0 (or is NaN).
    #[inline(always)]
    pub fn sign(self) -> i8 {
        if self.pos() {
            1
        } else if self.neg() {
            -1
        } else {
            0
        }
    }

    /// Encloses a third of every point (division is correctly rounded).
    #[inline(always)]
    pub fn div3(self) -> Iv {
        Iv {
            lo: (self.lo / 3.0).next_down(),
            hi: (self.hi / 3.0).next_up(),
        }
    }

    /// Times a positive float `k` (a product is correctly rounded).
    #[inline(always)]
    pub fn scale(self, k: f64) -> Iv {
        debug_assert!(k > 0.0);
        Iv {
            lo: (self.lo * k).next_down(),
            hi: (self.hi * k).next_up(),
        }
    }
}

impl Ring for Iv {
    #[inline(always)]
    fn add(&self, b: &Self) -> Self {
        Iv {
            lo: (self.lo + b.lo).next_down(),
            hi: (self.hi + b.hi).next_up(),
        }
    }
    #[inline(always)]
    fn sub(&self, b: &Self) -> Self {
        Iv {
            lo: (self.lo - b.hi).next_down(),
            hi: (self.hi - b.lo).next_up(),
        }
    }
    #[inline(always)]
    fn mul(&self, b: &Self) -> Self {
        let p = [
            self.lo * b.lo,
            self.lo * b.hi,
            self.hi * b.lo,
            self.hi * b.hi,
        ];
        // A NaN product (inf * 0) must not be dropped by min/max: propagate it.
        if p.iter().any(|x| x.is_nan()) {
            return Iv {
                lo: f64::NAN,
                hi: f64::NAN,
            };
        }
        let lo = p[0].min(p[1]).min(p[2].min(p[3]));
        let hi = p[0].max(p[1]).max(p[2].max(p[3]));
        Iv {
            lo: lo.next_down(),
            hi: hi.next_up(),
        }
    }
}
