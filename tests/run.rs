//! `btc run` as a user meets it: exit codes, the summary, the trace file,
//! tree files, fault scenarios and the controller.

mod support;

use std::process::Output;
use support::{btc, btc_in, compile, exits, json_of, plan_of, summary_of};

/// `btc run` of the ARIAC example with `extra` arguments.
fn run_ariac(extra: &[&str]) -> Output {
    let mut args = vec![
        "run",
        "examples/ariac/rules.btrules",
        "--plan",
        "examples/ariac/plan.txt",
    ];
    args.extend_from_slice(extra);
    btc(&args)
}

/// `btc compile` of the ARIAC example to `out`, which must succeed.
fn compile_ariac(emit: &str, out: &std::path::Path) {
    compile(
        "examples/ariac/rules.btrules",
        "examples/ariac/plan.txt",
        emit,
        out,
        &[],
    );
}

#[test]
fn every_example_runs_to_its_goal_and_exits_0() {
    for ex in ["ariac", "nist_kitting", "p3_assembler", "two_robots"] {
        let rules = format!("examples/{ex}/rules.btrules");
        let plan = plan_of(ex);
        let s = summary_of(&["run", &rules, "--plan", &plan], 0);
        assert_eq!(s["status"], "SUCCESS", "{ex}");
        assert_eq!(s["goal_reached"], true, "{ex}");
        assert_eq!(s["steps_done"], s["steps_total"], "{ex}");
    }
}

#[test]
fn the_text_summary_names_ticks_steps_and_the_goal() {
    let out = run_ariac(&["--ticks-per-action", "3"]);
    assert_eq!(out.status.code(), Some(0));
    let text = String::from_utf8_lossy(&out.stdout);
    // Four steps of one action each, three ticks per action plus the start.
    assert_eq!(
        text.lines().next().unwrap(),
        "SUCCESS after 13 ticks; 4 of 4 plan steps done; goal reached: yes"
    );
}

#[test]
fn a_fault_that_is_not_recovered_exits_1_with_its_record() {
    let out = run_ariac(&["--faults", "examples/ariac/faults/faulty_part.toml"]);
    assert_eq!(out.status.code(), Some(1));
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        text.contains("fault faulty_part (faulty_part): met at tick 2; not recovered"),
        "{text}"
    );
    assert!(
        text.contains("`(on battery_red bin1)` is false [fault: faulty_part]"),
        "{text}"
    );
}

#[test]
fn a_recovered_fault_exits_0() {
    let out = run_ariac(&[
        "--faults",
        "examples/ariac/faults/human_too_close.toml",
        "--format",
        "json",
    ]);
    exits(&out, 0, "run --faults human_too_close");
    let s = json_of(&out);
    assert_eq!(s["faults"][0]["ended"], "recovered");
}

#[test]
fn the_trace_is_json_lines_of_status_changes_written_atomically() {
    let dir = tempfile::tempdir().unwrap();
    let trace = dir.path().join("trace.jsonl");
    let out = run_ariac(&["--trace", trace.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(0));
    let text = std::fs::read_to_string(&trace).unwrap();
    let lines: Vec<serde_json::Value> = text
        .lines()
        .map(|l| serde_json::from_str(l).unwrap())
        .collect();
    assert!(lines.len() > 20);
    assert_eq!(lines[0]["node"], 0);
    assert_eq!(lines[0]["from"], "IDLE");
    assert_eq!(lines[0]["to"], "RUNNING");
    let last = lines.iter().rev().find(|l| l["node"] == 0).unwrap();
    assert_eq!(last["to"], "SUCCESS");
    assert_eq!(
        lines
            .iter()
            .filter(|l| l["event"] == "step_finished")
            .count(),
        4
    );
    // Only the trace is left in the folder: no temporary file.
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);
}

#[test]
fn an_emitted_tree_runs_with_tree_and_the_problem() {
    let dir = tempfile::tempdir().unwrap();
    for (fmt, ext) in [("btcpp", "xml"), ("json", "json")] {
        let tree = dir.path().join(format!("tree.{ext}"));
        compile_ariac(fmt, &tree);
        let s = summary_of(
            &[
                "run",
                "--tree",
                tree.to_str().unwrap(),
                "--problem",
                "examples/ariac/problem.pddl",
            ],
            0,
        );
        assert_eq!(s["goal_reached"], true);
    }
}

