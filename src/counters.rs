//! Work counters of a query: the `N_V`, `N_P`, `N_U` of the cost model
//! `T = N_V*C_V + N_P*C_P + N_U*C_U`.

/// Counted work of one query (or a sum of queries). Counting is per batch (one addition per
/// frontier level or leaf pair), so it is always on and costs nothing measurable.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct Counters {
    /// `N_V`: bounding-volume pairs tested for overlap.
    pub bv_tests: u64,
    /// `N_P`: triangle pairs given to the exact test.
    pub prim_tests: u64,
    /// `N_U`: bounding volumes refitted (both hierarchies).
    pub bv_updates: u64,
    /// Intersecting triangle pairs found.
    pub contacts: u64,
}

impl std::ops::AddAssign for Counters {
    fn add_assign(&mut self, o: Self) {
        self.bv_tests += o.bv_tests;
        self.prim_tests += o.prim_tests;
        self.bv_updates += o.bv_updates;
        self.contacts += o.contacts;
    }
}

impl std::ops::Add for Counters {
    type Output = Self;
    fn add(mut self, o: Self) -> Self {
        self += o;
        self
    }
}

impl std::iter::Sum for Counters {
    fn sum<I: Iterator<Item = Self>>(iter: I) -> Self {
        iter.fold(Self::default(), |a, b| a + b)
    }
}
