//! A node's status, as BehaviorTree.CPP v4 names them.

use serde::Serialize;

#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize)]
#[serde(rename_all = "UPPERCASE")]
pub enum Status {
    Idle,
    Running,
    Success,
    Failure,
    /// BT.CPP's SKIPPED: the node did not run (a precondition said so).
    /// Returned to the parent; the node itself stays as it was.
    Skipped,
}

impl Status {
    pub fn name(self) -> &'static str {
        match self {
            Status::Idle => "IDLE",
            Status::Running => "RUNNING",
            Status::Success => "SUCCESS",
            Status::Failure => "FAILURE",
            Status::Skipped => "SKIPPED",
        }
    }

    pub fn is_done(self) -> bool {
        matches!(self, Status::Success | Status::Failure)
    }
}
