//! Trial files written to break the reader: nesting ten times past the
//! limit, as flow and as block collections, read on a small stack.

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
