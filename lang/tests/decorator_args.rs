//! Decorator arguments (issue #10.4): they take the values ports take
//! (numbers, variables, table lookups, captures), by position or by the
//! parameter's name, and are checked against the decorator's parameter.
//! `fixtures/decorators/good.btrules` checks clean and its step-dependent
//! arguments reach the BT.CPP output as ports; `bad.btrules` gets one
//! diagnostic per mistake, in the user's terms (snapshot).

use btc_emit::{emit, Format, Options};
use btc_lang::db::{compile, rules_diagnostics, CompileJob, Database, SourceFile};
use btc_lang::path::FilePath;
use std::path::{Path, PathBuf};

fn repo() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}

fn load(db: &mut Database, rel: &str) -> SourceFile {
    let p = repo().join(rel);
    db.set_file(&FilePath::new(&p), std::fs::read_to_string(&p).unwrap())
}

/// `line:col [CODE] message` for each diagnostic of a rules fixture.
fn check(name: &str) -> (Database, SourceFile, Vec<String>) {
    let mut db = Database::new();
    load(&mut db, "examples/ariac/domain.pddl");
    let rel = format!("lang/tests/fixtures/decorators/{name}");
    let f = load(&mut db, &rel);
    let text = f.text(&db).clone();
    let lines = rules_diagnostics(&db, f)
        .iter()
        .map(|d| {
            let before = &text[..(d.span.start as usize).min(text.len())];
            let line = before.matches('\n').count() + 1;
            let col = before.len() - before.rfind('\n').map_or(0, |i| i + 1) + 1;
            format!("{line}:{col} [{}] {}", d.code, d.message)
        })
        .collect();
    (db, f, lines)
}

#[test]
fn decorator_arguments_take_port_values() {
    let (mut db, f, diags) = check("good.btrules");
    assert!(diags.is_empty(), "{diags:#?}");

    let problem = load(&mut db, "examples/ariac/problem.pddl");
    let plan = load(&mut db, "examples/ariac/plan.txt");
    let job = CompileJob::new(&db, f, plan, Some(problem), None);
    let ir = compile(&db, job).as_ref().unwrap();
    let xml = emit(ir, Format::Btcpp, &Options::default());
    // The grasp rule's retry count depends on the step: a port of its
    // tree, which each step's call fills in.
    assert!(
        xml.contains("<RetryUntilSuccessful num_attempts=\"{times}\""),
        "{xml}"
    );
    assert!(
        xml.contains("<SubTree ID=\"rule_grasp\" times=\"3\""),
        "{xml}"
    );
    // The move rule's time limit depends on the step too, but BT.CPP would
    // pass it to `Timeout` as an `int` where it takes an `unsigned`: the
    // rule's tree is written out at each step, with the step's number.
    assert!(
        xml.contains("<Timeout msec=\"6000\""),
        "the move to agv1: {xml}"
    );
    assert!(
        xml.contains("<Timeout msec=\"1500\""),
        "the move to bin1: {xml}"
    );
    assert!(!xml.contains("msec=\"{"), "{xml}");
    assert!(!xml.contains("rule_move"), "{xml}");
    // The same number for every step stays a number.
    assert!(xml.contains("<Timeout msec=\"100\""), "{xml}");
    // The inlined tree has the step's number in place.
    let flat = emit(
        ir,
        Format::Btcpp,
        &Options {
            inline: true,
            ..Options::default()
        },
    );
    assert!(flat.contains("<Timeout msec=\"6000\""), "{flat}");
    assert!(!flat.contains("msec=\"{"), "{flat}");
    // py_trees takes the number when the tree is built: the step's own
    // (milliseconds in the module's tree data), or the call's argument.
    let py = emit(ir, Format::Pytrees, &Options::default());
    assert!(py.contains(r#"("D", "timeout", 6000, "#), "{py}");
    assert!(py.contains(r#"("D", "timeout", 1500, "#), "{py}");
    assert!(py.contains(r#"("D", "retry", ("$", "times"), "#), "{py}");
}

#[test]
fn wrong_decorator_arguments_say_what_is_wrong() {
    let (_, _, diags) = check("bad.btrules");
    for d in &diags {
        assert!(!d.contains("expected"), "a parse error: {d}");
        assert!(!d.contains("action timeout"), "a misleading hint: {d}");
    }
    insta::assert_snapshot!(diags.join("\n"));
}
