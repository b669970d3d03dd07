//! Greedy action elimination: a step whose removal leaves every later step
//! applicable and still reaches the goal is dropped (first to last,
//! repeated until nothing changes). Costs are never negative, so the plan
//! gets no dearer; greedy search's plans often get shorter.

use crate::task::{holds, AxiomScratch, Task};

/// Whether `plan` without step `skip` applies from the initial state and
/// ends in a goal state.
fn valid_without(task: &Task, plan: &[u32], skip: usize, ax: &mut AxiomScratch) -> bool {
    let mut s = task.init.clone();
    let mut next = Vec::with_capacity(s.len());
    for (i, &o) in plan.iter().enumerate() {
        if i == skip {
            continue;
        }
        let op = &task.operators[o as usize];
        if !holds(&s, &op.pre) {
            return false;
        }
        task.apply(op, &s, &mut next, ax);
        std::mem::swap(&mut s, &mut next);
    }
    task.is_goal(&s)
}

/// `plan` with redundant steps removed.
pub fn eliminate_redundant(task: &Task, mut plan: Vec<u32>) -> Vec<u32> {
    let mut ax = AxiomScratch::default();
    loop {
        let mut changed = false;
        let mut i = 0;
        while i < plan.len() {
            if valid_without(task, &plan, i, &mut ax) {
                plan.remove(i);
                changed = true;
            } else {
                i += 1;
            }
        }
        if !changed {
            return plan;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::test_util::{fact, task};

    /// The operator that needs `from` and adds `to`.
    fn op(t: &Task, from: &str, to: &str) -> u32 {
        let (f, g) = (fact(t, from), fact(t, to));
        t.operators
            .iter()
            .position(|o| {
                o.pre.iter().any(|l| l.positive && l.fact == f)
                    && o.effects.iter().any(|e| e.add && e.fact == g)
            })
            .unwrap_or_else(|| panic!("no operator from {from} to {to}")) as u32
    }

    #[test]
    fn redundant_steps_are_dropped_and_needed_ones_stay() {
        let t = task(
            include_str!("../../examples/ariac/domain.pddl"),
            include_str!("../../examples/ariac/problem.pddl"),
        );
        let at = |c: &str| format!("(is_reachable floor_robot {c})");
        let to_bin = op(&t, &at("curr_position"), &at("bin1"));
        let stay = op(&t, &at("bin1"), &at("bin1"));
        let grasp = op(
            &t,
            "(on battery_red bin1)",
            "(attach battery_red floor_robot)",
        );
        let to_agv = op(&t, &at("bin1"), &at("agv1"));
        let place = op(
            &t,
            "(attach battery_red floor_robot)",
            "(on battery_red agv1)",
        );
        let away = op(&t, &at("agv1"), &at("bin5"));
        let plan = vec![to_bin, grasp, to_agv, place];
        assert_eq!(eliminate_redundant(&t, plan.clone()), plan);
        let padded = vec![to_bin, stay, grasp, to_agv, place, away];
        assert_eq!(eliminate_redundant(&t, padded), plan);
    }
}
