//! The btc planner: grounds a PDDL problem of the `btc-lang` model (with
//! reachability pruning) and searches it with greedy best-first search or
//! A* under h_FF, h_add, h_max or the blind heuristic.
//!
//! [`plan`] plans from a problem's `:init`; [`plan_from`] from any state of
//! the problem's objects (a runtime's knowledge base) to any goal, which is
//! what replanning needs. Nothing here prints.
//!
//! ```
//! use btc_pddl::pipeline::{domain_unit_from, problem_unit_from};
//! use btc_pddl::state::World;
//! use btc_planner::{plan_from, to_sas_plan, Options, Outcome};
//!
//! let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/../examples/ariac/");
//! let read = |f: &str| std::fs::read_to_string(format!("{dir}{f}")).unwrap();
//! let du = domain_unit_from(&read("domain.pddl"), 0);
//! let domain = du.domain.as_ref().unwrap();
//! let pu = problem_unit_from(&read("problem.pddl"), 1, Some(domain), &du.index);
//! let problem = pu.problem.as_ref().unwrap();
//!
//! // A knowledge base: the problem's facts, then what execution changed.
//! let world = World::of_checked(domain, &du.index, problem, &pu.index).unwrap();
//! let mut kb = world.initial_state();
//! let key = |pred: &str, args: &[&str]| -> Box<[u32]> {
//!     let mut k = vec![du.index.predicates[pred].index as u32];
//!     k.extend(args.iter().map(|a| pu.index.objects[*a].id));
//!     k.into()
//! };
//! kb.facts.remove(&key("is_reachable", &["floor_robot", "curr_position"]));
//! kb.facts.insert(key("is_reachable", &["floor_robot", "bin1"]));
//!
//! let report = plan_from(domain, &du.index, &pu.index, &kb, problem.goal.as_ref(),
//!                        &Options::default()).unwrap();
//! let Outcome::Plan(plan) = report.outcome else { panic!("no plan") };
//! assert_eq!(plan.steps.len(), 3); // grasp, move, place
//! print!("{}", to_sas_plan(domain, &pu.index, &plan));
//! ```

pub mod ground;
pub mod heuristic;
pub mod improve;
pub mod lama;
pub mod landmarks;
pub mod lazy;
pub mod lifted;
pub mod lmcount;
pub mod lmcut;
pub mod options;
mod reach;
pub mod search;
pub mod space;
pub mod task;

pub use ground::GroundStats;
pub use heuristic::Heuristic;
pub use search::{Algorithm, Options, SearchStats, DEFAULT_IMPROVE};

use btc_pddl::ast::{Domain, Formula, InitFact, Problem};
use btc_pddl::check::{DomainIndex, ProblemIndex};
use btc_pddl::diagnostic::{codes, Diagnostic};
use btc_pddl::state::{Key, State};
use std::time::{Duration, Instant};

/// One step of a plan: an action of the domain and its arguments (object
/// ids of the problem index).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Step {
    pub action: usize,
    pub args: Vec<u32>,
}

#[derive(Clone, Debug, PartialEq)]
pub struct Plan {
    pub steps: Vec<Step>,
    /// The sum of the step costs (`total-cost` increases, or 1 per step
    /// when the domain has no `total-cost`).
    pub cost: u64,
    /// `total-cost` before the first step.
    pub base_cost: f64,
    /// Whether every action costs 1.
    pub unit_cost: bool,
}

#[derive(Clone, Debug, PartialEq)]
pub enum Outcome {
    Plan(Plan),
    /// No plan exists (the search space is exhausted).
    Unsolvable,
    /// The time limit stopped the search.
    Timeout,
}

#[derive(Clone, Debug, PartialEq)]
pub struct Report {
    pub outcome: Outcome,
    pub ground: GroundStats,
    pub ground_time: Duration,
    pub search: SearchStats,
}

/// Plans from the problem's initial state to its goal.
pub fn plan(
    domain: &Domain,
    dix: &DomainIndex,
    problem: &Problem,
    pix: &ProblemIndex,
    opts: &Options,
) -> Result<Report, Vec<Diagnostic>> {
    // The facts and values of `:init`; derived atoms are the planner's job.
    let mut init = State::default();
    for f in &problem.init {
        match f {
            InitFact::Atom { atom } => init.facts.extend(ground_key(&dix.predicates, pix, atom)),
            InitFact::Value { fluent, value, .. } => {
                if let Some(k) = ground_key(&dix.functions, pix, fluent) {
                    init.fluents.insert(k, *value);
                }
            }
        }
    }
    plan_from(domain, dix, pix, &init, problem.goal.as_ref(), opts)
}

