//! A compiled tree: every emitter's text, and a run in btc's engine against
//! the problem's world with the embedder's own leaves.

use crate::diagnostic::{Diagnostic, Error};
use crate::faults::Faults;
use btc_agent::faults::FaultsOnEngine;
use btc_emit as emit;
use btc_ir::TreeIr;
use btc_pddl::state::World;
use btc_runtime::engine::{Observer, RunView, TickEvent};
use btc_runtime::{ActionCall, Engine, FaultOutcome, FaultRecord, Kb, Status, TreeDoc};
use serde::Serialize;
use std::sync::Arc;

/// The outputs `btc compile --emit` writes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Target {
    BtcppXml,
    PyTrees,
    Json,
    Dot,
    Mermaid,
    Commands,
}

#[derive(Clone, Debug)]
pub struct Tree {
    ir: Arc<TreeIr>,
    /// Why a py_trees module cannot run this tree as btc's engine does
    /// (empty when it can).
    pytrees_refusals: Vec<Diagnostic>,
}

/// A leaf node id a tree uses, as BT.CPP registers it: what a host that
/// builds the tree in its own factory must provide (or let btc's support
/// library provide: a condition with a formula, a simulated action).
#[derive(Clone, Debug, PartialEq, Eq, Serialize)]
pub struct NodeInfo {
    pub id: String,
    /// `action` or `condition`.
    pub kind: &'static str,
    pub ports: Vec<PortInfo>,
    /// For a condition the rules define by a formula: the formula over
    /// `?port` variables, as PDDL text.
    pub formula: Option<String>,
}

#[derive(Clone, Debug, PartialEq, Eq, Serialize)]
pub struct PortInfo {
    pub name: String,
    /// `input` or `output`.
    pub direction: &'static str,
    /// The rules' type: a PDDL type, or `string`, `int`, `float`, `bool`.
    #[serde(rename = "type")]
    pub ty: String,
}

/// How a run goes.
#[derive(Clone, Debug)]
pub struct RunOptions {
    /// Ticks a simulated action (one no handler takes) stays RUNNING.
    pub ticks_per_action: u32,
    /// Simulated milliseconds per tick (what `timeout` and `delay` count).
    pub ms_per_tick: u64,
    pub max_ticks: u64,
}

impl Default for RunOptions {
    fn default() -> Self {
        RunOptions {
            ticks_per_action: 1,
            ms_per_tick: 10,
            max_ticks: 100_000,
        }
    }
}

/// A leaf the embedder implements, for every action leaf of one node id.
pub type Handler<'h> = Box<dyn FnMut(&ActionCall<'_>) -> Status + 'h>;

/// Told that a RUNNING leaf was halted (a reactive condition failed above
/// it, a Parallel finished, the run stopped at its tick limit): BT.CPP's
/// `onHalted`, where an action client cancels its goal. The call names the
/// leaf and its ports as its last tick saw them.
pub type HaltHandler<'h> = Box<dyn FnMut(&ActionCall<'_>) + 'h>;

/// The embedder's leaves for [`Tree::run`]: per node id, what ticks its
/// action leaves and what hears of their halts.
#[derive(Default)]
pub struct Leaves<'h> {
    tick: Vec<(String, Handler<'h>)>,
    halt: Vec<(String, HaltHandler<'h>)>,
}

impl<'h> Leaves<'h> {
    pub fn new() -> Leaves<'h> {
        Leaves::default()
    }

    /// `tick` ticks every action leaf with node id `id`.
    pub fn action(
        mut self,
        id: impl Into<String>,
        tick: impl FnMut(&ActionCall<'_>) -> Status + 'h,
    ) -> Leaves<'h> {
        self.tick.push((id.into(), Box::new(tick)));
        self
    }

    /// `halted` hears of every halt of a RUNNING leaf with node id `id`.
    pub fn on_halt(
        mut self,
        id: impl Into<String>,
        halted: impl FnMut(&ActionCall<'_>) + 'h,
    ) -> Leaves<'h> {
        self.halt.push((id.into(), Box::new(halted)));
        self
    }
}

