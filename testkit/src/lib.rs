//! What btc's tests need from outside the repository, and what happens when
//! it is missing.
//!
//! A fresh clone has nothing beside it: no `../shared/corpus/`, perhaps no
//! py_trees or Neovim. A test asks for what it needs here; when it is there
//! the test gets it, when it is not the test is skipped with a line on the
//! terminal that says what was missing and how to get it. Under `CI=true` a
//! missing need fails the test instead, so CI keeps proving everything.
//!
//! The skip line is written straight to the process's stderr, past the test
//! harness's output capture, so `cargo test` shows it for passing tests too.

pub mod hostile;
pub mod scale;

use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::sync::OnceLock;

/// The repository's root folder (the workspace).
pub fn repo() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .expect("testkit sits in the workspace")
        .to_path_buf()
}

/// True when missing needs are failures (`CI` set to anything but `false`/`0`).
pub fn required() -> bool {
    std::env::var("CI").is_ok_and(|v| !v.is_empty() && v != "false" && v != "0")
}

/// Reports that the calling test cannot run: a failure under CI, otherwise
/// a `skipped:` line on the terminal. Returns normally only when skipping.
pub fn skip(what: &str, how: &str) {
    let test = std::thread::current().name().unwrap_or("a test").to_owned();
    if required() {
        panic!("{test} needs {what}, which is missing (CI=true makes that a failure): {how}");
    }
    let line = format!("skipped: {test}: needs {what} ({how})\n");
    let _ = std::io::stderr().write_all(line.as_bytes());
    if let Some(log) = std::env::var_os("BTC_SKIP_LOG") {
        if let Ok(mut f) = std::fs::OpenOptions::new()
            .create(true)
            .append(true)
            .open(log)
        {
            let _ = f.write_all(line.as_bytes());
        }
    }
}

/// The IPC corpus (`BTC_CORPUS`, or `../shared/corpus/ipc` beside the
/// repository), or `None` after [`skip`].
pub fn corpus() -> Option<PathBuf> {
    let dir = corpus_path();
    if dir.is_dir() {
        Some(dir)
    } else {
        skip(
            "the IPC corpus",
            &format!(
                "{} is not there; set BTC_CORPUS to its folder",
                dir.display()
            ),
        );
        None
    }
}

/// Where the IPC corpus is looked for (`BTC_CORPUS`, or
/// `../shared/corpus/ipc` beside the repository), whether or not it is there.
pub fn corpus_path() -> PathBuf {
    std::env::var_os("BTC_CORPUS")
        .map(PathBuf::from)
        .unwrap_or_else(|| repo().join("../shared/corpus/ipc"))
}

/// True when `python3` imports py_trees 2.2 or later; otherwise [`skip`]s.
pub fn py_trees() -> bool {
    static FOUND: OnceLock<Result<(), String>> = OnceLock::new();
    let found = FOUND.get_or_init(|| {
        let out = Command::new("python3")
            .args([
                "-c",
                "import py_trees.decorators; py_trees.decorators.Repeat",
            ])
            .output();
        match out {
            Ok(o) if o.status.success() => Ok(()),
            Ok(o) => Err(format!(
                "python3 cannot import it: {}",
                String::from_utf8_lossy(&o.stderr)
                    .lines()
                    .last()
                    .unwrap_or("")
                    .trim()
            )),
            Err(e) => Err(format!("python3 does not run: {e}")),
        }
    });
    match found {
        Ok(()) => true,
        Err(why) => {
            skip(
                "py_trees 2.2 or later",
                &format!("{why}; `pip install 'py_trees>=2.2'`"),
            );
            false
        }
    }
}

/// True when `program` runs (`program --version` exits 0); otherwise
/// [`skip`]s with `how` as the way to install it.
pub fn tool(program: &str, how: &str) -> bool {
    let ok = Command::new(program)
        .arg("--version")
        .output()
        .is_ok_and(|o| o.status.success());
    if !ok {
        skip(&format!("`{program}`"), how);
    }
    ok
}
// Inputs shared by the benchmarks.

/// A valid ARIAC plan of exactly `steps` steps: the robot carries the red
/// battery between bin1 and agv1, ending with it on agv1 when
/// `steps % 6 == 4` (as for 100,000).
pub fn long_ariac_plan(steps: usize) -> String {
    let mut s = String::from("(move floor_robot curr_position bin1)\n");
    let cycle = [
        "(grasp floor_robot battery_red bin1)",
        "(move floor_robot bin1 agv1)",
        "(place floor_robot battery_red agv1)",
        "(grasp floor_robot battery_red agv1)",
        "(move floor_robot agv1 bin1)",
        "(place floor_robot battery_red bin1)",
    ];
    for i in 0..steps - 1 {
        s.push_str(cycle[i % 6]);
        s.push('\n');
    }
    s
}
