//! Validation of a timed plan with PDDL 2.1's temporal semantics, as VAL
//! checks it: the plan is a sequence of happenings (the times at which
//! actions start and end); at each one, the conditions of every event are
//! checked in the state before it, events that interfere are refused, and
//! then every event's effects apply. A durative action's `over all`
//! condition must hold in every state strictly inside its interval; its
//! stated duration must be one its `:duration` allows.
//!
//! As the sequential replay, [`Replay::Cached`] tests and sets a step's
//! ground atoms in a table where that is exact (see [`super::ground`]),
//! and the general path evaluates the rest in a state flushed first. A
//! happening of several events is flushed before it starts: what its
//! events read and write is worked out from the state.

use super::ground::{GroundActions, GroundConds, GroundEffects};
use super::interference::Footprint;
use super::step::{Actions, Step};
use super::{finish, show_step, Replay, Validation};
use crate::ast::{Domain, Formula, Problem};
use crate::diagnostic::{codes, Diagnostic};
use crate::logic;
use crate::plan::{GroundStep, Plan};
use crate::state::{Changes, Cond, Eff, State, World};

/// The separation tolerance IPC uses (VAL's `-t 0.001`).
pub const DEFAULT_EPSILON: f64 = 0.001;

/// When an event happens within its action's interval.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Phase {
    /// A durative action's start.
    Start,
    /// A durative action's end.
    End,
    /// A plain action: its precondition and effect at one time.
    Instant,
}

/// One event: step `step` (an index into the ground steps) at `time`.
#[derive(Clone, Copy, Debug)]
struct Event {
    step: usize,
    phase: Phase,
    time: f64,
    /// An end's duration (its action's, known since its start).
    duration: Option<f64>,
    /// An end's ground action id, found at its start.
    ground: Option<usize>,
}

/// A durative action that has started and not yet ended.
struct Running {
    step: usize,
    /// Its ground action's id in the replay's [`GroundActions`].
    ground: Option<usize>,
    start: f64,
    end: f64,
    duration: f64,
}

/// Replays a plan whose steps all have times (`steps` in time order, as
/// the plan reader sorts them). Events less than `epsilon / 10` apart
/// form one happening, as in VAL: a plan must separate dependent events
/// by more than that (IPC plans use `epsilon` itself).
pub(super) fn validate_timed(
    replay: Replay,
    world: &World,
    domain: &Domain,
    problem: &Problem,
    plan: &Plan,
    steps: &[GroundStep],
    epsilon: f64,
) -> Validation {
    // Derived atoms are recomputed from all facts after every change,
    // which needs the facts in the state at each event.
    let cached = replay == Replay::Cached && world.model().derived.is_empty();
    let mut replay = TimedReplay {
        world,
        plan,
        steps,
        actions: Actions::new(world, domain),
        state: world.initial_state(),
        running: Vec::new(),
        started: 0,
        epsilon,
        changes: Changes::default(),
        binding: Vec::new(),
        events: Vec::new(),
        ready: Vec::new(),
    };
    let mut ground = cached.then(GroundActions::default);
    let ran = replay.run(ground.as_mut());
    if let Some(g) = &mut ground {
        g.facts.flush(&mut replay.state);
    }
    match ran {
        Ok(()) => finish(world, problem, plan, replay.state, steps.len(), Vec::new()),
        Err(d) => {
            let cost = super::cost(world, &replay.state, replay.started);
            Validation {
                valid: false,
                steps_applied: replay.started,
                cost,
                diagnostics: vec![d],
            }
        }
    }
}

struct TimedReplay<'a> {
    world: &'a World,
    plan: &'a Plan,
    steps: &'a [GroundStep],
    actions: Actions<'a>,
    state: State,
    running: Vec<Running>,
    /// Steps started (or, for plain actions, applied) so far.
    started: usize,
    epsilon: f64,
    changes: Changes,
    /// Buffers reused from event to event (a long plan has hundreds of
    /// thousands): a step's arguments as a binding, a happening's events
    /// and what they need (a buffer made for each happening cost a cache
    /// miss at its first write).
    binding: Vec<u32>,
    events: Vec<Event>,
    ready: Vec<Ready<'a>>,
}

/// An event with what it needs at its happening.
struct Ready<'a> {
    event: Event,
    action: Step<'a>,
    duration: Option<f64>,
    /// What it reads and writes, worked out only when the happening has
    /// other events it could interfere with (a long sequential plan has
    /// one event per happening).
    footprint: Option<Box<Footprint>>,
    /// Its ground action's id in the replay's [`GroundActions`].
    ground: Option<usize>,
}

