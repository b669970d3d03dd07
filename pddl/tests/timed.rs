//! Timed plans (`fixtures/timed/`): each plan's first diagnostic has the
//! code its case calls for, says when and which step, and the separation
//! tolerance and plans without times behave as documented.

use btc_pddl::diagnostic::Diagnostic;
use btc_pddl::pipeline::{domain_unit, plan_unit, problem_unit, validate_units_with};
use btc_pddl::source::Sources;
use std::path::{Path, PathBuf};

fn timed() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/timed")
}

/// The diagnostics of validating `plan` (text) on the factory domain.
fn validate(plan: &str, epsilon: f64) -> (bool, Vec<Diagnostic>) {
    let mut sources = Sources::new();
    let read = |f: &str| std::fs::read_to_string(timed().join(f)).unwrap();
    let d = sources.add("domain.pddl".to_string(), read("domain.pddl"));
    let p = sources.add("p1.pddl".to_string(), read("p1.pddl"));
    let l = sources.add("plan".to_string(), plan.to_string());
    let du = domain_unit(&sources, d);
    let pu = problem_unit(&sources, p, &du);
    let lu = plan_unit(&sources, l, &du, &pu);
    assert!(lu.diagnostics.is_empty(), "{:?}", lu.diagnostics);
    let v = validate_units_with(&du, &pu, &lu, epsilon).expect("inputs without errors");
    (v.valid, v.diagnostics)
}

fn fixture(name: &str) -> String {
    std::fs::read_to_string(timed().join(name)).unwrap()
}

#[test]
fn each_timed_fixture_fails_with_its_code_or_is_valid() {
    let expected = [
        ("p1.valid-concurrent.tplan", None),
        ("p1.valid-inspect-then-transport.tplan", None),
        ("p1.valid-lines-out-of-order.tplan", None),
        ("p1.valid-recharge.tplan", None),
        (
            "p1.bt-example-early-transport.tplan",
            Some(("V001", "t=1.000: step 4")),
        ),
        (
            "p1.over-all-broken.tplan",
            Some(("V007", "broken at t=1.000 after the start of step 3")),
        ),
        (
            "p1.over-all-assembly.tplan",
            Some(("V007", "broken at t=12.000 after the start of step 7")),
        ),
        (
            "p1.same-time-mutex.tplan",
            Some(("V006", "t=0.000: step 1")),
        ),
        (
            "p1.no-separation.tplan",
            Some(("V006", "its end adds `(robot_available r2d2)`")),
        ),
        (
            "p1.wrong-duration.tplan",
            Some(("V005", "states a duration of 3")),
        ),
        (
            "p1.wrong-fluent-duration.tplan",
            Some(("V005", "makes it 3 here")),
        ),
        (
            "p1.goal-missed.tplan",
            Some(("V002", "`(car_assembled car_1)`")),
        ),
    ];
    let on_disk = btc_testkit::sorted_entries(&timed())
        .into_iter()
        .filter(|p| p.extension().is_some_and(|e| e == "tplan"))
        .count();
    assert_eq!(
        on_disk,
        expected.len(),
        "a fixture without an expectation here"
    );
    for (name, want) in expected {
        let (valid, diags) = validate(&fixture(name), 0.001);
        match want {
            None => assert!(valid && diags.is_empty(), "{name}: {diags:?}"),
            Some((code, says)) => {
                assert!(!valid, "{name} is valid");
                let d = &diags[0];
                assert_eq!(d.code, code, "{name}: {}", d.message);
                assert!(d.message.contains(says), "{name}: {}", d.message);
            }
        }
    }
}

/// Events less than a tenth of the tolerance apart are one happening: with
/// a tolerance of 0.1, steps 0.001 after what they need collide with it.
#[test]
fn a_larger_tolerance_merges_close_events() {
    let plan = fixture("p1.valid-concurrent.tplan");
    assert!(validate(&plan, 0.001).0);
    let (valid, diags) = validate(&plan, 0.1);
    assert!(!valid);
    assert_eq!(diags[0].code, "V006", "{}", diags[0].message);
}

/// A durative domain's plan without times is replayed one step after
/// another, with a warning that says so.
#[test]
fn an_untimed_plan_of_a_durative_domain_warns_and_replays_in_sequence() {
    let untimed: String = fixture("p1.valid-concurrent.tplan")
        .lines()
        .filter(|l| !l.starts_with(';'))
        .map(|l| {
            let (o, c) = (l.find('(').unwrap(), l.find(')').unwrap());
            format!("{}\n", &l[o..=c])
        })
        .collect();
    let (valid, diags) = validate(&untimed, 0.001);
    assert!(valid);
    assert_eq!(diags.len(), 1);
    assert_eq!(diags[0].code, "V008");
    assert!(diags[0].message.contains("one after another"));
    // The early transport, fine in sequence, is caught only with times.
    let early = fixture("p1.bt-example-early-transport.tplan");
    assert!(!validate(&early, 0.001).0);
}
