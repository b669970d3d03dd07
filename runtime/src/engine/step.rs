//! Plan steps: a step node wraps the subtree of one plan step; it checks
//! the step's conditions and applies its effects to the KB, each time it
//! runs. With durations simulated ([`Engine::simulate_durations`]), a
//! timed step whose subtree is done sooner holds RUNNING until its
//! duration in ticks has passed since it started.

use super::record::Reason;
use super::{Engine, NodeDef, Status, TickEvent};
use crate::kb::{EffectId, FormulaId};

/// A plan step at run time.
#[derive(Clone, Debug, Default)]
pub(crate) struct StepRt {
    pub label: String,
    pub pre_start: Option<FormulaId>,
    pub pre_over_all: Option<FormulaId>,
    pub pre_end: Option<FormulaId>,
    pub eff_start: Option<EffectId>,
    pub eff_end: Option<EffectId>,
    pub skipped: bool,
    pub started: bool,
    pub finished: bool,
    /// The plan's stated duration of the step, in plan time units.
    pub duration: Option<f64>,
    /// Ticks the step lasts at least (0: as long as its subtree).
    pub min_ticks: u64,
    /// The tick it last started at.
    pub started_tick: u64,
    /// Its subtree is done and it waits for its duration to pass.
    pub holding: bool,
}

impl StepRt {
    /// What an action leaf of the step checks when it starts: the
    /// precondition, or (when at-start effects already changed the KB) the
    /// over-all condition.
    pub fn leaf_check(&self) -> Option<FormulaId> {
        if self.eff_start.is_some() {
            self.pre_over_all
        } else {
            self.pre_start.or(self.pre_over_all)
        }
    }
}

impl<'w> Engine<'w> {
    /// Makes each timed step last at least its duration times
    /// `ticks_per_unit` ticks (rounded up; 0 turns it off, the default):
    /// `btc run --ticks-per-time-unit`.
    pub fn simulate_durations(&mut self, ticks_per_unit: u32) {
        for s in &mut self.steps {
            s.min_ticks = match s.duration {
                // Rounded up, with a little slack so that 0.1 * 10 is 1.
                Some(d) if d > 0.0 => (d * f64::from(ticks_per_unit) - 1e-9).ceil().max(0.0) as u64,
                _ => 0,
            };
        }
    }

    #[inline(never)]
    pub(super) fn tick_step(&mut self, i: u32, def: NodeDef, k: u32) -> Status {
        let iu = i as usize;
        let ku = k as usize;
        if self.status[iu] != Status::Running {
            self.set(iu, Status::Running);
            if self.injector.is_some() {
                self.inject_on_step(ku);
            }
            self.step_running = Some(k);
            if let Some(st) = self.steps.get_mut(ku) {
                st.started_tick = self.tick;
                st.holding = false;
            }
            if self.observed() {
                self.notify(TickEvent::StepStarted {
                    tick: self.tick,
                    step: k,
                });
            }
            if let Some(st) = self.steps.get(ku) {
                // With at-start effects, the precondition is checked before
                // they apply; otherwise the step's action leaves check it.
                if st.eff_start.is_some() {
                    if let (Some(pre), Some(kb)) = (st.pre_start, self.kb.as_ref()) {
                        if !kb.holds(pre) {
                            self.note_failure(i, Reason::Precondition(pre));
                            return Status::Failure;
                        }
                    }
                }
                // Each run of the step applies its effects: a step redone
                // (a retry after a fault undid its work) re-establishes them.
                let eff = st.eff_start;
                self.steps[ku].started = true;
                if let (Some(e), Some(kb)) = (eff, self.kb.as_mut()) {
                    kb.apply(e);
                }
            }
        }
        if !self.steps.get(ku).is_some_and(|st| st.holding) {
            let c = self.kid(def, 0);
            let s = self.tick_node(c);
            if !s.is_done() {
                return s;
            }
            self.reset(c);
            if s == Status::Failure {
                return s;
            }
        }
        if let Some(st) = self.steps.get_mut(ku) {
            if self.tick < st.started_tick.saturating_add(st.min_ticks) {
                st.holding = true;
                return Status::Running;
            }
            st.holding = false;
        }
        if let Some(st) = self.steps.get(ku) {
            if let (Some(pre), Some(kb)) = (st.pre_end, self.kb.as_ref()) {
                if !kb.holds(pre) {
                    self.note_failure(i, Reason::EndCondition(pre));
                    return Status::Failure;
                }
            }
            let eff = st.eff_end;
            self.steps[ku].finished = true;
            if self.step_running == Some(k) {
                self.step_running = None;
            }
            if let (Some(e), Some(kb)) = (eff, self.kb.as_mut()) {
                kb.apply(e);
            }
            if self.observed() {
                self.notify(TickEvent::StepFinished {
                    tick: self.tick,
                    step: k,
                });
            }
        }
        Status::Success
    }
}
