//! `btc run --replan`: the closed loop on the ARIAC example, one test per
//! fault scenario (`examples/ariac/faults/`), checking the exit code, the
//! number of replans, the plans and the final goal check.

mod support;
use serde_json::Value;
use support::btc;

/// `btc run --replan --format json` on the ARIAC example with a problem
/// file and a fault scenario (by name); the exit code and the summary.
fn replan(problem: &str, scenario: Option<&str>, extra: &[&str]) -> (i32, Value) {
    let problem = format!("examples/ariac/{problem}");
    let mut args = vec![
        "run",
        "examples/ariac/rules.btrules",
        "--problem",
        &problem,
        "--replan",
        "--format",
        "json",
    ];
    let faults = scenario.map(|s| format!("examples/ariac/faults/{s}.toml"));
    if let Some(f) = &faults {
        args.extend(["--faults", f]);
    }
    args.extend(extra);
    let out = btc(&args);
    let v: Value = serde_json::from_slice(&out.stdout).unwrap_or_else(|e| {
        panic!(
            "{e}: {}{}",
            String::from_utf8_lossy(&out.stdout),
            String::from_utf8_lossy(&out.stderr)
        )
    });
    (out.status.code().unwrap_or(-1), v)
}

fn plan(s: &Value, attempt: usize) -> Vec<String> {
    s["attempts"][attempt]["plan"]
        .as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_str().unwrap().to_owned())
        .collect()
}

/// The loop reached its goal after `replans` replans; the fault recovered.
fn assert_recovered(s: &Value, code: i32, replans: usize) {
    assert_eq!(code, 0, "{s:#}");
    assert_eq!(s["ok"], true);
    assert_eq!(s["goal_reached"], true, "{s:#}");
    assert_eq!(s["replans"].as_array().unwrap().len(), replans, "{s:#}");
    // Every attempt but the last ended in a replan, or reached a priority
    // order's goal (then the whole goal is planned for).
    let attempts = s["attempts"].as_array().unwrap();
    let orders_done = attempts[..attempts.len() - 1]
        .iter()
        .filter(|a| a["status"] == "SUCCESS")
        .count();
    assert_eq!(attempts.len(), replans + 1 + orders_done, "{s:#}");
    let last = attempts.last().unwrap();
    assert_eq!(last["status"], "SUCCESS");
    assert_eq!(last["steps_done"], last["steps_total"]);
    for f in s["faults"].as_array().unwrap() {
        assert_eq!(f["ended"], "recovered", "{s:#}");
    }
}

const PLAN: [&str; 4] = [
    "(move floor_robot curr_position bin1)",
    "(grasp floor_robot battery_red bin1)",
    "(move floor_robot bin1 agv1)",
    "(place floor_robot battery_red agv1)",
];

#[test]
fn without_faults_one_plan_is_made_and_run() {
    let (code, s) = replan("problem.pddl", None, &[]);
    assert_recovered(&s, code, 0);
    assert_eq!(plan(&s, 0), PLAN);
    assert_eq!(s["attempts"][0]["source"], "planned");
    assert_eq!(s["goal"], "(on battery_red agv1)");
}

#[test]
fn robot_malfunction_waits_for_the_repair_then_replans() {
    let (code, s) = replan("problem.pddl", Some("robot_malfunction"), &[]);
    assert_recovered(&s, code, 1);
    let first = &s["attempts"][0];
    assert_eq!(first["status"], "FAILURE");
    // The malfunction lasts 5 ticks from tick 2; the grasp's retry tries
    // again at tick 3, where the plan's RobotNormal monitor fails. The loop
    // waits until the robot is repaired, and the next plan starts there.
    assert_eq!(first["end_tick"], 3);
    assert_eq!(first["waited_ticks"], 4);
    assert_eq!(s["attempts"][1]["start_tick"], 7);
    assert_eq!(s["replans"][0]["from_step"], 2);
    assert_eq!(s["replans"][0]["faults"][0], "robot_malfunction");
    // The robot is at bin1 already: grasp, move, place.
    assert_eq!(plan(&s, 1), PLAN[1..]);
    assert_eq!(s["faults"][0]["met_at"], 2);
}

#[test]
fn a_faulty_gripper_in_the_grasp_is_absorbed_by_the_retry() {
    let (code, s) = replan("problem.pddl", Some("faulty_gripper"), &[]);
    assert_recovered(&s, code, 0);
    assert_eq!(s["attempts"][0]["records"][0]["node_id"], "Grasp");
}

#[test]
fn a_part_dropped_by_the_gripper_is_fetched_again_where_it_fell() {
    let (code, s) = replan("problem.pddl", Some("dropped_part"), &[]);
    assert_recovered(&s, code, 1);
    assert_eq!(s["replans"][0]["from_step"], 3);
    assert_eq!(plan(&s, 1), PLAN[1..]);
}

