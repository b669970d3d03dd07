//! btc as a library: what the `btc` command does, callable from a robot's
//! own process. Plain values cross this boundary (paths, texts, plans,
//! trees, diagnostics); the incremental database and the IR stay inside.
//!
//! ```no_run
//! use btc_api::{Project, Target};
//! let mut project = Project::open("examples/ariac/rules.btrules")?;
//! let plan = project.plan(None)?;
//! let tree = project.compile(&plan, None)?;
//! println!("{}", tree.emit(Target::BtcppXml)?);
//! # Ok::<(), btc_api::Error>(())
//! ```
//!
//! - [`Project`]: a rules file and what it names, from disk or from texts;
//!   `check`, `plan`, `compile`.
//! - [`Plan`]: a plan value (read, made, written back).
//! - [`Tree`]: a compiled tree; every emitter's text, and a run in btc's
//!   engine with the embedder's own leaves ([`Tree::run`]).
//! - [`Agent`]: the closed loop (plan, compile, run, fault, replan) with
//!   the embedder's leaves, or with its own executor ([`Executor`]: a
//!   py_trees or BehaviorTree.CPP tree): the loop `btc run --replan` runs.
//! - [`Diagnostic`] and [`Error`]: what went wrong, where, what to do.

mod agent;
mod diagnostic;
mod executor;
mod faults;
mod plan;
mod project;
mod tree;

pub use agent::{
    Agent, AgentOptions, AgentReport, Attempt, FaultOutcome, FaultRecord, Replan, Unreachable,
};
pub use btc_runtime::{ActionCall, Status, Value};
pub use diagnostic::{Diagnostic, Error, Fix, Label, Position, Severity};
pub use executor::{AttemptInput, Executed, Executor, Record, ReportedFault};
pub use faults::Faults;
pub use plan::{Plan, Step};
pub use project::{Project, DOMAIN_TEXT, PROBLEM_TEXT, RULES_TEXT};
pub use tree::{
    HaltHandler, Handler, Leaves, NodeInfo, PortInfo, RunOptions, RunReport, StepEvent, Target,
    Tree,
};

/// btc's version.
pub const VERSION: &str = env!("CARGO_PKG_VERSION");

/// A plan for the problem at `problem` in the domain at `domain`, by btc's
/// planner, without rules.
pub fn plan(
    domain: impl AsRef<std::path::Path>,
    problem: impl AsRef<std::path::Path>,
) -> Result<Plan, Error> {
    project::plan_files(domain.as_ref(), problem.as_ref())
}

/// The Rust examples of docs/embedding.md, compiled as doc tests so that
/// the page keeps up with the API.
#[cfg(doctest)]
#[doc = include_str!("../../docs/embedding.md")]
pub struct EmbeddingGuide;
