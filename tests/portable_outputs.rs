//! An output's text does not depend on where btc ran or how it was given
//! its paths: every example, every `--emit` target (read from `btc compile
//! --help`, so a new target is covered without a list), on standard output
//! and through `-o`, from the repository with relative paths, from the
//! example's folder, and from elsewhere with absolute paths. A team keeps
//! these outputs under review; a snapshot that changed with the working
//! directory would be noise in every review.

mod support;

use std::path::{Path, PathBuf};
use support::{btc_in, exits};

fn repo() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

/// The `--emit` targets, as `btc compile --help` lists them.
fn targets() -> Vec<String> {
    let out = btc_in(repo(), &["compile", "--help"]);
    exits(&out, 0, "btc compile --help");
    let help = String::from_utf8(out.stdout).unwrap();
    let values = help
        .split("--emit <EMIT>\n")
        .nth(1)
        .and_then(|s| s.split("Possible values:").nth(1))
        .expect("`--emit` lists its values");
    let targets: Vec<String> = values
        .lines()
        .map(str::trim)
        .skip_while(|l| l.is_empty())
        .take_while(|l| l.starts_with("- "))
        .map(|l| l[2..].split(':').next().unwrap().trim().to_owned())
        .collect();
    assert!(targets.len() >= 7, "targets read from --help: {targets:?}");
    targets
}

/// The examples with a plan: (folder, plan file name).
fn examples() -> Vec<(PathBuf, String)> {
    let mut out = Vec::new();
    for e in std::fs::read_dir(repo().join("examples")).unwrap() {
        let dir = e.unwrap().path();
        if !dir.join("rules.btrules").is_file() {
            continue;
        }
        let name = dir.file_name().unwrap().to_string_lossy().into_owned();
        let plan = support::plan_of(&name);
        let plan = Path::new(&plan)
            .file_name()
            .unwrap()
            .to_string_lossy()
            .into_owned();
        out.push((dir, plan));
    }
    out.sort();
    assert!(out.len() >= 4, "examples: {out:?}");
    out
}

/// `btc compile` in `cwd` with the given rules and plan paths and extra
/// arguments; its standard output.
fn compile(cwd: &Path, rules: &Path, plan: &Path, extra: &[&str]) -> Vec<u8> {
    let mut args = vec![
        "compile",
        rules.to_str().unwrap(),
        "--plan",
        plan.to_str().unwrap(),
    ];
    args.extend_from_slice(extra);
    let out = btc_in(cwd, &args);
    exits(
        &out,
        0,
        &format!("in {}: btc {}", cwd.display(), args.join(" ")),
    );
    out.stdout
}

#[test]
fn every_target_is_the_same_wherever_btc_runs() {
    let elsewhere = tempfile::tempdir().unwrap();
    let out_dir = elsewhere.path().join("out");
    std::fs::create_dir(&out_dir).unwrap();
    let mut checked = 0;
    for (dir, plan) in examples() {
        let rel = dir.strip_prefix(repo()).unwrap();
        // The same files named three ways, each from its own folder.
        let ways: [(&Path, PathBuf, PathBuf); 3] = [
            (repo(), rel.join("rules.btrules"), rel.join(&plan)),
            (&dir, PathBuf::from("rules.btrules"), PathBuf::from(&plan)),
            (elsewhere.path(), dir.join("rules.btrules"), dir.join(&plan)),
        ];
        for target in targets() {
            let mut variants: Vec<Vec<&str>> = vec![vec!["--emit", &target]];
            if target == "pytrees" {
                variants.push(vec!["--emit", &target, "--source-paths"]);
            }
            for extra in variants {
                let what = format!("{} {}", rel.display(), extra.join(" "));
                // Standard output.
                let first = compile(ways[0].0, &ways[0].1, &ways[0].2, &extra);
                assert!(!first.is_empty(), "{what}: no output");
                for (cwd, rules, plan) in &ways[1..] {
                    let text = compile(cwd, rules, plan, &extra);
                    assert!(
                        text == first,
                        "{what}: standard output differs in {}:\n{}\n---- versus, from the repository:\n{}",
                        cwd.display(),
                        String::from_utf8_lossy(&text),
                        String::from_utf8_lossy(&first)
                    );
                }
                // `-o`: one file, named absolutely from the repository and
                // the example, relatively from where it lies.
                let file = out_dir.join("tree.out");
                let mut written = Vec::new();
                for (k, (cwd, rules, plan)) in ways.iter().enumerate() {
                    let o = if k == 2 {
                        PathBuf::from("out/tree.out")
                    } else {
                        file.clone()
                    };
                    let mut args = extra.clone();
                    args.extend(["-o", o.to_str().unwrap()]);
                    compile(cwd, rules, plan, &args);
                    written.push(std::fs::read(&file).unwrap());
                }
                for (k, w) in written.iter().enumerate().skip(1) {
                    assert!(
                        *w == written[0],
                        "{what} -o: the file written from {} differs:\n{}\n---- versus, from the repository:\n{}",
                        ways[k].0.display(),
                        String::from_utf8_lossy(w),
                        String::from_utf8_lossy(&written[0])
                    );
                }
                checked += 1;
            }
        }
    }
    assert!(checked >= 4 * 8, "{checked} example × target pairs checked");
}

/// On standard output there is no output file: the paths are recorded as
/// seen from the rules file's folder (`tests/run.rs` covers `-o`).
#[test]
fn standard_output_records_paths_from_the_rules_folder() {
    let out = btc_in(
        repo(),
        &[
            "compile",
            "examples/two_robots/rules.btrules",
            "--plan",
            "examples/two_robots/plan.plan",
            "--emit",
            "json",
        ],
    );
    exits(&out, 0, "compile --emit json");
    let ir: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    for (key, file) in [
        ("domain", "domain.pddl"),
        ("problem", "problem.pddl"),
        ("plan", "plan.plan"),
        ("rules", "rules.btrules"),
    ] {
        assert_eq!(ir[key], file, "{key}");
    }
}
