//! A timed plan with concurrent steps compiled in order: plain `steps` runs
//! the steps one after another in start-time order, which keeps every
//! "ends before it starts" of the plan but none of its concurrency. That is
//! a choice the user should make knowingly, so it is a warning (L011) with
//! `steps scheduled` as the hint, never a silent approximation.

use crate::db::{parsed_rules, typed_plan, CompileJob, Db};
use crate::rules::ast::{Item, StepsMode, Template};
use btc_pddl::diagnostic::{codes, Diagnostic};
use btc_pddl::plan::PlanStep;
use btc_pddl::validate::DEFAULT_EPSILON;

/// L011 at the first step that starts before an earlier step has ended,
/// when the rules file's plan runs its steps in order.
#[salsa::tracked(returns(ref))]
pub fn in_order_diagnostics(db: &dyn Db, job: CompileJob) -> Vec<Diagnostic> {
    if !runs_in_order(db, job) {
        return Vec::new();
    }
    let plan = &typed_plan(db, job).plan;
    first_overlap(&plan.steps)
        .map(|(earlier, later)| {
            let (e, l) = (&plan.steps[earlier], &plan.steps[later]);
            Diagnostic::warning(
                codes::PLAN_CONCURRENT_IN_ORDER,
                l.span,
                format!(
                    "`{}` starts at {} while `{}` (line {}) runs until {}: the plan runs them at the same time, but `steps` runs its steps one after another",
                    call_text(l),
                    btc_ir::format_float(l.time.unwrap_or(0.0)),
                    call_text(e),
                    e.line,
                    btc_ir::format_float(end(e)),
                ),
            )
            .with_hint("write `plan { steps scheduled }` to run the steps on the plan's schedule, concurrent steps concurrently")
        })
        .into_iter()
        .collect()
}

/// A step as the plan writes it: `(move r2d2 a b)`.
fn call_text(s: &PlanStep) -> String {
    let mut t = format!("({}", s.call.action);
    for a in &s.call.args {
        t.push(' ');
        t.push_str(a);
    }
    t.push(')');
    t
}

fn end(s: &PlanStep) -> f64 {
    s.time.unwrap_or(0.0) + s.duration.unwrap_or(0.0)
}

/// Whether the job's plan template is missing or arranges the steps with
/// plain `steps` only (`parallel`, `backchained` and `scheduled` say how
/// they order the plan themselves).
fn runs_in_order(db: &dyn Db, job: CompileJob) -> bool {
    let rules = job.rules(db);
    let template = parsed_rules(db, rules)
        .items
        .iter()
        .find_map(|n| match &*n.item {
            Item::Plan { body, .. } => Some(body.clone()),
            _ => None,
        });
    let Some(body) = template else {
        return true;
    };
    let mut in_order = false;
    let mut other = false;
    Template::walk_all(&body, &mut |t| {
        if let Template::Steps { mode, .. } = t {
            match mode {
                StepsMode::InOrder => in_order = true,
                _ => other = true,
            }
        }
    });
    in_order && !other
}

/// The first pair (earlier, later) of timed steps where the later starts
/// before the earlier ends (by more than the happening tolerance). The
/// steps are in start-time order, so the running maximum of ends suffices.
fn first_overlap(steps: &[PlanStep]) -> Option<(usize, usize)> {
    let tol = DEFAULT_EPSILON / 10.0;
    let mut latest: Option<usize> = None;
    for (j, s) in steps.iter().enumerate() {
        let start = s.time?;
        if let Some(i) = latest {
            if start < end(&steps[i]) - tol {
                return Some((i, j));
            }
        }
        if latest.is_none_or(|i| end(s) > end(&steps[i])) {
            latest = Some(j);
        }
    }
    None
}
