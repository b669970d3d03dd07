//! Lazy best-first search as in LAMA: a state is evaluated when it is
//! taken from the open lists, not when it is generated, and its successors
//! go in with its own heuristic values (so most generated states are never
//! evaluated). The open lists are those of LAMA: one per heuristic (h_FF and
//! landmark count) with every successor, one per heuristic with the
//! successors by preferred operators (h_FF's), taken in turn by priority;
//! whenever a heuristic reaches a new best value the preferred lists get
//! 1000 turns ahead. Ties go first in, first out: the search is
//! deterministic.
//!
//! Greedy search orders by h; weighted A* by g + w * h, reopening a state
//! reached again more cheaply. With a cost bound, successors whose cost
//! reaches it are not generated: what the search finds is cheaper.

use crate::heuristic::Evaluator;
use crate::lmcount::LmCount;
use crate::space::{Registry, Successors};
use crate::task::{AxiomScratch, Task};
use std::cmp::Reverse;
use std::collections::BinaryHeap;
use std::time::Instant;

/// How preferred lists are boosted when a heuristic improves (Fast
/// Downward's and LAMA's value).
const BOOST: i64 = 1000;

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Config {
    /// `None`: greedy (order by h); `Some(w)`: weighted A* (g + w * h).
    pub weight: Option<u64>,
    /// Reach closed states again when a cheaper path is found.
    pub reopen: bool,
    /// Only plans cheaper than this.
    pub bound: Option<u64>,
}

/// When a search must stop short of an answer.
#[derive(Clone, Copy, Debug, Default)]
pub struct Limits {
    pub deadline: Option<Instant>,
    /// At most this much work (see [`Counts::work`]).
    pub work: Option<u64>,
}

#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Outcome {
    /// Operator indexes and their total (real) cost.
    Plan(Vec<u32>, u64),
    /// No plan (within the bound) in the reachable space.
    Exhausted,
    /// A limit stopped the search.
    Stopped,
}

#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Counts {
    pub expanded: usize,
    pub generated: usize,
    pub evaluated: usize,
    /// A deterministic measure of the time spent, about proportional to
    /// it: the size of the relaxed task per evaluation, the size of a
    /// state per state taken from the open lists, a little per successor.
    pub work: u64,
}

struct Node {
    parent: u32,
    op: u32,
    g: u64,
    dead: bool,
}

/// Keys below this go in buckets; larger ones (large action costs under
/// weighted A*) in a heap.
const BUCKETS: u64 = 1 << 16;

/// An open list of successors `(parent, op)` by key, first in first out
/// among equal keys: buckets for small keys (constant time, as Fast
/// Downward's bucket lists), a heap for the rest.
#[derive(Default)]
struct Open {
    buckets: Vec<std::collections::VecDeque<(u32, u32)>>,
    /// No bucket below this is non-empty.
    low: usize,
    in_buckets: usize,
    heap: BinaryHeap<Reverse<(u64, u64, u32, u32)>>,
    counter: u64,
}

impl Open {
    fn is_empty(&self) -> bool {
        self.in_buckets == 0 && self.heap.is_empty()
    }

    fn push(&mut self, key: u64, parent: u32, op: u32) {
        if key < BUCKETS {
            let k = key as usize;
            if self.buckets.len() <= k {
                self.buckets.resize_with(k + 1, Default::default);
            }
            self.buckets[k].push_back((parent, op));
            self.low = self.low.min(k);
            self.in_buckets += 1;
        } else {
            self.counter += 1;
            self.heap.push(Reverse((key, self.counter, parent, op)));
        }
    }

    fn pop(&mut self) -> Option<(u32, u32)> {
        if self.in_buckets > 0 {
            while self.buckets[self.low].is_empty() {
                self.low += 1;
            }
            self.in_buckets -= 1;
            return self.buckets[self.low].pop_front();
        }
        self.heap.pop().map(|Reverse((_, _, p, o))| (p, o))
    }
}

const NO_STATE: u32 = u32::MAX;

