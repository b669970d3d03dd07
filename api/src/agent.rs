//! The closed loop as one piece an embedder runs: plan from the problem,
//! compile the plan with the rules, run the tree with the embedder's leaves
//! (the others simulated), and when the tree fails, take the fault record
//! and the knowledge base as the new initial state, adjust the goal (a
//! spare part for a discarded one, a priority order first) and plan again,
//! up to a limit. It is the loop `btc run --replan` runs.

use crate::diagnostic::{convert, Diagnostic, Error};
use crate::executor::{Adapter, Executor};
use crate::faults::Faults;
use crate::project::Project;
use crate::tree::{HaltHandler, Handler, RunOptions};
use btc_agent::{LoopError, LoopOptions};
use btc_runtime::{ActionCall, Engine, Status};
use std::cell::RefCell;
use std::path::{Path, PathBuf};
use std::rc::Rc;

pub use btc_agent::replan::{Attempt, Replan, Unreachable};
pub use btc_runtime::{FaultOutcome, FaultRecord};

/// How the loop runs.
#[derive(Clone, Debug)]
pub struct AgentOptions {
    pub run: RunOptions,
    /// Plans made after a failure, at most (the first plan does not count).
    pub max_replans: usize,
}

impl Default for AgentOptions {
    fn default() -> Self {
        AgentOptions {
            run: RunOptions::default(),
            max_replans: 5,
        }
    }
}

/// What the loop came to: each attempt (its plan, run and fault records),
/// each replan (why, from which step, what changed in the goal), the faults
/// and whether the goal was reached.
#[derive(Clone, Debug, serde::Serialize)]
pub struct AgentReport {
    pub attempts: Vec<Attempt>,
    pub replans: Vec<Replan>,
    pub faults: Vec<FaultOutcome>,
    /// The final goal: the problem's, adjusted by the faults.
    pub goal: String,
    pub goal_reached: bool,
    pub goal_failure: Option<String>,
    pub ticks: u64,
    /// Why the loop stopped short of the goal, as diagnostics (X008, X009,
    /// S004) on the problem's goal.
    pub stopped: Vec<Diagnostic>,
    /// Goal literals no plan reaches from where the loop stopped.
    pub unreachable: Vec<Unreachable>,
}

type Shared = Rc<RefCell<Handler<'static>>>;
type SharedHalt = Rc<RefCell<HaltHandler<'static>>>;

pub struct Agent {
    project: Project,
    problem: Option<PathBuf>,
    leaves: Vec<(String, Shared)>,
    halts: Vec<(String, SharedHalt)>,
}

impl Agent {
    /// An agent for `problem` (a path; `None`: the project's problem).
    pub fn new(project: Project, problem: Option<&Path>) -> Agent {
        Agent {
            project,
            problem: problem.map(Path::to_path_buf),
            leaves: Vec::new(),
            halts: Vec::new(),
        }
    }

