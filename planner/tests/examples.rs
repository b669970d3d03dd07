//! The planner on the repository's examples and small fixtures: plans that
//! validate, planning from a knowledge-base state, and the diagnostics for
//! what it refuses.

mod common;

use btc_pddl::state::World;
use btc_planner::{Algorithm, Heuristic, Options, Outcome};
use common::*;
use std::path::PathBuf;
use std::time::Duration;

fn example(name: &str) -> (PathBuf, PathBuf) {
    let dir = repo_dir().join("examples").join(name);
    (dir.join("domain.pddl"), dir.join("problem.pddl"))
}

fn fixture(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("tests/fixtures")
        .join(name)
}

#[test]
fn every_example_is_planned_with_valid_plans() {
    let mut dirs: Vec<_> = std::fs::read_dir(repo_dir().join("examples"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.join("domain.pddl").exists() && p.join("problem.pddl").exists())
        .collect();
    dirs.sort();
    assert!(dirs.len() >= 4, "examples: {dirs:?}");
    for dir in dirs {
        let mut l = load(&dir.join("domain.pddl"), &dir.join("problem.pddl"));
        for algorithm in [Algorithm::Gbfs, Algorithm::Astar] {
            let opts = Options {
                algorithm,
                ..Options::default()
            };
            let (text, _, _) = l.solve_and_validate(&opts);
            assert!(text.ends_with("(unit cost)\n"), "{}: {text}", dir.display());
        }
    }
}

#[test]
fn the_ariac_part_task_is_the_four_step_plan() {
    let (d, p) = example("ariac");
    let mut l = load(&d, &p);
    let opts = Options {
        algorithm: Algorithm::Astar,
        heuristic: Heuristic::Max,
        timeout: None,
        ..Options::default()
    };
    let (text, cost, _) = l.solve_and_validate(&opts);
    assert_eq!(
        text,
        "(move floor_robot curr_position bin1)\n(grasp floor_robot battery_red bin1)\n\
         (move floor_robot bin1 agv1)\n(place floor_robot battery_red agv1)\n; cost = 4 (unit cost)\n"
    );
    assert_eq!(cost, 4.0);
}

#[test]
fn the_p3_durative_domain_is_planned_and_scheduled() {
    let (d, p) = example("p3_assembler");
    let mut l = load(&d, &p);
    let (text, _, _) = l.solve_and_validate(&Options::default());
    for op in ["place_op1", "place_op2", "place_op3"] {
        assert!(text.contains(op), "{text}");
    }
}

/// Replanning starts from a knowledge base, not from `:init`: here the
/// part is already in the gripper, so the plan only moves and places it.
#[test]
fn planning_from_a_knowledge_base_state() {
    let (d, p) = example("ariac");
    let l = load(&d, &p);
    let (domain, problem) = (
        l.du.domain.as_ref().unwrap(),
        l.pu.problem.as_ref().unwrap(),
    );
    let world = World::of_checked(domain, &l.du.index, problem, &l.pu.index).unwrap();
    let mut kb = world.initial_state();
    let key = |pred: &str, args: &[&str]| -> Box<[u32]> {
        let mut k = vec![l.du.index.predicates[pred].index as u32];
        k.extend(args.iter().map(|a| l.pu.index.objects[*a].id));
        k.into_boxed_slice()
    };
    kb.facts.remove(&key("on", &["battery_red", "bin1"]));
    kb.facts
        .insert(key("attach", &["battery_red", "floor_robot"]));
    let plan_from = |kb: &btc_pddl::state::State| {
        btc_planner::plan_from(
            domain,
            &l.du.index,
            &l.pu.index,
            kb,
            problem.goal.as_ref(),
            &Options::default(),
        )
        .unwrap()
    };
    let report = plan_from(&kb);
    let Outcome::Plan(plan) = report.outcome else {
        panic!("no plan")
    };
    let text = btc_planner::to_sas_plan(domain, &l.pu.index, &plan);
    assert_eq!(
        text,
        "(move floor_robot curr_position agv1)\n(place floor_robot battery_red agv1)\n; cost = 2 (unit cost)\n"
    );
    // With the robot disabled nothing can happen.
    kb.facts.remove(&key("is_enabled", &["floor_robot"]));
    assert_eq!(plan_from(&kb).outcome, Outcome::Unsolvable);
}

#[test]
fn derived_predicates_disjunctions_and_conditional_effects() {
    let mut l = load(
        &fixture("rooms-domain.pddl"),
        &fixture("rooms-problem.pddl"),
    );
    for heuristic in [
        Heuristic::Ff,
        Heuristic::Add,
        Heuristic::Max,
        Heuristic::Blind,
    ] {
        for algorithm in [Algorithm::Gbfs, Algorithm::Astar] {
            let opts = Options {
                algorithm,
                heuristic,
                timeout: None,
                ..Options::default()
            };
            let (text, _, report) = l.solve_and_validate(&opts);
            assert_eq!(
                text,
                "(take brass hall)\n(go hall lab)\n(go lab vault)\n; cost = 3 (unit cost)\n"
            );
            assert!(report.ground.axioms > 0);
        }
    }
}

#[test]
fn an_unsolvable_problem_is_reported_as_such() {
    let l = load(
        &fixture("rooms-domain.pddl"),
        &fixture("rooms-unsolvable.pddl"),
    );
    for algorithm in [Algorithm::Gbfs, Algorithm::Astar] {
        for heuristic in [Heuristic::Ff, Heuristic::Blind] {
            let opts = Options {
                algorithm,
                heuristic,
                timeout: None,
                ..Options::default()
            };
            assert_eq!(l.plan(&opts).unwrap().outcome, Outcome::Unsolvable);
        }
    }
}

#[test]
fn a_zero_time_limit_stops_the_search() {
    let (d, p) = example("ariac");
    let l = load(&d, &p);
    let opts = Options {
        timeout: Some(Duration::ZERO),
        ..Options::default()
    };
    assert_eq!(l.plan(&opts).unwrap().outcome, Outcome::Timeout);
}

#[test]
fn numeric_conditions_and_effects_are_refused_by_name() {
    let l = load(
        &fixture("numeric-domain.pddl"),
        &fixture("numeric-problem.pddl"),
    );
    let diags = l.plan(&Options::default()).unwrap_err();
    let codes: Vec<&str> = diags.iter().map(|d| d.code).collect();
    assert_eq!(codes, ["S001", "S001"]);
    assert!(diags[0].message.contains("numeric conditions"));
    assert!(diags[1].message.contains("numeric effects"));
}

#[test]
fn fractional_costs_are_refused() {
    let l = load(
        &fixture("fraction-domain.pddl"),
        &fixture("fraction-problem.pddl"),
    );
    let diags = l.plan(&Options::default()).unwrap_err();
    assert_eq!(diags.len(), 1);
    assert_eq!(diags[0].code, "S002");
    assert!(diags[0].message.contains("0.5"), "{}", diags[0].message);
}

#[test]
fn the_time_limit_also_bounds_grounding() {
    let l = load(
        &fixture("blowup-domain.pddl"),
        &fixture("blowup-problem.pddl"),
    );
    let opts = Options {
        timeout: Some(Duration::from_millis(200)),
        ..Options::default()
    };
    let t = std::time::Instant::now();
    assert_eq!(l.plan(&opts).unwrap().outcome, Outcome::Timeout);
    assert!(t.elapsed() < Duration::from_secs(5), "{:?}", t.elapsed());
}
