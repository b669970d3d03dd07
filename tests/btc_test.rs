//! `btc test` end to end, on a copy of every example: a first run writes
//! the snapshots; a rerun passes and changes nothing; a changed rule fails
//! with a readable diff and `.snap.new` files; `--check` writes nothing;
//! `--accept` takes the change; the same snapshots pass from another
//! working directory and through an absolute path.

mod support;

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use support::{btc_in, exits};

/// Every file under `dir` with its bytes.
fn contents(dir: &Path) -> BTreeMap<PathBuf, Vec<u8>> {
    let mut out = BTreeMap::new();
    let mut todo = vec![dir.to_path_buf()];
    while let Some(d) = todo.pop() {
        for e in std::fs::read_dir(&d).unwrap() {
            let p = e.unwrap().path();
            if p.is_dir() {
                todo.push(p);
            } else {
                out.insert(
                    p.strip_prefix(dir).unwrap().to_path_buf(),
                    std::fs::read(&p).unwrap(),
                );
            }
        }
    }
    out
}

fn snapshots(dir: &Path, suffix: &str) -> Vec<String> {
    let mut v: Vec<String> = std::fs::read_dir(dir.join("snapshots"))
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| n.ends_with(suffix))
        .collect();
    v.sort();
    v
}

fn copy_example(name: &str, to: &Path) {
    let from = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("examples")
        .join(name);
    std::fs::create_dir_all(to).unwrap();
    for e in std::fs::read_dir(from).unwrap() {
        let p = e.unwrap().path();
        if p.is_file() {
            std::fs::copy(&p, to.join(p.file_name().unwrap())).unwrap();
        }
    }
}

fn text(out: &std::process::Output) -> String {
    String::from_utf8_lossy(&out.stdout).into_owned()
}

#[test]
fn btc_test_on_every_example() {
    let examples: Vec<String> =
        std::fs::read_dir(Path::new(env!("CARGO_MANIFEST_DIR")).join("examples"))
            .unwrap()
            .map(|e| e.unwrap().path())
            .filter(|p| p.join("rules.btrules").is_file())
            .map(|p| p.file_name().unwrap().to_string_lossy().into_owned())
            .collect();
    assert!(examples.len() >= 4, "{examples:?}");
    let tmp = tempfile::tempdir().unwrap();
    let mut changed_some = 0;
    for name in &examples {
        let dir = tmp.path().join(name);
        copy_example(name, &dir);
        // A first run writes the snapshots: per case, the two default
        // formats and the run.
        let first = btc_in(&dir, &["test", "rules.btrules"]);
        exits(&first, 0, &format!("{name}: first run"));
        let written = snapshots(&dir, ".snap");
        assert!(
            !written.is_empty() && written.len().is_multiple_of(3),
            "{name}: {written:?}"
        );
        for kind in ["btcpp", "mermaid", "run"] {
            assert!(
                written
                    .iter()
                    .any(|n| n.ends_with(&format!("__{kind}.snap"))),
                "{name}: {written:?}"
            );
        }
        let run = std::fs::read_to_string(
            dir.join("snapshots")
                .join(written.iter().find(|n| n.ends_with("__run.snap")).unwrap()),
        )
        .unwrap();
        assert!(run.starts_with("---\nsource: rules.btrules\n"), "{run}");
        assert!(
            run.contains("\nstart step 1: ") && run.contains("\ngoal: reached\n"),
            "{run}"
        );
        let stored = contents(&dir);
        // Unchanged: passes and changes nothing, here, from the folder
        // above, and through an absolute path from elsewhere.
        let abs = dir.join("rules.btrules");
        let rel = format!("{name}/rules.btrules");
        for (cwd, rules) in [
            (dir.as_path(), "rules.btrules"),
            (tmp.path(), rel.as_str()),
            (Path::new("/"), abs.to_str().unwrap()),
        ] {
            let again = btc_in(cwd, &["test", rules]);
            exits(&again, 0, &format!("{name}: rerun in {}", cwd.display()));
            assert!(
                text(&again).contains("0 new, 0 changed"),
                "{}",
                text(&again)
            );
            assert_eq!(contents(&dir), stored, "{name}: a passing run wrote");
        }
        // A changed rule.
        let rules = std::fs::read_to_string(&abs).unwrap();
        if !rules.contains("retry(3)") {
            continue;
        }
        changed_some += 1;
        std::fs::write(&abs, rules.replacen("retry(3)", "retry(2)", 1)).unwrap();
        let before = contents(&dir);
        let check = btc_in(tmp.path(), &["test", "--check", abs.to_str().unwrap()]);
        exits(&check, 1, &format!("{name}: --check after the change"));
        assert_eq!(contents(&dir), before, "{name}: --check wrote");
        let failed = btc_in(&dir, &["test", "rules.btrules"]);
        exits(&failed, 1, &format!("{name}: run after the change"));
        let said = text(&failed);
        assert!(
            said.contains("-    <RetryUntilSuccessful num_attempts=\"3\">"),
            "{said}"
        );
        assert!(
            said.contains("+    <RetryUntilSuccessful num_attempts=\"2\">"),
            "{said}"
        );
        assert!(
            said.contains("--- rules__") && said.contains("(stored)") && said.contains("@@"),
            "{said}"
        );
        let pending = snapshots(&dir, ".snap.new");
        assert!(
            pending.iter().any(|n| n.ends_with("__btcpp.snap.new")),
            "{pending:?}"
        );
        assert!(
            pending.iter().any(|n| n.ends_with("__mermaid.snap.new")),
            "{pending:?}"
        );
        // The stored snapshots are kept until accepted.
        for n in snapshots(&dir, ".snap") {
            assert_eq!(
                before[&Path::new("snapshots").join(&n)],
                std::fs::read(dir.join("snapshots").join(&n)).unwrap()
            );
        }
        let accept = btc_in(&dir, &["test", "--accept", "rules.btrules"]);
        exits(&accept, 0, &format!("{name}: --accept"));
        assert!(snapshots(&dir, ".snap.new").is_empty());
        exits(
            &btc_in(&dir, &["test", "--check", "rules.btrules"]),
            0,
            &format!("{name}: --check after --accept"),
        );
        exits(
            &btc_in(tmp.path(), &["test", &rel]),
            0,
            &format!("{name}: from above after --accept"),
        );
    }
    assert!(changed_some >= 1, "no example has a retry(3) to change");
}

