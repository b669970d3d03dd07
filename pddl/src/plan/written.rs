//! A plan made as a value (by a planner, or by a program through btc's
//! API), with the text it reads as. The compiler takes the value as it is;
//! the text is the plan file btc would write for it (`sas_plan`, or the
//! timed form), which a diagnostic on the plan shows, and each step's span
//! points into it as if the text had been read.

use super::parse::{Plan, PlanFormat, StatedCost};
use super::step::{Call, PlanStep};
use crate::ast::{Name, SmolStr};
use crate::source::{FileId, Span};
use std::collections::HashMap;
use std::fmt::Write as _;
use std::sync::Arc;

/// A plan value and its text; [`WrittenPlan::plan`] places it in a file.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct WrittenPlan {
    text: String,
    steps: Vec<WrittenStep>,
    /// The stated cost and where its line's `cost` starts and ends.
    cost: Option<(f64, u32, u32)>,
}

#[derive(Clone, Debug, PartialEq)]
struct WrittenStep {
    call: Arc<Call>,
    time: Option<f64>,
    duration: Option<f64>,
    line: u32,
    start: u32,
    end: u32,
}

/// Writes a plan a step at a time.
#[derive(Default)]
pub struct PlanWriter {
    plan: WrittenPlan,
    /// Steps that make the same call share it, as read plans do.
    calls: HashMap<(SmolStr, Vec<SmolStr>), Arc<Call>>,
}

impl PlanWriter {
    pub fn new() -> PlanWriter {
        PlanWriter::default()
    }

    /// Appends the step `(action args...)`, with its start time and
    /// duration for a timed plan.
    pub fn step<S: AsRef<str>>(
        &mut self,
        action: &str,
        args: &[S],
        time: Option<f64>,
        duration: Option<f64>,
    ) -> &mut Self {
        let text = &mut self.plan.text;
        if let Some(t) = time {
            let _ = write!(text, "{t:.3}: ");
        }
        let start = text.len();
        let mut names = Vec::with_capacity(args.len());
        text.push('(');
        let action = name_at(text, action);
        for a in args {
            text.push(' ');
            names.push(name_at(text, a.as_ref()));
        }
        text.push(')');
        let end = text.len();
        if let Some(d) = duration {
            let _ = write!(text, " [{d:.3}]");
        }
        text.push('\n');
        let key = (
            action.name.clone(),
            names.iter().map(|n| n.name.clone()).collect(),
        );
        let whole = Span::new(0, start, end);
        let call = self
            .calls
            .entry(key)
            .or_insert_with(|| Arc::new(Call::new(action, names, whole)))
            .clone();
        let line = self.plan.steps.len() as u32 + 1;
        self.plan.steps.push(WrittenStep {
            call,
            time,
            duration,
            line,
            start: start as u32,
            end: end as u32,
        });
        self
    }

    /// Ends the plan with `; cost = VALUE (NOTE)`, as Fast Downward does.
    pub fn cost(&mut self, value: f64, note: Option<&str>) -> &mut Self {
        let text = &mut self.plan.text;
        text.push_str("; ");
        let start = text.len() as u32;
        let _ = write!(text, "cost = {value}");
        if let Some(note) = note {
            let _ = write!(text, " ({note})");
        }
        let end = text.len() as u32;
        text.push('\n');
        self.plan.cost = Some((value, start, end));
        self
    }

    /// The plan; a timed plan's steps in the order of their times (each
    /// keeping its line), as a read plan has them.
    pub fn finish(mut self) -> WrittenPlan {
        if self.plan.steps.iter().any(|s| s.time.is_some()) {
            self.plan
                .steps
                .sort_by(|a, b| a.time.unwrap_or(0.0).total_cmp(&b.time.unwrap_or(0.0)));
        }
        self.plan
    }
}

/// Writes a name (lower-cased, as plans are read) and returns it with its
/// place in the text.
fn name_at(text: &mut String, name: &str) -> Name {
    let start = text.len();
    text.extend(name.chars().flat_map(char::to_lowercase));
    Name {
        name: SmolStr::new(&text[start..]),
        span: Span::new(0, start, text.len()),
    }
}

impl WrittenPlan {
    /// The plan file's text.
    pub fn text(&self) -> &str {
        &self.text
    }

    pub fn len(&self) -> usize {
        self.steps.len()
    }

    pub fn is_empty(&self) -> bool {
        self.steps.is_empty()
    }

    /// The plan, its spans in `file` (which holds [`WrittenPlan::text`]).
    pub fn plan(&self, file: FileId) -> Plan {
        let timed = self.steps.iter().any(|s| s.time.is_some());
        Plan {
            format: match (self.steps.is_empty(), timed) {
                (true, _) => PlanFormat::Empty,
                (false, true) => PlanFormat::Timed,
                (false, false) => PlanFormat::SasPlan,
            },
            steps: self
                .steps
                .iter()
                .map(|s| PlanStep {
                    call: s.call.clone(),
                    time: s.time,
                    duration: s.duration,
                    line: s.line,
                    span: Span::new(file, s.start as usize, s.end as usize),
                })
                .collect(),
            stated_cost: self.cost.map(|(value, start, end)| StatedCost {
                value,
                span: Span::new(file, start as usize, end as usize),
            }),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::plan::parse_plan;

    /// A written plan is the plan its text reads as, spans and all.
    fn reads_back(w: &WrittenPlan) {
        let (read, diags) = parse_plan(w.text(), 7);
        assert!(diags.is_empty(), "{diags:?}\n{}", w.text());
        assert_eq!(w.plan(7), read, "\n{}", w.text());
    }

    #[test]
    fn a_sequential_plan_reads_back_as_written() {
        let mut w = PlanWriter::new();
        w.step("move", &["r1", "a", "b"], None, None)
            .step("Pick", &["r1", "Box_2"], None, None)
            .step("move", &["r1", "a", "b"], None, None)
            .step("noop", &[] as &[&str], None, None)
            .cost(4.0, Some("unit cost"));
        let w = w.finish();
        assert_eq!(
            w.text(),
            "(move r1 a b)\n(pick r1 box_2)\n(move r1 a b)\n(noop)\n; cost = 4 (unit cost)\n"
        );
        reads_back(&w);
        let p = w.plan(7);
        assert!(Arc::ptr_eq(&p.steps[0].call, &p.steps[2].call));
    }

    #[test]
    fn a_timed_plan_reads_back_as_written() {
        let mut w = PlanWriter::new();
        w.step("transport", &["r2d2", "wheel"], Some(5.001), Some(5.0))
            .step("move", &["r2d2", "a", "b"], Some(0.0), Some(5.0))
            .step("move", &["c3po", "a", "c"], Some(0.0), Some(4.5))
            .cost(3.0, None);
        let w = w.finish();
        assert!(w
            .text()
            .starts_with("5.001: (transport r2d2 wheel) [5.000]\n"));
        reads_back(&w);
        assert_eq!(w.plan(0).steps[2].line, 1);
    }

    #[test]
    fn no_steps_is_an_empty_plan() {
        let w = PlanWriter::new().finish();
        assert!(w.is_empty());
        assert_eq!(w.plan(0).format, PlanFormat::Empty);
    }
}