/// The key of a ground atom of `:init` (`None` for what the checks refuse).
fn ground_key(
    heads: &rustc_hash::FxHashMap<String, btc_pddl::check::Signature>,
    pix: &ProblemIndex,
    atom: &btc_pddl::ast::Atom,
) -> Option<Key> {
    let mut k = vec![heads.get(atom.pred.as_str())?.index as u32];
    for t in &atom.args {
        match t {
            btc_pddl::ast::Term::Const { name } => k.push(pix.objects.get(name.as_str())?.id),
            btc_pddl::ast::Term::Var { .. } => return None,
        }
    }
    Some(k.into_boxed_slice())
}

/// Plans from `initial` (facts and numeric values over the problem's
/// objects; derived atoms are recomputed) to `goal` (`None`: already
/// reached).
pub fn plan_from(
    domain: &Domain,
    dix: &DomainIndex,
    pix: &ProblemIndex,
    initial: &State,
    goal: Option<&Formula>,
    opts: &Options,
) -> Result<Report, Vec<Diagnostic>> {
    let t0 = Instant::now();
    let deadline = opts.timeout.map(|t| t0 + t);
    let Some((task, ground)) = ground::ground(domain, dix, pix, initial, goal, deadline)? else {
        return Ok(Report {
            outcome: Outcome::Timeout,
            ground: GroundStats::default(),
            ground_time: t0.elapsed(),
            search: SearchStats::default(),
        });
    };
    let ground_time = t0.elapsed();
    let mut opts = *opts;
    if let Some(t) = opts.timeout {
        opts.timeout = Some(t.saturating_sub(ground_time));
    }
    let mut s = search::Search::new(&task, opts);
    let result = s.run();
    let outcome = match result {
        search::SearchResult::Plan(mut ops, mut cost) => {
            if opts.algorithm == Algorithm::Gbfs {
                ops = improve::eliminate_redundant(&task, ops);
                cost = ops.iter().map(|&o| task.operators[o as usize].cost).sum();
            }
            Outcome::Plan(Plan {
                steps: ops
                    .iter()
                    .map(|&o| {
                        let op = &task.operators[o as usize];
                        Step {
                            action: op.action,
                            args: op.args.clone(),
                        }
                    })
                    .collect(),
                cost,
                base_cost: task.base_cost,
                unit_cost: task.unit_cost,
            })
        }
        search::SearchResult::Unsolvable => Outcome::Unsolvable,
        search::SearchResult::Timeout => Outcome::Timeout,
    };
    Ok(Report {
        outcome,
        ground,
        ground_time,
        search: s.stats,
    })
}

/// The plan in Fast Downward's `sas_plan` format: one `(action args)` per
/// line, then `; cost = N (unit cost|general cost)`.
pub fn to_sas_plan(domain: &Domain, pix: &ProblemIndex, plan: &Plan) -> String {
    let mut out = String::new();
    for s in &plan.steps {
        out.push('(');
        out.push_str(&domain.actions[s.action].name.name);
        for &a in &s.args {
            out.push(' ');
            out.push_str(&pix.object_names[a as usize]);
        }
        out.push_str(")\n");
    }
    out.push_str(&cost_line(plan));
    out
}

/// `; cost = N (unit cost|general cost)`, a plan file's last line.
/// The plan as a value the compiler takes ([`btc_pddl::plan::WrittenPlan`]),
/// whose text is what [`to_sas_plan`] writes.
pub fn written_plan(
    domain: &Domain,
    pix: &ProblemIndex,
    plan: &Plan,
) -> btc_pddl::plan::WrittenPlan {
    let mut w = btc_pddl::plan::PlanWriter::new();
    for s in &plan.steps {
        let args: Vec<&str> = s
            .args
            .iter()
            .map(|&a| pix.object_names[a as usize].as_str())
            .collect();
        w.step(&domain.actions[s.action].name.name, &args, None, None);
    }
    let (total, kind) = cost_of(plan);
    w.cost(total, Some(kind));
    w.finish()
}

fn cost_of(plan: &Plan) -> (f64, &'static str) {
    let total = plan.base_cost + plan.cost as f64;
    let kind = if plan.unit_cost {
        "unit cost"
    } else {
        "general cost"
    };
    (total, kind)
}

fn cost_line(plan: &Plan) -> String {
    let (total, kind) = cost_of(plan);
    format!("; cost = {total} ({kind})\n")
}

