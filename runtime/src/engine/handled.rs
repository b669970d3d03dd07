//! Leaves the embedder implements ([`crate::handler`]): registering a
//! handler for an action ID, ticking a leaf through it, and telling it
//! when its RUNNING leaf is halted.

use super::{Engine, Reason, Status};
use crate::handler::{ActionCall, ActionHandler, HaltHandler};

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

    /// Makes `on_halt` hear of every halt of a RUNNING action leaf with
    /// this ID (BT.CPP's `StatefulActionNode::onHalted`: stop the robot
    /// there); returns how many leaves it listens to.
    pub fn set_halt_handler(&mut self, id: &str, on_halt: HaltHandler<'w>) -> usize {
        let h = self.halt_handlers.len() as u32;
        self.halt_handlers.push(on_halt);
        let mut n = 0;
        for a in &mut self.actions {
            if &*a.id == id {
                a.on_halt = Some(h);
                n += 1;
            }
        }
        n
    }

    /// Leaf `i` (action `a`) was RUNNING and is halted.
    #[cold]
    pub(crate) fn halt_handled(&mut self, i: u32, a: u32, h: u32) {
        let (p, q) = self.actions[a as usize].ports;
        let call = ActionCall {
            node: i,
            starting: false,
            ports: &self.ports[p as usize..q as usize],
            bb: &self.bb,
            reason: Default::default(),
        };
        (self.halt_handlers[h as usize])(&call);
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
            self.note_failure(i, Reason::Plain(why));
        }
        status
    }
}
