//! Any bytes as a PDDL file: decode, parse, check (a problem against the
//! fixed ARIAC domain), render every diagnostic. Nothing may panic, overflow
//! the stack, hang or blow up memory.
#![no_main]

use std::sync::OnceLock;

use btc_pddl::pipeline::{domain_unit, DomainUnit};
use btc_pddl::render::to_terminal;
use btc_pddl::source::{decode, Sources};
use btc_pddl::{self as pddl, Document};
use libfuzzer_sys::fuzz_target;

const DOMAIN_PATH: &str = "examples/ariac/domain.pddl";
const DOMAIN: &str = include_str!("../../examples/ariac/domain.pddl");

/// The ARIAC domain, parsed and checked once as file 0.
fn ariac() -> &'static DomainUnit {
    static UNIT: OnceLock<DomainUnit> = OnceLock::new();
    UNIT.get_or_init(|| {
        let mut sources = Sources::new();
        let file = sources.add(DOMAIN_PATH, DOMAIN);
        let unit = domain_unit(&sources, file);
        assert!(unit.domain.is_some(), "the ARIAC domain must parse");
        unit
    })
}

fuzz_target!(|data: &[u8]| {
    let (text, _problem) = decode(data);
    let domain = ariac();
    let mut sources = Sources::new();
    let domain_file = sources.add(DOMAIN_PATH, DOMAIN);
    debug_assert_eq!(domain_file, domain.file);
    let file = sources.add("fuzz.pddl", text);

    let (doc, mut diags) = pddl::parse_document(sources.text(file), file);
    match &doc {
        Some(Document::Domain(d)) => {
            let (_index, more) = pddl::check_domain(d);
            diags.extend(more);
        }
        Some(Document::Problem(p)) => {
            let d = domain.domain.as_ref().expect("ARIAC domain parsed");
            let (_index, more) = pddl::check_problem(p, d, &domain.index);
            diags.extend(more);
        }
        None => {}
    }
    let _ = to_terminal(&diags, &sources, false);
});
