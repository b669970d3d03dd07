//! `btc plan` on domains with durative actions writes timed plans that VAL
//! (the reference validator, built from `../shared/vendor/`) accepts: the
//! sequential plan scheduled so that steps run as early as the steps they
//! interfere with allow. Prints each plan's makespan against the sum of
//! its durations.

mod common;

use btc_planner::{Options, Outcome};
use common::*;
use std::path::PathBuf;
use std::process::Command;

/// Every durative domain the tests know: the corpus's (found by walking
/// it), the P3 example's, and the PlanSys2-style factory of
/// `btc-pddl`'s fixtures (one car with three robots, three cars).
fn durative_cases() -> Vec<(String, PathBuf, PathBuf)> {
    let repo = repo_dir();
    let factory = repo.join("pddl/tests/fixtures/timed");
    let mut out = vec![
        (
            "p3_assembler".to_owned(),
            repo.join("examples/p3_assembler/domain.pddl"),
            repo.join("examples/p3_assembler/problem.pddl"),
        ),
        (
            "factory p1".to_owned(),
            factory.join("domain.pddl"),
            factory.join("p1.pddl"),
        ),
        (
            "factory p3 (3 robots, 3 cars)".to_owned(),
            factory.join("domain.pddl"),
            factory.join("p3.pddl"),
        ),
    ];
    if let Some(cases) = btc_testkit::corpus_cases() {
        for c in cases {
            let text = std::fs::read_to_string(&c.domain).unwrap();
            if text.to_lowercase().contains(":durative-action") {
                out.push((c.problem.display().to_string(), c.domain, c.problem));
            }
        }
    }
    out
}

#[test]
fn planned_timed_plans_are_valid_for_val() {
    let Some(val) = btc_testkit::val() else {
        return;
    };
    let dir = std::env::temp_dir().join(format!("btc-timed-plans-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    for (n, (name, domain, problem)) in durative_cases().into_iter().enumerate() {
        let mut l = load(&domain, &problem);
        let (text, _, report) = l.solve_and_validate(&Options::default());
        let Outcome::Plan(plan) = &report.outcome else {
            unreachable!("solve_and_validate found a plan")
        };
        let s = l.schedule(plan).expect("a durative domain");
        assert!(
            !s.serialized,
            "{name}: the deordered schedule did not validate"
        );
        let file = dir.join(format!("{n}.tplan"));
        std::fs::write(&file, &text).unwrap();
        let out = Command::new(&val)
            .args(["-t", "0.001"])
            .args([&domain, &problem, &file])
            .output()
            .unwrap();
        let said = String::from_utf8_lossy(&out.stdout);
        assert!(
            said.lines().any(|l| l.trim() == "Plan valid"),
            "{name}: VAL rejects\n{text}\nVAL says:\n{said}"
        );
        // Never longer than the steps one after another (but for the
        // separations between them).
        let gaps = plan.steps.len() as f64 * btc_pddl::validate::DEFAULT_EPSILON;
        assert!(s.makespan <= s.sequential + gaps + 1e-9, "{name}: {s:?}");
        eprintln!(
            "{name}: {} steps, makespan {:.3}, the steps one after another {:.3}",
            plan.steps.len(),
            s.makespan,
            s.sequential
        );
    }
    let _ = std::fs::remove_dir_all(&dir);
}
