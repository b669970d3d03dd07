//! The CLI as a user meets it: several errors at once, hostile strings in
//! outputs, atomic output files, and the design page's examples.

mod support;
use std::path::Path;
use support::{btc, plan_of};

#[test]
fn check_reports_every_error_with_its_code_and_place() {
    let out = btc(&[
        "check",
        "tests/fixtures/cli/several_errors.btrules",
        "--format",
        "json",
    ]);
    assert_eq!(out.status.code(), Some(1));
    let doc: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let found: Vec<(String, u64)> = doc["diagnostics"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|d| d["severity"] == "error")
        .map(|d| {
            (
                d["code"].as_str().unwrap().to_owned(),
                d["start"]["line"].as_u64().unwrap(),
            )
        })
        .collect();
    for expected in [
        ("R006", 7),
        ("R002", 8),
        ("R007", 9),
        ("R004", 10),
        ("R001", 11),
    ] {
        assert!(
            found.contains(&(expected.0.to_owned(), expected.1)),
            "missing {expected:?} in {found:?}"
        );
    }
}

#[test]
fn hostile_names_stay_inside_their_xml_attributes() {
    let out = btc(&[
        "compile",
        "tests/fixtures/cli/hostile.btrules",
        "--plan",
        "examples/ariac/plan.txt",
        "--emit",
        "btcpp",
        "--inline",
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let xml = String::from_utf8(out.stdout).unwrap();
    // Parse it back: every attribute value is exactly the original text.
    let mut reader = quick_xml::Reader::from_str(&xml);
    let mut names = Vec::new();
    let mut texts = Vec::new();
    loop {
        match reader.read_event().expect("well-formed XML") {
            quick_xml::events::Event::Eof => break,
            quick_xml::events::Event::Start(e) | quick_xml::events::Event::Empty(e) => {
                for a in e.attributes() {
                    let a = a.unwrap();
                    let v = a.unescape_value().unwrap().into_owned();
                    match a.key.as_ref() {
                        b"name" => names.push(v),
                        b"text" => texts.push(v),
                        _ => {}
                    }
                }
            }
            _ => {}
        }
    }
    assert!(
        names
            .iter()
            .any(|n| n == "q\" a' </BehaviorTree> <!-- & \n ü 日本 \"\"\" '''"),
        "{names:?}"
    );
    assert!(
        texts.iter().any(|t| t == "]]> \" ' < > & \t end"),
        "{texts:?}"
    );
    assert!(
        texts.iter().any(|t| t == "battery_red -> agv1"),
        "{texts:?}"
    );
}

#[test]
fn output_files_are_written_whole_or_not_at_all() {
    let dir = tempfile::tempdir().unwrap();
    let out_path = dir.path().join("tree.xml");
    std::fs::write(&out_path, "previous contents").unwrap();
    // A failing compile leaves the old file alone.
    let bad = btc(&[
        "compile",
        "tests/fixtures/cli/several_errors.btrules",
        "--plan",
        "examples/ariac/plan.txt",
        "--emit",
        "btcpp",
        "-o",
        out_path.to_str().unwrap(),
    ]);
    assert_eq!(bad.status.code(), Some(1));
    assert_eq!(
        std::fs::read_to_string(&out_path).unwrap(),
        "previous contents"
    );
    let good = btc(&[
        "compile",
        "examples/ariac/rules.btrules",
        "--plan",
        "examples/ariac/plan.txt",
        "--emit",
        "btcpp",
        "-o",
        out_path.to_str().unwrap(),
    ]);
    assert!(good.status.success());
    assert!(std::fs::read_to_string(&out_path)
        .unwrap()
        .starts_with("<?xml"));
    assert_eq!(
        std::fs::read_dir(dir.path()).unwrap().count(),
        1,
        "no temporary file left behind"
    );
}

/// `btc compile -o` lowers and emits on a second core while it replays
/// the plan, into a temporary file: a plan the replay refuses leaves the
/// old output as it was and nothing beside it, though its tree lowered;
/// an accepted one writes the same bytes as standard output gets.
#[test]
fn an_output_made_while_the_plan_is_replayed_lands_only_if_the_plan_is_accepted() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("tree.py");
    std::fs::write(&out, "previous contents").unwrap();
    let compile = |plan: &str, extra: &[&str]| {
        let mut args = vec![
            "compile",
            "examples/p3_assembler/rules.btrules",
            "--plan",
            plan,
            "--problem",
            "examples/p3_assembler/problem.pddl",
            "--emit",
            "pytrees",
        ];
        args.extend_from_slice(extra);
        btc(&args)
    };
    let refused = compile(
        "tests/fixtures/cli/p3_refused.tplan",
        &["-o", out.to_str().unwrap()],
    );
    assert_eq!(refused.status.code(), Some(1));
    let stderr = String::from_utf8_lossy(&refused.stderr);
    assert!(stderr.contains("does not hold"), "{stderr}");
    assert_eq!(std::fs::read_to_string(&out).unwrap(), "previous contents");
    let names = |d: &Path| -> Vec<String> {
        let mut v: Vec<String> = std::fs::read_dir(d)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        v.sort();
        v
    };
    assert_eq!(names(dir.path()), ["tree.py"]);

    let plan = "examples/p3_assembler/plan.tplan";
    let accepted = compile(plan, &["-o", out.to_str().unwrap()]);
    assert!(accepted.status.success());
    assert_ne!(std::fs::read_to_string(&out).unwrap(), "previous contents");
    assert_eq!(names(dir.path()), ["tree.py"]);
    // The same bytes as the way that waits for the verdict (taken when the
    // output's folder is still to be created), its paths recorded alike.
    let (made, waited) = (dir.path().join("a"), dir.path().join("b"));
    std::fs::create_dir(&made).unwrap();
    for d in [&made, &waited] {
        let o = d.join("tree.py");
        let args = [
            "--runtime",
            "import",
            "--source-paths",
            "-o",
            o.to_str().unwrap(),
        ];
        assert!(compile(plan, &args).status.success());
        // An imported runtime is written beside the module either way.
        assert_eq!(names(d), ["btc_runtime.py", "tree.py"]);
    }
    let tree = std::fs::read_to_string(made.join("tree.py")).unwrap();
    assert!(tree.contains("# problem: \"../"), "{tree}");
    assert_eq!(
        tree,
        std::fs::read_to_string(waited.join("tree.py")).unwrap()
    );
}

/// `compile --check -o FILE` is CI's "is the committed tree current": exit
/// 1 when FILE is missing or would change, 0 when it would not, and never a
/// byte written (nor the py_trees runtime an imported module needs).
#[test]
fn compile_check_says_whether_the_output_would_change_and_writes_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("tree.py");
    let runtime = dir.path().join("btc_runtime.py");
    let compile = |extra: &[&str]| {
        let mut args = vec![
            "compile",
            "examples/two_robots/rules.btrules",
            "--plan",
            "examples/two_robots/plan.plan",
            "--emit",
            "pytrees",
            "--runtime",
            "import",
            "-o",
            out.to_str().unwrap(),
        ];
        args.extend_from_slice(extra);
        btc(&args)
    };
    let listing = || {
        let mut names: Vec<String> = std::fs::read_dir(dir.path())
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        names.sort();
        names
    };
    // Nothing there yet: both files are missing, and stay so.
    let missing = compile(&["--check"]);
    support::exits(&missing, 1, "--check with no file");
    let said = String::from_utf8_lossy(&missing.stdout);
    assert!(said.contains("tree.py: missing"), "{said}");
    assert!(said.contains("btc_runtime.py: missing"), "{said}");
    assert!(listing().is_empty(), "{:?}", listing());
    // Written, then current.
    support::exits(&compile(&[]), 0, "compile");
    support::exits(&compile(&["--check"]), 0, "--check after compile");
    // One byte changed in either file: out of date, and left as it is.
    for file in [&out, &runtime] {
        let good = std::fs::read(file).unwrap();
        let mut changed = good.clone();
        changed.push(b'\n');
        std::fs::write(file, &changed).unwrap();
        let stale = compile(&["--check"]);
        support::exits(&stale, 1, "--check on a changed file");
        let said = String::from_utf8_lossy(&stale.stdout);
        assert!(said.contains("out of date"), "{said}");
        assert_eq!(std::fs::read(file).unwrap(), changed);
        std::fs::write(file, &good).unwrap();
    }
    assert_eq!(listing(), ["btc_runtime.py", "tree.py"]);
    // `--check` needs a file to compare with.
    let no_file = btc(&[
        "compile",
        "examples/two_robots/rules.btrules",
        "--plan",
        "examples/two_robots/plan.plan",
        "--emit",
        "btcpp",
        "--check",
    ]);
    support::exits(&no_file, 2, "--check without -o");
}