impl<'h> From<Vec<(String, Handler<'h>)>> for Leaves<'h> {
    fn from(tick: Vec<(String, Handler<'h>)>) -> Leaves<'h> {
        Leaves {
            tick,
            halt: Vec::new(),
        }
    }
}

/// A step started or ended, at a tick.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
pub struct StepEvent {
    pub tick: u64,
    pub started: bool,
    /// 0-based plan step.
    pub step: u32,
}

/// What a run came to.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct RunReport {
    pub status: Status,
    pub ticks: u64,
    pub steps_done: usize,
    pub steps_total: usize,
    /// Whether the problem's goal holds at the end, and if not, why.
    pub goal_reached: bool,
    pub goal_failure: Option<String>,
    pub steps: Vec<StepEvent>,
    pub faults: Vec<FaultOutcome>,
    pub records: Vec<FaultRecord>,
    /// The final facts and values, sorted.
    pub kb: Vec<String>,
}

impl RunReport {
    pub fn success(&self) -> bool {
        self.status == Status::Success && self.goal_reached
    }
}

impl Tree {
    pub(crate) fn new(ir: Arc<TreeIr>, pytrees_refusals: Vec<Diagnostic>) -> Tree {
        Tree {
            ir,
            pytrees_refusals,
        }
    }

    /// The tree IR itself, for crates that build on btc's internals.
    pub fn ir(&self) -> &Arc<TreeIr> {
        &self.ir
    }

    /// The plan's steps, `(action arg ...)`.
    pub fn steps(&self) -> Vec<String> {
        self.ir.steps.iter().map(|s| s.display()).collect()
    }

    /// The leaf node ids the tree uses, with their ports (and formula, for
    /// a condition the rules define by one), in the tree's model order.
    pub fn nodes(&self) -> Vec<NodeInfo> {
        self.ir
            .nodes
            .iter()
            .map(|m| NodeInfo {
                id: m.id.clone(),
                kind: match m.kind {
                    btc_ir::LeafKind::Action => "action",
                    btc_ir::LeafKind::Condition => "condition",
                },
                ports: m
                    .ports
                    .iter()
                    .map(|p| PortInfo {
                        name: p.name.clone(),
                        direction: match p.direction {
                            btc_ir::PortDirection::Input => "input",
                            btc_ir::PortDirection::Output => "output",
                        },
                        ty: p.ty.clone(),
                    })
                    .collect(),
                formula: m.formula.as_ref().map(ToString::to_string),
            })
            .collect()
    }

    /// The tree in a target's form. py_trees is refused (with the
    /// diagnostics that say where) when the tree uses what a py_trees
    /// module cannot run as btc's engine does.
    pub fn emit(&self, target: Target) -> Result<String, Error> {
        let format = match target {
            Target::BtcppXml => emit::Format::Btcpp,
            Target::PyTrees => {
                if !self.pytrees_refusals.is_empty() {
                    return Err(Error::new(self.pytrees_refusals.clone()));
                }
                emit::Format::Pytrees
            }
            Target::Json => emit::Format::Json,
            Target::Dot => emit::Format::Dot,
            Target::Mermaid => emit::Format::Mermaid,
            Target::Commands => emit::Format::Commands,
        };
        Ok(emit::emit(&self.ir, format, &emit::Options::default()))
    }

    /// The py_trees module `btc compile --emit pytrees --runtime import`
    /// writes: the tree as data (world, plan, leaf classes, trees) over
    /// btc's py_trees runtime. Refused as [`Tree::emit`] refuses it.
    pub fn pytrees_module(&self) -> Result<String, Error> {
        if !self.pytrees_refusals.is_empty() {
            return Err(Error::new(self.pytrees_refusals.clone()));
        }
        let opts = emit::Options {
            runtime: emit::pytrees::Runtime::Import,
            ..emit::Options::default()
        };
        Ok(emit::emit(&self.ir, emit::Format::Pytrees, &opts))
    }

