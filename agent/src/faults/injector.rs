//! The ARIAC faults as the engine's injector: each fault's state at run
//! time, and what it does at the engine's hook points. Before a tick,
//! faults due start and faults whose time is up end; when a step or an
//! action starts, the faults it triggers start; an action of a robot a
//! fault holds fails or waits; a condition read in a sensor blackout
//! returns what the blackout says.

use super::scenario::{bad, Blackout, FaultSpec, Scenario, Trigger};
use super::FaultKind;
use btc_pddl::logic::{Atom, Formula, Terms};
use btc_pddl::state::Key;
use btc_runtime::engine::{ActionLeaf, FaultOutcome, FaultRecord, Injection, Interference};
use btc_runtime::kb::FormulaId;
use btc_runtime::{Injector, Kb, LoadError};

/// A fault at run time.
#[derive(Clone, Debug)]
pub struct FaultRt {
    pub spec: FaultSpec,
    pub met_at: Option<u64>,
    /// The tick at which its effect ends.
    pub until: Option<u64>,
    pub ended: bool,
    seen: u32,
    pending_fail: bool,
    /// Facts it removed and added (to undo, and to attribute failures).
    removed: Vec<Key>,
    added: Vec<Key>,
    shown: Vec<String>,
    goal: Option<FormulaId>,
}

impl FaultRt {
    fn armed(spec: FaultSpec, goal: Option<FormulaId>) -> FaultRt {
        FaultRt {
            spec,
            met_at: None,
            until: None,
            ended: false,
            seen: 0,
            pending_fail: false,
            removed: Vec::new(),
            added: Vec::new(),
            shown: Vec::new(),
            goal,
        }
    }

    fn in_effect(&self) -> bool {
        self.met_at.is_some() && !self.ended
    }
}

/// The faults of a run, armed, met or over: the injector the engine calls.
/// Replanning takes it out of one plan's engine and puts it into the next
/// one's, so a fault that fired does not fire again.
#[derive(Clone, Debug, Default)]
pub struct Faults {
    pub list: Vec<FaultRt>,
}

impl Faults {
    /// Arms a scenario's faults; their facts and goals are checked against
    /// the problem (`kb`), step triggers against the plan's `plan_steps`.
    pub fn arm(
        &mut self,
        s: &Scenario,
        mut kb: Option<&mut Kb<'_>>,
        plan_steps: usize,
    ) -> Result<(), LoadError> {
        for spec in &s.faults {
            let label = spec.label();
            let mut goal = None;
            if let Some(g) = &spec.goal {
                let kb = kb
                    .as_deref_mut()
                    .ok_or_else(|| bad("faults need a PDDL problem"))?;
                goal = Some(kb.formula(g).map_err(|m| {
                    bad(format!(
                        "fault `{label}`: goal `{g}` is not a condition of this problem: {m}"
                    ))
                })?);
            }
            let check_atoms = |kb: &Kb, list: &[Atom]| -> Result<(), LoadError> {
                for t in list {
                    kb.atom_key(t)
                        .map_err(|m| bad(format!("fault `{label}`: `{t}`: {m}")))?;
                }
                Ok(())
            };
            if let Some(kb) = kb.as_deref() {
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
                if k >= plan_steps {
                    return Err(bad(format!(
                        "fault `{label}`: the plan has no step {} ({plan_steps} steps)",
                        k + 1,
                    )));
                }
            }
            self.list.push(FaultRt::armed(spec.clone(), goal));
        }
        Ok(())
    }

    /// The goals of faults still to come, read again in the KB of the
    /// engine they move to.
    pub fn rebind(&mut self, mut kb: Option<&mut Kb<'_>>) {
        for rt in &mut self.list {
            rt.goal = match (&rt.spec.goal, kb.as_deref_mut()) {
                (Some(g), Some(kb)) => kb.formula(g).ok(),
                _ => None,
            };
        }
    }

