//! Heuristic search over packed states: eager greedy best-first search
//! (with a second open list for preferred operators when the heuristic
//! gives them) and A* (reopening states reached more cheaply).

pub use crate::options::{Algorithm, Options, SearchResult, SearchStats, DEFAULT_IMPROVE};
pub use crate::space::Successors;

use crate::heuristic::{Evaluator, Heuristic};
use crate::space::Registry;
use crate::task::{AxiomScratch, Task};
use std::cmp::Reverse;
use std::collections::BinaryHeap;
use std::time::Instant;

struct Node {
    parent: u32,
    op: u32,
    g: u64,
    h: u64,
    /// The `g` it was expanded with; `u64::MAX` if never.
    expanded_g: u64,
}

pub struct Search<'t> {
    task: &'t Task,
    opts: Options,
    succ: Successors,
    eval: Evaluator,
    reg: Registry,
    nodes: Vec<Node>,
    ax: AxiomScratch,
    pub stats: SearchStats,
}

impl<'t> Search<'t> {
    pub fn new(task: &'t Task, opts: Options) -> Search<'t> {
        let plus_one = opts.algorithm == Algorithm::Gbfs;
        let eval = Evaluator::new(task, opts.heuristic, plus_one);
        Search {
            task,
            opts,
            succ: Successors::new(task),
            stats: SearchStats {
                heuristic: Some(eval.kind()),
                ..SearchStats::default()
            },
            eval,
            reg: Registry::new(task.words),
            nodes: Vec::new(),
            ax: AxiomScratch::default(),
        }
    }

    fn plan_to(&self, mut id: u32) -> Vec<u32> {
        let mut plan = Vec::new();
        while self.nodes[id as usize].parent != u32::MAX {
            plan.push(self.nodes[id as usize].op);
            id = self.nodes[id as usize].parent;
        }
        plan.reverse();
        plan
    }

    pub fn run(&mut self) -> SearchResult {
        let start = Instant::now();
        let r = match self.opts.algorithm {
            Algorithm::Lama => {
                let deadline = self.opts.timeout.map(|t| start + t);
                let (r, any) =
                    crate::lama::plan(self.task, self.opts.improve, deadline, &mut self.stats);
                self.stats.heuristic = None;
                self.stats.iterations = any.iterations;
                self.stats.first_cost = any.first_cost;
                self.stats.proved_optimal = any.proved_optimal;
                r
            }
            Algorithm::Gbfs => self.gbfs(start),
            Algorithm::Astar => self.astar(start),
        };
        self.stats.time = start.elapsed();
        r
    }

    fn timed_out(&self, start: Instant) -> bool {
        self.stats.expanded.is_multiple_of(256)
            && self.opts.timeout.is_some_and(|t| start.elapsed() >= t)
    }

    fn cost_of(&self, plan: &[u32]) -> u64 {
        plan.iter()
            .map(|&o| self.task.operators[o as usize].cost)
            .sum()
    }

    /// Registers the initial state as the search's first node: its id and
    /// heuristic value, `None` when the heuristic finds it a dead end.
    fn root(&mut self) -> Option<(u32, u64)> {
        let init = self.task.init.clone();
        let (root, _) = self.reg.insert(&init);
        self.stats.evaluated += 1;
        let h0 = self.eval.eval(self.task, &init)?;
        self.nodes.push(Node {
            parent: u32::MAX,
            op: u32::MAX,
            g: 0,
            h: h0,
            expanded_g: u64::MAX,
        });
        Some((root, h0))
    }

    fn gbfs(&mut self, start: Instant) -> SearchResult {
        let Some((root, h0)) = self.root() else {
            return SearchResult::Unsolvable;
        };
        let task = self.task;
        let use_pref = self.opts.heuristic == Heuristic::Ff;
        // The preferred operators of each state, from its evaluation.
        let mut prefs: Vec<Box<[u32]>> = vec![self.eval.preferred.as_slice().into()];
        // Two open lists (all successors; successors by preferred
        // operators), picked by priority; progress boosts the preferred one.
        let mut open: [BinaryHeap<Reverse<(u64, u64, u32)>>; 2] =
            [BinaryHeap::new(), BinaryHeap::new()];
        let mut prio = [0i64; 2];
        let mut counter = 0u64;
        open[0].push(Reverse((h0, counter, root)));
        let mut best_h = h0;
        let mut state = Vec::new();
        let mut next = Vec::new();
        let mut app = Vec::new();
        let mut pref: Vec<u32> = Vec::new();
        loop {
            if self.timed_out(start) {
                return SearchResult::Timeout;
            }
            let q = if open[1].is_empty() || (!open[0].is_empty() && prio[0] <= prio[1]) {
                0
            } else {
                1
            };
            let Some(Reverse((_, _, id))) = open[q].pop() else {
                return SearchResult::Unsolvable;
            };
            prio[q] += 1;
            let node = &mut self.nodes[id as usize];
            if node.expanded_g != u64::MAX {
                continue;
            }
            node.expanded_g = node.g;
            let g = node.g;
            state.clear();
            state.extend_from_slice(self.reg.get(id));
            if task.is_goal(&state) {
                let plan = self.plan_to(id);
                let c = self.cost_of(&plan);
                return SearchResult::Plan(plan, c);
            }
            self.stats.expanded += 1;
            if use_pref {
                pref.clear();
                pref.extend_from_slice(&prefs[id as usize]);
            }
            self.succ.applicable(task, &state, &mut app);
            for &o in &app {
                let op = &task.operators[o as usize];
                task.apply(op, &state, &mut next, &mut self.ax);
                self.stats.generated += 1;
                let (sid, new) = self.reg.insert(&next);
                if !new {
                    continue;
                }
                self.stats.evaluated += 1;
                let h = self.eval.eval(task, &next);
                if use_pref {
                    prefs.push(self.eval.preferred.as_slice().into());
                }
                self.nodes.push(Node {
                    parent: id,
                    op: o,
                    g: g + op.cost,
                    h: h.unwrap_or(u64::MAX),
                    expanded_g: if h.is_none() { 0 } else { u64::MAX },
                });
                let Some(h) = h else { continue };
                counter += 1;
                open[0].push(Reverse((h, counter, sid)));
                if use_pref && pref.contains(&o) {
                    open[1].push(Reverse((h, counter, sid)));
                }
                if h < best_h {
                    best_h = h;
                    prio[1] -= 1000;
                }
            }
        }
    }

    fn astar(&mut self, start: Instant) -> SearchResult {
        let Some((root, h0)) = self.root() else {
            return SearchResult::Unsolvable;
        };
        let task = self.task;
        // (f, h, g, id): lowest f, then lowest h.
        let mut open: BinaryHeap<Reverse<(u64, u64, u64, u32)>> = BinaryHeap::new();
        open.push(Reverse((h0, h0, 0, root)));
        let mut state = Vec::new();
        let mut next = Vec::new();
        let mut app = Vec::new();
        while let Some(Reverse((_, _, g, id))) = open.pop() {
            if self.timed_out(start) {
                return SearchResult::Timeout;
            }
            let node = &mut self.nodes[id as usize];
            if g != node.g || node.expanded_g <= g {
                continue;
            }
            node.expanded_g = g;
            state.clear();
            state.extend_from_slice(self.reg.get(id));
            if task.is_goal(&state) {
                let plan = self.plan_to(id);
                return SearchResult::Plan(plan, g);
            }
            self.stats.expanded += 1;
            self.succ.applicable(task, &state, &mut app);
            for &o in &app {
                let op = &task.operators[o as usize];
                task.apply(op, &state, &mut next, &mut self.ax);
                self.stats.generated += 1;
                let ng = g + op.cost;
                let (sid, new) = self.reg.insert(&next);
                let h = if new {
                    self.stats.evaluated += 1;
                    let h = self.eval.eval(task, &next).unwrap_or(u64::MAX);
                    self.nodes.push(Node {
                        parent: id,
                        op: o,
                        g: ng,
                        h,
                        expanded_g: u64::MAX,
                    });
                    h
                } else {
                    let n = &mut self.nodes[sid as usize];
                    if ng >= n.g {
                        continue;
                    }
                    n.g = ng;
                    n.parent = id;
                    n.op = o;
                    n.h
                };
                if h != u64::MAX {
                    open.push(Reverse((ng + h, h, ng, sid)));
                }
            }
        }
        SearchResult::Unsolvable
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::test_util::rooms;

    #[test]
    fn astar_finds_the_cheapest_plan() {
        let t = rooms();
        for heuristic in [Heuristic::Max, Heuristic::Blind] {
            let opts = Options {
                algorithm: Algorithm::Astar,
                heuristic,
                ..Options::default()
            };
            let mut s = Search::new(&t, opts);
            assert!(matches!(s.run(), SearchResult::Plan(p, 3) if p.len() == 3));
        }
    }
}
