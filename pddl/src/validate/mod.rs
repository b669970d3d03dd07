//! Plan validation: replays a typed plan from the initial state and reports
//! the first step whose precondition fails, or the goal literals it misses.

use crate::ast::{Action, Domain, Formula, Problem};
use crate::diagnostic::{codes, Diagnostic};
use crate::plan::{GroundStep, Plan};
use crate::state::{Cond, State, World};
use serde::Serialize;

mod ground;
mod interference;
pub mod schedule;
mod step;
mod timed;
mod tracked;

pub use timed::DEFAULT_EPSILON;

#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Validation {
    pub valid: bool,
    /// Steps applied before the first failure (all of them when valid).
    pub steps_applied: usize,
    /// `total-cost` when the domain has it, else the number of steps.
    pub cost: f64,
    #[serde(skip)]
    pub diagnostics: Vec<Diagnostic>,
}

/// How a replay evaluates its steps. Both give the same [`Validation`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Replay {
    /// Grounds each distinct ground action's conditions and unconditional
    /// effects once, and evaluates only what depends on the state at each
    /// step (the general path's, for the rest).
    Cached,
    /// Evaluates every step's compiled conditions and effects afresh: the
    /// reference the cached replay is tested against.
    General,
}

/// Replays `steps` (from [`crate::plan::type_plan`], with no typing
/// errors) on `world`, the world of `domain` and `problem`, as `replay`
/// says ([`Replay::Cached`] but to test it).
pub fn validate(
    replay: Replay,
    world: &World,
    domain: &Domain,
    problem: &Problem,
    plan: &Plan,
    steps: &[GroundStep],
) -> Validation {
    validate_with(replay, world, domain, problem, plan, steps, DEFAULT_EPSILON)
}

/// [`validate`] with a separation tolerance for timed plans: a plan whose
/// steps all have times is replayed with PDDL 2.1's temporal semantics
/// (see [`timed`]); any other plan one step after another.
pub fn validate_with(
    replay: Replay,
    world: &World,
    domain: &Domain,
    problem: &Problem,
    plan: &Plan,
    steps: &[GroundStep],
    epsilon: f64,
) -> Validation {
    let timed = !plan.steps.is_empty() && plan.steps.iter().all(|s| s.time.is_some());
    if timed {
        return timed::validate_timed(replay, world, domain, problem, plan, steps, epsilon);
    }
    let mut diags = Vec::new();
    if let Some(a) = domain.actions.iter().find(|a| a.durative) {
        if let Some(step) = plan.steps.iter().find(|s| s.time.is_none()) {
            diags.push(
                Diagnostic::warning(
                    codes::UNTIMED_PLAN,
                    step.span,
                    format!(
                        "the domain has durative actions (`{}`), but this plan has no times: \
                         its steps are replayed one after another, each ending before the next \
                         starts, and no durations are checked",
                        a.name.name
                    ),
                )
                .with_hint(
                    "timed plans read `0.000: (action args) [duration]` (PDDL 2.1, as \
                     temporal planners write them); `btc plan` writes one for a durative domain",
                ),
            );
        }
    }
    let mut state = world.initial_state();
    let mut stepper = step::Stepper::new(world, domain, replay == Replay::Cached);
    for (n, g) in steps.iter().enumerate() {
        let applied = stepper.apply(&mut state, plan, g);
        if let Err(d) = applied {
            stepper.settle(&mut state);
            diags.push(d);
            return Validation {
                valid: false,
                steps_applied: n,
                cost: cost(world, &state, n),
                diagnostics: diags,
            };
        }
    }
    stepper.settle(&mut state);
    finish(world, problem, plan, state, steps.len(), diags)
}

/// The validation of a plan all of whose `steps` applied, ending in
/// `state`: the goal checked, the stated cost compared.
fn finish(
    world: &World,
    problem: &Problem,
    plan: &Plan,
    state: State,
    steps: usize,
    mut diags: Vec<Diagnostic>,
) -> Validation {
    let cost = cost(world, &state, steps);
    let mut valid = true;
    if let (Some(goal), Some(cond)) = (&problem.goal, world.goal()) {
        let missing = missing_goals(world, &state, goal, cond);
        if !missing.is_empty() {
            valid = false;
            let shown: Vec<String> = missing.iter().take(8).cloned().collect();
            let more = if missing.len() > 8 {
                format!(" and {} more", missing.len() - 8)
            } else {
                String::new()
            };
            diags.push(
                Diagnostic::error(
                    codes::GOAL_NOT_REACHED,
                    goal.span(),
                    format!(
                        "the plan does not reach the goal: {}{more}",
                        shown.join("; ")
                    ),
                )
                .with_hint(format!(
                    "after all {steps} steps these goal conditions still fail"
                )),
            );
        }
    }
    if let Some(stated) = &plan.stated_cost {
        if valid && (stated.value - cost).abs() > 1e-6 {
            diags.push(Diagnostic::warning(
                codes::COST_MISMATCH,
                stated.span,
                format!(
                    "the plan says its cost is {}, but its steps cost {}",
                    stated.value, cost
                ),
            ));
        }
    }
    Validation {
        valid,
        steps_applied: steps,
        cost,
        diagnostics: diags,
    }
}

fn cost(world: &World, state: &State, steps: usize) -> f64 {
    match world.function_id("total-cost") {
        Some(f) => state.fluents.get(&[f][..]).copied().unwrap_or(0.0),
        None => steps as f64,
    }
}

/// Goal conjuncts that do not hold, each explained.
fn missing_goals(world: &World, state: &State, goal: &Formula, cond: &Cond) -> Vec<String> {
    let mut b = Vec::new();
    match (goal, cond) {
        (Formula::And { parts, .. }, Cond::And(conds)) => parts
            .iter()
            .zip(conds)
            .filter(|(_, c)| !world.holds(state, c, &mut Vec::new(), None))
            .flat_map(|(p, c)| missing_goals(world, state, p, c))
            .collect(),
        _ if !world.holds(state, cond, &mut b, None) => {
            vec![world.why_not(state, cond, &mut b, None).0]
        }
        _ => Vec::new(),
    }
}

pub fn show_step(world: &World, action: &Action, g: &GroundStep) -> String {
    let mut s = format!("({}", action.name.name);
    for &o in g.args.iter() {
        s.push(' ');
        s.push_str(world.object_name(o));
    }
    s.push(')');
    s
}

/// Convenience for callers with a checked domain and problem at hand.
pub fn validate_plan(
    domain: &Domain,
    problem: &Problem,
    dix: &crate::DomainIndex,
    pix: &crate::ProblemIndex,
    plan: &Plan,
    steps: &[GroundStep],
) -> Result<Validation, String> {
    let world = World::of_checked(domain, dix, problem, pix)?;
    Ok(validate(
        Replay::Cached,
        &world,
        domain,
        problem,
        plan,
        steps,
    ))
}
