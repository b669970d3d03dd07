//! An attempt run outside btc's engine. The embedder's executor (a py_trees
//! tree, a BehaviorTree.CPP tree) ticks the attempt's tree with its own
//! behaviours and says how it went: the status, the KB it left, the
//! failure records, and the faults its behaviours reported. From there the
//! loop goes on as after a run in the engine: a reported fault changes the
//! KB as the same fault in a scenario would, a discarded part gets a spare,
//! an order's goal comes first.

use super::attempt::{carry_over, Compiled, Outcome, Ran, RunPart};
use super::carry::goal_formula;
use super::{LoopError, Run};
use crate::faults::{FaultKind, FaultOutcome, FaultSpec, Trigger};
use btc_ir::TreeIr;
use btc_lang::db::{CompileJob, Database};
use btc_pddl::diagnostic::codes;
use btc_pddl::logic::{Formula, InitFact};
use btc_pddl::state::Key;
use btc_runtime::engine::{Engine, FaultRecord, Status};
use btc_runtime::error::LoadError;
use std::sync::Arc;
use std::time::Instant;

/// Runs an attempt's tree somewhere else than btc's engine.
pub trait Executor {
    /// Ticks `handoff`'s tree from its state to the end (or to
    /// `handoff.max_ticks`) and says how it went. `Err`: the executor
    /// itself broke (not the tree: a failing tree is an `Executed` with
    /// status FAILURE); the loop stops with the message.
    fn execute(&mut self, handoff: &Handoff<'_>) -> Result<Executed, String>;
}

/// One attempt, as handed to an executor.
pub struct Handoff<'a> {
    /// 1-based.
    pub attempt: usize,
    /// The database and job the tree was compiled in (to emit it, and to
    /// ask what a target cannot express).
    pub db: &'a Database,
    pub job: CompileJob,
    pub ir: &'a Arc<TreeIr>,
    /// The KB to start from: the true facts, then the fluents' values
    /// `(= (f a) 3)`, sorted.
    pub state: Vec<String>,
    /// This attempt's goal (a priority order's, or the whole adjusted one).
    pub goal: &'a Formula,
    /// The tick the loop is at, and the most the attempt may run.
    pub tick: u64,
    pub max_ticks: u64,
}

/// How an attempt went outside the engine.
#[derive(Clone, Debug)]
pub struct Executed {
    /// SUCCESS, FAILURE, or RUNNING when it ran out of ticks.
    pub status: Status,
    /// The KB the run left: every true fact and every fluent's value.
    pub state: Vec<InitFact>,
    pub ticks: u64,
    pub steps_done: usize,
    /// Why nodes failed, the last one the failure the loop replans after.
    pub records: Vec<FaultRecord>,
    /// The faults the behaviours reported, each with the tick it happened
    /// at as its trigger.
    pub faults: Vec<FaultSpec>,
}

/// Where an attempt runs.
pub(super) enum Execution<'a, 'l> {
    /// In btc's engine, with the embedder's leaves (if any) installed.
    Engine(Option<super::InstallLeaves<'a, 'l>>),
    Outside(&'a mut (dyn Executor + 'l)),
}

impl Execution<'_, '_> {
    pub(super) fn is_outside(&self) -> bool {
        matches!(self, Execution::Outside(_))
    }

    pub(super) fn install(&mut self, engine: &mut Engine<'_>) {
        if let Execution::Engine(Some(install)) = self {
            install(engine);
        }
    }
}

fn kb_error(msg: String) -> LoopError {
    LoopError::Tree(LoadError::new(codes::X_KB, msg))
}

