//! The closed loop on ARIAC (`cargo bench -p btc-runtime --bench replan`):
//! one full cycle plan -> compile -> run -> fault -> replan -> compile ->
//! run, with the flipped-part and robot-malfunction scenarios:
//! - `cold`: a fresh database each time (rules, domain and problem parsed
//!   and checked, as one `btc run --replan` does);
//! - `warm`: the same database reused (only the plan text changes, as in a
//!   long-running agent), so salsa re-does only what the plan changes.

use btc_agent::faults::Scenario;
use btc_agent::{run_loop, LoopOptions};
use btc_lang::db::{CompileJob, Database};
use divan::Bencher;
use std::path::PathBuf;

#[global_allocator]
static GLOBAL: mimalloc::MiMalloc = mimalloc::MiMalloc;

fn main() {
    divan::main();
    report();
}

/// Where the time of one cycle goes (warm database, median of 200 runs).
fn report() {
    for name in SCENARIOS {
        let sc = scenario(name);
        let opts = LoopOptions::default();
        let (mut db, job) = ariac();
        let mut rows: Vec<[f64; 4]> = (0..200)
            .map(|_| {
                db.set_file("(planned).sas_plan", String::new());
                let s = run_loop(&mut db, job, false, Some(&sc), &opts).unwrap();
                let sum = |f: fn(&btc_agent::replan::Attempt) -> f64| -> f64 {
                    s.attempts.iter().map(f).sum()
                };
                [
                    s.elapsed_ms,
                    sum(|a| a.planning_ms),
                    sum(|a| a.compile_ms),
                    sum(|a| a.run_ms),
                ]
            })
            .collect();
        rows.sort_by(|a, b| a[0].total_cmp(&b[0]));
        let m = rows[rows.len() / 2];
        println!(
            "{name}: whole loop {:.3} ms: planning {:.3} ms (2 plans), compiling {:.3} ms, running {:.3} ms",
            m[0], m[1], m[2], m[3]
        );
    }
}

fn dir() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../examples/ariac")
}

fn ariac() -> (Database, CompileJob) {
    let mut db = Database::new();
    let mut load = |name: &str| {
        let p = dir().join(name);
        db.set_file(&p, std::fs::read_to_string(&p).unwrap())
    };
    let rules = load("rules.btrules");
    let domain = load("domain.pddl");
    let problem = load("problem.pddl");
    let plan = db.set_file("(planned).sas_plan", String::new());
    let job = CompileJob::new(&db, rules, plan, Some(problem), Some(domain));
    (db, job)
}

fn scenario(name: &str) -> Scenario {
    let p = dir().join(format!("faults/{name}.toml"));
    Scenario::parse(&std::fs::read_to_string(p).unwrap()).unwrap()
}

const SCENARIOS: &[&str] = &["flipped_part", "robot_malfunction"];

#[divan::bench(args = SCENARIOS)]
fn cold(b: Bencher, name: &str) {
    let sc = scenario(name);
    let opts = LoopOptions::default();
    b.bench(|| {
        let (mut db, job) = ariac();
        let s = run_loop(&mut db, job, false, Some(&sc), &opts).unwrap();
        assert!(s.success() && s.replans.len() == 1);
    });
}

#[divan::bench(args = SCENARIOS)]
fn warm(b: Bencher, name: &str) {
    let sc = scenario(name);
    let opts = LoopOptions::default();
    let (mut db, job) = ariac();
    b.bench_local(|| {
        db.set_file("(planned).sas_plan", String::new());
        let s = run_loop(&mut db, job, false, Some(&sc), &opts).unwrap();
        assert!(s.success() && s.replans.len() == 1);
    });
}
