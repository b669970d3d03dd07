//! The closed loop (`btc run --replan`): plan, compile the plan with the
//! rules, run the tree in the simulated world, and when it fails turn the
//! fault record into a new initial state and goal, plan again from there
//! with `btc_planner::plan_from`, and so on, up to a number of replans.
//!
//! One KB lives through the whole loop: the state the failed attempt left
//! (after the faults with a duration ended) is the next plan's initial
//! state. Faults are events in time: their run-time state moves from one
//! attempt's engine to the next and the tick count goes on, so a fault that
//! fired never fires again, and one that lasts N ticks lasts N ticks of the
//! loop. Nothing here prints or reads files; the CLI loads the files into
//! the database and renders the result.

mod after;
mod attempt;
mod carry;
mod external;
mod planning;

use external::Execution;
pub use external::{Executed, Executor, Handoff};

use crate::faults::{FaultOutcome, Scenario};
use btc_lang::db::{self, CompileJob, Database, JobWorld};
use btc_lang::path::FilePath;
use btc_pddl::diagnostic::{codes, Diagnostic};
use btc_pddl::logic::Formula;
use btc_pddl::source::Span;
use btc_pddl::state::World;
use btc_runtime::engine::{Engine, FaultRecord, Options, Status};
use btc_runtime::error::LoadError;
use carry::Carry;
use planning::Planned;
use serde::Serialize;
use std::time::Instant;

/// How the loop runs.
#[derive(Clone, Debug)]
pub struct LoopOptions {
    pub engine: Options,
    /// Write the loop's trace: each attempt's events and the loop's own
    /// (plans, replans, the goal check), as JSON Lines.
    pub trace: bool,
    pub planner: btc_planner::Options,
    /// Plans made after a failure, at most (the first plan does not count).
    pub max_replans: usize,
    /// Ticks in all, across attempts and waits.
    pub max_ticks: u64,
}

impl Default for LoopOptions {
    fn default() -> Self {
        LoopOptions {
            engine: Options::default(),
            trace: false,
            planner: btc_planner::Options::default(),
            max_replans: 5,
            max_ticks: 100_000,
        }
    }
}

/// One plan and its run.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Attempt {
    /// 1-based.
    pub attempt: usize,
    /// `given` (the `--plan` file) or `planned`.
    pub source: &'static str,
    /// The goal this plan was made for.
    pub goal: String,
    /// The plan's steps, `(action arg ...)`.
    pub plan: Vec<String>,
    /// Planning time (0 for a given plan) and states the search expanded.
    pub planning_ms: f64,
    pub expanded: usize,
    pub compile_ms: f64,
    pub run_ms: f64,
    /// The ticks the attempt ran: from `start_tick + 1` to `end_tick`.
    pub start_tick: u64,
    pub end_tick: u64,
    pub status: Status,
    pub steps_done: usize,
    pub steps_total: usize,
    pub records: Vec<FaultRecord>,
    /// Ticks waited after the failure for faults with a duration to end.
    pub waited_ticks: u64,
    /// A high-priority order halted the tree (its status is then RUNNING).
    pub preempted: bool,
}

/// Why the loop planned again, and what changed.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Replan {
    /// The attempt that failed (1-based).
    pub after_attempt: usize,
    /// The tick the new plan starts from.
    pub tick: u64,
    /// The failing node and reason, from the fault record.
    pub why: String,
    /// The 1-based plan step that failed, and its action.
    pub from_step: Option<usize>,
    pub action: Option<String>,
    pub faults: Vec<String>,
    /// Changes to the goal (a replaced part, an added order).
    pub adjustments: Vec<String>,
}

/// What the loop came to.
#[derive(Clone, Debug, Serialize)]
pub struct LoopSummary {
    pub attempts: Vec<Attempt>,
    pub replans: Vec<Replan>,
    pub faults: Vec<FaultOutcome>,
    /// The final goal (the problem's, adjusted).
    pub goal: String,
    pub goal_reached: bool,
    pub goal_failure: Option<String>,
    pub ticks: u64,
    /// Why the loop stopped short of the goal.
    pub stopped: Option<String>,
    /// Goal literals no plan reaches from the state the loop stopped in,
    /// each with the faults that name it.
    pub unreachable: Vec<Unreachable>,
    /// Wall-clock time of the whole loop.
    pub elapsed_ms: f64,
    /// The stop as a diagnostic (X008, X009, S004), on the problem's goal.
    #[serde(skip)]
    pub diagnostics: Vec<Diagnostic>,
    /// Every attempt's trace and the loop's events, as JSON Lines (when
    /// `trace` is set).
    #[serde(skip)]
    pub trace: String,
}