/// A long plan's tree is streamed: to a file and to standard output it is
/// the same bytes (a py_trees module's two parts made on two threads for
/// the file), and a reader that stops early (`| head`) ends the compile
/// quietly, not with a panic.
#[test]
fn a_long_plan_streams_to_a_file_and_to_a_reader_that_stops() {
    let dir = tempfile::tempdir().unwrap();
    for f in ["domain.pddl", "problem.pddl", "rules.btrules"] {
        std::fs::copy(
            Path::new("examples/p3_assembler").join(f),
            dir.path().join(f),
        )
        .unwrap();
    }
    std::fs::write(
        dir.path().join("plan.tplan"),
        btc_testkit::long_p3_plan(20_000),
    )
    .unwrap();
    let args = [
        "compile",
        "rules.btrules",
        "--plan",
        "plan.tplan",
        "--emit",
        "btcpp",
        "--allow-invalid-plan",
    ];
    let to_stdout = support::btc_in(dir.path(), &args);
    assert!(to_stdout.status.success());
    assert!(
        to_stdout.stdout.len() > 4 << 20,
        "{} bytes",
        to_stdout.stdout.len()
    );
    let to_file = support::btc_in(dir.path(), &[&args[..], &["-o", "tree.xml"]].concat());
    assert!(to_file.status.success());
    assert!(std::fs::read(dir.path().join("tree.xml")).unwrap() == to_stdout.stdout);
    let py_args = [&args[..5], &["pytrees", "--allow-invalid-plan"]].concat();
    let py_stdout = support::btc_in(dir.path(), &py_args);
    assert!(py_stdout.status.success());
    assert!(py_stdout.stdout.len() > 1 << 20);
    let py_file = support::btc_in(dir.path(), &[&py_args[..], &["-o", "tree.py"]].concat());
    assert!(py_file.status.success());
    assert!(std::fs::read(dir.path().join("tree.py")).unwrap() == py_stdout.stdout);

    let mut child = std::process::Command::new(env!("CARGO_BIN_EXE_btc"))
        .args(args)
        .current_dir(dir.path())
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    let mut head = [0u8; 64];
    std::io::Read::read_exact(child.stdout.as_mut().unwrap(), &mut head).unwrap();
    assert!(head.starts_with(b"<?xml"));
    drop(child.stdout.take());
    let out = child.wait_with_output().unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{stderr}");
    assert!(!stderr.contains("panicked"), "{stderr}");
}