/// One lazy search over a task, with the evaluators it uses.
pub struct Lazy<'a> {
    pub task: &'a Task,
    pub succ: &'a Successors,
    pub ff: &'a mut Evaluator,
    pub lm: Option<&'a LmCount<'a>>,
}

impl Lazy<'_> {
    pub fn run(&mut self, cfg: Config, limits: Limits, counts: &mut Counts) -> Outcome {
        let task = self.task;
        let lm_words = self.lm.map_or(0, |l| l.words());
        let mut reg = Registry::new(task.words);
        let mut nodes: Vec<Node> = Vec::new();
        // The reached landmarks of each registered state.
        let mut reached: Vec<u64> = Vec::new();
        let mut queues: [Open; 4] = Default::default();
        let mut prio = [0i64; 4];
        let mut best = [u64::MAX; 2];
        queues[0].push(0, NO_STATE, NO_STATE);
        let mut ax = AxiomScratch::default();
        let (mut state, mut app, mut lm_now) = (Vec::new(), Vec::new(), Vec::new());
        let mut preferred = vec![false; task.operators.len()];
        let work_at_start = counts.work;
        let eval_work = self.ff.work();
        let landmarks = self.lm.map_or(0, |l| l.len()) as u64;
        let pop_work = 40 + 2 * (task.words + lm_words) as u64 + landmarks / 2;
        let mut pops = 0u64;
        loop {
            // The clock is read on the first pop (a limit already passed
            // stops before any work) and every 256th after.
            if pops.is_multiple_of(256) && limits.deadline.is_some_and(|d| Instant::now() >= d) {
                return Outcome::Stopped;
            }
            pops += 1;
            if limits
                .work
                .is_some_and(|n| counts.work - work_at_start >= n)
            {
                return Outcome::Stopped;
            }
            // The non-empty list with the lowest priority, the first on ties.
            let Some(q) = (0..4)
                .filter(|&q| !queues[q].is_empty())
                .min_by_key(|&q| prio[q])
            else {
                return Outcome::Exhausted;
            };
            let Some((parent, op)) = queues[q].pop() else {
                return Outcome::Exhausted;
            };
            prio[q] += 1;
            counts.work += pop_work;
            let g = if parent == NO_STATE {
                state.clear();
                state.extend_from_slice(&task.init);
                0
            } else {
                let o = &task.operators[op as usize];
                task.apply(o, reg.get(parent), &mut state, &mut ax);
                nodes[parent as usize].g + o.cost
            };
            if cfg.bound.is_some_and(|b| g >= b) {
                continue;
            }
            let (sid, new) = reg.insert(&state);
            if let Some(lm) = self.lm {
                if parent == NO_STATE {
                    lm.initial(&state, &mut lm_now);
                } else {
                    let p = parent as usize * lm_words;
                    lm.progress(&reached[p..p + lm_words], &state, &mut lm_now);
                }
                if new {
                    reached.extend_from_slice(&lm_now);
                } else {
                    // Reached along every path seen.
                    let at = sid as usize * lm_words;
                    for (r, n) in reached[at..at + lm_words].iter_mut().zip(&lm_now) {
                        *r &= n;
                    }
                }
            }
            if new {
                nodes.push(Node {
                    parent,
                    op,
                    g,
                    dead: false,
                });
            } else {
                let n = &mut nodes[sid as usize];
                if n.dead || !(cfg.reopen && g < n.g) {
                    continue;
                }
                n.g = g;
                n.parent = parent;
                n.op = op;
            }
            counts.evaluated += 1;
            counts.work += eval_work;
            let Some(h_ff) = self.ff.eval(task, &state) else {
                nodes[sid as usize].dead = true;
                continue;
            };
            let h_lm = self.lm.map(|lm| {
                let at = sid as usize * lm_words;
                lm.value(&reached[at..at + lm_words], &state)
            });
            if task.is_goal(&state) {
                return Outcome::Plan(plan_to(&nodes, sid), g);
            }
            counts.expanded += 1;
            let mut improved = false;
            for (b, h) in best.iter_mut().zip([Some(h_ff), h_lm]) {
                if let Some(h) = h {
                    if h < *b {
                        *b = h;
                        improved = true;
                    }
                }
            }
            if improved {
                prio[2] -= BOOST;
                prio[3] -= BOOST;
            }
            for &o in &self.ff.preferred {
                preferred[o as usize] = true;
            }
            let key = |h: u64, succ_g: u64| match cfg.weight {
                None => h,
                Some(w) => succ_g.saturating_add(w.saturating_mul(h)),
            };
            self.succ.applicable(task, &state, &mut app);
            for &o in &app {
                let succ_g = g + task.operators[o as usize].cost;
                if cfg.bound.is_some_and(|b| succ_g >= b) {
                    continue;
                }
                counts.generated += 1;
                counts.work += 4;
                let pref = preferred[o as usize];
                let k_ff = key(h_ff, succ_g);
                queues[0].push(k_ff, sid, o);
                if pref {
                    queues[2].push(k_ff, sid, o);
                }
                if let Some(h) = h_lm {
                    let k_lm = key(h, succ_g);
                    queues[1].push(k_lm, sid, o);
                    if pref {
                        queues[3].push(k_lm, sid, o);
                    }
                }
            }
            for &o in &self.ff.preferred {
                preferred[o as usize] = false;
            }
        }
    }
}