    /// Makes `handler` tick every action leaf with node id `id`, in every
    /// attempt: the embedder's behaviour (an action client...). It returns
    /// RUNNING while the work goes on, FAILURE to report a fault. It owns
    /// what it captures (share state with `Rc`): it outlives each
    /// attempt's tree.
    pub fn leaf(
        &mut self,
        id: impl Into<String>,
        handler: impl FnMut(&ActionCall<'_>) -> Status + 'static,
    ) -> &mut Self {
        self.leaves
            .push((id.into(), Rc::new(RefCell::new(Box::new(handler)))));
        self
    }

    /// Makes `halted` hear of every halt of a RUNNING action leaf with
    /// node id `id`, in every attempt (BT.CPP's `onHalted`: cancel the goal
    /// the leaf sent). A fault the loop replans after halts what was
    /// running; so does a tree the tick limit stops.
    pub fn on_halt(
        &mut self,
        id: impl Into<String>,
        halted: impl FnMut(&ActionCall<'_>) + 'static,
    ) -> &mut Self {
        self.halts
            .push((id.into(), Rc::new(RefCell::new(Box::new(halted)))));
        self
    }

    pub fn project(&self) -> &Project {
        &self.project
    }

    /// Runs the loop to the goal, or until it must stop (no plan reaches
    /// the goal, the replan or tick limit).
    pub fn run(
        &mut self,
        options: &AgentOptions,
        faults: Option<&Faults>,
    ) -> Result<AgentReport, Error> {
        let ids = self.leaves.iter().map(|(id, _)| id);
        for id in ids.chain(self.halts.iter().map(|(id, _)| id)) {
            self.project.declared_action(id)?;
        }
        let (db, job) = self.project.loop_job(self.problem.as_deref())?;
        let opts = loop_options(options);
        let (leaves, halts) = (&self.leaves, &self.halts);
        let mut install = |engine: &mut Engine<'_>| {
            // A plan may use none of an id's leaves: that is fine.
            for (id, h) in leaves {
                let h = Rc::clone(h);
                engine.set_action_handler(
                    id,
                    Box::new(move |call: &ActionCall<'_>| (h.borrow_mut())(call)),
                );
            }
            for (id, h) in halts {
                let h = Rc::clone(h);
                engine.set_halt_handler(
                    id,
                    Box::new(move |call: &ActionCall<'_>| (h.borrow_mut())(call)),
                );
            }
        };
        let result = btc_agent::run_loop_with(
            db,
            job,
            false,
            faults.map(|f| &f.scenario),
            &opts,
            &mut std::io::sink(),
            Some(&mut install),
        );
        report(&self.project, result, faults)
    }

    /// Runs the loop with every attempt's tree ticked by `executor` (the
    /// embedder's py_trees or BehaviorTree.CPP tree with its own
    /// behaviours) instead of btc's engine. The loop plans, compiles, takes
    /// the KB, the failure records and the reported faults back from the
    /// executor, and replans as `btc run --replan` does. Leaves added with
    /// [`Agent::leaf`] are not used: the executor has its own.
    pub fn run_with(
        &mut self,
        options: &AgentOptions,
        executor: &mut dyn Executor,
    ) -> Result<AgentReport, Error> {
        let problem = self.problem.clone();
        self.project
            .run_agent(problem.as_deref(), options, executor)
    }
}

impl Project {
    /// [`Agent::run_with`] on this project, for `problem` (a path; `None`:
    /// the project's problem), without giving the project up: the
    /// compile jobs it keeps serve the loop's plans and later calls alike.
    pub fn run_agent(
        &mut self,
        problem: Option<&Path>,
        options: &AgentOptions,
        executor: &mut dyn Executor,
    ) -> Result<AgentReport, Error> {
        let opts = loop_options(options);
        let (db, job) = self.loop_job(problem)?;
        let mut adapter = Adapter { executor };
        let result = btc_agent::run_loop_outside(db, job, &opts, &mut adapter);
        report(self, result, None)
    }
}

fn report(
    project: &Project,
    result: Result<btc_agent::LoopSummary, LoopError>,
    faults: Option<&Faults>,
) -> Result<AgentReport, Error> {
    let summary = match result {
        Ok(s) => s,
        Err(LoopError::Compile(ds)) => return Err(project.error(&ds)),
        Err(LoopError::Tree(e)) => return Err(crate::faults::load_error(&e, "<tree>")),
        Err(LoopError::Scenario(e)) => {
            return Err(match faults {
                Some(f) => f.error(&e),
                None => crate::faults::load_error(&e, "<faults>"),
            })
        }
    };
    let sources = project.sources_for(&summary.diagnostics);
    Ok(AgentReport {
        attempts: summary.attempts,
        replans: summary.replans,
        faults: summary.faults,
        goal: summary.goal,
        goal_reached: summary.goal_reached,
        goal_failure: summary.goal_failure,
        ticks: summary.ticks,
        stopped: convert(&summary.diagnostics, &sources),
        unreachable: summary.unreachable,
    })
}

fn loop_options(options: &AgentOptions) -> LoopOptions {
    LoopOptions {
        engine: btc_runtime::Options {
            ticks_per_action: options.run.ticks_per_action,
            ms_per_tick: options.run.ms_per_tick,
        },
        trace: false,
        planner: btc_planner::Options::default(),
        max_replans: options.max_replans,
        max_ticks: options.run.max_ticks,
    }
}
