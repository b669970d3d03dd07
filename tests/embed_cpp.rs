//! The C++ agent example (`examples/embed/cpp`) built against real
//! BehaviorTree.CPP 4.10 and btc's C API, run on the ARIAC part task, and
//! compared with `btc run --replan --format json` on every scenario of
//! `examples/ariac/faults`: the example plays each scenario's fault where an
//! agent would meet it (its action node reports an `on_action` or `on_step`
//! fault when it starts; an `at_tick` fault, news from outside the tree, is
//! reported before that tick by the loop's `before_tick` hook), and its
//! simulated action server does to the robot what the fault says (a
//! dropped part, a robot down or paused for the fault's duration; the KB's
//! conditions dark in a sensor blackout). The attempts' plans and
//! statuses, the steps each attempt started (in order), the faults, the
//! replans and the goal verdict must be those of `btc run --replan`, and
//! the final KB that of the same loop with btc's engine executing. The example's node
//! stands in for a ROS 2 action client (goal, polls over ticks, cancel on
//! halt), so tick counts differ by design and are not compared.
//!
//! Skipped without BT.CPP locally, required under `CI=true`.

#[path = "support/engine.rs"]
mod engine;
mod support;
use std::path::{Path, PathBuf};
use std::process::Command;
use support::{btc, json_of};

/// The C API's static library cargo built beside this test (btc-capi is a
/// dev-dependency; its `staticlib` lands in the same `deps` folder).
fn capi_library() -> PathBuf {
    let exe = std::env::current_exe().unwrap();
    let lib = exe.parent().unwrap().join("libbtc_capi.a");
    assert!(lib.is_file(), "cargo built no {}", lib.display());
    lib
}

/// The example, built once per test process.
fn example() -> Option<PathBuf> {
    let prefix = btc_testkit::btcpp()?;
    let build = btc_testkit::target_dir("embed/cpp");
    let lib = capi_library().display().to_string();
    btc_testkit::cmake_build(
        &btc_testkit::repo().join("examples/embed/cpp"),
        &build,
        &prefix,
        &[("BTC_CAPI_LIBRARY", lib.as_str())],
        &["ariac_agent"],
    )
    .unwrap_or_else(|e| panic!("the C++ agent example does not build:\n{e}"));
    Some(build.join("ariac_agent"))
}

/// The example's flags that play a scenario's one fault as the agent would
/// meet it: reported by the node of an action's n-th goal (`on_action`),
/// by the first action node of a plan step or a later one (`on_step`), or
/// from outside the tree before a tick of the loop (`at_tick`), with what
/// the fault says. A scenario the example cannot play is an error.
fn injected(scenario: &Path) -> Result<Vec<String>, String> {
    let text = std::fs::read_to_string(scenario).unwrap();
    let doc: toml::Table = text.parse().map_err(|e| format!("not TOML: {e}"))?;
    let faults = doc
        .get("fault")
        .and_then(|f| f.as_array())
        .ok_or("no [[fault]]")?;
    let [fault] = faults.as_slice() else {
        return Err(format!("{} faults; the example plays one", faults.len()));
    };
    let fault = fault.as_table().ok_or("a fault that is not a table")?;
    let text_of = |key: &str| -> Result<String, String> {
        fault[key]
            .as_str()
            .map(str::to_owned)
            .ok_or_else(|| format!("`{key}` is not a string"))
    };
    let number_of = |key: &str| -> Result<String, String> {
        fault[key]
            .as_integer()
            .map(|n| n.to_string())
            .ok_or_else(|| format!("`{key}` is not a number"))
    };
    let mut flags = Vec::new();
    for key in fault.keys() {
        let flag = |name: &str, value: String| [format!("--{name}"), value];
        match key.as_str() {
            "on_action" => {
                let n = match fault.get("occurrence") {
                    Some(_) => number_of("occurrence")?,
                    None => "1".to_owned(),
                };
                flags.extend(flag("fail", format!("{}:{n}", text_of(key)?)));
            }
            "occurrence" => {}
            "on_step" => flags.extend(flag("fail-step", number_of(key)?)),
            "at_tick" => flags.extend(flag("at-tick", number_of(key)?)),
            "kind" | "robot" | "part" | "goal" | "conditions" => {
                flags.extend(flag(key, text_of(key)?));
            }
            "duration" => flags.extend(flag(key, number_of(key)?)),
            "retract" | "add" => {
                let list = fault[key]
                    .as_array()
                    .ok_or_else(|| format!("`{key}` is not a list"))?;
                for v in list {
                    let v = v
                        .as_str()
                        .ok_or_else(|| format!("`{key}` holds a non-string"))?;
                    flags.extend(flag(key, v.to_owned()));
                }
            }
            other => return Err(format!("the example has no flag for `{other}`")),
        }
    }
    Ok(flags)
}

/// What both runs must agree on.
#[derive(Debug, PartialEq)]
struct Outcome {
    plans: Vec<Vec<String>>,
    started: Vec<Vec<u64>>,
    statuses: Vec<String>,
    faults: Vec<String>,
    replans: usize,
    goal: String,
    goal_reached: bool,
    kb: Vec<String>,
}

