//! Leaves the embedder implements ([`crate::handler`]): registering a
//! handler for an action ID, and ticking a leaf through it.

use super::{Engine, Reason, Status};
use crate::handler::{ActionCall, ActionHandler};

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
            self.note_failure(i, Reason::Plain(why));
        }
        status
    }
}
