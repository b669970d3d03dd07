//! `btc init` and `btc stubs`: a first rules file in one command, and the
//! rules a file lacks added to it.
//!
//! On every corpus domain, `btc init` writes rules that check clean and
//! compile every valid plan of the domain; `btc stubs` adds exactly the
//! uncovered actions to an existing file and keeps its bytes.

mod support;

use btc_testkit::CorpusCase;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use support::{btc, btc_in, exits, json_of};

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// The rules file's own diagnostics in `btc check --format json`'s answer
/// (those of the corpus's PDDL files are not the rules' business).
fn rules_diagnostics(check: &serde_json::Value, rules: &Path) -> Vec<String> {
    let rules = rules.canonicalize().unwrap();
    check["diagnostics"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|d| {
            Path::new(d["file"].as_str().unwrap())
                .canonicalize()
                .is_ok_and(|f| f == rules)
        })
        .map(|d| format!("{}: {}", d["code"], d["message"]))
        .collect()
}

#[test]
fn init_writes_rules_that_check_clean_and_compile_every_valid_plan_of_each_corpus_domain() {
    let Some(cases) = btc_testkit::corpus_cases() else {
        return;
    };
    let tmp = tempfile::tempdir().unwrap();
    // Each domain file once, with the problems that use it.
    let mut domains: BTreeMap<PathBuf, Vec<&CorpusCase>> = BTreeMap::new();
    for c in &cases {
        domains.entry(c.domain.clone()).or_default().push(c);
    }
    let (mut compiled, mut invalid) = (0, 0);
    for (k, (domain, cases)) in domains.iter().enumerate() {
        let rules = tmp.path().join(format!("d{k}")).join("rules.btrules");
        std::fs::create_dir_all(rules.parent().unwrap()).unwrap();
        let what = domain.display();
        exits(
            &btc(&["init", s(domain), "-o", s(&rules)]),
            0,
            &format!("init {what}"),
        );
        let check = btc(&["check", s(&rules), "--format", "json"]);
        exits(&check, 0, &format!("check of init {what}"));
        let own = rules_diagnostics(&json_of(&check), &rules);
        assert!(own.is_empty(), "init {what}: {own:?}");
        for case in cases {
            for plan in &case.plans {
                let valid = btc(&["validate", s(domain), s(&case.problem), s(plan)]);
                if !valid.status.success() {
                    invalid += 1;
                    continue;
                }
                let out = btc(&[
                    "compile",
                    s(&rules),
                    "--plan",
                    s(plan),
                    "--problem",
                    s(&case.problem),
                    "--domain",
                    s(domain),
                    "--emit",
                    "btcpp",
                ]);
                exits(
                    &out,
                    0,
                    &format!("compile {} with init {what}", plan.display()),
                );
                compiled += 1;
            }
        }
    }
    eprintln!(
        "{} domains, {compiled} plans compiled, {invalid} invalid plans left out",
        domains.len()
    );
    assert!(domains.len() >= 10 && compiled >= 20, "{compiled} plans");
}

/// A starter file names its domain and problem relative to itself, and the
/// one it would overwrite is left alone.
#[test]
fn init_names_files_relative_to_the_rules_and_never_overwrites() {
    let tmp = tempfile::tempdir().unwrap();
    let fixture = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/stubs");
    let rules = tmp.path().join("cafe.btrules");
    let out = btc(&[
        "init",
        s(&fixture.join("domain.pddl")),
        s(&fixture.join("problem.pddl")),
        "-o",
        s(&rules),
    ]);
    exits(&out, 0, "init with a problem");
    let text = std::fs::read_to_string(&rules).unwrap();
    for (line, file) in [("domain", "domain.pddl"), ("problem", "problem.pddl")] {
        let named = text
            .lines()
            .find_map(|l| l.strip_prefix(line).map(|r| r.trim().trim_matches('"')))
            .unwrap_or_else(|| panic!("no {line} line:\n{text}"));
        assert!(Path::new(named).is_relative(), "{named}");
        assert_eq!(
            tmp.path().join(named).canonicalize().unwrap(),
            fixture.join(file).canonicalize().unwrap()
        );
    }
    // The plan compiles and runs with the problem the file names.
    let run = btc_in(
        tmp.path(),
        &[
            "run",
            "cafe.btrules",
            "--plan",
            s(&fixture.join("plan.plan")),
        ],
    );
    exits(&run, 0, "run with the starter rules");
    // A second init refuses, and says what to do instead.
    std::fs::write(&rules, "mine").unwrap();
    let again = btc(&["init", s(&fixture.join("domain.pddl")), "-o", s(&rules)]);
    exits(&again, 2, "init over an existing file");
    assert!(String::from_utf8_lossy(&again.stderr).contains("btc stubs"));
    assert_eq!(std::fs::read_to_string(&rules).unwrap(), "mine");
}

