//! Any bytes as a tree file for `btc run --tree` (BT.CPP XML or JSON IR):
//! load, build the engine against the ARIAC world, tick a bounded run.
#![no_main]

use btc_pddl::pipeline::{domain_unit, problem_unit, DomainUnit, ProblemUnit};
use btc_pddl::source::{decode, Sources};
use btc_runtime::{Engine, Kb, Options};
use libfuzzer_sys::fuzz_target;
use std::sync::OnceLock;

const DOMAIN: &str = include_str!("../../examples/ariac/domain.pddl");
const PROBLEM: &str = include_str!("../../examples/ariac/problem.pddl");

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
    let Ok((doc, _)) = btc_runtime::load_tree(&text) else {
        return;
    };
    let (d, p) = ariac();
    let Ok(world) = btc_pddl::state::World::of_checked(d.domain.as_ref().unwrap(), &d.index, p.problem.as_ref().unwrap(), &p.index) else {
        return;
    };
    let kb = Kb::new(&world);
    let opts = Options { trace: true, ..Options::default() };
    if let Ok(mut e) = Engine::build(&doc, Some(kb), opts) {
        e.run(200, |e| {
            let _ = e.drain_trace(&mut std::io::sink());
        });
        let _ = e.summary(btc_runtime::Status::Running);
    }
});
