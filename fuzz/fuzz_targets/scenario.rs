//! Any bytes as a fault scenario (`btc run --faults`): parse the TOML, add
//! its faults to an engine over the ARIAC world, run a few ticks.
#![no_main]

use btc_pddl::pipeline::{domain_unit, problem_unit, DomainUnit, ProblemUnit};
use btc_pddl::source::{decode, Sources};
use btc_runtime::{Engine, Kb, Options, Scenario};
use libfuzzer_sys::fuzz_target;
use std::sync::OnceLock;

const DOMAIN: &str = include_str!("../../examples/ariac/domain.pddl");
const PROBLEM: &str = include_str!("../../examples/ariac/problem.pddl");
const TREE: &str = r#"<root BTCPP_format="4" main_tree_to_execute="M"><BehaviorTree ID="M"><Sequence><Sleep msec="50"/><AlwaysSuccess/></Sequence></BehaviorTree></root>"#;

fn ariac() -> &'static (DomainUnit, ProblemUnit) {
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

fuzz_target!(|data: &[u8]| {
    let (text, _) = decode(data);
    let Ok(s) = Scenario::parse(&text) else {
        return;
    };
    let (d, p) = ariac();
    let Ok(world) = btc_pddl::state::World::of_checked(d.domain.as_ref().unwrap(), &d.index, p.problem.as_ref().unwrap(), &p.index) else {
        return;
    };
    let kb = Kb::new(&world);
    let (doc, _) = btc_runtime::load_tree(TREE).expect("the fixed tree loads");
    let mut e = Engine::build(&doc, Some(kb), Options::default()).expect("builds");
    if e.add_faults(&s).is_ok() {
        e.run(100, |_| {});
    }
});
