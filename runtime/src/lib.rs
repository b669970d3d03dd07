//! The btc runtime: a behavior-tree engine with BehaviorTree.CPP v4 tick
//! semantics that runs btc's tree IR and BT.CPP XML against a simulated
//! world (a PDDL knowledge base), with an optional queued robot controller
//! and a hook for the caller's fault injector (the ARIAC faults are one,
//! in `btc-agent`). Nothing here prints; `btc run` does.
//!
//! Loading: [`spec::TreeDoc`] from the IR ([`spec::TreeDoc::from_ir`]) or
//! XML ([`xml::parse`]), or a tree file of either kind ([`load_tree`]);
//! then [`Engine::build`] compiles it into a flat arena and
//! [`Engine::run`] ticks it. A JSON IR carries its world; a BT.CPP XML
//! tree runs in the world of PDDL files.

pub mod btlog;
pub mod controller;
pub mod engine;
pub mod error;
pub mod handler;
pub mod include;
pub mod kb;
pub mod observers;
pub mod script;
pub mod spec;
pub mod xml;

pub use controller::{Command, Controller};
pub use engine::{
    Engine, FaultOutcome, FaultRecord, Injection, Injector, Interference, Options, Status, Value,
};
pub use error::LoadError;
pub use handler::{ActionCall, ActionHandler, HaltHandler};
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

/// A tree file as read.
#[derive(Debug)]
#[allow(clippy::large_enum_variant)] // one per run
pub enum Loaded {
    /// BT.CPP XML: its world comes from PDDL files.
    Xml(TreeDoc),
    /// btc's JSON IR, with the world it runs in.
    Ir(btc_ir::TreeIr),
    /// A version-1 JSON IR: no world of its own; the PDDL files it names.
    IrV1(btc_ir::json::V1),
}

/// Reads a tree file: BT.CPP XML when it starts with `<`, btc's JSON IR
/// (any version) when it starts with `{`.
pub fn load_tree(text: &str) -> Result<Loaded, LoadError> {
    use btc_pddl::diagnostic::codes;
    match text.trim_start().chars().next() {
        Some('<') => xml::parse(text).map(Loaded::Xml),
        Some('{') => match btc_ir::json::decode(text) {
            Ok(btc_ir::json::IrFile::Current(ir)) => Ok(Loaded::Ir(ir)),
            Ok(btc_ir::json::IrFile::V1(v1)) => Ok(Loaded::IrV1(v1)),
            Err(e) => {
                let mut err = LoadError::new(
                    codes::X_TREE_SYNTAX,
                    format!("this is not btc's JSON tree IR: {}", e.message),
                )
                .hint("write it with `btc compile RULES --plan PLAN --emit json`");
                if e.line > 0 {
                    err = err.at(spec::line_col_offset(text, e.line, e.column));
                }
                Err(err)
            }
        },
        _ => Err(LoadError::new(
            codes::X_TREE_SYNTAX,
            "this is neither BT.CPP XML nor btc's JSON tree IR",
        )
        .at(0)
        .hint("give a file written by `btc compile --emit btcpp` or `--emit json`, or by Groot2")),
    }
}
