//! The queued controller: every command issued is executed exactly once, in
//! order, also under load with a tiny queue; shutdown is clean.

use btc_ir::LeafKind;
use btc_runtime::observers::EventLog;
use btc_runtime::spec::{Kind, SNode, TreeDoc};
use btc_runtime::{Command, Controller, Engine, Options, Status};
use std::time::Duration;

fn cmd(node: u32) -> Command {
    Command {
        seq: 0,
        node,
        command: "MoveTo".into(),
        args: vec![("target".into(), format!("slot{node}"))],
        step: None,
    }
}

#[test]
fn ten_thousand_commands_through_a_queue_of_two() {
    let mut c = Controller::start(2, Duration::ZERO);
    let mut seqs = Vec::new();
    for i in 0..10_000u32 {
        seqs.push(c.submit(cmd(i)));
        if i % 97 == 0 {
            c.poll();
        }
    }
    for &s in &seqs {
        c.wait(s);
        assert!(c.take_done(s), "command {s} was not reported done");
        assert!(!c.take_done(s), "command {s} was reported twice");
    }
    let log = c.shutdown();
    assert_eq!(log.len(), 10_000);
    for (k, cm) in log.iter().enumerate() {
        assert_eq!(cm.seq, k as u64 + 1, "out of order or duplicated");
        assert_eq!(cm.node, k as u32);
    }
}

fn leaf(i: usize) -> SNode {
    SNode {
        kind: Kind::Leaf {
            id: "Work".into(),
            kind: Some(LeafKind::Action),
            ports: vec![("n".into(), btc_ir::PortValue::Int(i as i64))],
        },
        name: Some(format!("work {i}")),
        children: Vec::new(),
        scripts: Default::default(),
        at: None,
    }
}

fn doc(root: SNode) -> TreeDoc {
    TreeDoc {
        main: "Main".into(),
        trees: vec![("Main".into(), root)],
        ..TreeDoc::default()
    }
}

#[test]
fn a_wide_parallel_issues_each_command_once_under_back_pressure() {
    let n = 300;
    let root = SNode {
        kind: Kind::Parallel {
            success: -1,
            failure: 1,
        },
        name: None,
        children: (0..n).map(leaf).collect(),
        scripts: Default::default(),
        at: None,
    };
    let mut e = Engine::build(&doc(root), None, Options::default()).unwrap();
    e.attach_controller(Controller::start(4, Duration::from_micros(20)));
    let s = e.run(1_000_000, |_| {});
    assert_eq!(s, Status::Success);
    let log = e.take_controller().unwrap().shutdown();
    assert_eq!(log.len(), n);
    let mut nodes: Vec<u32> = log.iter().map(|c| c.node).collect();
    nodes.sort();
    nodes.dedup();
    assert_eq!(nodes.len(), n, "a leaf's command was lost or duplicated");
    let mut ports: Vec<String> = log.iter().map(|c| c.args[0].1.clone()).collect();
    ports.sort_by_key(|p| p.parse::<usize>().unwrap());
    assert_eq!(ports, (0..n).map(|i| i.to_string()).collect::<Vec<_>>());
}

#[test]
fn a_sequence_waits_for_each_completion_in_turn() {
    let root = SNode {
        kind: Kind::Sequence,
        name: None,
        children: (0..50).map(leaf).collect(),
        scripts: Default::default(),
        at: None,
    };
    let mut e = Engine::build(&doc(root), None, Options::default()).unwrap();
    e.attach_controller(Controller::start(1, Duration::from_micros(50)));
    assert_eq!(e.run(1_000_000, |_| {}), Status::Success);
    let log = e.take_controller().unwrap().shutdown();
    let order: Vec<String> = log.iter().map(|c| c.args[0].1.clone()).collect();
    assert_eq!(order, (0..50).map(|i| i.to_string()).collect::<Vec<_>>());
}

#[test]
fn dropping_an_engine_with_commands_in_flight_shuts_down_cleanly() {
    let root = SNode {
        kind: Kind::Parallel {
            success: -1,
            failure: 1,
        },
        name: None,
        children: (0..20).map(leaf).collect(),
        scripts: Default::default(),
        at: None,
    };
    let mut e = Engine::build(&doc(root), None, Options::default()).unwrap();
    e.attach_controller(Controller::start(32, Duration::from_millis(1)));
    assert_eq!(e.tick_once(), Status::Running);
    let started = std::time::Instant::now();
    drop(e);
    // The consumer drains what was queued (20 ms of work) and stops.
    assert!(started.elapsed() < Duration::from_secs(5));
}

#[test]
fn halted_leaves_commands_still_run_once_and_are_not_waited_for() {
    // Each cycle: the sleep finishes first and the parallel halts the
    // action that waits for its command.
    let sleep = SNode {
        kind: Kind::Leaf {
            id: "Sleep".into(),
            kind: None,
            ports: vec![("msec".into(), btc_ir::PortValue::Int(10))],
        },
        name: None,
        children: Vec::new(),
        scripts: Default::default(),
        at: None,
    };
    let par = SNode {
        kind: Kind::Parallel {
            success: 1,
            failure: 1,
        },
        name: None,
        children: vec![sleep, leaf(0)],
        scripts: Default::default(),
        at: None,
    };
    let root = SNode {
        kind: Kind::Repeat(btc_runtime::spec::Amount::Fixed(3)),
        name: None,
        children: vec![par],
        scripts: Default::default(),
        at: None,
    };
    let mut e = Engine::build(&doc(root), None, Options::default()).unwrap();
    e.observe(EventLog::default());
    e.attach_controller(Controller::start(4, Duration::from_millis(20)));
    assert_eq!(e.run(10_000, |_| {}), Status::Success);
    let halted = e
        .observer::<EventLog>()
        .unwrap()
        .events
        .iter()
        .filter(|t| matches!(t, btc_runtime::engine::TickEvent::Status { node, from: Status::Running, to: Status::Idle, .. } if e.meta[*node as usize].name == "work 0"))
        .count();
    assert_eq!(halted, 3);
    let log = e.take_controller().unwrap().shutdown();
    let seqs: Vec<u64> = log.iter().map(|c| c.seq).collect();
    assert_eq!(seqs, [1, 2, 3]);
}
