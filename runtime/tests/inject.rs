//! The fault-injection hook, with an injector of the test's own: the
//! engine calls it at its four points, tells the observers what it says
//! happened, records the failures it causes and gives it back with its
//! state. (The ARIAC faults are one such injector: `btc-agent`'s tests.)

mod common;
use btc_runtime::engine::{ActionLeaf, FaultOutcome, FaultRecord, Injection, Interference};
use btc_runtime::{Injector, Options, Status, TreeDoc};
use common::*;

/// Fails the first start of an action leaf with ID `id` that acts on
/// `object`; reads every condition as RUNNING for the ticks in `blind`.
#[derive(Default)]
struct Breaker {
    id: &'static str,
    object: &'static str,
    blind: std::ops::Range<u64>,
    tick: u64,
    steps: Vec<usize>,
    fired_at: Option<u64>,
}

impl Injector for Breaker {
    fn live(&self) -> bool {
        self.fired_at.is_none() || self.tick < self.blind.end
    }

    fn before_tick(&mut self, run: &mut Injection<'_, '_>) {
        self.tick = run.tick;
    }

    fn step_started(&mut self, _: &mut Injection<'_, '_>, step: usize) {
        self.steps.push(step);
    }

    fn action(
        &mut self,
        run: &mut Injection<'_, '_>,
        leaf: &ActionLeaf<'_>,
        fresh: bool,
    ) -> Option<Interference> {
        if !fresh || self.fired_at.is_some() || leaf.id != self.id || !leaf.mentions(self.object) {
            return None;
        }
        self.fired_at = Some(run.tick);
        run.happened(0);
        Some(Interference::Fail {
            fault: 0,
            reason: format!("{} broke on {}", self.id, self.object),
        })
    }

    fn condition(&self) -> Option<Interference> {
        self.blind
            .contains(&self.tick)
            .then_some(Interference::Wait)
    }

    fn describe(&self, fault: usize) -> Option<(String, &'static str)> {
        (fault == 0).then(|| ("breaker".to_owned(), "test_break"))
    }

    fn attributed(&self, cause: Option<usize>, _: &str) -> Vec<String> {
        match cause {
            Some(0) => vec!["breaker".to_owned()],
            _ => Vec::new(),
        }
    }

    fn outcomes(&self, success: bool, _: &[FaultRecord]) -> Vec<FaultOutcome> {
        vec![FaultOutcome {
            fault: "breaker".to_owned(),
            kind: "test_break",
            met_at: self.fired_at,
            ended: if success {
                "recovered"
            } else {
                "not recovered"
            }
            .to_owned(),
        }]
    }
}

#[test]
fn an_injector_is_called_at_each_hook_and_its_failures_are_recorded() {
    let ex = example("ariac");
    let w = ex.world();
    let doc = TreeDoc::from_ir(&ex.ir);
    let mut plain = traced(ex.engine(&w, &doc, Options::default()));
    assert_eq!(plain.run(10_000, |_| {}), Status::Success);

    let mut e = traced(ex.engine(&w, &doc, Options::default()));
    e.inject(Breaker {
        id: "Grasp",
        object: "battery_red",
        ..Breaker::default()
    });
    let s = e.run(10_000, |_| {});
    let sum = e.summary(s);
    // The grasp's retry absorbs the break.
    assert!(sum.success(), "{sum:#?}");
    let r = &sum.records[0];
    assert_eq!(r.node_id, "Grasp");
    assert_eq!(r.reason, "Grasp broke on battery_red");
    assert_eq!(r.faults, vec!["breaker".to_owned()]);
    assert_eq!(sum.faults[0].ended, "recovered");
    assert!(
        jsonl(&e).contains(r#""event":"fault_triggered","fault":"breaker","kind":"test_break""#)
    );
    let b = e
        .take_injector::<Breaker>()
        .expect("the injector comes back");
    assert_eq!(b.fired_at, sum.faults[0].met_at);
    assert_eq!(b.steps, (0..e.plan_steps()).collect::<Vec<_>>());
    assert!(e.injector::<Breaker>().is_none());
}

#[test]
fn conditions_an_injector_blinds_wait_and_the_run_is_later() {
    let ex = example("ariac");
    let w = ex.world();
    let doc = TreeDoc::from_ir(&ex.ir);
    let mut plain = ex.engine(&w, &doc, Options::default());
    plain.run(10_000, |_| {});
    let mut e = ex.engine(&w, &doc, Options::default());
    e.inject(Breaker {
        id: "none",
        object: "none",
        blind: 1..6,
        ..Breaker::default()
    });
    let s = e.run(10_000, |_| {});
    assert_eq!(s, Status::Success);
    assert!(
        e.tick > plain.tick,
        "{} ticks, {} without",
        e.tick,
        plain.tick
    );
    // Time passed with no tree ticked reaches the injector too.
    let t = e.tick;
    e.pass_tick();
    assert_eq!(e.injector::<Breaker>().unwrap().tick, t + 1);
}
