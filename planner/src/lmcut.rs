//! The LM-cut heuristic (Helmert and Domshlak 2009): repeatedly compute
//! h_max, cut the justification graph between the state and the goal zone,
//! add the cheapest cut operator's cost and take it off every cut operator.
//! Admissible, and much more informed than h_max. It needs operators whose
//! effects are unconditional and no axioms; on other tasks the evaluator
//! uses h_max instead ([`LmCut::supports`]).

use crate::task::{test, Lit, Task};
use std::cmp::Reverse;
use std::collections::BinaryHeap;

const INF: u64 = u64::MAX / 4;

struct Op {
    pre: Vec<u32>,
    eff: Vec<u32>,
    cost: u64,
}

pub struct LmCut {
    ops: Vec<Op>,
    pre_of: Vec<Vec<u32>>,
    eff_of: Vec<Vec<u32>>,
    /// Facts with complements (complement `i` is fact `nf0 + i`).
    complements: Vec<u32>,
    nf0: usize,
    /// Always true; the precondition of operators without one.
    truth: u32,
    /// Reached by the goal operator (the last one).
    goal: u32,
    // scratch
    fact_cost: Vec<u64>,
    op_cost: Vec<u64>,
    unsat: Vec<u32>,
    pcf: Vec<u32>,
    heap: BinaryHeap<Reverse<(u64, u32)>>,
    zone: Vec<bool>,
    reached: Vec<bool>,
    by_pcf: Vec<Vec<u32>>,
    cut: Vec<u32>,
    in_cut: Vec<bool>,
    stack: Vec<u32>,
}

impl LmCut {
    /// Whether LM-cut applies: no conditional effects, no axioms.
    pub fn supports(task: &Task) -> bool {
        task.axioms.is_empty()
            && task
                .operators
                .iter()
                .all(|o| o.effects.iter().all(|e| e.cond.is_empty()))
    }

    pub fn new(task: &Task) -> LmCut {
        let nf0 = task.num_facts();
        let mut comp = vec![u32::MAX; nf0];
        let mut complements = Vec::new();
        {
            let mut need = |l: &Lit| {
                if !l.positive && comp[l.fact as usize] == u32::MAX {
                    comp[l.fact as usize] = (nf0 + complements.len()) as u32;
                    complements.push(l.fact);
                }
            };
            for o in &task.operators {
                o.pre.iter().for_each(&mut need);
            }
            task.goal.iter().for_each(&mut need);
        }
        let truth = (nf0 + complements.len()) as u32;
        let goal = truth + 1;
        let nf = goal as usize + 1;
        let lits = |ls: &[Lit]| -> Vec<u32> {
            let mut out: Vec<u32> = ls
                .iter()
                .filter_map(|l| {
                    if l.positive {
                        Some(l.fact)
                    } else {
                        (comp[l.fact as usize] != u32::MAX).then(|| comp[l.fact as usize])
                    }
                })
                .collect();
            out.sort_unstable();
            out.dedup();
            if out.is_empty() {
                out.push(truth);
            }
            out
        };
        let mut ops: Vec<Op> = task
            .operators
            .iter()
            .map(|o| {
                let mut eff: Vec<u32> = o
                    .effects
                    .iter()
                    .filter_map(|e| {
                        if e.add {
                            Some(e.fact)
                        } else {
                            (comp[e.fact as usize] != u32::MAX).then(|| comp[e.fact as usize])
                        }
                    })
                    .collect();
                eff.sort_unstable();
                eff.dedup();
                Op {
                    pre: lits(&o.pre),
                    eff,
                    cost: o.cost,
                }
            })
            .collect();
        ops.push(Op {
            pre: lits(&task.goal),
            eff: vec![goal],
            cost: 0,
        });
        let mut pre_of = vec![Vec::new(); nf];
        let mut eff_of = vec![Vec::new(); nf];
        for (i, o) in ops.iter().enumerate() {
            for &p in &o.pre {
                pre_of[p as usize].push(i as u32);
            }
            for &e in &o.eff {
                eff_of[e as usize].push(i as u32);
            }
        }
        let n = ops.len();
        LmCut {
            ops,
            pre_of,
            eff_of,
            complements,
            nf0,
            truth,
            goal,
            fact_cost: vec![INF; nf],
            op_cost: vec![0; n],
            unsat: vec![0; n],
            pcf: vec![u32::MAX; n],
            heap: BinaryHeap::new(),
            zone: vec![false; nf],
            reached: vec![false; nf],
            by_pcf: vec![Vec::new(); nf],
            cut: Vec::new(),
            in_cut: vec![false; n],
            stack: Vec::new(),
        }
    }

