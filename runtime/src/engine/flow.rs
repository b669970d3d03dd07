//! BT.CPP's conditional nodes: IfThenElse, WhileDoElse and Switch2..6
//! (controls), Delay, RunOnce and Precondition (decorators).

use super::record::Reason;
use super::state::NodeState;
use super::{Arg, Engine, NodeDef, Status, Value};

impl<'w> Engine<'w> {
    /// The condition (first child) picks the then (second) or the else
    /// (third) child once; that child then runs to completion.
    #[inline(never)]
    pub(super) fn tick_if_then_else(&mut self, i: u32, def: NodeDef) -> Status {
        let iu = i as usize;
        self.set(iu, Status::Running);
        let mut branch = match self.state[iu] {
            NodeState::Branch(b) => b,
            _ => 0,
        };
        if branch == 0 {
            let c = self.kid(def, 0);
            match self.tick_node(c) {
                Status::Running => return Status::Running,
                Status::Success => branch = 1,
                Status::Failure if def.len == 3 => branch = 2,
                Status::Failure => return Status::Failure,
                _ => {
                    self.note_failure(
                        i,
                        Reason::Plain("the condition of IfThenElse was skipped".into()),
                    );
                    return Status::Failure;
                }
            }
        }
        let c = self.kid(def, branch);
        let s = self.tick_node(c);
        if s == Status::Running {
            self.state[iu] = NodeState::Branch(branch);
            return Status::Running;
        }
        self.reset_children(def, 0);
        self.state[iu] = NodeState::Fresh;
        s
    }

    /// The condition is ticked every tick; the branch it picks runs, and
    /// the other one is halted.
    #[inline(never)]
    pub(super) fn tick_while_do_else(&mut self, i: u32, def: NodeDef) -> Status {
        self.set(i as usize, Status::Running);
        let cond = self.kid(def, 0);
        let s = match self.tick_node(cond) {
            Status::Running => return Status::Running,
            Status::Success => {
                if def.len == 3 {
                    let other = self.kid(def, 2);
                    self.reset(other);
                }
                let c = self.kid(def, 1);
                self.tick_node(c)
            }
            Status::Failure if def.len == 3 => {
                let other = self.kid(def, 1);
                self.reset(other);
                let c = self.kid(def, 2);
                self.tick_node(c)
            }
            Status::Failure => Status::Failure,
            // BT.CPP 4.10 returns IDLE here, and setting IDLE throws.
            _ => {
                self.reset_children(def, 0);
                return self.fail(i, "the condition of WhileDoElse was skipped");
            }
        };
        if s != Status::Running {
            self.reset_children(def, 0);
        }
        s
    }

    /// The child of the first case equal to the variable (as strings, or
    /// as numbers), or the last child.
    #[inline(never)]
    pub(super) fn tick_switch(
        &mut self,
        iu: usize,
        def: NodeDef,
        variable: u32,
        first_case: u32,
        cases: u32,
    ) -> Status {
        let var = self.read(variable).clone();
        let pick = if var == Value::Empty {
            cases
        } else {
            (0..cases)
                .find(|&k| same_case(&var, self.read(first_case + k)))
                .unwrap_or(cases)
        };
        if let NodeState::Branch(running) = self.state[iu] {
            if running != pick {
                let c = self.kid(def, running);
                self.reset(c);
            }
        }
        let c = self.kid(def, pick);
        let s = self.tick_node(c);
        match s {
            Status::Running => self.state[iu] = NodeState::Branch(pick),
            Status::Skipped => self.state[iu] = NodeState::Fresh,
            _ => {
                self.reset_children(def, 0);
                self.state[iu] = NodeState::Fresh;
            }
        }
        s
    }

    /// RUNNING for `msec` of simulated time, then the child's status.
    #[inline(never)]
    pub(super) fn tick_delay(&mut self, i: u32, def: NodeDef, arg: Arg<u64>) -> Status {
        let iu = i as usize;
        let until = match self.state[iu] {
            NodeState::Until(t) => t,
            _ => {
                // Read when the delay starts, as BT.CPP does.
                let msec = match self.amount(arg, "delay_msec", |n| u64::try_from(n).ok()) {
                    Ok(ms) => ms,
                    Err(r) => {
                        self.note_failure(i, r);
                        return Status::Failure;
                    }
                };
                self.set(iu, Status::Running);
                let t = self.now_ms.saturating_add(msec);
                self.state[iu] = NodeState::Until(t);
                // The delay starts now; the child is ticked on a later tick.
                return Status::Running;
            }
        };
        if self.now_ms < until {
            return Status::Running;
        }
        let c = self.kid(def, 0);
        let s = self.tick_node(c);
        if s.is_done() {
            self.state[iu] = NodeState::Fresh;
            self.reset(c);
        }
        s
    }

    /// The child runs once; afterwards SKIPPED, or its result again.
    #[inline(never)]
    pub(super) fn tick_run_once(&mut self, iu: usize, def: NodeDef, then_skip: bool) -> Status {
        if let NodeState::Ran(s) = self.state[iu] {
            return if then_skip { Status::Skipped } else { s };
        }
        self.set(iu, Status::Running);
        let c = self.kid(def, 0);
        let s = self.tick_node(c);
        if s.is_done() {
            self.state[iu] = NodeState::Ran(s);
            self.reset(c);
        }
        s
    }

    /// The child runs when the script holds as it starts; else `otherwise`.
    #[inline(never)]
    pub(super) fn tick_precondition(
        &mut self,
        i: u32,
        def: NodeDef,
        script: u32,
        otherwise: Status,
    ) -> Status {
        let iu = i as usize;
        if self.state[iu] != NodeState::Admitted {
            match self.script_holds(i, script) {
                Some(true) => self.state[iu] = NodeState::Admitted,
                Some(false) => {
                    if otherwise == Status::Failure {
                        let why = format!(
                            "its condition `{}` does not hold (Precondition)",
                            self.scripts[script as usize].text
                        );
                        self.note_failure(i, Reason::Plain(why));
                    }
                    return otherwise;
                }
                None => return Status::Failure,
            }
        }
        let c = self.kid(def, 0);
        let s = self.tick_node(c);
        if s.is_done() {
            self.reset(c);
            self.state[iu] = NodeState::Fresh;
        }
        s
    }
}

/// BT.CPP's case test: equal text, or equal numbers.
fn same_case(var: &Value, case: &Value) -> bool {
    let (a, b) = (var.text(), case.text());
    if a == b {
        return true;
    }
    match (a.trim().parse::<f64>(), b.trim().parse::<f64>()) {
        (Ok(x), Ok(y)) => x == y,
        _ => false,
    }
}
