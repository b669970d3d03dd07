//! What happens in a trial, as values: the task level's events (written to
//! the trace as JSON Lines), why a part task is given up, and who holds a
//! resource. The trace is an observer: it receives events and the agents'
//! tree traces and writes nothing the simulation reads back.

use super::tasks::TaskId;
use crate::trial::PartKind;
use serde::Serialize;
use std::fmt;

/// A task-level event. Serialised with its `event` tag and, in the trace,
/// the tick it happened on.
#[derive(Clone, Debug, PartialEq, Serialize)]
#[serde(tag = "event", rename_all = "snake_case")]
pub enum Event {
    Conveyor {
        part: String,
        what: Belt,
    },
    /// An AGV leaves for a place with an order's kit, or arrives.
    Agv {
        agv: String,
        #[serde(flatten)]
        what: AgvMove,
    },
    Order {
        order: String,
        #[serde(flatten)]
        what: OrderEvent,
    },
    Task {
        task: TaskId,
        order: String,
        #[serde(flatten)]
        what: TaskEvent,
    },
    /// An agent starts an attempt at a task with a plan.
    Attempt {
        task: TaskId,
        order: String,
        agent: String,
        goal: String,
        plan: Vec<String>,
    },
    Challenge {
        challenge: String,
        #[serde(flatten)]
        what: ChallengeEvent,
    },
}

#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub enum Belt {
    #[serde(rename = "arrives")]
    Arrives,
    #[serde(rename = "falls off the end")]
    FallsOff,
}

#[derive(Clone, Debug, PartialEq, Serialize)]
#[serde(untagged)]
pub enum AgvMove {
    Leaves { order: String, leaves_for: String },
    Arrives { arrives: String },
}

#[derive(Clone, Debug, PartialEq, Serialize)]
#[serde(tag = "what", rename_all = "snake_case")]
pub enum OrderEvent {
    Announced {
        #[serde(rename = "type")]
        ty: &'static str,
        priority: bool,
    },
    Submitted {
        score: i64,
    },
}

#[derive(Clone, Debug, PartialEq, Serialize)]
#[serde(tag = "what", rename_all = "snake_case")]
pub enum TaskEvent {
    Created {
        work: String,
        queue: &'static str,
    },
    Split {
        into: Vec<TaskId>,
    },
    Converted {
        into: Vec<TaskId>,
    },
    Done {
        #[serde(skip_serializing_if = "Option::is_none")]
        how: Option<&'static str>,
    },
    Failed {
        cause: String,
    },
    Requeued {
        why: String,
    },
    Preempted {
        by: String,
    },
}

#[derive(Clone, Debug, PartialEq, Serialize)]
#[serde(tag = "what", rename_all = "snake_case")]
pub enum ChallengeEvent {
    Triggered,
    Ended,
    Dropped { part: String },
}

/// Why a part task is given up. Its text is what the report and the trace
/// say (`TaskState::Failed`'s cause).
#[derive(Clone, Debug, PartialEq)]
pub enum Cause {
    NoSuchTray {
        tray: u8,
    },
    AgvHasAnotherTray {
        agv: u8,
        has: String,
        tray: u8,
    },
    TrayNotOnTables {
        tray: u8,
    },
    /// No part of the kind is left where the task may take it from: the
    /// bins and the belt (`from_agvs` empty) or the order's AGVs.
    InsufficientParts {
        part: PartKind,
        from_agvs: Vec<u8>,
    },
    SlotTaken {
        station: u8,
        ty: &'static str,
    },
    KittingHalfPartGone,
    GoalDoesNotFit {
        goal: String,
        why: String,
    },
    GaveUp {
        attempts: u32,
        last: String,
    },
    TrialStopped {
        why: String,
    },
}

impl Cause {
    /// Whether it means ARIAC's insufficient-parts challenge.
    pub fn insufficient(&self) -> bool {
        matches!(self, Cause::InsufficientParts { .. })
    }
}

impl fmt::Display for Cause {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Cause::NoSuchTray { tray } => write!(f, "the cell has no tray {tray}"),
            Cause::AgvHasAnotherTray { agv, has, tray } => {
                write!(f, "agv{agv} carries {has} already, not tray {tray}")
            }
            Cause::TrayNotOnTables { tray } => write!(
                f,
                "tray {tray} is on neither tray table (the trial's `kitting_trays` do not have it)"
            ),
            Cause::InsufficientParts { part, from_agvs } if from_agvs.is_empty() => write!(
                f,
                "insufficient parts: no {part} is left in the bins or on the conveyor, nor still to come"
            ),
            Cause::InsufficientParts { part, from_agvs } => {
                let agvs: Vec<String> = from_agvs.iter().map(|n| format!("agv{n}")).collect();
                write!(f, "insufficient parts: no {part} is on {}", agvs.join(" or "))
            }
            Cause::SlotTaken { station, ty } => write!(
                f,
                "the insert at as{station} has a {ty} in its slot already"
            ),
            Cause::KittingHalfPartGone => write!(f, "the part its kitting half placed is gone"),
            Cause::GoalDoesNotFit { goal, why } => {
                write!(f, "its goal `{goal}` does not fit the cell's domain: {why}")
            }
            Cause::GaveUp { attempts, last } => {
                write!(f, "gave up after {attempts} attempts; the last: {last}")
            }
            Cause::TrialStopped { why } => write!(f, "not done when the trial stopped ({why})"),
        }
    }
}