/// A long plan's compile serves its large buffers from a region whose
/// pages a second thread writes in (`btc::alloc`, the binary's allocator
/// only): the binary's tree is byte for byte the one the same command
/// makes in this process, where the region is never made.
#[test]
fn a_long_compile_is_the_same_with_its_pages_written_in_beforehand() {
    let dir = tempfile::tempdir().unwrap();
    let example = Path::new("examples/p3_assembler");
    let plan = dir.path().join("plan.tplan");
    std::fs::write(&plan, btc_testkit::long_p3_plan(30_000)).unwrap();
    assert!(std::fs::metadata(&plan).unwrap().len() > 1 << 20);
    for (format, file) in [("pytrees", "tree.py"), ("btcpp", "tree.xml")] {
        let args = |out: &Path| -> Vec<std::ffi::OsString> {
            vec![
                "compile".into(),
                example.join("rules.btrules").into(),
                "--plan".into(),
                plan.clone().into(),
                "--problem".into(),
                example.join("problem.pddl").into(),
                "--emit".into(),
                format.into(),
                "-o".into(),
                out.into(),
            ]
        };
        let (by_binary, in_process) =
            (dir.path().join(file), dir.path().join(format!("in-{file}")));
        let out = std::process::Command::new(env!("CARGO_BIN_EXE_btc"))
            .args(args(&by_binary))
            .output()
            .unwrap();
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        let mut argv = vec![std::ffi::OsString::from("btc")];
        argv.extend(args(&in_process));
        assert_eq!(btc::run(argv), std::process::ExitCode::SUCCESS);
        let (a, b) = (
            std::fs::read(&by_binary).unwrap(),
            std::fs::read(&in_process).unwrap(),
        );
        assert!(a.len() > 1 << 20, "{format}: {} bytes", a.len());
        assert!(
            a == b,
            "{format}: the binary's tree differs from the library's"
        );
    }
}

