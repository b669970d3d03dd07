//! The faults hook: what injected faults do to the tick. Before a tick,
//! faults due start and faults whose time is up end; when a step or an
//! action starts, the faults it triggers start; an action of a robot a
//! fault holds fails or waits; a condition read in a sensor blackout
//! returns what the blackout says. The scenarios and the faults' state are
//! data in [`crate::faults`].

use super::record::Reason;
use super::{Engine, Status, TickEvent};
use crate::error::LoadError;
use crate::faults::{bad, Blackout, FaultKind, FaultOutcome, FaultRt, Scenario, Trigger};
use btc_pddl::logic::Atom;

impl<'w> Engine<'w> {
    /// Arms a scenario's faults; their facts and goals are checked against
    /// the problem.
    pub fn add_faults(&mut self, s: &Scenario) -> Result<(), LoadError> {
        for spec in &s.faults {
            let label = spec.label();
            let mut goal = None;
            if let Some(g) = &spec.goal {
                let kb = self
                    .kb
                    .as_mut()
                    .ok_or_else(|| bad("faults need a PDDL problem"))?;
                goal = Some(kb.formula(g).map_err(|m| {
                    bad(format!(
                        "fault `{label}`: goal `{g}` is not a condition of this problem: {m}"
                    ))
                })?);
            }
            let check_atoms = |kb: &mut crate::kb::Kb, list: &[Atom]| -> Result<(), LoadError> {
                for t in list {
                    kb.atom_key(t)
                        .map_err(|m| bad(format!("fault `{label}`: `{t}`: {m}")))?;
                }
                Ok(())
            };
            if let Some(kb) = self.kb.as_mut() {
                check_atoms(kb, spec.retract.as_deref().unwrap_or(&[]))?;
                check_atoms(kb, &spec.add)?;
                for o in [&spec.robot, &spec.part].into_iter().flatten() {
                    if kb.object(o).is_none() {
                        return Err(bad(format!(
                            "fault `{label}`: `{o}` is not an object of the problem"
                        )));
                    }
                }
            } else if spec.retract.is_some() || !spec.add.is_empty() || spec.part.is_some() {
                return Err(bad(format!(
                    "fault `{label}` changes the KB, and no PDDL problem was given"
                )));
            }
            if let Trigger::Step(k) = spec.trigger {
                if k >= self.steps.len() {
                    return Err(bad(format!(
                        "fault `{label}`: the plan has no step {} ({} steps)",
                        k + 1,
                        self.steps.len()
                    )));
                }
            }
            self.faults.push(FaultRt {
                spec: spec.clone(),
                met_at: None,
                until: None,
                ended: false,
                seen: 0,
                pending_fail: false,
                removed: Vec::new(),
                added: Vec::new(),
                shown: Vec::new(),
                goal,
            });
        }
        self.refresh_live();
        Ok(())
    }

    fn refresh_live(&mut self) {
        self.faults_live = self.faults.iter().any(|f| f.met_at.is_none() || !f.ended);
    }

    fn trigger(&mut self, f: usize) {
        let tick = self.tick;
        let spec = self.faults[f].spec.clone();
        self.faults[f].met_at = Some(tick);
        if self.observed() {
            self.notify(TickEvent::Fault {
                tick,
                fault: f,
                ended: false,
            });
        }
        // KB changes.
        if let Some(kb) = self.kb.as_mut() {
            let (add, retract) = spec.changes(kb);
            let shown: Vec<String> = retract.iter().chain(&add).map(|k| kb.show(k)).collect();
            kb.apply_keys(add.clone(), retract.clone());
            if let Some(g) = self.faults[f].goal {
                kb.add_goal(g);
            }
            let rt = &mut self.faults[f];
            rt.removed = retract;
            rt.added = add;
            rt.shown = shown;
        }
        let rt = &mut self.faults[f];
        rt.pending_fail = spec.kind == FaultKind::FaultyGripper;
        match spec.duration {
            Some(d) if spec.kind != FaultKind::FaultyGripper => {
                rt.until = Some(tick.saturating_add(d))
            }
            _ => {
                // A one-off: nothing to undo; it stays "in effect" only for
                // a gripper whose failure is still to happen.
                rt.ended = !rt.pending_fail;
            }
        }
        self.refresh_live();
    }

