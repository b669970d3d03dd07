//! The generated C++ executor (`btc executor`) runs btc's trees in real
//! BehaviorTree.CPP exactly as `btc run` runs them: for every example, the
//! values and scripts fixtures (the scripts are BT.CPP's own, so its
//! `Script`, `ScriptCondition` and pre-/post-conditions run them), the
//! workshop fixtures (`steps`, `steps backchained`, `steps parallel`) and
//! every corpus domain with rules, each plan is compiled to BT.CPP XML (with
//! and without `--inline`) and its world to a `.kb` file, run by the
//! executor with the generated nodes (whose default bodies simulate the
//! actions as `btc run` does) and by `btc run`; the step starts and ends
//! (with their ticks), the final status, the goal check and the final KB
//! must be the same. A timed plan with concurrent steps (three robots, as
//! PlanSys2's bt_example) runs `steps scheduled` and `steps`: in BT.CPP too,
//! every step the plan ends before another starts ends first.
//!
//! Build cost: the support library is compiled once, and every rules file's
//! generated nodes go into one executable (`all.cpp` below dispatches on
//! the rule set's name), which takes the tree and the world as arguments.

mod support;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use support::btc;

fn repo() -> PathBuf {
    btc_testkit::repo()
}

fn ok(out: &Output, what: &str) {
    assert!(
        out.status.code() != Some(2) && out.status.code().is_some(),
        "{what}: {}{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
}

/// A rules file and the plans it runs.
struct RuleSet {
    name: String,
    rules: PathBuf,
    jobs: Vec<Job>,
}

struct Job {
    plan: PathBuf,
    problem: PathBuf,
    /// Extra `--ticks-per-action` values to run (1 always runs).
    ticks: Vec<u32>,
}

fn first_plan(dir: &Path) -> PathBuf {
    let mut plans: Vec<PathBuf> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| {
            p.file_name()
                .is_some_and(|n| n.to_string_lossy().starts_with("plan."))
        })
        .collect();
    plans.sort();
    plans.remove(0)
}

fn rule_sets() -> Vec<RuleSet> {
    let mut sets = Vec::new();
    for ex in ["ariac", "nist_kitting", "p3_assembler", "two_robots"] {
        let dir = repo().join("examples").join(ex);
        sets.push(RuleSet {
            name: ex.into(),
            rules: dir.join("rules.btrules"),
            jobs: vec![Job {
                plan: first_plan(&dir),
                problem: dir.join("problem.pddl"),
                ticks: vec![0, 3],
            }],
        });
    }
    // A plan whose second step cannot start: both fail there, alike.
    sets[0].jobs.push(Job {
        plan: repo().join("tests/fixtures/btcpp/ariac_grasp_first.txt"),
        problem: repo().join("examples/ariac/problem.pddl"),
        ticks: vec![],
    });
    // Values computed per step (table lookups passed to a tree, strings
    // interpolating them) as ports of SubTree calls.
    let values = repo().join("tests/fixtures/emit/values");
    sets.push(RuleSet {
        name: "values".into(),
        rules: values.join("rules.btrules"),
        jobs: vec![Job {
            plan: values.join("plan.txt"),
            problem: values.join("problem.pddl"),
            ticks: vec![0, 3],
        }],
    });
    // BT.CPP scripts from the rules: `Script`/`ScriptCondition` leaves and
    // the pre- and post-condition attributes (`_skipIf`, `_onSuccess`,
    // `_failureIf`, `_successIf`, `_post`...), each rule tree's entries in
    // its SubTree's blackboard (in one blackboard with `--inline`).
    let scripts = repo().join("tests/fixtures/scripts");
    sets.push(RuleSet {
        name: "scripts".into(),
        rules: scripts.join("rules.btrules"),
        jobs: vec![Job {
            plan: scripts.join("plan.txt"),
            problem: values.join("problem.pddl"),
            ticks: vec![0, 3],
        }],
    });
    let workshop = repo().join("lang/tests/fixtures/pytrees/workshop");
    arrangements(
        &mut sets,
        "workshop",
        &workshop,
        "plan.txt",
        &["in_order", "backchained", "parallel"],
    );
    let timed = repo().join("runtime/tests/fixtures/three_way/timed");
    arrangements(
        &mut sets,
        "timed",
        &timed,
        "plan.tplan",
        &["scheduled", "in_order", "scheduled_imported"],
    );
    for d in btc_testkit::corpus_rules().unwrap_or_default() {
        sets.push(RuleSet {
            jobs: d
                .plans
                .into_iter()
                .map(|p| Job {
                    problem: d
                        .corpus
                        .join(format!("{}.pddl", p.file_stem().unwrap().to_string_lossy())),
                    plan: p,
                    ticks: vec![],
                })
                .collect(),
            name: d.name,
            rules: d.rules,
        });
    }
    sets
}