#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Unreachable {
    pub literal: String,
    pub faults: Vec<String>,
}

impl LoopSummary {
    pub fn success(&self) -> bool {
        self.goal_reached
    }
}

/// Inputs the loop cannot work with.
#[derive(Debug)]
pub enum LoopError {
    /// The rules, domain, problem or a plan do not compile.
    Compile(Vec<Diagnostic>),
    /// The compiled tree cannot be run.
    Tree(LoadError),
    /// The fault scenario does not fit the problem or the plan.
    Scenario(LoadError),
}

/// Runs the loop on a compile job whose plan file is `job.plan`: with
/// `given_plan`, that file's text is the first plan; otherwise (and for
/// every replan) the planner writes the plan into it (sas_plan text) and the
/// job is compiled again, as `btc compile` would compile that file.
pub fn run_loop(
    db: &mut Database,
    job: CompileJob,
    given_plan: bool,
    scenario: Option<&Scenario>,
    opts: &LoopOptions,
) -> Result<LoopSummary, LoopError> {
    let mut trace = Vec::new();
    let mut out = run_loop_traced(db, job, given_plan, scenario, opts, &mut trace)?;
    out.trace = String::from_utf8_lossy(&trace).into_owned();
    Ok(out)
}

/// [`run_loop`] with the trace (when `opts.trace` is set) written to
/// `trace` as it happens, tick by tick, instead of kept in the summary: a
/// long loop holds bounded memory and a killed one leaves its trace so far.
/// Write errors are the writer's to keep (`btc_files::Stream` does).
pub fn run_loop_traced(
    db: &mut Database,
    job: CompileJob,
    given_plan: bool,
    scenario: Option<&Scenario>,
    opts: &LoopOptions,
    trace_out: &mut dyn std::io::Write,
) -> Result<LoopSummary, LoopError> {
    run_loop_with(db, job, given_plan, scenario, opts, trace_out, None)
}

/// Installs an embedder's leaves in each attempt's engine, before it ticks
/// (`Engine::set_action_handler` for the node ids it implements).
pub type InstallLeaves<'a, 'l> = &'a mut (dyn FnMut(&mut Engine<'_>) + 'l);

/// [`run_loop_traced`], with the action leaves `leaves` installs ticking
/// the embedder's code instead of the simulated world's actions: the
/// library facade's agent runs the loop this way.
pub fn run_loop_with(
    db: &mut Database,
    job: CompileJob,
    given_plan: bool,
    scenario: Option<&Scenario>,
    opts: &LoopOptions,
    trace_out: &mut dyn std::io::Write,
    leaves: Option<InstallLeaves<'_, '_>>,
) -> Result<LoopSummary, LoopError> {
    let execution = Execution::Engine(leaves);
    run_loop_on(db, job, given_plan, scenario, opts, trace_out, execution)
}

/// The loop with every attempt's tree run by `executor` instead of btc's
/// engine (a py_trees or BehaviorTree.CPP tree with the embedder's
/// behaviours): the planning, the faults' effects and the replanning are
/// the loop's, as for `btc run --replan`. There is no scenario: faults are
/// what the executor reports.
pub fn run_loop_outside(
    db: &mut Database,
    job: CompileJob,
    opts: &LoopOptions,
    executor: &mut dyn Executor,
) -> Result<LoopSummary, LoopError> {
    let execution = Execution::Outside(executor);
    let sink = &mut std::io::sink();
    run_loop_on(db, job, false, None, opts, sink, execution)
}

