//! Steps that write the same call share it, and typing does each call's
//! work once, without changing what a step reads as or reports.

use btc_pddl::diagnostic::codes;
use btc_pddl::pipeline::{domain_unit, plan_unit, problem_unit, PlanUnit};
use btc_pddl::source::Sources;
use std::sync::Arc;

const DOMAIN: &str = include_str!("../../examples/p3_assembler/domain.pddl");
const PROBLEM: &str = include_str!("../../examples/p3_assembler/problem.pddl");
const PLAN: &str = include_str!("fixtures/plan_calls/plan.tplan");

fn unit() -> (Sources, PlanUnit) {
    let mut sources = Sources::new();
    let d = sources.add("domain.pddl", DOMAIN);
    let p = sources.add("problem.pddl", PROBLEM);
    let l = sources.add("plan.tplan", PLAN);
    let du = domain_unit(&sources, d);
    let pu = problem_unit(&sources, p, &du);
    let lu = plan_unit(&sources, l, &du, &pu);
    (sources, lu)
}

#[test]
fn a_call_written_again_is_shared_and_placed_where_each_step_writes_it() {
    let (_, lu) = unit();
    let s = &lu.plan.steps;
    assert!(Arc::ptr_eq(&s[0].call, &s[3].call));
    assert!(Arc::ptr_eq(&s[4].call, &s[6].call));
    // Other spacing or case is another call, read to the same names.
    assert!(!Arc::ptr_eq(&s[0].call, &s[5].call));
    assert_eq!(s[0].action_name(), s[5].action_name());
    assert_eq!(s[0].call.args, s[5].call.args);
    for step in s {
        let action = step.action();
        assert_eq!(
            PLAN[action.span.range()].to_ascii_lowercase(),
            action.name.as_str()
        );
        for arg in step.args() {
            assert_eq!(&PLAN[arg.span.range()], arg.name.as_str());
        }
    }
}

#[test]
fn typing_shares_a_call_s_objects_and_reports_a_bad_call_at_each_step() {
    let (sources, lu) = unit();
    let g = &lu.steps;
    // Steps 5 and 7 name an object the problem lacks: each is reported.
    let unknown: Vec<_> = lu
        .diagnostics
        .iter()
        .filter(|d| d.code == codes::PLAN_UNKNOWN_OBJECT.id)
        .map(|d| sources.get(d.span.file).line_col(d.span.start).0)
        .collect();
    assert_eq!(unknown, [6, 8]);
    assert_eq!(
        g.iter().map(|g| g.step).collect::<Vec<_>>(),
        [0, 1, 2, 3, 5]
    );
    assert!(Arc::ptr_eq(&g[0].args, &g[3].args));
    assert_eq!(g[0].args, g[4].args);
    assert_ne!(g[0].args, g[2].args);
}
