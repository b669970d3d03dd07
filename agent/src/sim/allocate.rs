//! The task manager's step: idle agents take tasks by the paper's rules
//! ([`super::allocation`]); a task whose part, resources and goal resolve
//! is launched, one that can never run is given up with its cause.

use super::allocation::{self, Candidate, Combine};
use super::challenges::{Challenge, Kind};
use super::events::Cause;
use super::model::Sim;
use super::resolve::Resolve;
use super::tasks::{TaskId, Work};
use crate::cell::Var;
use crate::trial::{OrderType, Task as OrderTask};

impl Sim<'_, '_> {
    /// Whether no challenge in effect disables agent `a`'s robot.
    pub(super) fn normal(&self, a: usize) -> bool {
        let r = self.agents[a].robot;
        !self
            .challenges
            .iter()
            .any(|c| c.disables(r) && c.in_effect(self.tick))
    }

    fn idle(&self, a: usize) -> bool {
        self.agents[a].idle()
    }

    /// Whether every agent but `a` is idle, working, and can kit (a split's
    /// kitting half has someone to take it).
    fn others_idle(&self, a: usize) -> bool {
        (0..self.agents.len()).all(|b| {
            b == a
                || (self.idle(b)
                    && self.normal(b)
                    && self.agents[b].queues.contains(&OrderType::Kitting))
        })
    }

    pub(super) fn allocate(&mut self) {
        self.tm.unblock();
        // Passes until nothing changes: a split in one pass gives the floor
        // agent work in the next.
        for _ in 0..8 {
            let mut changed = false;
            for a in 0..self.agents.len() {
                if !self.idle(a) || !self.normal(a) {
                    continue;
                }
                changed |= self.take(a);
            }
            if !changed {
                break;
            }
        }
    }

    /// Agent `a` looks through its queues by the rules; true when it got
    /// work or a queue changed.
    fn take(&mut self, a: usize) -> bool {
        let queues = self.agents[a].queues.clone();
        for (prio, q) in allocation::visit_order(&queues) {
            let mut cands: Vec<Candidate> = self
                .tm
                .queued(q, prio)
                .map(|t| Candidate {
                    task: t.id,
                    on_conveyor: t.work.part_kind().is_some_and(|k| self.w.on_conveyor(k)),
                    created: t.created,
                })
                .collect();
            allocation::rank(&mut cands);
            for c in cands {
                let t = c.task;
                if q == OrderType::Combined {
                    if self.split_or_convert(a, t) {
                        return true;
                    }
                    continue;
                }
                match self.start(a, t) {
                    Some(true) => return true,
                    Some(false) => continue,
                    None => return true,
                }
            }
        }
        false
    }

    /// Rule 2 on combined task `t` for agent `a`. True when the agent got
    /// work (or the queue changed).
    fn split_or_convert(&mut self, a: usize, t: TaskId) -> bool {
        let Work::Combined { station, .. } = self.tm.tasks[t].work else {
            return false;
        };
        let o = self.tm.tasks[t].order;
        let others_idle = self.others_idle(a);
        let (tick, n) = (self.tick, self.agents.len());
        match allocation::split_or_convert(n, others_idle, || self.split_place(o, station)) {
            Combine::Split { agv, quadrant } => {
                self.tm.split(t, agv, quadrant, tick, &mut self.trace);
            }
            Combine::Convert => {
                if let Some(asm) = self.tm.convert(t, tick, &mut self.trace) {
                    self.start(a, asm);
                }
            }
        }
        true
    }

