//! Delete-relaxation heuristics over unary operators (one per add effect,
//! with the effect's condition added to the precondition; axioms are
//! operators of cost 0): h_max (admissible), h_add, h_FF (h_add's best
//! supporters, relaxed plan extraction, preferred operators), and blind.
//! Negative conditions are ignored, as in Fast Downward's relaxation.

use crate::task::{holds, Lit, Task};
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
    /// LM-cut (admissible); h_max on tasks with conditional effects or
    /// derived predicates.
    LmCut,
}

/// The action costs a heuristic counts.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Costs {
    /// The task's costs.
    Real,
    /// Each cost plus 1 (LAMA's choice for greedy search on tasks with
    /// costs: it sees costs, and a free action is not free of effort).
    PlusOne,
    /// Every action costs 1.
    Unit,
}

impl Costs {
    pub fn of(self, cost: u64) -> u64 {
        match self {
            Costs::Real => cost,
            Costs::PlusOne => cost + 1,
            Costs::Unit => 1,
        }
    }
}

const INF: u64 = u64::MAX / 4;

/// The open facts of the cost computation: a binary heap, or buckets by
/// cost when every cost is small (such as unit costs).
enum Queue {
    Heap(BinaryHeap<Reverse<(u64, u32)>>),
    /// Buckets, the current one, and one past the highest used.
    Buckets(Vec<Vec<u32>>, usize, usize),
}

impl Queue {
    fn clear(&mut self) {
        match self {
            Queue::Heap(h) => h.clear(),
            Queue::Buckets(b, cur, hi) => {
                b[..*hi].iter_mut().for_each(Vec::clear);
                *cur = 0;
                *hi = 0;
            }
        }
    }

    fn push(&mut self, c: u64, f: u32) {
        match self {
            Queue::Heap(h) => h.push(Reverse((c, f))),
            Queue::Buckets(b, cur, hi) if c >= 1 << 14 => {
                // Too many buckets: continue with a heap.
                let mut h = BinaryHeap::new();
                for (i, fs) in b[..*hi].iter().enumerate().skip(*cur) {
                    h.extend(fs.iter().map(|&f| Reverse((i as u64, f))));
                }
                h.push(Reverse((c, f)));
                *self = Queue::Heap(h);
            }
            Queue::Buckets(b, _, hi) => {
                let c = c as usize;
                if b.len() <= c {
                    b.resize_with(c + 1, Vec::new);
                }
                b[c].push(f);
                *hi = (*hi).max(c + 1);
            }
        }
    }

    fn pop(&mut self) -> Option<(u64, u32)> {
        match self {
            Queue::Heap(h) => h.pop().map(|Reverse(x)| x),
            Queue::Buckets(b, cur, hi) => {
                while *cur < *hi {
                    if let Some(f) = b[*cur].pop() {
                        return Some((*cur as u64, f));
                    }
                    *cur += 1;
                }
                None
            }
        }
    }
}

/// A relaxed operator: an operator's unconditional effects, or its effects
/// under one condition (with the condition added to the precondition), or
/// an axiom. Counting preconditions once for all the effects they share
/// makes an evaluation several times cheaper than one operator per effect.
struct UnaryOp {
    pre: Vec<u32>,
    effs: Vec<u32>,
    cost: u64,
    /// The operator this comes from; `None` for axioms.
    op: Option<u32>,
}

pub struct Evaluator {
    kind: Heuristic,
    lmcut: Option<crate::lmcut::LmCut>,
    ops: Vec<UnaryOp>,
    pre_of: Vec<Vec<u32>>,
    no_pre: Vec<u32>,
    goal: Vec<u32>,
    is_goal: Vec<bool>,
    /// The facts with complements, in complement order (complement `i` is
    /// fact `num_facts + i`).
    complements: Vec<u32>,
    min_cost: u64,
    // scratch
    cost: Vec<u64>,
    supporter: Vec<u32>,
    unsat: Vec<u32>,
    acc: Vec<u64>,
    heap: Queue,
    unsat_init: Vec<u32>,
    marked: Vec<bool>,
    in_plan: Vec<bool>,
    stack: Vec<u32>,
    /// The relaxed plan's operators (kept to reuse its allocation).
    plan: Vec<u32>,
    /// Operators of the last relaxed plan that apply in the evaluated state.
    pub preferred: Vec<u32>,
}