    fn end_fault(&mut self, f: usize) {
        let rt = &mut self.faults[f];
        rt.ended = true;
        // A malfunction is repaired: what it retracted comes back.
        if rt.spec.kind == FaultKind::RobotMalfunction {
            let (add, del) = (
                std::mem::take(&mut rt.removed),
                std::mem::take(&mut rt.added),
            );
            if let Some(kb) = self.kb.as_mut() {
                kb.apply_keys(add.clone(), del.clone());
            }
            let rt = &mut self.faults[f];
            rt.removed = add;
            rt.added = del;
        }
        if self.observed() {
            self.notify(TickEvent::Fault {
                tick: self.tick,
                fault: f,
                ended: true,
            });
        }
        self.refresh_live();
    }

    /// Takes the faults' run-time state out of the engine (which keeps no
    /// faults): replanning moves it to the next plan's engine, so a fault
    /// that fired does not fire again.
    pub fn take_faults(&mut self) -> Vec<FaultRt> {
        let v = std::mem::take(&mut self.faults);
        self.refresh_live();
        v
    }

    /// Puts faults taken from an earlier engine into this one; the goals
    /// of faults still to come are re-read in this engine's KB.
    pub fn restore_faults(&mut self, mut faults: Vec<FaultRt>) {
        for rt in &mut faults {
            rt.goal = match (&rt.spec.goal, self.kb.as_mut()) {
                (Some(g), Some(kb)) => kb.formula(g).ok(),
                _ => None,
            };
        }
        self.faults = faults;
        self.refresh_live();
    }

    /// Whether a fault with a duration (a malfunction, a pause, a
    /// blackout) is in effect.
    pub fn timed_fault_in_effect(&self) -> bool {
        (0..self.faults.len()).any(|f| self.in_effect(f) && self.faults[f].until.is_some())
    }

    /// Lets time pass, with no tree ticked, until no fault with a duration
    /// is in effect or tick `limit` is reached; faults due meanwhile start
    /// and end (a malfunction's repair gives its facts back). Returns the
    /// ticks waited.
    pub fn wait_for_faults(&mut self, limit: u64) -> u64 {
        let start = self.tick;
        while self.timed_fault_in_effect() && self.tick < limit {
            self.tick += 1;
            self.now_ms = self.tick.saturating_mul(self.opts.ms_per_tick);
            self.faults_before_tick();
        }
        self.tick - start
    }

    /// The parts that faults discarded or found missing (`faulty_part`,
    /// `insufficient_parts`), with the fault's label.
    pub fn discarded_parts(&self) -> Vec<(String, String)> {
        self.faults
            .iter()
            .filter(|rt| {
                rt.met_at.is_some()
                    && matches!(
                        rt.spec.kind,
                        FaultKind::FaultyPart | FaultKind::InsufficientParts
                    )
            })
            .filter_map(|rt| rt.spec.part.clone().map(|p| (p, rt.spec.label())))
            .collect()
    }

    pub(crate) fn faults_before_tick(&mut self) {
        let tick = self.tick;
        for f in 0..self.faults.len() {
            let rt = &self.faults[f];
            if rt.met_at.is_some() && !rt.ended && rt.until.is_some_and(|u| tick >= u) {
                self.end_fault(f);
            } else if rt.met_at.is_none() && rt.spec.trigger == Trigger::Tick(tick) {
                self.trigger(f);
            }
        }
    }

    pub(crate) fn faults_on_step(&mut self, step: usize) {
        for f in 0..self.faults.len() {
            if self.faults[f].met_at.is_none() && self.faults[f].spec.trigger == Trigger::Step(step)
            {
                self.trigger(f);
            }
        }
    }

    fn in_effect(&self, f: usize) -> bool {
        let rt = &self.faults[f];
        rt.met_at.is_some() && !rt.ended
    }

