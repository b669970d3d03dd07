//! Choosing what a task needs from the world: the part (by the paper's
//! preferences), the resources it holds while it runs, and its goal; or
//! that it must wait, is done already, or can never run (its cause).

use super::events::Cause;
use super::facts::Place;
use super::model::Sim;
use super::tasks::{Resource, TaskId, Work};
use super::world::PartId;
use crate::cell::{Literal, Var};
use crate::trial::PartKind;

/// What choosing a task's part and resources came to.
pub(super) enum Resolve {
    Go {
        part: Option<PartId>,
        resources: Vec<Resource>,
        goal: Vec<Literal>,
    },
    /// Its goal already holds.
    Done,
    /// Not now (a part still to come, a resource held).
    Wait,
    /// Never: the cause.
    Never(Cause),
}

impl Sim<'_, '_> {
    /// A part for the task, by the paper's preferences: the one the agent's
    /// robot holds (what the fault record kept), then one on the conveyor,
    /// then one lying the right way up, then any.
    pub(super) fn pick_part(
        &self,
        a: usize,
        t: TaskId,
        kind: PartKind,
        from_agvs: &[u8],
    ) -> Result<Option<PartId>, ()> {
        let robot = self.agents[a].obj;
        let s = &self.w.kb.state;
        // The part the task's last attempt used, wherever it lies now (the
        // fault record keeps it), unless another robot holds it.
        if let Some(k) = self.tm.tasks[t].part {
            let p = &self.w.parts[k];
            let usable = match self.w.facts.place(s, p.obj) {
                Place::Held(r) => r == robot,
                Place::At(_) | Place::InKit { .. } => true,
                _ => false,
            };
            if usable
                && p.gone.is_none()
                && !p.faulty
                && p.reserved.is_none()
                && p.info.kind == kind
            {
                return Ok(Some(k));
            }
        }
        let mut best: Option<(u8, PartId)> = None;
        let mut someone_has = false;
        for (k, p) in self.w.parts.with_ids() {
            if p.info.kind != kind || p.gone.is_some() || p.faulty {
                continue;
            }
            let place = self.w.facts.place(s, p.obj);
            let rank = match place {
                Place::Held(r) if r == robot => 0,
                Place::At(l) if from_agvs.is_empty() && l == self.w.obj.conveyor => 1,
                Place::At(l) if from_agvs.is_empty() && self.w.obj.bins.contains(&l) => {
                    if s.facts
                        .contains(&self.w.facts.flipped.key(&[(Var::Part, p.obj)]))
                    {
                        3
                    } else {
                        2
                    }
                }
                Place::InKit { agv, .. }
                    if from_agvs
                        .iter()
                        .any(|&n| self.w.obj.agv[n as usize - 1] == agv) =>
                {
                    2
                }
                _ => {
                    if p.spawn.is_some_and(|t| t > self.tick) && from_agvs.is_empty() {
                        someone_has = true;
                    }
                    continue;
                }
            };
            if p.reserved.is_some() {
                someone_has = true;
                continue;
            }
            if best.is_none_or(|(r, _)| rank < r) {
                best = Some((rank, k));
            }
        }
        match best {
            Some((_, k)) => Ok(Some(k)),
            None if someone_has => Ok(None),
            None => Err(()),
        }
    }

