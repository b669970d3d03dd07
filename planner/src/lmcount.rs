//! The landmark-count heuristic of LAMA: the cost of the landmarks a state
//! has not reached yet, plus those it reached but needs again. Which
//! landmarks are reached depends on the path to a state, so it is kept per
//! state as a bitset and carried along transitions: a landmark becomes
//! reached when it holds and every landmark ordered before it was reached
//! in the state before. A reached landmark is needed again when it does not
//! hold and it is a goal, or a landmark ordered after it is not reached.
//!
//! A landmark not reached counts the cheapest of its possible first
//! achievers (those the landmark generation found can make it true before
//! it ever was), one needed again the cheapest of all its achievers, as
//! Fast Downward's `landmark_sum` does: on tasks with costs a cheap
//! achiever that needs the landmark itself (pouring an ingredient back
//! from a shaker that needs it poured in first) does not hide the cost of
//! the only way to make it true the first time.

use crate::heuristic::Costs;
use crate::landmarks::{Landmark, LandmarkGraph};
use crate::task::test;

pub struct LmCount<'g> {
    graph: &'g LandmarkGraph,
    /// Each landmark's cost in the count when it was not reached: the
    /// cheapest of its possible first achievers.
    cost: Vec<u64>,
    /// Its cost when it is needed again: the cheapest of all achievers.
    again: Vec<u64>,
    words: usize,
}

fn holds(l: &Landmark, s: &[u64]) -> bool {
    l.facts.iter().any(|&f| test(s, f))
}

fn bit(set: &[u64], i: usize) -> bool {
    set[i >> 6] >> (i & 63) & 1 == 1
}

impl<'g> LmCount<'g> {
    pub fn new(graph: &'g LandmarkGraph, costs: Costs) -> LmCount<'g> {
        LmCount {
            cost: graph
                .landmarks
                .iter()
                .map(|l| costs.of(l.first_cost))
                .collect(),
            again: graph
                .landmarks
                .iter()
                .map(|l| costs.of(l.min_cost))
                .collect(),
            words: graph.landmarks.len().div_ceil(64).max(1),
            graph,
        }
    }

    /// The number of landmarks.
    pub fn len(&self) -> usize {
        self.cost.len()
    }

    pub fn is_empty(&self) -> bool {
        self.cost.is_empty()
    }

    /// Words of a reached set.
    pub fn words(&self) -> usize {
        self.words
    }

    /// The landmarks reached in the initial state `s`: those that hold.
    pub fn initial(&self, s: &[u64], out: &mut Vec<u64>) {
        out.clear();
        out.resize(self.words, 0);
        for (i, l) in self.graph.landmarks.iter().enumerate() {
            if holds(l, s) {
                out[i >> 6] |= 1 << (i & 63);
            }
        }
    }

    /// The landmarks reached in `s` after a transition from a state whose
    /// reached set is `before`.
    pub fn progress(&self, before: &[u64], s: &[u64], out: &mut Vec<u64>) {
        out.clear();
        out.extend_from_slice(before);
        for (i, l) in self.graph.landmarks.iter().enumerate() {
            if !bit(before, i) && holds(l, s) && l.parents.iter().all(|&p| bit(before, p as usize))
            {
                out[i >> 6] |= 1 << (i & 63);
            }
        }
    }

    /// The heuristic value of `s` with `reached` landmarks.
    pub fn value(&self, reached: &[u64], s: &[u64]) -> u64 {
        let mut h = 0;
        for (i, l) in self.graph.landmarks.iter().enumerate() {
            if !bit(reached, i) {
                h += self.cost[i];
            } else if !holds(l, s)
                && (l.goal || l.children.iter().any(|&c| !bit(reached, c as usize)))
            {
                h += self.again[i];
            }
        }
        h
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::task::AxiomScratch;
    use crate::test_util::{fact, task};

    /// A coin is bought (10) or taken back (1) once given away: taking back
    /// needs the coin given, so only buying can come first. The count
    /// costs an unreached landmark its cheapest possible first achiever,
    /// and one needed again its cheapest achiever.
    #[test]
    fn unreached_landmarks_cost_their_cheapest_first_achiever() {
        let t = task(
            "(define (domain coins) (:requirements :strips :typing :action-costs)
               (:types coin) (:predicates (have ?c - coin) (given ?c - coin) (kept ?c - coin))
               (:functions (total-cost) - number)
               (:action buy :parameters (?c - coin) :effect (and (have ?c) (increase (total-cost) 10)))
               (:action give :parameters (?c - coin) :precondition (have ?c)
                 :effect (and (given ?c) (not (have ?c)) (increase (total-cost) 1)))
               (:action take-back :parameters (?c - coin) :precondition (given ?c)
                 :effect (and (have ?c) (increase (total-cost) 1)))
               (:action keep :parameters (?c - coin) :precondition (and (have ?c) (given ?c))
                 :effect (and (kept ?c) (increase (total-cost) 1))))",
            "(define (problem p) (:domain coins) (:objects a - coin) (:init (= (total-cost) 0))
               (:goal (kept a)) (:metric minimize (total-cost)))",
        );
        let g = LandmarkGraph::generate(&t);
        let have = &g.landmarks[g.by_fact[fact(&t, "(have a)") as usize][0] as usize];
        assert_eq!((have.first_cost, have.min_cost), (10, 1));
        let h = LmCount::new(&g, Costs::Real);
        let mut reached = Vec::new();
        h.initial(&t.init, &mut reached);
        // (kept a) 1, (given a) 1, (have a) 10.
        assert_eq!(h.value(&reached, &t.init), 12);
        assert_eq!(
            LmCount::new(&g, Costs::PlusOne).value(&reached, &t.init),
            15
        );
        // After buying and giving, the coin is needed again for keeping:
        // taking it back (1) will do.
        let mut ax = AxiomScratch::default();
        let (mut s, mut next, mut r2) = (t.init.clone(), Vec::new(), Vec::new());
        for adds in ["(have a)", "(given a)"] {
            let f = fact(&t, adds);
            let o = t
                .operators
                .iter()
                .find(|o| {
                    // Buying (no precondition), not taking back.
                    o.effects.iter().any(|e| e.add && e.fact == f)
                        && (o.pre.is_empty() || adds == "(given a)")
                })
                .unwrap();
            t.apply(o, &s, &mut next, &mut ax);
            h.progress(&reached, &next, &mut r2);
            std::mem::swap(&mut s, &mut next);
            std::mem::swap(&mut reached, &mut r2);
        }
        assert_eq!(h.value(&reached, &s), 1 + 1);
    }

