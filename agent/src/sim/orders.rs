//! Orders through the trial: announced when their condition comes true,
//! quality-checked (faulty parts found and replaced), shipped and
//! submitted, and scored on submission; and the orders and challenges a
//! tick's placements and submissions announce or start.

use super::events::{AgvMove, Event, OrderEvent};
use super::model::Sim;
use super::scoring;
use super::tasks::{Resource, TaskState, Work};
use super::world::PartId;
use crate::cell::Var;
use crate::trial::{Condition, Destination, OrderType, Task as OrderTask};

impl Sim<'_, '_> {
    pub(super) fn announce_orders(&mut self) {
        for k in 0..self.tm.orders.len() {
            if self.tm.orders[k].announced.is_some() {
                continue;
            }
            let go = match &self.trial.orders[k].announcement {
                Condition::Time(t) => self.cell.spec.time.ticks(*t) < self.tick,
                // Placements and submissions of the previous tick.
                Condition::PartPlace { .. } | Condition::Submission(_) => false,
            };
            if go {
                self.announce(k);
            }
        }
    }

    /// Order `k` is announced: its part tasks join their queues, and a
    /// high-priority order may preempt agents.
    fn announce(&mut self, k: usize) {
        self.tm.announce(k, self.tick, &mut self.trace);
        if !self.trial.orders[k].priority {
            return;
        }
        if let Some(c) = self.priority_challenge(k) {
            self.challenges[c].met_at = Some(self.tick);
            self.challenges[c].touch(k);
            self.preempt_for_priority(c);
        }
    }

    /// Orders after the agents' tick: quality checks, shipping and
    /// submission.
    pub(super) fn progress_orders(&mut self) {
        for o in 0..self.tm.orders.len() {
            self.progress_order(o);
        }
    }

    /// Orders and challenges whose condition this tick's placements and
    /// submissions met.
    pub(super) fn conditions(&mut self) {
        // Conditions on placements and submissions.
        let placed = std::mem::take(&mut self.placed);
        let submitted = std::mem::take(&mut self.submitted_now);
        for k in 0..self.tm.orders.len() {
            if self.tm.orders[k].announced.is_some() {
                continue;
            }
            if self.condition_met(
                &self.trial.orders[k].announcement.clone(),
                &placed,
                &submitted,
            ) {
                self.announce(k);
            }
        }
        for c in 0..self.challenges.len() {
            if self.challenges[c].met_at.is_some() {
                continue;
            }
            if let Some(cond) = self.challenges[c].kind.condition().cloned() {
                if !matches!(cond, Condition::Time(_))
                    && self.condition_met(&cond, &placed, &submitted)
                {
                    self.trigger(c);
                }
            }
        }
        self.placed = placed;
        self.submitted_now = submitted;
    }

    fn condition_met(&self, c: &Condition, placed: &[(PartId, u8)], submitted: &[usize]) -> bool {
        match c {
            Condition::Time(_) => false,
            Condition::PartPlace { agv, kind } => placed
                .iter()
                .any(|(p, a)| a == agv && self.w.parts[*p].info.kind == *kind),
            Condition::Submission(id) => submitted.iter().any(|&o| self.trial.orders[o].id == *id),
        }
    }

