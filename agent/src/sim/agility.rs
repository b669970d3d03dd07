//! The challenges in the world: what each kind ([`super::challenges`])
//! does to the shared state and the agents' trees when it starts, while it
//! lasts and when it ends; and the placements and picks that set the
//! part challenges off.

use super::challenges::{fault, Kind};
use super::events::{ChallengeEvent, Event};
use super::model::Sim;
use super::world::PartId;
use crate::cell::Var;
use crate::faults::{FaultKind, FaultSpec, FaultsOnEngine, Scenario};
use crate::trial::{Condition, Robot, Task as OrderTask};
use btc_pddl::state::Key;

impl Sim<'_, '_> {
    /// Challenges on the clock: effects that end, drops that come, time
    /// conditions met; then the human's approach.
    pub(super) fn challenge_times(&mut self) {
        let tick = self.tick;
        for c in 0..self.challenges.len() {
            if self.challenges[c].expires(tick) {
                self.end_challenge(c);
                continue;
            }
            if let Kind::DroppedPart(d) = &self.challenges[c].kind {
                if let Some(part) = d.due(tick) {
                    self.drop_part(c, part);
                }
            }
            let ch = &self.challenges[c];
            if ch.met_at.is_none() {
                if let Some(Condition::Time(t)) = ch.kind.condition() {
                    if self.cell.spec.time.ticks(*t) < tick {
                        self.trigger(c);
                    }
                }
            }
        }
        self.human();
    }

    /// Challenge `c` is met: its effect on the world and the trees.
    pub(super) fn trigger(&mut self, c: usize) {
        let time = self.cell.spec.time.clone();
        self.challenges[c].trigger(self.tick, &mut self.rng, &time);
        let label = self.challenges[c].label.clone();
        self.event(Event::Challenge {
            challenge: label,
            what: ChallengeEvent::Triggered,
        });
        match self.challenges[c].kind.clone() {
            Kind::RobotMalfunction(m) => {
                for r in m.robots {
                    let Some(a) = self.agents.iter().position(|x| x.robot == r) else {
                        continue;
                    };
                    let obj = self.agents[a].obj;
                    let off = self.w.facts.enabled.key(&[(Var::Robot, obj)]);
                    self.w.apply(Vec::new(), vec![off]);
                    let name = self.cell.robot(r).object.clone();
                    self.challenges[c].note(format!("{name} disabled for {} s", m.duration));
                    self.inject(a);
                }
            }
            Kind::SensorBlackout(b) => {
                self.challenges[c].note(format!(
                    "{} silent for {} s: the monitors wait, the agents work from their world model",
                    b.sensors.join(", "),
                    b.duration
                ));
                for a in 0..self.agents.len() {
                    self.inject(a);
                }
            }
            _ => {}
        }
    }

    /// The human's approach: the ceiling robot keeps its distance (pauses)
    /// while the human is close.
    fn human(&mut self) {
        let tick = self.tick;
        for c in 0..self.challenges.len() {
            let Kind::Human(h) = &self.challenges[c].kind else {
                continue;
            };
            let Some((s, e)) = h.window else {
                continue;
            };
            if tick == s && !self.challenges[c].ended {
                let secs = self.secs(e - s);
                self.challenges[c].note(format!(
                    "the human came close to the ceiling robot; it kept its distance for {secs} s"
                ));
                if let Some(a) = self
                    .agents
                    .iter()
                    .position(|x| x.robot == Robot::CeilingRobot)
                {
                    self.inject(a);
                }
            }
        }
    }

    /// The runtime faults the challenges in effect mean for a robot's tree.
    pub(super) fn faults_for(&self, robot: Robot, from: u64) -> Vec<FaultSpec> {
        let name = &self.cell.robot(robot).object;
        self.challenges
            .iter()
            .filter_map(|c| c.fault(robot, name, from))
            .collect()
    }

    /// Puts the faults now in effect into agent `a`'s running tree.
    fn inject(&mut self, a: usize) {
        let robot = self.agents[a].robot;
        let specs = self.faults_for(robot, self.tick);
        if let Some(e) = self.agents[a].engine.as_mut() {
            // Only faults the tree does not have yet.
            let fresh: Vec<FaultSpec> = specs
                .into_iter()
                .filter(|s| {
                    !e.fault_outcomes(false)
                        .iter()
                        .any(|o| Some(&o.fault) == s.name.as_ref() && o.met_at.is_none())
                })
                .collect();
            let _ = e.add_faults(&Scenario {
                description: None,
                faults: fresh,
            });
        }
    }

