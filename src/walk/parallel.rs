//! Running a walk: on the calling thread, or split into rayon tasks.
//!
//! A parallel walk first expands breadth-first on the calling thread until there are
//! [`SEEDS_PER_THREAD`] pairs per thread (leaf pairs met on the way wait with the rest), then
//! walks the seeds depth-first in tasks of at least the workspace's grain, each task with its
//! own stack and output, merged in seed order. Every node pair is visited at most once
//! whatever the split, so the counters are the same for every thread count.

use pulp::{Simd, WithSimd};
use rayon::prelude::*;

use super::engine::Task;
use super::{Query, Walked, Workspace};
use crate::control::POLL_EVERY;
use crate::par::Par;

/// Pairs the breadth-first start aims for, per thread, before the parallel walk.
const SEEDS_PER_THREAD: usize = 64;

/// Leaf pairs per task of [`leaf_pairs`].
const LEAF_PAIRS_PER_TASK: usize = 64;

/// Walks `query` from its root, with `ws`'s scratch, on the threads `par` names.
pub(crate) fn walk<Q: Query>(query: &Q, ws: &mut Workspace, par: Par) -> Walked<Q::Out> {
    par.install(|| {
        // Only a parallel walk asks for the pool's size: asking starts rayon's global pool,
        // which a sequential walk must not (one idle thread per core).
        let threads = if par.is_parallel() {
            rayon::current_num_threads()
        } else {
            1
        };
        let mut task = Task::new(query);
        let mut out = query.out();
        let seed_target = if threads > 1 {
            SEEDS_PER_THREAD * threads
        } else {
            1
        };
        dispatch(StartOp {
            task: &mut task,
            seeds: &mut ws.seeds,
            stack: &mut ws.stack,
            seed_target,
        });
        let split = threads > 1 && !ws.seeds.is_empty();
        if split {
            let grain = ws.grain;
            let seeds = &ws.seeds[..];
            let (counters, fitted, part) = (0..seeds.len().div_ceil(grain))
                .into_par_iter()
                .fold(
                    || (Task::new(query), Box::new(query.out()), Vec::new()),
                    |(mut task, mut out, mut stack), t| {
                        let end = ((t + 1) * grain).min(seeds.len());
                        dispatch(WalkOp {
                            task: &mut task,
                            seeds: &seeds[t * grain..end],
                            stack: &mut stack,
                            out: &mut out,
                        });
                        (task, out, stack)
                    },
                )
                .map(|(task, out, _)| (task.counters, task.fitted, out))
                .reduce(
                    || (Default::default(), [0; 2], Box::new(query.out())),
                    |(ca, fa, mut oa), (cb, fb, ob)| {
                        query.merge(&mut oa, *ob);
                        (ca + cb, [fa[0] + fb[0], fa[1] + fb[1]], oa)
                    },
                );
            task.counters += counters;
            task.fitted = [task.fitted[0] + fitted[0], task.fitted[1] + fitted[1]];
            query.merge(&mut out, *part);
        } else {
            dispatch(WalkOp {
                task: &mut task,
                seeds: &ws.seeds,
                stack: &mut ws.stack,
                out: &mut out,
            });
        }
        finish(task, out, split)
    })
}

/// The query's leaf action on each of `pairs` (overlapping leaf pairs, e.g. from a broad
/// phase), in order, on the threads `par` names.
pub(crate) fn leaf_pairs<Q: Query>(query: &Q, pairs: &[[u32; 2]], par: Par) -> Walked<Q::Out> {
    let run = |chunk: &[[u32; 2]]| {
        let mut task = Task::new(query);
        let mut out = query.out();
        dispatch(LeafOp {
            task: &mut task,
            pairs: chunk,
            out: &mut out,
        });
        finish(task, out, false)
    };
    if !par.is_parallel() {
        return run(pairs);
    }
    par.install(|| {
        pairs.par_chunks(LEAF_PAIRS_PER_TASK).map(run).reduce(
            || finish(Task::new(query), query.out(), false),
            |mut a, b| {
                query.merge(&mut a.out, b.out);
                a.counters += b.counters;
                a.fitted = [a.fitted[0] + b.fitted[0], a.fitted[1] + b.fitted[1]];
                a
            },
        )
    })
}

