//! The library facade (`btc-api`) against the `btc` command on the same
//! inputs: a tree compiled in-process is the tree `btc compile` writes, a
//! plan made in-process is `btc plan`'s, and the agent's closed loop makes
//! the decisions `btc run --replan` makes on every ARIAC fault scenario.
//! Then bad input through the API: an error value with diagnostics, never
//! a panic.

#[path = "support/engine.rs"]
mod engine;
mod support;
use btc_api::{
    Agent, AgentOptions, AttemptInput, Executed, Executor, Faults, Plan, Project, RunOptions,
    Status, Target,
};
use engine::ReportingEngine;
use serde_json::Value;
use std::cell::Cell;
use std::path::Path;
use std::rc::Rc;
use support::{btc, exits, json_of};

const EXAMPLES: &[(&str, &str)] = &[
    ("ariac", "plan.txt"),
    ("nist_kitting", "plan.plan"),
    ("p3_assembler", "plan.tplan"),
    ("two_robots", "plan.plan"),
];

fn read(path: &str) -> String {
    std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join(path)).unwrap()
}

fn open(dir: &str) -> Project {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    Project::open(root.join(format!("examples/{dir}/rules.btrules"))).unwrap()
}

/// Lines of an output without those that name input files (which the
/// facade and the command name differently: a plan value has no file).
fn without_paths(text: &str) -> Vec<&str> {
    text.lines()
        .filter(|l| {
            !l.contains(".pddl") && !l.contains("plan") || l.contains('<') && !l.contains("<!--")
        })
        .collect()
}

fn without_lines(jsonl: &str) -> String {
    jsonl
        .lines()
        .map(|l| {
            let mut v: Value = serde_json::from_str(l).unwrap();
            v.as_object_mut().unwrap().remove("line");
            format!("{v}\n")
        })
        .collect()
}

#[test]
fn a_tree_compiled_in_process_is_the_tree_btc_compile_writes() {
    for (dir, plan_file) in EXAMPLES {
        let mut project = open(dir);
        let plan = Plan::parse(&read(&format!("examples/{dir}/{plan_file}"))).unwrap();
        let tree = project.compile(&plan, None).unwrap();
        let plan_path = format!("examples/{dir}/{plan_file}");
        let rules = format!("examples/{dir}/rules.btrules");
        for (target, emit) in [
            (Target::BtcppXml, "btcpp"),
            (Target::Mermaid, "mermaid"),
            (Target::Dot, "dot"),
            (Target::Commands, "commands"),
        ] {
            let out = btc(&["compile", &rules, "--plan", &plan_path, "--emit", emit]);
            exits(&out, 0, &format!("{dir} --emit {emit}"));
            let cli = String::from_utf8(out.stdout).unwrap();
            let mut ours = tree.emit(target).unwrap();
            let mut cli = cli;
            if target == Target::Commands {
                // A command says its step's line in the plan file; a plan
                // value has no file, and its steps are its lines.
                ours = without_lines(&ours);
                cli = without_lines(&cli);
            }
            assert_eq!(
                without_paths(&ours),
                without_paths(&cli),
                "{dir} --emit {emit}"
            );
        }
    }
}

#[test]
fn a_plan_made_in_process_is_btc_plans() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let domain = root.join("examples/ariac/domain.pddl");
    let problem = root.join("examples/ariac/problem.pddl");
    let ours = btc_api::plan(&domain, &problem).unwrap();
    let out = btc(&[
        "plan",
        "examples/ariac/domain.pddl",
        "examples/ariac/problem.pddl",
        "--quiet",
    ]);
    exits(&out, 0, "btc plan");
    // The same steps and cost (`btc plan` adds Fast Downward's "(unit cost)").
    let cli = Plan::parse(&String::from_utf8(out.stdout).unwrap()).unwrap();
    assert_eq!(ours, cli);
    // The project plans for the problem its rules name, the same plan.
    assert_eq!(
        open("ariac").plan(None).unwrap(),
        Plan::parse(&ours.to_string()).unwrap()
    );
    // A plan value reads back from its text.
    assert_eq!(
        Plan::parse(&ours.to_string()).unwrap().to_string(),
        ours.to_string()
    );
}