/// Every command that prints its result ends quietly when its reader has
/// gone before it writes (`btc plan ... --format json | head -c 10`): the
/// pipe's read end is closed before btc starts, so every write fails.
#[test]
fn every_command_ends_quietly_when_its_reader_has_gone() {
    let out_dir = tempfile::tempdir().unwrap();
    let out = out_dir.path().display().to_string();
    let (ariac, p3) = ("examples/ariac", "examples/p3_assembler");
    let rules = format!("{ariac}/rules.btrules");
    let plan = format!("{ariac}/plan.txt");
    let (d, p) = (format!("{p3}/domain.pddl"), format!("{p3}/problem.pddl"));
    let timed = format!("{p3}/plan.tplan");
    let trial = "examples/ariac_cell/trials/mixed.yaml";
    let commands: Vec<Vec<&str>> = vec![
        vec!["plan", &d, &p],
        vec!["validate", &d, &p, &timed],
        vec!["pddl", &d, &p],
        vec!["pddl", &d, "--json"],
        vec!["check", &rules],
        vec!["compile", &rules, "--plan", &plan, "--emit", "btcpp"],
        vec!["run", &rules, "--plan", &plan],
        vec!["run", &rules, "--replan"],
        vec!["trial", trial],
        vec!["executor", &rules, "-o", &out],
    ];
    let runs = commands
        .iter()
        .flat_map(|c| {
            [
                [&c[..], &["--format", "text"]].concat(),
                [&c[..], &["--format", "json"]].concat(),
            ]
        })
        .chain([vec!["fmt", "--check", &rules]]);
    for args in runs {
        let (reader, writer) = std::io::pipe().unwrap();
        drop(reader);
        let run = std::process::Command::new(env!("CARGO_BIN_EXE_btc"))
            .args(&args)
            .env("NO_COLOR", "1")
            .stdout(writer)
            .stderr(std::process::Stdio::piped())
            .output()
            .unwrap();
        let stderr = String::from_utf8_lossy(&run.stderr);
        let what = format!("btc {}", args.join(" "));
        assert!(
            !stderr.contains("panicked") && !stderr.contains("Broken pipe"),
            "{what}: {stderr}"
        );
        assert!(run.status.success(), "{what}: {:?}\n{stderr}", run.status);
    }
}

/// The two example files of the design page (btrules v1, kept as
/// `tests/fixtures/design/`) parse and check as written.
#[test]
fn the_design_page_examples_check_as_written() {
    for example in ["ariac", "p3_assembler"] {
        let block = std::fs::read_to_string(
            Path::new(env!("CARGO_MANIFEST_DIR"))
                .join("tests/fixtures/design")
                .join(format!("{example}.btrules")),
        )
        .unwrap();
        let dir = tempfile::tempdir().unwrap();
        for f in ["domain.pddl", "problem.pddl"] {
            std::fs::copy(
                Path::new(env!("CARGO_MANIFEST_DIR"))
                    .join("examples")
                    .join(example)
                    .join(f),
                dir.path().join(f),
            )
            .unwrap();
        }
        let rules = dir.path().join("rules.btrules");
        std::fs::write(&rules, block).unwrap();
        let out = btc(&["check", rules.to_str().unwrap()]);
        assert!(
            out.status.success(),
            "{example}: {}",
            String::from_utf8_lossy(&out.stderr)
        );
        assert!(String::from_utf8_lossy(&out.stdout).contains("0 errors"));
    }
}

/// Each example's README shows the picture `--emit mermaid` draws today.
#[test]
fn example_readmes_show_the_current_picture() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples");
    let mut checked = 0;
    for e in std::fs::read_dir(&root).unwrap() {
        let dir = e.unwrap().path();
        if !dir.join("rules.btrules").is_file() {
            continue;
        }
        let readme =
            std::fs::read_to_string(dir.join("README.md")).expect("every example has a README");
        let shown = readme
            .split("```mermaid\n")
            .nth(1)
            .and_then(|r| r.split("```").next())
            .expect("a mermaid picture");
        let name = dir.file_name().unwrap().to_string_lossy();
        let rules = format!("examples/{name}/rules.btrules");
        let plan = plan_of(&name);
        let out = btc(&["compile", &rules, "--plan", &plan, "--emit", "mermaid"]);
        assert_eq!(
            shown,
            String::from_utf8_lossy(&out.stdout),
            "{}: regenerate the README picture",
            dir.display()
        );
        checked += 1;
    }
    assert!(checked >= 4);
}