#[test]
fn a_kb_tree_without_a_problem_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let tree = dir.path().join("tree.xml");
    compile_ariac("btcpp", &tree);
    let out = btc(&["run", "--tree", tree.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&out.stderr).contains("[X005]"));
}

#[test]
fn the_controller_executes_each_command_once() {
    let s = summary_of(
        &[
            "run",
            "examples/nist_kitting/rules.btrules",
            "--plan",
            &plan_of("nist_kitting"),
            "--controller",
        ],
        0,
    );
    let cmds = s["commands"].as_array().unwrap();
    assert!(cmds.len() > 10);
    for (k, c) in cmds.iter().enumerate() {
        assert_eq!(c["seq"], k as u64 + 1);
    }
}

#[test]
fn usage_and_io_errors_exit_2() {
    let out = btc(&["run", "--tree", "no/such/tree.xml"]);
    assert_eq!(out.status.code(), Some(2));
    let out = btc(&["run", "examples/ariac/rules.btrules"]);
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("--plan"));
    let out = btc(&["run"]);
    assert_eq!(out.status.code(), Some(2));
}

#[test]
fn a_tree_that_never_finishes_is_halted_after_max_ticks() {
    let s = summary_of(
        &[
            "run",
            "--tree",
            "tests/fixtures/run/forever.xml",
            "--max-ticks",
            "50",
        ],
        1,
    );
    assert_eq!(s["status"], "RUNNING");
    assert_eq!(s["ticks"], 50);
    let reason = s["records"][0]["reason"].as_str().unwrap();
    assert!(reason.contains("still running after 50 ticks"), "{reason}");
}

#[test]
fn an_xml_tree_checks_step_preconditions_from_the_domain() {
    let dir = tempfile::tempdir().unwrap();
    let tree = dir.path().join("tree.xml");
    compile_ariac("btcpp", &tree);
    let out = btc(&[
        "run",
        "--tree",
        tree.to_str().unwrap(),
        "--problem",
        "examples/ariac/problem.pddl",
        "--faults",
        "examples/ariac/faults/insufficient_parts.toml",
    ]);
    assert_eq!(out.status.code(), Some(1));
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        text.contains("its step's precondition does not hold: `(on battery_red bin1)` is false"),
        "{text}"
    );
}

