//! The fault-injection hook: a caller's [`Injector`] changes a run from
//! outside the tree at four points (before a tick, when a plan step starts,
//! when an action leaf is ticked, when a condition is read) and names the
//! faults a failure is attributed to. The engine knows no kind of fault:
//! what a fault is, when it happens and what it does are the injector's
//! (the ARIAC 2023 challenges are one injector, in `btc-agent`). The
//! engine owns the injector only while it runs, as it owns its observers:
//! the caller takes it back, with its state, by its type.

use super::record::{FaultRecord, Reason};
use super::{Engine, Status, TickEvent};
use crate::kb::Kb;
use serde::Serialize;
use std::any::Any;

/// What an injected fault does to the node the engine asked about.
#[derive(Clone, Debug, PartialEq)]
pub enum Interference {
    /// The node waits: RUNNING (an action not started yet or paused, a
    /// condition that cannot be read yet).
    Wait,
    /// The node fails because of fault `fault`, for `reason` (words for
    /// the fault record).
    Fail { fault: usize, reason: String },
}

/// An action leaf being ticked, as an injector sees it.
pub struct ActionLeaf<'a> {
    /// Its node ID (`Grasp`).
    pub id: &'a str,
    /// The texts its ports hold now (the objects it acts on).
    pub ports: &'a [&'a str],
}

impl ActionLeaf<'_> {
    /// Whether one of its ports holds `object`.
    pub fn mentions(&self, object: &str) -> bool {
        self.ports.contains(&object)
    }
}

/// What an injector may change when it is called: the run's clock and its
/// knowledge base; and what it tells the observers.
pub struct Injection<'a, 'w> {
    pub tick: u64,
    pub kb: Option<&'a mut Kb<'w>>,
    told: Vec<(usize, bool)>,
}

impl Injection<'_, '_> {
    /// Fault `fault` happened now (observers are told).
    pub fn happened(&mut self, fault: usize) {
        self.told.push((fault, false));
    }

    /// Fault `fault`'s effect ended now (observers are told).
    pub fn ended(&mut self, fault: usize) {
        self.told.push((fault, true));
    }
}

/// How an injected fault ended, for the run's summary.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct FaultOutcome {
    pub fault: String,
    /// The name of its kind (`faulty_gripper`).
    pub kind: &'static str,
    pub met_at: Option<u64>,
    /// `not met`, `recovered` or `not recovered: REASON`.
    pub ended: String,
}

/// Faults injected into a run. Every hook has a default that does
/// nothing, so an injector says only what its faults do.
pub trait Injector: Any {
    /// Whether a fault may still happen or is in effect: while it is not,
    /// leaves do not call the injector.
    fn live(&self) -> bool;

    /// Before each tick (and each tick that passes with no tree ticked:
    /// [`Engine::pass_tick`]).
    fn before_tick(&mut self, _run: &mut Injection<'_, '_>) {}

    /// When plan step `step` (0-based) starts.
    fn step_started(&mut self, _run: &mut Injection<'_, '_>, _step: usize) {}

    /// When an action leaf is ticked (`fresh`: it starts now); `Some`
    /// overrides the tick.
    fn action(
        &mut self,
        _run: &mut Injection<'_, '_>,
        _leaf: &ActionLeaf<'_>,
        _fresh: bool,
    ) -> Option<Interference> {
        None
    }

    /// When a condition is read; `Some` overrides what it returns.
    fn condition(&self) -> Option<Interference> {
        None
    }

    /// The label and kind name of fault `fault` (for observers).
    fn describe(&self, fault: usize) -> Option<(String, &'static str)>;

    /// The labels of the faults a failure is attributed to: `cause` is the
    /// fault that made the node fail, if one did; `reason` the record's
    /// words.
    fn attributed(&self, cause: Option<usize>, reason: &str) -> Vec<String>;

    /// How each fault ended, given whether the run succeeded and its
    /// fault records.
    fn outcomes(&self, success: bool, records: &[FaultRecord]) -> Vec<FaultOutcome>;
}

impl<'w> Engine<'w> {
    /// Injects faults into the run (in place of any injector given
    /// before).
    pub fn inject(&mut self, injector: impl Injector) {
        self.inject_live = injector.live();
        self.injector = Some(Box::new(injector));
    }

