//! Which problem a plan goes with, and a plan that is not for its problem:
//! each command line of `tests/fixtures/pairing/cases` runs in that folder
//! and its whole output is a snapshot.

use std::path::Path;
use std::process::Command;

fn run(dir: &Path, line: &str) -> String {
    let out = Command::new(env!("CARGO_BIN_EXE_btc"))
        .args(line.split_whitespace())
        .current_dir(dir)
        .env("NO_COLOR", "1")
        .output()
        .unwrap();
    format!(
        "$ btc {line}\nexit: {}\n--- stdout\n{}--- stderr\n{}",
        out.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    )
}

#[test]
fn every_case_as_a_user_sees_it() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/pairing");
    let cases = std::fs::read_to_string(dir.join("cases")).unwrap();
    let mut settings = insta::Settings::clone_current();
    settings.set_prepend_module_to_snapshot(true);
    for (n, line) in cases
        .lines()
        .filter(|l| !l.trim().is_empty() && !l.starts_with('#'))
        .enumerate()
    {
        let out = run(&dir, line);
        assert!(!out.contains("exit: 101"), "btc panicked: {out}");
        settings.bind(|| insta::assert_snapshot!(format!("case{:02}", n + 1), out));
    }
}