#[test]
fn a_project_from_texts_is_the_project_on_disk() {
    let (rules, domain, problem) = (
        read("examples/ariac/rules.btrules"),
        read("examples/ariac/domain.pddl"),
        read("examples/ariac/problem.pddl"),
    );
    let mut texts = Project::from_texts(&rules, &domain, Some(&problem)).unwrap();
    let mut disk = open("ariac");
    let codes = |p: &Project| p.check().iter().map(|d| d.code.clone()).collect::<Vec<_>>();
    assert_eq!(codes(&texts), codes(&disk));
    let plan = texts.plan(None).unwrap();
    assert_eq!(plan, disk.plan(None).unwrap());
    assert_eq!(
        texts.compile(&plan, None).unwrap().to_btcpp_xml(),
        disk.compile(&plan, None).unwrap().to_btcpp_xml()
    );
}

/// `btc run --replan --format json` on the ARIAC example with a scenario.
fn cli_loop(scenario: &str) -> Value {
    let faults = format!("examples/ariac/faults/{scenario}.toml");
    let out = btc(&[
        "run",
        "examples/ariac/rules.btrules",
        "--problem",
        "examples/ariac/problem.pddl",
        "--replan",
        "--faults",
        &faults,
        "--format",
        "json",
    ]);
    json_of(&out)
}

/// The loop's decisions in two reports: the goal and its verdict, the
/// ticks, the replans, the faults and what no plan reaches.
fn same_decisions(scenario: &str, ours: &Value, cli: &Value) {
    for key in [
        "goal",
        "goal_reached",
        "goal_failure",
        "ticks",
        "replans",
        "faults",
        "unreachable",
    ] {
        assert_eq!(ours[key], cli[key], "{scenario}: {key}");
    }
}

#[test]
fn the_agent_decides_as_btc_run_replan_on_every_ariac_fault() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut scenarios: Vec<String> = std::fs::read_dir(root.join("examples/ariac/faults"))
        .unwrap()
        .map(|e| {
            e.unwrap()
                .path()
                .file_stem()
                .unwrap()
                .to_string_lossy()
                .into_owned()
        })
        .collect();
    scenarios.sort();
    assert!(scenarios.len() >= 8, "{scenarios:?}");
    for s in &scenarios {
        let faults = Faults::open(root.join(format!("examples/ariac/faults/{s}.toml"))).unwrap();
        let mut agent = Agent::new(
            open("ariac"),
            Some(&root.join("examples/ariac/problem.pddl")),
        );
        let ours = agent.run(&AgentOptions::default(), Some(&faults)).unwrap();
        let mut ours = serde_json::to_value(&ours).unwrap();
        let cli = cli_loop(s);
        same_decisions(s, &ours, &cli);
        // Attempts agree but for their timings.
        let strip = |v: &mut Value| {
            for a in v["attempts"].as_array_mut().unwrap() {
                let a = a.as_object_mut().unwrap();
                for t in ["planning_ms", "compile_ms", "run_ms"] {
                    a.remove(t);
                }
            }
        };
        strip(&mut ours);
        let mut cli = cli;
        strip(&mut cli);
        assert_eq!(ours["attempts"], cli["attempts"], "{s}: attempts");
    }
}

/// Every scenario but `priority_order`: there, `btc run --replan` halts
/// the tree the tick the order comes (the order preempts the plan), while
/// `Tree::run`, this executor's engine, runs its tree to the end; an
/// executor of its own halts its tree when a behaviour reports the order.
const REPORTED: &[&str] = &[
    "dropped_part",
    "faulty_gripper",
    "faulty_part",
    "flipped_part",
    "high_priority_order",
    "priority_order",
    "human_too_close",
    "insufficient_parts",
    "robot_malfunction",
    "sensor_blackout",
];

