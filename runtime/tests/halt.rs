//! An embedder's leaf hears of its halts (BT.CPP's
//! `StatefulActionNode::onHalted`): a RUNNING leaf halted by its parent or
//! by the end of a run calls the halt handler with its ports; a leaf that
//! finished is not halted.

use btc_runtime::{xml, Engine, Options, Status};
use std::cell::RefCell;
use std::path::Path;
use std::rc::Rc;

fn fixture(name: &str) -> String {
    let p = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/fixtures/halt")
        .join(format!("{name}.xml"));
    std::fs::read_to_string(&p).unwrap_or_else(|e| panic!("{}: {e}", p.display()))
}

/// Runs the fixture with Drive always RUNNING and Grip succeeding at
/// once, for `max_ticks`; returns the run's status and the halts heard,
/// as `(node, robot)`.
fn run(max_ticks: u64) -> (Status, Vec<(u32, String)>) {
    let doc = xml::parse(&fixture("parallel")).unwrap();
    let mut e = Engine::build(&doc, None, Options::default()).unwrap();
    let halts = Rc::new(RefCell::new(Vec::new()));
    assert_eq!(
        e.set_action_handler("Drive", Box::new(|_| Status::Running)),
        2
    );
    assert_eq!(
        e.set_action_handler("Grip", Box::new(|_| Status::Success)),
        2
    );
    let heard = halts.clone();
    let n = e.set_halt_handler(
        "Drive",
        Box::new(move |c| {
            let robot = c.port("robot").map(|v| v.text()).unwrap_or_default();
            heard.borrow_mut().push((c.node, robot.to_string()));
        }),
    );
    assert_eq!(n, 2);
    let never = e.set_halt_handler("Grip", Box::new(|c| panic!("Grip {} halted", c.node)));
    assert_eq!(never, 2);
    let status = e.run(max_ticks, |_| {});
    let out = halts.borrow().clone();
    (status, out)
}

#[test]
fn a_parallel_that_succeeds_halts_its_running_leaf_once() {
    let (status, halts) = run(3);
    // The Parallel halted the first Drive (r1); the second Drive (r2) was
    // still running when the ticks ran out, and the run halted it too.
    assert_eq!(status, Status::Running);
    let robots: Vec<&str> = halts.iter().map(|(_, r)| r.as_str()).collect();
    assert_eq!(robots, ["r1", "r2"], "{halts:?}");
    assert_ne!(halts[0].0, halts[1].0);
}
