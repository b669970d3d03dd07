//! The execution level, once: what an agent does with a goal wherever it
//! runs — plan from a state, compile the plan with its robot's rules into
//! a tree (exactly as `btc compile` compiles a plan file), and start the
//! engine the tree runs in. The closed loop ([`crate::replan`]: `btc run
//! --replan` and the packages) and the trial's agents ([`crate::sim`]) both
//! go through these three; what each does with the outcome (replan, hand
//! the task back) is its own.

use btc_lang::db::{self, CompileJob, Database, JobWorld};
use btc_lang::path::AsFilePath;
use btc_pddl::diagnostic::Diagnostic;
use btc_pddl::logic::Formula;
use btc_pddl::plan::WrittenPlan;
use btc_pddl::source::Span;
use btc_pddl::state::State;
use btc_pddl::{Domain, DomainIndex, ProblemIndex};
use btc_planner::{Outcome, Plan};
use btc_runtime::observers::JsonlTrace;
use btc_runtime::{Engine, Kb, LoadError, Options, TreeDoc};
use std::sync::Arc;
use std::time::Instant;

/// What an agent plans in: its domain and its problem's objects.
#[derive(Clone, Copy)]
pub struct PlanningWorld<'a> {
    pub domain: &'a Domain,
    pub dix: &'a DomainIndex,
    pub pix: &'a ProblemIndex,
}

impl<'a> From<&JobWorld<'a>> for PlanningWorld<'a> {
    fn from(w: &JobWorld<'a>) -> Self {
        PlanningWorld {
            domain: w.domain,
            dix: w.dix,
            pix: w.pix,
        }
    }
}

/// A plan the planner made, as the value the compiler takes (the world it
/// was made in is borrowed from the database the compiler then changes,
/// so the plan carries its names).
pub struct MadePlan(WrittenPlan);

impl MadePlan {
    fn of(w: PlanningWorld<'_>, plan: &Plan) -> MadePlan {
        MadePlan(btc_planner::written_plan(w.domain, w.pix, plan))
    }

    /// The goal held already: the plan has no steps.
    pub fn is_empty(&self) -> bool {
        self.0.is_empty()
    }
}

/// What planning came to, with the time it took (milliseconds).
pub enum Planning {
    /// A plan (of no steps when the goal holds already).
    Made {
        plan: MadePlan,
        ms: f64,
        expanded: usize,
    },
    /// No plan reaches the goal.
    Unsolvable { ms: f64 },
    /// The planner's time limit stopped it.
    Timeout { ms: f64 },
}

/// Plans from `state` to `goal` (reported at `span`).
pub fn plan(
    w: PlanningWorld<'_>,
    state: &State,
    goal: &Formula,
    span: Span,
    opts: &btc_planner::Options,
) -> Result<Planning, Vec<Diagnostic>> {
    let t = Instant::now();
    let report = btc_planner::plan_from(
        w.domain,
        w.dix,
        w.pix,
        state,
        Some(&goal.to_ast(span)),
        opts,
    )?;
    let ms = t.elapsed().as_secs_f64() * 1e3;
    Ok(match report.outcome {
        Outcome::Plan(plan) => Planning::Made {
            plan: MadePlan::of(w, &plan),
            ms,
            expanded: report.search.expanded,
        },
        Outcome::Unsolvable => Planning::Unsolvable { ms },
        Outcome::Timeout => Planning::Timeout { ms },
    })
}

/// Compiles the agent's job with `plan` as its plan (`None`: the plan the
/// job has already, e.g. a plan file given): the job's diagnostics when it
/// does not compile. The plan goes to the compiler as a value; its file
/// holds only the text a diagnostic shows.
pub fn compile(
    db: &mut Database,
    job: CompileJob,
    plan_file: &(impl AsFilePath + ?Sized),
    plan: Option<MadePlan>,
) -> Result<Arc<btc_ir::TreeIr>, Vec<Diagnostic>> {
    if let Some(MadePlan(plan)) = plan {
        db.set_plan(plan_file, plan);
    }
    db::compile(db, job).clone().map_err(|e| {
        if e.is_empty() {
            db::job_diagnostics(db, job)
                .iter()
                .filter(|d| d.is_error())
                .cloned()
                .collect()
        } else {
            e
        }
    })
}

/// The engine a compiled tree runs in, on `kb`, its clock at `tick`, with
/// the JSON Lines trace observed when `trace` is set.
pub fn start<'w>(
    doc: &TreeDoc,
    kb: Kb<'w>,
    opts: Options,
    tick: u64,
    trace: bool,
) -> Result<Engine<'w>, LoadError> {
    let mut engine = Engine::build(doc, Some(kb), opts)?;
    if trace {
        engine.observe(JsonlTrace::default());
    }
    engine.tick = tick;
    Ok(engine)
}