fn finish<Q: Query>(task: Task<'_, Q>, out: Q::Out, split: bool) -> Walked<Q::Out> {
    let mut counters = task.counters;
    counters.bv_updates = task.fitted[0] + task.fitted[1];
    Walked {
        out,
        counters,
        fitted: task.fitted,
        split,
    }
}

/// `op` on the runtime-detected backend ([`dhcd_kernels::arch`]). Not inlined, so the
/// scalar backend's copy of each operation (which `Arch::dispatch` inlines) is compiled once,
/// not at every call site.
#[inline(never)]
fn dispatch<Op: WithSimd>(op: Op) -> Op::Output {
    dhcd_kernels::arch().dispatch(op)
}

/// The calling thread's part of a walk: the root's test, then a breadth-first expansion
/// until `seed_target` pairs are waiting (left in `seeds`; 1: the root alone). Leaf pairs
/// met on the way wait too: the walk tasks run their leaf action.
struct StartOp<'w, 'q, Q: Query> {
    task: &'w mut Task<'q, Q>,
    seeds: &'w mut Vec<[u32; 2]>,
    stack: &'w mut Vec<[u32; 2]>,
    seed_target: usize,
}

impl<Q: Query> WithSimd for StartOp<'_, '_, Q> {
    type Output = ();
    #[inline(always)]
    fn with_simd<S: Simd>(self, simd: S) {
        self.seeds.clear();
        let Some(root) = self.task.root(simd) else {
            return;
        };
        self.seeds.push(root);
        let mut next = std::mem::take(self.stack);
        let mut split = true;
        while split && !self.seeds.is_empty() && self.seeds.len() < self.seed_target {
            next.clear();
            split = false;
            for &pair in self.seeds.iter() {
                if self.task.split(simd, pair, &mut next) {
                    split = true;
                } else {
                    next.push(pair);
                }
            }
            std::mem::swap(self.seeds, &mut next);
        }
        *self.stack = next;
    }
}

/// One walk task: depth-first from each of its seeds.
struct WalkOp<'w, 'q, Q: Query> {
    task: &'w mut Task<'q, Q>,
    seeds: &'w [[u32; 2]],
    stack: &'w mut Vec<[u32; 2]>,
    out: &'w mut Q::Out,
}

impl<Q: Query> WithSimd for WalkOp<'_, '_, Q> {
    type Output = ();
    #[inline(always)]
    fn with_simd<S: Simd>(self, simd: S) {
        for &seed in self.seeds {
            self.stack.clear();
            self.stack.push(seed);
            // PERF (compile time): the one place the walk engine (the split, the query's
            // group fetch, node test and leaf action inlined) is instantiated per backend.
            self.task.descend(simd, self.stack, self.out);
            if self.task.query.stopped(false) {
                return;
            }
        }
    }
}

/// The leaf action on given leaf pairs ([`leaf_pairs`]).
struct LeafOp<'w, 'q, Q: Query> {
    task: &'w mut Task<'q, Q>,
    pairs: &'w [[u32; 2]],
    out: &'w mut Q::Out,
}

impl<Q: Query> WithSimd for LeafOp<'_, '_, Q> {
    type Output = ();
    #[inline(always)]
    fn with_simd<S: Simd>(self, simd: S) {
        let q = self.task.query;
        for (k, &[x, y]) in self.pairs.iter().enumerate() {
            q.leaf_pair(
                simd,
                x as usize,
                y as usize,
                &mut self.task.counters,
                self.out,
            );
            if q.stopped((k + 1) % POLL_EVERY as usize == 0) {
                return;
            }
        }
    }
}
