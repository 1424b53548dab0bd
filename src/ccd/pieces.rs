//! The one walk over time pieces that the interval filters share (`near.rs`, `planar.rs`):
//! pieces of `[0, t_max]` visited earliest first, each certified apart, halved, split at a
//! point, or decided.
//! Visiting earliest first is what lets a filter read a contact time off the first piece
//! it cannot certify apart: every earlier time was.

use super::filter::Verdict;

/// Most splits in a row: above the 47 halvings that a piece of `[0, 1]` narrower than `2^-46`
/// needs (the midpoints of float endpoints are exact or rounded between them), plus a
/// split at a point.
const MAX_DEPTH: usize = 64;

/// What a filter says of one piece `[lo, hi]`.
pub(crate) enum Piece {
    /// Certainly no contact in it.
    Apart,
    /// Undecided: visit its two halves (or `Unknown` when it cannot be halved).
    Split,
    /// Undecided: visit `[lo, a]`, then `[a, hi]`, `a` placed by an estimate of the contact
    /// time; halved instead unless `lo < a < hi` and the depth bound allows (`Unknown` when
    /// it cannot be halved either).
    SplitAt(f64),
    /// The query's verdict.
    Decided(Verdict),
}

/// Visits the pieces of `[0, t_max]` earliest first, asking `visit(lo, hi, last)`, where
/// `last` says the piece cannot be halved (its midpoint is not strictly inside, or the
/// depth bound is reached). `Miss` when every piece is apart; `Unknown` after `max_visits`
/// pieces or when a piece that cannot be halved is to be split.
#[inline(always)]
pub(crate) fn earliest_first(
    t_max: f64,
    max_visits: u32,
    mut visit: impl FnMut(f64, f64, bool) -> Piece,
) -> Verdict {
    let mut stack = [(0.0f64, 0.0f64); MAX_DEPTH + 1];
    stack[0] = (0.0, t_max);
    let (mut n, mut visits) = (1usize, 0u32);
    while n > 0 {
        n -= 1;
        let (lo, hi) = stack[n];
        visits += 1;
        if visits > max_visits {
            return Verdict::Unknown;
        }
        let mid = 0.5 * (lo + hi);
        let last = n + 2 > MAX_DEPTH || !(lo < mid && mid < hi);
        let at = match visit(lo, hi, last) {
            Piece::Apart => continue,
            Piece::Decided(v) => return v,
            Piece::SplitAt(a) if lo < a && a < hi && n + 2 <= MAX_DEPTH => a,
            Piece::Split | Piece::SplitAt(_) if last => return Verdict::Unknown,
            Piece::Split | Piece::SplitAt(_) => mid,
        };
        stack[n] = (at, hi);
        stack[n + 1] = (lo, at);
        n += 2;
    }
    Verdict::Miss
}
