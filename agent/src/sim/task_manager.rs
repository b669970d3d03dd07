//! The task manager (Liu et al. 2024, section 3.2, Figure 2): orders
//! become part tasks when they are announced, the tasks wait in the
//! kitting, assembly and combined queues (blocked until the tasks before
//! them end), combined tasks are split or converted, failed attempts go
//! back to their queue until the last, and an order ends when its tasks
//! have. Which task an agent takes is decided by the rules of
//! [`super::allocation`]; this is the bookkeeping they read and change.

use super::events::{Cause, Event, OrderEvent, TaskEvent, Trace};
use super::scoring::Breakdown;
use super::tasks::{Attempt, Task, TaskId, TaskState, Work};
use crate::trial::{OrderType, Task as OrderTask, Trial};

/// What the simulation knows of an order.
#[derive(Default)]
pub struct OrderRt {
    pub announced: Option<u64>,
    pub submitted: Option<u64>,
    pub tasks: Vec<TaskId>,
    pub qc_done: bool,
    /// Combined orders: the AGV their kitting halves go on, and whether it
    /// has left for the station.
    pub agv: Option<u8>,
    pub committed: bool,
    pub submitting: bool,
    pub score: i64,
    pub breakdown: Option<Breakdown>,
}

/// The part tasks an order's announcement creates: queue, work, and
/// whether it waits for the order's first task (a kit's tray).
pub fn part_tasks(task: &OrderTask) -> Vec<(OrderType, Work, bool)> {
    match task {
        OrderTask::Kitting {
            agv,
            tray_id,
            products,
            ..
        } => {
            let tray = Work::Tray {
                agv: *agv,
                tray: *tray_id,
            };
            std::iter::once((OrderType::Kitting, tray, false))
                .chain(products.iter().map(|p| {
                    let kit = Work::Kit {
                        part: p.kind,
                        agv: *agv,
                        quadrant: p.quadrant,
                    };
                    (OrderType::Kitting, kit, true)
                }))
                .collect()
        }
        OrderTask::Assembly {
            agvs,
            station,
            products,
        } => products
            .iter()
            .map(|p| {
                let work = Work::Assemble {
                    part: p.kind,
                    station: *station,
                    agvs: agvs.clone(),
                    from_task: None,
                };
                (OrderType::Assembly, work, false)
            })
            .collect(),
        OrderTask::Combined { station, products } => products
            .iter()
            .map(|p| {
                let work = Work::Combined {
                    part: p.kind,
                    station: *station,
                };
                (OrderType::Combined, work, false)
            })
            .collect(),
    }
}

pub struct TaskManager<'w> {
    trial: &'w Trial,
    pub tasks: Vec<Task>,
    pub orders: Vec<OrderRt>,
}