    #[test]
    fn landmarks_are_counted_reached_and_needed_again() {
        let t = task(
            include_str!("../../examples/ariac/domain.pddl"),
            include_str!("../../examples/ariac/problem.pddl"),
        );
        let g = LandmarkGraph::generate(&t);
        let h = LmCount::new(&g, Costs::Unit);
        let mut reached = Vec::new();
        h.initial(&t.init, &mut reached);
        // Five landmarks; the part in the bin holds already.
        assert_eq!(h.value(&reached, &t.init), 4);
        let op = |from: &str, to: &str| {
            let (f, g) = (fact(&t, from), fact(&t, to));
            t.operators
                .iter()
                .find(|o| {
                    o.pre.iter().any(|l| l.positive && l.fact == f)
                        && o.effects.iter().any(|e| e.add && e.fact == g)
                })
                .unwrap()
        };
        let at = |c: &str| format!("(is_reachable floor_robot {c})");
        let mut ax = AxiomScratch::default();
        let (mut s, mut next, mut r2) = (t.init.clone(), Vec::new(), Vec::new());
        for (from, to, h_after) in [
            (at("curr_position"), at("bin1"), 3),
            (
                "(on battery_red bin1)".to_owned(),
                "(attach battery_red floor_robot)".to_owned(),
                2,
            ),
            // Leaving the bin for the AGV: the bin is no longer needed.
            (at("bin1"), at("agv1"), 1),
            (
                "(attach battery_red floor_robot)".to_owned(),
                "(on battery_red agv1)".to_owned(),
                0,
            ),
        ] {
            t.apply(op(&from, &to), &s, &mut next, &mut ax);
            h.progress(&reached, &next, &mut r2);
            std::mem::swap(&mut s, &mut next);
            std::mem::swap(&mut reached, &mut r2);
            assert_eq!(h.value(&reached, &s), h_after, "after {to}");
        }
        // Going to the AGV before the bin reaches the AGV landmark, but
        // it is needed again once the part is held.
        let mut s = t.init.clone();
        h.initial(&s, &mut reached);
        for (from, to) in [(at("curr_position"), at("agv1")), (at("agv1"), at("bin1"))] {
            t.apply(op(&from, &to), &s, &mut next, &mut ax);
            h.progress(&reached, &next, &mut r2);
            std::mem::swap(&mut s, &mut next);
            std::mem::swap(&mut reached, &mut r2);
        }
        // Not reached: attach, the goal; needed again: at agv1 (ordered
        // before the goal, which is not reached).
        assert_eq!(h.value(&reached, &s), 3);
    }
}
