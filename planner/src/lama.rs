//! The default search, after LAMA (Richter and Westphal 2010): lazy greedy
//! search with h_FF and the landmark-count heuristic and preferred
//! operators finds a first plan; then, within an effort budget, restarts
//! improve it: lazy greedy search with costs counted plus one (on tasks
//! with costs), then lazy weighted A* with weights 5, 3, 2 and 1 (the last
//! repeated), each under the cost bound of the best plan so far. A
//! weighted A* search that exhausts its space under the bound proves that
//! no cheaper plan exists, and ends the search. Every plan found goes
//! through action elimination ([`crate::improve`]) before it sets the
//! bound.
//!
//! The budget counts work ([`crate::lazy::Counts::work`]: relaxed-task
//! sizes of the evaluations, state sizes of the states visited), not time,
//! so the outcome is the same on every machine and every run; `timeout`
//! can only cut it shorter.

use crate::heuristic::{Costs, Evaluator, Heuristic};
use crate::landmarks::LandmarkGraph;
use crate::lazy::{Config, Counts, Lazy, Limits, Outcome};
use crate::lmcount::LmCount;
use crate::options::{SearchResult, SearchStats};
use crate::space::Successors;
use crate::task::Task;
use std::time::Instant;

/// The weights of the weighted A* restarts; the last is repeated.
const WEIGHTS: [u64; 4] = [5, 3, 2, 1];

/// The restarts may spend this many times the first search's work on top
/// of the base budget.
pub const RELATIVE: u64 = 4;

/// What the anytime phase did, for the statistics.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Anytime {
    /// Searches run, the first included.
    pub iterations: usize,
    /// The cost of the first plan (after action elimination).
    pub first_cost: Option<u64>,
    /// Whether a search proved the plan optimal.
    pub proved_optimal: bool,
}

/// Plans with the LAMA configuration; the restarts may spend `improve`
/// work ([`crate::lazy::Counts::work`]) plus [`RELATIVE`] times the first
/// search's; `improve` 0 stops at the first plan.
pub fn plan(
    task: &Task,
    improve: u64,
    deadline: Option<Instant>,
    stats: &mut SearchStats,
) -> (SearchResult, Anytime) {
    let succ = Successors::new(task);
    let graph = LandmarkGraph::generate(task);
    // On tasks without costs, every search counts each action as 1; on
    // the others, the first search does (it wants any plan, fast), later
    // ones count costs plus one.
    let later = if task.unit_cost {
        Costs::Unit
    } else {
        Costs::PlusOne
    };
    let lm_unit = LmCount::new(&graph, Costs::Unit);
    let lm_later = LmCount::new(&graph, later);
    let mut ff_unit = Evaluator::with_costs(task, Heuristic::Ff, Costs::Unit);
    let mut ff_later =
        (later != Costs::Unit).then(|| Evaluator::with_costs(task, Heuristic::Ff, later));
    let mut counts = Counts::default();
    let mut anytime = Anytime::default();
    let limits = Limits {
        deadline,
        work: None,
    };
    let greedy = Config {
        weight: None,
        reopen: false,
        bound: None,
    };
    anytime.iterations += 1;
    let first = Lazy {
        task,
        succ: &succ,
        ff: &mut ff_unit,
        lm: Some(&lm_unit),
    }
    .run(greedy, limits, &mut counts);
    let mut best = match first {
        Outcome::Plan(ops, _) => shorten(task, ops),
        Outcome::Exhausted => return finish(SearchResult::Unsolvable, anytime, counts, stats),
        Outcome::Stopped => return finish(SearchResult::Timeout, anytime, counts, stats),
    };
    anytime.first_cost = Some(best.1);
    // Larger tasks get more: the first search's work, several times over.
    let improve = if improve == 0 {
        0
    } else {
        improve.saturating_add(counts.work.saturating_mul(RELATIVE))
    };
    let spent_before = counts.work;
    // The restarts: (weight, reopen), greedy first on tasks with costs.
    let mut schedule: Vec<Option<u64>> = Vec::new();
    if !task.unit_cost {
        schedule.push(None);
    }
    schedule.extend(WEIGHTS.iter().map(|&w| Some(w)));
    let mut next = 0;
    while best.1 > 0 {
        let left = improve.saturating_sub(counts.work - spent_before);
        if left == 0 {
            break;
        }
        let last = next + 1 >= schedule.len();
        let weight = schedule[next.min(schedule.len() - 1)];
        next += 1;
        // A restart that stalls must leave the later ones half the budget.
        let share = if last { left } else { left.div_ceil(2) };
        let cfg = Config {
            weight,
            reopen: weight.is_some(),
            bound: Some(best.1),
        };
        let limits = Limits {
            deadline,
            work: Some(share),
        };
        let (ff, lm) = match &mut ff_later {
            Some(ff) => (ff, &lm_later),
            None => (&mut ff_unit, &lm_unit),
        };
        anytime.iterations += 1;
        let outcome = Lazy {
            task,
            succ: &succ,
            ff,
            lm: Some(lm),
        }
        .run(cfg, limits, &mut counts);
        match outcome {
            Outcome::Plan(ops, _) => {
                let p = shorten(task, ops);
                if p.1 < best.1 {
                    best = p;
                }
            }
            // Weighted A* prunes only by cost: nothing cheaper exists.
            Outcome::Exhausted if cfg.reopen => {
                anytime.proved_optimal = true;
                break;
            }
            Outcome::Exhausted => {}
            Outcome::Stopped if last => break,
            Outcome::Stopped => {}
        }
    }
    if best.1 == 0 {
        anytime.proved_optimal = true;
    }
    finish(SearchResult::Plan(best.0, best.1), anytime, counts, stats)
}

/// A plan after action elimination, with its cost.
fn shorten(task: &Task, ops: Vec<u32>) -> (Vec<u32>, u64) {
    let ops = crate::improve::eliminate_redundant(task, ops);
    let cost = ops.iter().map(|&o| task.operators[o as usize].cost).sum();
    (ops, cost)
}

fn finish(
    r: SearchResult,
    anytime: Anytime,
    counts: Counts,
    stats: &mut SearchStats,
) -> (SearchResult, Anytime) {
    stats.expanded += counts.expanded;
    stats.generated += counts.generated;
    stats.evaluated += counts.evaluated;
    stats.work += counts.work;
    (r, anytime)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::test_util::rooms;

    #[test]
    fn restarts_improve_the_first_plan_to_the_optimum_and_prove_it() {
        let t = rooms();
        let mut stats = SearchStats::default();
        let (r, any) = plan(&t, u64::MAX, None, &mut stats);
        assert_eq!(r, SearchResult::Plan(r_ops(&r), 3));
        assert!(any.proved_optimal);
        assert!(any.iterations >= 2);
        assert!(any.first_cost.is_some_and(|c| c >= 3));
        // Without a budget only the first search runs.
        let (r0, any0) = plan(&t, 0, None, &mut stats);
        assert!(matches!(r0, SearchResult::Plan(..)));
        assert_eq!(any0.iterations, 1);
    }

    fn r_ops(r: &SearchResult) -> Vec<u32> {
        match r {
            SearchResult::Plan(ops, _) => ops.clone(),
            _ => Vec::new(),
        }
    }
}