/// `btc plan` writes a plan `btc validate` accepts, to stdout or atomically
/// to `-o`; statistics go to stderr; the exit code says what happened.
#[test]
fn plan_writes_plans_that_validate() {
    let dir = tempfile::tempdir().unwrap();
    let out_path = dir.path().join("sas_plan");
    let (domain, problem) = ("examples/ariac/domain.pddl", "examples/ariac/problem.pddl");
    let run = btc(&["plan", domain, problem, "-o", out_path.to_str().unwrap()]);
    assert!(run.status.success(), "{run:?}");
    assert!(run.stdout.is_empty());
    let stderr = String::from_utf8_lossy(&run.stderr);
    assert!(stderr.contains("plan: 4 steps, cost 4;"), "{stderr}");
    assert!(stderr.contains("expanded"), "{stderr}");
    let text = std::fs::read_to_string(&out_path).unwrap();
    assert!(text.ends_with("; cost = 4 (unit cost)\n"), "{text}");
    let check = btc(&["validate", domain, problem, out_path.to_str().unwrap()]);
    assert!(check.status.success(), "{check:?}");
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);

    // Optimal search to stdout gives the same four steps.
    let astar = btc(&[
        "plan",
        domain,
        problem,
        "--search",
        "astar",
        "--heuristic",
        "max",
    ]);
    assert_eq!(String::from_utf8_lossy(&astar.stdout), text);

    // JSON: the plan and the statistics in one document.
    let json = btc(&["plan", domain, problem, "--format", "json"]);
    let doc: serde_json::Value = serde_json::from_slice(&json.stdout).unwrap();
    assert_eq!(doc["solved"], true);
    assert_eq!(doc["plan"]["steps"], 4);
    assert!(doc["statistics"]["expanded"].as_u64().unwrap() >= 4);

    // Unsolvable: exit 1, no plan; a bad limit is a usage error (2).
    let none = btc(&[
        "plan",
        "tests/fixtures/diagnostics/S003/domain.pddl",
        "tests/fixtures/diagnostics/S003/problem.pddl",
    ]);
    assert_eq!(none.status.code(), Some(1));
    assert!(none.stdout.is_empty());
    assert!(String::from_utf8_lossy(&none.stderr).contains("no plan exists"));
    let bad = btc(&["plan", domain, problem, "--timeout", "-1"]);
    assert_eq!(bad.status.code(), Some(2));
}

#[test]
fn json_diagnostics_carry_their_fixes() {
    let out = btc(&[
        "check",
        "tests/fixtures/diagnostics/R007/rules.btrules",
        "--format",
        "json",
    ]);
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let d = v["diagnostics"]
        .as_array()
        .unwrap()
        .iter()
        .find(|d| d["code"] == "R007")
        .unwrap();
    let fix = &d["fixes"][0];
    assert_eq!(fix["replacement"], "MoveTo");
    assert_eq!(fix["start"], d["start"]);
    assert_eq!(fix["end"], d["end"]);
    // Diagnostics without a fix have no `fixes` key at all.
    let r014 = v["diagnostics"]
        .as_array()
        .unwrap()
        .iter()
        .find(|d| d["code"] == "R014")
        .unwrap();
    assert!(r014.get("fixes").is_none());
}

#[test]
fn a_palette_port_type_that_a_rule_does_not_fit_is_shown_in_the_palette() {
    // tests/fixtures/palette: MoveTo's `target` is an int in nodes.xml.
    let out = btc(&["check", "tests/fixtures/palette/rules.btrules"]);
    assert_eq!(out.status.code(), Some(1));
    insta::assert_snapshot!(String::from_utf8_lossy(&out.stderr));
    let out = btc(&[
        "check",
        "tests/fixtures/palette/rules.btrules",
        "--format",
        "json",
    ]);
    let doc: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let d = &doc["diagnostics"][0];
    assert_eq!(d["code"], "R004");
    assert_eq!(d["labels"][0]["file"], "tests/fixtures/palette/nodes.xml");
    assert_eq!(d["labels"][0]["start"]["line"], 11);
}