    fn state_facts(&self, s: &[u64], out: &mut Vec<u32>) {
        out.clear();
        for (w, &word) in s.iter().enumerate() {
            let mut bits = word;
            while bits != 0 {
                let f = (w * 64) as u32 + bits.trailing_zeros();
                bits &= bits - 1;
                if (f as usize) < self.nf0 {
                    out.push(f);
                }
            }
        }
        for (i, &f) in self.complements.iter().enumerate() {
            if !test(s, f) {
                out.push((self.nf0 + i) as u32);
            }
        }
        out.push(self.truth);
    }

    /// h_max under the current operator costs, recording each operator's
    /// precondition choice (its costliest precondition).
    fn hmax(&mut self, init: &[u32]) {
        self.fact_cost.iter_mut().for_each(|c| *c = INF);
        for (i, o) in self.ops.iter().enumerate() {
            self.unsat[i] = o.pre.len() as u32;
            self.pcf[i] = u32::MAX;
        }
        self.heap.clear();
        for &f in init {
            self.fact_cost[f as usize] = 0;
            self.heap.push(Reverse((0, f)));
        }
        while let Some(Reverse((c, f))) = self.heap.pop() {
            if c > self.fact_cost[f as usize] {
                continue;
            }
            for &oi in &self.pre_of[f as usize] {
                let i = oi as usize;
                self.unsat[i] -= 1;
                if self.unsat[i] == 0 {
                    // Facts pop in order of cost: `f` is the costliest.
                    self.pcf[i] = f;
                    let nc = c + self.op_cost[i];
                    for &e in &self.ops[i].eff {
                        if nc < self.fact_cost[e as usize] {
                            self.fact_cost[e as usize] = nc;
                            self.heap.push(Reverse((nc, e)));
                        }
                    }
                }
            }
        }
    }

    /// Updates h_max after the cut's operators got cheaper: costs only go
    /// down, starting at the cut's effects; an operator whose costliest
    /// precondition got cheaper picks its costliest precondition again.
    fn hmax_after_cut(&mut self) {
        self.heap.clear();
        for &o in &self.cut {
            let i = o as usize;
            let c = self.fact_cost[self.pcf[i] as usize] + self.op_cost[i];
            for &e in &self.ops[i].eff {
                if c < self.fact_cost[e as usize] {
                    self.fact_cost[e as usize] = c;
                    self.heap.push(Reverse((c, e)));
                }
            }
        }
        while let Some(Reverse((c, f))) = self.heap.pop() {
            if c > self.fact_cost[f as usize] {
                continue;
            }
            for &oi in &self.pre_of[f as usize] {
                let i = oi as usize;
                if self.pcf[i] != f {
                    continue;
                }
                let (mut best, mut best_cost) = (f, c);
                for &p in &self.ops[i].pre {
                    if self.fact_cost[p as usize] > best_cost {
                        best = p;
                        best_cost = self.fact_cost[p as usize];
                    }
                }
                self.pcf[i] = best;
                let nc = best_cost + self.op_cost[i];
                for &e in &self.ops[i].eff {
                    if nc < self.fact_cost[e as usize] {
                        self.fact_cost[e as usize] = nc;
                        self.heap.push(Reverse((nc, e)));
                    }
                }
            }
        }
    }