    pub fn to_btcpp_xml(&self) -> String {
        emit::emit(&self.ir, emit::Format::Btcpp, &emit::Options::default())
    }

    pub fn to_json(&self) -> String {
        emit::emit(&self.ir, emit::Format::Json, &emit::Options::default())
    }

    pub fn to_dot(&self) -> String {
        emit::emit(&self.ir, emit::Format::Dot, &emit::Options::default())
    }

    pub fn to_mermaid(&self) -> String {
        emit::emit(&self.ir, emit::Format::Mermaid, &emit::Options::default())
    }

    /// Runs the tree in btc's engine against the problem's initial state:
    /// action leaves whose id `leaves` names tick the embedder's code (a
    /// `Vec` of `(id, handler)` or a [`Leaves`], which also takes halt
    /// handlers), the others are simulated as `btc run` simulates them.
    pub fn run<'h>(
        &self,
        options: &RunOptions,
        leaves: impl Into<Leaves<'h>>,
        faults: Option<&Faults>,
    ) -> Result<RunReport, Error> {
        let leaves = leaves.into();
        let world = World::new(self.ir.world.clone()).map_err(|m| {
            Error::one(Diagnostic::without_place(
                btc_pddl::diagnostic::codes::X_WORLD.id,
                format!("the tree's world does not fit together: {m}"),
                &self.ir.problem,
            ))
        })?;
        let doc = TreeDoc::from_ir(&self.ir);
        let opts = btc_runtime::Options {
            ticks_per_action: options.ticks_per_action,
            ms_per_tick: options.ms_per_tick,
        };
        let tree_error = |e: btc_runtime::LoadError| crate::faults::load_error(&e, &self.ir.plan);
        let mut engine = Engine::build(&doc, Some(Kb::new(&world)), opts).map_err(tree_error)?;
        let unknown = |id: &str| {
            Error::one(
                Diagnostic::without_place(
                    btc_pddl::diagnostic::codes::X_UNKNOWN_NODE.id,
                    format!("no action leaf of this tree has the id `{id}`"),
                    &self.ir.rules,
                )
                .hint("a handler takes the action leaves of one node id the rules declare"),
            )
        };
        for (id, h) in leaves.tick {
            if engine.set_action_handler(&id, h) == 0 {
                return Err(unknown(&id));
            }
        }
        for (id, h) in leaves.halt {
            if engine.set_halt_handler(&id, h) == 0 {
                return Err(unknown(&id));
            }
        }
        if let Some(f) = faults {
            engine.add_faults(&f.scenario).map_err(|e| f.error(&e))?;
        }
        engine.observe(StepLog::default());
        let status = engine.run(options.max_ticks, |_| {});
        let steps = engine.take_observer::<StepLog>().unwrap_or_default().0;
        let sum = engine.summary(status);
        Ok(RunReport {
            status,
            ticks: sum.ticks,
            steps_done: sum.steps_done,
            steps_total: sum.steps_total,
            goal_reached: sum.goal_reached.unwrap_or(true),
            goal_failure: sum.goal_failure,
            steps,
            faults: sum.faults,
            records: sum.records,
            kb: engine.kb.as_ref().map(Kb::snapshot).unwrap_or_default(),
        })
    }
}

/// The observer of a run's step starts and ends (all a report keeps of
/// its events).
#[derive(Default)]
struct StepLog(Vec<StepEvent>);

impl Observer for StepLog {
    fn observe(&mut self, event: &TickEvent, _: &RunView<'_>) {
        let (tick, started, step) = match *event {
            TickEvent::StepStarted { tick, step } => (tick, true, step),
            TickEvent::StepFinished { tick, step } => (tick, false, step),
            _ => return,
        };
        self.0.push(StepEvent {
            tick,
            started,
            step,
        });
    }
}
