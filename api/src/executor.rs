//! The agent's attempts run by the embedder's own executor: a py_trees or
//! BehaviorTree.CPP tree ticking the embedder's behaviours. The executor
//! gets each attempt's tree and the KB to start from, and says how the run
//! went in plain values: the status, the KB it left, why nodes failed, and
//! the faults its behaviours reported ("the gripper dropped the part").

use crate::tree::Tree;
use btc_agent::faults::{Blackout, FaultKind, FaultSpec, Trigger};
use btc_agent::replan as core;
use btc_pddl::logic::{decode, Formula, InitFact, NumExpr};
use btc_runtime::{FaultRecord, Status};

/// Runs the attempts of [`crate::Agent::run_with`].
pub trait Executor {
    /// Ticks `attempt.tree` from `attempt.state` until it ends (or
    /// `attempt.max_ticks`) and says how it went. A failing tree is an
    /// `Ok` with status FAILURE; `Err` means the executor itself broke,
    /// and the loop stops with its message.
    fn execute(&mut self, attempt: &AttemptInput) -> Result<Executed, String>;
}

/// One attempt of the loop, as the executor gets it.
#[derive(Clone, Debug)]
pub struct AttemptInput {
    /// 1-based.
    pub attempt: usize,
    pub tree: Tree,
    /// The KB to start from: true facts `(at r1 a)`, then fluent values
    /// `(= (f a) 3)`, sorted. It replaces the problem's initial state.
    pub state: Vec<String>,
    /// The attempt's goal.
    pub goal: String,
    /// The tick the loop is at, and the most ticks the attempt may run.
    pub tick: u64,
    pub max_ticks: u64,
}

/// How an attempt went.
#[derive(Clone, Debug)]
pub struct Executed {
    /// SUCCESS, FAILURE, or RUNNING if it ran out of ticks.
    pub status: Status,
    /// Every true fact and fluent value when the run ended, in the form of
    /// [`AttemptInput::state`].
    pub state: Vec<String>,
    pub ticks: u64,
    /// Plan steps that ended.
    pub steps_done: usize,
    /// Why nodes failed, the last one the failure the loop replans after.
    pub records: Vec<Record>,
    pub faults: Vec<ReportedFault>,
}

/// A failing node.
#[derive(Clone, Debug, Default)]
pub struct Record {
    /// The node's id (its class: `Pick`) and its name in the tree.
    pub node_id: String,
    pub node_name: String,
    pub reason: String,
    /// The 1-based plan step it belongs to, if any.
    pub step: Option<usize>,
    /// Ticks into the attempt.
    pub tick: u64,
    /// The labels of reported faults the failure is due to.
    pub faults: Vec<String>,
}

/// A fault a behaviour reports: one of the eight ARIAC 2023 challenges,
/// with what a scenario file would say of it (docs/runtime.md). It changes
/// the KB as the scenario's fault would (a faulty part is gone from the
/// KB), and the loop replans as `btc run --replan` does.
#[derive(Clone, Debug, Default)]
pub struct ReportedFault {
    /// `faulty_part`, `faulty_gripper`, `robot_malfunction`,
    /// `flipped_part`, `sensor_blackout`, `high_priority_order`,
    /// `insufficient_parts` or `human_too_close`.
    pub kind: String,
    /// Its label in the report (default: the kind).
    pub name: Option<String>,
    pub robot: Option<String>,
    pub part: Option<String>,
    pub duration: Option<u64>,
    /// Facts it made false and true (a flipped part).
    pub retract: Vec<String>,
    pub add: Vec<String>,
    /// A high-priority order's goal.
    pub goal: Option<String>,
    /// When it happened: ticks into the attempt.
    pub tick: u64,
}

impl ReportedFault {
    /// The fault of a scenario as a behaviour would report it.
    pub(crate) fn of(spec: &FaultSpec) -> ReportedFault {
        let texts = |v: &[btc_pddl::logic::Atom]| v.iter().map(ToString::to_string).collect();
        ReportedFault {
            kind: spec.kind.name().to_owned(),
            name: spec.name.clone(),
            robot: spec.robot.clone(),
            part: spec.part.clone(),
            duration: spec.duration,
            retract: spec.retract.as_deref().map(texts).unwrap_or_default(),
            add: texts(&spec.add),
            goal: spec.goal.as_ref().map(ToString::to_string),
            tick: 0,
        }
    }

