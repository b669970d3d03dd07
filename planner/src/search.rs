//! Heuristic search over packed states: eager greedy best-first search
//! (with a second open list for preferred operators when the heuristic
//! gives them) and A* (reopening states reached more cheaply).

use crate::heuristic::{Evaluator, Heuristic};
use crate::task::{holds, test, AxiomScratch, Task};
use hashbrown::HashTable;
use std::cmp::Reverse;
use std::collections::BinaryHeap;
use std::hash::BuildHasher;
use std::time::{Duration, Instant};

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Algorithm {
    /// LAMA's search: lazy greedy search with h_FF, landmarks and preferred
    /// operators, then restarts that improve the plan within
    /// [`Options::improve`] ([`crate::lama`]). The heuristic option is not
    /// used.
    Lama,
    /// Eager greedy best-first search: fast, not necessarily optimal.
    Gbfs,
    /// A*: optimal with an admissible heuristic.
    Astar,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Options {
    pub algorithm: Algorithm,
    pub heuristic: Heuristic,
    /// Stop after this long (with `Lama`, the best plan found by then is
    /// the answer).
    pub timeout: Option<Duration>,
    /// `Lama`: the work the restarts may spend improving the first plan
    /// ([`crate::lazy::Counts::work`]: about the facts, relaxed operators
    /// and state words visited).
    /// A measure of work rather than time keeps the plan the same on every
    /// machine; 0 stops at the first plan.
    pub improve: u64,
}

/// The default base budget of the restarts (plus four times the first
/// search's work): a tenth to a third of a second, see docs/planner.md. Enough
/// for the restarts to match or beat lama-first's costs on the corpus and
/// the held-out problems (barman/p02 needs it: 106 with 10M or 20M, 94
/// with 30M).
pub const DEFAULT_IMPROVE: u64 = 30_000_000;

impl Default for Options {
    fn default() -> Self {
        Options {
            algorithm: Algorithm::Lama,
            heuristic: Heuristic::Ff,
            timeout: None,
            improve: DEFAULT_IMPROVE,
        }
    }
}

#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct SearchStats {
    /// The heuristic used (LM-cut falls back to h_max where it does not apply).
    pub heuristic: Option<Heuristic>,
    pub expanded: usize,
    pub generated: usize,
    pub evaluated: usize,
    pub time: Duration,
    /// `Lama`: searches run, the cost of the first plan, and whether a
    /// search proved the last plan optimal.
    pub iterations: usize,
    pub first_cost: Option<u64>,
    pub proved_optimal: bool,
    /// `Lama`: the work done ([`crate::lazy::Counts::work`]).
    pub work: u64,
}

#[derive(Clone, Debug, PartialEq, Eq)]
pub enum SearchResult {
    /// Operator indexes, in order, and their total cost.
    Plan(Vec<u32>, u64),
    /// The search space is exhausted (or the relaxation proves it).
    Unsolvable,
    Timeout,
}

/// The applicable operators of a state, found through one trigger fact per
/// operator instead of a scan of all operators.
pub struct Successors {
    by_fact: Vec<Vec<u32>>,
    always: Vec<u32>,
}

impl Successors {
    pub fn new(task: &Task) -> Successors {
        let mut by_fact = vec![Vec::new(); task.num_facts()];
        let mut always = Vec::new();
        for (i, o) in task.operators.iter().enumerate() {
            // Prefer a condition that is false initially: it is more often
            // false, so the operator is looked at less often.
            let pos = o.pre.iter().filter(|l| l.positive);
            let trigger = pos
                .clone()
                .find(|l| !test(&task.init, l.fact))
                .or_else(|| pos.clone().next());
            match trigger {
                Some(l) => by_fact[l.fact as usize].push(i as u32),
                None => always.push(i as u32),
            }
        }
        Successors { by_fact, always }
    }

    pub fn applicable(&self, task: &Task, s: &[u64], out: &mut Vec<u32>) {
        out.clear();
        for &o in &self.always {
            if holds(s, &task.operators[o as usize].pre) {
                out.push(o);
            }
        }
        for (w, &word) in s.iter().enumerate() {
            let mut bits = word;
            while bits != 0 {
                let f = w * 64 + bits.trailing_zeros() as usize;
                bits &= bits - 1;
                if let Some(ops) = self.by_fact.get(f) {
                    for &o in ops {
                        if holds(s, &task.operators[o as usize].pre) {
                            out.push(o);
                        }
                    }
                }
            }
        }
    }
}

/// States stored once in an arena, found by hash.
pub(crate) struct Registry {
    words: usize,
    arena: Vec<u64>,
    table: HashTable<u32>,
    hasher: rustc_hash::FxBuildHasher,
}

impl Registry {
    pub(crate) fn new(words: usize) -> Registry {
        Registry {
            words,
            arena: Vec::new(),
            table: HashTable::new(),
            hasher: rustc_hash::FxBuildHasher,
        }
    }

    pub(crate) fn get(&self, id: u32) -> &[u64] {
        let i = id as usize * self.words;
        &self.arena[i..i + self.words]
    }

    fn hash(&self, s: &[u64]) -> u64 {
        self.hasher.hash_one(s)
    }

    /// The state's id, and whether it is new.
    pub(crate) fn insert(&mut self, s: &[u64]) -> (u32, bool) {
        let h = self.hash(s);
        let (arena, words) = (&self.arena, self.words);
        let at = |id: u32| &arena[id as usize * words..(id as usize + 1) * words];
        if let Some(&id) = self.table.find(h, |&id| at(id) == s) {
            return (id, false);
        }
        let id = (self.arena.len() / self.words) as u32;
        self.arena.extend_from_slice(s);
        let (arena, hasher) = (&self.arena, &self.hasher);
        self.table.insert_unique(h, id, |&id| {
            hasher.hash_one(&arena[id as usize * words..(id as usize + 1) * words])
        });
        (id, true)
    }
}

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
    fn the_registry_stores_each_state_once() {
        let mut r = Registry::new(2);
        assert_eq!(r.insert(&[1, 2]), (0, true));
        assert_eq!(r.insert(&[3, 4]), (1, true));
        assert_eq!(r.insert(&[1, 2]), (0, false));
        assert_eq!(r.get(1), &[3, 4]);
    }

    #[test]
    fn successors_are_the_applicable_operators() {
        let t = rooms();
        let succ = Successors::new(&t);
        let mut ax = AxiomScratch::default();
        let (mut s, mut next, mut app) = (t.init.clone(), Vec::new(), Vec::new());
        for _ in 0..3 {
            succ.applicable(&t, &s, &mut app);
            app.sort_unstable();
            let scan: Vec<u32> = (0..t.operators.len() as u32)
                .filter(|&o| holds(&s, &t.operators[o as usize].pre))
                .collect();
            assert_eq!(app, scan);
            let Some(&o) = app.first() else { break };
            t.apply(&t.operators[o as usize], &s, &mut next, &mut ax);
            std::mem::swap(&mut s, &mut next);
        }
    }

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
