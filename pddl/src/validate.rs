//! Plan validation: replays a typed plan from the initial state and reports
//! the first step whose precondition fails, or the goal literals it misses.

use crate::ast::{Action, Domain, Formula, Problem};
use crate::diagnostic::{codes, Diagnostic};
use crate::logic::{self, ActionSchema};
use crate::plan::{GroundStep, Plan};
use crate::state::{Changes, CompiledAction, Cond, Eff, State, World};
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

/// Replays `steps` (from [`crate::plan::type_plan`], with no typing
/// errors) on `world`, the world of `domain` and `problem`.
pub fn validate(
    world: &World,
    domain: &Domain,
    problem: &Problem,
    plan: &Plan,
    steps: &[GroundStep],
) -> Validation {
    let mut state = world.initial_state();
    let mut diags = Vec::new();
    let mut actions = Actions::new(world, domain);
    let mut scratch = Scratch::default();
    for (n, g) in steps.iter().enumerate() {
        let applied = actions
            .get(g.action)
            .and_then(|a| apply_step(world, &a, &mut state, plan, g, &mut scratch));
        if let Err(d) = applied {
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

/// The domain's actions, each converted and compiled once, when a step
/// first uses it.
struct Actions<'a> {
    world: &'a World,
    domain: &'a Domain,
    compiled: Vec<Option<std::rc::Rc<CompiledAction>>>,
}

impl<'a> Actions<'a> {
    fn new(world: &'a World, domain: &'a Domain) -> Actions<'a> {
        Actions {
            world,
            domain,
            compiled: vec![None; domain.actions.len()],
        }
    }

    fn get(&mut self, i: usize) -> Result<Step<'a>, Diagnostic> {
        let ast = &self.domain.actions[i];
        if self.compiled[i].is_none() {
            let c = self
                .world
                .compile_action(&ActionSchema::from_ast(ast))
                .map_err(|m| {
                    Diagnostic::error(
                        codes::PRECONDITION_FAILS,
                        ast.name.span,
                        format!("action `{}` does not fit the problem: {m}", ast.name.name),
                    )
                })?;
            self.compiled[i] = Some(std::rc::Rc::new(c));
        }
        Ok(Step {
            ast,
            compiled: self.compiled[i].clone().expect("compiled above"),
        })
    }
}

/// An action as the AST has it (for spans) and compiled (to evaluate).
struct Step<'a> {
    ast: &'a Action,
    compiled: std::rc::Rc<CompiledAction>,
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

/// What every step needs room for, kept from step to step so that a long
/// replay does not allocate it again for each.
#[derive(Default)]
struct Scratch {
    binding: Vec<u32>,
    changes: Changes,
}

/// Applies one step: durative actions as start conditions, start effects,
/// over-all and end conditions, end effects.
fn apply_step(
    world: &World,
    action: &Step,
    state: &mut State,
    plan: &Plan,
    g: &GroundStep,
    scratch: &mut Scratch,
) -> Result<(), Diagnostic> {
    let c = &action.compiled;
    let a = action.ast;
    let step = &plan.steps[g.step];
    let Scratch { binding, changes } = scratch;
    binding.clear();
    binding.extend_from_slice(&g.args);
    let duration = match &c.duration {
        Some(d) => world.value(state, d, binding, None).or(step.duration),
        None => step.duration,
    };
    let start_phase = if a.durative {
        "its `at start` condition"
    } else {
        "its precondition"
    };
    let ctx = StepCtx {
        world,
        plan,
        g,
        action: a,
        duration,
    };
    ctx.check(state, &c.pre_start, &a.pre_start, binding, start_phase)?;
    if a.durative {
        ctx.apply_effects(state, &c.eff_start, binding, changes)?;
        ctx.check(
            state,
            &c.pre_over_all,
            &a.pre_over_all,
            binding,
            "its `over all` condition",
        )?;
        ctx.check(
            state,
            &c.pre_end,
            &a.pre_end,
            binding,
            "its `at end` condition",
        )?;
    }
    ctx.apply_effects(state, &c.eff_end, binding, changes)
}

struct StepCtx<'w> {
    world: &'w World,
    plan: &'w Plan,
    g: &'w GroundStep,
    action: &'w Action,
    duration: Option<f64>,
}

impl StepCtx<'_> {
    fn check(
        &self,
        state: &State,
        conds: &[Cond],
        written: &[Formula],
        binding: &mut Vec<u32>,
        phase: &str,
    ) -> Result<(), Diagnostic> {
        let (world, g) = (self.world, self.g);
        for (c, f) in conds.iter().zip(written) {
            if !world.holds(state, c, binding, self.duration) {
                let (why, path) = world.why_not(state, c, binding, self.duration);
                return Err(Diagnostic::error(
                    codes::PRECONDITION_FAILS,
                    self.plan.steps[g.step].span,
                    format!(
                        "step {} `{}`: {phase} does not hold: {why}",
                        g.step + 1,
                        show_step(world, self.action, g)
                    ),
                )
                .with_label(logic::span_at(f, &path), "this condition fails"));
            }
        }
        Ok(())
    }

    fn apply_effects(
        &self,
        state: &mut State,
        effects: &[Eff],
        binding: &mut Vec<u32>,
        changes: &mut Changes,
    ) -> Result<(), Diagnostic> {
        let (world, g) = (self.world, self.g);
        for e in effects {
            world.collect(state, e, binding, self.duration, changes);
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
        world.apply_changes(state, changes);
        Ok(())
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
    Ok(validate(&world, domain, problem, plan, steps))
}
