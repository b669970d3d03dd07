//! Trial files and fault scenarios written to break their readers:
//! nesting ten times past the limit, read on a small stack.

use btc_agent::faults::Scenario;
use btc_agent::trial::{self, yaml::MAX_DEPTH};
use btc_pddl::diagnostic::codes;
use btc_testkit::hostile::on_small_stack;

#[test]
fn nesting_ten_times_the_limit_is_refused_on_a_small_stack() {
    let depth = 10 * MAX_DEPTH;
    let block: String = (0..depth)
        .map(|i| format!("{}k{i}:\n", "  ".repeat(i)))
        .collect::<String>()
        + &"  ".repeat(depth)
        + "x\n";
    for text in [
        format!("a: {}{}", "[".repeat(depth), "]".repeat(depth)),
        format!("a: {}1{}", "{b: ".repeat(depth), "}".repeat(depth)),
        block,
    ] {
        let (t, diags) = on_small_stack(move || trial::read(&text, 0));
        assert!(t.is_none(), "a trial too deep to read");
        assert_eq!(diags.len(), 1, "{diags:#?}");
        assert_eq!(diags[0].code, codes::TRIAL_SYNTAX.id);
    }
}

#[test]
fn scenarios_ten_times_the_limit_are_refused_on_a_small_stack() {
    let depth = 10 * btc_pddl::limits::MAX_NESTING;
    for text in [
        format!("x = {}{}", "[".repeat(depth), "]".repeat(depth)),
        format!("x = {}1{}", "{ a = ".repeat(depth), " }".repeat(depth)),
        (0..depth)
            .map(|i| format!("t{i}"))
            .collect::<Vec<_>>()
            .join(".")
            + " = 1",
    ] {
        let r = on_small_stack(move || Scenario::parse(&text).map(|_| ()));
        assert_eq!(r.expect_err("not a scenario").code, codes::X_SCENARIO);
    }
}