impl<'a> TimedReplay<'a> {
    /// Replays every happening; with `ground`, the state's facts may lag
    /// behind its tracked atoms (flush it before reading them).
    fn run(&mut self, mut ground: Option<&mut GroundActions<'a>>) -> Result<(), Diagnostic> {
        loop {
            let next_start = self.steps.get(self.started).map(|g| self.time_of(g));
            let next_end = self.running.iter().map(|r| r.end).reduce(f64::min);
            let now = match (next_start, next_end) {
                (None, None) => return Ok(()),
                (Some(t), None) | (None, Some(t)) => t,
                (Some(s), Some(e)) => s.min(e),
            };
            let before = self.started;
            let happening = self.happening(now);
            if let Err(d) = self.apply_happening(now, happening, ground.as_deref_mut()) {
                // The steps of the failing happening did not apply.
                self.started = before;
                return Err(d);
            }
        }
    }

    fn time_of(&self, g: &GroundStep) -> f64 {
        self.plan.steps[g.step].time.unwrap_or(0.0)
    }

    /// The events within `epsilon / 10` of `now`: ends of running actions
    /// first, then starts in plan order.
    fn happening(&mut self, now: f64) -> Vec<Event> {
        let window = now + self.epsilon / 10.0;
        let mut events = std::mem::take(&mut self.events);
        events.clear();
        let mut i = 0;
        while i < self.running.len() {
            if self.running[i].end <= window {
                let r = self.running.remove(i);
                events.push(Event {
                    step: r.step,
                    phase: Phase::End,
                    time: r.end,
                    duration: Some(r.duration),
                    ground: r.ground,
                });
            } else {
                i += 1;
            }
        }
        while let Some(g) = self.steps.get(self.started) {
            let time = self.time_of(g);
            if time > window {
                break;
            }
            events.push(Event {
                step: self.started,
                phase: Phase::Instant, // a durative action's start: set from the action
                time,
                duration: None,
                ground: None,
            });
            self.started += 1;
        }
        events
    }

    fn apply_happening(
        &mut self,
        now: f64,
        mut events: Vec<Event>,
        mut ground: Option<&mut GroundActions<'a>>,
    ) -> Result<(), Diagnostic> {
        let world = self.world;
        // Left empty by the happening before (or by none).
        let mut ready = std::mem::take(&mut self.ready);
        let concurrent = events.len() > 1;
        if let (true, Some(g)) = (concurrent, ground.as_deref_mut()) {
            // The events' footprints are read from the state.
            g.facts.flush(&mut self.state);
        }
        for mut event in events.drain(..) {
            let g = &self.steps[event.step];
            let action = self.actions.get(g.action)?;
            if event.phase == Phase::Instant && action.ast.durative {
                event.phase = Phase::Start;
            }
            let duration = self.duration(&event, &action)?;
            let c = &*action.compiled;
            let (conds, effects): (&[Cond], &[Eff]) = match event.phase {
                Phase::Start => (&c.pre_start, &c.eff_start),
                Phase::End => (&c.pre_end, &c.eff_end),
                Phase::Instant => (&c.pre_start, &c.eff_end),
            };
            let footprint = concurrent.then(|| {
                let mut b = g.args.to_vec();
                Box::new(Footprint::of(
                    world,
                    &self.state,
                    conds,
                    effects,
                    &mut b,
                    duration,
                ))
            });
            let ground = event.ground.or_else(|| {
                ground
                    .as_deref_mut()
                    .map(|gr| gr.id(g.action, c, &g.args, &self.state))
            });
            ready.push(Ready {
                event,
                action,
                duration,
                footprint,
                ground,
            });
        }
        self.events = events;
        self.check_interference(now, &ready)?;
        for r in &ready {
            self.check_conditions(r, ground.as_deref_mut())?;
        }
        for r in &ready {
            self.apply_effects(r, ground.as_deref_mut())?;
            if r.event.phase == Phase::Start {
                let duration = r.duration.unwrap_or(0.0);
                self.running.push(Running {
                    step: r.event.step,
                    ground: r.ground,
                    start: r.event.time,
                    end: r.event.time + duration,
                    duration,
                });
            }
        }
        let checked = self.check_invariants(now, &ready, ground);
        ready.clear();
        self.ready = ready;
        checked
    }

