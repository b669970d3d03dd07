//! One attempt: the plan compiled with the rules, exactly as `btc compile`
//! compiles the plan file, and the tree run in the carried world until it
//! ends, a high-priority order preempts it, or the ticks run out.

use super::carry::{goal_formula, Carry};
use super::planning::Planned;
use super::{push_event, Attempt, LoopError, LoopSummary, Run};
use crate::execution;
use crate::faults::{FaultKind, FaultsOnEngine};
use btc_pddl::logic::Formula;
use btc_runtime::engine::{FaultRecord, Status};
use btc_runtime::observers::JsonlTrace;
use btc_runtime::{Kb, TreeDoc};
use std::time::Instant;

/// What an attempt leaves the next, wherever it ran: the goals faults added
/// (returned: those new in this attempt), the KB's state, the tick, and
/// whether the goal is reached (`reached`: the attempt may count as
/// reaching it). Over the loop's fields, not `Run`: the KB borrows its
/// world.
pub(super) fn carry_over(
    carry: &mut Carry,
    out: &mut LoopSummary,
    kb: &mut Kb<'_>,
    tick: u64,
    reached: bool,
) -> Vec<Formula> {
    let mut added = kb.extra_goals();
    added.retain(|a| !carry.extra_goals.contains(a));
    carry.extra_goals.extend(added.iter().cloned());
    let (goal_ok, goal_why) = kb.goal();
    carry.state = Some(std::mem::take(&mut kb.state));
    carry.tick = tick;
    out.ticks = tick;
    out.goal_reached = goal_ok && reached;
    out.goal_failure = goal_why;
    added
}

/// What planning and compiling an attempt made, before it runs.
pub(super) struct Compiled {
    pub attempt: usize,
    pub source: &'static str,
    pub goal_text: String,
    pub plan: Vec<String>,
    pub planning_ms: f64,
    pub expanded: usize,
    pub compile_ms: f64,
    /// The attempt is for a priority order's goal, not the whole goal.
    pub for_priority: bool,
}

/// How an attempt's run went, for its record.
pub(super) struct RunPart {
    pub run_ms: f64,
    pub start_tick: u64,
    pub end_tick: u64,
    pub status: Status,
    pub steps_done: usize,
    pub steps_total: usize,
    pub records: Vec<FaultRecord>,
    pub waited_ticks: u64,
    pub preempted: bool,
}

impl Compiled {
    pub(super) fn record(self, r: RunPart) -> Attempt {
        Attempt {
            attempt: self.attempt,
            source: self.source,
            goal: self.goal_text,
            plan: self.plan,
            planning_ms: self.planning_ms,
            expanded: self.expanded,
            compile_ms: self.compile_ms,
            run_ms: r.run_ms,
            start_tick: r.start_tick,
            end_tick: r.end_tick,
            status: r.status,
            steps_done: r.steps_done,
            steps_total: r.steps_total,
            records: r.records,
            waited_ticks: r.waited_ticks,
            preempted: r.preempted,
        }
    }
}

/// What an attempt's run ended in, for deciding what comes next.
pub(super) struct Ran {
    pub status: Status,
    /// The tree succeeded and no order preempted it.
    pub done: bool,
    pub preempted: bool,
    /// The goals of the orders that preempted the tree.
    pub preempting: Vec<Formula>,
    /// The high-priority-order faults met at the attempt's last tick.
    pub order_faults: Vec<String>,
    /// Parts discarded by faults, with the fault: (part, fault).
    pub discarded: Vec<(String, String)>,
    /// Goals faults added during this attempt.
    pub added: Vec<Formula>,
    pub end_tick: u64,
    /// The last fault record: the failure the loop replans after.
    pub last_record: Option<FaultRecord>,
}

/// What an attempt's run decides beyond its record.
pub(super) struct Outcome {
    pub done: bool,
    pub preempting: Vec<Formula>,
    pub order_faults: Vec<String>,
    pub discarded: Vec<(String, String)>,
    pub added: Vec<Formula>,
}

impl Run<'_, '_> {
    /// Records attempt `c` as `part` ran it (in btc's engine or outside),
    /// and says what it ended in.
    pub(super) fn close(&mut self, c: Compiled, part: RunPart, o: Outcome) -> Ran {
        let ran = Ran {
            status: part.status,
            done: o.done,
            preempted: part.preempted,
            preempting: o.preempting,
            order_faults: o.order_faults,
            discarded: o.discarded,
            added: o.added,
            end_tick: part.end_tick,
            last_record: part.records.last().cloned(),
        };
        self.out.attempts.push(c.record(part));
        ran
    }

