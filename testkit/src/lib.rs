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

/// The entries of `dir`, in path order.
pub fn sorted_entries(dir: &Path) -> Vec<PathBuf> {
    let mut out: Vec<PathBuf> = std::fs::read_dir(dir)
        .unwrap_or_else(|e| panic!("{}: {e}", dir.display()))
        .map(|e| e.unwrap().path())
        .collect();
    out.sort();
    out
}

/// One corpus problem with its domain and plans.
pub struct CorpusCase {
    pub dir: PathBuf,
    pub domain: PathBuf,
    pub problem: PathBuf,
    pub plans: Vec<PathBuf>,
}

/// Every corpus problem (found by walking the corpus, not by a list), in
/// path order; `None` (after [`skip`]) without the corpus.
pub fn corpus_cases() -> Option<Vec<CorpusCase>> {
    let name = |p: &Path| p.file_name().unwrap().to_string_lossy().into_owned();
    let mut out = Vec::new();
    for dir in sorted_entries(&corpus()?)
        .into_iter()
        .filter(|d| d.is_dir())
    {
        let files = sorted_entries(&dir);
        for problem in files
            .iter()
            .filter(|p| name(p).ends_with(".pddl") && !name(p).contains("domain"))
        {
            let stem = problem.file_stem().unwrap().to_string_lossy().into_owned();
            // `domain.pddl`, or `pNN-domain.pddl` beside `pNN.pddl`
            let own = dir.join(format!("{stem}-domain.pddl"));
            let domain = if own.exists() {
                own
            } else {
                dir.join("domain.pddl")
            };
            let plans = files
                .iter()
                .filter(|p| {
                    let n = name(p);
                    n.starts_with(&format!("{stem}."))
                        && (n.ends_with(".plan") || n.ends_with(".tplan"))
                })
                .cloned()
                .collect();
            out.push(CorpusCase {
                dir: dir.clone(),
                domain,
                problem: problem.clone(),
                plans,
            });
        }
    }
    Some(out)
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

/// A corpus domain with rules in `tests/corpus_rules/<name>/`.
pub struct RulesDomain {
    pub name: String,
    /// `tests/corpus_rules/<name>/rules.btrules`.
    pub rules: PathBuf,
    /// The domain's folder in the corpus.
    pub corpus: PathBuf,
    /// Its plans (`.plan`, `.tplan`), sorted; each `pXX` pairs with the
    /// problem `pXX.pddl` beside it.
    pub plans: Vec<PathBuf>,
}

/// Every corpus domain the repository has rules for, by name, or `None`
/// after [`skip`] without the corpus.
pub fn corpus_rules() -> Option<Vec<RulesDomain>> {
    let ipc = corpus()?;
    let sorted = |dir: &Path, keep: &dyn Fn(&Path) -> bool| -> Vec<PathBuf> {
        let mut v: Vec<PathBuf> = std::fs::read_dir(dir)
            .unwrap_or_else(|e| panic!("{}: {e}", dir.display()))
            .map(|e| e.unwrap().path())
            .filter(|p| keep(p))
            .collect();
        v.sort();
        v
    };
    let domains = sorted(&repo().join("tests/corpus_rules"), &|p| p.is_dir());
    Some(
        domains
            .into_iter()
            .map(|dir| {
                let name = dir.file_name().unwrap().to_string_lossy().into_owned();
                let corpus = ipc.join(&name);
                let plans = sorted(&corpus, &|p| {
                    p.extension().is_some_and(|e| e == "plan" || e == "tplan")
                });
                RulesDomain {
                    rules: dir.join("rules.btrules"),
                    name,
                    corpus,
                    plans,
                }
            })
            .collect(),
    )
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
        build_vendored("integrations/btcpp/build-btcpp.sh", &btcpp_archive())
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

/// Runs a build script of `integrations/` on a vendored source archive
/// and returns the last line it prints (what it built), or why not.
fn build_vendored(script: &str, archive: &Path) -> Result<PathBuf, String> {
    if !archive.is_file() {
        return Err(format!("{} is not there", archive.display()));
    }
    if Command::new("cmake").arg("--version").output().is_err() {
        return Err("cmake is not installed (`apt-get install cmake`)".into());
    }
    let script = repo().join(script);
    let out = Command::new("bash")
        .arg(&script)
        .arg(archive)
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
    Ok(PathBuf::from(stdout.lines().last().unwrap_or("").trim()))
}

/// VAL's `Validate` binary (KCL-Planning/VAL, the reference PDDL plan
/// validator), or `None` after [`skip`]. `BTC_VAL` names an existing
/// binary; otherwise `integrations/val/build-val.sh` builds it from
/// `../shared/vendor/VAL-3c7a1f3.tar.gz` (or `BTC_VAL_ARCHIVE`) into
/// `~/.cache/btc/val-<sha256>` (once: later calls find it there).
pub fn val() -> Option<PathBuf> {
    static FOUND: OnceLock<Result<PathBuf, String>> = OnceLock::new();
    let found = FOUND.get_or_init(|| {
        if let Some(p) = std::env::var_os("BTC_VAL") {
            let p = PathBuf::from(p);
            return if p.is_file() {
                Ok(p)
            } else {
                Err(format!("BTC_VAL={} is no file", p.display()))
            };
        }
        let archive = std::env::var_os("BTC_VAL_ARCHIVE")
            .map(PathBuf::from)
            .unwrap_or_else(|| repo().join("../shared/vendor/VAL-3c7a1f3.tar.gz"));
        build_vendored("integrations/val/build-val.sh", &archive)
    });
    match found {
        Ok(p) => Some(p.clone()),
        Err(why) => {
            skip(
                "VAL's Validate",
                &format!(
                    "{why}; `bash integrations/val/build-val.sh` builds it from \
                     ../shared/vendor, or set BTC_VAL to the binary"
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
/// (`integrations/btcpp/harness/`: `btc_conformance`, `btc_kb_eval`,
/// `btc_peer`), built
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
            &["btc_conformance", "btc_kb_eval", "btc_peer"],
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

/// A valid timed plan of `steps` steps for `examples/p3_assembler` in the
/// P3 generator's input format: the example's first four steps, then a
/// cycle of picks and places at the assembly station (with a self-move the
/// rules skip, a wait and a round trip), times increasing; from 6 steps on
/// the last one takes the robot home, so the plan reaches the goal.
pub fn long_p3_plan(steps: usize) -> String {
    let start = [
        ("MOVE_TO robot1 home tool_rack", 2.0),
        ("PICK_OP1 robot1 screwdriver tool_rack", 3.0),
        ("MOVE_TO robot1 tool_rack assembly_station", 2.0),
        ("PLACE_OP1 robot1 screwdriver", 3.0),
    ];
    let mut out = String::with_capacity(steps * 48);
    let mut t = 0.0f64;
    let mut push = |out: &mut String, a: &str, d: f64| {
        out.push_str(&format!("{t:.3}: ({a}) [{d:.3}]\n"));
        t += d + 0.001;
    };
    for (a, d) in start.iter().take(steps) {
        push(&mut out, a, *d);
    }
    // Three cycles do each operation once; the goal also wants the robot
    // home at the end.
    let home = steps > start.len() + 18;
    let cycle = steps.saturating_sub(start.len() + usize::from(home));
    for i in 0..cycle {
        let op = 1 + (i / 6) % 3;
        match i % 6 {
            0 => push(
                &mut out,
                &format!("PICK_OP{op} robot1 screwdriver assembly_station"),
                3.0,
            ),
            1 => push(
                &mut out,
                "MOVE_TO robot1 assembly_station assembly_station",
                2.0,
            ),
            2 => push(&mut out, &format!("PLACE_OP{op} robot1 screwdriver"), 3.0),
            3 => push(&mut out, "WAIT robot1", 1.0),
            4 => push(&mut out, "MOVE_TO robot1 assembly_station tool_rack", 2.0),
            _ => push(&mut out, "MOVE_TO robot1 tool_rack assembly_station", 2.0),
        }
    }
    if home {
        let from = if cycle % 6 == 5 {
            "tool_rack"
        } else {
            "assembly_station"
        };
        push(&mut out, &format!("MOVE_TO robot1 {from} home"), 2.0);
    }
    out
}

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
