//! Timed plans from `btc plan` against temporal planners from the package
//! index (`cargo bench --bench makespan`): on every durative domain btc's
//! tests know (the P3 example, the PlanSys2-style factory with one car and
//! with three cars and three robots, and the corpus's durative domains),
//! each planner's makespan, btc's against the sum of its steps' durations
//! (what a sequential executor takes), and the wall-clock time of each,
//! whole process, in the same run.
//!
//! The peers are unified-planning's engines (`pip install unified-planning
//! up-tamer up-aries up-lpg`), run by `benches/temporal/peer.py`; one not
//! installed is said so, and one that runs past `BTC_PEER_SECONDS`
//! (default 60; Tamer ignores timeouts) is stopped and shown as out of
//! time. Every plan shown is first checked by `btc validate` (and by VAL
//! when `BTC_VAL` names its `Validate`): a plan a validator rejects shows
//! as rejected, not as a figure.

use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

const BTC: &str = env!("CARGO_BIN_EXE_btc");
const PEERS: [&str; 3] = ["tamer", "aries", "lpg"];

fn repo() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// `(name, domain, problem)` of every durative case.
fn cases() -> Vec<(String, PathBuf, PathBuf)> {
    let r = repo();
    let factory = r.join("pddl/tests/fixtures/timed");
    let mut out = vec![
        (
            "p3_assembler".to_owned(),
            r.join("examples/p3_assembler/domain.pddl"),
            r.join("examples/p3_assembler/problem.pddl"),
        ),
        (
            "factory, 1 car".to_owned(),
            factory.join("domain.pddl"),
            factory.join("p1.pddl"),
        ),
        (
            "factory, 3 cars, 3 robots".to_owned(),
            factory.join("domain.pddl"),
            factory.join("p3.pddl"),
        ),
    ];
    if let Some(cases) = btc_testkit::corpus_cases() {
        for c in cases {
            let text = std::fs::read_to_string(&c.domain).unwrap_or_default();
            if text.to_lowercase().contains(":durative-action") {
                out.push((c.problem.display().to_string(), c.domain, c.problem));
            }
        }
    }
    out
}

/// What a planner came to on a case.
enum Outcome {
    Plan {
        makespan: f64,
        seconds: f64,
        text: String,
    },
    NoPlan(String),
    Skipped(String),
}

/// btc's plan, and the sum of its steps' durations.
fn btc_plan(domain: &Path, problem: &Path) -> (Outcome, Option<f64>) {
    let t = Instant::now();
    let out = Command::new(BTC)
        .args(["plan", "--format", "json"])
        .arg(domain)
        .arg(problem)
        .output()
        .expect("btc runs");
    let seconds = t.elapsed().as_secs_f64();
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap_or_default();
    let outcome = match (v["plan"]["makespan"].as_f64(), v["plan"]["plan"].as_str()) {
        (Some(makespan), Some(text)) => Outcome::Plan {
            makespan,
            seconds,
            text: text.to_owned(),
        },
        _ => Outcome::NoPlan(String::from_utf8_lossy(&out.stderr).trim().to_owned()),
    };
    (outcome, v["plan"]["sequential_duration"].as_f64())
}

fn peer(name: &str, domain: &Path, problem: &Path, limit: Duration) -> Outcome {
    let mut child = match Command::new("python3")
        .arg(repo().join("benches/temporal/peer.py"))
        .arg(name)
        .arg(domain)
        .arg(problem)
        .stdout(Stdio::piped())
        .stderr(Stdio::null())
        .spawn()
    {
        Ok(c) => c,
        Err(e) => return Outcome::Skipped(format!("python3: {e}")),
    };
    let t = Instant::now();
    loop {
        if let Ok(Some(_)) = child.try_wait() {
            break;
        }
        if t.elapsed() > limit {
            let _ = child.kill();
            let _ = child.wait();
            return Outcome::NoPlan(format!("out of time ({} s)", limit.as_secs()));
        }
        std::thread::sleep(Duration::from_millis(20));
    }
    let out = child.wait_with_output().expect("the peer's output");
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap_or_default();
    if let Some(s) = v["skipped"].as_str() {
        return Outcome::Skipped(s.to_owned());
    }
    match (
        v["makespan"].as_f64(),
        v["seconds"].as_f64(),
        v["plan"].as_array(),
    ) {
        (Some(makespan), Some(seconds), Some(steps)) => Outcome::Plan {
            makespan,
            seconds,
            text: steps
                .iter()
                .filter_map(|s| s.as_str())
                .map(|s| format!("{s}\n"))
                .collect(),
        },
        _ => Outcome::NoPlan(v["status"].as_str().unwrap_or("no plan").to_owned()),
    }
}

/// Whether `btc validate` (and VAL, with `BTC_VAL`) accept the timed plan.
fn rejected_by(domain: &Path, problem: &Path, plan: &str, n: usize) -> Option<&'static str> {
    let file = std::env::temp_dir().join(format!("btc-makespan-{}-{n}.tplan", std::process::id()));
    std::fs::write(&file, plan).expect("a temporary plan file");
    let btc_ok = Command::new(BTC)
        .arg("validate")
        .args([domain, problem, &file])
        .output()
        .is_ok_and(|o| o.status.success());
    let val_ok = std::env::var_os("BTC_VAL").is_none_or(|val| {
        Command::new(val)
            .args(["-t", "0.001"])
            .args([domain, problem, &file])
            .output()
            .is_ok_and(|o| {
                String::from_utf8_lossy(&o.stdout)
                    .lines()
                    .any(|l| l.trim() == "Plan valid")
            })
    });
    let _ = std::fs::remove_file(&file);
    match (btc_ok, val_ok) {
        (true, true) => None,
        (false, _) => Some("btc validate"),
        (true, false) => Some("VAL"),
    }
}

fn main() {
    let limit = Duration::from_secs(
        std::env::var("BTC_PEER_SECONDS")
            .ok()
            .and_then(|v| v.parse().ok())
            .unwrap_or(60),
    );
    let mut n = 0;
    println!("makespan of timed plans (whole process; `btc validate` checks each plan shown)");
    for (name, domain, problem) in cases() {
        println!("\n{name}");
        let (btc, sum) = btc_plan(&domain, &problem);
        if let Some(s) = sum {
            println!("  {:<8} {s:>9.3}  (btc's steps one after another)", "sum");
        }
        let mut runs = vec![("btc".to_owned(), btc)];
        for p in PEERS {
            runs.push((p.to_owned(), peer(p, &domain, &problem, limit)));
        }
        for (who, r) in runs {
            n += 1;
            match r {
                Outcome::Plan {
                    makespan,
                    seconds,
                    text,
                } => match rejected_by(&domain, &problem, &text, n) {
                    None => println!("  {who:<8} {makespan:>9.3}  in {seconds:.3} s"),
                    Some(v) => println!("  {who:<8} {:>9}  (its plan is rejected by {v})", "-"),
                },
                Outcome::NoPlan(why) => println!("  {who:<8} {:>9}  ({why})", "-"),
                Outcome::Skipped(how) => println!("  {who:<8} {:>9}  (not installed: {how})", "-"),
            }
        }
    }
}
