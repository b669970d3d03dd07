//! Plan validation: replays a typed plan from the initial state and reports
//! the first step whose precondition fails, or the goal literals it misses.

use crate::ast::{Action, Domain, Effect, Formula, Problem};
use crate::diagnostic::{codes, Diagnostic};
use crate::plan::{GroundStep, Plan};
use crate::state::{Changes, Env, State, World};
use serde::Serialize;

#[derive(Clone, Debug, Serialize)]
pub struct Validation {
    pub valid: bool,
    /// Steps applied before the first failure (all of them when valid).
    pub steps_applied: usize,
    /// `total-cost` when the domain has it, else the number of steps.
    pub cost: f64,
    #[serde(skip)]
    pub diagnostics: Vec<Diagnostic>,
}

/// Replays `steps` (from [`crate::plan::type_plan`], with no typing errors).
pub fn validate(world: &World, problem: &Problem, plan: &Plan, steps: &[GroundStep]) -> Validation {
    let mut state = world.initial_state(problem);
    let mut diags = Vec::new();
    for (n, g) in steps.iter().enumerate() {
        if let Err(d) = apply_step(world, &mut state, plan, g) {
            diags.push(d);
            return Validation {
                valid: false,
                steps_applied: n,
                cost: cost(world, &state, n),
                diagnostics: diags,
            };
        }
    }
    let cost = cost(world, &state, steps.len());
    let mut valid = true;
    if let Some(goal) = &problem.goal {
        let missing = missing_goals(world, &state, goal);
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
                    "after all {} steps these goal conditions still fail",
                    steps.len()
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
        steps_applied: steps.len(),
        cost,
        diagnostics: diags,
    }
}

fn cost(world: &World, state: &State, steps: usize) -> f64 {
    match world.dix.functions.get("total-cost") {
        Some(sig) => state
            .fluents
            .get(&[sig.index as u32][..])
            .copied()
            .unwrap_or(0.0),
        None => steps as f64,
    }
}

/// Goal conjuncts that do not hold, each explained.
fn missing_goals(world: &World, state: &State, goal: &Formula) -> Vec<String> {
    let mut env = Env::new();
    match goal {
        Formula::And { parts, .. } => parts
            .iter()
            .filter(|p| !world.holds(state, p, &mut Env::new(), None))
            .flat_map(|p| missing_goals(world, state, p))
            .collect(),
        g if !world.holds(state, g, &mut env, None) => {
            vec![world.why_not(state, g, &mut env, None).0]
        }
        _ => Vec::new(),
    }
}

fn bind<'a>(action: &'a Action, g: &GroundStep) -> Env<'a> {
    action
        .params
        .iter()
        .map(|p| p.name.as_str())
        .zip(g.args.iter().copied())
        .collect()
}

/// Applies one step: durative actions as start conditions, start effects,
/// over-all and end conditions, end effects.
pub fn apply_step(
    world: &World,
    state: &mut State,
    plan: &Plan,
    g: &GroundStep,
) -> Result<(), Diagnostic> {
    let action = &world.domain.actions[g.action];
    let step = &plan.steps[g.step];
    let mut env = bind(action, g);
    let duration = match &action.duration {
        Some(d) => world.value(state, &d.value, &env, None).or(step.duration),
        None => step.duration,
    };
    let start_phase = if action.durative {
        "its `at start` condition"
    } else {
        "its precondition"
    };
    let ctx = StepCtx {
        world,
        plan,
        g,
        action,
        duration,
    };
    ctx.check(state, &action.pre_start, &mut env, start_phase)?;
    if action.durative {
        ctx.apply_effects(state, &action.eff_start, &mut env)?;
        ctx.check(
            state,
            &action.pre_over_all,
            &mut env,
            "its `over all` condition",
        )?;
        ctx.check(state, &action.pre_end, &mut env, "its `at end` condition")?;
    }
    ctx.apply_effects(state, &action.eff_end, &mut env)
}

struct StepCtx<'w, 'a> {
    world: &'w World<'w>,
    plan: &'w Plan,
    g: &'w GroundStep,
    action: &'a Action,
    duration: Option<f64>,
}

impl<'a> StepCtx<'_, 'a> {
    fn check(
        &self,
        state: &State,
        conds: &'a [Formula],
        env: &mut Env<'a>,
        phase: &str,
    ) -> Result<(), Diagnostic> {
        let (world, g) = (self.world, self.g);
        for c in conds {
            if !world.holds(state, c, env, self.duration) {
                let (why, at) = world.why_not(state, c, env, self.duration);
                return Err(Diagnostic::error(
                    codes::PRECONDITION_FAILS,
                    self.plan.steps[g.step].span,
                    format!(
                        "step {} `{}`: {phase} does not hold: {why}",
                        g.step + 1,
                        show_step(world, self.action, g)
                    ),
                )
                .with_label(at, "this condition fails"));
            }
        }
        Ok(())
    }

    fn apply_effects(
        &self,
        state: &mut State,
        effects: &'a [Effect],
        env: &mut Env<'a>,
    ) -> Result<(), Diagnostic> {
        let (world, g) = (self.world, self.g);
        let mut changes = Changes::default();
        for e in effects {
            world.collect_effect(state, e, env, self.duration, &mut changes);
        }
        if let Some(err) = changes.numeric_errors.first() {
            return Err(Diagnostic::error(
                codes::EFFECT_CONFLICT,
                self.plan.steps[g.step].span,
                format!(
                    "step {} `{}`: `{}` has no value to update",
                    g.step + 1,
                    show_step(world, self.action, g),
                    err.fluent
                ),
            )
            .with_label(self.action.name.span, "the action that updates it")
            .with_hint(
                "give the function a value in the problem's `:init`, e.g. `(= (total-cost) 0)`",
            ));
        }
        world.apply(state, changes);
        Ok(())
    }
}

pub fn show_step(world: &World, action: &Action, g: &GroundStep) -> String {
    let mut s = format!("({}", action.name.name);
    for &o in &g.args {
        s.push(' ');
        s.push_str(&world.pix.object_names[o as usize]);
    }
    s.push(')');
    s
}

/// Convenience for callers with a domain and problem at hand.
pub fn validate_plan(
    domain: &Domain,
    problem: &Problem,
    dix: &crate::DomainIndex,
    pix: &crate::ProblemIndex,
    plan: &Plan,
    steps: &[GroundStep],
) -> Validation {
    let world = World::new(domain, dix, pix);
    validate(&world, problem, plan, steps)
}
