//! The ARIAC example's world, which the runtime targets run trees and
//! fault scenarios against: parsed and checked once per process.

use btc_pddl::pipeline::{domain_unit, problem_unit, DomainUnit, ProblemUnit};
use btc_pddl::source::Sources;
use btc_pddl::state::World;
use std::sync::OnceLock;

const DOMAIN: &str = include_str!("../../../examples/ariac/domain.pddl");
const PROBLEM: &str = include_str!("../../../examples/ariac/problem.pddl");

pub fn units() -> &'static (DomainUnit, ProblemUnit) {
    static UNITS: OnceLock<(DomainUnit, ProblemUnit)> = OnceLock::new();
    UNITS.get_or_init(|| {
        let mut s = Sources::new();
        s.add("domain.pddl", DOMAIN);
        s.add("problem.pddl", PROBLEM);
        let d = domain_unit(&s, 0);
        let p = problem_unit(&s, 1, &d);
        (d, p)
    })
}

/// The world of the ARIAC problem, or `None` if it does not build.
pub fn world() -> Option<World> {
    let (d, p) = units();
    World::of_checked(d.domain.as_ref()?, &d.index, p.problem.as_ref()?, &p.index).ok()
}