/// What a run came to, as both sides report it.
#[derive(Debug, PartialEq)]
struct Outcome {
    /// (tick, started?, step)
    steps: Vec<(u64, bool, u64)>,
    status: String,
    ticks: u64,
    goal: bool,
    kb: Vec<String>,
}

fn from_executor(out: &str) -> Outcome {
    let mut o = Outcome {
        steps: Vec::new(),
        status: String::new(),
        ticks: 0,
        goal: false,
        kb: Vec::new(),
    };
    let mut in_kb = false;
    for line in out.lines() {
        if in_kb {
            o.kb.push(line.trim().to_owned());
        } else if let Some(rest) = line.strip_prefix("tick ") {
            // tick 3: started step 2: (grasp ...)
            let (tick, rest) = rest.split_once(": ").unwrap();
            let (what, rest) = rest.split_once(" step ").unwrap();
            let step = rest.split(':').next().unwrap();
            o.steps.push((
                tick.parse().unwrap(),
                what == "started",
                step.parse().unwrap(),
            ));
        } else if let Some(rest) = line.strip_prefix("status: ") {
            let mut w = rest.split_whitespace();
            o.status = w.next().unwrap().to_owned();
            o.ticks = w.nth(1).unwrap().parse().unwrap();
        } else if let Some(rest) = line.strip_prefix("goal: ") {
            o.goal = rest == "reached";
        } else if line == "kb:" {
            in_kb = true;
        }
    }
    o
}

fn from_btc_run(summary: &str, trace: &str) -> Outcome {
    let s: serde_json::Value = serde_json::from_str(summary).unwrap();
    let mut steps = Vec::new();
    for line in trace.lines() {
        let v: serde_json::Value = serde_json::from_str(line).unwrap();
        let started = match v["event"].as_str() {
            Some("step_started") => true,
            Some("step_finished") => false,
            _ => continue,
        };
        steps.push((
            v["tick"].as_u64().unwrap(),
            started,
            v["step"].as_u64().unwrap(),
        ));
    }
    Outcome {
        steps,
        status: s["status"].as_str().unwrap().to_owned(),
        ticks: s["ticks"].as_u64().unwrap(),
        goal: s["goal_reached"].as_bool().unwrap_or(true),
        kb: s["kb"]
            .as_array()
            .unwrap_or_else(|| panic!("btc run printed no KB:\n{summary}"))
            .iter()
            .map(|f| f.as_str().unwrap().to_owned())
            .collect(),
    }
}

/// For a timed plan: the first pair of steps where the plan ends the first
/// before the second starts (within IPC's tolerance) and the run (its
/// events in their order) does not, if any. A step with no events is one
/// the rules skip.
fn plan_order_broken(plan: &Path, steps: &[(u64, bool, u64)]) -> Option<(usize, usize)> {
    let text = std::fs::read_to_string(plan).unwrap();
    let (plan, _) = btc_pddl::plan::parse_plan(&text, 0);
    if plan.steps.iter().any(|s| s.time.is_none()) {
        return None;
    }
    let tol = btc_pddl::validate::DEFAULT_EPSILON / 10.0;
    let at = |started: bool, step: usize| {
        steps
            .iter()
            .position(|&(_, s, k)| s == started && k == step as u64)
    };
    let ends = |s: &btc_pddl::plan::PlanStep| s.time.unwrap_or(0.0) + s.duration.unwrap_or(0.0);
    for (i, a) in plan.steps.iter().enumerate() {
        for (j, b) in plan.steps.iter().enumerate().skip(i + 1) {
            let (Some(end), Some(start)) = (at(false, i + 1), at(true, j + 1)) else {
                continue;
            };
            if ends(a) <= b.time.unwrap_or(0.0) + tol && end > start {
                return Some((i + 1, j + 1));
            }
        }
    }
    None
}