fn run_loop_on(
    db: &mut Database,
    job: CompileJob,
    given_plan: bool,
    scenario: Option<&Scenario>,
    opts: &LoopOptions,
    trace_out: &mut dyn std::io::Write,
    execution: Execution<'_, '_>,
) -> Result<LoopSummary, LoopError> {
    let t0 = Instant::now();
    let goal_span = world(db, job)?.problem.goal.as_ref().map_or(
        Span::new(problem_file_id(db, job), 0, 0),
        btc_pddl::ast::Formula::span,
    );
    // The world does not change from plan to plan: only the plan file does.
    let the_world = world(db, job)?
        .world()
        .map_err(|m| LoopError::Tree(LoadError::new(codes::X_KB, m)))?;
    let base_goal = the_world
        .model()
        .goal
        .clone()
        .unwrap_or_else(Formula::truth);
    let mut run = Run {
        plan_path: job.plan(db).path(db).clone(),
        db,
        job,
        given_plan,
        scenario,
        opts,
        trace_out,
        execution,
        out: LoopSummary::new(base_goal.to_string()),
        world: the_world,
        base_goal,
        goal_span,
        carry: Carry::default(),
    };
    run.attempts()?;
    let mut out = run.out;
    out.goal = run.carry.goal(&run.base_goal).to_string();
    out.elapsed_ms = t0.elapsed().as_secs_f64() * 1e3;
    if opts.trace {
        push_event(
            run.trace_out,
            serde_json::json!({
                "event": "goal_check", "tick": out.ticks, "goal": out.goal,
                "reached": out.goal_reached, "replans": out.replans.len(),
            }),
        );
    }
    Ok(out)
}

/// A loop under way: its inputs, the world, and what it has come to.
struct Run<'a, 'l> {
    db: &'a mut Database,
    job: CompileJob,
    plan_path: FilePath,
    given_plan: bool,
    scenario: Option<&'a Scenario>,
    opts: &'a LoopOptions,
    trace_out: &'a mut dyn std::io::Write,
    execution: Execution<'a, 'l>,
    world: World,
    /// The problem's goal, before any adjustment.
    base_goal: Formula,
    /// Where the loop's stops are reported: the problem's goal.
    goal_span: Span,
    carry: Carry,
    out: LoopSummary,
}

impl Run<'_, '_> {
    /// Plans, compiles and runs attempts until the goal holds or the loop
    /// must stop.
    fn attempts(&mut self) -> Result<(), LoopError> {
        loop {
            let attempt = self.out.attempts.len() + 1;
            let whole = self.carry.goal(&self.base_goal);
            self.out.goal = whole.to_string();
            // This attempt's goal: a priority order's first, then the whole.
            let for_priority = !self.carry.priority.is_empty();
            let goal = if for_priority {
                self.carry.priority_goal()
            } else {
                whole
            };
            let planned = match self.plan(attempt, &goal, for_priority)? {
                Planned::PriorityDone => {
                    self.carry.priority.clear();
                    continue;
                }
                Planned::GoalHolds => {
                    self.out.goal_reached = true;
                    self.out.goal_failure = None;
                    return Ok(());
                }
                Planned::Stopped => return Ok(()),
                planned => planned,
            };
            let ran = self.attempt(attempt, &goal, planned, for_priority)?;
            if ran.done && for_priority {
                // The priority order is done: back to the whole goal.
                self.carry.priority.clear();
                self.out.goal_reached = false;
                continue;
            }
            if ran.done || self.out_of_limits(&ran) {
                return Ok(());
            }
            let rp = self.replan(attempt, &goal, ran);
            if self.opts.trace {
                let mut v = serde_json::to_value(&rp).unwrap_or_default();
                if let Some(o) = v.as_object_mut() {
                    o.insert("event".into(), "replan".into());
                }
                push_event(self.trace_out, v);
            }
            self.out.replans.push(rp);
        }
    }
}

impl LoopSummary {
    fn new(goal: String) -> LoopSummary {
        LoopSummary {
            attempts: Vec::new(),
            replans: Vec::new(),
            faults: Vec::new(),
            goal,
            goal_reached: false,
            goal_failure: None,
            ticks: 0,
            stopped: None,
            unreachable: Vec::new(),
            elapsed_ms: 0.0,
            diagnostics: Vec::new(),
            trace: String::new(),
        }
    }
}

fn push_event(out: &mut dyn std::io::Write, v: serde_json::Value) {
    let _ = writeln!(out, "{v}");
}

fn plural(n: usize, what: &str) -> String {
    if n == 1 {
        format!("1 {what}")
    } else {
        format!("{n} {what}s")
    }
}

fn quoted(v: &[String]) -> String {
    v.iter()
        .map(|s| format!("`{s}`"))
        .collect::<Vec<_>>()
        .join(", ")
}

fn problem_file_id(db: &Database, job: CompileJob) -> u32 {
    db::job_problem(db, job).map_or(0, |p| db::file_id(db, p))
}

fn world(db: &Database, job: CompileJob) -> Result<JobWorld<'_>, LoopError> {
    JobWorld::of(db, job).ok_or_else(|| {
        LoopError::Compile(
            db::job_diagnostics(db, job)
                .iter()
                .filter(|d| d.is_error())
                .cloned()
                .collect(),
        )
    })
}
