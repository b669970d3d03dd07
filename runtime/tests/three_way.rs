//! One meaning in every executor: each job (every example with a plan, every
//! corpus plan of a domain with rules, every rules fixture of the py_trees
//! and parallel folders, the feature fixtures of `fixtures/three_way/` —
//! name patterns, guards, decorator arguments, control nodes, the three
//! step arrangements, derived predicates and fluents — and the rule-effect
//! fixture) runs three ways — the IR in btc's engine, the emitted
//! BT.CPP XML in btc's engine (SubTree mode and `--inline`), and the emitted
//! py_trees module under real py_trees — and all give the same step starts
//! and ends (with their ticks), the same final KB, the same status and the
//! same goal verdict.
//!
//! Needs `python3` with py_trees (skipped locally without it, required
//! under CI=true) and, for the corpus jobs, the corpus.

mod common;

use btc_emit::pytrees::{self, PyOptions, Runtime};
use btc_runtime::engine::TickEvent;
use btc_runtime::{Engine, Options, TreeDoc};
use common::{events, root, traced, Example};
use std::path::{Path, PathBuf};
use std::process::Command;

const MAX_TICKS: u64 = 100_000;

/// Jobs on which all executions agree but do not reach the goal, because
/// of the tree btc compiles, not of a target. An entry that starts
/// reaching its goal fails this test, so the list cannot outlive its
/// cause. (Empty since `steps backchained` skips a step only when a later
/// stage's sufficient condition holds.)
const KNOWN_UNREACHED: &[&str] = &[];

/// What a run ends with, in the form all three executions can give.
#[derive(Debug, PartialEq, serde::Deserialize)]
struct Outcome {
    status: String,
    goal_reached: bool,
    /// `(tick, "start" | "end", 1-based step)`
    events: Vec<(u64, String, usize)>,
    kb: Vec<String>,
}

fn engine_outcome(mut e: Engine<'_>) -> Outcome {
    let status = e.run(MAX_TICKS, |_| {});
    let events = events(&e)
        .iter()
        .filter_map(|t| match t {
            TickEvent::StepStarted { tick, step } => {
                Some((*tick, "start".to_owned(), *step as usize + 1))
            }
            TickEvent::StepFinished { tick, step } => {
                Some((*tick, "end".to_owned(), *step as usize + 1))
            }
            _ => None,
        })
        .collect();
    Outcome {
        status: status.name().to_owned(),
        goal_reached: e.goal().is_none_or(|(ok, _)| ok),
        events,
        kb: e.kb.as_ref().map(|kb| kb.snapshot()).unwrap_or_default(),
    }
}

fn work_dir(name: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR"))
        .join("three_way")
        .join(name);
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// The module with the runtime imported from beside it, run with `--json`.
fn pytrees_outcome(ex: &Example, name: &str) -> Outcome {
    let dir = work_dir(name);
    let text = pytrees::emit(
        &ex.ir,
        &PyOptions {
            runtime: Runtime::Import,
            ..PyOptions::default()
        },
    );
    std::fs::write(dir.join("module.py"), text).unwrap();
    std::fs::write(dir.join("btc_runtime.py"), pytrees::RUNTIME).unwrap();
    let out = Command::new("python3")
        .args(["module.py", "--json", "--max-ticks", &MAX_TICKS.to_string()])
        .current_dir(&dir)
        .env("PYTHONDONTWRITEBYTECODE", "1")
        .output()
        .expect("python3 runs");
    serde_json::from_slice(&out.stdout).unwrap_or_else(|e| {
        panic!(
            "{name}: {e}\n--- stdout\n{}\n--- stderr\n{}",
            String::from_utf8_lossy(&out.stdout),
            String::from_utf8_lossy(&out.stderr)
        )
    })
}

/// Runs `ex` three ways (four: XML in both modes) and compares.
fn three_ways(ex: &Example, name: &str) -> Outcome {
    let w = ex.world();
    let from_ir = engine_outcome(traced(ex.engine(
        &w,
        &TreeDoc::from_ir(&ex.ir),
        Options::default(),
    )));
    assert!(
        !from_ir.events.is_empty() || ex.ir.steps.iter().all(|s| s.skipped),
        "{name}: no step ran"
    );
    for inline in [false, true] {
        let xml = btc_emit::btcpp::emit(&ex.ir, inline);
        let from_xml = engine_outcome(traced(ex.engine(&w, &ex.xml(&xml), Options::default())));
        assert_eq!(
            from_ir, from_xml,
            "{name}: IR and XML (inline={inline}) differ"
        );
    }
    let from_py = pytrees_outcome(ex, name);
    if from_ir != from_py {
        let d = from_ir
            .events
            .iter()
            .zip(&from_py.events)
            .position(|(a, b)| a != b);
        panic!(
            "{name}: btc's engine and py_trees differ (first differing event {d:?})\n\
             engine:   {from_ir:?}\npy_trees: {from_py:?}"
        );
    }
    from_ir
}

/// A timed plan's order kept: for every two steps where one ends before
/// the other starts in the plan (within IPC's tolerance), the run ends the
/// first before it starts the second. With `concurrent` (`steps
/// scheduled`), steps the plan overlaps overlap in the run too (one starts
/// before the other ends): not every such pair, as a step starts when what
/// it waits for has ended, not at its time, and the actions take their
/// ticks rather than their durations; without (`steps`), none does. (Every
/// execution gives the same events, so checking one checks all three.)
fn follows_schedule(ex: &Example, o: &Outcome, name: &str, concurrent: bool) {
    let steps = &ex.ir.steps;
    if steps.is_empty() || steps.iter().any(|s| s.time.is_none()) {
        assert!(
            !concurrent,
            "{name}: `steps scheduled` jobs need a timed plan"
        );
        return;
    }
    let tol = btc_pddl::validate::DEFAULT_EPSILON / 10.0;
    let at = |what: &str, step: usize| {
        o.events
            .iter()
            .position(|(_, w, s)| w == what && *s == step)
            .unwrap_or_else(|| panic!("{name}: step {step} has no {what}"))
    };
    let span = |s: &btc_ir::StepInfo| {
        let t = s.time.unwrap_or(0.0);
        (t, t + s.duration.unwrap_or(0.0))
    };
    let mut overlapped = 0;
    for (i, a) in steps.iter().enumerate().filter(|(_, s)| !s.skipped) {
        for (j, b) in steps.iter().enumerate().filter(|(_, s)| !s.skipped) {
            let ((start_a, end_a), (start_b, end_b)) = (span(a), span(b));
            if i < j && end_a <= start_b + tol {
                assert!(
                    at("end", i + 1) < at("start", j + 1),
                    "{name}: step {} ends at {end_a} in the plan, before step {} starts at {start_b},                      but not in the run: {:?}",
                    i + 1,
                    j + 1,
                    o.events
                );
            } else if i < j && start_b < end_a - tol && start_a < end_b - tol {
                let run_overlaps =
                    at("start", j + 1) < at("end", i + 1) && at("start", i + 1) < at("end", j + 1);
                overlapped += usize::from(run_overlaps);
            }
        }
    }
    assert_eq!(
        concurrent,
        overlapped > 0,
        "{name}: {overlapped} pairs of steps the plan overlaps overlap in the run: {:?}",
        o.events
    );
}

/// Every `*.btrules` not starting with `_` in `dir`, with the folder's
/// problem and first plan.
fn folder_jobs(dir: &Path) -> Vec<(String, Example)> {
    let mut rules: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| n.ends_with(".btrules") && !n.starts_with('_'))
        .collect();
    rules.sort();
    let mut plans: Vec<PathBuf> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| {
            p.file_name()
                .is_some_and(|n| n.to_string_lossy().starts_with("plan."))
        })
        .collect();
    plans.sort();
    rules
        .into_iter()
        .map(|r| {
            let ex = common::load(&dir.join(&r), &plans[0], &dir.join("problem.pddl"));
            (r, ex)
        })
        .collect()
}