impl Run<'_, '_> {
    /// Hands the attempt's tree to the executor, and takes back the KB, the
    /// records and the reported faults as the engine's run would leave them.
    pub(super) fn run_outside(
        &mut self,
        c: Compiled,
        goal: &Formula,
        ir: &Arc<TreeIr>,
    ) -> Result<Ran, LoopError> {
        let mut kb = self.carry.kb(&self.world);
        let g = goal_formula(&mut kb, goal)?;
        kb.set_goal(g);
        let start_tick = self.carry.tick;
        // The tree the executor gets starts where the loop is: its world's
        // initial state is the carried KB and its goal the attempt's, so
        // every emitter's output (a py_trees module, the KB of a
        // BehaviorTree.CPP tree) starts there too.
        let mut here = (**ir).clone();
        here.world.init = self.world.init_of(&kb.state);
        here.world.goal = Some(goal.clone());
        let ir = &Arc::new(here);
        let handoff = Handoff {
            attempt: c.attempt,
            db: self.db,
            job: self.job,
            ir,
            state: kb.snapshot(),
            goal,
            tick: start_tick,
            max_ticks: self.opts.max_ticks.saturating_sub(start_tick),
        };
        let Execution::Outside(executor) = &mut self.execution else {
            unreachable!("run_outside runs only with an executor");
        };
        let tr = Instant::now();
        let ex = executor
            .execute(&handoff)
            .map_err(|m| kb_error(format!("the executor stopped attempt {}: {m}", c.attempt)))?;
        let run_ms = tr.elapsed().as_secs_f64() * 1e3;
        let end_tick = start_tick.saturating_add(ex.ticks);

        // The KB the run left, then what the reported faults did to it.
        let mut facts = Vec::new();
        kb.state.fluents.clear();
        for f in &ex.state {
            match f {
                InitFact::Atom(a) => facts.push(
                    kb.atom_key(a)
                        .map_err(|m| kb_error(format!("the executor's KB holds `{a}`: {m}")))?,
                ),
                InitFact::Value(a, v) => {
                    let k = kb.world.fluent_key(a).map_err(|m| {
                        kb_error(format!("the executor's KB gives `{a}` a value: {m}"))
                    })?;
                    kb.state.fluents.insert(k, *v);
                }
            }
        }
        kb.state.facts.clear();
        // Through `apply_keys`: the derived atoms follow the new facts.
        kb.apply_keys(facts, Vec::new());
        let mut discarded = Vec::new();
        let mut orders = Vec::new();
        let mut happened = self.carry.faults.take().unwrap_or_default();
        for spec in &ex.faults {
            self.check_reported(&kb, spec)?;
            let (add, retract): (Vec<Key>, Vec<Key>) = spec.changes(&kb);
            let shown = retract.iter().chain(&add).map(|k| kb.show(k)).collect();
            let met_at = match spec.trigger {
                Trigger::Tick(t) => t,
                _ => start_tick,
            };
            happened.reported(spec.clone(), met_at, retract.clone(), add.clone(), shown);
            kb.apply_keys(add, retract);
            if let (FaultKind::FaultyPart | FaultKind::InsufficientParts, Some(p)) =
                (spec.kind, &spec.part)
            {
                discarded.push((p.clone(), spec.label()));
            }
            if let Some(g) = &spec.goal {
                let id = goal_formula(&mut kb, g)?;
                kb.add_goal(id);
                orders.push(spec.label());
            }
        }
        // An order's goal that does not hold preempts the plan, as in the
        // engine: the loop reaches it first.
        let preempting = kb.unmet_extra_goals();
        let preempted = !preempting.is_empty();
        let status = if preempted {
            Status::Running
        } else {
            ex.status
        };
        let done = !preempted && ex.status == Status::Success && kb.goal().0;
        // As after a run in the engine: a failed attempt waits for the
        // faults with a duration to end before the loop plans again, and a
        // malfunction's repair gives back what it took.
        let waited = if done || (ex.status == Status::Running && !preempted) {
            0
        } else {
            let until = happened
                .list
                .iter()
                .filter_map(|rt| Some(rt.met_at? + rt.spec.duration?))
                .max()
                .unwrap_or(end_tick)
                .min(self.opts.max_ticks);
            for rt in &happened.list {
                if rt.spec.kind == FaultKind::RobotMalfunction {
                    let back = |v: &[btc_pddl::logic::Atom]| -> Vec<Key> {
                        v.iter().filter_map(|a| kb.atom_key(a).ok()).collect()
                    };
                    let (add, del) = (
                        back(rt.spec.retract.as_deref().unwrap_or(&[])),
                        back(&rt.spec.add),
                    );
                    kb.apply_keys(add, del);
                }
            }
            until.saturating_sub(end_tick)
        };
        let end_tick_waited = end_tick + waited;
        let reached = done && !c.for_priority;
        let added = carry_over(
            &mut self.carry,
            &mut self.out,
            &mut kb,
            end_tick_waited,
            reached,
        );
        self.carry.faults = Some(happened);
        self.note_reported(&ex, start_tick, done);
        let steps_total = ir.steps.len();
        let order_faults = if preempted { orders } else { Vec::new() };
        Ok(self.close(
            c,
            RunPart {
                run_ms,
                start_tick,
                end_tick,
                status,
                steps_done: ex.steps_done.min(steps_total),
                steps_total,
                records: ex.records.clone(),
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

    /// A reported fault is held to what a scenario's fault must say, and
    /// its objects and facts must be the problem's.
    fn check_reported(&self, kb: &btc_runtime::Kb<'_>, spec: &FaultSpec) -> Result<(), LoopError> {
        let label = spec.label();
        if let Some(m) = spec.missing() {
            return Err(kb_error(format!("the reported fault `{label}`: {m}")));
        }
        for o in [&spec.robot, &spec.part].into_iter().flatten() {
            if kb.object(o).is_none() {
                return Err(kb_error(format!(
                    "the reported fault `{label}`: `{o}` is not an object of the problem"
                )));
            }
        }
        for a in spec.retract.iter().flatten().chain(&spec.add) {
            kb.atom_key(a)
                .map_err(|m| kb_error(format!("the reported fault `{label}`: `{a}`: {m}")))?;
        }
        Ok(())
    }

    /// The reported faults join the loop's list of faults, as a scenario's
    /// would: met at the tick reported, recovered once an attempt reaches
    /// the goal.
    fn note_reported(&mut self, ex: &Executed, tick: u64, done: bool) {
        for f in &mut self.out.faults {
            if done && f.ended.starts_with("not recovered") {
                f.ended = "recovered".to_owned();
            }
        }
        for spec in &ex.faults {
            let label = spec.label();
            let ended = if done {
                "recovered".to_owned()
            } else {
                match ex.records.iter().rev().find(|r| r.faults.contains(&label)) {
                    Some(r) => format!("not recovered: {} failed: {}", r.node_name, r.reason),
                    None => "not recovered".to_owned(),
                }
            };
            let met_at = match spec.trigger {
                Trigger::Tick(t) => t,
                _ => tick,
            };
            self.out.faults.push(FaultOutcome {
                fault: label,
                kind: spec.kind.name(),
                met_at: Some(met_at),
                ended,
            });
        }
    }
}