#[test]
fn btlog_writes_a_groot2_replay_of_the_run() {
    let dir = tempfile::tempdir().unwrap();
    let log = dir.path().join("run.btlog");
    let out = run_ariac(&["--btlog", log.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(0));
    let b = std::fs::read(&log).unwrap();
    assert_eq!(&b[..19], b"BTCPP4-FileLogger2\x01");
    let n = i32::from_le_bytes(b[19..23].try_into().unwrap()) as usize;
    let xml = std::str::from_utf8(&b[23..23 + n]).unwrap();
    // The tree as BT.CPP's WriteTreeToXML: instances, uids, ports, models.
    assert!(xml.contains(r#"<BehaviorTree ID="rule_grasp" _fullpath="rule_grasp::10">"#));
    assert!(xml.contains(
        r#"<KbStep name="step 2: (grasp floor_robot battery_red bin1)" _uid="9" step="2""#
    ));
    assert!(xml.contains(r#"<Action ID="MoveTo">"#));
    // One 9-byte record per status change (the trace's), plus the root's
    // reset after the last tick.
    let trace = dir.path().join("run.jsonl");
    run_ariac(&["--trace", trace.to_str().unwrap()]);
    let changes = std::fs::read_to_string(&trace)
        .unwrap()
        .lines()
        .filter(|l| l.contains("\"from\""))
        .count();
    assert_eq!(b.len() - (31 + n), 9 * (changes + 1));
    // With the trace file too, the replay keeps every transition (the
    // trace is streamed tick by tick; the replay used to find it drained).
    let both = dir.path().join("both.btlog");
    let traced = dir.path().join("both.jsonl");
    let out = run_ariac(&[
        "--btlog",
        both.to_str().unwrap(),
        "--trace",
        traced.to_str().unwrap(),
    ]);
    assert_eq!(out.status.code(), Some(0));
    assert_eq!(std::fs::read(&both).unwrap().len(), b.len());
    assert_eq!(
        std::fs::read_to_string(&traced).unwrap(),
        std::fs::read_to_string(&trace).unwrap()
    );
    // Groot2 opens only `.btlog` files.
    let bad = run_ariac(&["--btlog", "run.log"]);
    assert_eq!(bad.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&bad.stderr).contains(".btlog"));
}

#[test]
fn a_json_ir_carries_its_world_and_runs_from_its_own_folder() {
    let dir = tempfile::tempdir().unwrap();
    let out_dir = dir.path().join("out");
    std::fs::create_dir(&out_dir).unwrap();
    let rules = format!(
        "{}/examples/ariac/rules.btrules",
        env!("CARGO_MANIFEST_DIR")
    );
    let tree = out_dir.join("p01.json");
    compile(&rules, "examples/ariac/plan.txt", "json", &tree, &[]);
    let ir: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&tree).unwrap()).unwrap();
    assert_eq!(ir["ir_version"], 2);
    // Recorded relative to the JSON file, never as `//home/...`.
    let domain = ir["domain"].as_str().unwrap();
    assert!(
        !domain.starts_with('/') && !domain.contains("//"),
        "{domain}"
    );
    assert!(out_dir.join(domain).is_file(), "{domain}");
    // So are the problem, the plan and the rules file.
    for key in ["problem", "plan", "rules"] {
        let p = ir[key].as_str().unwrap_or_else(|| panic!("no {key}"));
        assert!(!p.starts_with('/') && !p.contains("//"), "{key}: {p}");
        assert!(out_dir.join(p).is_file(), "{key}: {p}");
    }
    assert!(ir["plan"]
        .as_str()
        .unwrap()
        .ends_with("examples/ariac/plan.txt"));
    // `cd out && btc run --tree p01.json`: no PDDL file needed.
    let out = btc_in(&out_dir, &["run", "--tree", "p01.json", "--format", "json"]);
    exits(&out, 0, "run --tree p01.json");
    assert_eq!(json_of(&out)["goal_reached"], true);
    // Even with the PDDL files gone.
    let moved = dir.path().join("elsewhere.json");
    std::fs::copy(&tree, &moved).unwrap();
    let out = btc_in(
        dir.path(),
        &["run", "--tree", "elsewhere.json", "--format", "json"],
    );
    exits(&out, 0, "run --tree elsewhere.json");
}

#[test]
fn version_1_json_files_still_run() {
    // Written by btc before the IR carried its world: paths relative to the
    // folder it was compiled in (the repository), formulas as strings, and
    // a backchained plan's `KbHolds` formulas as text ports.
    for file in ["ariac", "workshop_backchained"] {
        let tree = format!("tests/fixtures/ir_v1/{file}.json");
        let s = summary_of(&["run", "--tree", &tree], 0);
        assert_eq!(s["goal_reached"], true, "{file}");
        assert_eq!(s["steps_done"], s["steps_total"], "{file}");
    }
    // Its paths are also found relative to the file itself.
    let dir = tempfile::tempdir().unwrap();
    let text = std::fs::read_to_string(format!(
        "{}/tests/fixtures/ir_v1/ariac.json",
        env!("CARGO_MANIFEST_DIR")
    ))
    .unwrap();
    let root = env!("CARGO_MANIFEST_DIR");
    for f in ["domain.pddl", "problem.pddl"] {
        std::fs::copy(format!("{root}/examples/ariac/{f}"), dir.path().join(f)).unwrap();
    }
    let text = text
        .replace("examples/ariac/domain.pddl", "domain.pddl")
        .replace("examples/ariac/problem.pddl", "problem.pddl");
    std::fs::write(dir.path().join("v1.json"), text).unwrap();
    summary_of(
        &[
            "run",
            "--tree",
            dir.path().join("v1.json").to_str().unwrap(),
        ],
        0,
    );
}

/// `btc run ARGS --controller --format json`, which must exit 0: the
/// commands it sends its controller, as (step, command, args).
fn commands_of(args: &[&str], what: &str) -> Vec<serde_json::Value> {
    let mut all = args.to_vec();
    all.push("--controller");
    let s = summary_of(&all, 0);
    assert_eq!(s["goal_reached"], true, "{what}");
    let mut commands: Vec<serde_json::Value> = s["commands"]
        .as_array()
        .expect("a controller run lists its commands")
        .iter()
        .map(|c| serde_json::json!([c["step"], c["command"], c["args"]]))
        .collect();
    // The controller is a thread: which of two concurrent steps' commands
    // it is handed first depends on when the other's completion arrived.
    // Each step's own commands keep their order (a stable sort).
    commands.sort_by_key(|c| c[0].as_u64());
    commands
}

/// The rules compiled to the JSON IR, to BT.CPP XML and to inlined XML each
/// run to `expected`'s commands in `problem`.
fn same_commands_from_the_ir_and_the_xml(
    rules: &str,
    plan: &str,
    problem: &str,
    expected: &[serde_json::Value],
) {
    let dir = tempfile::tempdir().unwrap();
    for (what, emit, extra) in [
        ("json", "json", None),
        ("xml", "btcpp", None),
        ("inlined xml", "btcpp", Some("--inline")),
    ] {
        let tree = dir.path().join(format!("tree_{emit}_{}", extra.is_some()));
        let extra: Vec<&str> = extra.into_iter().collect();
        compile(rules, plan, emit, &tree, &extra);
        let got = commands_of(
            &[
                "run",
                "--tree",
                tree.to_str().unwrap(),
                "--problem",
                problem,
            ],
            what,
        );
        assert_eq!(got, expected, "{what}");
    }
}

/// Every value a step computes (table lookups passed to a tree, strings
/// interpolating them) reaches btc's engine the same way from the rules,
/// from the JSON IR, and from the BT.CPP XML in SubTree mode and inlined.
#[test]
fn computed_values_reach_the_engine_from_the_ir_and_from_the_xml() {
    let rules = "tests/fixtures/emit/values/rules.btrules";
    let plan = "tests/fixtures/emit/values/plan.txt";
    let problem = "tests/fixtures/emit/values/problem.pddl";
    let expected = commands_of(&["run", rules, "--plan", plan], "rules");
    let say: Vec<&serde_json::Value> = expected.iter().filter(|c| c[1] == "Say").collect();
    assert_eq!(
        say.iter().map(|c| c[2].clone()).collect::<Vec<_>>(),
        [
            serde_json::json!([["text", "holding battery_red at 5 N"]]),
            serde_json::json!([["text", "holding pump_blue at 8 N"]]),
        ]
    );
    assert!(expected.contains(&serde_json::json!([
        6,
        "ChangeGripper",
        [["robot", "floor_robot"], ["gripper", "tray_gripper"]]
    ])));
    same_commands_from_the_ir_and_the_xml(rules, plan, problem, &expected);
}

#[test]
fn an_xml_tree_runs_with_the_trees_it_includes() {
    // main.xml includes parts/pick.xml, which includes ../count.xml; run
    // from another folder, the paths stay relative to each file.
    let s = summary_of(
        &["run", "--tree", "runtime/tests/fixtures/include/main.xml"],
        0,
    );
    assert_eq!(s["status"], "SUCCESS");
}

/// A fault undoes a finished step's work (the part slips out of the
/// gripper); `retry(3) sequence { steps backchained }` ticks the plan
/// again, redoes the grasp, and the grasp's effect holds again, from the
/// rules and from the compiled XML alike.
#[test]
fn a_step_redone_after_a_fault_re_establishes_its_effects() {
    let rules = "tests/fixtures/run/redo/rules.btrules";
    let fault = "examples/ariac/faults/dropped_part.toml";
    let s = summary_of(
        &[
            "run",
            rules,
            "--plan",
            "examples/ariac/plan.txt",
            "--faults",
            fault,
        ],
        0,
    );
    assert_eq!(s["goal_reached"], true);
    assert_eq!(s["faults"][0]["ended"], "recovered", "{s}");
    let dir = tempfile::tempdir().unwrap();
    let tree = dir.path().join("tree.xml");
    compile(rules, "examples/ariac/plan.txt", "btcpp", &tree, &[]);
    let s = summary_of(
        &[
            "run",
            "--tree",
            tree.to_str().unwrap(),
            "--problem",
            "examples/ariac/problem.pddl",
            "--faults",
            fault,
        ],
        0,
    );
    assert_eq!(s["goal_reached"], true);
}

/// Scripts written in the rules run in btc's engine: a `script` leaf sets
/// an entry, `on_success` counts, `skip_if` lets one `Say` run and skips the
/// other, `script_condition` and `failure_if` guard the grasp. The same
/// commands come from the rules, the JSON IR and the BT.CPP XML in SubTree
/// mode and inlined.
#[test]
fn scripts_in_the_rules_run_the_same_from_the_ir_and_the_xml() {
    let rules = "tests/fixtures/scripts/rules.btrules";
    let plan = "tests/fixtures/scripts/plan.txt";
    let problem = "tests/fixtures/emit/values/problem.pddl";
    let expected = commands_of(&["run", rules, "--plan", plan], "rules");
    let said: Vec<&serde_json::Value> = expected
        .iter()
        .filter(|c| c[1] == "Say")
        .map(|c| &c[2][0][1])
        .collect();
    assert_eq!(said, ["moved once"; 4], "{expected:?}");
    assert_eq!(expected.iter().filter(|c| c[1] == "Grip").count(), 2);
    same_commands_from_the_ir_and_the_xml(rules, plan, problem, &expected);
}

/// `btc fmt` keeps scripts: the fixture is in canonical layout, so a
/// formatter that dropped or rewrote a `[skip_if: ...]` or a `script` leaf
/// would make `--check` fail.
#[test]
fn fmt_keeps_the_scripts_of_a_rules_file() {
    let out = btc(&["fmt", "--check", "tests/fixtures/scripts/rules.btrules"]);
    exits(
        &out,
        0,
        "btc fmt --check tests/fixtures/scripts/rules.btrules",
    );
}

#[test]
fn a_timed_plans_durations_become_ticks_on_request() {
    let dir = "runtime/tests/fixtures/three_way/timed";
    let rules = format!("{dir}/scheduled.btrules");
    let plan = format!("{dir}/plan.tplan");
    let ticks = |per_unit: &str| {
        let s = summary_of(
            &[
                "run",
                &rules,
                "--plan",
                &plan,
                "--ticks-per-time-unit",
                per_unit,
            ],
            0,
        );
        assert_eq!(s["goal_reached"], true, "{s}");
        s["ticks"].as_u64().unwrap()
    };
    // Off by default: the steps take their actions' ticks, as before.
    let default = summary_of(&["run", &rules, "--plan", &plan], 0);
    assert_eq!(default["ticks"].as_u64().unwrap(), ticks("0"));
    // Five-unit steps one after another on each robot's chain: the run
    // grows with the ticks per unit, about as the plan's makespan (37).
    let (ten, hundred) = (ticks("10"), ticks("100"));
    assert!((300..=420).contains(&ten), "{ten} ticks");
    assert!((3000..=4000).contains(&hundred), "{hundred} ticks");
    // Replanning makes its own plans: the option is refused with it.
    let out = btc(&["run", &rules, "--replan", "--ticks-per-time-unit", "5"]);
    assert_eq!(out.status.code(), Some(2));
}

/// The `(tick, event, step)` of each step start and end in a `btc run`'s
/// trace, and the leaves' commands.
fn step_events_and_commands(
    rules: &str,
    plan: &str,
) -> (Vec<(u64, String, u64)>, Vec<serde_json::Value>) {
    let dir = tempfile::tempdir().unwrap();
    let trace = dir.path().join("trace.jsonl");
    let out = btc(&[
        "run",
        rules,
        "--plan",
        plan,
        "--trace",
        trace.to_str().unwrap(),
    ]);
    exits(&out, 0, rules);
    let events = std::fs::read_to_string(&trace)
        .unwrap()
        .lines()
        .map(|l| serde_json::from_str::<serde_json::Value>(l).unwrap())
        .filter(|l| l["event"] == "step_started" || l["event"] == "step_finished")
        .map(|l| {
            (
                l["tick"].as_u64().unwrap(),
                l["event"].as_str().unwrap().to_owned(),
                l["step"].as_u64().unwrap(),
            )
        })
        .collect();
    (events, commands_of(&["run", rules, "--plan", plan], rules))
}

/// PlanSys2-style per-action BT.CPP trees imported into the rules run as
/// the hand-written rules that mean the same: the same step starts and
/// ends at the same ticks, the same leaves with the same ports, from the
/// rules, the IR and the XML.
#[test]
fn imported_btcpp_trees_run_as_their_hand_written_equivalent() {
    let dir = "runtime/tests/fixtures/three_way/timed";
    let plan = format!("{dir}/plan.tplan");
    let imported = format!("{dir}/scheduled_imported.btrules");
    let (events, commands) = step_events_and_commands(&imported, &plan);
    let (hand_events, hand_commands) =
        step_events_and_commands(&format!("{dir}/scheduled.btrules"), &plan);
    assert_eq!(events.len(), 44, "{events:?}");
    assert_eq!(events, hand_events);
    assert_eq!(commands, hand_commands);
    same_commands_from_the_ir_and_the_xml(
        &imported,
        &plan,
        &format!("{dir}/problem.pddl"),
        &commands,
    );
}
