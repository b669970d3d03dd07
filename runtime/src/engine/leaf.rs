//! Leaves: the built-in ones (Sleep, SetBlackboard, the KB nodes,
//! WaitForStep), conditions (formula-defined ones read the KB) and actions
//! (simulated, or commands run by the controller).

use super::record::Reason;
use super::state::NodeState;
use super::step::StepRt;
use super::{Engine, Src, Status, TickEvent, Value};
use crate::controller::Command;
use crate::kb::{EffectId, FormulaId};

impl<'w> Engine<'w> {
    #[inline(never)]
    pub(super) fn tick_sleep(&mut self, iu: usize, port: u32) -> Status {
        if self.status[iu] != Status::Running {
            let ms = self.read(port).as_int().unwrap_or(0);
            if ms <= 0 {
                return Status::Success;
            }
            self.state[iu] = NodeState::Until(self.now_ms.saturating_add(ms as u64));
            Status::Running
        } else if self.now_ms >= self.state[iu].until() {
            Status::Success
        } else {
            Status::Running
        }
    }

    #[inline(never)]
    pub(super) fn tick_set_blackboard(&mut self, value: u32, slot: u32) -> Status {
        let v = self.read(value).clone();
        if self.bb[slot as usize] != v {
            self.bb[slot as usize] = v;
            self.bb_gen += 1;
        }
        Status::Success
    }

    #[inline(never)]
    pub(super) fn tick_kb_holds(&mut self, i: u32, f: FormulaId) -> Status {
        if let Some(s) = self.inject_on_condition(i) {
            return s;
        }
        match self.kb.as_ref() {
            Some(kb) if kb.holds(f) => Status::Success,
            Some(_) => {
                self.note_failure(i, Reason::ConditionFalse(f));
                Status::Failure
            }
            None => Status::Failure,
        }
    }

    pub(super) fn tick_kb_apply(&mut self, e: EffectId) -> Status {
        if let Some(kb) = self.kb.as_mut() {
            kb.apply(e);
        }
        Status::Success
    }

    pub(super) fn tick_wait_for_step(&mut self, i: u32, k: u32) -> Status {
        match self.steps.get(k as usize) {
            Some(s) if s.finished || s.skipped => Status::Success,
            Some(_) => Status::Running,
            None => self.fail(i, &format!("there is no step {}", k + 1)),
        }
    }

    #[inline]
    pub(super) fn tick_condition(&mut self, i: u32, c: u32) -> Status {
        let cu = c as usize;
        let Some(formula) = self.conds[cu].formula else {
            return Status::Success;
        };
        if let Some(s) = self.inject_on_condition(i) {
            return s;
        }
        if self.conds[cu].generation != self.bb_gen {
            self.conds[cu].objects = self.port_objects(&self.conds[cu].slot_ports);
            self.conds[cu].generation = self.bb_gen;
        }
        let Some(kb) = self.kb.as_ref() else {
            return Status::Failure;
        };
        match &self.conds[cu].objects {
            Ok(objects) if kb.holds_with(formula, objects) => Status::Success,
            Ok(objects) => {
                let r = Reason::PortsFalse(formula, objects.clone());
                self.note_failure(i, r);
                Status::Failure
            }
            Err(m) => {
                let r = Reason::Plain(m.clone());
                self.note_failure(i, r);
                Status::Failure
            }
        }
    }

    /// The objects a formula-defined condition's ports name now.
    pub(super) fn port_objects(&self, slot_ports: &[u32]) -> Result<Vec<u32>, String> {
        let kb = self.kb.as_ref().ok_or("no knowledge base")?;
        slot_ports
            .iter()
            .map(|&p| {
                let port = &self.ports[p as usize];
                // PDDL names are case-insensitive; a port's text keeps its case.
                let v = self.value(&port.src).text();
                kb.object(&v.to_lowercase()).ok_or_else(|| {
                    format!(
                        "port `{}` holds `{v}`, which is not an object of this problem",
                        port.name
                    )
                })
            })
            .collect()
    }

    #[inline]
    pub(super) fn tick_action(&mut self, i: u32, a: u32) -> Status {
        if let Some(h) = self.actions[a as usize].handler {
            return self.tick_handled(i, a, h);
        }
        let iu = i as usize;
        let running = self.status[iu] == Status::Running;
        if self.inject_live {
            if let Some(s) = self.inject_on_action(i, a, !running) {
                if s == Status::Failure {
                    self.state[iu] = NodeState::Fresh;
                }
                return s;
            }
        }
        match self.state[iu] {
            NodeState::Commanded(seq) if running => {
                let done = self.controller.as_mut().is_some_and(|c| c.take_done(seq));
                if done {
                    self.state[iu] = NodeState::Fresh;
                    return Status::Success;
                }
                Status::Running
            }
            NodeState::Working(left) if running => {
                let left = left.saturating_sub(1);
                if left == 0 {
                    self.state[iu] = NodeState::Fresh;
                    Status::Success
                } else {
                    self.state[iu] = NodeState::Working(left);
                    Status::Running
                }
            }
            _ => self.start_action(i, a),
        }
    }

    /// An action leaf starts: its step's condition is checked, then it is
    /// commanded or simulated.
    fn start_action(&mut self, i: u32, a: u32) -> Status {
        let iu = i as usize;
        let step = self.meta[iu].step;
        if let (Some(k), Some(kb)) = (step, self.kb.as_ref()) {
            if let Some(pre) = self.steps.get(k as usize).and_then(StepRt::leaf_check) {
                if !kb.holds(pre) {
                    self.note_failure(i, Reason::Precondition(pre));
                    return Status::Failure;
                }
            }
        }
        if self.controller.is_some() {
            let cmd = self.command(i, a);
            let seq = self.controller.as_mut().map_or(0, |c| c.submit(cmd));
            if self.observed() {
                self.notify(TickEvent::Command {
                    tick: self.tick,
                    seq,
                    node: i,
                });
            }
            self.state[iu] = NodeState::Commanded(seq);
            return Status::Running;
        }
        if self.opts.ticks_per_action == 0 {
            return Status::Success;
        }
        self.state[iu] = NodeState::Working(self.opts.ticks_per_action as u64);
        Status::Running
    }

    fn command(&self, i: u32, a: u32) -> Command {
        let info = &self.actions[a as usize];
        let (p, q) = info.ports;
        Command {
            seq: 0,
            node: i,
            command: info.id.to_string(),
            args: self.ports[p as usize..q as usize]
                .iter()
                .map(|b| (b.name.to_string(), self.value(&b.src).text()))
                .collect(),
            step: self.meta[i as usize].step.map(|s| s as usize + 1),
        }
    }

    #[inline]
    pub(crate) fn value<'a>(&'a self, s: &'a Src) -> &'a Value {
        match s {
            Src::Const(v) => v,
            Src::Slot(k) => &self.bb[*k as usize],
        }
    }

    #[inline]
    pub(super) fn read(&self, port: u32) -> &Value {
        let p = &self.ports[port as usize];
        self.value(&p.src)
    }
}