fn plan_to(nodes: &[Node], mut id: u32) -> Vec<u32> {
    let mut plan = Vec::new();
    while nodes[id as usize].parent != NO_STATE {
        plan.push(nodes[id as usize].op);
        id = nodes[id as usize].parent;
    }
    plan.reverse();
    plan
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_open_list_pops_by_key_first_in_first_out() {
        let mut o = Open::default();
        o.push(5, 1, 0);
        o.push(BUCKETS + 7, 2, 0);
        o.push(2, 3, 0);
        o.push(5, 4, 0);
        o.push(BUCKETS + 1, 5, 0);
        let order: Vec<u32> = std::iter::from_fn(|| o.pop()).map(|(p, _)| p).collect();
        assert_eq!(order, [3, 1, 4, 5, 2]);
        assert!(o.is_empty());
        o.push(9, 6, 0);
        o.push(1, 7, 0);
        assert_eq!(o.pop(), Some((7, 0)));
    }
    use crate::heuristic::{Costs, Heuristic};
    use crate::landmarks::LandmarkGraph;
    use crate::test_util::rooms;

    #[test]
    fn greedy_and_weighted_searches_find_plans_and_respect_the_bound() {
        let t = rooms();
        let succ = Successors::new(&t);
        let graph = LandmarkGraph::generate(&t);
        let lm = LmCount::new(&graph, Costs::Unit);
        let mut ff = Evaluator::with_costs(&t, Heuristic::Ff, Costs::Unit);
        let mut search = Lazy {
            task: &t,
            succ: &succ,
            ff: &mut ff,
            lm: Some(&lm),
        };
        let mut counts = Counts::default();
        let greedy = Config {
            weight: None,
            reopen: false,
            bound: None,
        };
        let Outcome::Plan(plan, cost) = search.run(greedy, Limits::default(), &mut counts) else {
            panic!("no plan");
        };
        assert_eq!(plan.len() as u64, cost);
        assert!(cost >= 3, "the optimum is 3");
        // Weighted A* with w = 1 under the bound of the optimum finds
        // nothing: the space is exhausted.
        let astar = Config {
            weight: Some(1),
            reopen: true,
            bound: Some(3),
        };
        assert_eq!(
            search.run(astar, Limits::default(), &mut counts),
            Outcome::Exhausted
        );
        let astar = Config {
            bound: Some(4),
            ..astar
        };
        assert!(matches!(
            search.run(astar, Limits::default(), &mut counts),
            Outcome::Plan(p, 3) if p.len() == 3
        ));
        let limits = Limits {
            work: Some(0),
            ..Limits::default()
        };
        assert_eq!(search.run(greedy, limits, &mut counts), Outcome::Stopped);
        assert!(counts.evaluated > 0 && counts.expanded > 0 && counts.generated > 0);
        assert!(counts.work > counts.evaluated as u64);
    }
}
