//! Any bytes as a `.btrules` file next to the ARIAC domain and problem:
//! parse, check every item and the file (through the salsa database, as
//! `btc check` does), format, render every diagnostic; and check that
//! each item's quick parse (no error messages) agrees with its rich one.
#![no_main]

use btc_lang::db::{checked_domain, rules_diagnostics, Database};
use btc_pddl::render::to_terminal;
use btc_pddl::source::decode;
use libfuzzer_sys::fuzz_target;

const DOMAIN: &str = include_str!("../../examples/ariac/domain.pddl");
const PROBLEM: &str = include_str!("../../examples/ariac/problem.pddl");

fuzz_target!(|data: &[u8]| {
    let (text, _) = decode(data);
    let mut db = Database::new();
    let d = db.set_file("/f/domain.pddl", DOMAIN.to_owned());
    db.set_file("/f/problem.pddl", PROBLEM.to_owned());
    let f = db.set_file("/f/rules.btrules", text.clone());
    let mut diags = rules_diagnostics(&db, f).clone();
    diags.extend(checked_domain(&db, d).diagnostics.iter().cloned());
    let _ = btc_lang::rules::fmt::format(&text);
    let _ = to_terminal(&diags, &db.sources(), false);
    if let Some(d) = btc_lang::rules::parse::quick_and_rich_disagree(&text) {
        panic!("the quick and the rich parse disagree: {d}");
    }
});