    /// The heuristic value of `s`; `None` for a dead end.
    pub fn eval(&mut self, s: &[u64]) -> Option<u64> {
        for (i, o) in self.ops.iter().enumerate() {
            self.op_cost[i] = o.cost;
        }
        let mut init = Vec::new();
        self.state_facts(s, &mut init);
        self.hmax(&init);
        if self.fact_cost[self.goal as usize] >= INF {
            return None;
        }
        let mut h = 0u64;
        while self.fact_cost[self.goal as usize] > 0 {
            // The goal zone: facts from which the goal is reached through
            // zero-cost operators along their precondition choices.
            self.zone.iter_mut().for_each(|z| *z = false);
            self.zone[self.goal as usize] = true;
            self.stack.clear();
            self.stack.push(self.goal);
            while let Some(f) = self.stack.pop() {
                for &oi in &self.eff_of[f as usize] {
                    let i = oi as usize;
                    let p = self.pcf[i];
                    if p != u32::MAX && self.op_cost[i] == 0 && !self.zone[p as usize] {
                        self.zone[p as usize] = true;
                        self.stack.push(p);
                    }
                }
            }
            // Forward from the state without entering the zone: operators
            // whose choice is reached and that reach into the zone form
            // the cut.
            for v in &mut self.by_pcf {
                v.clear();
            }
            for (i, &p) in self.pcf.iter().enumerate() {
                if p != u32::MAX {
                    self.by_pcf[p as usize].push(i as u32);
                }
            }
            self.reached.iter_mut().for_each(|r| *r = false);
            self.stack.clear();
            for &f in &init {
                if !self.reached[f as usize] {
                    self.reached[f as usize] = true;
                    self.stack.push(f);
                }
            }
            self.cut.clear();
            while let Some(f) = self.stack.pop() {
                for k in 0..self.by_pcf[f as usize].len() {
                    let oi = self.by_pcf[f as usize][k];
                    let i = oi as usize;
                    for &e in &self.ops[i].eff {
                        if self.zone[e as usize] {
                            if !self.in_cut[i] {
                                self.in_cut[i] = true;
                                self.cut.push(oi);
                            }
                        } else if !self.reached[e as usize] {
                            self.reached[e as usize] = true;
                            self.stack.push(e);
                        }
                    }
                }
            }
            let m = self
                .cut
                .iter()
                .map(|&o| self.op_cost[o as usize])
                .min()
                .unwrap_or(0);
            for &o in &self.cut {
                self.op_cost[o as usize] -= m;
                self.in_cut[o as usize] = false;
            }
            if m == 0 {
                // Cannot happen with a consistent h_max; stop rather than loop.
                break;
            }
            h += m;
            self.hmax_after_cut();
        }
        Some(h)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::test_util::{fact, task};

    fn ariac() -> Task {
        task(
            include_str!("../../examples/ariac/domain.pddl"),
            include_str!("../../examples/ariac/problem.pddl"),
        )
    }

    /// The incremental h_max update gives the same values as computing
    /// h_max from scratch with the reduced costs.
    #[test]
    fn incremental_h_max_agrees_with_recomputing() {
        let t = ariac();
        for k in 2..6 {
            let mut h = LmCut::new(&t);
            let mut init = Vec::new();
            h.state_facts(&t.init, &mut init);
            for (i, o) in h.ops.iter().enumerate() {
                h.op_cost[i] = o.cost;
            }
            h.hmax(&init);
            // Every k-th reachable operator gets cheaper, as if in a cut.
            h.cut = (0..h.ops.len() as u32)
                .filter(|&o| (o as usize).is_multiple_of(k) && h.pcf[o as usize] != u32::MAX)
                .collect();
            assert!(!h.cut.is_empty());
            for &o in &h.cut {
                h.op_cost[o as usize] = 0;
            }
            h.hmax_after_cut();
            let incremental = h.fact_cost.clone();
            h.hmax(&init);
            assert_eq!(incremental, h.fact_cost, "every {k}th operator");
        }
    }

    /// Move to the bin, grasp, move to the AGV, place: four landmarks of
    /// cost 1 (each step is needed), where h_max sees only 2.
    #[test]
    fn lm_cut_counts_every_landmark_of_the_ariac_task() {
        let t = ariac();
        assert!(LmCut::supports(&t));
        let mut h = LmCut::new(&t);
        assert_eq!(h.eval(&t.init), Some(4));
        let mut max = crate::heuristic::Evaluator::new(&t, crate::heuristic::Heuristic::Max, false);
        assert_eq!(max.eval(&t, &t.init), Some(3));
    }

    #[test]
    fn goal_states_are_zero_and_dead_ends_none() {
        let t = ariac();
        let mut h = LmCut::new(&t);
        let mut s = t.init.clone();
        for l in &t.goal {
            crate::task::set(&mut s, l.fact);
        }
        assert_eq!(h.eval(&s), Some(0));
        let mut dead = t.init.clone();
        crate::task::clear(
            &mut dead,
            fact(&t, "(is_reachable floor_robot curr_position)"),
        );
        assert_eq!(h.eval(&dead), None);
    }

    #[test]
    fn tasks_with_axioms_or_conditional_effects_are_not_supported() {
        assert!(!LmCut::supports(&crate::test_util::rooms()));
    }
}
