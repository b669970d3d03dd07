//! Landmarks: facts (or disjunctions of facts) that every plan makes true
//! at some point, with greedy-necessary orderings between them, found by
//! backchaining from the goal in the style of Richter, Helmert and
//! Westphal (2008), the landmarks of LAMA.
//!
//! For a landmark, the relaxed exploration from the initial state that may
//! not use its achievers finds the achievers that can come first (their
//! conditions are reachable without the landmark). Every condition those
//! *possible first achievers* share is a landmark too, ordered before it;
//! conditions they do not share but that all of them have of one predicate
//! form a disjunctive landmark (at most [`MAX_DISJUNCTION`] facts). The new
//! landmarks are backchained in turn. The relaxation ignores deletes and
//! negative conditions; a conditional effect is an achiever whose
//! conditions include the effect's, an axiom one of cost 0.
//!
//! Richter et al. also derive landmarks from the domain transition graphs
//! of a multi-valued encoding; the planner's tasks are propositional, so
//! those are not found here.

use crate::task::{test, Task};
use rustc_hash::FxHashMap;
use std::collections::VecDeque;

/// The most facts in a disjunctive landmark (as in Fast Downward).
pub const MAX_DISJUNCTION: usize = 4;

/// Landmark generation stops after this many landmarks: each one costs a
/// relaxed exploration, and more add little guidance.
pub const MAX_LANDMARKS: usize = 2000;

#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Landmark {
    /// One fact, or the facts of a disjunctive landmark (sorted).
    pub facts: Vec<u32>,
    /// A fact of the goal.
    pub goal: bool,
    /// Holds in the initial state.
    pub initial: bool,
    /// Landmarks ordered greedy-necessarily before this one: one of them
    /// holds in the state before this landmark first becomes true.
    pub parents: Vec<u32>,
    pub children: Vec<u32>,
    /// The cheapest cost of an achiever (0 for derived facts).
    pub min_cost: u64,
    /// The cheapest cost of a possible first achiever (one that can make
    /// the landmark true before it ever was); `min_cost` when they are not
    /// known (landmarks true initially).
    pub first_cost: u64,
}

#[derive(Clone, Debug, Default)]
pub struct LandmarkGraph {
    pub landmarks: Vec<Landmark>,
    /// For each fact, the landmarks it is a fact of.
    pub by_fact: Vec<Vec<u32>>,
}

/// A relaxed operator with one effect: an operator's effect (its
/// precondition and the effect's condition, positive facts only) or an
/// axiom.
struct Unary {
    pre: Vec<u32>,
    eff: u32,
    /// The operator (for operator effects) or `u32::MAX` (axioms).
    op: u32,
    cost: u64,
}

struct Generator<'t> {
    task: &'t Task,
    unary: Vec<Unary>,
    /// Unary operators by precondition fact.
    pre_of: Vec<Vec<u32>>,
    /// Unary operators by effect fact.
    achievers: Vec<Vec<u32>>,
    // Scratch of the exploration.
    waiting: Vec<u32>,
    reached: Vec<bool>,
    queue: Vec<u32>,
    excluded_op: Vec<bool>,
}

