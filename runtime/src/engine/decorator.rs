//! Decorators: one child, its status transformed (Inverter, ForceSuccess,
//! ForceFailure, KeepRunningUntilFailure, and SubTree, which passes it
//! through), repeated (Retry, Repeat) or bounded in time (Timeout).

use super::record::Reason;
use super::state::NodeState;
use super::{Arg, Engine, NodeDef, Op, Status};

impl<'w> Engine<'w> {
    /// The decorators that map their child's status.
    #[inline(never)]
    pub(super) fn tick_wrapper(&mut self, i: u32, def: NodeDef) -> Status {
        // BT.CPP's SubTree becomes RUNNING only from IDLE: one ticked again
        // after it finished (WhileDoElse's condition) keeps its status.
        if def.op != Op::SubTree || self.status[i as usize] == Status::Idle {
            self.set(i as usize, Status::Running);
        }
        let c = self.kid(def, 0);
        let s = self.tick_node(c);
        if s.is_done() {
            self.reset(c);
        }
        match (def.op, s) {
            (_, Status::Running) => Status::Running,
            // BT.CPP 4.10 returns its own status (RUNNING) for a SKIPPED
            // child; the others pass SKIPPED on.
            (Op::KeepRunningUntilFailure, Status::Skipped) => Status::Running,
            (_, Status::Skipped) => Status::Skipped,
            (Op::Inverter, Status::Success) => self.fail(i, "its child succeeded (Inverter)"),
            (Op::Inverter, _) => Status::Success,
            (Op::ForceSuccess, _) => Status::Success,
            (Op::ForceFailure, _) => self.fail(i, "ForceFailure"),
            (Op::KeepRunningUntilFailure, Status::Success) => Status::Running,
            (_, s) => s,
        }
    }

    /// Retry (`RETRY`) counts failures and stops at a success; Repeat
    /// counts successes and stops at a failure. `n < 0`: forever.
    #[inline(never)]
    pub(super) fn tick_loop<const RETRY: bool>(
        &mut self,
        i: u32,
        def: NodeDef,
        n: Arg<i32>,
    ) -> Status {
        let iu = i as usize;
        let what = if RETRY { "num_attempts" } else { "num_cycles" };
        let n = match self.amount(n, what, |n| i32::try_from(n).ok().filter(|n| *n >= -1)) {
            Ok(n) => n,
            Err(r) => {
                self.note_failure(i, r);
                return Status::Failure;
            }
        };
        self.set(iu, Status::Running);
        let c = self.kid(def, 0);
        let (again, end) = if RETRY {
            (Status::Failure, Status::Success)
        } else {
            (Status::Success, Status::Failure)
        };
        let more = |made: u32| n < 0 || (made as i64) < n as i64;
        loop {
            let made = self.state[iu].attempts();
            if !more(made) {
                self.state[iu] = NodeState::Fresh;
                return again;
            }
            let fresh = self.status[c as usize] == Status::Idle;
            let s = self.tick_node(c);
            if s == Status::Running {
                return Status::Running;
            }
            self.reset(c);
            if s == Status::Skipped {
                // The attempts made so far stay counted, as in BT.CPP.
                return Status::Skipped;
            }
            if s == end {
                self.state[iu] = NodeState::Fresh;
                return end;
            }
            let made = made.saturating_add(1);
            if !more(made) {
                self.state[iu] = NodeState::Fresh;
                return again;
            }
            self.state[iu] = NodeState::Attempts(made);
            // BT.CPP 4.10: an attempt that started and ended in this tick
            // hands the flow back (RUNNING); the next attempt runs at the
            // next tick. After a child that was RUNNING, the next attempt
            // starts at once.
            if fresh {
                return Status::Running;
            }
        }
    }

    #[inline(never)]
    pub(super) fn tick_timeout(&mut self, i: u32, def: NodeDef, arg: Arg<u64>) -> Status {
        let iu = i as usize;
        let c = self.kid(def, 0);
        if self.status[iu] != Status::Running {
            // Read when the timeout starts, as BT.CPP does.
            let msec = match self.amount(arg, "msec", |n| u64::try_from(n).ok()) {
                Ok(ms) => ms,
                Err(r) => {
                    self.note_failure(i, r);
                    return Status::Failure;
                }
            };
            self.set(iu, Status::Running);
            self.state[iu] = NodeState::Deadline {
                until: self.now_ms.saturating_add(msec),
                msec: u32::try_from(msec).unwrap_or(u32::MAX),
            };
        }
        let (until, msec) = match self.state[iu] {
            NodeState::Deadline { until, msec } => (until, msec),
            _ => (0, 0),
        };
        if msec > 0 && self.now_ms >= until && self.status[c as usize] == Status::Running {
            self.reset(c);
            self.note_failure(i, Reason::Plain(format!("timed out after {msec} ms")));
            Status::Failure
        } else {
            let s = self.tick_node(c);
            if s.is_done() {
                self.reset(c);
            }
            s
        }
    }

    /// A decorator's count: fixed, or read from its blackboard slot (a fault
    /// reason when the entry holds no number the decorator takes).
    pub(super) fn amount<T: Copy>(
        &self,
        a: Arg<T>,
        port: &str,
        fit: impl Fn(i64) -> Option<T>,
    ) -> Result<T, Reason> {
        match a {
            Arg::Fixed(n) => Ok(n),
            Arg::Slot(s) => {
                let v = &self.bb[s as usize];
                v.as_int().and_then(fit).ok_or_else(|| {
                    Reason::Plain(format!(
                        "`{port}` reads `{}` from the blackboard, which is not a number it takes",
                        v.text()
                    ))
                })
            }
        }
    }
}
