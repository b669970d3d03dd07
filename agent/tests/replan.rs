//! The closed loop as a library (`btc_agent::run_loop`): the CLI tests
//! (`tests/replan.rs` in the root package) cover every ARIAC scenario; these
//! check the loop's state handling directly.

use btc_agent::faults::Scenario;
use btc_agent::{run_loop, LoopOptions};
use btc_lang::db::{CompileJob, Database};
use btc_runtime::Status;
use btc_testkit::repo as root;

/// The ARIAC rules and `problem` in a database, with an empty plan file
/// that the loop fills in.
fn ariac(problem: &str) -> (Database, CompileJob) {
    let dir = root().join("examples/ariac");
    let mut db = Database::new();
    let mut load = |name: &str| {
        let p = dir.join(name);
        db.set_file(&p, std::fs::read_to_string(&p).unwrap())
    };
    let rules = load("rules.btrules");
    let domain = load("domain.pddl");
    let problem = load(problem);
    let plan = db.set_file("(planned).sas_plan", String::new());
    let job = CompileJob::new(&db, rules, plan, Some(problem), Some(domain));
    (db, job)
}

fn scenario(name: &str) -> Scenario {
    let p = root().join(format!("examples/ariac/faults/{name}.toml"));
    Scenario::parse(&std::fs::read_to_string(p).unwrap()).unwrap()
}

#[test]
fn the_state_after_a_malfunction_is_the_next_plans_initial_state() {
    let (mut db, job) = ariac("problem.pddl");
    let sc = scenario("robot_malfunction");
    let s = run_loop(&mut db, job, false, Some(&sc), &LoopOptions::default()).unwrap();
    assert!(s.success(), "{s:#?}");
    assert_eq!(s.attempts.len(), 2);
    let (a, b) = (&s.attempts[0], &s.attempts[1]);
    assert_eq!(a.status, Status::Failure);
    // The first move was done: the second plan starts at bin1.
    assert_eq!(a.steps_done, 1);
    assert!(a
        .records
        .last()
        .unwrap()
        .kb
        .contains(&"(is_reachable floor_robot bin1)".into()));
    assert_eq!(b.plan[0], "(grasp floor_robot battery_red bin1)");
    // Ticks go on: the repair is waited for, then the second plan runs.
    assert_eq!(b.start_tick, a.end_tick + a.waited_ticks);
    assert_eq!(s.ticks, b.end_tick);
    // The malfunction fired once, at its step of the first plan (tick 2; the
    // grasp's retry tries again at tick 3, where the plan's monitor fails),
    // though the second plan also has a step 2.
    assert_eq!(s.faults.len(), 1);
    assert_eq!(s.faults[0].met_at, Some(2));
    assert_eq!(a.end_tick, 3);
    assert_eq!(s.faults[0].ended, "recovered");
}

#[test]
fn the_loop_reuses_the_database_and_its_plan_file() {
    let (mut db, job) = ariac("problem_spare.pddl");
    let sc = scenario("faulty_part");
    let s = run_loop(&mut db, job, false, Some(&sc), &LoopOptions::default()).unwrap();
    assert!(s.success());
    // The plan file holds the last plan, as the planner wrote it.
    let text = job.plan(&db).text(&db).clone();
    assert!(text.starts_with("(move floor_robot bin1 bin5)\n"), "{text}");
    assert_eq!(s.replans[0].from_step, Some(2));
    assert_eq!(s.goal, "(on battery_red_2 agv1)");
}

#[test]
fn a_scenario_that_does_not_fit_the_problem_is_an_error() {
    let (mut db, job) = ariac("problem.pddl");
    let sc = Scenario::parse(
        "[[fault]]\nkind = \"faulty_part\"\non_step = 1\npart = \"no_such_part\"\n",
    )
    .unwrap();
    let r = run_loop(&mut db, job, false, Some(&sc), &LoopOptions::default());
    assert!(matches!(r, Err(btc_agent::LoopError::Scenario(_))));
}