#[test]
fn an_executor_outside_the_engine_gets_the_replans_btc_run_replan_makes() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    for s in REPORTED {
        let faults = Faults::open(root.join(format!("examples/ariac/faults/{s}.toml"))).unwrap();
        let mut agent = Agent::new(open("ariac"), None);
        let mut executor = ReportingEngine::new(faults);
        let ours = agent
            .run_with(&AgentOptions::default(), &mut executor)
            .unwrap();
        let ours = serde_json::to_value(&ours).unwrap();
        let cli = cli_loop(s);
        same_decisions(s, &ours, &cli);
        let plans = |v: &Value| -> Vec<Value> {
            v["attempts"]
                .as_array()
                .unwrap()
                .iter()
                .map(|a| serde_json::json!([a["plan"], a["status"], a["steps_done"]]))
                .collect()
        };
        assert_eq!(plans(&ours), plans(&cli), "{s}: attempts");
    }
}

#[test]
fn the_embedders_leaves_tick_in_the_run_and_in_the_loop() {
    let mut project = open("ariac");
    let plan = project.plan(None).unwrap();
    let tree = project.compile(&plan, None).unwrap();
    // Every `Grasp` is the embedder's: RUNNING once, then SUCCESS.
    let calls = Rc::new(Cell::new(0));
    let c = Rc::clone(&calls);
    let handler: btc_api::Handler<'_> = Box::new(move |call: &btc_api::ActionCall<'_>| {
        c.set(c.get() + 1);
        if call.starting {
            Status::Running
        } else {
            Status::Success
        }
    });
    let report = tree
        .run(
            &RunOptions::default(),
            vec![("Grasp".into(), handler)],
            None,
        )
        .unwrap();
    assert!(report.success(), "{report:#?}");
    let picks = plan.steps.iter().filter(|s| s.action == "grasp").count();
    assert!(picks > 0);
    assert_eq!(calls.get(), 2 * picks);
    // Each step starts once and ends once, in order.
    assert_eq!(report.steps.len(), 2 * plan.steps.len());
    // An embedder's FAILURE is a fault the agent replans after (`Place`
    // has no retry around it in these rules).
    let mut agent = Agent::new(open("ariac"), None);
    let failed = Rc::new(Cell::new(false));
    let f = Rc::clone(&failed);
    agent.leaf("Place", move |call| {
        if f.replace(true) {
            Status::Success
        } else {
            call.fail("the gripper dropped the part")
        }
    });
    let r = agent.run(&AgentOptions::default(), None).unwrap();
    assert!(r.goal_reached, "{r:#?}");
    assert_eq!(r.replans.len(), 1, "{r:#?}");
    assert_eq!(
        r.attempts[0].records.last().map(|x| x.node_id.as_str()),
        Some("Place"),
        "{r:#?}"
    );
    assert_eq!(
        r.replans[0].why, "`Place` (Place) failed: the gripper dropped the part",
        "{r:#?}"
    );
    assert_eq!(
        r.replans[0].action.as_deref(),
        Some("step 4: (place floor_robot battery_red agv1)")
    );
}

