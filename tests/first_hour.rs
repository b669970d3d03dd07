//! What a newcomer meets in the first hour with btc (issue #28): each
//! message says what to do, once, about the right file.

mod support;
use std::path::Path;
use support::{btc_in, exits, json_of};

/// `btc ARGS` in `dir`, which must exit with `code`.
fn run_in(dir: &Path, args: &[&str], code: i32) -> std::process::Output {
    let out = btc_in(dir, args);
    exits(&out, code, &args.join(" "));
    out
}

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

/// A decorator count looked up in a table that lacks the step's key:
/// `btc check` warns (R024) for the problem's objects without a key, and
/// the compile's R023 names the table and the key.
#[test]
fn a_lookup_without_the_key_names_the_table_and_the_key() {
    let dir = fixture("diagnostics/R024");
    let check = run_in(&dir, &["check", "rules.btrules"], 0);
    let said = String::from_utf8_lossy(&check.stderr);
    assert!(
        said.contains("table `move_ms` has no key for `home`, `bin3`"),
        "{said}"
    );
    let args = [
        "compile",
        "rules.btrules",
        "--plan",
        "plan.plan",
        "--emit",
        "btcpp",
    ];
    let compile = run_in(&dir, &args, 1);
    let said = String::from_utf8_lossy(&compile.stderr);
    assert!(
        said.contains("`timeout` gets no value: table `move_ms` has no key `bin3`"),
        "{said}"
    );
}

/// The ARIAC example in a fresh folder, its domain saved as `floor.pddl`
/// (a name `btc pddl` and `btc run --tree` find by the domain it defines).
fn ariac_elsewhere() -> tempfile::TempDir {
    let tmp = tempfile::tempdir().unwrap();
    let ex = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/ariac");
    for f in ["problem.pddl", "plan.txt"] {
        std::fs::copy(ex.join(f), tmp.path().join(f)).unwrap();
    }
    std::fs::copy(ex.join("domain.pddl"), tmp.path().join("floor.pddl")).unwrap();
    let rules = std::fs::read_to_string(ex.join("rules.btrules"))
        .unwrap()
        .replace("domain \"domain.pddl\"", "domain \"floor.pddl\"");
    std::fs::write(tmp.path().join("rules.btrules"), rules).unwrap();
    tmp
}

/// A misspelled path, in a rules file or on the command line, gets the
/// closest file beside it; every command says F001 the same way.
#[test]
fn a_misspelled_path_gets_the_file_beside_it() {
    let tmp = ariac_elsewhere();
    let dir = tmp.path();
    let rules = std::fs::read_to_string(dir.join("rules.btrules")).unwrap();
    std::fs::write(
        dir.join("typo.btrules"),
        rules.replace("\"floor.pddl\"", "\"flor.pddl\""),
    )
    .unwrap();
    let check = json_of(&btc_in(dir, &["check", "typo.btrules", "--format", "json"]));
    let r017 = &check["diagnostics"][0];
    assert_eq!(r017["code"], "R017", "{check:#}");
    assert_eq!(r017["hint"], "did you mean `floor.pddl`? It is beside it");
    assert_eq!(r017["fixes"][0]["replacement"], "\"floor.pddl\"");
    for args in [
        &["plan", "flor.pddl", "problem.pddl"][..],
        &["check", "rule.btrules"],
        &["validate", "floor.pddl", "problem.pddl", "plan.tx"],
        &[
            "compile",
            "rules.btrules",
            "--plan",
            "plan.tx",
            "--emit",
            "json",
        ],
    ] {
        let out = btc_in(dir, args);
        exits(&out, 2, &args.join(" "));
        let said = String::from_utf8_lossy(&out.stderr);
        assert!(
            said.starts_with("error: [F001] cannot read `")
                && said.contains("`: no such file; did you mean `"),
            "{args:?}: {said}"
        );
    }
}

/// `-o` makes the folders it needs, for every command that writes.
#[test]
fn outputs_go_into_folders_that_do_not_exist_yet() {
    let tmp = ariac_elsewhere();
    let dir = tmp.path();
    for args in [
        &[
            "compile",
            "rules.btrules",
            "--plan",
            "plan.txt",
            "--emit",
            "btcpp",
            "-o",
            "out/a/tree.xml",
        ][..],
        &[
            "plan",
            "floor.pddl",
            "problem.pddl",
            "-q",
            "-o",
            "out/b/sas_plan",
        ],
        &[
            "run",
            "rules.btrules",
            "--plan",
            "plan.txt",
            "--trace",
            "out/c/trace.jsonl",
        ],
    ] {
        exits(&btc_in(dir, args), 0, &args.join(" "));
        let written = args.last().unwrap();
        assert!(dir.join(written).is_file(), "{written}");
    }
}

/// `btc run --tree` finds a problem's domain as `btc pddl` does: by the
/// domain name, in the problem's folder.
#[test]
fn run_finds_the_domain_of_a_problem_as_pddl_does() {
    let tmp = ariac_elsewhere();
    let dir = tmp.path();
    let args = [
        "compile",
        "rules.btrules",
        "--plan",
        "plan.txt",
        "--emit",
        "btcpp",
        "-o",
        "t.xml",
    ];
    exits(&btc_in(dir, &args), 0, "compile");
    exits(&btc_in(dir, &["pddl", "problem.pddl"]), 0, "btc pddl");
    let run = btc_in(
        dir,
        &["run", "--tree", "t.xml", "--problem", "problem.pddl"],
    );
    exits(&run, 0, "btc run --tree");
    assert!(String::from_utf8_lossy(&run.stdout).contains("goal reached: yes"));
}

/// The bundled examples check clean: no diagnostic on any rules file, and
/// none on any PDDL file (the first command of the README is one of them).
#[test]
fn every_example_checks_without_a_warning() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut seen = 0;
    for e in std::fs::read_dir(root.join("examples")).unwrap() {
        let dir = e.unwrap().path();
        for f in std::fs::read_dir(&dir).unwrap() {
            let f = f.unwrap().path();
            let name = f.to_str().unwrap();
            let args: Vec<&str> = match f.extension().and_then(|x| x.to_str()) {
                Some("btrules") => vec!["check", name, "--format", "json"],
                Some("pddl") => vec!["pddl", name, "--format", "json"],
                _ => continue,
            };
            let v = json_of(&btc_in(root, &args));
            assert_eq!(v["diagnostics"], serde_json::json!([]), "{name}: {v:#}");
            seen += 1;
        }
    }
    assert!(seen >= 10, "{seen} files");
}

/// The generated py_trees module says how it builds leaf classes as the
/// runtime does (and docs/pytrees.md says): with the step for btc's bases.
#[test]
fn the_pytrees_header_says_how_classes_are_built() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let args = [
        "compile",
        "examples/p3_assembler/rules.btrules",
        "--plan",
        "examples/p3_assembler/plan.tplan",
        "--emit",
        "pytrees",
        "--node-module",
        "p3_nodes",
    ];
    let out = run_in(root, &args, 0);
    let module = String::from_utf8_lossy(&out.stdout);
    let header: String = module
        .lines()
        .take_while(|l| l.starts_with('#'))
        .collect::<Vec<_>>()
        .join("\n");
    assert!(
        header.contains("`Class(node_name, step=k, **ports)`")
            && header.contains("as `Class(node_name, **ports)` otherwise"),
        "{header}"
    );
}