/// For a domain with durative actions, `plan` scheduled into a timed plan
/// (see [`btc_pddl::validate::schedule`], with the default tolerance);
/// `None` for a classical domain.
pub fn schedule_plan(
    domain: &Domain,
    dix: &DomainIndex,
    problem: &Problem,
    pix: &ProblemIndex,
    plan: &Plan,
) -> Result<Option<btc_pddl::validate::schedule::Schedule>, String> {
    if !domain.actions.iter().any(|a| a.durative) {
        return Ok(None);
    }
    let world = btc_pddl::state::World::of_checked(domain, dix, problem, pix)?;
    let steps: Vec<(usize, std::sync::Arc<[u32]>)> = plan
        .steps
        .iter()
        .map(|s| (s.action, s.args.as_slice().into()))
        .collect();
    btc_pddl::validate::schedule::schedule(
        &world,
        domain,
        problem,
        &steps,
        btc_pddl::validate::DEFAULT_EPSILON,
    )
    .map(Some)
}

/// A durative domain's plan as a temporal planner writes it: one
/// `start: (action args) [duration]` per line, in time order, then the
/// makespan and the cost. `schedule` gives each step's start and duration
/// (see [`btc_pddl::validate::schedule`]).
pub fn to_timed_plan(
    domain: &Domain,
    pix: &ProblemIndex,
    plan: &Plan,
    schedule: &btc_pddl::validate::schedule::Schedule,
) -> String {
    let mut order: Vec<usize> = (0..plan.steps.len()).collect();
    order.sort_by(|&a, &b| schedule.starts[a].total_cmp(&schedule.starts[b]));
    let mut out = String::new();
    for i in order {
        let s = &plan.steps[i];
        out.push_str(&format!("{:.3}: (", schedule.starts[i]));
        out.push_str(&domain.actions[s.action].name.name);
        for &a in &s.args {
            out.push(' ');
            out.push_str(&pix.object_names[a as usize]);
        }
        out.push_str(&format!(") [{:.3}]\n", schedule.durations[i]));
    }
    out.push_str(&format!(
        "; makespan = {:.3} (the steps one after another: {:.3})\n",
        schedule.makespan, schedule.sequential
    ));
    out.push_str(&cost_line(plan));
    out
}

/// The diagnostic for a goal no plan reaches.
pub fn unsolvable(problem: &Problem) -> Diagnostic {
    let span = problem.goal.as_ref().map_or(problem.span, Formula::span);
    Diagnostic::error(
        codes::PLAN_UNSOLVABLE,
        span,
        "no plan reaches this goal from the initial state",
    )
    .with_hint("every reachable state was searched; check the goal and the `:init` facts")
}

/// The diagnostic for a search stopped by its time limit.
pub fn timeout(problem: &Problem, limit: Duration) -> Diagnostic {
    Diagnostic::error(
        codes::PLAN_TIMEOUT,
        problem.name.span,
        format!(
            "no plan found within the time limit of {} s",
            limit.as_secs_f64()
        ),
    )
    .with_hint("raise `--timeout`, or try `--search gbfs --heuristic ff`")
}

#[cfg(test)]
pub(crate) mod test_util {
    use btc_pddl::pipeline::{domain_unit_from, problem_unit_from};
    use btc_pddl::state::World;

    /// The ground task of a domain and problem text (fixtures from
    /// `tests/fixtures/`).
    pub fn task(domain: &str, problem: &str) -> crate::task::Task {
        let du = domain_unit_from(domain, 0);
        let d = du.domain.as_ref().expect("domain parses");
        let pu = problem_unit_from(problem, 1, Some(d), &du.index);
        let p = pu.problem.as_ref().expect("problem parses");
        let world = World::of_checked(d, &du.index, p, &pu.index).expect("a world");
        let init = world.initial_state();
        crate::ground::ground(d, &du.index, &pu.index, &init, p.goal.as_ref(), None)
            .expect("grounds")
            .expect("no time limit")
            .0
    }

    pub fn rooms() -> crate::task::Task {
        task(
            include_str!("../tests/fixtures/rooms-domain.pddl"),
            include_str!("../tests/fixtures/rooms-problem.pddl"),
        )
    }

    pub fn fact(t: &crate::task::Task, name: &str) -> u32 {
        t.fact_names
            .iter()
            .position(|n| n == name)
            .unwrap_or_else(|| panic!("no fact {name}")) as u32
    }
}