fn strings(v: &serde_json::Value) -> Vec<String> {
    v.as_array()
        .map(|a| a.iter().map(|s| s.as_str().unwrap().to_owned()).collect())
        .unwrap_or_default()
}

#[test]
fn the_cpp_agent_recovers_as_btc_run_replan_does() {
    let Some(agent) = example() else { return };
    let ariac = btc_testkit::repo().join("examples/ariac");
    let rules = ariac.join("rules.btrules");
    let scenarios = btc_testkit::sorted_entries(&ariac.join("faults"));
    let mut compared = 0;
    for scenario in &scenarios {
        let name = scenario.file_name().unwrap().to_string_lossy().into_owned();
        let flags = injected(scenario)
            .unwrap_or_else(|e| panic!("{name}: the C++ agent cannot play it: {e}"));
        let out = Command::new(&agent)
            .arg(&rules)
            .arg("--json")
            .args(&flags)
            .output()
            .unwrap();
        assert!(
            out.status.code().is_some_and(|c| c < 2),
            "{name}: the C++ agent failed:\n{}{}",
            String::from_utf8_lossy(&out.stdout),
            String::from_utf8_lossy(&out.stderr)
        );
        let cpp = json_of(&out);
        let ours = outcome(&cpp["report"], cpp_started(&cpp), strings(&cpp["kb"]));
        let (cli, started) = cli_run(&rules, &ariac, scenario);
        let (kb, plans) = engine_kb(&rules, scenario);
        let theirs = outcome(&cli, started, kb);
        assert_eq!(
            plans, theirs.plans,
            "{name}: the reference loop does not decide as btc run --replan"
        );
        assert_eq!(
            ours, theirs,
            "{name}: the C++ agent against btc run --replan"
        );
        compared += 1;
    }
    assert!(
        compared == scenarios.len() && compared >= 10,
        "{compared} of {} scenarios compared",
        scenarios.len()
    );
}

/// The outcome a loop's report (btc-api's or `btc run --replan`'s JSON)
/// gives, with the steps each attempt started and the final KB.
fn outcome(report: &serde_json::Value, started: Vec<Vec<u64>>, kb: Vec<String>) -> Outcome {
    let list = |key: &str| report[key].as_array().unwrap().clone();
    Outcome {
        plans: list("attempts")
            .iter()
            .map(|a| strings(&a["plan"]))
            .collect(),
        started,
        statuses: list("attempts")
            .iter()
            .map(|a| a["status"].as_str().unwrap().to_ascii_uppercase())
            .collect(),
        faults: list("faults")
            .iter()
            .map(|f| f["kind"].as_str().unwrap().to_owned())
            .collect(),
        replans: list("replans").len(),
        goal: report["goal"].as_str().unwrap().to_owned(),
        goal_reached: report["goal_reached"].as_bool().unwrap(),
        kb,
    }
}

/// The steps each attempt of the C++ agent started, in order.
fn cpp_started(cpp: &serde_json::Value) -> Vec<Vec<u64>> {
    cpp["attempts"]
        .as_array()
        .unwrap()
        .iter()
        .map(|a| {
            a["steps"]
                .as_array()
                .unwrap()
                .iter()
                .filter(|s| s["started"] == true)
                .map(|s| s["step"].as_u64().unwrap())
                .collect()
        })
        .collect()
}

/// `btc run --replan --format json` on a scenario, and the steps each
/// attempt started, in order, from its trace (1-based, as the KB numbers
/// them).
fn cli_run(rules: &Path, ariac: &Path, scenario: &Path) -> (serde_json::Value, Vec<Vec<u64>>) {
    let dir = tempfile::tempdir().unwrap();
    let trace = dir.path().join("trace.jsonl");
    let out = btc(&[
        "run",
        rules.to_str().unwrap(),
        "--problem",
        ariac.join("problem.pddl").to_str().unwrap(),
        "--replan",
        "--faults",
        scenario.to_str().unwrap(),
        "--format",
        "json",
        "--trace",
        trace.to_str().unwrap(),
    ]);
    let report = json_of(&out);
    let text = std::fs::read_to_string(&trace).unwrap();
    let mut attempts: Vec<Vec<u64>> = Vec::new();
    for line in text.lines() {
        let e: serde_json::Value = serde_json::from_str(line).unwrap();
        if e["event"] == "plan" {
            attempts.push(Vec::new());
        }
        if e["event"] == "step_started" {
            attempts
                .last_mut()
                .unwrap()
                .push(e["step"].as_u64().unwrap());
        }
    }
    (report, attempts)
}

/// The final KB of the same loop with btc's engine as the executor (the
/// engine `btc run --replan` runs; `btc run` does not print the final KB
/// of a closed loop), and its attempts' plans.
fn engine_kb(rules: &Path, scenario: &Path) -> (Vec<String>, Vec<Vec<String>>) {
    let project = btc_api::Project::open(rules).unwrap();
    let mut agent = btc_api::Agent::new(project, None);
    let mut engine = engine::ReportingEngine::new(btc_api::Faults::open(scenario).unwrap());
    let report = agent
        .run_with(&btc_api::AgentOptions::default(), &mut engine)
        .unwrap();
    let plans = report.attempts.iter().map(|a| a.plan.clone()).collect();
    (engine.kb, plans)
}