    /// A starting durative action's duration: the plan's, checked against
    /// the domain's `:duration` in the state at its start, or the domain's
    /// when the plan states none.
    fn duration(&self, event: &Event, action: &Step) -> Result<Option<f64>, Diagnostic> {
        let g = &self.steps[event.step];
        let stated = self.plan.steps[g.step].duration;
        match event.phase {
            Phase::Instant => Ok(None),
            Phase::End => Ok(event.duration),
            Phase::Start => {
                let allowed = action
                    .compiled
                    .duration
                    .as_ref()
                    .and_then(|d| self.world.value(&self.state, d, &g.args, None));
                match (stated, allowed) {
                    (Some(s), Some(a)) if (s - a).abs() >= self.epsilon => {
                        let span = action
                            .ast
                            .duration
                            .as_ref()
                            .map_or(action.ast.name.span, |d| d.span);
                        Err(self
                            .error(
                                codes::DURATION_NOT_ALLOWED,
                                event,
                                action,
                                format_args!(
                                    "states a duration of {s}, but its `:duration` makes it {a} here"
                                ),
                            )
                            .with_label(span, "the duration the domain allows")
                            .with_hint(format!("write `[{a:.3}]` after the step")))
                    }
                    (Some(s), _) => Ok(Some(s)),
                    (None, Some(a)) if !(a.is_finite() && a >= 0.0) => Err(self.error(
                        codes::DURATION_NOT_ALLOWED,
                        event,
                        action,
                        format_args!(
                            "states no duration, and its `:duration` makes it {a} here, \
                             which no step can take"
                        ),
                    )),
                    (None, a) => Ok(a),
                }
            }
        }
    }

    /// Refuses two events of one happening that interfere.
    fn check_interference(&self, now: f64, ready: &[Ready]) -> Result<(), Diagnostic> {
        for (i, a) in ready.iter().enumerate() {
            for b in &ready[i + 1..] {
                let (Some(fa), Some(fb)) = (&a.footprint, &b.footprint) else {
                    continue;
                };
                let Some(clash) = fa.clash(fb, self.world) else {
                    continue;
                };
                let other = self.describe(b);
                return Err(self
                    .error(
                        codes::INTERFERENCE,
                        &a.event,
                        &a.action,
                        format_args!(
                            "{} {} at the same time as {other}, which {}",
                            subject(a.event.phase),
                            clash.first,
                            clash.second
                        ),
                    )
                    .with_label(
                        self.plan.steps[self.steps[b.event.step].step].span,
                        "the step it interferes with",
                    )
                    .with_hint(format!(
                        "PDDL 2.1 forbids interfering events at one time (t={}); separate \
                         them by at least {} (the tolerance, `--epsilon`)",
                        fmt_time(now),
                        self.epsilon
                    )));
            }
        }
        Ok(())
    }

    fn check_conditions(
        &mut self,
        r: &Ready,
        ground: Option<&mut GroundActions<'a>>,
    ) -> Result<(), Diagnostic> {
        if let (Some(ground), Some(id)) = (ground, r.ground) {
            let (ga, facts) = ground.parts(id);
            let literals = match r.event.phase {
                Phase::Start | Phase::Instant => &ga.pre_start,
                Phase::End => &ga.pre_end,
            };
            if let GroundConds::Literals(l) = literals {
                if facts.all_hold(l) {
                    return Ok(());
                }
            }
            // The general path says why not (or finds that it holds).
            facts.flush(&mut self.state);
        }
        let (c, a) = (&*r.action.compiled, r.action.ast);
        let (conds, written, what): (&[Cond], &[Formula], &str) = match r.event.phase {
            Phase::Start => (&c.pre_start, &a.pre_start, "its `at start` condition"),
            Phase::End => (&c.pre_end, &a.pre_end, "its `at end` condition"),
            Phase::Instant => (&c.pre_start, &a.pre_start, "its precondition"),
        };
        let mut b = self.binding_of(r.event.step);
        for (cond, f) in conds.iter().zip(written) {
            if !self.world.holds(&self.state, cond, &mut b, r.duration) {
                let (why, path) = self.world.why_not(&self.state, cond, &mut b, r.duration);
                return Err(self
                    .error(
                        codes::PRECONDITION_FAILS,
                        &r.event,
                        &r.action,
                        format_args!("{what} does not hold: {why}"),
                    )
                    .with_label(logic::span_at(f, &path), "this condition fails"));
            }
        }
        self.binding = b;
        Ok(())
    }

    fn apply_effects(
        &mut self,
        r: &Ready,
        ground: Option<&mut GroundActions<'a>>,
    ) -> Result<(), Diagnostic> {
        let c = &*r.action.compiled;
        let start = r.event.phase == Phase::Start;
        let mut effects: &[Eff] = if start { &c.eff_start } else { &c.eff_end };
        let mut tracked = None;
        if let (Some(ground), Some(id)) = (ground, r.ground) {
            let (ga, facts) = ground.parts(id);
            match if start { &ga.eff_start } else { &ga.eff_end } {
                GroundEffects::Cached {
                    delete,
                    add,
                    numeric,
                } => {
                    // Numeric updates read fluents only, which the
                    // table never holds back: evaluated here, applied
                    // with the atoms.
                    facts.set(delete, false);
                    facts.set(add, true);
                    if numeric.is_empty() {
                        return Ok(());
                    }
                    effects = numeric;
                }
                GroundEffects::General => {
                    facts.flush(&mut self.state);
                    tracked = Some(facts);
                }
            }
        }
        let mut b = self.binding_of(r.event.step);
        for e in effects {
            self.world
                .collect(&self.state, e, &mut b, r.duration, &mut self.changes);
        }
        self.binding = b;
        if let Some(facts) = tracked {
            facts.note(&self.changes);
        }
        if let Some(err) = self.changes.numeric_errors.first() {
            let d = self
                .error(
                    codes::EFFECT_CONFLICT,
                    &r.event,
                    &r.action,
                    format_args!("`{}` has no value to update", err.fluent),
                )
                .with_hint(
                    "give the function a value in the problem's `:init`, e.g. `(= (total-cost) 0)`",
                );
            self.changes = Changes::default();
            return Err(d);
        }
        self.world.apply_changes(&mut self.state, &mut self.changes);
        Ok(())
    }