impl Evaluator {
    /// `plus_one`: count every operator as its cost plus 1, as LAMA does
    /// (greedy search then favours short plans, but sees costs and never
    /// takes a free action as no step at all); otherwise use the task's
    /// costs.
    pub fn new(task: &Task, kind: Heuristic, plus_one: bool) -> Evaluator {
        let costs = if plus_one {
            Costs::PlusOne
        } else {
            Costs::Real
        };
        Evaluator::with_costs(task, kind, costs)
    }

    /// An evaluator that counts `costs` (LM-cut always counts the task's).
    pub fn with_costs(task: &Task, kind: Heuristic, costs: Costs) -> Evaluator {
        let lmcut = (kind == Heuristic::LmCut && crate::lmcut::LmCut::supports(task))
            .then(|| crate::lmcut::LmCut::new(task));
        let kind = match kind {
            Heuristic::LmCut if lmcut.is_none() => Heuristic::Max,
            k => k,
        };
        // Facts some condition needs false get a complement fact, true
        // when they are false and made true by the effects that delete
        // them: negative conditions then guide the relaxation too.
        let nf0 = task.num_facts();
        let mut comp = vec![u32::MAX; nf0];
        let mut complements = Vec::new();
        {
            let mut need = |l: &Lit| {
                if !l.positive
                    && !task.derived[l.fact as usize]
                    && comp[l.fact as usize] == u32::MAX
                {
                    comp[l.fact as usize] = (nf0 + complements.len()) as u32;
                    complements.push(l.fact);
                }
            };
            for o in &task.operators {
                o.pre.iter().for_each(&mut need);
                o.effects.iter().flat_map(|e| &e.cond).for_each(&mut need);
            }
            task.axioms.iter().flat_map(|a| &a.body).for_each(&mut need);
            task.goal.iter().for_each(&mut need);
        }
        let lits = |ls: &[Lit], out: &mut Vec<u32>| {
            for l in ls {
                if l.positive {
                    out.push(l.fact);
                } else if comp[l.fact as usize] != u32::MAX {
                    out.push(comp[l.fact as usize]);
                }
            }
        };
        let mut ops = Vec::new();
        for (i, o) in task.operators.iter().enumerate() {
            let mut base = Vec::new();
            lits(&o.pre, &mut base);
            // Effects grouped by condition, the unconditional ones first.
            let mut groups: Vec<(&[Lit], Vec<u32>)> = vec![(&[], Vec::new())];
            for e in &o.effects {
                let eff = if e.add {
                    e.fact
                } else if comp[e.fact as usize] != u32::MAX {
                    comp[e.fact as usize]
                } else {
                    continue;
                };
                match groups.iter_mut().find(|(c, _)| *c == e.cond.as_slice()) {
                    Some((_, effs)) => effs.push(eff),
                    None => groups.push((&e.cond, vec![eff])),
                }
            }
            for (cond, mut effs) in groups {
                if effs.is_empty() {
                    continue;
                }
                effs.sort_unstable();
                effs.dedup();
                let mut pre = base.clone();
                lits(cond, &mut pre);
                pre.sort_unstable();
                pre.dedup();
                ops.push(UnaryOp {
                    pre,
                    effs,
                    cost: costs.of(o.cost),
                    op: Some(i as u32),
                });
            }
        }
        for a in &task.axioms {
            let mut pre = Vec::new();
            lits(&a.body, &mut pre);
            pre.sort_unstable();
            pre.dedup();
            ops.push(UnaryOp {
                pre,
                effs: vec![a.head],
                cost: 0,
                op: None,
            });
        }
        let mut goal = Vec::new();
        lits(&task.goal, &mut goal);
        let nf = nf0 + complements.len();
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
            .map(|o| costs.of(o.cost))
            .min()
            .unwrap_or(0);
        let n = ops.len();
        let mut is_goal = vec![false; nf];
        for &g in &goal {
            is_goal[g as usize] = true;
        }
        Evaluator {
            kind,
            lmcut,
            is_goal,
            goal,
            complements,
            ops,
            pre_of,
            no_pre,
            min_cost,
            cost: vec![INF; nf],
            supporter: vec![u32::MAX; nf],
            unsat: vec![0; n],
            acc: vec![0; n],
            heap: if task.operators.iter().all(|o| o.cost <= 100) {
                Queue::Buckets(Vec::new(), 0, 0)
            } else {
                Queue::Heap(BinaryHeap::new())
            },
            unsat_init: Vec::new(),
            marked: vec![false; nf],
            in_plan: vec![false; task.operators.len()],
            stack: Vec::new(),
            plan: Vec::new(),
            preferred: Vec::new(),
        }
    }

