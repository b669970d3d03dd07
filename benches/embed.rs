//! One plan -> tree round on the ARIAC part task as an embedding agent meets
//! it (`cargo bench --bench embed`): plan, compile, build the py_trees tree,
//! in-process from Python through the `btc` package, and by the subprocess
//! route (`btc plan`, `btc compile --emit pytrees`, import the module) in
//! the same run; target p50 under 1 ms in-process. The Python side is
//! `python/bench/round.py`; `BTC_PYTHON` names a Python with the package
//! installed (`pip install ./python`), else `python3`. In-process from C++
//! is not measured: the C++ agent does not exist yet.

use std::path::Path;
use std::process::Command;

fn main() {
    let repo = Path::new(env!("CARGO_MANIFEST_DIR"));
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
