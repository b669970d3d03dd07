//! BehaviorTree.CPP v4 semantics, node by node, on small XML trees
//! (`tests/fixtures/semantics/`) over a world of flags the tests switch
//! between ticks. Expected behaviour follows BT.CPP's documentation and
//! sources (`controls/*.cpp`, `decorators/*.cpp`).

mod common;
use btc_pddl::logic::decode;
use btc_pddl::pipeline;
use btc_pddl::state::World;
use btc_runtime::engine::TickEvent;
use btc_runtime::observers::EventLog;
use btc_runtime::{xml, Engine, Kb, Options, Status, Value};
use common::fixture;
use Status::*;

struct Flags {
    world: World,
}

fn flags() -> Flags {
    let du = pipeline::domain_unit_from(&fixture("flags/domain.pddl"), 0);
    let pu = pipeline::problem_unit_from(
        &fixture("flags/problem.pddl"),
        1,
        du.domain.as_ref(),
        &du.index,
    );
    assert!(du.diagnostics.is_empty() && pu.diagnostics.is_empty());
    let world = World::of_checked(
        du.domain.as_ref().unwrap(),
        &du.index,
        pu.problem.as_ref().unwrap(),
        &pu.index,
    )
    .unwrap();
    Flags { world }
}

fn engine<'a>(w: &'a Flags, tree: &str, ticks_per_action: u32) -> Engine<'a> {
    let doc = xml::parse(&fixture(&format!("semantics/{tree}.xml")))
        .unwrap_or_else(|e| panic!("{tree}: {e}"));
    let kb = Kb::new(&w.world);
    let opts = Options {
        ticks_per_action,
        ms_per_tick: 10,
    };
    let mut e = Engine::build(&doc, Some(kb), opts).unwrap_or_else(|e| panic!("{tree}: {e}"));
    e.observe(EventLog::default());
    e
}

fn set(e: &mut Engine, fact: &str, on: bool) {
    let kb = e.kb.as_mut().unwrap();
    let text = if on {
        fact.to_owned()
    } else {
        format!("(not {fact})")
    };
    let id = kb.effect(&decode::effect(&text).unwrap()).unwrap();
    kb.apply(id);
}

fn holds(e: &mut Engine, fact: &str) -> bool {
    let kb = e.kb.as_mut().unwrap();
    let f = kb.formula(&decode::formula(fact).unwrap()).unwrap();
    kb.holds(f)
}

/// Root statuses of `n` ticks.
fn ticks(e: &mut Engine, n: usize) -> Vec<Status> {
    (0..n).map(|_| e.tick_once()).collect()
}

fn transitions(e: &Engine, name: &str, from: Option<Status>, to: Option<Status>) -> usize {
    e.observer::<EventLog>()
        .expect("observed")
        .events
        .iter()
        .filter(|t| match t {
            TickEvent::Status {
                node,
                from: f,
                to: t,
                ..
            } => {
                e.meta[*node as usize].name == name
                    && from.is_none_or(|x| x == *f)
                    && to.is_none_or(|x| x == *t)
            }
            _ => false,
        })
        .count()
}

/// How often a node was ticked from IDLE (a start, or a condition check).
fn starts(e: &Engine, name: &str) -> usize {
    transitions(e, name, Some(Idle), None)
}

/// How often a running node was halted.
fn halts(e: &Engine, name: &str) -> usize {
    transitions(e, name, Some(Running), Some(Idle))
}

#[test]
fn sequence_resumes_at_the_running_child_and_restarts_after_failure() {
    let w = flags();
    let mut e = engine(&w, "sequence", 1);
    // a runs (tick 1), succeeds (2); go? fails: the sequence fails, reset.
    assert_eq!(ticks(&mut e, 2), [Running, Failure]);
    assert_eq!(starts(&e, "a"), 1);
    set(&mut e, "(go)", true);
    // Restarted from the first child: a runs again.
    assert_eq!(ticks(&mut e, 3), [Running, Running, Success]);
    assert_eq!(starts(&e, "a"), 2);
    assert_eq!(starts(&e, "b"), 1);
    // A non-reactive sequence checks go? once per pass, not every tick.
    assert_eq!(starts(&e, "go?"), 2);
}

#[test]
fn reactive_sequence_rechecks_conditions_and_halts_the_running_child() {
    let w = flags();
    let mut e = engine(&w, "reactive_sequence", 5);
    set(&mut e, "(go)", true);
    assert_eq!(ticks(&mut e, 3), [Running, Running, Running]);
    assert_eq!(starts(&e, "go?"), 3, "the condition is ticked every tick");
    assert_eq!(starts(&e, "a"), 1, "the action keeps running");
    set(&mut e, "(go)", false);
    assert_eq!(ticks(&mut e, 1), [Failure]);
    assert_eq!(halts(&e, "a"), 1, "the running action is halted");
    set(&mut e, "(go)", true);
    // Restarted from scratch: five more ticks of running.
    assert_eq!(
        ticks(&mut e, 6),
        [Running, Running, Running, Running, Running, Success]
    );
    assert_eq!(starts(&e, "a"), 2);
}