    /// What one evaluation costs, about: the relaxed operators, their
    /// preconditions and the facts.
    pub fn work(&self) -> u64 {
        let pre: usize = self.ops.iter().map(|u| u.pre.len() + u.effs.len()).sum();
        (pre + self.ops.len() + self.cost.len()) as u64
    }

    /// The heuristic this evaluator computes (LM-cut falls back to h_max).
    pub fn kind(&self) -> Heuristic {
        self.kind
    }

    /// The heuristic value of `s`; `None` when the goal is unreachable even
    /// in the relaxation (a dead end).
    pub fn eval(&mut self, task: &Task, s: &[u64]) -> Option<u64> {
        self.preferred.clear();
        if let Some(l) = &mut self.lmcut {
            return l.eval(s);
        }
        if self.kind == Heuristic::Blind {
            return Some(if task.is_goal(s) { 0 } else { self.min_cost });
        }
        let max = self.kind == Heuristic::Max;
        self.cost.iter_mut().for_each(|c| *c = INF);
        if self.unsat_init.len() != self.ops.len() {
            self.unsat_init = self.ops.iter().map(|u| u.pre.len() as u32).collect();
        }
        self.unsat.copy_from_slice(&self.unsat_init);
        self.acc.iter_mut().for_each(|a| *a = 0);
        self.heap.clear();
        let nf0 = self.cost.len() - self.complements.len();
        for (w, &word) in s.iter().enumerate() {
            let mut bits = word;
            while bits != 0 {
                let f = (w * 64) as u32 + bits.trailing_zeros();
                bits &= bits - 1;
                if (f as usize) < nf0 {
                    self.cost[f as usize] = 0;
                    self.supporter[f as usize] = u32::MAX;
                    self.heap.push(0, f);
                }
            }
        }
        for (i, &f) in self.complements.iter().enumerate() {
            if !crate::task::test(s, f) {
                let c = (nf0 + i) as u32;
                self.cost[c as usize] = 0;
                self.supporter[c as usize] = u32::MAX;
                self.heap.push(0, c);
            }
        }
        for i in 0..self.no_pre.len() {
            let ui = self.no_pre[i];
            let u = &self.ops[ui as usize];
            for &e in &u.effs {
                if u.cost < self.cost[e as usize] {
                    self.cost[e as usize] = u.cost;
                    self.supporter[e as usize] = ui;
                    self.heap.push(u.cost, e);
                }
            }
        }
        // Costs are final when popped: stop once every goal fact is. The
        // tables are borrowed as slices first, so that their lengths stay
        // in registers (through `self` they were reloaded on every access).
        let (cost, supporter, unsat, acc, heap) = (
            &mut self.cost[..],
            &mut self.supporter[..],
            &mut self.unsat[..],
            &mut self.acc[..],
            &mut self.heap,
        );
        let (ops, pre_of, is_goal) = (&self.ops[..], &self.pre_of[..], &self.is_goal[..]);
        let mut goals_left = self.goal.len();
        while let Some((c, f)) = heap.pop() {
            if goals_left == 0 {
                break;
            }
            if c > cost[f as usize] {
                continue;
            }
            if is_goal[f as usize] {
                goals_left -= 1;
            }
            for &ui in &pre_of[f as usize] {
                let i = ui as usize;
                unsat[i] -= 1;
                acc[i] = if max {
                    acc[i].max(c)
                } else {
                    acc[i].saturating_add(c)
                };
                if unsat[i] == 0 {
                    let u = &ops[i];
                    let nc = acc[i].saturating_add(u.cost);
                    for &e in &u.effs {
                        if nc < cost[e as usize] {
                            cost[e as usize] = nc;
                            supporter[e as usize] = ui;
                            heap.push(nc, e);
                        }
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
        let mut plan = std::mem::take(&mut self.plan);
        plan.clear();
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
        for &o in &plan {
            self.in_plan[o as usize] = false;
            if holds(s, &task.operators[o as usize].pre) {
                self.preferred.push(o);
            }
        }
        self.plan = plan;
        Some(hff)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::test_util::rooms;

    /// The rooms fixture by hand: `take` (1) makes `holding` and with it
    /// the door condition; `go hall lab` (2), `go lab vault` (3) reaches the
    /// vault, and moves the held key along.
    #[test]
    fn heuristic_values_of_the_rooms_fixture() {
        let t = rooms();
        let h = |kind| Evaluator::new(&t, kind, false).eval(&t, &t.init);
        assert_eq!(h(Heuristic::Max), Some(3));
        // `locked` is static, so the door condition is `holding`. At vault:
        // 1 + at lab (2) + holding (1) = 4; key in vault: the same
        // operator, its `when (holding)` condition adds nothing new: 4.
        assert_eq!(h(Heuristic::Add), Some(8));
        assert_eq!(h(Heuristic::Ff), Some(3));
        assert_eq!(h(Heuristic::Blind), Some(1));
    }

    #[test]
    fn preferred_operators_apply_in_the_state() {
        let t = rooms();
        let mut e = Evaluator::new(&t, Heuristic::Ff, true);
        e.eval(&t, &t.init);
        assert_eq!(e.preferred.len(), 1);
        let op = &t.operators[e.preferred[0] as usize];
        assert!(holds(&t.init, &op.pre));
    }

    #[test]
    fn goal_states_have_value_zero_and_dead_ends_none() {
        let t = crate::test_util::task(
            include_str!("../tests/fixtures/rooms-domain.pddl"),
            include_str!("../tests/fixtures/rooms-unsolvable.pddl"),
        );
        for kind in [Heuristic::Max, Heuristic::Add, Heuristic::Ff] {
            assert_eq!(Evaluator::new(&t, kind, false).eval(&t, &t.init), None);
        }
        let t = rooms();
        let mut goal = t.init.clone();
        for l in &t.goal {
            crate::task::set(&mut goal, l.fact);
        }
        for kind in [
            Heuristic::Max,
            Heuristic::Add,
            Heuristic::Ff,
            Heuristic::Blind,
        ] {
            assert_eq!(Evaluator::new(&t, kind, false).eval(&t, &goal), Some(0));
        }
    }

    #[test]
    fn the_bucket_queue_pops_in_cost_order_and_clears() {
        let mut q = Queue::Buckets(Vec::new(), 0, 0);
        q.push(5, 1);
        q.push(0, 2);
        q.push(3, 3);
        assert_eq!(q.pop(), Some((0, 2)));
        q.push(3, 4);
        assert_eq!(q.pop().map(|x| x.0), Some(3));
        assert_eq!(q.pop().map(|x| x.0), Some(3));
        q.clear();
        assert_eq!(q.pop(), None);
        q.push(1, 9);
        assert_eq!(q.pop(), Some((1, 9)));
        assert_eq!(q.pop(), None);
    }

    #[test]
    fn the_bucket_queue_falls_back_to_a_heap_for_large_costs() {
        let mut q = Queue::Buckets(Vec::new(), 0, 0);
        q.push(3, 7);
        q.push(1 << 30, 8);
        q.push(2, 9);
        assert!(matches!(q, Queue::Heap(_)));
        assert_eq!(q.pop(), Some((2, 9)));
        assert_eq!(q.pop(), Some((3, 7)));
        assert_eq!(q.pop(), Some((1 << 30, 8)));
        assert_eq!(q.pop(), None);
    }
}