    /// The injector, if it is of type `I`.
    pub fn injector<I: Injector>(&self) -> Option<&I> {
        let i: &dyn Any = self.injector.as_deref()?;
        i.downcast_ref::<I>()
    }

    /// Takes the injector back, if it is of type `I`: the engine keeps no
    /// faults after.
    pub fn take_injector<I: Injector>(&mut self) -> Option<I> {
        self.injector::<I>()?;
        let b: Box<dyn Any> = self.injector.take()?;
        self.inject_live = false;
        b.downcast::<I>().ok().map(|b| *b)
    }

    /// The number of the plan's steps (skipped ones too): what a step
    /// trigger may name.
    pub fn plan_steps(&self) -> usize {
        self.steps.len()
    }

    /// One tick passes with no tree ticked (waiting for a repair): the
    /// clock moves and the injector is called as before a tick.
    pub fn pass_tick(&mut self) {
        self.tick += 1;
        self.now_ms = self.tick.saturating_mul(self.opts.ms_per_tick);
        self.inject_before_tick();
    }

    /// How each injected fault ended, given the run's result.
    pub fn fault_outcomes(&self, success: bool) -> Vec<FaultOutcome> {
        self.injector
            .as_ref()
            .map(|i| i.outcomes(success, &self.records))
            .unwrap_or_default()
    }

    /// Calls the injector with the run's clock and KB, then tells the
    /// observers what it said happened.
    fn with_injector<R>(
        &mut self,
        call: impl FnOnce(&mut dyn Injector, &mut Injection<'_, 'w>) -> R,
    ) -> Option<R> {
        let mut inj = self.injector.take()?;
        let mut run = Injection {
            tick: self.tick,
            kb: self.kb.as_mut(),
            told: Vec::new(),
        };
        let r = call(inj.as_mut(), &mut run);
        let told = run.told;
        self.inject_live = inj.live();
        self.injector = Some(inj);
        if self.observed() {
            for (fault, ended) in told {
                self.notify(TickEvent::Fault {
                    tick: self.tick,
                    fault,
                    ended,
                });
            }
        }
        Some(r)
    }

    pub(crate) fn inject_before_tick(&mut self) {
        self.with_injector(|i, run| i.before_tick(run));
    }

    pub(crate) fn inject_on_step(&mut self, step: usize) {
        self.with_injector(|i, run| i.step_started(run, step));
    }

    /// What injected faults do to action leaf `i` (action `a`): `Some`
    /// overrides its tick; a failure is noted and recorded.
    pub(crate) fn inject_on_action(&mut self, i: u32, a: u32, fresh: bool) -> Option<Status> {
        let (p, q) = self.actions[a as usize].ports;
        let texts: Vec<std::rc::Rc<str>> = self.ports[p as usize..q as usize]
            .iter()
            .filter_map(|b| match self.value(&b.src) {
                super::Value::Text(t) => Some(t.clone()),
                _ => None,
            })
            .collect();
        let ports: Vec<&str> = texts.iter().map(|t| &**t).collect();
        let id = self.actions[a as usize].id.clone();
        let leaf = ActionLeaf {
            id: &id,
            ports: &ports,
        };
        match self.with_injector(|inj, run| inj.action(run, &leaf, fresh))? {
            None => None,
            Some(Interference::Wait) => Some(Status::Running),
            Some(Interference::Fail { fault, reason }) => {
                let r = Reason::Fault(fault, reason);
                self.note_failure(i, r.clone());
                self.record(i, &r);
                Some(Status::Failure)
            }
        }
    }

    /// What injected faults make condition node `i` return: `Some`
    /// overrides it; a failure is noted (the node's parent records it).
    pub(crate) fn inject_on_condition(&mut self, i: u32) -> Option<Status> {
        if !self.inject_live {
            return None;
        }
        match self.injector.as_ref()?.condition()? {
            Interference::Wait => Some(Status::Running),
            Interference::Fail { fault, reason } => {
                self.note_failure(i, Reason::Fault(fault, reason));
                Some(Status::Failure)
            }
        }
    }

    /// The faults a failure is attributed to.
    pub(crate) fn faults_related(&self, r: &Reason, reason: &str) -> Vec<String> {
        let cause = match r {
            Reason::Fault(f, _) => Some(*f),
            _ => None,
        };
        self.injector
            .as_ref()
            .map(|i| i.attributed(cause, reason))
            .unwrap_or_default()
    }
}