    /// A fault that happened outside btc's engine (an embedder's behaviour
    /// reported it) at tick `met_at`, having removed and added these facts:
    /// over, with nothing left to do but to be named by what it changed.
    pub fn reported(
        &mut self,
        spec: FaultSpec,
        met_at: u64,
        removed: Vec<Key>,
        added: Vec<Key>,
        shown: Vec<String>,
    ) {
        self.list.push(FaultRt {
            met_at: Some(met_at),
            ended: true,
            seen: 1,
            removed,
            added,
            shown,
            ..FaultRt::armed(spec, None)
        });
    }

    /// Whether a fault with a duration (a malfunction, a pause, a
    /// blackout) is in effect.
    pub fn timed_in_effect(&self) -> bool {
        self.list
            .iter()
            .any(|rt| rt.in_effect() && rt.until.is_some())
    }

    /// The parts that faults discarded or found missing (`faulty_part`,
    /// `insufficient_parts`), with the fault's label.
    pub fn discarded_parts(&self) -> Vec<(String, String)> {
        self.list
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

    /// The met faults that removed or added a fact `lit` mentions, or
    /// whose part or robot it names (`lit`: a goal literal): their labels.
    pub fn naming(&self, lit: &Formula) -> Vec<String> {
        let objects = lit.objects();
        let text = lit.to_string();
        self.list
            .iter()
            .filter(|rt| rt.met_at.is_some())
            .filter(|rt| {
                [&rt.spec.part, &rt.spec.robot]
                    .into_iter()
                    .flatten()
                    .any(|o| objects.iter().any(|x| **x == **o))
                    || rt.shown.iter().any(|s| text.contains(s.as_str()))
            })
            .map(|rt| rt.spec.label())
            .collect()
    }

    fn trigger(&mut self, f: usize, run: &mut Injection<'_, '_>) {
        let tick = run.tick;
        run.happened(f);
        let rt = &mut self.list[f];
        rt.met_at = Some(tick);
        if let Some(kb) = run.kb.as_deref_mut() {
            let (add, retract) = rt.spec.changes(kb);
            rt.shown = retract.iter().chain(&add).map(|k| kb.show(k)).collect();
            kb.apply_keys(add.clone(), retract.clone());
            if let Some(g) = rt.goal {
                kb.add_goal(g);
            }
            rt.removed = retract;
            rt.added = add;
        }
        rt.pending_fail = rt.spec.kind == FaultKind::FaultyGripper;
        match rt.spec.duration {
            Some(d) if rt.spec.kind != FaultKind::FaultyGripper => {
                rt.until = Some(tick.saturating_add(d))
            }
            // A one-off: nothing to undo; it stays "in effect" only for a
            // gripper whose failure is still to happen.
            _ => rt.ended = !rt.pending_fail,
        }
    }

    fn end(&mut self, f: usize, run: &mut Injection<'_, '_>) {
        let rt = &mut self.list[f];
        rt.ended = true;
        // A malfunction is repaired: what it retracted comes back.
        if rt.spec.kind == FaultKind::RobotMalfunction {
            if let Some(kb) = run.kb.as_deref_mut() {
                kb.apply_keys(rt.removed.clone(), rt.added.clone());
            }
        }
        run.ended(f);
    }
}

impl Injector for Faults {
    fn live(&self) -> bool {
        self.list.iter().any(|f| f.met_at.is_none() || !f.ended)
    }

    fn before_tick(&mut self, run: &mut Injection<'_, '_>) {
        let tick = run.tick;
        for f in 0..self.list.len() {
            let rt = &self.list[f];
            if rt.in_effect() && rt.until.is_some_and(|u| tick >= u) {
                self.end(f, run);
            } else if rt.met_at.is_none() && rt.spec.trigger == Trigger::Tick(tick) {
                self.trigger(f, run);
            }
        }
    }

    fn step_started(&mut self, run: &mut Injection<'_, '_>, step: usize) {
        for f in 0..self.list.len() {
            if self.list[f].met_at.is_none() && self.list[f].spec.trigger == Trigger::Step(step) {
                self.trigger(f, run);
            }
        }
    }

