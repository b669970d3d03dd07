//! The observers btc registers on an engine: a log of events kept in
//! memory (tests, the library's step events) and the JSON Lines trace of
//! `btc run --trace`. The Groot2 replay is `crate::btlog::BtlogRecorder`.

use crate::engine::{Observer, RunView, TickEvent};
use serde_json::{json, Value as Json};

/// Every event, kept in order.
#[derive(Debug, Default)]
pub struct EventLog {
    pub events: Vec<TickEvent>,
}

impl Observer for EventLog {
    fn observe(&mut self, event: &TickEvent, _: &RunView<'_>) {
        self.events.push(event.clone());
    }
}

impl EventLog {
    /// The plan's step starts and ends, in order: `(tick, started, step)`
    /// with the step 0-based.
    pub fn step_events(&self) -> impl Iterator<Item = (u64, bool, u32)> + '_ {
        self.events.iter().filter_map(|e| match *e {
            TickEvent::StepStarted { tick, step } => Some((tick, true, step)),
            TickEvent::StepFinished { tick, step } => Some((tick, false, step)),
            _ => None,
        })
    }
}

/// The trace as JSON Lines, a line an event. The lines wait in a buffer
/// until [`JsonlTrace::drain`] writes them out, so that a long run can
/// stream its trace in bounded memory.
#[derive(Debug, Default)]
pub struct JsonlTrace {
    buf: Vec<u8>,
}

impl Observer for JsonlTrace {
    fn observe(&mut self, event: &TickEvent, run: &RunView<'_>) {
        // Writing a JSON value into a Vec cannot fail.
        let _ = serde_json::to_writer(&mut self.buf, &line(event, run));
        self.buf.push(b'\n');
    }
}

impl JsonlTrace {
    /// Writes the lines so far and forgets them.
    pub fn drain(&mut self, out: &mut dyn std::io::Write) -> std::io::Result<()> {
        out.write_all(&self.buf)?;
        self.buf.clear();
        Ok(())
    }

    /// The lines not yet drained.
    pub fn text(&self) -> &str {
        // Only serde_json's output (UTF-8) goes into the buffer.
        std::str::from_utf8(&self.buf).unwrap_or_default()
    }

    pub fn into_text(self) -> String {
        String::from_utf8(self.buf).unwrap_or_default()
    }
}

/// One line of the trace.
pub fn line(event: &TickEvent, run: &RunView<'_>) -> Json {
    match *event {
        TickEvent::Status {
            tick,
            node,
            from,
            to,
        } => {
            let m = &run.meta[node as usize];
            json!({
                "tick": tick, "node": node, "id": m.id, "name": m.name,
                "from": from.name(), "to": to.name(),
            })
        }
        TickEvent::StepStarted { tick, step } => json!({
            "tick": tick, "event": "step_started", "step": step + 1,
            "action": run.step_label(step),
        }),
        TickEvent::StepFinished { tick, step } => json!({
            "tick": tick, "event": "step_finished", "step": step + 1,
            "action": run.step_label(step),
        }),
        TickEvent::Fault { tick, fault, ended } => {
            let (label, kind) = run.fault(fault).unwrap_or_default();
            json!({
                "tick": tick, "event": if ended { "fault_ended" } else { "fault_triggered" },
                "fault": label, "kind": kind,
            })
        }
        TickEvent::Record(k) => {
            let mut v = run
                .record(k)
                .and_then(|r| serde_json::to_value(r).ok())
                .unwrap_or_default();
            if let Some(o) = v.as_object_mut() {
                o.insert("event".into(), "fault_record".into());
            }
            v
        }
        TickEvent::Command { tick, seq, node } => json!({
            "tick": tick, "event": "command", "seq": seq, "node": node,
            "command": run.meta[node as usize].id,
        }),
    }
}