impl<'t> Generator<'t> {
    fn new(task: &'t Task) -> Generator<'t> {
        let nf = task.num_facts();
        let mut unary = Vec::new();
        let positive = |ls: &[crate::task::Lit], out: &mut Vec<u32>| {
            out.extend(ls.iter().filter(|l| l.positive).map(|l| l.fact));
        };
        for (i, o) in task.operators.iter().enumerate() {
            let mut base = Vec::new();
            positive(&o.pre, &mut base);
            for e in o.effects.iter().filter(|e| e.add) {
                let mut pre = base.clone();
                positive(&e.cond, &mut pre);
                pre.sort_unstable();
                pre.dedup();
                unary.push(Unary {
                    pre,
                    eff: e.fact,
                    op: i as u32,
                    cost: o.cost,
                });
            }
        }
        for a in &task.axioms {
            let mut pre = Vec::new();
            positive(&a.body, &mut pre);
            pre.sort_unstable();
            pre.dedup();
            unary.push(Unary {
                pre,
                eff: a.head,
                op: u32::MAX,
                cost: 0,
            });
        }
        let mut pre_of = vec![Vec::new(); nf];
        let mut achievers = vec![Vec::new(); nf];
        for (i, u) in unary.iter().enumerate() {
            for &p in &u.pre {
                pre_of[p as usize].push(i as u32);
            }
            achievers[u.eff as usize].push(i as u32);
        }
        Generator {
            task,
            waiting: vec![0; unary.len()],
            unary,
            pre_of,
            achievers,
            reached: vec![false; nf],
            queue: Vec::new(),
            excluded_op: vec![false; task.operators.len()],
        }
    }

    /// Relaxed reachability from the initial state without the operators
    /// (and axioms) that achieve any of `facts`; fills `self.reached`.
    fn explore_without(&mut self, facts: &[u32]) {
        let task = self.task;
        for &f in facts {
            for &u in &self.achievers[f as usize] {
                let op = self.unary[u as usize].op;
                if op != u32::MAX {
                    self.excluded_op[op as usize] = true;
                }
            }
        }
        let excluded = |g: &Self, u: &Unary| {
            if u.op == u32::MAX {
                facts.contains(&u.eff)
            } else {
                g.excluded_op[u.op as usize]
            }
        };
        self.reached.iter_mut().for_each(|r| *r = false);
        self.queue.clear();
        for (w, u) in self.waiting.iter_mut().zip(&self.unary) {
            *w = u.pre.len() as u32;
        }
        for f in 0..task.num_facts() as u32 {
            if test(&task.init, f) && !task.derived[f as usize] {
                self.reached[f as usize] = true;
                self.queue.push(f);
            }
        }
        for i in 0..self.unary.len() {
            let u = &self.unary[i];
            if u.pre.is_empty() && !excluded(self, u) && !self.reached[u.eff as usize] {
                self.reached[u.eff as usize] = true;
                self.queue.push(u.eff);
            }
        }
        while let Some(f) = self.queue.pop() {
            for k in 0..self.pre_of[f as usize].len() {
                let ui = self.pre_of[f as usize][k] as usize;
                self.waiting[ui] -= 1;
                if self.waiting[ui] == 0 {
                    let u = &self.unary[ui];
                    if !excluded(self, u) && !self.reached[u.eff as usize] {
                        self.reached[u.eff as usize] = true;
                        self.queue.push(u.eff);
                    }
                }
            }
        }
        for &f in facts {
            for &u in &self.achievers[f as usize] {
                let op = self.unary[u as usize].op;
                if op != u32::MAX {
                    self.excluded_op[op as usize] = false;
                }
            }
        }
    }

    /// The possible first achievers of `facts`: achievers whose conditions
    /// are reachable without achieving any of them.
    fn first_achievers(&mut self, facts: &[u32]) -> Vec<u32> {
        self.explore_without(facts);
        let mut out: Vec<u32> = facts
            .iter()
            .flat_map(|&f| self.achievers[f as usize].iter().copied())
            .filter(|&u| {
                self.unary[u as usize]
                    .pre
                    .iter()
                    .all(|&p| self.reached[p as usize])
            })
            .collect();
        out.sort_unstable();
        out.dedup();
        out
    }
}

impl LandmarkGraph {
    /// The landmarks of a task and their orderings.
    pub fn generate(task: &Task) -> LandmarkGraph {
        let mut gen = Generator::new(task);
        let mut graph = LandmarkGraph {
            landmarks: Vec::new(),
            by_fact: vec![Vec::new(); task.num_facts()],
        };
        let mut ids: FxHashMap<Vec<u32>, u32> = FxHashMap::default();
        let mut removed: Vec<bool> = Vec::new();
        let mut queue = VecDeque::new();
        let initial = |facts: &[u32]| facts.iter().any(|&f| test(&task.init, f));
        for l in task.goal.iter().filter(|l| l.positive) {
            let facts = vec![l.fact];
            if ids.contains_key(&facts) {
                continue;
            }
            let id = graph.landmarks.len() as u32;
            ids.insert(facts.clone(), id);
            graph.landmarks.push(Landmark {
                initial: initial(&facts),
                facts,
                goal: true,
                parents: Vec::new(),
                children: Vec::new(),
                min_cost: 0,
                first_cost: u64::MAX,
            });
            removed.push(false);
            queue.push_back(id);
        }
        while let Some(id) = queue.pop_front() {
            if removed[id as usize] || graph.landmarks[id as usize].initial {
                continue;
            }
            let facts = graph.landmarks[id as usize].facts.clone();
            let first = gen.first_achievers(&facts);
            if first.is_empty() {
                continue;
            }
            graph.landmarks[id as usize].first_cost = first
                .iter()
                .map(|&u| gen.unary[u as usize].cost)
                .min()
                .unwrap_or(u64::MAX);
            // Conditions every possible first achiever has.
            let mut shared: Vec<u32> = gen.unary[first[0] as usize].pre.clone();
            for &u in &first[1..] {
                let pre = &gen.unary[u as usize].pre;
                shared.retain(|p| pre.binary_search(p).is_ok());
            }
            shared.retain(|p| !facts.contains(p));
            let mut found: Vec<Vec<u32>> = shared.iter().map(|&p| vec![p]).collect();
            // Conditions of one predicate that every achiever has some of.
            let mut preds: Vec<u32> = gen.unary[first[0] as usize]
                .pre
                .iter()
                .map(|&p| task.fact_preds[p as usize])
                .filter(|&p| p != u32::MAX)
                .collect();
            preds.sort_unstable();
            preds.dedup();
            for pred in preds {
                let mut union: Vec<u32> = Vec::new();
                let mut every = true;
                for &u in &first {
                    let before = union.len();
                    union.extend(gen.unary[u as usize].pre.iter().copied().filter(|&p| {
                        task.fact_preds[p as usize] == pred
                            && !shared.contains(&p)
                            && !facts.contains(&p)
                    }));
                    if union.len() == before {
                        every = false;
                        break;
                    }
                }
                union.sort_unstable();
                union.dedup();
                if every
                    && union.len() >= 2
                    && union.len() <= MAX_DISJUNCTION
                    && !initial(&union)
                    && union.iter().all(|&f| !ids.contains_key(&vec![f]))
                {
                    found.push(union);
                }
            }
            for facts in found {
                if graph.landmarks.len() >= MAX_LANDMARKS && !ids.contains_key(&facts) {
                    break;
                }
                let child = id;
                let parent = match ids.get(&facts) {
                    Some(&p) => p,
                    None => {
                        if facts.len() == 1 {
                            // A fact landmark replaces the disjunctions it is part of.
                            for (k, l) in graph.landmarks.iter().enumerate() {
                                if l.facts.len() > 1 && l.facts.contains(&facts[0]) {
                                    removed[k] = true;
                                }
                            }
                        }
                        let p = graph.landmarks.len() as u32;
                        ids.insert(facts.clone(), p);
                        graph.landmarks.push(Landmark {
                            initial: initial(&facts),
                            facts,
                            goal: false,
                            parents: Vec::new(),
                            children: Vec::new(),
                            min_cost: 0,
                            first_cost: u64::MAX,
                        });
                        removed.push(false);
                        queue.push_back(p);
                        p
                    }
                };
                if parent != child && !graph.landmarks[child as usize].parents.contains(&parent) {
                    graph.landmarks[child as usize].parents.push(parent);
                }
            }
        }
        graph.compact(&removed, &gen);
        graph
    }

