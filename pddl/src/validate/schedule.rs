//! Post-hoc scheduling of a sequential plan into a timed one (the usual
//! deorder-and-schedule): each step starts as early as the steps before
//! it that it interferes with allow, `epsilon` after the last of them has
//! ended; steps that interfere with none of the earlier ones run at once.
//!
//! Why that is sound: two steps interfere when either changes an atom or a
//! fluent the other reads in any of its conditions or effects, or when one
//! adds what the other deletes (see [`super::interference`]). Interfering
//! steps keep their plan order and never overlap, so every atom a step
//! reads has, at each of its events, the value it had in the sequential
//! replay; steps that do not interfere cannot change what the other sees.
//! The result is checked by the temporal validator anyway; should it fail,
//! the steps are laid one after another (always valid when the sequential
//! plan is).

use super::interference::Footprint;
use super::step::Actions;
use super::timed::validate_timed;
use crate::ast::{Domain, Problem};
use crate::plan::{GroundStep, Plan, PlanFormat, PlanStep};
use crate::source::Span;
use crate::state::{Changes, World};
use serde::Serialize;
use std::sync::Arc;

/// A timed plan: when each step of the sequential plan starts, and for
/// how long it runs.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Schedule {
    pub starts: Vec<f64>,
    pub durations: Vec<f64>,
    /// The last end.
    pub makespan: f64,
    /// The durations' sum: the makespan of the steps one after another.
    pub sequential: f64,
    /// True when the deordered schedule failed its validation and the
    /// steps were laid one after another instead.
    pub serialized: bool,
}

/// Schedules `steps` (action index and arguments, a valid sequential plan
/// of `world`), or says why not: a step whose duration has no value.
pub fn schedule(
    world: &World,
    domain: &Domain,
    problem: &Problem,
    steps: &[(usize, Arc<[u32]>)],
    epsilon: f64,
) -> Result<Schedule, String> {
    let mut actions = Actions::new(world, domain);
    let mut state = world.initial_state();
    let mut changes = Changes::default();
    let mut footprints = Vec::with_capacity(steps.len());
    let mut durations = Vec::with_capacity(steps.len());
    for (action, args) in steps {
        let a = actions.get(*action).map_err(|d| d.message)?;
        let c = &*a.compiled;
        let mut b = args.to_vec();
        let duration = match (&c.duration, a.ast.durative) {
            (Some(d), true) => world.value(&state, d, &b, None).ok_or_else(|| {
                format!(
                    "the duration of `{}` has no value in the state where it starts",
                    a.ast.name.name
                )
            })?,
            _ => 0.0,
        };
        if !(duration.is_finite() && duration >= 0.0) {
            return Err(format!(
                "`{}` would take {duration}, which no step can take",
                a.ast.name.name
            ));
        }
        let conds: Vec<_> = [&c.pre_start, &c.pre_over_all, &c.pre_end]
            .into_iter()
            .flatten()
            .cloned()
            .collect();
        let effects: Vec<_> = c.eff_start.iter().chain(&c.eff_end).cloned().collect();
        footprints.push(Footprint::of(
            world,
            &state,
            &conds,
            &effects,
            &mut b,
            Some(duration),
        ));
        durations.push(duration);
        for phase in [&c.eff_start, &c.eff_end] {
            for e in phase {
                world.collect(&state, e, &mut b, Some(duration), &mut changes);
            }
            world.apply_changes(&mut state, &mut changes);
        }
    }
    let mut starts: Vec<f64> = Vec::with_capacity(steps.len());
    for (i, f) in footprints.iter().enumerate() {
        let earliest = (0..i)
            .filter(|&j| {
                f.clash(&footprints[j], world).is_some() || footprints[j].clash(f, world).is_some()
            })
            .map(|j| starts[j] + durations[j] + epsilon)
            .fold(0.0, f64::max);
        starts.push(to_millis(earliest));
    }
    let mut serialized = false;
    if !valid(world, domain, problem, steps, &starts, &durations, epsilon) {
        serialized = true;
        let mut t = 0.0;
        for (s, d) in starts.iter_mut().zip(&durations) {
            *s = to_millis(t);
            t = *s + d + epsilon;
        }
    }
    let makespan = starts
        .iter()
        .zip(&durations)
        .map(|(s, d)| s + d)
        .fold(0.0, f64::max);
    Ok(Schedule {
        sequential: durations.iter().sum(),
        starts,
        durations,
        makespan,
        serialized,
    })
}

/// `t` rounded up to the millisecond a plan file states (so that what VAL
/// reads back is no earlier than what was scheduled).
fn to_millis(t: f64) -> f64 {
    if t <= 0.0 {
        return 0.0;
    }
    (t * 1000.0 - 1e-6).ceil() / 1000.0
}

/// Whether the timed plan validates (with the durations as a plan file
/// states them, to the millisecond).
fn valid(
    world: &World,
    domain: &Domain,
    problem: &Problem,
    steps: &[(usize, Arc<[u32]>)],
    starts: &[f64],
    durations: &[f64],
    epsilon: f64,
) -> bool {
    let mut order: Vec<usize> = (0..steps.len()).collect();
    order.sort_by(|&a, &b| starts[a].total_cmp(&starts[b]));
    let span = Span::new(0, 0, 0);
    let name = |n: &str| crate::ast::Name {
        name: n.into(),
        span,
    };
    let plan = Plan {
        format: PlanFormat::Timed,
        steps: order
            .iter()
            .map(|&i| {
                let (action, args) = &steps[i];
                let durative = domain.actions[*action].durative;
                PlanStep::new(
                    name(&domain.actions[*action].name.name),
                    args.iter().map(|&o| name(world.object_name(o))).collect(),
                    Some(starts[i]),
                    durative.then(|| (durations[i] * 1000.0).round() / 1000.0),
                    0,
                    span,
                )
            })
            .collect(),
        stated_cost: None,
    };
    let ground: Vec<GroundStep> = order
        .iter()
        .enumerate()
        .map(|(n, &i)| GroundStep {
            step: n,
            action: steps[i].0,
            args: steps[i].1.clone(),
        })
        .collect();
    validate_timed(
        super::Replay::Cached,
        world,
        domain,
        problem,
        &plan,
        &ground,
        epsilon,
    )
    .valid
}