/// A leaf still RUNNING when the run stops is halted, and its halt handler
/// hears of it (BT.CPP's `onHalted`, where a client cancels its goal),
/// with the ports of its last tick; in the run and in the agent's loop.
#[test]
fn a_halted_leaf_hears_of_its_halt_in_the_run_and_in_the_loop() {
    let mut project = open("ariac");
    let plan = project.plan(None).unwrap();
    let tree = project.compile(&plan, None).unwrap();
    let halted: Rc<std::cell::RefCell<Vec<String>>> = Rc::default();
    let h = Rc::clone(&halted);
    let leaves = btc_api::Leaves::new()
        // The gripper never finishes.
        .action("Grasp", |_: &btc_api::ActionCall<'_>| Status::Running)
        .on_halt("Grasp", move |call: &btc_api::ActionCall<'_>| {
            let part = match call.port("part") {
                Some(btc_api::Value::Text(t)) => t.to_string(),
                other => format!("{other:?}"),
            };
            h.borrow_mut().push(part);
        });
    let options = RunOptions {
        max_ticks: 40,
        ..RunOptions::default()
    };
    let report = tree.run(&options, leaves, None).unwrap();
    assert_eq!(report.status, Status::Running, "{report:#?}");
    let grasped = plan
        .steps
        .iter()
        .find(|s| s.action == "grasp")
        .expect("the plan grasps");
    assert_eq!(halted.borrow().len(), 1, "{:?}", halted.borrow());
    assert!(
        grasped.args.contains(&halted.borrow()[0]),
        "{:?} halted, {grasped:?} grasps",
        halted.borrow()
    );
    // A leaf that never halts is not told anything.
    let quiet = Rc::new(Cell::new(0));
    let q = Rc::clone(&quiet);
    let leaves = btc_api::Leaves::new().on_halt("Grasp", move |_| q.set(q.get() + 1));
    assert!(tree
        .run(&RunOptions::default(), leaves, None)
        .unwrap()
        .success());
    assert_eq!(quiet.get(), 0);
    // An id no leaf has is an error, as for a tick handler.
    let leaves = btc_api::Leaves::new().on_halt("Grasps", |_| {});
    let e = tree.run(&RunOptions::default(), leaves, None).unwrap_err();
    assert!(e.to_string().contains("`Grasps`"), "{e}");
    // The agent's loop: every attempt's stuck `Grasp` is halted when its
    // tree stops at the tick limit.
    let mut agent = Agent::new(open("ariac"), None);
    let stops = Rc::new(Cell::new(0));
    let s = Rc::clone(&stops);
    agent
        .leaf("Grasp", |_| Status::Running)
        .on_halt("Grasp", move |_| s.set(s.get() + 1));
    let r = agent
        .run(
            &AgentOptions {
                run: options,
                max_replans: 0,
            },
            None,
        )
        .unwrap();
    assert!(!r.goal_reached, "{r:#?}");
    assert_eq!(stops.get(), r.attempts.len(), "{r:#?}");
}

#[test]
fn bad_input_is_an_error_with_diagnostics_never_a_panic() {
    let domain = read("examples/ariac/domain.pddl");
    // A rules file that does not parse: every error, with its place.
    let p = Project::from_texts("rule (pick ?r { Nope(", &domain, None).unwrap();
    let d = p.check();
    assert!(
        d.iter()
            .any(|d| d.is_error() && d.path == "rules.btrules" && d.line() == 1),
        "{d:#?}"
    );
    // A plan that does not parse.
    let e = Plan::parse("0.000: (move a b [oops").unwrap_err();
    assert!(
        e.diagnostics
            .iter()
            .all(|d| d.path == "<plan>" && d.line() == 1),
        "{e:#?}"
    );
    // A plan with an action the domain lacks.
    let mut ariac = open("ariac");
    let e = ariac
        .compile(&Plan::parse("(fly robot1 moon)\n").unwrap(), None)
        .unwrap_err();
    assert!(e.errors().next().is_some(), "{e}");
    assert!(e.to_string().contains("fly"), "{e}");
    // A rules file that is not there: btc's F001.
    let e = Project::open("/nonexistent/rules.btrules").err().unwrap();
    assert_eq!(e.diagnostics[0].code, "F001");
    // A leaf for a node the rules do not declare.
    let mut agent = Agent::new(open("ariac"), None);
    agent.leaf("Teleport", |_| Status::Success);
    let e = agent.run(&AgentOptions::default(), None).unwrap_err();
    assert_eq!(e.diagnostics[0].code, "X002", "{e}");
    // A fault scenario that is not TOML.
    assert!(Faults::parse("[[fault]\nkind = 3").is_err());
    // Hostile texts of every kind come back as values.
    for text in [
        "",
        "\0\0\0",
        "(((((((((((",
        "rule",
        "domain \"/dev/zero\"",
        "\u{feff}(define",
    ] {
        if let Ok(p) = Project::from_texts(text, text, Some(text)) {
            let _ = p.check();
        }
        let _ = Plan::parse(text);
        let _ = Faults::parse(text);
    }
}

