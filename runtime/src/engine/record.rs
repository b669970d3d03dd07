//! Why nodes fail, and the fault records: the failure that ended a run (or
//! the goal that does not hold), written to the records, the blackboard
//! (`fault_node`, `fault_step`, `fault_reason`, `fault_kb`) and the trace.

use super::{Engine, Status, TickEvent, Value};
use crate::kb::{ConditionId, FormulaId, Kb};
use serde::Serialize;

/// Why a node failed.
#[derive(Clone, Debug, PartialEq)]
pub(crate) enum Reason {
    Precondition(FormulaId),
    EndCondition(FormulaId),
    ConditionFalse(FormulaId),
    /// A formula-defined condition with these objects in its ports.
    PortsFalse(ConditionId, Vec<u32>),
    Fault(usize, String),
    Plain(String),
}

/// A record of a failure: what failed, in which step, why, and the KB.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct FaultRecord {
    pub tick: u64,
    pub node: u32,
    pub node_id: String,
    pub node_name: String,
    /// 1-based plan step: the failing node's, or for a node outside every
    /// step (a plan-level monitor), the step that was running.
    pub step: Option<usize>,
    pub action: Option<String>,
    pub reason: String,
    /// The injected faults the failure is attributed to.
    pub faults: Vec<String>,
    pub kb: Vec<String>,
}

impl FaultRecord {
    /// The `node` of a record an executor outside btc's engine made (a
    /// py_trees or BehaviorTree.CPP tree): it names its node by id and name.
    pub const OUTSIDE_ENGINE: u32 = u32::MAX;
}

impl<'w> Engine<'w> {
    pub(crate) fn note_failure(&mut self, node: u32, r: Reason) {
        self.last_failure = Some((node, r));
    }

    /// Node `node` fails for a reason told in words.
    #[cold]
    pub(super) fn fail(&mut self, node: u32, why: &str) -> Status {
        self.note_failure(node, Reason::Plain(why.to_owned()));
        Status::Failure
    }

    pub(crate) fn reason_text(&self, r: &Reason) -> String {
        let kb = self.kb.as_ref();
        match r {
            Reason::Precondition(f) => kb.map_or_else(String::new, |kb| {
                format!("its step's precondition does not hold: {}", kb.why_not(*f))
            }),
            Reason::EndCondition(f) => kb.map_or_else(String::new, |kb| {
                format!(
                    "its step's at-end condition does not hold: {}",
                    kb.why_not(*f)
                )
            }),
            Reason::ConditionFalse(f) => kb.map_or_else(String::new, |kb| {
                format!("the condition does not hold: {}", kb.why_not(*f))
            }),
            Reason::PortsFalse(c, objects) => kb.map_or_else(String::new, |kb| {
                format!(
                    "the condition does not hold: {}",
                    kb.why_not_with(*c, objects)
                )
            }),
            Reason::Fault(_, s) | Reason::Plain(s) => s.clone(),
        }
    }

    /// Writes a fault record for a failure of `node` to the records, the
    /// blackboard and the trace.
    pub(crate) fn record(&mut self, node: u32, r: &Reason) {
        let reason = self.reason_text(r);
        let meta = &self.meta[node as usize];
        let step = meta.step.or(self.step_running).map(|s| s as usize);
        let faults = self.faults_related(r, &reason);
        let rec = FaultRecord {
            tick: self.tick,
            node,
            node_id: meta.id.clone(),
            node_name: meta.name.clone(),
            step: step.map(|s| s + 1),
            action: step
                .and_then(|s| self.steps.get(s))
                .map(|s| s.label.clone()),
            reason,
            faults,
            kb: self.kb.as_ref().map(Kb::snapshot).unwrap_or_default(),
        };
        let [n, s, why, kb] = self.record_slots;
        self.bb[n as usize] = Value::Text(format!("{} ({})", rec.node_name, rec.node_id).into());
        self.bb[s as usize] = rec.step.map_or(Value::Empty, |s| Value::Int(s as i64));
        self.bb[why as usize] = Value::Text(rec.reason.as_str().into());
        self.bb[kb as usize] = Value::Text(rec.kb.join(" ").into());
        self.bb_gen += 1;
        self.records.push(rec);
        if self.observed() {
            self.notify(TickEvent::Record(self.records.len() - 1));
        }
    }

    /// After the run: the record of the failure that ended it, of the goal
    /// that does not hold, or of a tree still running (a SKIPPED root
    /// leaves none).
    pub(super) fn finish(&mut self, s: Status) {
        if s == Status::Failure {
            if let Some((node, r)) = self.last_failure.clone() {
                let dup = self.records.last().is_some_and(|rec| {
                    rec.node == node && rec.reason == self.reason_text(&r) && rec.tick == self.tick
                });
                if !dup {
                    self.record(node, &r);
                }
            }
        } else if s == Status::Success {
            if let Some((false, Some(why))) = self.kb.as_ref().map(Kb::goal) {
                self.record(
                    0,
                    &Reason::Plain(format!(
                        "the tree succeeded but the goal does not hold: {why}"
                    )),
                );
            }
        } else if s == Status::Running {
            let t = self.tick;
            self.record(
                0,
                &Reason::Plain(format!("the tree was still running after {t} ticks")),
            );
        }
    }
}