/// Cases in `plans/` are found too; `--check` with no snapshots fails and
/// writes nothing (not even the folder).
#[test]
fn cases_in_a_plans_folder_and_check_without_snapshots() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path().join("two_robots");
    copy_example("two_robots", &dir);
    std::fs::create_dir(dir.join("plans")).unwrap();
    std::fs::rename(dir.join("plan.plan"), dir.join("plans/first.plan")).unwrap();
    let before = contents(&dir);
    let check = btc_in(&dir, &["test", "--check", "rules.btrules"]);
    exits(&check, 1, "--check with no snapshots");
    assert!(
        text(&check).contains("plans/first.plan btcpp: missing"),
        "{}",
        text(&check)
    );
    assert_eq!(contents(&dir), before);
    assert!(!dir.join("snapshots").exists());
    exits(
        &btc_in(
            &dir,
            &["test", "rules.btrules", "--emit", "json", "--emit", "dot"],
        ),
        0,
        "first run",
    );
    assert_eq!(
        snapshots(&dir, ".snap"),
        [
            "rules__plans-first.plan__dot.snap",
            "rules__plans-first.plan__json.snap",
            "rules__plans-first.plan__run.snap"
        ]
    );
}

/// A case with a fault scenario beside its plan (`STEM.faults.toml`): its
/// run snapshot holds the fault and the record it leaves; the scenario is
/// not a case of its own.
#[test]
fn a_case_runs_with_the_fault_scenario_beside_its_plan() {
    let dir = tempfile::tempdir().unwrap();
    let cell = dir.path().join("ariac");
    copy_example("ariac", &cell);
    std::fs::copy(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/ariac/faults/robot_malfunction.toml"),
        cell.join("plan.faults.toml"),
    )
    .unwrap();
    let out = btc_in(&cell, &["test", "rules.btrules"]);
    exits(&out, 0, "first run");
    assert!(text(&out).contains("1 cases"), "{}", text(&out));
    let run = std::fs::read_to_string(cell.join("snapshots/rules__plan.txt__run.snap")).unwrap();
    assert!(run.contains("fault triggered"), "{run}");
    assert!(run.contains("record"), "{run}");
    assert!(run.contains("status: FAILURE"), "{run}");
    // A broken scenario is an error that names it.
    std::fs::write(cell.join("plan.faults.toml"), "[[fault]]\nkind = 3\n").unwrap();
    let out = btc_in(&cell, &["test", "rules.btrules"]);
    assert_ne!(out.status.code(), Some(0));
    assert!(
        String::from_utf8_lossy(&out.stderr).contains("plan.faults.toml"),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
}
