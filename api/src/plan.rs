//! A plan as a value: steps of actions with their arguments (and times, for
//! a timed plan), and the cost when it is known. Read from any plan format
//! btc reads, made by btc's planner, written back in `sas_plan` form (or
//! the timed form for a timed plan).

use crate::diagnostic::{convert, Error};
use btc_pddl::source::Sources;
use serde::Serialize;
use std::fmt;

#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Step {
    /// The action's name, lower-cased as PDDL compares names.
    pub action: String,
    pub args: Vec<String>,
    /// Start time and duration, for a step of a timed plan.
    pub time: Option<f64>,
    pub duration: Option<f64>,
}

#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct Plan {
    pub steps: Vec<Step>,
    /// The plan's cost: the planner's, or the `; cost = N` a plan file
    /// states.
    pub cost: Option<f64>,
}

/// The path plan texts are reported under.
pub(crate) const PLAN_TEXT: &str = "<plan>";

impl Plan {
    /// Reads a plan in any format `btc compile` reads (sas_plan, timed,
    /// bare `action args` lines, FF's output).
    pub fn parse(text: &str) -> Result<Plan, Error> {
        let mut sources = Sources::new();
        let id = sources.add(PLAN_TEXT, text);
        let (plan, diags) = btc_pddl::plan::parse_plan(text, id);
        if btc_pddl::diagnostic::has_errors(&diags) {
            return Err(Error::new(convert(&diags, &sources)));
        }
        Ok(Plan::from_parsed(&plan))
    }

    pub(crate) fn from_parsed(plan: &btc_pddl::plan::parse::Plan) -> Plan {
        Plan {
            steps: plan
                .steps
                .iter()
                .map(|s| Step {
                    action: s.call.action.to_string(),
                    args: s.call.args.iter().map(ToString::to_string).collect(),
                    time: s.time,
                    duration: s.duration,
                })
                .collect(),
            cost: plan.stated_cost.as_ref().map(|c| c.value),
        }
    }

    /// The planner's plan, with the names of the domain and problem.
    pub(crate) fn from_planner(
        domain: &btc_pddl::ast::Domain,
        pix: &btc_pddl::check::ProblemIndex,
        plan: &btc_planner::Plan,
    ) -> Plan {
        Plan {
            steps: plan
                .steps
                .iter()
                .map(|s| Step {
                    action: domain.actions[s.action].name.name.to_string(),
                    args: s
                        .args
                        .iter()
                        .map(|&a| pix.object_names[a as usize].to_string())
                        .collect(),
                    time: None,
                    duration: None,
                })
                .collect(),
            cost: Some(plan.base_cost + plan.cost as f64),
        }
    }

    /// The plan as the compiler takes it, with its `sas_plan` text.
    pub(crate) fn written(&self) -> btc_pddl::plan::WrittenPlan {
        let mut w = btc_pddl::plan::PlanWriter::new();
        for s in &self.steps {
            w.step(&s.action, &s.args, s.time, s.duration);
        }
        if let Some(c) = self.cost {
            w.cost(c, None);
        }
        w.finish()
    }

    pub fn is_timed(&self) -> bool {
        self.steps.iter().any(|s| s.time.is_some())
    }
}

impl fmt::Display for Step {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if let Some(t) = self.time {
            write!(f, "{t:.3}: ")?;
        }
        write!(f, "({}", self.action)?;
        for a in &self.args {
            write!(f, " {a}")?;
        }
        f.write_str(")")?;
        if let Some(d) = self.duration {
            write!(f, " [{d:.3}]")?;
        }
        Ok(())
    }
}

impl fmt::Display for Plan {
    /// One step a line, then `; cost = N` when the cost is known: the
    /// `sas_plan` form (each line with its time for a timed plan), which
    /// [`Plan::parse`] reads back.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        for s in &self.steps {
            writeln!(f, "{s}")?;
        }
        if let Some(c) = self.cost {
            writeln!(f, "; cost = {c}")?;
        }
        Ok(())
    }
}