    /// Compiles and runs attempt `attempt` for `goal`, and records it.
    pub(super) fn attempt(
        &mut self,
        attempt: usize,
        goal: &Formula,
        planned: Planned,
        for_priority: bool,
    ) -> Result<Ran, LoopError> {
        let (made, planning_ms, expanded) = match planned {
            Planned::Made { plan, ms, expanded } => (Some(plan), ms, expanded),
            _ => (None, 0.0, 0),
        };
        let source = if made.is_some() { "planned" } else { "given" };
        let tc = Instant::now();
        let ir = execution::compile(self.db, self.job, &self.plan_path, made)
            .map_err(LoopError::Compile)?;
        let compile_ms = tc.elapsed().as_secs_f64() * 1e3;
        let plan: Vec<String> = ir.steps.iter().map(|s| s.display()).collect();
        let goal_text = goal.to_string();
        let trace = self.opts.trace;
        if trace {
            push_event(
                self.trace_out,
                serde_json::json!({
                    "event": "plan", "attempt": attempt, "tick": self.carry.tick,
                    "source": source, "goal": goal_text, "steps": plan,
                }),
            );
        }
        let compiled = Compiled {
            attempt,
            source,
            goal_text,
            plan,
            planning_ms,
            expanded,
            compile_ms,
            for_priority,
        };
        if self.execution.is_outside() {
            self.run_outside(compiled, goal, &ir)
        } else {
            self.run_in_engine(compiled, goal, &TreeDoc::from_ir(&ir))
        }
    }

    /// Runs the attempt's tree in btc's engine, in the carried world, with
    /// the scenario's faults and the embedder's installed leaves.
    fn run_in_engine(
        &mut self,
        c: Compiled,
        goal: &Formula,
        doc: &TreeDoc,
    ) -> Result<Ran, LoopError> {
        let trace = self.opts.trace;
        // Run, in the carried world.
        let mut kb = self.carry.kb(&self.world);
        let g = goal_formula(&mut kb, goal)?;
        kb.set_goal(g);
        let mut engine =
            execution::start(doc, kb, self.opts.engine.clone(), self.carry.tick, trace)
                .map_err(LoopError::Tree)?;
        self.execution.install(&mut engine);
        match self.carry.faults.take() {
            Some(f) => engine.restore_faults(f),
            None => {
                if let Some(s) = self.scenario {
                    engine.add_faults(s).map_err(LoopError::Scenario)?;
                }
            }
        }
        let start_tick = engine.tick;
        let tr = Instant::now();
        let trace_out = &mut *self.trace_out;
        // A high-priority order whose goal does not hold preempts the plan.
        let (status, preempted) = engine.run_until(self.opts.max_ticks, |e| {
            if let Some(t) = e.observer_mut::<JsonlTrace>() {
                let _ = t.drain(trace_out);
            }
            e.kb.as_ref()
                .is_some_and(|kb| !kb.unmet_extra_goals().is_empty())
        });
        let run_ms = tr.elapsed().as_secs_f64() * 1e3;
        let sum = engine.summary(status);
        let done = !preempted && sum.success();
        let end_tick = engine.tick;
        let waited = if done || (status == Status::Running && !preempted) {
            0
        } else {
            engine.wait_for_faults(self.opts.max_ticks)
        };
        let preempting: Vec<Formula> = if preempted {
            engine
                .kb
                .as_ref()
                .map(Kb::unmet_extra_goals)
                .unwrap_or_default()
        } else {
            Vec::new()
        };
        let order_faults: Vec<String> = sum
            .faults
            .iter()
            .filter(|f| f.kind == FaultKind::HighPriorityOrder.name() && f.met_at == Some(end_tick))
            .map(|f| f.fault.clone())
            .collect();
        self.out.faults = engine.fault_outcomes(done);
        if let Some(t) = engine.observer_mut::<JsonlTrace>() {
            let _ = t.drain(self.trace_out);
        }
        let discarded = engine.discarded_parts();
        let kb = engine.kb.as_mut().expect("built with a KB");
        let reached = done && !c.for_priority;
        let added = carry_over(&mut self.carry, &mut self.out, kb, engine.tick, reached);
        self.carry.faults = Some(engine.take_faults());
        // The engine borrows the shared world the record is kept beside.
        drop(engine);
        Ok(self.close(
            c,
            RunPart {
                run_ms,
                start_tick,
                end_tick,
                status,
                steps_done: sum.steps_done,
                steps_total: sum.steps_total,
                records: sum.records.clone(),
                waited_ticks: waited,
                preempted,
            },
            Outcome {
                done,
                preempting,
                order_faults,
                discarded,
                added,
            },
        ))
    }
}