    /// Drops removed landmarks, renumbers, links children and fills the
    /// fact index and costs.
    fn compact(&mut self, removed: &[bool], gen: &Generator) {
        let mut new_id = vec![u32::MAX; self.landmarks.len()];
        let mut kept = Vec::new();
        for (i, l) in std::mem::take(&mut self.landmarks).into_iter().enumerate() {
            if !removed[i] {
                new_id[i] = kept.len() as u32;
                kept.push(l);
            }
        }
        for l in &mut kept {
            l.parents = l
                .parents
                .iter()
                .map(|&p| new_id[p as usize])
                .filter(|&p| p != u32::MAX)
                .collect();
            l.parents.sort_unstable();
            l.children.clear();
        }
        for i in 0..kept.len() {
            for k in 0..kept[i].parents.len() {
                let p = kept[i].parents[k] as usize;
                kept[p].children.push(i as u32);
            }
        }
        for (i, l) in kept.iter_mut().enumerate() {
            l.min_cost = l
                .facts
                .iter()
                .flat_map(|&f| &gen.achievers[f as usize])
                .map(|&u| gen.unary[u as usize].cost)
                .min()
                .unwrap_or(0);
            if l.first_cost == u64::MAX {
                l.first_cost = l.min_cost;
            }
            for &f in &l.facts {
                self.by_fact[f as usize].push(i as u32);
            }
        }
        self.landmarks = kept;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::test_util::{fact, task};

    fn names(t: &Task, g: &LandmarkGraph) -> Vec<String> {
        let mut v: Vec<String> = g
            .landmarks
            .iter()
            .map(|l| {
                l.facts
                    .iter()
                    .map(|&f| t.fact_names[f as usize].clone())
                    .collect::<Vec<_>>()
                    .join(" | ")
            })
            .collect();
        v.sort();
        v
    }

    /// ARIAC: the part on the AGV needs it in the gripper, which needs the
    /// robot at the bin and the part in it (true at first); placing needs
    /// the robot at the AGV.
    #[test]
    fn the_ariac_landmarks_and_their_orderings() {
        let t = task(
            include_str!("../../examples/ariac/domain.pddl"),
            include_str!("../../examples/ariac/problem.pddl"),
        );
        let g = LandmarkGraph::generate(&t);
        assert_eq!(
            names(&t, &g),
            [
                "(attach battery_red floor_robot)",
                "(is_reachable floor_robot agv1)",
                "(is_reachable floor_robot bin1)",
                "(on battery_red agv1)",
                "(on battery_red bin1)",
            ]
        );
        let id = |name: &str| {
            let f = fact(&t, name);
            g.by_fact[f as usize][0]
        };
        let goal = &g.landmarks[id("(on battery_red agv1)") as usize];
        assert!(goal.goal && !goal.initial);
        let mut parents = goal.parents.clone();
        parents.sort();
        let mut expected = vec![
            id("(attach battery_red floor_robot)"),
            id("(is_reachable floor_robot agv1)"),
        ];
        expected.sort();
        assert_eq!(parents, expected);
        let attach = &g.landmarks[id("(attach battery_red floor_robot)") as usize];
        let mut expected = vec![
            id("(is_reachable floor_robot bin1)"),
            id("(on battery_red bin1)"),
        ];
        expected.sort();
        assert_eq!(attach.parents, expected);
        assert!(g.landmarks[id("(on battery_red bin1)") as usize].initial);
        assert!(attach.children.contains(&id("(on battery_red agv1)")));
    }

    /// Gripper: a ball in the other room must be carried by one of the two
    /// grippers, a disjunctive landmark.
    #[test]
    fn disjunctive_landmarks_group_conditions_of_one_predicate() {
        let t = task(
            include_str!("../tests/fixtures/gripper-domain.pddl"),
            include_str!("../tests/fixtures/gripper-problem.pddl"),
        );
        let g = LandmarkGraph::generate(&t);
        let n = names(&t, &g);
        assert!(
            n.contains(&"(carry ball1 left) | (carry ball1 right)".to_owned()),
            "{n:?}"
        );
        assert!(n.contains(&"(at-robby roomb)".to_owned()), "{n:?}");
    }
}