#[test]
fn a_flipped_part_is_flipped_by_the_new_plan() {
    let (code, s) = replan("problem.pddl", Some("flipped_part"), &[]);
    assert_recovered(&s, code, 1);
    assert_eq!(
        plan(&s, 1),
        [
            "(flip floor_robot battery_red bin1)",
            "(grasp floor_robot battery_red bin1)",
            "(move floor_robot bin1 agv1)",
            "(place floor_robot battery_red agv1)",
        ]
    );
}

#[test]
fn a_faulty_part_is_replaced_by_a_spare_of_the_same_kind() {
    let (code, s) = replan("problem_spare.pddl", Some("faulty_part"), &[]);
    assert_recovered(&s, code, 1);
    assert_eq!(s["goal"], "(on battery_red_2 agv1)");
    let adj = s["replans"][0]["adjustments"][0].as_str().unwrap();
    assert!(
        adj.contains("battery_red_2") && adj.contains("faulty_part"),
        "{adj}"
    );
    assert_eq!(plan(&s, 1)[1], "(grasp floor_robot battery_red_2 bin5)");
}

#[test]
fn a_faulty_part_without_a_spare_stops_with_a_report() {
    let (code, s) = replan("problem.pddl", Some("faulty_part"), &[]);
    assert_eq!(code, 1);
    assert_eq!(s["goal_reached"], false);
    assert_eq!(s["diagnostics"][0]["code"], "X008");
    assert_eq!(s["unreachable"][0]["literal"], "(on battery_red agv1)");
    assert_eq!(s["unreachable"][0]["faults"][0], "faulty_part");
}

#[test]
fn insufficient_parts_stop_with_the_unreachable_literal_and_the_fault() {
    let (code, s) = replan("problem.pddl", Some("insufficient_parts"), &[]);
    assert_eq!(code, 1, "{s:#}");
    assert_eq!(s["ok"], false);
    assert_eq!(s["goal_reached"], false);
    // One plan ran and failed; the replan found no plan.
    assert_eq!(s["attempts"].as_array().unwrap().len(), 1);
    assert_eq!(s["replans"].as_array().unwrap().len(), 1);
    assert_eq!(s["unreachable"][0]["literal"], "(on battery_red agv1)");
    assert_eq!(s["unreachable"][0]["faults"][0], "insufficient_parts");
    let d = &s["diagnostics"][0];
    assert_eq!(d["code"], "X008");
    let msg = d["message"].as_str().unwrap();
    assert!(
        msg.contains("`(on battery_red agv1)` is unreachable")
            && msg.contains("insufficient_parts"),
        "{msg}"
    );
    assert!(s["faults"][0]["ended"]
        .as_str()
        .unwrap()
        .starts_with("not recovered"));
}

#[test]
fn insufficient_parts_text_report_names_the_literal_and_exits_1() {
    let out = btc(&[
        "run",
        "examples/ariac/rules.btrules",
        "--problem",
        "examples/ariac/problem.pddl",
        "--replan",
        "--faults",
        "examples/ariac/faults/insufficient_parts.toml",
    ]);
    assert_eq!(out.status.code(), Some(1));
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        text.contains("unreachable: (on battery_red agv1) (fault: insufficient_parts)"),
        "{text}"
    );
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("X008"), "{err}{text}");
}

#[test]
fn a_high_priority_order_whose_effect_applies_needs_no_replan() {
    let (code, s) = replan("problem.pddl", Some("high_priority_order"), &[]);
    assert_recovered(&s, code, 0);
    // The order's goal is part of the final goal check.
    assert_eq!(s["goal"], "(and (on battery_red agv1) (on pump_red agv2))");
}

#[test]
fn a_high_priority_order_preempts_the_plan_and_is_done_first() {
    let (code, s) = replan("problem.pddl", Some("priority_order"), &[]);
    assert_recovered(&s, code, 1);
    assert_eq!(s["goal"], "(and (on battery_red agv1) (on pump_red agv2))");
    // The order arrives at tick 2 and halts the first plan; the robot is
    // preempted for 2 ticks, then the order is planned for on its own.
    let first = &s["attempts"][0];
    assert_eq!(first["preempted"], true);
    assert_eq!(first["end_tick"], 2);
    assert_eq!(first["waited_ticks"], 2);
    let rp = &s["replans"][0];
    assert!(rp["why"].as_str().unwrap().contains("preempted"), "{rp}");
    assert_eq!(rp["faults"][0], "high_priority_order");
    assert_eq!(
        rp["adjustments"][0],
        "a fault added the goal `(on pump_red agv2)`"
    );
    assert_eq!(s["attempts"][1]["goal"], "(on pump_red agv2)");
    assert_eq!(
        plan(&s, 1),
        [
            "(move floor_robot curr_position bin1)",
            "(grasp floor_robot pump_red bin1)",
            "(move floor_robot bin1 agv2)",
            "(place floor_robot pump_red agv2)",
        ]
    );
    // Then the regular order, from agv2.
    assert_eq!(s["attempts"][2]["goal"], s["goal"]);
    assert_eq!(plan(&s, 2)[0], "(move floor_robot agv2 bin1)");
    assert_eq!(plan(&s, 2)[3], "(place floor_robot battery_red agv1)");
}