    /// Every running action's `over all` condition, in the state after
    /// this happening (strictly inside its interval).
    fn check_invariants(
        &mut self,
        now: f64,
        ready: &[Ready],
        mut ground: Option<&mut GroundActions<'a>>,
    ) -> Result<(), Diagnostic> {
        let world = self.world;
        let steps = self.steps;
        for r in &self.running {
            let g = &steps[r.step];
            let action = self.actions.get(g.action)?;
            let (c, a) = (&*action.compiled, action.ast);
            if c.pre_over_all.is_empty() {
                continue;
            }
            if let (Some(ground), Some(id)) = (ground.as_deref_mut(), r.ground) {
                let (ga, facts) = ground.parts(id);
                if let GroundConds::Literals(l) = &ga.pre_over_all {
                    if facts.all_hold(l) {
                        continue;
                    }
                }
                facts.flush(&mut self.state);
            }
            let mut b = g.args.to_vec();
            for (cond, f) in c.pre_over_all.iter().zip(&a.pre_over_all) {
                if world.holds(&self.state, cond, &mut b, Some(r.duration)) {
                    continue;
                }
                let (why, path) = world.why_not(&self.state, cond, &mut b, Some(r.duration));
                let reads = Footprint::of(
                    world,
                    &self.state,
                    std::slice::from_ref(cond),
                    &[],
                    &mut b,
                    Some(r.duration),
                );
                let culprit = ready
                    .iter()
                    .find(|e| match &e.footprint {
                        Some(f) => f.changes_any(&reads),
                        // The happening's only event: it broke it.
                        None => true,
                    })
                    .map(|e| format!(" after {}", self.describe(e)))
                    .unwrap_or_default();
                let event = Event {
                    step: r.step,
                    phase: Phase::Start,
                    time: r.start,
                    duration: Some(r.duration),
                    ground: r.ground,
                };
                return Err(self
                    .error(
                        codes::OVER_ALL_BROKEN,
                        &event,
                        &action,
                        format_args!(
                            "its `over all` condition is broken at t={}{culprit}, while it runs \
                             (until t={}): {why}",
                            fmt_time(now),
                            fmt_time(r.end)
                        ),
                    )
                    .with_label(logic::span_at(f, &path), "this condition must hold throughout")
                    .with_hint(
                        "start the other step after this one ends, or end this one before the other starts",
                    ));
            }
        }
        Ok(())
    }

    /// Step `step`'s arguments as a binding, in the reused buffer (put it
    /// back in `self.binding` after use).
    fn binding_of(&mut self, step: usize) -> Vec<u32> {
        let mut b = std::mem::take(&mut self.binding);
        b.clear();
        b.extend_from_slice(&self.steps[step].args);
        b
    }

    /// "the start of step 3 `(move r2d2 wp1 wp2)`".
    fn describe(&self, r: &Ready) -> String {
        let g = &self.steps[r.event.step];
        format!(
            "{}step {} `{}`",
            phase_word(r.event.phase),
            g.step + 1,
            show_step(self.world, r.action.ast, g)
        )
    }

    /// An error at the event's step: `t=1.000: step N `(action args)`: {what}`.
    fn error(
        &self,
        code: crate::diagnostic::Code,
        event: &Event,
        action: &Step,
        what: std::fmt::Arguments,
    ) -> Diagnostic {
        let g = &self.steps[event.step];
        Diagnostic::error(
            code,
            self.plan.steps[g.step].span,
            format!(
                "t={}: step {} `{}`: {what}",
                fmt_time(event.time),
                g.step + 1,
                show_step(self.world, action.ast, g)
            ),
        )
    }
}

fn phase_word(p: Phase) -> &'static str {
    match p {
        Phase::Start => "the start of ",
        Phase::End => "the end of ",
        Phase::Instant => "",
    }
}

/// The event as the subject of a sentence about its step.
fn subject(p: Phase) -> &'static str {
    match p {
        Phase::Start => "its start",
        Phase::End => "its end",
        Phase::Instant => "it",
    }
}

fn fmt_time(t: f64) -> String {
    format!("{t:.3}")
}