#[test]
fn sequence_with_memory_does_not_rerun_finished_children_after_a_failure() {
    let w = flags();
    let mut e = engine(&w, "sequence_with_memory", 1);
    assert_eq!(ticks(&mut e, 2), [Running, Failure]);
    set(&mut e, "(go)", true);
    // Resumes at go?, not at a. go? starts and succeeds in one tick, so the
    // node hands the flow back (RUNNING) and starts b at the next tick, as
    // BT.CPP 4.10 does (runtime/tests/btcpp_conformance.rs).
    assert_eq!(ticks(&mut e, 3), [Running, Running, Success]);
    assert_eq!(starts(&e, "a"), 1);
    assert_eq!(starts(&e, "go?"), 2);
    assert_eq!(starts(&e, "b"), 1);
}

#[test]
fn fallback_tries_children_in_order_until_one_succeeds() {
    let w = flags();
    let mut e = engine(&w, "fallback", 1);
    assert_eq!(ticks(&mut e, 2), [Running, Success]);
    assert_eq!(starts(&e, "a"), 1);
    set(&mut e, "(go)", true);
    assert_eq!(ticks(&mut e, 1), [Success]);
    assert_eq!(
        starts(&e, "a"),
        1,
        "the first child succeeded: a is not run"
    );
}

#[test]
fn reactive_fallback_halts_the_running_child_when_an_earlier_one_succeeds() {
    let w = flags();
    let mut e = engine(&w, "reactive_fallback", 5);
    assert_eq!(ticks(&mut e, 2), [Running, Running]);
    set(&mut e, "(go)", true);
    assert_eq!(ticks(&mut e, 1), [Success]);
    assert_eq!(halts(&e, "a"), 1);
    assert_eq!(starts(&e, "go?"), 3);
}

#[test]
fn parallel_thresholds() {
    let w = flags();
    // success_count -1: every child must succeed (the 50 ms sleep: tick 6).
    let mut e = engine(&w, "parallel_all", 1);
    assert_eq!(
        ticks(&mut e, 6),
        [Running, Running, Running, Running, Running, Success]
    );
    // A finished child is not ticked again while the others run.
    assert_eq!(starts(&e, "short"), 1);
    assert_eq!(transitions(&e, "short", Some(Running), Some(Success)), 1);
    // success_count 1: the first success ends it; the other child is halted.
    let mut e = engine(&w, "parallel_first", 1);
    assert_eq!(ticks(&mut e, 3), [Running, Running, Success]);
    assert_eq!(halts(&e, "long"), 1);
    // Once success is out of reach it fails, before the failure count.
    let mut e = engine(&w, "parallel_hopeless", 1);
    assert_eq!(ticks(&mut e, 1), [Failure]);
    assert_eq!(halts(&e, "short"), 1);
    assert_eq!(
        starts(&e, "long"),
        0,
        "it failed before ticking the third child"
    );
    // failure_count 2: two failures fail it.
    let mut e = engine(&w, "parallel_failures", 1);
    assert_eq!(ticks(&mut e, 1), [Failure]);
    assert_eq!(halts(&e, "long"), 1);
}

#[test]
fn a_parallel_with_fewer_children_than_its_threshold_is_refused() {
    let doc = xml::parse(&fixture("semantics/parallel_too_few.xml")).unwrap();
    let err = Engine::build(&doc, None, Options::default()).err().unwrap();
    assert_eq!(err.code.id, "X003");
    assert!(
        err.message.contains("fewer than its success_count 3"),
        "{}",
        err.message
    );
}

#[test]
fn inverter_force_success_and_force_failure() {
    let w = flags();
    let mut e = engine(&w, "decorators", 1);
    assert_eq!(ticks(&mut e, 2), [Running, Success]);
    assert_eq!(transitions(&e, "inv", None, Some(Success)), 1);
    assert_eq!(transitions(&e, "fs", None, Some(Success)), 1);
    assert_eq!(transitions(&e, "ff", None, Some(Failure)), 1);
    // RUNNING passes through an inverter unchanged.
    assert_eq!(transitions(&e, "a", Some(Idle), Some(Running)), 1);
}

#[test]
fn retry_runs_the_child_again_at_once_up_to_num_attempts() {
    let w = flags();
    let mut e = engine(&w, "retry", 1);
    // Each attempt: a runs one tick; the next attempt starts in the tick
    // the previous one failed.
    assert_eq!(ticks(&mut e, 4), [Running, Running, Running, Failure]);
    assert_eq!(starts(&e, "a"), 3);
    assert_eq!(starts(&e, "go?"), 3);
    // The count starts again for the next run; now the second check passes.
    assert_eq!(ticks(&mut e, 1), [Running]);
    set(&mut e, "(go)", true);
    assert_eq!(ticks(&mut e, 1), [Success]);
}

