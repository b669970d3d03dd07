//! Scripts in the tree: the `Script` and `ScriptCondition` leaves, and the
//! pre- and post-conditions BT.CPP runs around any node's tick (`_skipIf`,
//! `_onSuccess`...). A script is parsed once, when the tree is built; its
//! variables are blackboard slots.

use super::record::Reason;
use super::{Engine, NodeDef, Status, Value};
use crate::script::{self, Env, Script};

pub(crate) struct CompiledScript {
    pub script: Script,
    /// The blackboard slot of each of the script's variables.
    pub slots: Box<[u32]>,
    /// The text, for fault records.
    pub text: Box<str>,
}

/// A node's scripts, by BT.CPP's order: `_failureIf`, `_successIf`,
/// `_skipIf`, `_while`; `_onSuccess`, `_onFailure`, `_post`, `_onHalted`.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct Guard {
    pub pre: [Option<u32>; 4],
    pub post: [Option<u32>; 4],
}

const FAILURE_IF: usize = 0;
const SUCCESS_IF: usize = 1;
const SKIP_IF: usize = 2;
const WHILE: usize = 3;
const ON_SUCCESS: usize = 0;
const ON_FAILURE: usize = 1;
const POST: usize = 2;
const ON_HALTED: usize = 3;

/// The blackboard as a script sees it: an entry exists once it holds a
/// value (or `:=` makes it).
struct Blackboard<'a> {
    bb: &'a mut [Value],
    slots: &'a [u32],
    created: bool,
}

impl Env for Blackboard<'_> {
    fn get(&self, var: u32) -> Option<&Value> {
        let v = &self.bb[self.slots[var as usize] as usize];
        (*v != Value::Empty).then_some(v)
    }

    fn entry(&mut self, var: u32, create: bool) -> Option<&mut Value> {
        let v = &mut self.bb[self.slots[var as usize] as usize];
        if *v == Value::Empty && !create && !self.created {
            return None;
        }
        self.created |= create;
        Some(v)
    }
}

impl<'w> Engine<'w> {
    /// Runs script `k`: its value, or (after noting the failure of node
    /// `i`) `None` when it fails.
    fn run_script(&mut self, i: u32, k: u32) -> Option<Value> {
        let sc = &self.scripts[k as usize];
        let mut env = Blackboard {
            bb: &mut self.bb,
            slots: &sc.slots,
            created: false,
        };
        let out = sc.script.run(&mut env);
        self.bb_gen += 1;
        match out {
            Ok(v) => Some(v),
            Err(e) => {
                let why = format!("the script `{}` failed: {e}", sc.text);
                self.note_failure(i, Reason::Plain(why));
                None
            }
        }
    }

    /// Whether script `k` holds (`None`: it failed, noted).
    pub(super) fn script_holds(&mut self, i: u32, k: u32) -> Option<bool> {
        let v = self.run_script(i, k)?;
        match script::as_bool(&v) {
            Ok(b) => Some(b),
            Err(e) => {
                let why = format!(
                    "the script `{}` gave `{}`: {e}",
                    self.scripts[k as usize].text,
                    v.text()
                );
                self.note_failure(i, Reason::Plain(why));
                None
            }
        }
    }

    #[inline(never)]
    pub(super) fn tick_script(&mut self, i: u32, k: u32) -> Status {
        match self.run_script(i, k) {
            Some(_) => Status::Success,
            None => Status::Failure,
        }
    }

    #[inline(never)]
    pub(super) fn tick_script_condition(&mut self, i: u32, k: u32) -> Status {
        match self.script_holds(i, k) {
            Some(true) => Status::Success,
            Some(false) => {
                let why = format!("`{}` does not hold", self.scripts[k as usize].text);
                self.note_failure(i, Reason::Plain(why));
                Status::Failure
            }
            None => Status::Failure,
        }
    }

    /// A node with scripts around it, ticked as BT.CPP's `executeTick`.
    #[cold]
    #[inline(never)]
    pub(super) fn tick_guarded(&mut self, i: u32, def: NodeDef) -> Status {
        let iu = i as usize;
        let g = self.guards[def.guard as usize];
        let s = match self.preconditions(i, &g) {
            Some(s) => s,
            None => self.tick_op(i, def),
        };
        if s.is_done() {
            let first = if s == Status::Success {
                ON_SUCCESS
            } else {
                ON_FAILURE
            };
            for k in [g.post[first], g.post[POST]].into_iter().flatten() {
                self.run_script(i, k);
            }
        }
        if s != Status::Skipped {
            self.set(iu, s);
        }
        s
    }

    /// What the preconditions make of the tick, if anything.
    fn preconditions(&mut self, i: u32, g: &super::guard::Guard) -> Option<Status> {
        let status = self.status[i as usize];
        for (which, k) in g.pre.iter().enumerate() {
            let Some(k) = *k else { continue };
            if status == Status::Idle {
                let holds = self.script_holds(i, k);
                match (which, holds) {
                    (_, None) => return Some(Status::Failure),
                    (FAILURE_IF, Some(true)) => {
                        let why =
                            format!("its `_failureIf` holds: {}", self.scripts[k as usize].text);
                        self.note_failure(i, Reason::Plain(why));
                        return Some(Status::Failure);
                    }
                    (SUCCESS_IF, Some(true)) => return Some(Status::Success),
                    (SKIP_IF, Some(true)) | (WHILE, Some(false)) => return Some(Status::Skipped),
                    _ => {}
                }
            } else if status == Status::Running && which == WHILE {
                match self.script_holds(i, k) {
                    None => return Some(Status::Failure),
                    Some(false) => {
                        self.reset(i);
                        return Some(Status::Skipped);
                    }
                    Some(true) => {}
                }
            }
        }
        None
    }

    /// `_onHalted`, when a running node is halted.
    pub(super) fn on_halted(&mut self, i: u32, guard: u32) {
        if let Some(k) = self.guards[guard as usize].post[ON_HALTED] {
            self.run_script(i, k);
        }
    }
}
