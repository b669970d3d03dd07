//! The soak test: seeded random trials (random orders, supplies and
//! challenge mixes, `btc_agent::random::soak`) on the bundled cell, with
//! the world checked after every tick (each part in exactly one place, no
//! resource held by two tasks, no robot holding two things). No trial may
//! panic, break the world or lose a part task: each ends done, or failed
//! with its cause.
//!
//! `BTC_SOAK_TRIALS` sets the number of trials. By default CI (`CI=true`)
//! runs the 1,000 (about two minutes in a debug build) and a local
//! `cargo test` 100, which run in seconds.

use btc_agent::cell;
use btc_agent::random;
use btc_agent::sim::tasks::TaskState;
use btc_agent::sim::{Runner, TrialError, TrialOptions};
use btc_lang::db::Database;

#[test]
fn random_trials_never_break_the_world_nor_lose_a_part_task() {
    let n: u64 = std::env::var("BTC_SOAK_TRIALS")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(if btc_testkit::required() { 1000 } else { 100 });
    let mut db = Database::new();
    let path = btc_testkit::repo().join("examples/ariac_cell/cell.toml");
    let c = cell::load::load(&mut db, &path, &mut |p| {
        std::fs::read_to_string(p).map_err(|e| e.to_string())
    })
    .unwrap_or_else(|e| panic!("{e:?}"));
    let mut runner = Runner::with_db(&c, db).unwrap_or_else(|e| panic!("{e:?}"));
    let t0 = std::time::Instant::now();
    let (mut tasks, mut failed, mut orders, mut submitted) = (0, 0, 0, 0);
    for seed in 1..=n {
        let trial = random::soak(seed);
        let opts = TrialOptions {
            seed,
            check: true,
            ..TrialOptions::default()
        };
        let r = match runner.run(&trial, &format!("soak {seed}"), &opts) {
            Ok(r) => r,
            Err(TrialError::Inconsistent { tick, what }) => {
                panic!("seed {seed}: the world broke at tick {tick}: {what}")
            }
            Err(e) => panic!("seed {seed}: {e:?}"),
        };
        for t in &r.tasks {
            tasks += 1;
            match &t.state {
                TaskState::Done { .. } | TaskState::Split { .. } => {}
                TaskState::Failed { cause, .. } => {
                    failed += 1;
                    assert!(
                        !cause.is_empty(),
                        "seed {seed}: task {} failed without a cause",
                        t.id
                    );
                }
                open => panic!("seed {seed}: task {} was lost ({open:?})", t.id),
            }
        }
        orders += r.orders.len();
        submitted += r.orders.iter().filter(|o| o.submitted.is_some()).count();
    }
    eprintln!(
        "soak: {n} trials in {:.1} s; {tasks} part tasks ({failed} failed with a cause); {submitted} of {orders} orders submitted",
        t0.elapsed().as_secs_f64()
    );
}