impl<'w> TaskManager<'w> {
    pub fn new(trial: &'w Trial) -> TaskManager<'w> {
        TaskManager {
            trial,
            tasks: Vec::new(),
            orders: (0..trial.orders.len())
                .map(|_| OrderRt::default())
                .collect(),
        }
    }

    /// Something happened to task `t`.
    fn task_event(&self, t: TaskId, what: TaskEvent, tick: u64, trace: &mut Trace) {
        let order = self.trial.orders[self.tasks[t].order].id.clone();
        trace.event(
            tick,
            &Event::Task {
                task: t,
                order,
                what,
            },
        );
    }

    /// Order `k` is announced: its part tasks join their queues.
    pub fn announce(&mut self, k: usize, tick: u64, trace: &mut Trace) {
        let o = &self.trial.orders[k];
        self.orders[k].announced = Some(tick);
        let ty = o.task.order_type();
        trace.event(
            tick,
            &Event::Order {
                order: o.id.clone(),
                what: OrderEvent::Announced {
                    ty: ty.name(),
                    priority: o.priority,
                },
            },
        );
        let mut first = None;
        for (queue, work, after_first) in part_tasks(&o.task) {
            let after = match first {
                Some(f) if after_first => vec![f],
                _ => Vec::new(),
            };
            let id = self.new_task(k, queue, work, after, tick, trace);
            first.get_or_insert(id);
        }
    }

    pub fn new_task(
        &mut self,
        order: usize,
        queue: OrderType,
        work: Work,
        after: Vec<TaskId>,
        tick: u64,
        trace: &mut Trace,
    ) -> TaskId {
        let id = self.tasks.len();
        let priority = self.trial.orders[order].priority;
        trace.event(
            tick,
            &Event::Task {
                task: id,
                order: self.trial.orders[order].id.clone(),
                what: TaskEvent::Created {
                    work: work.describe(),
                    queue: queue.name(),
                },
            },
        );
        self.tasks.push(Task {
            id,
            order,
            queue,
            work,
            priority,
            state: if after.is_empty() {
                TaskState::Queued
            } else {
                TaskState::Blocked
            },
            after,
            part: None,
            attempts: Vec::new(),
            reassignments: 0,
            created: tick,
        });
        self.orders[order].tasks.push(id);
        id
    }

    /// Blocked tasks whose tasks before them are done become queued.
    pub fn unblock(&mut self) {
        for t in 0..self.tasks.len() {
            if self.tasks[t].state != TaskState::Blocked {
                continue;
            }
            let ready = self.tasks[t]
                .after
                .iter()
                .all(|&d| !self.tasks[d].is_open())
                && self.assembly_half_ready(t);
            if ready {
                self.tasks[t].state = TaskState::Queued;
            }
        }
    }

    /// An assembly half waits until no kitting half of its order is still
    /// to go on the same AGV and its order's quality check is done.
    fn assembly_half_ready(&self, t: TaskId) -> bool {
        let Work::Assemble {
            from_task: Some(_), ..
        } = &self.tasks[t].work
        else {
            return true;
        };
        let o = self.tasks[t].order;
        let Some(agv) = self.orders[o].agv else {
            return true;
        };
        !self.open_kits(o, agv, true) && self.orders[o].qc_done
    }

    /// Whether a kitting task of order `o` onto `agv` is open (replacements
    /// too, with `replacements`).
    pub fn open_kits(&self, o: usize, agv: u8, replacements: bool) -> bool {
        self.orders[o].tasks.iter().any(|&k| {
            self.tasks[k].is_open()
                && match &self.tasks[k].work {
                    Work::Kit { agv: a, .. } => *a == agv,
                    Work::Replace { agv: a, .. } => replacements && *a == agv,
                    _ => false,
                }
        })
    }

    /// The queued tasks of a queue and priority.
    pub fn queued(&self, queue: OrderType, priority: bool) -> impl Iterator<Item = &Task> + '_ {
        self.tasks.iter().filter(move |t| {
            t.queue == queue && t.priority == priority && t.state == TaskState::Queued
        })
    }

    /// Rule 2's split: combined task `t` becomes a kitting half onto the
    /// AGV's quadrant and an assembly half after it.
    pub fn split(&mut self, t: TaskId, agv: u8, quadrant: u8, tick: u64, trace: &mut Trace) {
        let Work::Combined { part, station } = self.tasks[t].work.clone() else {
            return;
        };
        let o = self.tasks[t].order;
        let kit = self.new_task(
            o,
            OrderType::Kitting,
            Work::Kit {
                part,
                agv,
                quadrant,
            },
            Vec::new(),
            tick,
            trace,
        );
        let asm = self.new_task(
            o,
            OrderType::Assembly,
            Work::Assemble {
                part,
                station,
                agvs: vec![agv],
                from_task: Some(kit),
            },
            vec![kit],
            tick,
            trace,
        );
        self.orders[o].agv = Some(agv);
        self.tasks[t].state = TaskState::Split {
            into: vec![kit, asm],
        };
        self.task_event(
            t,
            TaskEvent::Split {
                into: vec![kit, asm],
            },
            tick,
            trace,
        );
    }

    /// Rule 2's conversion: combined task `t` becomes one assembly task
    /// (its part from the bins or the belt), returned.
    pub fn convert(&mut self, t: TaskId, tick: u64, trace: &mut Trace) -> Option<TaskId> {
        let Work::Combined { part, station } = self.tasks[t].work.clone() else {
            return None;
        };
        let o = self.tasks[t].order;
        let asm = self.new_task(
            o,
            OrderType::Assembly,
            Work::Assemble {
                part,
                station,
                agvs: Vec::new(),
                from_task: None,
            },
            Vec::new(),
            tick,
            trace,
        );
        self.tasks[t].state = TaskState::Split { into: vec![asm] };
        self.task_event(t, TaskEvent::Converted { into: vec![asm] }, tick, trace);
        Some(asm)
    }

    /// Task `t`'s goal already held.
    pub fn done_already(&mut self, t: TaskId, tick: u64, trace: &mut Trace) {
        self.tasks[t].state = TaskState::Done { tick };
        self.task_event(
            t,
            TaskEvent::Done {
                how: Some("its goal already held"),
            },
            tick,
            trace,
        );
    }

    /// An attempt at task `t` succeeded.
    pub fn done(&mut self, t: TaskId, attempt: Attempt, tick: u64, trace: &mut Trace) {
        self.tasks[t].attempts.push(attempt);
        self.tasks[t].state = TaskState::Done { tick };
        self.task_event(t, TaskEvent::Done { how: None }, tick, trace);
    }

