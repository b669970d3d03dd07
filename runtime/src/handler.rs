//! Action leaves the embedding program implements: a handler registered for
//! an action ID replaces the simulated action (and the controller) for every
//! leaf of that ID. btc's tests implement scripted leaves this way to run
//! the same trees in btc's engine and in BehaviorTree.CPP.

use crate::engine::port::{PortBind, Src};
use crate::engine::status::Status;
use crate::engine::value::Value;

/// What a handler sees of the leaf it ticks.
pub struct ActionCall<'a> {
    /// The leaf's node index (preorder).
    pub node: u32,
    /// The leaf was not RUNNING before this tick: it starts now (first
    /// tick, or after it finished or was halted).
    pub starting: bool,
    pub(crate) ports: &'a [PortBind],
    pub(crate) bb: &'a [Value],
    /// Why the leaf failed, when its implementation says so.
    pub(crate) reason: std::cell::RefCell<Option<String>>,
}

impl ActionCall<'_> {
    /// A port's value (a constant, or its blackboard entry's current value).
    pub fn port(&self, name: &str) -> Option<&Value> {
        self.ports
            .iter()
            .find(|p| &*p.name == name)
            .map(|p| match &p.src {
                Src::Const(v) => v,
                Src::Slot(k) => &self.bb[*k as usize],
            })
    }
}

impl ActionCall<'_> {
    /// Fails the leaf for a reason told in the user's words ("the gripper
    /// dropped the part"): the fault record of the failure says it.
    /// Returning FAILURE without it records that the leaf failed.
    pub fn fail(&self, why: impl Into<String>) -> Status {
        *self.reason.borrow_mut() = Some(why.into());
        Status::Failure
    }
}

/// A leaf implementation: returns the leaf's status for this tick. Halting
/// a RUNNING leaf resets it to IDLE without calling it; a [`HaltHandler`]
/// hears of the halt.
pub type ActionHandler<'w> = Box<dyn FnMut(&ActionCall<'_>) -> Status + 'w>;

/// Told that a RUNNING leaf was halted (a reactive condition failed above
/// it, a Parallel finished, the run stopped): the call names the leaf and
/// its ports, as its last tick saw them.
pub type HaltHandler<'w> = Box<dyn FnMut(&ActionCall<'_>) + 'w>;