#[test]
fn faults_fire_once_across_replans_and_the_trace_has_the_loop_events() {
    let dir = tempfile::tempdir().unwrap();
    let trace = dir.path().join("t.jsonl");
    let trace_s = trace.to_str().unwrap();
    // The flipped part fires on step 2; the second plan's step 2 (grasp)
    // must not flip it again.
    let (code, s) = replan("problem.pddl", Some("flipped_part"), &["--trace", trace_s]);
    assert_recovered(&s, code, 1);
    let lines: Vec<Value> = std::fs::read_to_string(&trace)
        .unwrap()
        .lines()
        .map(|l| serde_json::from_str(l).unwrap())
        .collect();
    let events = |e: &str| lines.iter().filter(|l| l["event"] == e).count();
    assert_eq!(events("fault_triggered"), 1);
    assert_eq!(events("plan"), 2);
    assert_eq!(events("replan"), 1);
    assert_eq!(events("goal_check"), 1);
    let last = lines.last().unwrap();
    assert_eq!(last["event"], "goal_check");
    assert_eq!(last["reached"], true);
    // Ticks go on across attempts.
    let ticks: Vec<u64> = lines.iter().filter_map(|l| l["tick"].as_u64()).collect();
    assert!(ticks.windows(2).all(|w| w[0] <= w[1]), "{ticks:?}");
}

#[test]
fn a_given_plan_is_the_first_plan() {
    let (code, s) = replan(
        "problem.pddl",
        Some("dropped_part"),
        &["--plan", "examples/ariac/plan.txt"],
    );
    assert_recovered(&s, code, 1);
    assert_eq!(s["attempts"][0]["source"], "given");
    assert_eq!(s["attempts"][1]["source"], "planned");
    assert_eq!(plan(&s, 0), PLAN);
}

#[test]
fn the_replan_limit_stops_the_loop_with_x009() {
    let (code, s) = replan(
        "problem.pddl",
        Some("flipped_part"),
        &["--max-replans", "0"],
    );
    assert_eq!(code, 1);
    assert_eq!(s["goal_reached"], false);
    assert_eq!(s["replans"].as_array().unwrap().len(), 0);
    assert_eq!(s["diagnostics"][0]["code"], "X009");
}

#[test]
fn without_replan_the_same_scenarios_fail() {
    for sc in [
        "robot_malfunction",
        "dropped_part",
        "flipped_part",
        "priority_order",
    ] {
        let out = btc(&[
            "run",
            "examples/ariac/rules.btrules",
            "--plan",
            "examples/ariac/plan.txt",
            "--faults",
            &format!("examples/ariac/faults/{sc}.toml"),
        ]);
        assert_eq!(out.status.code(), Some(1), "{sc}");
    }
}

#[test]
fn pauses_and_blackouts_are_absorbed_by_the_tree_without_replans() {
    for sc in ["human_too_close", "sensor_blackout"] {
        let (code, s) = replan("problem.pddl", Some(sc), &[]);
        assert_recovered(&s, code, 0);
        assert!(s["ticks"].as_u64().unwrap() > 5, "{sc}: {s:#}");
    }
}

#[test]
fn replanning_without_a_problem_is_refused_with_r017() {
    let dir = tempfile::tempdir().unwrap();
    for f in ["rules.btrules", "domain.pddl"] {
        std::fs::copy(
            format!("{}/examples/ariac/{f}", env!("CARGO_MANIFEST_DIR")),
            dir.path().join(f),
        )
        .unwrap();
    }
    let rules = dir.path().join("rules.btrules");
    let out = btc(&["run", rules.to_str().unwrap(), "--replan"]);
    assert_eq!(out.status.code(), Some(1));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("R017"), "{err}");
}

#[test]
fn a_malfunction_that_outlasts_the_tick_limit_is_named_in_the_report() {
    let (code, s) = replan(
        "problem.pddl",
        Some("robot_malfunction"),
        &["--max-ticks", "4"],
    );
    assert_eq!(code, 1);
    assert_eq!(s["goal_reached"], false);
    assert_eq!(s["attempts"][0]["waited_ticks"], 1);
    let d = &s["diagnostics"][0];
    assert_eq!(d["code"], "X008");
    assert!(
        d["message"].as_str().unwrap().contains("robot_malfunction"),
        "{d}"
    );
}