    fn end_challenge(&mut self, c: usize) {
        self.challenges[c].ended = true;
        let label = self.challenges[c].label.clone();
        self.event(Event::Challenge {
            challenge: label,
            what: ChallengeEvent::Ended,
        });
        let Kind::RobotMalfunction(m) = self.challenges[c].kind.clone() else {
            return;
        };
        for r in m.robots {
            // Another malfunction may still hold it.
            let still = self
                .challenges
                .iter()
                .enumerate()
                .any(|(d, x)| d != c && x.disables(r) && x.in_effect(self.tick));
            if still {
                continue;
            }
            if let Some(a) = self.agents.iter().position(|x| x.robot == r) {
                let on = self
                    .w
                    .facts
                    .enabled
                    .key(&[(Var::Robot, self.agents[a].obj)]);
                self.w.apply(vec![on], Vec::new());
                let name = self.cell.robot(r).object.clone();
                self.challenges[c].note(format!("{name} repaired"));
            }
        }
    }

    /// The gripper lets go of part `k` (if it still holds it).
    fn drop_part(&mut self, c: usize, k: PartId) {
        self.challenges[c].ended = true;
        let Kind::DroppedPart(d) = &mut self.challenges[c].kind else {
            return;
        };
        d.drop = None;
        let robot = d.robot;
        let Some(a) = self.agents.iter().position(|x| x.robot == robot) else {
            return;
        };
        let robj = self.agents[a].obj;
        let p = self.w.parts[k].obj;
        let holds = self
            .w
            .facts
            .holding
            .key(&[(Var::Robot, robj), (Var::Part, p)]);
        let name = self.w.parts[k].info.name.clone();
        if !self.w.holds(&holds) {
            self.challenges[c].note(format!(
                "{name} was already placed when the gripper failed: nothing dropped"
            ));
            return;
        }
        self.challenges[c].met_at = Some(self.tick);
        let empty = self.w.facts.hand_empty.key(&[(Var::Robot, robj)]);
        let flipped = self.w.facts.flipped.key(&[(Var::Part, p)]);
        self.w.apply(vec![empty], vec![holds, flipped]);
        self.w.parts[k].gone = Some("the gripper dropped it on the floor".into());
        let rname = self.cell.robot(robot).object.clone();
        self.challenges[c].note(format!("{rname}'s gripper dropped {name}"));
        if let Some(t) = self.w.parts[k].reserved {
            let o = self.tm.tasks[t].order;
            self.challenges[c].touch(o);
        }
        let label = self.challenges[c].label.clone();
        if let Some(e) = self.agents[a].engine.as_mut() {
            let _ = e.add_faults(&Scenario {
                description: None,
                faults: vec![fault(
                    FaultKind::FaultyGripper,
                    &label,
                    &rname,
                    self.tick,
                    None,
                )],
            });
        }
        self.event(Event::Challenge {
            challenge: label,
            what: ChallengeEvent::Dropped { part: name },
        });
    }

    /// ARIAC's faulty parts: part `part` was placed in quadrant `q` of
    /// `agv`'s kit.
    pub(super) fn faulty_on_place(&mut self, part: PartId, agv: u8, q: u8) {
        for c in 0..self.challenges.len() {
            let Kind::FaultyPart(f) = &self.challenges[c].kind else {
                continue;
            };
            let Some(o) = self.trial.orders.iter().position(|x| x.id == f.order_id) else {
                continue;
            };
            let rt = &self.tm.orders[o];
            if rt.announced.is_none() || rt.submitted.is_some() {
                continue;
            }
            let order_agv = match &self.trial.orders[o].task {
                OrderTask::Kitting { agv, .. } => Some(*agv),
                OrderTask::Combined { .. } => rt.agv,
                OrderTask::Assembly { .. } => None,
            };
            if order_agv != Some(agv) {
                continue;
            }
            let Kind::FaultyPart(f) = &mut self.challenges[c].kind else {
                continue;
            };
            if !f.placed(q) {
                continue;
            }
            let ch = &mut self.challenges[c];
            ch.met_at.get_or_insert(self.tick);
            ch.touch(o);
            self.w.parts[part].faulty = true;
            let name = self.w.parts[part].info.name.clone();
            ch.note(format!("{name}, the first part in quadrant {q}, is faulty"));
        }
    }