/// `btc compile` to `out`, which must succeed.
fn compile(rules: &str, plan: &str, problem: &str, emit: &str, out: &str, inline: bool) {
    let mut args = vec![
        "compile",
        rules,
        "--plan",
        plan,
        "--problem",
        problem,
        "--emit",
        emit,
        "-o",
        out,
        // Some plans fail on purpose (a grasp before the move): both
        // executors must fail them the same way.
        "--allow-invalid-plan",
    ];
    if inline {
        args.push("--inline");
    }
    let c = btc(&args);
    assert_eq!(
        c.status.code(),
        Some(0),
        "btc {}: {}",
        args.join(" "),
        String::from_utf8_lossy(&c.stderr)
    );
}

/// `btc run` with a trace, and what it came to.
fn btc_run(
    rules: &str,
    plan: &str,
    problem: &str,
    ticks_per_action: &str,
    trace: &Path,
) -> (Output, Outcome) {
    let run = btc(&[
        "run",
        rules,
        "--plan",
        plan,
        "--problem",
        problem,
        "--ticks-per-action",
        ticks_per_action,
        "--allow-invalid-plan",
        "--trace",
        trace.to_str().unwrap(),
        "--format",
        "json",
    ]);
    ok(&run, "btc run");
    let outcome = from_btc_run(
        &String::from_utf8_lossy(&run.stdout),
        &std::fs::read_to_string(trace).unwrap(),
    );
    (run, outcome)
}

/// The test's executable: every rule set's generated nodes, one `main`.
fn all_executors(sets: &[RuleSet], dir: &Path) -> String {
    let mut src = String::from(
        "// Written by tests/btcpp_executor.rs: every rule set's generated nodes in one\n\
         // executable; the first argument names the rule set.\n\
         #include <btc/executor.hpp>\n#include <cstring>\n#include <iostream>\n",
    );
    for s in sets {
        let _ = writeln!(src, "#include \"{}/btc_nodes.cpp\"", s.name);
    }
    src.push_str(
        "\nint main(int argc, char** argv)\n{\n  struct Set { const char* name; btc::RegisterNodes nodes; };\n  const Set sets[] = {\n",
    );
    for s in sets {
        let _ = writeln!(src, "    {{ \"{0}\", &{0}::registerNodes }},", s.name);
    }
    src.push_str(
        "  };\n  for(const Set& s : sets)\n  {\n    if(argc > 1 && std::strcmp(argv[1], s.name) == 0)\n    {\n      argv[1] = argv[0];\n      return btc::runExecutor(argc - 1, argv + 1, s.nodes);\n    }\n  }\n  std::cerr << \"no such rule set\\n\";\n  return 2;\n}\n",
    );
    std::fs::write(dir.join("all.cpp"), src).unwrap();
    format!(
        "cmake_minimum_required(VERSION 3.16)\nproject(btc_executors LANGUAGES CXX)\n\
         find_package(behaviortree_cpp REQUIRED)\n\
         add_subdirectory(\"{}\" btc_btcpp)\n\
         add_executable(btc_all_executors all.cpp)\n\
         target_compile_features(btc_all_executors PRIVATE cxx_std_17)\n\
         target_link_libraries(btc_all_executors PRIVATE btc::btcpp)\n",
        repo().join("integrations/btcpp").display()
    )
}

