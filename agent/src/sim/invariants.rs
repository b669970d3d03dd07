//! The checking mode (`TrialOptions::check`, the soak test's): after
//! every tick, each part is in exactly one place (or none, before it
//! arrives and after it is gone), no robot holds two things, no resource
//! is held twice, and only running tasks reserve parts.

use super::model::Sim;
use super::options::TrialError;
use super::tasks::TaskState;
use crate::cell::Var;

impl Sim<'_, '_> {
    pub(super) fn check(&self) -> Result<(), TrialError> {
        let s = &self.w.kb.state;
        let bad = |what: String| TrialError::Inconsistent {
            tick: self.tick,
            what,
        };
        for p in self.w.parts.iter() {
            let places = self.w.facts.places(s, p.obj);
            let in_cell = p.gone.is_none() && p.spawn.is_none_or(|t| t <= self.tick);
            let expect = usize::from(in_cell);
            if places.len() != expect {
                return Err(bad(format!(
                    "{} is in {} places ({:?}); it should be in {expect}",
                    p.info.name,
                    places.len(),
                    places
                )));
            }
        }
        for a in &self.agents {
            let held = s
                .facts
                .iter()
                .filter(|k| self.w.facts.holding.get(k, Var::Robot) == Some(a.obj))
                .count();
            let empty = s
                .facts
                .contains(&self.w.facts.hand_empty.key(&[(Var::Robot, a.obj)]));
            if held > 1 || (held == 1 && empty) {
                return Err(bad(format!(
                    "{} holds {held} parts and its hand is {}empty",
                    self.w.name(a.obj),
                    if empty { "" } else { "not " }
                )));
            }
        }
        for (i, (r, t)) in self.w.held.iter().enumerate() {
            for (r2, t2) in &self.w.held[i + 1..] {
                if t != t2 && r.conflicts(*r2) {
                    return Err(bad(format!("{r:?} is held by {t} and {r2:?} by {t2}")));
                }
            }
        }
        for (k, p) in self.w.parts.with_ids() {
            if let Some(t) = p.reserved {
                if !matches!(self.tm.tasks[t].state, TaskState::Running { .. }) {
                    return Err(bad(format!(
                        "part {k} is reserved by task {t}, which is not running"
                    )));
                }
            }
        }
        Ok(())
    }
}
