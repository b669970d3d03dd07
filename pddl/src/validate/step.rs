//! Applying one plan step: checking its conditions and applying its
//! effects phase by phase, by the general path (the compiled action
//! evaluated afresh) or by the step's cached ground action where that is
//! exact.

use super::ground::{GroundActions, GroundConds, GroundEffects};
use super::show_step;
use super::tracked::TrackedFacts;
use crate::ast::{Action, Domain, Formula};
use crate::diagnostic::{codes, Diagnostic};
use crate::logic::{self, ActionSchema};
use crate::plan::{GroundStep, Plan};
use crate::state::{Changes, CompiledAction, Cond, Eff, State, World};
use std::rc::Rc;

/// Applies a replay's steps, one after another, to its state.
pub(super) struct Stepper<'a> {
    world: &'a World,
    actions: Actions<'a>,
    /// `None`: every step takes the general path.
    ground: Option<GroundActions<'a>>,
    binding: Vec<u32>,
    /// Kept from step to step so that a long replay does not allocate it
    /// again for each.
    changes: Changes,
}

impl<'a> Stepper<'a> {
    pub fn new(world: &'a World, domain: &'a Domain, cached: bool) -> Stepper<'a> {
        Stepper {
            world,
            actions: Actions::new(world, domain),
            // Derived atoms are recomputed from all facts after every
            // change, which needs the facts in the state at each step.
            ground: (cached && world.model().derived.is_empty()).then(GroundActions::default),
            binding: Vec::new(),
            changes: Changes::default(),
        }
    }

    /// Applies one step: durative actions as start conditions, start
    /// effects, over-all and end conditions, end effects. Call
    /// [`Stepper::settle`] before reading `state`'s facts.
    pub fn apply(
        &mut self,
        state: &mut State,
        plan: &Plan,
        g: &'a GroundStep,
    ) -> Result<(), Diagnostic> {
        let world = self.world;
        let action = self.actions.get(g.action)?;
        let (c, a) = (&*action.compiled, action.ast);
        let binding = &mut self.binding;
        binding.clear();
        binding.extend_from_slice(&g.args);
        let step = &plan.steps[g.step];
        let duration = match &c.duration {
            Some(d) => world.value(state, d, binding, None).or(step.duration),
            None => step.duration,
        };
        let mut ctx = StepCtx {
            world,
            plan,
            g,
            action: a,
            duration,
            binding,
            changes: &mut self.changes,
        };
        let start_phase = if a.durative {
            "its `at start` condition"
        } else {
            "its precondition"
        };
        let Some(ground) = &mut self.ground else {
            ctx.check(state, &c.pre_start, &a.pre_start, start_phase)?;
            if a.durative {
                ctx.apply_effects(state, &c.eff_start, None)?;
                ctx.check(state, &c.pre_over_all, &a.pre_over_all, OVER_ALL)?;
                ctx.check(state, &c.pre_end, &a.pre_end, AT_END)?;
            }
            return ctx.apply_effects(state, &c.eff_end, None);
        };
        let (ga, facts) = ground.get(g.action, c, &g.args, state);
        ctx.check_cached(
            state,
            &ga.pre_start,
            &c.pre_start,
            &a.pre_start,
            start_phase,
            facts,
        )?;
        if a.durative {
            ctx.apply_cached(state, &ga.eff_start, &c.eff_start, facts)?;
            ctx.check_cached(
                state,
                &ga.pre_over_all,
                &c.pre_over_all,
                &a.pre_over_all,
                OVER_ALL,
                facts,
            )?;
            ctx.check_cached(state, &ga.pre_end, &c.pre_end, &a.pre_end, AT_END, facts)?;
        }
        ctx.apply_cached(state, &ga.eff_end, &c.eff_end, facts)
    }

    /// Brings `state`'s facts up to date with every step applied.
    pub fn settle(&mut self, state: &mut State) {
        if let Some(ground) = &mut self.ground {
            ground.facts.flush(state);
        }
    }
}

const OVER_ALL: &str = "its `over all` condition";
const AT_END: &str = "its `at end` condition";

/// The domain's actions, each converted and compiled once, when a step
/// first uses it.
pub(super) struct Actions<'a> {
    world: &'a World,
    domain: &'a Domain,
    compiled: Vec<Option<Rc<CompiledAction>>>,
}