    /// What faults do to an action leaf: `Some(status)` overrides its tick.
    pub(crate) fn faults_on_action(&mut self, i: u32, a: u32, fresh: bool) -> Option<Status> {
        if fresh {
            for f in 0..self.faults.len() {
                let fire = match &self.faults[f].spec.trigger {
                    Trigger::Action { id, occurrence, .. }
                        if self.faults[f].met_at.is_none()
                            && **id == *self.actions[a as usize].id =>
                    {
                        let occ = *occurrence;
                        self.faults[f].seen += 1;
                        self.faults[f].seen >= occ
                    }
                    _ => false,
                };
                if fire {
                    self.trigger(f);
                }
            }
        }
        for f in 0..self.faults.len() {
            if !self.in_effect(f) {
                continue;
            }
            let spec = &self.faults[f].spec;
            let Some(robot) = spec.robot.clone() else {
                continue;
            };
            if !self.action_mentions(a, &robot) {
                continue;
            }
            let label = spec.label();
            match spec.kind {
                FaultKind::RobotMalfunction => {
                    let r =
                        Reason::Fault(f, format!("robot `{robot}` malfunctions (fault `{label}`)"));
                    self.note_failure(i, r.clone());
                    self.record(i, &r);
                    return Some(Status::Failure);
                }
                FaultKind::FaultyGripper if self.faults[f].pending_fail => {
                    self.faults[f].pending_fail = false;
                    self.faults[f].ended = true;
                    self.refresh_live();
                    let r = Reason::Fault(
                        f,
                        format!("the gripper of `{robot}` dropped the part (fault `{label}`)"),
                    );
                    self.note_failure(i, r.clone());
                    self.record(i, &r);
                    return Some(Status::Failure);
                }
                FaultKind::HumanTooClose | FaultKind::HighPriorityOrder
                    if self.faults[f].until.is_some() =>
                {
                    // Paused: the action waits (or does not start yet).
                    return Some(Status::Running);
                }
                _ => {}
            }
        }
        None
    }

    /// During a sensor blackout: what conditions return.
    pub(crate) fn blackout(&self) -> Option<Status> {
        if !self.faults_live {
            return None;
        }
        (0..self.faults.len())
            .find(|&f| self.in_effect(f) && self.faults[f].spec.kind == FaultKind::SensorBlackout)
            .map(|f| match self.faults[f].spec.blackout {
                Blackout::Running => Status::Running,
                Blackout::Failure => Status::Failure,
            })
    }

    pub(crate) fn note_blackout(&mut self, i: u32) {
        if let Some(f) = (0..self.faults.len())
            .find(|&f| self.in_effect(f) && self.faults[f].spec.kind == FaultKind::SensorBlackout)
        {
            let label = self.faults[f].spec.label();
            self.note_failure(
                i,
                Reason::Fault(
                    f,
                    format!("sensor blackout: the condition cannot be read (fault `{label}`)"),
                ),
            );
        }
    }

    /// The faults a failure is attributed to: the one that caused it, those
    /// in effect, and those whose facts the reason names.
    pub(crate) fn faults_related(&self, r: &Reason, reason: &str) -> Vec<String> {
        let mut out = Vec::new();
        for (f, rt) in self.faults.iter().enumerate() {
            if rt.met_at.is_none() {
                continue;
            }
            let direct = matches!(r, Reason::Fault(g, _) if *g == f);
            let named = rt.shown.iter().any(|s| reason.contains(s.as_str()))
                || rt
                    .spec
                    .goal
                    .as_ref()
                    .is_some_and(|g| reason.contains(&g.to_string()));
            if direct || named || self.in_effect(f) {
                out.push(rt.spec.label());
            }
        }
        out
    }

    /// How each fault ended, given the run's result.
    pub fn fault_outcomes(&self, success: bool) -> Vec<FaultOutcome> {
        self.faults
            .iter()
            .map(|rt| {
                let label = rt.spec.label();
                let ended = if rt.met_at.is_none() {
                    "not met".to_owned()
                } else if success {
                    "recovered".to_owned()
                } else {
                    match self
                        .records
                        .iter()
                        .rev()
                        .find(|r| r.faults.contains(&label))
                    {
                        Some(r) => format!("not recovered: {} failed: {}", r.node_name, r.reason),
                        None => "not recovered".to_owned(),
                    }
                };
                FaultOutcome {
                    fault: label,
                    kind: rt.spec.kind,
                    met_at: rt.met_at,
                    ended,
                }
            })
            .collect()
    }
}
