//! Every example × every emitter, snapshotted: one glob over `examples/`,
//! so a new example is covered without a list. Review every snapshot change
//! as if it were code.

use std::path::Path;
use std::process::Command;

const EMITTERS: &[&str] = &["btcpp", "pytrees", "json", "dot", "mermaid", "commands"];

/// The first plan of an example folder (`plan.*`, sorted).
fn plan_of(dir: &Path) -> std::path::PathBuf {
    let mut plans: Vec<_> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| {
            p.file_name()
                .unwrap()
                .to_string_lossy()
                .starts_with("plan.")
        })
        .collect();
    plans.sort();
    plans.into_iter().next().expect("an example has a plan.*")
}

fn compile(rules: &Path, emit: &str, extra: &[&str]) -> String {
    let dir = rules.parent().unwrap();
    let out = Command::new(env!("CARGO_BIN_EXE_btc"))
        .arg("compile")
        .arg(rules)
        .arg("--plan")
        .arg(plan_of(dir))
        .args(["--emit", emit])
        .args(extra)
        .env("NO_COLOR", "1")
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{} --emit {emit}: {}",
        rules.display(),
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8(out.stdout).unwrap()
}

#[test]
fn every_example_with_every_emitter() {
    insta::glob!("../examples", "*/rules.btrules", |rules| {
        let rel = rules.strip_prefix(env!("CARGO_MANIFEST_DIR")).unwrap();
        for emit in EMITTERS {
            // The py_trees runtime is a file of its own (emit/python/), tested
            // there: the snapshot is the module, with the runtime imported.
            let extra: &[&str] = if *emit == "pytrees" {
                &["--runtime", "import"]
            } else {
                &[]
            };
            let text = compile(rel, emit, extra);
            insta::assert_snapshot!(format!("{emit}"), text);
        }
        insta::assert_snapshot!("btcpp_inline", compile(rel, "btcpp", &["--inline"]));
    });
}

/// Fixtures for what a rules file says about names and values: each folder
/// of `tests/fixtures/emit/` through every emitter like the examples,
/// snapshots named after the folder.
#[test]
fn every_emit_fixture_with_every_emitter() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/emit");
    let mut dirs: Vec<String> = std::fs::read_dir(&root)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    dirs.sort();
    assert!(!dirs.is_empty(), "no fixture under {}", root.display());
    for dir in dirs {
        let rules = format!("tests/fixtures/emit/{dir}/rules.btrules");
        let rules = Path::new(&rules);
        for emit in EMITTERS {
            insta::assert_snapshot!(format!("{dir}_{emit}"), compile(rules, emit, &[]));
        }
        insta::assert_snapshot!(
            format!("{dir}_btcpp_inline"),
            compile(rules, "btcpp", &["--inline"])
        );
    }
}

/// PlanSys2-style per-action BT.CPP trees imported into the rules
/// (`import "trees/move.xml" as MoveTree`) through every emitter: each
/// imported tree is in the output as the rules' own trees are.
#[test]
fn imported_btcpp_trees_with_every_emitter() {
    let rules = Path::new("runtime/tests/fixtures/three_way/timed/scheduled_imported.btrules");
    for emit in EMITTERS {
        let extra: &[&str] = if *emit == "pytrees" {
            &["--runtime", "import"]
        } else {
            &[]
        };
        insta::assert_snapshot!(
            format!("imported_trees_{emit}"),
            compile(rules, emit, extra)
        );
    }
    insta::assert_snapshot!(
        "imported_trees_btcpp_inline",
        compile(rules, "btcpp", &["--inline"])
    );
}

/// `name="..."` attribute values of an XML text.
fn name_attributes(xml: &str) -> Vec<&str> {
    xml.split(" name=\"")
        .skip(1)
        .map(|rest| &rest[..rest.find('"').unwrap_or(rest.len())])
        .collect()
}

/// BT.CPP has no interpolation in `name`, and Groot2 shows it as written:
/// no `{...}` may reach a name in either mode, and every value a step
/// computes (a table lookup passed to a tree, an interpolation of it)
/// arrives filled in.
#[test]
fn no_placeholder_reaches_a_btcpp_name_and_no_value_is_lost() {
    let rules = Path::new("tests/fixtures/emit/values/rules.btrules");
    for extra in [&[][..], &["--inline"][..]] {
        let xml = compile(rules, "btcpp", extra);
        for name in name_attributes(&xml) {
            assert!(
                !name.contains('{') && !name.contains('}'),
                "{extra:?}: name=\"{name}\""
            );
        }
        for line in xml.lines().filter(|l| !l.contains("<KbStep")) {
            assert!(!line.contains("=\"\""), "{extra:?}: an empty port: {line}");
        }
        assert!(
            xml.contains("holding battery_red at 5 N"),
            "{extra:?}\n{xml}"
        );
        assert!(xml.contains("tray_gripper"), "{extra:?}\n{xml}");
    }
    let xml = compile(rules, "btcpp", &[]);
    assert!(
        xml.contains(r#"<Sequence name="pick ?p with ?gripper">"#),
        "{xml}"
    );
    let inline = compile(rules, "btcpp", &["--inline"]);
    assert!(
        inline.contains(r#"<Sequence name="pick pump_blue with tray_gripper">"#),
        "{inline}"
    );
    for emit in ["mermaid", "dot"] {
        let text = compile(rules, emit, &[]);
        assert!(
            text.contains("pick battery_red with part_gripper"),
            "{text}"
        );
        assert!(!text.contains("{newtons}"), "{text}");
    }
}

/// Scripts in the rules (`script` leaves, `[skip_if: ...]` and other pre-
/// and post-conditions) through every emitter that can express them: BT.CPP
/// attributes and `<Script>` leaves in both modes, the JSON IR's `scripts`;
/// DOT and Mermaid do not show them. A py_trees module cannot run them:
/// E001 at each script leaf and attribute.
#[test]
fn scripts_through_every_emitter_and_refused_for_py_trees() {
    let rules = Path::new("tests/fixtures/scripts/rules.btrules");
    for emit in EMITTERS.iter().filter(|e| **e != "pytrees") {
        insta::assert_snapshot!(format!("scripts_{emit}"), compile(rules, emit, &[]));
    }
    let inline = compile(rules, "btcpp", &["--inline"]);
    assert!(
        inline.contains(r#"<MoveTo _onSuccess="moved += 1" robot="floor_robot" target="bin1"/>"#),
        "{inline}"
    );
    insta::assert_snapshot!("scripts_btcpp_inline", inline);
    let out = Command::new(env!("CARGO_BIN_EXE_btc"))
        .arg("compile")
        .arg(rules)
        .args([
            "--plan",
            "tests/fixtures/scripts/plan.txt",
            "--emit",
            "pytrees",
        ])
        .env("NO_COLOR", "1")
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(1), "py_trees must be refused");
    let stderr = String::from_utf8_lossy(&out.stderr);
    for key in [
        "on_success",
        "skip_if",
        "failure_if",
        "post",
        "Script",
        "ScriptCondition",
    ] {
        assert!(
            stderr.contains(&format!(
                "[E001] Error: a py_trees module cannot run `{key}`"
            )),
            "{key}:\n{stderr}"
        );
    }
    insta::assert_snapshot!("scripts_pytrees_refused", stderr);
}
