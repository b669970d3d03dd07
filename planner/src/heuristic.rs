//! Delete-relaxation heuristics over unary operators (one per add effect,
//! with the effect's condition added to the precondition; axioms are
//! operators of cost 0): h_max (admissible), h_add, h_FF (h_add's best
//! supporters, relaxed plan extraction, preferred operators), and blind.
//! Negative conditions are ignored, as in Fast Downward's relaxation.

use crate::task::{holds, Task};
use std::cmp::Reverse;
use std::collections::BinaryHeap;

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Heuristic {
    /// The FF heuristic: the cost of a relaxed plan.
    Ff,
    /// The additive heuristic.
    Add,
    /// The max heuristic (admissible).
    Max,
    /// 0 in goal states, the cheapest action's cost elsewhere (admissible).
    Blind,
}

const INF: u64 = u64::MAX / 4;

struct UnaryOp {
    pre: Vec<u32>,
    eff: u32,
    cost: u64,
    /// The operator this comes from; `None` for axioms.
    op: Option<u32>,
}

pub struct Evaluator {
    kind: Heuristic,
    ops: Vec<UnaryOp>,
    pre_of: Vec<Vec<u32>>,
    no_pre: Vec<u32>,
    goal: Vec<u32>,
    min_cost: u64,
    // scratch
    cost: Vec<u64>,
    supporter: Vec<u32>,
    unsat: Vec<u32>,
    acc: Vec<u64>,
    heap: BinaryHeap<Reverse<(u64, u32)>>,
    marked: Vec<bool>,
    in_plan: Vec<bool>,
    stack: Vec<u32>,
    /// Operators of the last relaxed plan that apply in the evaluated state.
    pub preferred: Vec<u32>,
}

impl Evaluator {
    /// `unit`: count every operator as cost 1 (greedy search measures
    /// distance in steps); otherwise use the task's costs.
    pub fn new(task: &Task, kind: Heuristic, unit: bool) -> Evaluator {
        let mut ops = Vec::new();
        for (i, o) in task.operators.iter().enumerate() {
            let base: Vec<u32> = o
                .pre
                .iter()
                .filter(|l| l.positive)
                .map(|l| l.fact)
                .collect();
            for e in o.effects.iter().filter(|e| e.add) {
                let mut pre = base.clone();
                pre.extend(e.cond.iter().filter(|l| l.positive).map(|l| l.fact));
                pre.sort_unstable();
                pre.dedup();
                ops.push(UnaryOp {
                    pre,
                    eff: e.fact,
                    cost: if unit { 1 } else { o.cost },
                    op: Some(i as u32),
                });
            }
        }
        for a in &task.axioms {
            let mut pre: Vec<u32> = a
                .body
                .iter()
                .filter(|l| l.positive)
                .map(|l| l.fact)
                .collect();
            pre.sort_unstable();
            pre.dedup();
            ops.push(UnaryOp {
                pre,
                eff: a.head,
                cost: 0,
                op: None,
            });
        }
        let nf = task.num_facts();
        let mut pre_of = vec![Vec::new(); nf];
        let mut no_pre = Vec::new();
        for (i, u) in ops.iter().enumerate() {
            if u.pre.is_empty() {
                no_pre.push(i as u32);
            }
            for &p in &u.pre {
                pre_of[p as usize].push(i as u32);
            }
        }
        let min_cost = task
            .operators
            .iter()
            .map(|o| if unit { 1 } else { o.cost })
            .min()
            .unwrap_or(0);
        let n = ops.len();
        Evaluator {
            kind,
            goal: task
                .goal
                .iter()
                .filter(|l| l.positive)
                .map(|l| l.fact)
                .collect(),
            ops,
            pre_of,
            no_pre,
            min_cost,
            cost: vec![INF; nf],
            supporter: vec![u32::MAX; nf],
            unsat: vec![0; n],
            acc: vec![0; n],
            heap: BinaryHeap::new(),
            marked: vec![false; nf],
            in_plan: vec![false; task.operators.len()],
            stack: Vec::new(),
            preferred: Vec::new(),
        }
    }

    /// The heuristic value of `s`; `None` when the goal is unreachable even
    /// in the relaxation (a dead end).
    pub fn eval(&mut self, task: &Task, s: &[u64]) -> Option<u64> {
        self.preferred.clear();
        if self.kind == Heuristic::Blind {
            return Some(if task.is_goal(s) { 0 } else { self.min_cost });
        }
        let max = self.kind == Heuristic::Max;
        self.cost.iter_mut().for_each(|c| *c = INF);
        for (i, u) in self.ops.iter().enumerate() {
            self.unsat[i] = u.pre.len() as u32;
            self.acc[i] = 0;
        }
        self.heap.clear();
        for (w, &word) in s.iter().enumerate() {
            let mut bits = word;
            while bits != 0 {
                let f = (w * 64) as u32 + bits.trailing_zeros();
                bits &= bits - 1;
                if (f as usize) < self.cost.len() {
                    self.cost[f as usize] = 0;
                    self.supporter[f as usize] = u32::MAX;
                    self.heap.push(Reverse((0, f)));
                }
            }
        }
        for i in 0..self.no_pre.len() {
            let ui = self.no_pre[i];
            let u = &self.ops[ui as usize];
            if u.cost < self.cost[u.eff as usize] {
                self.cost[u.eff as usize] = u.cost;
                self.supporter[u.eff as usize] = ui;
                self.heap.push(Reverse((u.cost, u.eff)));
            }
        }
        while let Some(Reverse((c, f))) = self.heap.pop() {
            if c > self.cost[f as usize] {
                continue;
            }
            for &ui in &self.pre_of[f as usize] {
                let i = ui as usize;
                self.unsat[i] -= 1;
                self.acc[i] = if max {
                    self.acc[i].max(c)
                } else {
                    self.acc[i].saturating_add(c)
                };
                if self.unsat[i] == 0 {
                    let u = &self.ops[i];
                    let nc = self.acc[i].saturating_add(u.cost);
                    if nc < self.cost[u.eff as usize] {
                        self.cost[u.eff as usize] = nc;
                        self.supporter[u.eff as usize] = ui;
                        self.heap.push(Reverse((nc, u.eff)));
                    }
                }
            }
        }
        let mut h = 0u64;
        for &g in &self.goal {
            let c = self.cost[g as usize];
            if c >= INF {
                return None;
            }
            h = if max { h.max(c) } else { h.saturating_add(c) };
        }
        if self.kind != Heuristic::Ff {
            return Some(h);
        }
        // Relaxed plan from the best supporters.
        self.marked.iter_mut().for_each(|m| *m = false);
        let mut plan: Vec<u32> = Vec::new();
        self.stack.clear();
        self.stack.extend(self.goal.iter().copied());
        let mut hff = 0u64;
        while let Some(f) = self.stack.pop() {
            if std::mem::replace(&mut self.marked[f as usize], true) {
                continue;
            }
            let sup = self.supporter[f as usize];
            if sup == u32::MAX {
                continue;
            }
            let u = &self.ops[sup as usize];
            if let Some(o) = u.op {
                if !std::mem::replace(&mut self.in_plan[o as usize], true) {
                    plan.push(o);
                    hff += u.cost;
                }
            }
            self.stack.extend(u.pre.iter().copied());
        }
        for o in plan {
            self.in_plan[o as usize] = false;
            if holds(s, &task.operators[o as usize].pre) {
                self.preferred.push(o);
            }
        }
        Some(hff)
    }
}