    fn action(
        &mut self,
        run: &mut Injection<'_, '_>,
        leaf: &ActionLeaf<'_>,
        fresh: bool,
    ) -> Option<Interference> {
        if fresh {
            for f in 0..self.list.len() {
                let rt = &mut self.list[f];
                let fire = match &rt.spec.trigger {
                    Trigger::Action { id, occurrence, .. }
                        if rt.met_at.is_none() && id == leaf.id =>
                    {
                        rt.seen += 1;
                        rt.seen >= *occurrence
                    }
                    _ => false,
                };
                if fire {
                    self.trigger(f, run);
                }
            }
        }
        for (f, rt) in self.list.iter_mut().enumerate() {
            if !rt.in_effect() {
                continue;
            }
            let Some(robot) = rt.spec.robot.as_deref() else {
                continue;
            };
            if !leaf.mentions(robot) {
                continue;
            }
            let label = rt.spec.label();
            match rt.spec.kind {
                FaultKind::RobotMalfunction => {
                    return Some(Interference::Fail {
                        fault: f,
                        reason: format!("robot `{robot}` malfunctions (fault `{label}`)"),
                    });
                }
                FaultKind::FaultyGripper if rt.pending_fail => {
                    rt.pending_fail = false;
                    rt.ended = true;
                    return Some(Interference::Fail {
                        fault: f,
                        reason: format!(
                            "the gripper of `{robot}` dropped the part (fault `{label}`)"
                        ),
                    });
                }
                // Paused: the action waits (or does not start yet).
                FaultKind::HumanTooClose | FaultKind::HighPriorityOrder if rt.until.is_some() => {
                    return Some(Interference::Wait);
                }
                _ => {}
            }
        }
        None
    }

    fn condition(&self) -> Option<Interference> {
        let (f, rt) = self
            .list
            .iter()
            .enumerate()
            .find(|(_, rt)| rt.in_effect() && rt.spec.kind == FaultKind::SensorBlackout)?;
        Some(match rt.spec.blackout {
            Blackout::Running => Interference::Wait,
            Blackout::Failure => Interference::Fail {
                fault: f,
                reason: format!(
                    "sensor blackout: the condition cannot be read (fault `{}`)",
                    rt.spec.label()
                ),
            },
        })
    }

    fn describe(&self, fault: usize) -> Option<(String, &'static str)> {
        self.list
            .get(fault)
            .map(|f| (f.spec.label(), f.spec.kind.name()))
    }

    /// The one that caused it, those in effect, and those whose facts or
    /// goal the reason names.
    fn attributed(&self, cause: Option<usize>, reason: &str) -> Vec<String> {
        let mut out = Vec::new();
        for (f, rt) in self.list.iter().enumerate() {
            if rt.met_at.is_none() {
                continue;
            }
            let named = rt.shown.iter().any(|s| reason.contains(s.as_str()))
                || rt
                    .spec
                    .goal
                    .as_ref()
                    .is_some_and(|g| reason.contains(&g.to_string()));
            if cause == Some(f) || named || rt.in_effect() {
                out.push(rt.spec.label());
            }
        }
        out
    }

    fn outcomes(&self, success: bool, records: &[FaultRecord]) -> Vec<FaultOutcome> {
        self.list
            .iter()
            .map(|rt| {
                let label = rt.spec.label();
                let ended = if rt.met_at.is_none() {
                    "not met".to_owned()
                } else if success {
                    "recovered".to_owned()
                } else {
                    match records.iter().rev().find(|r| r.faults.contains(&label)) {
                        Some(r) => format!("not recovered: {} failed: {}", r.node_name, r.reason),
                        None => "not recovered".to_owned(),
                    }
                };
                FaultOutcome {
                    fault: label,
                    kind: rt.spec.kind.name(),
                    met_at: rt.met_at,
                    ended,
                }
            })
            .collect()
    }
}
