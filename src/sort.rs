//! Sorting result rows whose leading key is a small dense index (a vertex, a triangle, a
//! contact type and vertex): a counting sort by that index, then each group's few rows by
//! their whole key. A contact set's rows (keyed by contact type and first vertex) come in
//! no order by vertex: on cloth-ball a comparison sort of its 419,335 rows took 22 ms, the
//! counting sort 10-16 ms.

/// `rows` sorted by `key` into `sorted` (its old contents dropped), given
/// `group(row) < groups` that orders rows as `key` does (a row of a smaller group has a
/// smaller key). Rows of equal key keep no particular order. `starts` is scratch.
///
/// Where the rows are not few against the groups (at least a quarter as many), a counting
/// sort by group (`O(rows + groups)` time, one index per group of memory), then each group
/// by `key`; else a comparison sort by `key`. The buffers are the caller's so that a query
/// run again reuses their memory (fresh pages cost a fault each: on cloth-ball's contact set
/// the faults of its scratch took about a tenth of the call).
pub(crate) fn by_group_into<T: Copy, K: Ord>(
    rows: &[T],
    sorted: &mut Vec<T>,
    starts: &mut Vec<usize>,
    groups: usize,
    group: impl Fn(&T) -> usize,
    key: impl Fn(&T) -> K,
) {
    sorted.clear();
    let Some(&any) = rows.first() else {
        return;
    };
    if rows.len() < groups / 4 {
        sorted.extend_from_slice(rows);
        sorted.sort_unstable_by_key(key);
        return;
    }
    // `starts[g]` is where group `g` begins, then (from `groups + 1` on) where its next row
    // goes.
    starts.clear();
    starts.resize(2 * (groups + 1), 0);
    let (start, next) = starts.split_at_mut(groups + 1);
    for r in rows {
        start[group(r) + 1] += 1;
    }
    for g in 0..groups {
        start[g + 1] += start[g];
    }
    next.copy_from_slice(start);
    sorted.resize(rows.len(), any);
    for r in rows {
        let g = group(r);
        sorted[next[g]] = *r;
        next[g] += 1;
    }
    for g in start.windows(2) {
        if g[1] - g[0] > 1 {
            sorted[g[0]..g[1]].sort_unstable_by_key(&key);
        }
    }
}

/// Four indices as one number ordered as the array is (lexicographically): a sort key
/// compared in two instructions rather than element by element.
#[inline]
pub(crate) fn as_one(v: [u32; 4]) -> u128 {
    let [v0, v1, v2, v3] = v.map(u128::from);
    v0 << 96 | v1 << 64 | v2 << 32 | v3
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    /// No rows, with groups too few for the comparison sort: no rows back, no panic.
    #[test]
    fn no_rows_sort_to_none() {
        for groups in [0, 1, 3, 4, 100] {
            let mut got = vec![(7, 7)];
            by_group_into::<(u32, u16), _>(
                &[],
                &mut got,
                &mut Vec::new(),
                groups,
                |r| r.0 as usize,
                |r| *r,
            );
            assert!(got.is_empty());
        }
    }

    proptest! {
        /// One number per array, in the arrays' order.
        #[test]
        fn as_one_keeps_the_order(a in any::<[u32; 4]>(), b in any::<[u32; 4]>()) {
            prop_assert_eq!(as_one(a).cmp(&as_one(b)), a.cmp(&b));
        }

        /// The counting sort (many rows against the groups) and the comparison sort (few)
        /// both give a plain sort's order.
        #[test]
        fn both_ways_give_a_plain_sorts_order(
            rows in prop::collection::vec((0u32..6, any::<u16>()), 0..300),
            more_groups in 0usize..2000,
        ) {
            let mut want = rows.clone();
            want.sort();
            // The buffers reused from one sort to the next, as a query's workspace does.
            let (mut got, mut starts) = (vec![(9, 9); 5], vec![3; 11]);
            for groups in [6, 6 + more_groups, 6] {
                by_group_into(&rows, &mut got, &mut starts, groups, |r| r.0 as usize, |r| *r);
                prop_assert_eq!(&got, &want);
            }
        }
    }
}
