//! The planner as a user meets it: whole processes (`cargo bench --bench
//! planner_process`), each figure printed beside its target and the peer's
//! figure from the same run (or "peer not installed"):
//! - `btc --version` (target: under 1 ms);
//!
//! The binary measured is the shipped one, as `dist/build-release.sh`
//! builds it (static on Linux; `BTC_BIN` names another), when it is
//! there; else, with a note, cargo's own (dynamically linked) build.
//! `--version` and the ARIAC plan are timed for both when both exist.
//! - `btc plan` on the ARIAC per-part problem against `pyperplan`
//!   (target: at least 40 times faster);
//! - `btc plan` on every corpus problem and the held-out problems
//!   (`BTC_HELDOUT`, default `target/heldout/`, which
//!   `planner/benches/heldout.sh` assembles) against Fast Downward's `lama-first` (from
//!   the `up-fast-downward` wheel; `BTC_FAST_DOWNWARD` names another
//!   `fast-downward.py`): time at most lama-first's, plan cost at most its
//!   cost.
//!
//! Times are medians of `BTC_BENCH_RUNS` runs (default 5). The problems
//! run one after another, never in parallel, so the peers and btc see the
//! same machine. `BTC_BENCH_FILTER=text` keeps the problems whose name
//! contains it.

use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

/// cargo's build of `btc` for this bench (dynamically linked).
const CARGO_BTC: &str = env!("CARGO_BIN_EXE_btc");

/// The shipped binary: `BTC_BIN`, else `target/<triple>/release/btc` as
/// `dist/build-release.sh` leaves it.
fn shipped() -> Option<PathBuf> {
    if let Some(p) = std::env::var_os("BTC_BIN") {
        return Some(PathBuf::from(p));
    }
    let mut found: Vec<PathBuf> = std::fs::read_dir(repo().join("target"))
        .ok()?
        .flatten()
        .map(|e| e.path().join("release/btc"))
        .filter(|p| p.is_file())
        .collect();
    found.sort();
    found.pop()
}

/// The binary the figures are for (see the module's comment).
fn btc() -> &'static Path {
    static BIN: std::sync::OnceLock<PathBuf> = std::sync::OnceLock::new();
    BIN.get_or_init(|| shipped().unwrap_or_else(|| PathBuf::from(CARGO_BTC)))
}

fn repo() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn runs() -> usize {
    std::env::var("BTC_BENCH_RUNS")
        .ok()
        .and_then(|v| v.parse().ok())
        .filter(|&n| n > 0)
        .unwrap_or(5)
}

/// A problem: its name, domain and problem files.
struct Case {
    name: String,
    domain: PathBuf,
    problem: PathBuf,
}

/// `domain/pNN` problems of a corpus-shaped folder (`<domain>/pNN.pddl`
/// with `domain.pddl` or `pNN-domain.pddl` beside it).
fn cases(root: &Path, prefix: &str) -> Vec<Case> {
    let mut out = Vec::new();
    let Ok(rd) = std::fs::read_dir(root) else {
        return out;
    };
    let mut dirs: Vec<PathBuf> = rd
        .flatten()
        .map(|e| e.path())
        .filter(|p| p.is_dir())
        .collect();
    dirs.sort();
    for dir in dirs {
        let dname = dir.file_name().unwrap().to_string_lossy().into_owned();
        let mut stems: Vec<String> = std::fs::read_dir(&dir)
            .into_iter()
            .flatten()
            .flatten()
            .map(|e| e.file_name().to_string_lossy().into_owned())
            .filter(|n| n.starts_with('p') && n.ends_with(".pddl") && !n.contains("domain"))
            .map(|n| n.trim_end_matches(".pddl").to_owned())
            .collect();
        stems.sort();
        for stem in stems {
            let own = dir.join(format!("{stem}-domain.pddl"));
            let domain = if own.exists() {
                own
            } else {
                dir.join("domain.pddl")
            };
            out.push(Case {
                name: format!("{prefix}{dname}/{stem}"),
                problem: dir.join(format!("{stem}.pddl")),
                domain,
            });
        }
    }
    out
}

/// The median of `n` runs of `f`, which returns the elapsed time and what
/// the run produced (kept from the last run).
fn median<T>(n: usize, mut f: impl FnMut() -> Option<(Duration, T)>) -> Option<(Duration, T)> {
    let mut times = Vec::new();
    let mut last = None;
    for _ in 0..n {
        let (t, v) = f()?;
        times.push(t);
        last = Some(v);
    }
    times.sort();
    Some((times[times.len() / 2], last?))
}