#[test]
fn generated_executors_run_every_plan_as_btc_run_does() {
    let Some(prefix) = btc_testkit::btcpp() else {
        return;
    };
    let sets = rule_sets();
    let dir = btc_testkit::target_dir("btcpp/executors");
    std::fs::create_dir_all(&dir).unwrap();
    for s in &sets {
        let out = btc(&[
            "executor",
            s.rules.to_str().unwrap(),
            "-o",
            dir.join(&s.name).to_str().unwrap(),
            "--name",
            &s.name,
        ]);
        assert_eq!(
            out.status.code(),
            Some(0),
            "btc executor {}: {}",
            s.name,
            String::from_utf8_lossy(&out.stderr)
        );
    }
    let cmake = all_executors(&sets, &dir);
    std::fs::write(dir.join("CMakeLists.txt"), cmake).unwrap();
    let build = btc_testkit::target_dir("btcpp/executors-build");
    btc_testkit::cmake_build(&dir, &build, &prefix, &[], &["btc_all_executors"])
        .unwrap_or_else(|e| panic!("{e}"));
    let exe = build.join("btc_all_executors");
    let work = btc_testkit::target_dir("btcpp/executor-runs");
    std::fs::create_dir_all(&work).unwrap();
    let mut compared = 0;
    let mut failed_alike = 0;
    for s in &sets {
        let rules = s.rules.to_str().unwrap();
        for (j, job) in s.jobs.iter().enumerate() {
            let plan = job.plan.to_str().unwrap();
            let problem = job.problem.to_str().unwrap();
            let stem = work.join(format!("{}-{j}", s.name));
            let kb = stem.with_extension("kb");
            compile(rules, plan, problem, "kb", kb.to_str().unwrap(), false);
            for ticks in std::iter::once(1).chain(job.ticks.iter().copied()) {
                let tpa = ticks.to_string();
                let trace = stem.with_extension(format!("t{ticks}.jsonl"));
                let (run, want) = btc_run(rules, plan, problem, &tpa, &trace);
                for inline in [false, true] {
                    let xml = stem.with_extension(if inline { "inline.xml" } else { "xml" });
                    let xml_s = xml.to_str().unwrap().to_owned();
                    compile(rules, plan, problem, "btcpp", &xml_s, inline);
                    let ran = Command::new(&exe)
                        .args([
                            &s.name,
                            &xml_s,
                            kb.to_str().unwrap(),
                            "--ticks-per-action",
                            &tpa,
                        ])
                        .output()
                        .unwrap();
                    let text = String::from_utf8_lossy(&ran.stdout);
                    assert_ne!(
                        ran.status.code(),
                        Some(2),
                        "{} {plan} inline={inline}: {}",
                        s.name,
                        String::from_utf8_lossy(&ran.stderr)
                    );
                    let got = from_executor(&text);
                    assert_eq!(
                        got, want,
                        "{} {plan} inline={inline} ticks-per-action={ticks}: BT.CPP (left) and btc run (right) differ\n{text}",
                        s.name
                    );
                    assert_eq!(
                        ran.status.code() == Some(0),
                        run.status.code() == Some(0),
                        "{} {plan}: exit codes",
                        s.name
                    );
                    assert!(!got.steps.is_empty() && !got.kb.is_empty());
                    assert_eq!(
                        plan_order_broken(&job.plan, &got.steps),
                        None,
                        "{} {plan}: a step (left) the plan ends before another (right) starts does not end first in BT.CPP",
                        s.name
                    );
                    if got.status == "SUCCESS" {
                        assert!(got.goal, "{} {plan}", s.name);
                    } else {
                        failed_alike += 1;
                    }
                    compared += 1;
                }
            }
        }
    }
    // The examples, workshop and failing plans at least (and the corpus
    // when it is there); exactly the failing plan's runs fail.
    assert!(compared >= 56, "{compared} runs compared");
    assert_eq!(failed_alike, 2, "only the plan that grasps first fails");
    palette_written_by_btcpp_imports_and_checks(&exe, &work);
}