impl<'a> Actions<'a> {
    pub fn new(world: &'a World, domain: &'a Domain) -> Actions<'a> {
        Actions {
            world,
            domain,
            compiled: vec![None; domain.actions.len()],
        }
    }

    pub fn get(&mut self, i: usize) -> Result<Step<'a>, Diagnostic> {
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
            self.compiled[i] = Some(Rc::new(c));
        }
        Ok(Step {
            ast,
            compiled: self.compiled[i].clone().expect("compiled above"),
        })
    }
}

/// An action as the AST has it (for spans) and compiled (to evaluate).
pub(super) struct Step<'a> {
    pub ast: &'a Action,
    pub compiled: Rc<CompiledAction>,
}

struct StepCtx<'w> {
    world: &'w World,
    plan: &'w Plan,
    g: &'w GroundStep,
    action: &'w Action,
    duration: Option<f64>,
    binding: &'w mut Vec<u32>,
    changes: &'w mut Changes,
}

impl StepCtx<'_> {
    /// A phase's conditions by its cached literals; when they fail, or the
    /// phase has none, by the general path, which explains the failure.
    fn check_cached(
        &mut self,
        state: &mut State,
        ground: &GroundConds,
        conds: &[Cond],
        written: &[Formula],
        phase: &str,
        facts: &mut TrackedFacts,
    ) -> Result<(), Diagnostic> {
        if let GroundConds::Literals(literals) = ground {
            if facts.all_hold(literals) {
                return Ok(());
            }
        }
        facts.flush(state);
        self.check(state, conds, written, phase)
    }

    fn check(
        &mut self,
        state: &State,
        conds: &[Cond],
        written: &[Formula],
        phase: &str,
    ) -> Result<(), Diagnostic> {
        let world = self.world;
        for (c, f) in conds.iter().zip(written) {
            if !world.holds(state, c, self.binding, self.duration) {
                let (why, path) = world.why_not(state, c, self.binding, self.duration);
                return Err(self
                    .error(
                        codes::PRECONDITION_FAILS,
                        format_args!("{phase} does not hold: {why}"),
                    )
                    .with_label(logic::span_at(f, &path), "this condition fails"));
            }
        }
        Ok(())
    }

    /// An error at the step's line: `step N `(action args)`: {what}`.
    fn error(&self, code: crate::diagnostic::Code, what: std::fmt::Arguments) -> Diagnostic {
        let g = self.g;
        Diagnostic::error(
            code,
            self.plan.steps[g.step].span,
            format!(
                "step {} `{}`: {what}",
                g.step + 1,
                show_step(self.world, self.action, g)
            ),
        )
    }

    /// A phase's effects by its cached atoms (numeric updates still
    /// evaluated, on fluents the cache never holds back), or by the
    /// general path.
    fn apply_cached(
        &mut self,
        state: &mut State,
        ground: &GroundEffects,
        effects: &[Eff],
        facts: &mut TrackedFacts,
    ) -> Result<(), Diagnostic> {
        let GroundEffects::Cached {
            delete,
            add,
            numeric,
        } = ground
        else {
            facts.flush(state);
            return self.apply_effects(state, effects, Some(facts));
        };
        if numeric.is_empty() {
            facts.set(delete, false);
            facts.set(add, true);
            return Ok(());
        }
        self.collect(state, numeric)?;
        facts.set(delete, false);
        facts.set(add, true);
        // Only numeric changes: the world has no derived predicates to
        // recompute (or no step would be cached).
        self.world.apply_changes(state, self.changes);
        Ok(())
    }

    /// Applies effects by the general path; `facts`, when given, follows
    /// the changes.
    fn apply_effects(
        &mut self,
        state: &mut State,
        effects: &[Eff],
        facts: Option<&mut TrackedFacts>,
    ) -> Result<(), Diagnostic> {
        self.collect(state, effects)?;
        if let Some(facts) = facts {
            facts.note(self.changes);
        }
        self.world.apply_changes(state, self.changes);
        Ok(())
    }

    /// Gathers the changes of `effects` in `state`; fails on a numeric
    /// update of a fluent with no value.
    fn collect(&mut self, state: &State, effects: &[Eff]) -> Result<(), Diagnostic> {
        for e in effects {
            self.world
                .collect(state, e, self.binding, self.duration, self.changes);
        }
        if let Some(err) = self.changes.numeric_errors.first() {
            return Err(self
                .error(
                    codes::EFFECT_CONFLICT,
                    format_args!("`{}` has no value to update", err.fluent),
                )
                .with_label(self.action.name.span, "the action that updates it")
                .with_hint(
                    "give the function a value in the problem's `:init`, e.g. `(= (total-cost) 0)`",
                ));
        }
        Ok(())
    }
}