    fn progress_order(&mut self, o: usize) {
        if self.tm.orders[o].announced.is_none()
            || self.tm.orders[o].submitted.is_some()
            || self.tm.orders[o].submitting
        {
            return;
        }
        let ty = self.trial.orders[o].task.order_type();
        // Combined: the quality check of the split AGV before it leaves.
        if ty == OrderType::Combined && !self.tm.orders[o].qc_done {
            if let Some(agv) = self.tm.orders[o].agv {
                if !self.tm.open_kits(o, agv, false) {
                    self.quality_check(o, agv);
                }
            }
        }
        if ty == OrderType::Combined {
            // Assembly halves start only after the AGV's kit is checked.
            if self.tm.orders[o].tasks.iter().any(|&t| {
                matches!(self.tm.tasks[t].state, TaskState::Running { .. })
                    && matches!(
                        &self.tm.tasks[t].work,
                        Work::Assemble {
                            from_task: Some(_),
                            ..
                        }
                    )
            }) {
                self.tm.orders[o].committed = true;
            }
        }
        if !self.tm.order_ended(o) {
            return;
        }
        // ARIAC: a high-priority order is submitted before the regular ones.
        let priority_open = self.trial.orders.iter().zip(&self.tm.orders).any(|(x, r)| {
            x.priority && r.announced.is_some() && r.submitted.is_none() && !r.submitting
        });
        if !self.trial.orders[o].priority && priority_open {
            return;
        }
        match &self.trial.orders[o].task {
            OrderTask::Kitting {
                agv, destination, ..
            } => {
                let agv = *agv;
                if !self.tm.orders[o].qc_done {
                    self.quality_check(o, agv);
                    if !self.tm.order_ended(o) {
                        return;
                    }
                }
                // Ship the kit: the AGV to its destination.
                let aobj = self.w.obj.agv(agv);
                let to = match destination {
                    Destination::Warehouse => self.w.obj.warehouse,
                    Destination::Kitting => self.w.obj.kitting_station[agv as usize - 1],
                    Destination::Station(n) => self.w.obj.station[*n as usize - 1],
                };
                if !self.w.free(&[Resource::Agv(agv)]) {
                    return;
                }
                let goes = self.w.holds(
                    &self
                        .w
                        .facts
                        .agv_goes
                        .key(&[(Var::Agv, aobj), (Var::Place, to)]),
                );
                self.tm.orders[o].submitting = true;
                if goes && self.w.facts.agv_place(&self.w.kb.state, aobj) != Some(to) {
                    let arrive = self.tick + u64::from(self.cell.spec.time.ticks_per_action);
                    self.w.send(agv, to, arrive, Some(o));
                    let id = self.trial.orders[o].id.clone();
                    let dest = self.w.name(to).to_owned();
                    self.event(Event::Agv {
                        agv: format!("agv{agv}"),
                        what: AgvMove::Leaves {
                            order: id,
                            leaves_for: dest,
                        },
                    });
                } else {
                    self.submit(o);
                }
            }
            _ => {
                self.tm.orders[o].submitting = true;
                self.submit(o);
            }
        }
    }

    /// ARIAC's quality check (once per order): faulty parts in the kit are
    /// found and replaced; the new parts are good.
    fn quality_check(&mut self, o: usize, agv: u8) {
        self.tm.orders[o].qc_done = true;
        if !self.has_faulty_challenge(o)
            && self.trial.orders[o].task.order_type() == OrderType::Combined
        {
            return;
        }
        let aobj = self.w.obj.agv(agv);
        let kit = self.w.facts.kit(&self.w.kb.state, aobj);
        for (q, p) in kit {
            let Some(&k) = self.w.part_of.get(&p) else {
                continue;
            };
            if !self.w.parts[k].faulty {
                continue;
            }
            let Some(qn) = self.w.obj.quadrant.iter().position(|&x| x == q) else {
                continue;
            };
            let quadrant = qn as u8 + 1;
            let kind = self.w.parts[k].info.kind;
            let r = self.tm.new_task(
                o,
                OrderType::Kitting,
                Work::Replace {
                    part: kind,
                    agv,
                    quadrant,
                    faulty: k,
                },
                Vec::new(),
                self.tick,
                &mut self.trace,
            );
            let name = self.w.parts[k].info.name.clone();
            self.note_faulty_found(
                o,
                format!("the quality check found {name} faulty: task {r} replaces it"),
            );
            // An assembly half that was to take the faulty part takes the
            // replacement instead.
            for t in 0..self.tm.tasks.len() {
                if let Work::Assemble {
                    from_task: Some(ft),
                    ..
                } = &self.tm.tasks[t].work
                {
                    if self.tm.tasks[*ft].part == Some(k) && self.tm.tasks[t].is_open() {
                        if let Work::Assemble { from_task, .. } = &mut self.tm.tasks[t].work {
                            *from_task = Some(r);
                        }
                        self.tm.tasks[t].after.push(r);
                        self.tm.tasks[t].state = TaskState::Blocked;
                    }
                }
            }
        }
    }

    pub(super) fn submit(&mut self, o: usize) {
        self.tm.orders[o].submitted = Some(self.tick);
        self.submitted_now.push(o);
        let (score, breakdown) = scoring::order(&self.w, self.cell, &self.trial.orders[o]);
        self.tm.orders[o].score = score;
        self.tm.orders[o].breakdown = Some(breakdown);
        let id = self.trial.orders[o].id.clone();
        self.event(Event::Order {
            order: id,
            what: OrderEvent::Submitted { score },
        });
        // A high-priority order submitted while regular ones were still open.
        if let Some(c) = self.priority_challenge(o) {
            let before = self
                .tm
                .orders
                .iter()
                .enumerate()
                .filter(|(k, r)| {
                    *k != o
                        && !self.trial.orders[*k].priority
                        && r.announced.is_some()
                        && r.submitted.is_none()
                })
                .count();
            let note = format!(
                "submitted at {} s{}",
                self.secs(self.tick),
                if before > 0 {
                    format!(", before {before} regular order(s) still open")
                } else {
                    String::new()
                }
            );
            self.challenges[c].ended = true;
            self.challenges[c].note(note);
        }
    }
}
