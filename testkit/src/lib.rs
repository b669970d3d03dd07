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
/// Where `build-btcpp.sh` looks for the BehaviorTree.CPP source archive
/// (`BTC_BTCPP_ARCHIVE`, or `../shared/vendor/` beside the repository).
pub fn btcpp_archive() -> PathBuf {
    std::env::var_os("BTC_BTCPP_ARCHIVE")
        .map(PathBuf::from)
        .unwrap_or_else(|| repo().join("../shared/vendor/BehaviorTree.CPP-4.10.0.tar.gz"))
}

/// The install prefix of a BehaviorTree.CPP 4.10 build, or `None` after
/// [`skip`]. `BTC_BTCPP` names an existing install; otherwise
/// `integrations/btcpp/build-btcpp.sh` builds one from the vendored archive
/// into `~/.cache/btc/btcpp-<sha256>` (once: later calls find it there).
/// Needs the archive, cmake and a C++17 compiler.
pub fn btcpp() -> Option<PathBuf> {
    static FOUND: OnceLock<Result<PathBuf, String>> = OnceLock::new();
    let found = FOUND.get_or_init(|| {
        if let Some(p) = std::env::var_os("BTC_BTCPP") {
            let p = PathBuf::from(p);
            return if p.join("include/behaviortree_cpp/bt_factory.h").is_file() {
                Ok(p)
            } else {
                Err(format!(
                    "BTC_BTCPP={} has no include/behaviortree_cpp/bt_factory.h",
                    p.display()
                ))
            };
        }
        let archive = btcpp_archive();
        if !archive.is_file() {
            return Err(format!("{} is not there", archive.display()));
        }
        if Command::new("cmake").arg("--version").output().is_err() {
            return Err("cmake is not installed (`apt-get install cmake`)".into());
        }
        let script = repo().join("integrations/btcpp/build-btcpp.sh");
        let out = Command::new("bash")
            .arg(&script)
            .arg(&archive)
            .output()
            .map_err(|e| format!("{} does not run: {e}", script.display()))?;
        if !out.status.success() {
            let err = String::from_utf8_lossy(&out.stderr);
            let tail: Vec<&str> = err.lines().rev().take(15).collect();
            return Err(format!(
                "building it failed:\n{}",
                tail.into_iter().rev().collect::<Vec<_>>().join("\n")
            ));
        }
        let stdout = String::from_utf8_lossy(&out.stdout);
        let prefix = stdout.lines().last().unwrap_or("").trim();
        Ok(PathBuf::from(prefix))
    });
    match found {
        Ok(p) => Some(p.clone()),
        Err(why) => {
            skip(
                "BehaviorTree.CPP 4.10",
                &format!(
                    "{why}; `bash integrations/btcpp/build-btcpp.sh` builds it from \
                     ../shared/vendor, or set BTC_BTCPP to an install prefix"
                ),
            );
            None
        }
    }
}

/// Configures (once) and builds CMake project `source` in `build` (under
/// `target/`, so later runs rebuild only what changed) against the
/// BehaviorTree.CPP at `prefix`; `targets` are built. Errors carry the
/// compiler's output.
pub fn cmake_build(
    source: &Path,
    build: &Path,
    prefix: &Path,
    defines: &[(&str, &str)],
    targets: &[&str],
) -> Result<(), String> {
    let run = |cmd: &mut Command| -> Result<(), String> {
        let out = cmd
            .output()
            .map_err(|e| format!("cmake does not run: {e}"))?;
        if out.status.success() {
            Ok(())
        } else {
            Err(format!(
                "{:?} failed:\n{}{}",
                cmd,
                String::from_utf8_lossy(&out.stdout),
                String::from_utf8_lossy(&out.stderr)
            ))
        }
    };
    let mut configure = Command::new("cmake");
    configure
        .arg("-S")
        .arg(source)
        .arg("-B")
        .arg(build)
        .arg("-DCMAKE_BUILD_TYPE=Release")
        .arg(format!("-DCMAKE_PREFIX_PATH={}", prefix.display()));
    for (k, v) in defines {
        configure.arg(format!("-D{k}={v}"));
    }
    run(&mut configure)?;
    let jobs = std::env::var("BTC_BUILD_JOBS").unwrap_or_else(|_| "2".into());
    let mut make = Command::new("cmake");
    make.arg("--build").arg(build).arg("-j").arg(jobs);
    for t in targets {
        make.arg("--target").arg(t);
    }
    run(&mut make)
}

/// The build folder of btc's C++ test harnesses
/// (`integrations/btcpp/harness/`: `btc_conformance`, `btc_kb_eval`), built
/// once per test process against [`btcpp`]; `None` after [`skip`]. A build
/// that fails is a test failure, not a skip.
pub fn btcpp_harness() -> Option<PathBuf> {
    static BUILT: OnceLock<Result<PathBuf, String>> = OnceLock::new();
    let prefix = btcpp()?;
    let built = BUILT.get_or_init(|| {
        let build = target_dir("btcpp/harness");
        cmake_build(
            &repo().join("integrations/btcpp/harness"),
            &build,
            &prefix,
            &[],
            &["btc_conformance", "btc_kb_eval"],
        )
        .map(|()| build)
    });
    match built {
        Ok(p) => Some(p.clone()),
        Err(e) => panic!("the C++ test harnesses do not build:\n{e}"),
    }
}

/// A folder under the workspace's `target/` for build products of tests.
pub fn target_dir(name: &str) -> PathBuf {
    let base = std::env::var_os("CARGO_TARGET_DIR")
        .map(PathBuf::from)
        .unwrap_or_else(|| repo().join("target"));
    base.join(name)
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