#[test]
fn repeat_runs_the_child_num_cycles_times_and_stops_at_a_failure() {
    let w = flags();
    let mut e = engine(&w, "repeat", 1);
    assert_eq!(ticks(&mut e, 4), [Running, Running, Running, Success]);
    assert_eq!(starts(&e, "a"), 3);
    let mut e = engine(&w, "repeat_fails", 1);
    assert_eq!(ticks(&mut e, 2), [Running, Failure]);
    assert_eq!(starts(&e, "a"), 1);
}

#[test]
fn timeout_fails_and_halts_a_child_that_runs_too_long() {
    let w = flags();
    let mut e = engine(&w, "timeout", 1);
    // nap: 20 ms at 10 ms a tick, within 100 ms: done at tick 3. long starts
    // at tick 3 (30 ms); the 30 ms timeout fires at tick 6.
    let got = ticks(&mut e, 6);
    assert_eq!(got, [Running, Running, Running, Running, Running, Failure]);
    assert_eq!(transitions(&e, "quick", None, Some(Success)), 1);
    assert_eq!(halts(&e, "long"), 1);
    assert_eq!(transitions(&e, "slow", None, Some(Failure)), 1);
}

#[test]
fn keep_running_until_failure() {
    let w = flags();
    let mut e = engine(&w, "keep_running", 1);
    set(&mut e, "(go)", true);
    assert_eq!(ticks(&mut e, 3), [Running, Running, Running]);
    set(&mut e, "(go)", false);
    assert_eq!(ticks(&mut e, 1), [Failure]);
}

#[test]
fn blackboard_ports_are_typed_and_conditions_follow_their_values() {
    let w = flags();
    let mut e = engine(&w, "blackboard", 1);
    assert_eq!(ticks(&mut e, 1), [Success]);
    assert_eq!(
        e.blackboard("Main/target"),
        Some(&Value::Text("bin2".into()))
    );
    assert_eq!(transitions(&e, "at target", None, Some(Success)), 1);
    assert_eq!(transitions(&e, "not at target", None, Some(Failure)), 1);
}

#[test]
fn subtrees_remap_ports_and_keep_their_own_entries() {
    let w = flags();
    let mut e = engine(&w, "subtree", 1);
    assert_eq!(ticks(&mut e, 1), [Success]);
    assert_eq!(
        e.blackboard("Check#1/private"),
        Some(&Value::Text("mine".into()))
    );
    assert_eq!(e.blackboard("Main/private"), None);
    assert_eq!(e.blackboard("Main/spot"), Some(&Value::Text("bin1".into())));
    let sub = e.meta.iter().position(|m| m.id == "SubTree").unwrap();
    assert_eq!(e.meta[sub].name, "Check");
}

#[test]
fn kb_steps_apply_start_effects_at_start_and_end_effects_on_success() {
    let w = flags();
    let mut e = engine(&w, "kbstep", 2);
    assert_eq!(ticks(&mut e, 1), [Running]);
    assert!(
        holds(&mut e, "(go)"),
        "the start effect applies when the step starts"
    );
    assert!(!holds(&mut e, "(done)"));
    assert_eq!(ticks(&mut e, 2), [Running, Failure]);
    assert!(
        holds(&mut e, "(done)"),
        "the end effect applies when the child succeeds"
    );
    assert!(
        holds(&mut e, "(go)"),
        "a failed step's end effect does not apply"
    );
    assert_eq!(e.steps_done(), 1);
    let rec = e.summary(Failure);
    assert_eq!(rec.goal_reached, Some(true));
    assert!(!rec.success());
}

#[test]
fn halted_actions_start_over() {
    let w = flags();
    let mut e = engine(&w, "reactive_sequence", 3);
    set(&mut e, "(go)", true);
    assert_eq!(ticks(&mut e, 2), [Running, Running]);
    set(&mut e, "(go)", false);
    assert_eq!(ticks(&mut e, 1), [Failure]);
    set(&mut e, "(go)", true);
    // Three full ticks of running again, not the one that was left.
    assert_eq!(ticks(&mut e, 4), [Running, Running, Running, Success]);
}

#[test]
fn retry_forever_makes_one_attempt_per_tick() {
    let w = flags();
    let mut e = engine(&w, "retry_forever", 1);
    assert_eq!(ticks(&mut e, 3), [Running, Running, Running]);
    assert_eq!(starts(&e, "go?"), 3);
    set(&mut e, "(go)", true);
    assert_eq!(ticks(&mut e, 1), [Success]);
}
