//! BT.CPP's scripting language and the nodes around it, on small XML trees
//! (`tests/fixtures/scripting/`): `Script`, `ScriptCondition`, the pre- and
//! post-condition attributes, SKIPPED, `IfThenElse`, `WhileDoElse`,
//! `Switch2`..`Switch6`, `Delay`, `RunOnce` and `Precondition`. Expected
//! values follow BT.CPP 4.10's sources and gtests (`gtest_preconditions`,
//! `gtest_postconditions`, `gtest_skipping`, `gtest_switch`...).

use btc_runtime::observers::EventLog;
use btc_runtime::{xml, Engine, LoadError, Options, Status, Value};
use std::path::Path;

fn fixture(name: &str) -> String {
    let p = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/fixtures/scripting")
        .join(format!("{name}.xml"));
    std::fs::read_to_string(&p).unwrap_or_else(|e| panic!("{}: {e}", p.display()))
}

fn build(name: &str) -> Result<Engine<'static>, LoadError> {
    let doc = xml::parse(&fixture(name))?;
    Engine::build(&doc, None, Options::default())
}

/// Runs the tree to the end: its status and the ticks it took.
fn run(name: &str) -> (Engine<'static>, Status) {
    let mut e = build(name).unwrap_or_else(|err| panic!("{name}: {err}"));
    let s = e.run(100, |_| {});
    (e, s)
}

fn bb<'e>(e: &'e Engine, key: &str) -> Option<&'e Value> {
    e.blackboard(&format!("Main/{key}"))
}

fn text(s: &str) -> Option<Value> {
    Some(Value::Text(s.into()))
}

#[test]
fn scripts_compute_with_bt_cpp_value_rules() {
    let (e, s) = run("script");
    assert_eq!(s, Status::Success);
    assert_eq!(bb(&e, "a"), Some(&Value::Int(1)));
    assert_eq!(bb(&e, "b"), Some(&Value::Float(3.0)));
    assert_eq!(bb(&e, "s").cloned(), text("n=1"));
    assert_eq!(bb(&e, "done"), Some(&Value::Float(1.0)));
}

#[test]
fn preconditions_skip_succeed_or_fail_a_node_and_postconditions_run_after_it() {
    let (e, s) = run("preconditions");
    assert_eq!(s, Status::Success);
    assert_eq!(e.tick, 1);
    // Only `runs` ran: `skipped` was skipped, `succeeds` succeeded unrun.
    assert_eq!(bb(&e, "ran"), Some(&Value::Int(100)));
    assert_eq!(bb(&e, "ok").cloned(), text("yes"));
    assert_eq!(bb(&e, "post"), Some(&Value::Int(1)));
    assert_eq!(bb(&e, "bad").cloned(), text("yes"));
    // A skipped node stays IDLE.
    let skipped = e.meta.iter().position(|m| m.name == "skipped").unwrap();
    assert_eq!(e.status_of(skipped as u32), Status::Idle);
}

#[test]
fn a_failure_if_that_holds_fails_the_node_and_says_why() {
    let (e, s) = run("failure_if");
    assert_eq!(s, Status::Failure);
    assert_eq!(e.records.len(), 1);
    assert_eq!(e.records[0].node_name, "go");
    assert_eq!(e.records[0].reason, "its `_failureIf` holds: battery < 20");
}

#[test]
fn while_halts_a_running_node_when_it_stops_holding() {
    let (e, s) = run("while");
    assert_eq!(s, Status::Success);
    assert_eq!(e.tick, 3);
    assert_eq!(bb(&e, "n"), Some(&Value::Int(3)));
    // `_onHalted` ran when `_while` halted the Sleep.
    assert_eq!(bb(&e, "halted"), Some(&Value::Int(3)));
}

#[test]
fn if_then_else_and_while_do_else_pick_their_branch() {
    let (e, s) = run("if_then_else");
    assert_eq!(s, Status::Success);
    assert_eq!(bb(&e, "branch").cloned(), text("then"));
    assert_eq!(bb(&e, "second").cloned(), text("else"));
    assert_eq!(bb(&e, "n"), Some(&Value::Int(6)));
}

#[test]
fn switch_picks_the_equal_case_as_text_or_number_or_the_default() {
    let (e, s) = run("switch");
    assert_eq!(s, Status::Success);
    assert_eq!(bb(&e, "picked"), Some(&Value::Int(2)));
    assert_eq!(bb(&e, "numeric"), Some(&Value::Int(2)));
    assert_eq!(bb(&e, "fallthrough").cloned(), text("default"));
}

#[test]
fn delay_waits_run_once_runs_once_and_precondition_gates() {
    let (e, s) = run("delay_run_once");
    assert_eq!(s, Status::Success);
    // 30 ms at 10 ms per tick: the delay starts on tick 1, its child runs
    // on tick 4. Then each of Repeat's cycles, started and finished in one
    // tick, hands the flow back (BT.CPP 4.10): cycles on ticks 4, 5 and 6.
    assert_eq!(e.tick, 6);
    assert_eq!(bb(&e, "delayed"), Some(&Value::Int(1)));
    assert_eq!(bb(&e, "once"), Some(&Value::Int(1)));
    assert_eq!(bb(&e, "every"), Some(&Value::Int(3)));
    assert_eq!(bb(&e, "admitted"), Some(&Value::Int(1)));
    assert_eq!(bb(&e, "refused"), Some(&Value::Empty));
}

#[test]
fn a_script_that_fails_at_run_time_fails_its_node_with_the_reason() {
    let (e, s) = run("script_error");
    assert_eq!(s, Status::Failure);
    assert_eq!(e.records[0].node_name, "oops");
    assert!(
        e.records[0]
            .reason
            .starts_with("the script `missing = 1` failed: the entry does not exist yet"),
        "{}",
        e.records[0].reason
    );
}

#[test]
fn a_skipped_condition_fails_if_then_else_and_while_do_else_with_the_reason() {
    let doc = xml::parse(&fixture("skipped_condition")).unwrap();
    let mut e = Engine::build(&doc, None, Options::default()).unwrap();
    e.observe(EventLog::default());
    assert_eq!(e.run(10, |_| {}), Status::Failure);
    assert_eq!(e.tick, 1);
    let failed: Vec<(u32, &str)> = e
        .observer::<EventLog>()
        .unwrap()
        .events
        .iter()
        .filter_map(|t| match t {
            btc_runtime::engine::TickEvent::Status {
                node,
                to: Status::Failure,
                ..
            } => Some((*node, e.meta[*node as usize].name.as_str())),
            _ => None,
        })
        .collect();
    assert_eq!(failed[..2], [(1, "if"), (4, "while")], "{failed:?}");
    assert_eq!(e.records[0].node_name, "while");
    assert_eq!(
        e.records[0].reason,
        "the condition of WhileDoElse was skipped"
    );
}

#[test]
fn malformed_trees_are_refused_with_their_codes() {
    let code = |name: &str| build(name).err().map(|e| (e.code.id, e.message));
    let (c, m) = code("bad_script").unwrap();
    assert_eq!(c, "X040");
    assert!(
        m.starts_with("`code` of `Script`: expected an operand"),
        "{m}"
    );
    let (c, m) = code("bad_attribute").unwrap();
    assert_eq!(c, "X041");
    assert_eq!(
        m,
        "<AlwaysSuccess>: the attribute `_skipif` is not one btc runs"
    );
    let (c, m) = code("bad_if_then_else").unwrap();
    assert_eq!(c, "X003");
    assert_eq!(m, "`IfThenElse` takes 2 or 3 children, and has 1");
}
