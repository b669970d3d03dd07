//! What a newcomer meets in the first hour with btc (issue #28): each
//! message says what to do, once, about the right file.

mod support;
use std::path::Path;
use support::{btc_in, exits, json_of};

fn fixture(dir: &str) -> std::path::PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/fixtures")
        .join(dir)
}

/// An undeclared predicate (not a typo of a declared one) is reported once,
/// on the domain, with the declaration its use implies as a fix; applying
/// the fix makes the domain check clean of it. The problem beside it is not
/// blamed.
#[test]
fn an_undeclared_predicate_gets_its_declaration_as_a_fix() {
    let dir = fixture("diagnostics/P102");
    let out = btc_in(
        &dir,
        &["pddl", "domain.pddl", "problem.pddl", "--format", "json"],
    );
    exits(&out, 1, "btc pddl");
    let v = json_of(&out);
    let p102: Vec<&serde_json::Value> = v["diagnostics"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|d| d["code"] == "P102")
        .collect();
    assert_eq!(p102.len(), 2, "once per use: {p102:#?}");
    assert!(p102.iter().all(|d| d["file"] == "domain.pddl"));
    let summaries = v["summaries"].as_array().unwrap();
    assert!(
        summaries[1]
            .as_str()
            .unwrap()
            .ends_with("0 errors, 0 warnings"),
        "{summaries:?}"
    );
    let flipped = p102
        .iter()
        .find(|d| d["message"].as_str().unwrap().contains("`flipped`"))
        .unwrap();
    let fix = &flipped["fixes"][0];
    assert_eq!(
        fix["replacement"], "\n    (flipped ?p - part ?r - robot)",
        "{fix}"
    );
    let text = std::fs::read_to_string(dir.join("domain.pddl")).unwrap();
    let (start, end) = (
        fix["start"]["offset"].as_u64().unwrap() as usize,
        fix["end"]["offset"].as_u64().unwrap() as usize,
    );
    let fixed = format!(
        "{}{}{}",
        &text[..start],
        fix["replacement"].as_str().unwrap(),
        &text[end..]
    );
    let tmp = tempfile::tempdir().unwrap();
    std::fs::write(tmp.path().join("domain.pddl"), fixed).unwrap();
    let after = json_of(&btc_in(
        tmp.path(),
        &["pddl", "domain.pddl", "--format", "json"],
    ));
    let left: Vec<&str> = after["diagnostics"]
        .as_array()
        .unwrap()
        .iter()
        .map(|d| d["message"].as_str().unwrap())
        .collect();
    assert_eq!(left, ["predicate `redy` is not declared in the domain"]);
}
