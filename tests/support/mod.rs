//! The `btc` binary as the integration tests run it: in the repository
//! (or a given folder), without colour, with the exit code checked and
//! both streams shown when it is not the expected one.

#![allow(dead_code)] // each test binary uses part of it

use std::path::Path;
use std::process::{Command, Output};

/// `btc ARGS` in the repository's root.
pub fn btc(args: &[&str]) -> Output {
    btc_in(Path::new(env!("CARGO_MANIFEST_DIR")), args)
}

/// `btc ARGS` with the working directory `dir`.
pub fn btc_in(dir: &Path, args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_btc"))
        .args(args)
        .env("NO_COLOR", "1")
        .current_dir(dir)
        .output()
        .unwrap()
}

/// Asserts `out` exited with `code`; `what` says which run failed.
pub fn exits(out: &Output, code: i32, what: &str) {
    assert_eq!(
        out.status.code(),
        Some(code),
        "{what}: exit {:?}\nstdout:\n{}\nstderr:\n{}",
        out.status.code(),
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
}

/// Standard output read as one JSON value.
pub fn json_of(out: &Output) -> serde_json::Value {
    serde_json::from_slice(&out.stdout)
        .unwrap_or_else(|e| panic!("{e}: {}", String::from_utf8_lossy(&out.stdout)))
}

/// `btc ARGS --format json`, which must exit with `code`: its summary.
pub fn summary_of(args: &[&str], code: i32) -> serde_json::Value {
    let mut all = args.to_vec();
    all.extend(["--format", "json"]);
    let out = btc(&all);
    exits(&out, code, &args.join(" "));
    json_of(&out)
}

/// `btc compile RULES --plan PLAN --emit EMIT -o OUT EXTRA`, which must
/// succeed.
pub fn compile(rules: &str, plan: &str, emit: &str, out: &Path, extra: &[&str]) {
    let mut args = vec![
        "compile",
        rules,
        "--plan",
        plan,
        "--emit",
        emit,
        "-o",
        out.to_str().unwrap(),
    ];
    args.extend_from_slice(extra);
    exits(&btc(&args), 0, &args.join(" "));
}

/// The first plan of an example, by name: `examples/NAME/plan.*`.
pub fn plan_of(example: &str) -> String {
    let dir = format!("{}/examples/{example}", env!("CARGO_MANIFEST_DIR"));
    let mut plans: Vec<String> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| n.starts_with("plan."))
        .collect();
    plans.sort();
    format!("examples/{example}/{}", plans[0])
}
