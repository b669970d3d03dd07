//! Action leaves the embedding program implements: a handler registered for
//! an action ID replaces the simulated action (and the controller) for every
//! leaf of that ID. btc's tests implement scripted leaves this way to run
//! the same trees in btc's engine and in BehaviorTree.CPP.

use crate::engine::{Engine, PortBind, Src, Status, Value};

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
    reason: std::cell::RefCell<Option<String>>,
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
/// a RUNNING leaf resets it to IDLE without calling the handler.
pub type ActionHandler<'w> = Box<dyn FnMut(&ActionCall<'_>) -> Status + 'w>;

impl<'w> Engine<'w> {
    /// Makes `handler` tick every action leaf with this ID; returns how
    /// many leaves it took over.
    pub fn set_action_handler(&mut self, id: &str, handler: ActionHandler<'w>) -> usize {
        let h = self.handlers.len() as u32;
        self.handlers.push(handler);
        let mut n = 0;
        for a in &mut self.actions {
            if &*a.id == id {
                a.handler = Some(h);
                n += 1;
            }
        }
        n
    }

    pub(crate) fn tick_handled(&mut self, i: u32, a: u32, h: u32) -> Status {
        let (p, q) = self.actions[a as usize].ports;
        let call = ActionCall {
            node: i,
            starting: self.status[i as usize] != Status::Running,
            ports: &self.ports[p as usize..q as usize],
            bb: &self.bb,
            reason: Default::default(),
        };
        let status = (self.handlers[h as usize])(&call);
        if status == Status::Failure {
            let why = call.reason.into_inner().unwrap_or_else(|| {
                format!(
                    "the `{}` leaf's implementation returned FAILURE",
                    self.actions[a as usize].id
                )
            });
            self.note_failure(i, crate::engine::Reason::Plain(why));
        }
        status
    }
}
