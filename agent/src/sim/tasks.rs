//! Part tasks, the smallest unit of work (Liu et al. 2024, section 3.2),
//! and the three queues they wait in.

use crate::trial::{OrderType, PartKind};
use serde::Serialize;
use std::fmt;

/// A part task: its place in the trial's list of tasks (the report's
/// `tasks`), which is also its number.
pub type TaskId = usize;

/// A part of the trial: its place among the trial's parts. Written as the
/// number (in the report and in messages).
#[derive(Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize)]
#[serde(transparent)]
pub struct PartId(pub usize);

impl fmt::Debug for PartId {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}", self.0)
    }
}

impl fmt::Display for PartId {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}", self.0)
    }
}

/// What a part task does.
#[derive(Clone, Debug, PartialEq, Serialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum Work {
    /// Put the order's kit tray on its AGV.
    Tray { agv: u8, tray: u8 },
    /// A part of `part` into `quadrant` of the AGV's kit.
    Kit {
        part: PartKind,
        agv: u8,
        quadrant: u8,
    },
    /// The part found faulty in `quadrant` to the disposal bin, and a new
    /// one in its place.
    Replace {
        part: PartKind,
        agv: u8,
        quadrant: u8,
        faulty: PartId,
    },
    /// A part into the station's insert: from the order's AGVs (assembly),
    /// from the bins or the belt (a converted combined task), or the part a
    /// kitting half put on an AGV (`from_task`).
    Assemble {
        part: PartKind,
        station: u8,
        agvs: Vec<u8>,
        from_task: Option<TaskId>,
    },
    /// A combined part task not yet split or converted.
    Combined { part: PartKind, station: u8 },
}

impl Work {
    pub fn part_kind(&self) -> Option<PartKind> {
        match self {
            Work::Tray { .. } => None,
            Work::Kit { part, .. }
            | Work::Replace { part, .. }
            | Work::Assemble { part, .. }
            | Work::Combined { part, .. } => Some(*part),
        }
    }

    pub fn describe(&self) -> String {
        match self {
            Work::Tray { agv, tray } => format!("tray {tray} onto agv{agv}"),
            Work::Kit {
                part,
                agv,
                quadrant,
            } => format!("{part} into agv{agv} quadrant {quadrant}"),
            Work::Replace {
                part,
                agv,
                quadrant,
                ..
            } => format!("replace the faulty part in agv{agv} quadrant {quadrant} with a {part}"),
            Work::Assemble {
                part,
                station,
                from_task: Some(_),
                ..
            } => format!("{part} from its AGV into the insert at as{station}"),
            Work::Assemble { part, station, .. } => {
                format!("{part} into the insert at as{station}")
            }
            Work::Combined { part, station } => format!("{part} for the insert at as{station}"),
        }
    }
}

#[derive(Clone, Debug, PartialEq, Serialize)]
#[serde(tag = "state", rename_all = "snake_case")]
pub enum TaskState {
    /// Waiting for other tasks (the tray, the kitting halves of its AGV).
    Blocked,
    Queued,
    Running {
        agent: usize,
    },
    Done {
        tick: u64,
    },
    /// Given up, with the cause.
    Failed {
        tick: u64,
        cause: String,
    },
    /// Split into a kitting and an assembly half, or converted into an
    /// assembly task (the tasks that carry on).
    Split {
        into: Vec<TaskId>,
    },
}

/// One attempt at a task by an agent.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Attempt {
    pub agent: String,
    pub start_tick: u64,
    pub end_tick: u64,
    /// The part object the attempt used.
    pub part: Option<String>,
    pub goal: String,
    pub plan: Vec<String>,
    pub planning_ms: f64,
    /// `done`, `failed: ...`, `preempted`, `no plan`.
    pub outcome: String,
    pub challenges: Vec<String>,
}

#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Task {
    pub id: TaskId,
    pub order: usize,
    pub queue: OrderType,
    pub work: Work,
    pub priority: bool,
    pub state: TaskState,
    /// Tasks that must be done first.
    pub after: Vec<TaskId>,
    /// The part object chosen for the running or last attempt.
    pub part: Option<PartId>,
    pub attempts: Vec<Attempt>,
    /// Times it went back to its queue after a failure or a preemption.
    pub reassignments: u32,
    pub created: u64,
}

impl Task {
    pub fn is_open(&self) -> bool {
        matches!(
            self.state,
            TaskState::Blocked | TaskState::Queued | TaskState::Running { .. }
        )
    }

    pub fn is_done(&self) -> bool {
        matches!(self.state, TaskState::Done { .. })
    }
}

/// Something a task holds while it runs: one task at a time.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Resource {
    Part(PartId),
    /// The AGV itself (moving it, its tray).
    Agv(u8),
    /// One quadrant of an AGV's kit.
    Quadrant(u8, u8),
    Station(u8),
    Tray(u8),
}

impl Resource {
    /// Whether two holds exclude each other.
    pub fn conflicts(self, other: Resource) -> bool {
        match (self, other) {
            (Resource::Agv(a), Resource::Quadrant(b, _))
            | (Resource::Quadrant(b, _), Resource::Agv(a)) => a == b,
            (a, b) => a == b,
        }
    }
}
