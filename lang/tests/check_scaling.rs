//! The shape of `btc check`'s cost (issue #14): on a domain of N actions
//! with one rule per action (`btc_testkit::scale`), plus a few rules whose
//! patterns match whole families of actions, the number of comparisons of
//! a rule's name with an action's grows linearly with N. Counted, not
//! timed: wall-clock tests are noisy; `cargo bench -p btc-lang --bench
//! scaling` has the times.

use btc_lang::db::{rules_diagnostics, Database};
use btc_lang::rules::matching::name_comparisons;

/// Comparisons a check from scratch makes, and its diagnostics' codes.
fn check(n: usize) -> (u64, Vec<&'static str>) {
    let mut rules = btc_testkit::scale::rules(n, "domain.pddl");
    // Family rules: each is compared with a quarter of the actions.
    rules.push_str("rule (move-{k}-fast ?r ?a ?a) => skip\n");
    rules
        .push_str("rule (pick-{k}-part ?r ?p ?l) where ?r - tool { Grasp(robot: ?r, part: ?p) }\n");
    let mut db = Database::new();
    db.set_file("scale/domain.pddl", btc_testkit::scale::domain(n));
    let f = db.set_file("scale/rules.btrules", rules);
    let before = name_comparisons();
    let codes = rules_diagnostics(&db, f).iter().map(|d| d.code).collect();
    (name_comparisons() - before, codes)
}

#[test]
fn name_comparisons_grow_linearly() {
    let (c50, codes) = check(50);
    // The family rules: a skip that changes nothing is fine; a robot is
    // never a tool (R041).
    assert_eq!(codes, ["R041"], "{codes:?}");
    let (c500, _) = check(500);
    let (c5000, _) = check(5000);
    println!("name comparisons: 50 -> {c50}, 500 -> {c500}, 5000 -> {c5000}");
    for (small, big) in [(c50, c500), (c500, c5000)] {
        assert!(
            big <= small * 12,
            "tenfold rules made {big} comparisons from {small}: more than linear"
        );
    }
    // A handful per rule, not one per rule and action.
    assert!(c5000 <= 5 * 5000, "{c5000}");
}

/// Finding the actions a literal rule name names is a lookup: the index
/// used to scan every action after the first of that name, which made a
/// file of one rule per action quadratic (5,000 rules: 15x the time of
/// 500) while the comparison count above stayed linear. The bound is
/// loose: on this test's data 500 -> 5,000 costs 17-38x even when linear
/// (the larger domain falls out of the caches); the scan cost 107-361x.
#[test]
fn literal_names_are_looked_up_not_scanned() {
    use btc_lang::rules::actions::ActionIndex;
    use btc_lang::rules::ast::NamePart;
    use btc_lang::rules::name::Key;
    use btc_pddl::source::Span;
    btc_testkit::hostile::assert_linear(
        "matching every action's own name",
        500,
        60.0,
        |n| {
            let text = btc_testkit::scale::domain(n);
            let unit = btc_pddl::pipeline::domain_unit_from(&text, 0);
            let domain = unit.domain.expect("the scale domain parses");
            let index = ActionIndex::new(&domain);
            (domain, index)
        },
        |(domain, index)| {
            for a in &domain.actions {
                let parts = [NamePart::Lit {
                    text: a.name.name.to_string(),
                    key: Key::of_pddl(&a.name.name),
                    span: Span::new(0, 0, 0),
                }];
                assert_eq!(index.matches(&parts, domain).len(), 1);
            }
        },
    );
}
