//! Any bytes as a plan for the fixed ARIAC domain and problem: decode, parse,
//! type, validate, render every diagnostic. Nothing may panic, overflow the
//! stack, hang or blow up memory.
#![no_main]

use std::sync::OnceLock;

use btc_pddl::pipeline::{
    domain_unit, plan_unit, problem_unit, validate_units, DomainUnit, ProblemUnit,
};
use btc_pddl::render::to_terminal;
use btc_pddl::source::{decode, Sources};
use libfuzzer_sys::fuzz_target;

const DOMAIN_PATH: &str = "examples/ariac/domain.pddl";
const DOMAIN: &str = include_str!("../../examples/ariac/domain.pddl");
const PROBLEM_PATH: &str = "examples/ariac/problem.pddl";
const PROBLEM: &str = include_str!("../../examples/ariac/problem.pddl");

/// Domain (file 0) and problem (file 1), parsed and checked once.
fn ariac() -> &'static (DomainUnit, ProblemUnit) {
    static UNITS: OnceLock<(DomainUnit, ProblemUnit)> = OnceLock::new();
    UNITS.get_or_init(|| {
        let sources = base_sources();
        let domain = domain_unit(&sources, 0);
        let problem = problem_unit(&sources, 1, &domain);
        assert!(domain.domain.is_some() && problem.problem.is_some());
        (domain, problem)
    })
}

fn base_sources() -> Sources {
    let mut sources = Sources::new();
    sources.add(DOMAIN_PATH, DOMAIN);
    sources.add(PROBLEM_PATH, PROBLEM);
    sources
}

fuzz_target!(|data: &[u8]| {
    let (text, _problem) = decode(data);
    let (domain, problem) = ariac();
    let mut sources = base_sources();
    let file = sources.add("fuzz.plan", text);

    let plan = plan_unit(&sources, file, domain, problem);
    let mut diags = plan.diagnostics.clone();
    if let Some(v) = validate_units(domain, problem, &plan) {
        diags.extend(v.diagnostics);
    }
    let _ = to_terminal(&diags, &sources, false);
});
