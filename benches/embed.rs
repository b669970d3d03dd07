//! One plan -> tree round on the ARIAC part task as an embedding agent meets
//! it (`cargo bench --bench embed`): plan, compile, build the py_trees tree,
//! in-process from Python through the `btc` package, and by the subprocess
//! route (`btc plan`, `btc compile --emit pytrees`, import the module) in
//! the same run; target p50 under 1 ms in-process. The Python side is
//! `python/bench/round.py`; `BTC_PYTHON` names a Python with the package
//! installed (`pip install ./python`), else `python3`. The C++ side is
//! `benches/cpp/round.cpp` (through btc's C API, and by the subprocess
//! route: `btc plan`, `btc compile --emit btcpp` and `--emit kb`, the tree
//! built in a BT.CPP factory), built against BT.CPP 4.10
//! (`btc_testkit::btcpp`) and the release `libbtc_capi.a`, which this
//! bench has cargo build.

use std::path::{Path, PathBuf};
use std::process::Command;

fn main() {
    let repo = Path::new(env!("CARGO_MANIFEST_DIR"));
    python(repo);
    cpp(repo);
}

fn python(repo: &Path) {
    let python = std::env::var("BTC_PYTHON").unwrap_or_else(|_| "python3".into());
    let has_btc = Command::new(&python)
        .args(["-c", "import btc"])
        .output()
        .is_ok_and(|o| o.status.success());
    if !has_btc {
        println!("embed: skipped, `{python}` cannot import btc (pip install ./python, or set BTC_PYTHON)");
        return;
    }
    let status = Command::new(&python)
        .arg(repo.join("python/bench/round.py"))
        .args(["--btc", env!("CARGO_BIN_EXE_btc")])
        .status();
    match status {
        Ok(s) if s.success() => {}
        other => println!("embed: the Python bench failed: {other:?}"),
    }
}

/// The release `libbtc_capi.a`, built by cargo (a no-op after `cargo
/// bench`'s own release build, but for this crate).
fn capi_library() -> Result<PathBuf, String> {
    let cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".into());
    let out = Command::new(cargo)
        .args([
            "build",
            "--release",
            "-p",
            "btc-capi",
            "--message-format=json",
        ])
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output()
        .map_err(|e| format!("cargo does not run: {e}"))?;
    if !out.status.success() {
        return Err(String::from_utf8_lossy(&out.stderr).into_owned());
    }
    String::from_utf8_lossy(&out.stdout)
        .lines()
        .filter_map(|l| serde_json::from_str::<serde_json::Value>(l).ok())
        .filter(|m| m["target"]["name"] == "btc_capi")
        .flat_map(|m| m["filenames"].as_array().cloned().unwrap_or_default())
        .filter_map(|f| f.as_str().map(PathBuf::from))
        .find(|f| f.extension().is_some_and(|e| e == "a"))
        .ok_or_else(|| "cargo built no libbtc_capi.a".to_owned())
}

fn cpp(repo: &Path) {
    let Some(prefix) = btc_testkit::btcpp() else {
        println!("embed (C++): skipped, no BehaviorTree.CPP 4.10");
        return;
    };
    let lib = match capi_library() {
        Ok(l) => l,
        Err(e) => {
            println!("embed (C++): the C API does not build: {e}");
            return;
        }
    };
    let build = btc_testkit::target_dir("bench/cpp");
    let lib = lib.display().to_string();
    if let Err(e) = btc_testkit::cmake_build(
        &repo.join("benches/cpp"),
        &build,
        &prefix,
        &[("BTC_CAPI_LIBRARY", lib.as_str())],
        &["btc_round"],
    ) {
        println!("embed (C++): the bench program does not build: {e}");
        return;
    }
    let status = Command::new(build.join("btc_round"))
        .arg(repo.join("examples/ariac"))
        .args(["--btc", env!("CARGO_BIN_EXE_btc")])
        .current_dir(&build)
        .status();
    match status {
        Ok(s) if s.success() => {}
        other => println!("embed (C++): the round failed or missed its target: {other:?}"),
    }
}