    /// The AGV and quadrant for a split's kitting half: the order's AGV if
    /// it has one still at its kitting station, else a free AGV that serves
    /// the station.
    fn split_place(&self, o: usize, station: u8) -> Option<(u8, u8)> {
        let w = &self.w;
        let st = w.obj.station[station as usize - 1];
        let free_quadrant = |agv: u8| -> Option<u8> {
            let aobj = w.obj.agv(agv);
            (1..=4u8).find(|&q| {
                let k = w
                    .facts
                    .kit_free
                    .key(&[(Var::Agv, aobj), (Var::Quadrant, w.obj.quadrant[q as usize - 1])]);
                w.holds(&k)
                    && !self.tm.tasks.iter().any(|t| {
                        t.is_open() && matches!(t.work, Work::Kit { agv: a, quadrant: qq, .. } if a == agv && qq == q)
                    })
            })
        };
        let at_home = |agv: u8| {
            w.facts.agv_place(&w.kb.state, w.obj.agv(agv))
                == Some(w.obj.kitting_station[agv as usize - 1])
        };
        let orders = &self.tm.orders;
        if let Some(agv) = orders[o].agv {
            if orders[o].committed || !at_home(agv) {
                return None;
            }
            return free_quadrant(agv).map(|q| (agv, q));
        }
        for agv in 1..=4u8 {
            let serves = w.holds(
                &w.facts
                    .agv_goes
                    .key(&[(Var::Agv, w.obj.agv(agv)), (Var::Place, st)]),
            );
            let used = orders
                .iter()
                .enumerate()
                .any(|(k, r)| k != o && r.agv == Some(agv) && r.submitted.is_none())
                || self.tm.tasks.iter().any(|t| {
                    t.is_open()
                        && match &t.work {
                            Work::Tray { agv: a, .. }
                            | Work::Kit { agv: a, .. }
                            | Work::Replace { agv: a, .. } => *a == agv,
                            Work::Assemble { agvs, .. } => agvs.contains(&agv),
                            Work::Combined { .. } => false,
                        }
                })
                || self.trial.orders.iter().zip(orders).any(|(ord, r)| {
                    r.submitted.is_none()
                        && match &ord.task {
                            OrderTask::Kitting { agv: a, .. } => *a == agv,
                            OrderTask::Assembly { agvs, .. } => agvs.contains(&agv),
                            OrderTask::Combined { .. } => false,
                        }
                });
            if serves && at_home(agv) && !used {
                if let Some(q) = free_quadrant(agv) {
                    return Some((agv, q));
                }
            }
        }
        None
    }

    /// Starts task `t` on agent `a`: `Some(true)` started (or finished at
    /// once), `Some(false)` not now, `None` the task ended without running.
    pub(super) fn start(&mut self, a: usize, t: TaskId) -> Option<bool> {
        match self.resolve(a, t) {
            Resolve::Wait => Some(false),
            Resolve::Done => {
                self.tm.done_already(t, self.tick, &mut self.trace);
                None
            }
            Resolve::Never(cause) => {
                self.fail_task(t, cause);
                None
            }
            Resolve::Go {
                part,
                resources,
                goal,
            } => {
                if !self.w.free(&resources) {
                    return Some(false);
                }
                self.launch(a, t, part, resources, goal);
                Some(true)
            }
        }
    }

    /// Gives task `t` up. A task short of parts meets ARIAC's
    /// insufficient-parts challenge.
    pub(super) fn fail_task(&mut self, t: TaskId, cause: Cause) {
        if cause.insufficient() {
            if let Some(kind) = self.tm.tasks[t].work.part_kind() {
                let c = match self
                    .challenges
                    .iter()
                    .position(|c| c.kind == Kind::InsufficientParts { kind })
                {
                    Some(c) => c,
                    None => {
                        self.challenges.push(Challenge::new(
                            format!("insufficient_parts({kind})"),
                            Kind::InsufficientParts { kind },
                        ));
                        self.challenges.len() - 1
                    }
                };
                let o = self.tm.tasks[t].order;
                let ch = &mut self.challenges[c];
                ch.met_at.get_or_insert(self.tick);
                ch.touch(o);
                ch.ended = true;
                ch.note(format!("task {t}: {cause}"));
            }
        }
        self.tm.fail(t, &cause, self.tick, &mut self.trace);
    }
}