/// An executor whose report the loop cannot take: the agent's error names
/// what is wrong; the host goes on.
struct Hostile(&'static str);

impl Executor for Hostile {
    fn execute(&mut self, a: &AttemptInput) -> Result<Executed, String> {
        let mut ex = Executed {
            status: Status::Failure,
            state: a.state.clone(),
            ticks: 1,
            steps_done: 0,
            records: Vec::new(),
            faults: Vec::new(),
        };
        match self.0 {
            "fact" => ex.state.push("(on battery_red the_moon)".into()),
            "text" => ex.state.push("(on battery_red".into()),
            "kind" => ex.faults.push(btc_api::ReportedFault {
                kind: "dropped".into(),
                ..Default::default()
            }),
            "part" => ex.faults.push(btc_api::ReportedFault {
                kind: "faulty_part".into(),
                ..Default::default()
            }),
            _ => return Err("the action server went away".into()),
        }
        Ok(ex)
    }
}

#[test]
fn a_report_the_loop_cannot_take_is_an_error_with_diagnostics() {
    for (what, says) in [
        ("fact", "the_moon"),
        ("text", "is not a fact"),
        ("kind", "`dropped` is not a fault kind"),
        ("part", "needs `part`"),
        ("broken", "the action server went away"),
    ] {
        let mut agent = Agent::new(open("ariac"), None);
        let err = agent
            .run_with(&AgentOptions::default(), &mut Hostile(what))
            .unwrap_err();
        let text = err.to_string();
        assert!(text.contains(says), "{what}: {text}");
        assert!(!err.diagnostics.is_empty());
    }
}

/// Writes each attempt's knowledge base and goal as a PDDL problem, plans
/// it in a project of its own, then runs the attempt as `ReportingEngine`.
struct WritingProblems {
    inner: ReportingEngine,
    project: Project,
    /// The plans the written problems gave, and the attempts' own.
    plans: Vec<(Vec<String>, Vec<String>)>,
}

impl Executor for WritingProblems {
    fn execute(&mut self, a: &AttemptInput) -> Result<Executed, String> {
        let text = self
            .project
            .problem_text(&a.state, &a.goal, None)
            .map_err(|e| e.to_string())?;
        let own = Project::from_texts(
            &read("examples/ariac/rules.btrules"),
            &read("examples/ariac/domain.pddl"),
            Some(&text),
        )
        .map_err(|e| e.to_string())?
        .plan(None)
        .map_err(|e| format!("{e}\n{text}"))?;
        let steps = own.steps.iter().map(|s| s.to_string()).collect();
        self.plans.push((steps, a.tree.steps()));
        self.inner.execute(a)
    }
}

#[test]
fn the_knowledge_base_written_as_a_problem_plans_as_the_loop_does() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let faults = Faults::open(root.join("examples/ariac/faults/flipped_part.toml")).unwrap();
    let mut executor = WritingProblems {
        inner: ReportingEngine::new(faults),
        project: open("ariac"),
        plans: Vec::new(),
    };
    let mut agent = Agent::new(open("ariac"), None);
    let report = agent
        .run_with(&AgentOptions::default(), &mut executor)
        .unwrap();
    assert!(report.goal_reached, "{report:#?}");
    assert_eq!(executor.plans.len(), 2, "one replan after the flip");
    for (written, loop_plan) in &executor.plans {
        assert_eq!(written, loop_plan);
    }
    // What it cannot write is an error, not a line of the problem.
    let mut p = open("ariac");
    let err = p
        .problem_text(
            &["(on battery_red the_moon)".into()],
            "(on battery_red agv1)",
            None,
        )
        .unwrap_err();
    assert!(err.to_string().contains("the_moon"), "{err}");
}