    /// Task `t` is given up; the assembly half that waited for a failed
    /// kitting half takes its part from the bins instead.
    pub fn fail(&mut self, t: TaskId, cause: &Cause, tick: u64, trace: &mut Trace) {
        let cause = cause.to_string();
        self.task_event(
            t,
            TaskEvent::Failed {
                cause: cause.clone(),
            },
            tick,
            trace,
        );
        self.tasks[t].state = TaskState::Failed { tick, cause };
        for d in &mut self.tasks {
            if d.after.contains(&t) && d.state == TaskState::Blocked {
                if let Work::Assemble {
                    from_task, agvs, ..
                } = &mut d.work
                {
                    if *from_task == Some(t) {
                        *from_task = None;
                        agvs.clear();
                    }
                }
            }
        }
    }

    /// A failed attempt at task `t` (`why` it failed): the task goes back
    /// to its queue for reassignment, or is given up (returned) after its
    /// last attempt.
    pub fn attempt_failed(
        &mut self,
        t: TaskId,
        attempt: Attempt,
        why: String,
        max_attempts: u32,
        tick: u64,
        trace: &mut Trace,
    ) -> Option<Cause> {
        self.tasks[t].attempts.push(attempt);
        let n = self.tasks[t].attempts.len() as u32;
        if n >= max_attempts {
            return Some(Cause::GaveUp {
                attempts: n,
                last: why,
            });
        }
        self.requeue(t);
        self.task_event(t, TaskEvent::Requeued { why }, tick, trace);
        None
    }

    /// Task `t` was stopped for a high-priority order (`by` its id).
    pub fn preempted(
        &mut self,
        t: TaskId,
        attempt: Attempt,
        by: String,
        tick: u64,
        trace: &mut Trace,
    ) {
        self.tasks[t].attempts.push(attempt);
        self.requeue(t);
        self.task_event(t, TaskEvent::Preempted { by }, tick, trace);
    }

    fn requeue(&mut self, t: TaskId) {
        self.tasks[t].state = TaskState::Queued;
        self.tasks[t].reassignments += 1;
    }

    /// Every task of the order ended (done or given up).
    pub fn order_ended(&self, o: usize) -> bool {
        self.orders[o]
            .tasks
            .iter()
            .all(|&t| !self.tasks[t].is_open())
    }

    /// Whether order `o` has a queued task in one of `queues`.
    pub fn has_queued_for(&self, o: usize, queues: &[OrderType]) -> bool {
        self.orders[o].tasks.iter().any(|&pt| {
            self.tasks[pt].state == TaskState::Queued && queues.contains(&self.tasks[pt].queue)
        })
    }

