//! The btc runtime: a behavior-tree engine with BehaviorTree.CPP v4 tick
//! semantics that runs btc's tree IR and BT.CPP XML against a simulated
//! world (a PDDL knowledge base), with an optional queued robot controller
//! and injected ARIAC faults. Nothing here prints; `btc run` does.
//!
//! Loading: [`spec::TreeDoc`] from the IR ([`spec::TreeDoc::from_ir`]),
//! JSON ([`spec::TreeDoc::from_json`]) or XML ([`xml::parse`]); then
//! [`Engine::build`] compiles it into a flat arena and [`Engine::run`]
//! ticks it.

pub mod btlog;
pub mod controller;
pub mod engine;
pub mod error;
pub mod faults;
pub mod handler;
pub mod kb;
pub mod spec;
pub mod xml;

pub use controller::{Command, Controller};
pub use engine::{Engine, FaultRecord, Options, Status, Value};
pub use error::LoadError;
pub use faults::{FaultKind, FaultOutcome, Scenario};
pub use handler::{ActionCall, ActionHandler};
pub use kb::Kb;
pub use spec::TreeDoc;

use serde::Serialize;

/// What a run came to.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Summary {
    pub status: Status,
    pub ticks: u64,
    pub steps_done: usize,
    pub steps_total: usize,
    /// Whether the goal holds in the final KB (`None`: no problem given),
    /// and if not, why.
    pub goal_reached: Option<bool>,
    pub goal_failure: Option<String>,
    pub faults: Vec<FaultOutcome>,
    pub records: Vec<FaultRecord>,
}

impl Summary {
    /// The tree succeeded and the goal (if any) holds.
    pub fn success(&self) -> bool {
        self.status == Status::Success && self.goal_reached != Some(false)
    }
}

impl<'w> Engine<'w> {
    /// The summary after [`Engine::run`] returned `status`.
    pub fn summary(&self, status: Status) -> Summary {
        let goal = self.goal();
        let ok = status == Status::Success && goal.as_ref().is_none_or(|g| g.0);
        Summary {
            status,
            ticks: self.tick,
            steps_done: self.steps_done(),
            steps_total: self.steps_total(),
            goal_reached: goal.as_ref().map(|g| g.0),
            goal_failure: goal.and_then(|g| g.1),
            faults: self.fault_outcomes(ok),
            records: self.records.clone(),
        }
    }
}

/// Reads a tree file: BT.CPP XML when it starts with `<`, btc's JSON IR
/// when it starts with `{`. The IR comes back too (it names its problem).
pub fn load_tree(text: &str) -> Result<(TreeDoc, Option<btc_ir::TreeIr>), LoadError> {
    match text.trim_start().chars().next() {
        Some('<') => xml::parse(text).map(|d| (d, None)),
        Some('{') => TreeDoc::from_json(text).map(|(d, ir)| (d, Some(ir))),
        _ => Err(LoadError::new(
            btc_pddl::diagnostic::codes::X_TREE_SYNTAX,
            "this is neither BT.CPP XML nor btc's JSON tree IR",
        )
        .at(0)
        .hint("give a file written by `btc compile --emit btcpp` or `--emit json`, or by Groot2")),
    }
}
