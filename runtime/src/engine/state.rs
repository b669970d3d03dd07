//! Per-node run-time state: one typed value per node, what the node's
//! family needs to carry from one tick to the next.

/// A node's state between ticks. `Fresh` is a node that has not started
/// (or was reset); each family uses its own variant.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub(crate) enum NodeState {
    #[default]
    Fresh,
    /// Sequence and Fallback families: the child to tick next, and how
    /// many were SKIPPED so far.
    Child { next: u32, skipped: u32 },
    /// IfThenElse: the branch taken; Switch: the child running.
    Branch(u32),
    /// Precondition: its script held, the child runs until it is done.
    Admitted,
    /// RunOnce: the child ran, and returned this.
    Ran(super::Status),
    /// Parallel: how many children have succeeded and failed so far.
    Tally { success: u32, failure: u32 },
    /// Retry and Repeat: the attempts (or cycles) made so far.
    Attempts(u32),
    /// Timeout and Sleep: the simulated time (ms) at which it ends.
    Until(u64),
    /// Timeout: when it ends, and its duration as read when it started.
    Deadline { until: u64, msec: u32 },
    /// A simulated action leaf: the ticks it stays RUNNING.
    Working(u64),
    /// An action leaf whose command the controller runs: its number.
    Commanded(u64),
}

impl NodeState {
    /// The child a Sequence or Fallback ticks next, and the skipped ones.
    #[inline]
    pub fn child(self) -> (u32, u32) {
        match self {
            NodeState::Child { next, skipped } => (next, skipped),
            _ => (0, 0),
        }
    }

    /// Attempts made by a Retry or a Repeat.
    #[inline]
    pub fn attempts(self) -> u32 {
        match self {
            NodeState::Attempts(n) => n,
            _ => 0,
        }
    }

    /// The end of a Timeout or a Sleep.
    #[inline]
    pub fn until(self) -> u64 {
        match self {
            NodeState::Until(t) => t,
            _ => 0,
        }
    }

    /// A Parallel's tally.
    #[inline]
    pub fn tally(self) -> (u32, u32) {
        match self {
            NodeState::Tally { success, failure } => (success, failure),
            _ => (0, 0),
        }
    }
}