#[test]
fn examples_mean_the_same_in_every_executor() {
    if !btc_testkit::py_trees() {
        return;
    }
    // Every example folder with a rules file and a plan, found rather than
    // listed, so a new example is covered (`ariac_cell` has rules for the
    // trial's agents, which plan for themselves: no plan to compile).
    let mut dirs: Vec<PathBuf> = std::fs::read_dir(root().join("examples"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|d| d.join("rules.btrules").is_file())
        .collect();
    dirs.sort();
    for dir in &dirs {
        let name = dir.file_name().unwrap().to_string_lossy().into_owned();
        let ex = common::compile_dir(dir, &name);
        let o = three_ways(&ex, &format!("example_{name}"));
        assert_eq!(o.status, "SUCCESS", "{name}");
        assert!(o.goal_reached, "{name}");
    }
    assert!(
        dirs.len() >= common::EXAMPLES.len(),
        "examples went missing"
    );
}

#[test]
fn rules_fixtures_mean_the_same_in_every_executor() {
    if !btc_testkit::py_trees() {
        return;
    }
    let mut ran = 0;
    for folder in ["pytrees/workshop", "parallel"] {
        let dir = root().join("lang/tests/fixtures").join(folder);
        for (rules, ex) in folder_jobs(&dir) {
            let name = format!("{}_{}", folder.replace('/', "_"), rules.replace('.', "_"));
            let o = three_ways(&ex, &name);
            assert!(o.status == "SUCCESS" && o.goal_reached, "{name}: {o:?}");
            ran += 1;
        }
    }
    let dir = root().join("runtime/tests/fixtures/three_way");
    let mut folders: Vec<PathBuf> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.is_dir())
        .collect();
    folders.sort();
    // A rule whose effect differs from the PDDL action's: all three show
    // the rule's effect in the final KB.
    folders.push(root().join("runtime/tests/fixtures/rule_effect"));
    for f in folders {
        for (rules, ex) in folder_jobs(&f) {
            let name = format!(
                "feature_{}_{}",
                f.file_name().unwrap().to_string_lossy(),
                rules.replace('.', "_")
            );
            let o = three_ways(&ex, &name);
            follows_schedule(&ex, &o, &name, rules.starts_with("scheduled"));
            let reached = o.status == "SUCCESS" && o.goal_reached;
            if KNOWN_UNREACHED.contains(&name.as_str()) {
                assert!(
                    !reached,
                    "{name} reaches its goal now: take it out of KNOWN_UNREACHED"
                );
            } else {
                assert!(reached, "{name}: {o:?}");
            }
            ran += 1;
        }
    }
    assert!(ran >= 8, "only {ran} fixtures ran");
}

#[test]
fn corpus_plans_mean_the_same_in_every_executor() {
    let Some(domains) = btc_testkit::corpus_rules() else {
        return;
    };
    if !btc_testkit::py_trees() {
        return;
    }
    let mut ran = 0;
    for d in domains {
        for plan in &d.plans {
            let stem = plan.file_stem().unwrap().to_string_lossy().into_owned();
            let problem = d.corpus.join(format!("{stem}.pddl"));
            let ex = common::load(&d.rules, plan, &problem);
            let o = three_ways(&ex, &format!("corpus_{}_{stem}", d.name));
            assert!(o.goal_reached, "{} {stem}", d.name);
            ran += 1;
        }
    }
    assert!(ran >= 12, "only {ran} corpus plans");
}