    /// The fault as the runtime's fault specification.
    fn spec(&self, start: u64) -> Result<FaultSpec, String> {
        let kind = FaultKind::from_name(&self.kind).ok_or_else(|| {
            let kinds: Vec<&str> = FaultKind::ALL.iter().map(|k| k.name()).collect();
            format!(
                "`{}` is not a fault kind; the kinds are {}",
                self.kind,
                kinds.join(", ")
            )
        })?;
        let atoms = |list: &[String]| -> Result<Vec<_>, String> {
            list.iter()
                .map(|t| decode::atom(t).map_err(|m| format!("`{t}` is not a PDDL fact: {m}")))
                .collect()
        };
        let goal = match &self.goal {
            Some(g) => Some(
                decode::formula(g)
                    .map_err(|m| format!("goal `{g}` is not a PDDL condition: {m}"))?,
            ),
            None => None,
        };
        Ok(FaultSpec {
            kind,
            name: self.name.clone(),
            trigger: Trigger::Tick(start.saturating_add(self.tick)),
            robot: self.robot.clone(),
            part: self.part.clone(),
            duration: self.duration,
            retract: (!self.retract.is_empty())
                .then(|| atoms(&self.retract))
                .transpose()?,
            add: atoms(&self.add)?,
            goal,
            blackout: Blackout::Running,
        })
    }
}

/// A KB entry as the executor wrote it: `(p a b)` or `(= (f a) 3)`.
pub(crate) fn fact(text: &str) -> Result<InitFact, String> {
    let bad = |m: String| format!("`{text}` is not a fact or a fluent value: {m}");
    match decode::formula(text).map_err(bad)? {
        Formula::Atom(a) => Ok(InitFact::Atom(a)),
        Formula::Compare(_, l, r) => match (*l, *r) {
            (NumExpr::Fluent(a), NumExpr::Number(v)) => Ok(InitFact::Value(a, v)),
            _ => Err(bad("a value is written `(= (f a) 3)`".into())),
        },
        _ => Err(bad("write one atom, `(on a b)`".into())),
    }
}

/// The embedder's executor as the loop's: values in, values out.
pub(crate) struct Adapter<'e> {
    pub executor: &'e mut dyn Executor,
}

impl core::Executor for Adapter<'_> {
    fn execute(&mut self, h: &core::Handoff<'_>) -> Result<core::Executed, String> {
        let refusals =
            btc_lang::targets::refusals(h.db, h.job, h.ir, btc_lang::targets::Target::Pytrees);
        let sources = h.db.sources_for(&refusals);
        let input = AttemptInput {
            attempt: h.attempt,
            tree: Tree::new(
                h.ir.clone(),
                crate::diagnostic::convert(&refusals, &sources),
            ),
            state: h.state.clone(),
            goal: h.goal.to_string(),
            tick: h.tick,
            max_ticks: h.max_ticks,
        };
        let ex = self.executor.execute(&input)?;
        let state = ex
            .state
            .iter()
            .map(|f| fact(f))
            .collect::<Result<Vec<_>, _>>()?;
        let faults = ex
            .faults
            .iter()
            .map(|f| f.spec(h.tick).map_err(|m| format!("a reported fault: {m}")))
            .collect::<Result<Vec<_>, _>>()?;
        let records = ex
            .records
            .iter()
            .map(|r| FaultRecord {
                tick: h.tick.saturating_add(r.tick),
                node: FaultRecord::OUTSIDE_ENGINE,
                node_id: r.node_id.clone(),
                node_name: r.node_name.clone(),
                step: r.step,
                action: r
                    .step
                    .and_then(|s| h.ir.steps.get(s.wrapping_sub(1)))
                    .map(|s| s.label()),
                reason: r.reason.clone(),
                faults: r.faults.clone(),
                kb: ex.state.clone(),
            })
            .collect();
        Ok(core::Executed {
            status: ex.status,
            state,
            ticks: ex.ticks,
            steps_done: ex.steps_done,
            records,
            faults,
        })
    }
}
