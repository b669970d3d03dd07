//! The trace: an observer of the tick that keeps status changes and events
//! (steps, faults, records, commands), written out as JSON Lines.

use super::{Engine, Status};

/// One line of the trace.
#[derive(Clone, Debug, PartialEq)]
pub enum TraceItem {
    Status {
        tick: u64,
        node: u32,
        from: Status,
        to: Status,
    },
    StepStarted {
        tick: u64,
        step: u32,
    },
    StepFinished {
        tick: u64,
        step: u32,
    },
    Fault {
        tick: u64,
        fault: usize,
        ended: bool,
    },
    Record(usize),
    Command {
        tick: u64,
        seq: u64,
        node: u32,
    },
}

impl<'w> Engine<'w> {
    /// A status change, seen when the trace is on.
    #[cold]
    pub(super) fn observe_status(&mut self, node: u32, from: Status, to: Status) {
        self.trace.push(TraceItem::Status {
            tick: self.tick,
            node,
            from,
            to,
        });
    }

    /// The trace as JSON Lines.
    pub fn trace_jsonl(&self) -> String {
        let mut out = String::new();
        for t in &self.trace {
            out.push_str(&self.trace_line(t).to_string());
            out.push('\n');
        }
        out
    }

    /// Writes the trace so far as JSON Lines and forgets it, so that a long
    /// run streams its trace in bounded memory (`btc run --trace` calls this
    /// after every tick).
    pub fn drain_trace(&mut self, out: &mut dyn std::io::Write) -> std::io::Result<()> {
        let items = std::mem::take(&mut self.trace);
        let mut line = Vec::new();
        for t in &items {
            line.clear();
            serde_json::to_writer(&mut line, &self.trace_line(t))?;
            line.push(b'\n');
            out.write_all(&line)?;
        }
        self.trace = items;
        self.trace.clear();
        Ok(())
    }

    fn trace_line(&self, t: &TraceItem) -> serde_json::Value {
        match t {
            TraceItem::Status {
                tick,
                node,
                from,
                to,
            } => {
                let m = &self.meta[*node as usize];
                serde_json::json!({
                    "tick": tick, "node": node, "id": m.id, "name": m.name,
                    "from": from.name(), "to": to.name(),
                })
            }
            TraceItem::StepStarted { tick, step } => serde_json::json!({
                "tick": tick, "event": "step_started", "step": step + 1,
                "action": self.step_label(*step as usize),
            }),
            TraceItem::StepFinished { tick, step } => serde_json::json!({
                "tick": tick, "event": "step_finished", "step": step + 1,
                "action": self.step_label(*step as usize),
            }),
            TraceItem::Fault { tick, fault, ended } => {
                let f = &self.faults[*fault];
                serde_json::json!({
                    "tick": tick, "event": if *ended { "fault_ended" } else { "fault_triggered" },
                    "fault": f.spec.label(), "kind": f.spec.kind.name(),
                })
            }
            TraceItem::Record(k) => {
                let mut v = serde_json::to_value(&self.records[*k]).unwrap_or_default();
                if let Some(o) = v.as_object_mut() {
                    o.insert("event".into(), "fault_record".into());
                }
                v
            }
            TraceItem::Command { tick, seq, node } => serde_json::json!({
                "tick": tick, "event": "command", "seq": seq, "node": node,
                "command": self.meta[*node as usize].id,
            }),
        }
    }
}
