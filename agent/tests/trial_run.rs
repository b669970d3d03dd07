//! Trials on the bundled cell, end to end.

use btc_agent::cell::{self, Cell};
use btc_agent::sim::{Runner, TrialOptions};
use btc_agent::trial;
use btc_lang::db::{self, Database};
use btc_testkit::repo;

fn cell(db: &mut Database) -> Cell {
    let path = repo().join("examples/ariac_cell/cell.toml");
    match cell::load::load(db, &path, &mut |p| {
        std::fs::read_to_string(p).map_err(|e| e.to_string())
    }) {
        Ok(c) => c,
        Err(e) => panic!("{e:?}"),
    }
}

fn run(name: &str) -> btc_agent::sim::TrialReport {
    let mut db = Database::new();
    let c = cell(&mut db);
    let path = repo().join(format!("examples/ariac_cell/trials/{name}.yaml"));
    let text = std::fs::read_to_string(&path).unwrap();
    let f = db.set_file(&db::normalize(&path), text.clone());
    let (t, diags) = trial::read(&text, db::file_id(&db, f));
    assert!(diags.iter().all(|d| !d.is_error()), "{diags:#?}");
    let mut r = Runner::with_db(&c, db).unwrap_or_else(|e| panic!("{e:?}"));
    let opts = TrialOptions {
        check: true,
        ..TrialOptions::default()
    };
    r.run(&t.unwrap(), name, &opts)
        .unwrap_or_else(|e| panic!("{e:?}"))
}

#[test]
fn the_kitting_trial_scores_full_marks() {
    let r = run("kitting");
    println!("{}", serde_json::to_string_pretty(&r).unwrap());
    assert_eq!(r.score, r.best, "{r:#?}");
}

#[test]
fn the_assembly_trial_scores_full_marks() {
    let r = run("assembly");
    assert_eq!(
        r.score,
        r.best,
        "{}",
        serde_json::to_string_pretty(&r).unwrap()
    );
}

#[test]
fn the_combined_trial_scores_full_marks() {
    let r = run("combined");
    assert_eq!(
        r.score,
        r.best,
        "{}",
        serde_json::to_string_pretty(&r).unwrap()
    );
}
