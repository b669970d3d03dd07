//! After a failed attempt: whether the loop may go on (its tick and replan
//! limits), and if so what changed — the goal's adjustments (goals faults
//! added, discarded parts replaced by spares, a priority order first) and
//! the record of why it plans again.

use super::attempt::Ran;
use super::{plural, quoted, Replan, Run};
use btc_pddl::diagnostic::codes;
use btc_pddl::logic::{Formula, Terms};
use btc_runtime::engine::Status;

impl Run<'_, '_> {
    /// Stops the loop (and says why) when a failed attempt used up its ticks
    /// or replans.
    pub(super) fn out_of_limits(&mut self, ran: &Ran) -> bool {
        if ran.status == Status::Running && !ran.preempted {
            let msg = format!("the loop ran out of ticks ({} in all)", self.opts.max_ticks);
            self.out.stop(
                codes::X_REPLAN_LIMIT,
                self.goal_span,
                msg,
                "raise `--max-ticks`",
            );
            return true;
        }
        if self.out.replans.len() >= self.opts.max_replans {
            let msg = format!(
                "the goal was not reached after {} (the limit)",
                plural(self.opts.max_replans, "replan")
            );
            self.out.stop(
                codes::X_REPLAN_LIMIT,
                self.goal_span,
                msg,
                "raise `--max-replans`, or look at the fault records",
            );
            return true;
        }
        false
    }

    /// Adjusts the carried goal after the failed attempt `attempt` (whose
    /// goal was `goal`), and says why the loop plans again.
    pub(super) fn replan(&mut self, attempt: usize, goal: &Formula, ran: Ran) -> Replan {
        let mut adjustments: Vec<String> = ran
            .added
            .iter()
            .map(|a| format!("a fault added the goal `{a}`"))
            .collect();
        self.substitute_spares(goal, &ran.discarded, &mut adjustments);
        if ran.preempted {
            for g in &ran.preempting {
                adjustments.push(format!("`{g}` comes first: the order preempted the plan"));
            }
            self.carry.priority = ran.preempting.clone();
            let goals: Vec<String> = ran.preempting.iter().map(|g| g.to_string()).collect();
            return Replan {
                after_attempt: attempt,
                tick: self.carry.tick,
                why: format!(
                    "a high-priority order preempted the plan at tick {}: {}",
                    ran.end_tick,
                    quoted(&goals)
                ),
                from_step: None,
                action: None,
                faults: ran.order_faults,
                adjustments,
            };
        }
        let last = ran.last_record.as_ref();
        Replan {
            after_attempt: attempt,
            tick: self.carry.tick,
            why: last.map_or_else(
                || "the tree failed".to_owned(),
                |r| format!("`{}` ({}) failed: {}", r.node_name, r.node_id, r.reason),
            ),
            from_step: last.and_then(|r| r.step),
            action: last.and_then(|r| r.action.clone()),
            faults: last.map(|r| r.faults.clone()).unwrap_or_default(),
            adjustments,
        }
    }

    /// Each part the goal names that a fault discarded is replaced by a
    /// spare in the carried goal, or said to have none.
    fn substitute_spares(
        &mut self,
        goal: &Formula,
        discarded: &[(String, String)],
        adjustments: &mut Vec<String>,
    ) {
        let kb = self.carry.kb(&self.world);
        let named = goal.objects();
        for (part, fault) in discarded {
            let part = btc_pddl::logic::name(part);
            if self.carry.substitutions.iter().any(|(p, _)| *p == part) || !named.contains(&part) {
                continue;
            }
            match self.carry.spare(&kb, &part, &named) {
                Some(s) => {
                    adjustments.push(format!(
                        "`{part}` is gone (fault `{fault}`): the goal uses `{s}` instead"
                    ));
                    self.carry.substitutions.push((part, s));
                }
                None => adjustments.push(format!(
                    "`{part}` is gone (fault `{fault}`) and the problem has no spare `{part}_...`"
                )),
            }
        }
    }
}