/// Who holds a resource: a running task, or an AGV on its way (which no
/// task holds).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Holder {
    Task(TaskId),
    Travel,
}

impl fmt::Display for Holder {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Holder::Task(t) => write!(f, "task {t}"),
            Holder::Travel => write!(f, "an AGV's trip"),
        }
    }
}

/// The trace: task-level events and the agents' tree traces, each line
/// with its tick, sorted by tick at the end (stable: events of one tick
/// keep their order).
#[derive(Default)]
pub struct Trace {
    on: bool,
    lines: Vec<(u64, String)>,
}

impl Trace {
    pub fn new(on: bool) -> Trace {
        Trace {
            on,
            lines: Vec::new(),
        }
    }

    pub fn is_on(&self) -> bool {
        self.on
    }

    pub fn event(&mut self, tick: u64, e: &Event) {
        if !self.on {
            return;
        }
        if let Ok(mut v) = serde_json::to_value(e) {
            if let Some(o) = v.as_object_mut() {
                o.insert("tick".into(), tick.into());
            }
            self.lines.push((tick, v.to_string()));
        }
    }

    /// An attempt's tree trace (JSON Lines from the engine), each line
    /// marked with its agent and task.
    pub fn tree(&mut self, jsonl: &str, agent: &str, task: TaskId, now: u64) {
        if !self.on {
            return;
        }
        for line in jsonl.lines() {
            if let Ok(mut v) = serde_json::from_str::<serde_json::Value>(line) {
                let tick = v
                    .get("tick")
                    .and_then(serde_json::Value::as_u64)
                    .unwrap_or(now);
                if let Some(o) = v.as_object_mut() {
                    o.insert("agent".into(), agent.into());
                    o.insert("task".into(), task.into());
                }
                self.lines.push((tick, v.to_string()));
            }
        }
    }

    /// The JSON Lines, in tick order.
    pub fn finish(&mut self) -> String {
        let mut out = String::new();
        if self.on {
            self.lines.sort_by_key(|(t, _)| *t);
            for (_, l) in &self.lines {
                out.push_str(l);
                out.push('\n');
            }
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn line(e: Event) -> String {
        let mut t = Trace::new(true);
        t.event(7, &e);
        t.finish()
    }

    #[test]
    fn events_serialise_as_the_trace_always_wrote_them() {
        // The JSON the untyped events wrote, key for key.
        let cases = [
            (
                Event::Task {
                    task: 3,
                    order: "o1".into(),
                    what: TaskEvent::Done { how: None },
                },
                serde_json::json!({"event": "task", "task": 3, "order": "o1", "what": "done", "tick": 7}),
            ),
            (
                Event::Task {
                    task: 3,
                    order: "o1".into(),
                    what: TaskEvent::Split { into: vec![4, 5] },
                },
                serde_json::json!({"event": "task", "task": 3, "order": "o1", "what": "split", "into": [4, 5], "tick": 7}),
            ),
            (
                Event::Conveyor {
                    part: "p".into(),
                    what: Belt::FallsOff,
                },
                serde_json::json!({"event": "conveyor", "part": "p", "what": "falls off the end", "tick": 7}),
            ),
            (
                Event::Agv {
                    agv: "agv1".into(),
                    what: AgvMove::Leaves {
                        order: "o".into(),
                        leaves_for: "w".into(),
                    },
                },
                serde_json::json!({"event": "agv", "agv": "agv1", "order": "o", "leaves_for": "w", "tick": 7}),
            ),
            (
                Event::Order {
                    order: "o".into(),
                    what: OrderEvent::Announced {
                        ty: "kitting",
                        priority: true,
                    },
                },
                serde_json::json!({"event": "order", "order": "o", "what": "announced", "type": "kitting", "priority": true, "tick": 7}),
            ),
            (
                Event::Challenge {
                    challenge: "c".into(),
                    what: ChallengeEvent::Triggered,
                },
                serde_json::json!({"event": "challenge", "challenge": "c", "what": "triggered", "tick": 7}),
            ),
        ];
        for (e, want) in cases {
            let got: serde_json::Value = serde_json::from_str(line(e).trim()).unwrap();
            assert_eq!(got, want);
        }
    }

    #[test]
    fn a_trace_that_is_off_records_nothing() {
        let mut t = Trace::new(false);
        t.event(
            1,
            &Event::Challenge {
                challenge: "c".into(),
                what: ChallengeEvent::Ended,
            },
        );
        t.tree("{\"tick\": 1}\n", "r", 0, 1);
        assert_eq!(t.finish(), "");
    }
}