    pub(super) fn resolve(&self, a: usize, t: TaskId) -> Resolve {
        let s = &self.w.kb.state;
        let f = &self.cell.spec.facts;
        match self.tm.tasks[t].work.clone() {
            Work::Tray { agv, tray } => {
                let aobj = self.w.obj.agv[agv as usize - 1];
                let tname = self.cell.tray(tray);
                let Some(tobj) = self.pu.index.objects.get(&tname).map(|o| o.id) else {
                    return Resolve::Never(Cause::NoSuchTray { tray });
                };
                match self.w.facts.tray_of(s, aobj) {
                    Some(x) if x == tobj => return Resolve::Done,
                    Some(x) => {
                        return Resolve::Never(Cause::AgvHasAnotherTray {
                            agv,
                            has: self.w.name(x).to_owned(),
                            tray,
                        })
                    }
                    None => {}
                }
                let on_table = s
                    .facts
                    .iter()
                    .any(|k| self.w.facts.tray_at.get(k, Var::Tray) == Some(tobj));
                let holder = s
                    .facts
                    .iter()
                    .find(|k| self.w.facts.holding_tray.get(k, Var::Tray) == Some(tobj))
                    .and_then(|k| self.w.facts.holding_tray.get(k, Var::Robot));
                match holder {
                    Some(r) if r != self.agents[a].obj => return Resolve::Wait,
                    Some(_) => {}
                    None if !on_table => return Resolve::Never(Cause::TrayNotOnTables { tray }),
                    None => {}
                }
                if self.w.facts.agv_place(s, aobj)
                    != Some(self.w.obj.kitting_station[agv as usize - 1])
                {
                    return Resolve::Wait;
                }
                Resolve::Go {
                    part: None,
                    resources: vec![Resource::Agv(agv), Resource::Tray(tray)],
                    goal: vec![Literal {
                        positive: true,
                        atom: f
                            .tray_on
                            .ground(&[(Var::Tray, &tname), (Var::Agv, self.w.name(aobj))]),
                    }],
                }
            }
            Work::Kit {
                part,
                agv,
                quadrant,
            }
            | Work::Replace {
                part,
                agv,
                quadrant,
                ..
            } => {
                let aobj = self.w.obj.agv[agv as usize - 1];
                let qobj = self.w.obj.quadrant[quadrant as usize - 1];
                if self.w.facts.agv_place(s, aobj)
                    != Some(self.w.obj.kitting_station[agv as usize - 1])
                {
                    return Resolve::Wait;
                }
                let mut goal = Vec::new();
                let mut resources = vec![Resource::Quadrant(agv, quadrant)];
                let occupant = self
                    .w
                    .facts
                    .kit(s, aobj)
                    .into_iter()
                    .find(|(q, _)| *q == qobj)
                    .and_then(|(_, p)| self.w.part_of.get(&p).copied());
                if let Work::Replace { faulty, .. } = self.tm.tasks[t].work {
                    goal.push(self.w.lit(
                        &f.discarded,
                        &[(Var::Part, self.w.parts[faulty].obj)],
                        true,
                    ));
                    resources.push(Resource::Part(faulty));
                }
                if let Some(occ) = occupant {
                    let is_replace = matches!(self.tm.tasks[t].work, Work::Replace { faulty, .. } if faulty == occ);
                    if !is_replace {
                        if self.w.parts[occ].info.kind == part && !self.w.parts[occ].faulty {
                            // The part is there: turned over if need be.
                            if !s.facts.contains(
                                &self
                                    .w
                                    .facts
                                    .flipped
                                    .key(&[(Var::Part, self.w.parts[occ].obj)]),
                            ) {
                                return Resolve::Done;
                            }
                            resources.push(Resource::Part(occ));
                            goal.extend(self.w.lits_kit(
                                self.cell,
                                self.w.parts[occ].obj,
                                aobj,
                                qobj,
                            ));
                            return Resolve::Go {
                                part: Some(occ),
                                resources,
                                goal,
                            };
                        }
                        goal.push(self.w.lit(
                            &f.discarded,
                            &[(Var::Part, self.w.parts[occ].obj)],
                            true,
                        ));
                        resources.push(Resource::Part(occ));
                    }
                }
                match self.pick_part(a, t, part, &[]) {
                    Ok(Some(k)) => {
                        resources.push(Resource::Part(k));
                        goal.extend(self.w.lits_kit(self.cell, self.w.parts[k].obj, aobj, qobj));
                        Resolve::Go {
                            part: Some(k),
                            resources,
                            goal,
                        }
                    }
                    Ok(None) => Resolve::Wait,
                    Err(()) => Resolve::Never(Cause::InsufficientParts {
                        part,
                        from_agvs: Vec::new(),
                    }),
                }
            }
            Work::Assemble {
                part,
                station,
                agvs,
                from_task,
            } => {
                let st = self.w.obj.station[station as usize - 1];
                let taken = self
                    .w
                    .facts
                    .insert(s, st)
                    .into_iter()
                    .filter_map(|p| self.w.part_of.get(&p))
                    .any(|&k| self.w.parts[k].info.kind.ty == part.ty);
                if taken {
                    return Resolve::Never(Cause::SlotTaken {
                        station,
                        ty: part.ty.name(),
                    });
                }
                let k = match from_task {
                    Some(kt) => match self.tm.tasks[kt].part {
                        Some(k) if self.w.parts[k].gone.is_none() => k,
                        _ => return Resolve::Never(Cause::KittingHalfPartGone),
                    },
                    None => match self.pick_part(a, t, part, &agvs) {
                        Ok(Some(k)) => k,
                        Ok(None) => return Resolve::Wait,
                        Err(()) => {
                            return Resolve::Never(Cause::InsufficientParts {
                                part,
                                from_agvs: agvs,
                            })
                        }
                    },
                };
                let mut resources = vec![Resource::Part(k), Resource::Station(station)];
                if let Place::InKit { agv, .. } = self.w.facts.place(s, self.w.parts[k].obj) {
                    if let Some(n) = self.w.obj.agv.iter().position(|&x| x == agv) {
                        resources.push(Resource::Agv(n as u8 + 1));
                    }
                }
                let p = self.w.parts[k].obj;
                Resolve::Go {
                    part: Some(k),
                    resources,
                    goal: vec![
                        self.w
                            .lit(&f.installed, &[(Var::Part, p), (Var::Station, st)], true),
                        self.w.lit(&f.flipped, &[(Var::Part, p)], false),
                    ],
                }
            }
            Work::Combined { .. } => Resolve::Wait,
        }
    }
}