/// `btc stubs` adds a rule for each uncovered action (`pick-up`,
/// `put-down`), declares only the leaf that is missing (`PickUp`), keeps
/// the file's bytes (its layout, its line endings, a last line without a
/// newline), and then has nothing left to add.
#[test]
fn stubs_add_exactly_the_uncovered_actions_and_keep_the_file() {
    let fixture = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/stubs");
    let original = std::fs::read_to_string(fixture.join("partial.btrules")).unwrap();
    let crlf = original.replace('\n', "\r\n");
    let variants = [
        ("as written", original.clone()),
        ("CRLF, no last newline", crlf.trim_end().to_owned()),
    ];
    for (what, before) in variants {
        let tmp = tempfile::tempdir().unwrap();
        for f in ["domain.pddl", "problem.pddl", "plan.plan"] {
            std::fs::copy(fixture.join(f), tmp.path().join(f)).unwrap();
        }
        let rules = tmp.path().join("rules.btrules");
        std::fs::write(&rules, &before).unwrap();
        let check = json_of(&btc(&["check", s(&rules), "--format", "json"]));
        let mut codes: Vec<&str> = check["diagnostics"]
            .as_array()
            .unwrap()
            .iter()
            .map(|d| d["code"].as_str().unwrap())
            .collect();
        codes.sort();
        assert_eq!(codes, ["R012", "R012", "R014"], "{what}: before");
        let out = btc(&["stubs", s(&rules)]);
        exits(&out, 0, &format!("stubs, {what}"));
        let said = String::from_utf8_lossy(&out.stderr);
        assert!(said.contains("2 rule stubs (pick-up, put-down)"), "{said}");
        let after = std::fs::read_to_string(&rules).unwrap();
        let added = after
            .strip_prefix(before.as_str())
            .unwrap_or_else(|| panic!("{what}: the file's bytes changed:\n{after}"));
        assert_eq!(added.matches("rule (").count(), 2, "{what}: {added}");
        assert!(added.contains("rule (pick-up ?r ?c ?p)"), "{added}");
        assert!(added.contains("rule (put-down ?r ?c ?p)"), "{added}");
        assert!(
            added.contains("action PickUp(r: robot, c: cup, p: place)"),
            "{added}"
        );
        assert!(!added.contains("action PutDown"), "{added}");
        let newline_kept = if before.contains("\r\n") {
            added.replace("\r\n", "").contains('\n')
        } else {
            added.contains('\r')
        };
        assert!(!newline_kept, "{what}: mixed line endings: {added:?}");
        // Clean now, compiles the plan, and nothing more to add.
        let check = btc(&["check", s(&rules), "--format", "json"]);
        assert_eq!(
            json_of(&check)["diagnostics"],
            serde_json::json!([]),
            "{what}"
        );
        let compile = btc_in(
            tmp.path(),
            &[
                "compile",
                "rules.btrules",
                "--plan",
                "plan.plan",
                "--emit",
                "mermaid",
            ],
        );
        exits(&compile, 0, &format!("compile after stubs, {what}"));
        exits(&btc(&["stubs", s(&rules)]), 0, "stubs again");
        assert_eq!(std::fs::read_to_string(&rules).unwrap(), after, "{what}");
    }
}

/// A file with a domain and no rules is told, once, how to start.
#[test]
fn a_file_without_rules_is_told_how_to_start() {
    let tmp = tempfile::tempdir().unwrap();
    let fixture = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/stubs");
    std::fs::copy(fixture.join("domain.pddl"), tmp.path().join("domain.pddl")).unwrap();
    let rules = tmp.path().join("rules.btrules");
    std::fs::write(&rules, "domain \"domain.pddl\"\n").unwrap();
    let out = btc(&["check", s(&rules)]);
    exits(&out, 0, "check of a file without rules");
    let said = String::from_utf8_lossy(&out.stderr);
    assert_eq!(said.matches("Warning").count(), 1, "{said}");
    assert!(
        said.contains("[R025]") && said.contains("`btc stubs rules.btrules`"),
        "{said}"
    );
}