    /// ARIAC's faulty gripper: agent `a`'s robot picked `part`.
    pub(super) fn on_pick(&mut self, a: usize, part: PartId) {
        let robot = self.agents[a].robot;
        let kind = self.w.parts[part].info.kind;
        let time = &self.cell.spec.time;
        for c in &mut self.challenges {
            if c.ended {
                continue;
            }
            if let Kind::DroppedPart(d) = &mut c.kind {
                d.picked(robot, kind, part, self.tick, time);
            }
        }
    }

    /// Whether order `o` has a faulty-part challenge.
    pub(super) fn has_faulty_challenge(&self, o: usize) -> bool {
        let id = &self.trial.orders[o].id;
        self.challenges
            .iter()
            .any(|c| matches!(&c.kind, Kind::FaultyPart(f) if f.order_id == *id))
    }

    /// The faulty-part challenge of order `o` notes what its quality check
    /// found.
    pub(super) fn note_faulty_found(&mut self, o: usize, note: String) {
        if let Some(c) = self
            .challenges
            .iter_mut()
            .find(|c| matches!(&c.kind, Kind::FaultyPart(_)) && c.orders.contains(&o))
        {
            c.note(note);
        }
    }

    /// The challenge of high-priority order `o`, if it is one.
    pub(super) fn priority_challenge(&self, o: usize) -> Option<usize> {
        self.challenges
            .iter()
            .position(|c| c.kind == Kind::HighPriorityOrder { order: o })
    }

    /// A flipped part is used by task `t`: the flipped-parts challenge of
    /// its kind is met.
    pub(super) fn note_flipped_use(&mut self, k: PartId, t: usize) {
        if !self.w.is_flipped(self.w.parts[k].obj) {
            return;
        }
        let kind = self.w.parts[k].info.kind;
        let o = self.tm.tasks[t].order;
        let tick = self.tick;
        let name = self.w.parts[k].info.name.clone();
        if let Some(c) = self
            .challenges
            .iter_mut()
            .find(|c| matches!(&c.kind, Kind::FlippedParts { kind: kk, .. } if *kk == kind))
        {
            c.met_at.get_or_insert(tick);
            c.touch(o);
            c.note(format!(
                "{name} lies flipped: the plan of task {t} turns it over"
            ));
        }
    }

    /// The parts the agents' tick placed on AGVs (faulty parts) and picked
    /// (the faulty gripper's drops).
    pub(super) fn placements_and_picks(&mut self) {
        // Placements on AGVs.
        let kit = self.w.facts_of(&self.w.facts.in_kit);
        let new_kit: Vec<Key> = kit.difference(&self.prev_kit).cloned().collect();
        self.prev_kit = kit;
        for k in new_kit {
            let (Some(p), Some(agv), Some(q)) = (
                self.w.facts.in_kit.get(&k, Var::Part),
                self.w.facts.in_kit.get(&k, Var::Agv),
                self.w.facts.in_kit.get(&k, Var::Quadrant),
            ) else {
                continue;
            };
            let (Some(&part), Some(n), Some(qn)) = (
                self.w.part_of.get(&p),
                self.w.obj.agv.iter().position(|&x| x == agv),
                self.w.obj.quadrant.iter().position(|&x| x == q),
            ) else {
                continue;
            };
            self.placed.push((part, n as u8 + 1));
            self.faulty_on_place(part, n as u8 + 1, qn as u8 + 1);
        }
        // Picks.
        let holding = self.w.facts_of(&self.w.facts.holding);
        let picks: Vec<Key> = holding.difference(&self.prev_holding).cloned().collect();
        self.prev_holding = holding;
        for k in picks {
            let (Some(r), Some(p)) = (
                self.w.facts.holding.get(&k, Var::Robot),
                self.w.facts.holding.get(&k, Var::Part),
            ) else {
                continue;
            };
            if let (Some(a), Some(&part)) = (
                self.agents.iter().position(|x| x.obj == r),
                self.w.part_of.get(&p),
            ) {
                self.on_pick(a, part);
            }
        }
    }
}
