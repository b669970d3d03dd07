//! Planning an attempt from the carried state, and the loop's stop when no
//! plan reaches the goal or the planner runs out of time.

use super::carry::{goal_formula, Carry};
use super::{quoted, world, LoopError, LoopOptions, LoopSummary, Run, Unreachable};
use crate::execution::{self, MadePlan, Planning, PlanningWorld};
use btc_lang::db::JobWorld;
use btc_pddl::diagnostic::codes;
use btc_pddl::logic::Formula;
use btc_pddl::source::Span;
use btc_runtime::Kb;

/// What planning an attempt came to.
pub(super) enum Planned {
    /// The first attempt runs the given plan file.
    Given,
    /// A new plan.
    Made {
        plan: MadePlan,
        ms: f64,
        expanded: usize,
    },
    /// The priority goal holds already (e.g. by the order's own effect).
    PriorityDone,
    /// The whole goal holds: nothing left to do.
    GoalHolds,
    /// No plan: the loop stops (the summary says why).
    Stopped,
}

impl Run<'_, '_> {
    /// Plans attempt `attempt` for `goal` from the carried state.
    pub(super) fn plan(
        &mut self,
        attempt: usize,
        goal: &Formula,
        for_priority: bool,
    ) -> Result<Planned, LoopError> {
        if attempt == 1 && self.given_plan {
            return Ok(Planned::Given);
        }
        let w = world(self.db, self.job)?;
        let mut kb = self.carry.kb(&self.world);
        let g = goal_formula(&mut kb, goal)?;
        kb.set_goal(g);
        if kb.goal().0 {
            return Ok(if for_priority {
                Planned::PriorityDone
            } else {
                Planned::GoalHolds
            });
        }
        let planning = execution::plan(
            PlanningWorld::from(&w),
            &kb.state,
            goal,
            self.goal_span,
            &self.opts.planner,
        )
        .map_err(LoopError::Compile)?;
        match planning {
            Planning::Made { plan, ms, expanded } => Ok(Planned::Made { plan, ms, expanded }),
            Planning::Unsolvable { .. } => {
                let un = unreachable(&w, &kb, goal, self.goal_span, &self.carry, self.opts)?;
                let msg = unsolvable_message(&un, &self.carry, self.out.attempts.is_empty());
                self.out.stop(
                    codes::X_REPLAN_UNSOLVABLE,
                    self.goal_span,
                    msg,
                    "a fault removed what the goal needs and nothing in the problem replaces \
                     it; a discarded part is replaced by a spare of the same kind (an object \
                     of its type named `PART_...`, e.g. `battery_red_2`)",
                );
                self.out.unreachable = un;
                self.out.goal_failure = kb.goal().1;
                Ok(Planned::Stopped)
            }
            Planning::Timeout { .. } => {
                let limit = self.opts.planner.timeout.unwrap_or_default();
                let msg = format!(
                    "planning from the state at tick {} found no plan within {} s",
                    self.carry.tick,
                    limit.as_secs_f64()
                );
                self.out.stop(
                    codes::PLAN_TIMEOUT,
                    self.goal_span,
                    msg,
                    "raise the planner's time limit",
                );
                self.out.goal_failure = kb.goal().1;
                Ok(Planned::Stopped)
            }
        }
    }
}

impl LoopSummary {
    /// The loop stops here, for the reason `msg`, reported as `code`.
    pub(super) fn stop(
        &mut self,
        code: btc_pddl::diagnostic::Code,
        span: Span,
        msg: String,
        hint: &str,
    ) {
        self.diagnostics
            .push(btc_pddl::diagnostic::Diagnostic::error(code, span, msg.clone()).with_hint(hint));
        self.stopped = Some(msg);
    }
}

/// Why no plan reaches the goal: the literals none reaches and the faults
/// that made it so (those that name them, and those still in effect).
fn unsolvable_message(un: &[Unreachable], carry: &Carry, at_start: bool) -> String {
    let lits: Vec<String> = un.iter().map(|u| format!("`{}`", u.literal)).collect();
    let by = un.iter().flat_map(|u| u.faults.iter().cloned());
    // Faults still in effect (a malfunction that outlasted the tick limit)
    // count too.
    let in_effect = carry
        .faults
        .iter()
        .flat_map(|f| &f.list)
        .filter(|rt| rt.met_at.is_some() && !rt.ended)
        .map(|rt| rt.spec.label());
    let mut faults: Vec<String> = Vec::new();
    for f in by.chain(in_effect) {
        if !faults.contains(&f) {
            faults.push(f);
        }
    }
    format!(
        "no plan reaches the goal from the state after {}: {} {} unreachable{}",
        if at_start {
            "the start".to_owned()
        } else {
            format!("tick {}", carry.tick)
        },
        if lits.is_empty() {
            "the goal as a whole".to_owned()
        } else {
            lits.join(", ")
        },
        if lits.len() > 1 { "are" } else { "is" },
        if faults.is_empty() {
            String::new()
        } else {
            format!(" (made so by fault {})", quoted(&faults))
        }
    )
}

/// The goal's conjuncts (nested conjunctions split too) that no plan
/// reaches from the KB's state, with the faults that name them.
fn unreachable(
    w: &JobWorld<'_>,
    kb: &Kb<'_>,
    goal: &Formula,
    span: Span,
    carry: &Carry,
    opts: &LoopOptions,
) -> Result<Vec<Unreachable>, LoopError> {
    let mut literals = Vec::new();
    for part in goal.conjuncts() {
        literals.extend(part.conjuncts().iter().cloned());
    }
    let none = crate::faults::Faults::default();
    let faults = carry.faults.as_ref().unwrap_or(&none);
    let mut out = Vec::new();
    for lit in literals {
        let r = execution::plan(PlanningWorld::from(w), &kb.state, &lit, span, &opts.planner)
            .map_err(LoopError::Compile)?;
        if matches!(r, Planning::Unsolvable { .. }) {
            out.push(Unreachable {
                literal: lit.to_string(),
                faults: faults.naming(&lit),
            });
        }
    }
    Ok(out)
}