/// The palette BT.CPP writes for the ARIAC executor's factory
/// (`writeTreeNodesModelXML`) declares the nodes of a rules file that
/// imports it: it checks, and its tree runs in BT.CPP as the example's
/// does; a port type from the palette is enforced, shown at the palette.
fn palette_written_by_btcpp_imports_and_checks(exe: &Path, work: &Path) {
    let dir = work.join("palette");
    std::fs::create_dir_all(&dir).unwrap();
    let palette = Command::new(exe)
        .args(["ariac", "--palette"])
        .output()
        .unwrap();
    assert_eq!(palette.status.code(), Some(0));
    let xml = String::from_utf8(palette.stdout).unwrap();
    assert!(xml.contains("<TreeNodesModel>") && xml.contains("<Action ID=\"Grasp\">"));
    std::fs::write(dir.join("nodes.xml"), &xml).unwrap();
    let fixture = repo().join("tests/fixtures/btcpp/palette");
    for f in ["rules.btrules", "mismatch.btrules"] {
        std::fs::copy(fixture.join(f), dir.join(f)).unwrap();
    }
    let example = repo().join("examples/ariac");
    std::fs::copy(example.join("domain.pddl"), dir.join("domain.pddl")).unwrap();
    let path = |f: &str| dir.join(f).to_str().unwrap().to_owned();

    let check = btc(&["check", &path("rules.btrules"), "--format", "json"]);
    let doc: serde_json::Value = serde_json::from_slice(&check.stdout).unwrap();
    assert_eq!(doc["ok"], true, "{doc:#}");
    let codes: Vec<&str> = doc["diagnostics"]
        .as_array()
        .unwrap()
        .iter()
        .map(|d| d["code"].as_str().unwrap())
        .collect();
    assert!(codes.is_empty(), "the example checks clean: {codes:?}");

    let (plan, problem) = (example.join("plan.txt"), example.join("problem.pddl"));
    let (plan, problem) = (plan.to_str().unwrap(), problem.to_str().unwrap());
    let tree = path("tree.xml");
    let kb = path("world.kb");
    compile(&path("rules.btrules"), plan, problem, "btcpp", &tree, false);
    compile(&path("rules.btrules"), plan, problem, "kb", &kb, false);
    let example_rules = example.join("rules.btrules");
    let trace = dir.join("run.jsonl");
    let (_, want) = btc_run(example_rules.to_str().unwrap(), plan, problem, "1", &trace);
    let ran = Command::new(exe)
        .args(["ariac", &tree, &kb])
        .output()
        .unwrap();
    let text = String::from_utf8_lossy(&ran.stdout);
    assert_eq!(
        ran.status.code(),
        Some(0),
        "{text}{}",
        String::from_utf8_lossy(&ran.stderr)
    );
    assert_eq!(from_executor(&text), want, "{text}");

    let check = btc(&["check", &path("mismatch.btrules"), "--format", "json"]);
    assert_eq!(check.status.code(), Some(1));
    let doc: serde_json::Value = serde_json::from_slice(&check.stdout).unwrap();
    let d = &doc["diagnostics"][0];
    assert_eq!(d["code"], "R004", "{doc:#}");
    assert_eq!(d["labels"][0]["file"].as_str().unwrap(), path("nodes.xml"));
    let line = d["labels"][0]["start"]["line"].as_u64().unwrap() as usize;
    let declared = xml.lines().nth(line - 1).unwrap();
    assert!(
        declared.contains(r#"name="step" type="int""#),
        "the label is on WaitForStep's port: {declared}"
    );
}

/// One rule set per arrangement of a fixture folder (`NAME.btrules` beside
/// one plan and its problem), each run for 0 and 2 ticks an action.
fn arrangements(sets: &mut Vec<RuleSet>, prefix: &str, dir: &Path, plan: &str, names: &[&str]) {
    for arrangement in names {
        sets.push(RuleSet {
            name: format!("{prefix}_{arrangement}"),
            rules: dir.join(format!("{arrangement}.btrules")),
            jobs: vec![Job {
                plan: dir.join(plan),
                problem: dir.join("problem.pddl"),
                ticks: vec![0, 2],
            }],
        });
    }
}