fn timed(cmd: &mut Command) -> Option<(Duration, std::process::Output)> {
    let start = Instant::now();
    let out = cmd.stdin(Stdio::null()).output().ok()?;
    Some((start.elapsed(), out))
}

/// The cost in a `sas_plan` file's `; cost = N` line.
fn plan_cost(text: &str) -> Option<f64> {
    text.lines()
        .find_map(|l| l.trim().strip_prefix("; cost = "))
        .and_then(|rest| rest.split_whitespace().next())
        .and_then(|n| n.parse().ok())
}

fn scratch(tag: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("btc-bench-{}-{tag}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// `btc plan`, the plan to stdout (as `btc plan D P > plan`): time and
/// plan cost.
fn btc_plan(c: &Case) -> Option<(Duration, Option<f64>)> {
    btc_plan_with(btc(), c)
}

fn btc_plan_with(bin: &Path, c: &Case) -> Option<(Duration, Option<f64>)> {
    let (t, out) = timed(
        Command::new(bin)
            .arg("plan")
            .arg(&c.domain)
            .arg(&c.problem)
            .arg("--quiet")
            .stderr(Stdio::null()),
    )?;
    let cost = out
        .status
        .success()
        .then(|| String::from_utf8(out.stdout).ok())
        .flatten()
        .and_then(|p| plan_cost(&p));
    Some((t, cost))
}

/// Fast Downward's `fast-downward.py`: `BTC_FAST_DOWNWARD`, or the one in
/// the `up-fast-downward` wheel of `python3`.
fn fast_downward() -> Option<PathBuf> {
    if let Some(p) = std::env::var_os("BTC_FAST_DOWNWARD") {
        return Some(PathBuf::from(p));
    }
    // find_spec locates the package without importing it (its __init__
    // needs unified_planning, which the driver does not).
    let out = Command::new("python3")
        .args([
            "-c",
            "import importlib.util as u; s = u.find_spec('up_fast_downward'); \
             print(s.submodule_search_locations[0] if s else '')",
        ])
        .output()
        .ok()?;
    let dir = String::from_utf8(out.stdout).ok()?;
    let p = Path::new(dir.trim()).join("downward/fast-downward.py");
    (!dir.trim().is_empty() && p.exists()).then_some(p)
}

/// `lama-first`, run in its own folder (it writes `output.sas` and the
/// plan there): time and plan cost.
fn lama_first(fd: &Path, c: &Case, dir: &Path) -> Option<(Duration, Option<f64>)> {
    let _ = std::fs::remove_file(dir.join("sas_plan"));
    let (t, out) = timed(
        Command::new("python3")
            .arg(fd)
            .args(["--alias", "lama-first", "--plan-file", "sas_plan"])
            .arg(&c.domain)
            .arg(&c.problem)
            .current_dir(dir)
            .stdout(Stdio::null())
            .stderr(Stdio::null()),
    )?;
    let _ = out;
    let cost = std::fs::read_to_string(dir.join("sas_plan"))
        .ok()
        .and_then(|p| plan_cost(&p));
    Some((t, cost))
}

fn has_pyperplan() -> bool {
    Command::new("pyperplan")
        .arg("--help")
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .status()
        .is_ok_and(|s| s.success())
}

fn ms(d: Duration) -> f64 {
    d.as_secs_f64() * 1e3
}

fn version() {
    match shipped() {
        Some(p) => println!("binary: {} (the shipped build)", p.display()),
        None => println!(
            "binary: cargo's dynamically linked build; `dist/build-release.sh` builds the shipped \
             one, which starts faster"
        ),
    }
    let n = 50;
    let (t, _) = median(n, || timed(Command::new(btc()).arg("--version"))).expect("btc runs");
    println!(
        "btc --version: {:.2} ms (median of {n}; target: under 1 ms) {}",
        ms(t),
        if t < Duration::from_millis(1) {
            "ok"
        } else {
            "MISSED"
        }
    );
    if btc() != Path::new(CARGO_BTC) {
        let (t, _) =
            median(n, || timed(Command::new(CARGO_BTC).arg("--version"))).expect("btc runs");
        println!("  (cargo's dynamically linked build: {:.2} ms)", ms(t));
    }
    // What starting any process costs here, measured the same way: the
    // floor under the figure above.
    if let Some((t, _)) = median(n, || timed(&mut Command::new("true"))) {
        println!("  (`true`, a process that does nothing: {:.2} ms)", ms(t));
    }
}

fn ariac() {
    let dir = scratch("ariac");
    let ex = repo().join("examples/ariac");
    // pyperplan writes its solution beside the problem: plan copies.
    for f in ["domain.pddl", "problem.pddl"] {
        std::fs::copy(ex.join(f), dir.join(f)).unwrap();
    }
    let case = Case {
        name: "ariac".into(),
        domain: dir.join("domain.pddl"),
        problem: dir.join("problem.pddl"),
    };
    let n = 4 * runs() + 1;
    let (ours, _) = median(n, || btc_plan(&case)).expect("btc runs");
    print!(
        "btc plan examples/ariac: {:.2} ms (median of {n}; target: at least 40x pyperplan)",
        ms(ours)
    );
    if has_pyperplan() {
        let (peer, _) = median(runs(), || {
            timed(
                Command::new("pyperplan")
                    .arg(&case.domain)
                    .arg(&case.problem)
                    .stdout(Stdio::null())
                    .stderr(Stdio::null()),
            )
        })
        .expect("pyperplan runs");
        let x = peer.as_secs_f64() / ours.as_secs_f64();
        println!(
            "; pyperplan {:.1} ms: {x:.1}x {}",
            ms(peer),
            if x >= 40.0 { "ok" } else { "MISSED" }
        );
    } else {
        println!("; pyperplan: peer not installed");
    }
    if btc() != Path::new(CARGO_BTC) {
        let bin = Path::new(CARGO_BTC);
        let (t, _) = median(n, || btc_plan_with(bin, &case)).expect("btc runs");
        println!("  (cargo's dynamically linked build: {:.2} ms)", ms(t));
    }
    let _ = std::fs::remove_dir_all(&dir);
}

fn corpus() {
    let filter = std::env::var("BTC_BENCH_FILTER").unwrap_or_default();
    let corpus = std::env::var_os("BTC_CORPUS")
        .map(PathBuf::from)
        .unwrap_or_else(|| repo().join("../shared/corpus/ipc"));
    let mut all = cases(&corpus, "");
    if all.is_empty() {
        println!("corpus: {} is not there, skipped", corpus.display());
    }
    let heldout = std::env::var_os("BTC_HELDOUT")
        .map(PathBuf::from)
        .unwrap_or_else(|| repo().join("target/heldout"));
    let held = cases(&heldout, "heldout/");
    if held.is_empty() {
        println!(
            "held-out problems: {} is not there, skipped (planner/benches/heldout.sh assembles them)",
            heldout.display()
        );
    }
    all.extend(held);
    all.retain(|c| c.name.contains(&filter));
    let fd = fast_downward();
    let dir = scratch("corpus");
    println!(
        "\nbtc plan against lama-first, whole process, median of {} (target: time and cost at most lama-first's){}",
        runs(),
        if fd.is_none() {
            "; lama-first: peer not installed"
        } else {
            ""
        }
    );
    println!(
        "{:<28} {:>9} {:>9} {:>9} {:>9}  verdict",
        "problem", "btc ms", "lama ms", "btc cost", "lama cost"
    );
    let (mut faster, mut cheaper, mut compared) = (0, 0, 0);
    let show = |c: Option<f64>| c.map_or_else(|| "-".to_owned(), |c| format!("{c}"));
    for c in &all {
        let Some((ours, cost)) = median(runs(), || btc_plan(c)) else {
            println!("{:<28} btc did not run", c.name);
            continue;
        };
        let peer = fd
            .as_ref()
            .and_then(|fd| median(runs(), || lama_first(fd, c, &dir)));
        match peer {
            Some((pt, pc)) => {
                compared += 1;
                let time_ok = ours <= pt;
                let cost_ok = match (cost, pc) {
                    (Some(a), Some(b)) => a <= b,
                    (Some(_), None) => true,
                    _ => false,
                };
                faster += time_ok as usize;
                cheaper += cost_ok as usize;
                let verdict = match (time_ok, cost_ok) {
                    (true, true) => "ok",
                    (false, true) => "SLOWER",
                    (true, false) => "COSTLIER",
                    (false, false) => "SLOWER COSTLIER",
                };
                println!(
                    "{:<28} {:>9.1} {:>9.1} {:>9} {:>9}  {verdict}",
                    c.name,
                    ms(ours),
                    ms(pt),
                    show(cost),
                    show(pc)
                );
            }
            None => println!(
                "{:<28} {:>9.1} {:>9} {:>9} {:>9}",
                c.name,
                ms(ours),
                "-",
                show(cost),
                "-"
            ),
        }
    }
    if compared > 0 {
        println!(
            "time at most lama-first's on {faster} of {compared}; cost at most its cost on {cheaper} of {compared}"
        );
    }
    let _ = std::fs::remove_dir_all(&dir);
}

fn main() {
    // `cargo bench` passes `--bench`; a filter argument is not used.
    version();
    ariac();
    corpus();
}
