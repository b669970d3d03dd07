//! The task level (`cargo bench -p btc-agent --bench trial`):
//! - `mixed_with_every_challenge`: the whole process of `btc trial` on
//!   `examples/ariac_cell/trials/mixed_challenges.yaml`: reading the trial
//!   and the cell's files, checking the rules, building the trial's
//!   problem, running the trial (target: under 20 ms);
//! - `soak_1000`: 1,000 seeded random soak trials on one runner (target:
//!   under 30 s on 2 cores).
//!
//! After divan's table, the time of one mixed trial is broken down
//! (planning, the rest) from its report.

use btc_agent::cell::{self, Cell};
use btc_agent::random;
use btc_agent::sim::{Runner, TrialOptions, TrialReport};
use btc_agent::trial;
use btc_lang::db::{self, Database};
use divan::Bencher;
use std::path::PathBuf;

#[global_allocator]
static GLOBAL: mimalloc::MiMalloc = mimalloc::MiMalloc;

fn main() {
    divan::main();
    let r = whole();
    let planning: f64 = r.agents.iter().map(|a| a.planning_ms).sum();
    let plans: usize = r.agents.iter().map(|a| a.plans).sum();
    println!(
        "mixed_challenges: {:.2} ms run, of which planning {planning:.2} ms ({plans} plans); {} ticks, score {} of {}",
        r.elapsed_ms, r.ticks, r.score, r.best
    );
    println!(
        "targets: mixed_with_every_challenge under 20 ms; soak_1000 under 30 s (the medians above)"
    );
}

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("..")
}

fn read(p: &std::path::Path) -> Result<String, String> {
    std::fs::read_to_string(p).map_err(|e| e.to_string())
}

fn load(db: &mut Database) -> Cell {
    cell::load::load(db, &root().join("examples/ariac_cell/cell.toml"), &mut read).unwrap()
}

/// Everything `btc trial mixed_challenges.yaml` does but print.
fn whole() -> TrialReport {
    let mut db = Database::new();
    let c = load(&mut db);
    let path = root().join("examples/ariac_cell/trials/mixed_challenges.yaml");
    let text = read(&path).unwrap();
    let f = db.set_file(&path, text.clone());
    let (t, _) = trial::read(&text, db::file_id(&db, f));
    let mut r = Runner::with_db(&c, db).unwrap();
    r.run(&t.unwrap(), "mixed_challenges", &TrialOptions::default())
        .unwrap()
}

#[divan::bench(sample_count = 20)]
fn mixed_with_every_challenge(b: Bencher) {
    b.bench(whole);
}

#[divan::bench(sample_count = 1, sample_size = 1)]
fn soak_1000(b: Bencher) {
    b.bench(|| {
        let mut db = Database::new();
        let c = load(&mut db);
        let mut r = Runner::with_db(&c, db).unwrap();
        let mut n = 0;
        for seed in 1..=1000 {
            let opts = TrialOptions {
                seed,
                ..TrialOptions::default()
            };
            n += r
                .run(&random::soak(seed), "soak", &opts)
                .unwrap()
                .tasks
                .len();
        }
        n
    });
}