    /// What the queues came to: stopping needs two quiet ticks alike.
    pub fn signature(&self) -> (usize, usize, usize, usize) {
        (
            self.tasks.len() + self.tasks.iter().map(|t| t.attempts.len()).sum::<usize>(),
            self.tasks.iter().filter(|t| t.is_open()).count(),
            self.tasks
                .iter()
                .filter(|t| t.state == TaskState::Blocked)
                .count()
                + 1000
                    * self
                        .tasks
                        .iter()
                        .filter(|t| matches!(t.state, TaskState::Running { .. }))
                        .count(),
            self.orders.iter().filter(|o| o.announced.is_some()).count()
                + self.orders.iter().filter(|o| o.submitted.is_some()).count(),
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::random::{self, Scenario};

    fn attempt(outcome: &str) -> Attempt {
        Attempt {
            agent: "floor_robot".into(),
            start_tick: 1,
            end_tick: 2,
            part: None,
            goal: String::new(),
            plan: Vec::new(),
            planning_ms: 0.0,
            outcome: outcome.into(),
            challenges: Vec::new(),
        }
    }

    /// `f` on a task manager that announced a random order of type `ty`
    /// at tick 1, with a trace.
    fn announced(ty: OrderType, f: impl FnOnce(&mut TaskManager, &mut Trace)) {
        let trial = random::experiment(ty, Scenario::Normal, 1);
        let mut trace = Trace::new(true);
        let mut tm = TaskManager::new(&trial);
        tm.announce(0, 1, &mut trace);
        f(&mut tm, &mut trace);
    }

    #[test]
    fn a_kitting_order_is_a_tray_task_and_kit_tasks_after_it() {
        announced(OrderType::Kitting, |tm, trace| {
            let n = tm.tasks.len();
            assert!(n > 1);
            assert!(matches!(tm.tasks[0].work, Work::Tray { .. }));
            assert_eq!(tm.tasks[0].state, TaskState::Queued);
            for t in &tm.tasks[1..] {
                assert!(matches!(t.work, Work::Kit { .. }));
                assert_eq!(
                    (t.state.clone(), t.after.clone()),
                    (TaskState::Blocked, vec![0])
                );
            }
            tm.unblock();
            assert_eq!(tm.tasks[1].state, TaskState::Blocked, "the tray is open");
            tm.done(0, attempt("done"), 3, trace);
            tm.unblock();
            assert!(tm.tasks[1..].iter().all(|t| t.state == TaskState::Queued));
            assert_eq!(tm.queued(OrderType::Kitting, false).count(), n - 1);
            assert_eq!(tm.orders[0].announced, Some(1));
            assert!(trace.finish().contains("\"what\":\"announced\""));
        });
    }

    #[test]
    fn split_makes_a_kitting_half_and_an_assembly_half_that_waits_for_it() {
        announced(OrderType::Combined, |tm, trace| {
            assert!(matches!(tm.tasks[0].work, Work::Combined { .. }));
            tm.split(0, 2, 3, 4, trace);
            assert_eq!(tm.tasks[0].state, TaskState::Split { into: vec![4, 5] });
            let kit = tm.tasks.len() - 2;
            assert_eq!(kit, 4);
            assert!(matches!(
                tm.tasks[kit].work,
                Work::Kit {
                    agv: 2,
                    quadrant: 3,
                    ..
                }
            ));
            assert_eq!(tm.tasks[kit].queue, OrderType::Kitting);
            let asm = &tm.tasks[kit + 1];
            assert!(
                matches!(&asm.work, Work::Assemble { from_task: Some(k), agvs, .. } if *k == kit && *agvs == [2])
            );
            assert_eq!(
                (asm.state.clone(), asm.after.clone()),
                (TaskState::Blocked, vec![kit])
            );
            assert_eq!(tm.orders[0].agv, Some(2));
            // The assembly half waits for the kitting half and the quality check.
            tm.done(kit, attempt("done"), 5, trace);
            tm.unblock();
            assert_eq!(tm.tasks[kit + 1].state, TaskState::Blocked);
            tm.orders[0].qc_done = true;
            tm.unblock();
            assert_eq!(tm.tasks[kit + 1].state, TaskState::Queued);
        });
    }

    #[test]
    fn convert_makes_one_assembly_task_from_the_bins() {
        announced(OrderType::Combined, |tm, trace| {
            let asm = tm.convert(1, 2, trace).unwrap();
            assert_eq!(tm.tasks[1].state, TaskState::Split { into: vec![asm] });
            assert!(
                matches!(&tm.tasks[asm].work, Work::Assemble { from_task: None, agvs, .. } if agvs.is_empty())
            );
            assert_eq!(tm.tasks[asm].state, TaskState::Queued);
            assert_eq!(tm.convert(asm, 2, trace), None, "only a combined task");
            assert!(trace.finish().contains("\"what\":\"converted\""));
        });
    }

    #[test]
    fn a_failed_attempt_is_requeued_until_the_last_then_given_up() {
        announced(OrderType::Assembly, |tm, trace| {
            let why = || "`pick` failed: dropped".to_owned();
            assert_eq!(
                tm.attempt_failed(0, attempt("failed"), why(), 2, 3, trace),
                None
            );
            assert_eq!(
                (tm.tasks[0].state.clone(), tm.tasks[0].reassignments),
                (TaskState::Queued, 1)
            );
            let cause = tm
                .attempt_failed(0, attempt("failed"), why(), 2, 4, trace)
                .unwrap();
            assert_eq!(
                cause.to_string(),
                "gave up after 2 attempts; the last: `pick` failed: dropped"
            );
            tm.fail(0, &cause, 4, trace);
            assert!(
                matches!(&tm.tasks[0].state, TaskState::Failed { tick: 4, cause: c } if *c == cause.to_string())
            );
            assert!(!tm.order_ended(0), "the other parts are still open");
            tm.preempted(1, attempt("preempted"), "o2".into(), 5, trace);
            assert_eq!(
                (tm.tasks[1].state.clone(), tm.tasks[1].reassignments),
                (TaskState::Queued, 1)
            );
        });
    }

    #[test]
    fn when_a_kitting_half_fails_its_assembly_half_takes_a_part_from_the_bins() {
        announced(OrderType::Combined, |tm, trace| {
            tm.split(0, 1, 1, 2, trace);
            let (kit, asm) = (tm.tasks.len() - 2, tm.tasks.len() - 1);
            let cause = Cause::InsufficientParts {
                part: crate::trial::PartKind {
                    ty: crate::trial::PartType::Pump,
                    color: crate::trial::Color::Red,
                },
                from_agvs: Vec::new(),
            };
            assert!(cause.insufficient());
            tm.fail(kit, &cause, 3, trace);
            assert!(
                matches!(&tm.tasks[asm].work, Work::Assemble { from_task: None, agvs, .. } if agvs.is_empty())
            );
            tm.unblock();
            assert_eq!(tm.tasks[asm].state, TaskState::Queued);
        });
    }
}
