//! `delay(N) T` and `run_once T` (BT.CPP's `Delay` and `RunOnce`, added to
//! the rules through the node vocabulary): the rules compile to the IR, the
//! IR to BT.CPP XML with the vocabulary's tags and ports, and btc's engine
//! runs the IR and the XML alike (fixture `tests/fixtures/delay_run_once/`).

mod common;
use btc_runtime::engine::TickEvent;
use btc_runtime::{Options, Status, TreeDoc};
use common::*;

#[test]
fn delay_and_run_once_round_trip_from_the_rules_to_the_engine() {
    let dir =
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/delay_run_once");
    let ex = compile_dir(&dir, "delay_run_once");
    let json = serde_json::to_string(&ex.ir).unwrap();
    assert!(json.contains(r#""kind":"delay","ms":120"#), "{json}");
    assert!(json.contains(r#""kind":"run-once""#), "{json}");
    let xml = btc_emit::btcpp::emit(&ex.ir, false);
    assert!(xml.contains(r#"<Delay delay_msec="120">"#), "{xml}");
    assert!(xml.contains(r#"<Delay delay_msec="30">"#), "{xml}");
    assert!(xml.contains(r#"<RunOnce name="inspect once">"#), "{xml}");
    let w = ex.world();
    let mut runs = Vec::new();
    for doc in [TreeDoc::from_ir(&ex.ir), ex.xml(&xml)] {
        let mut e = traced(ex.engine(&w, &doc, Options::default()));
        let s = e.run(100_000, |_| {});
        assert_eq!(s, Status::Success, "{:#?}", e.records);
        assert_eq!(e.summary(s).goal_reached, Some(true));
        let steps: Vec<String> = events(&e)
            .iter()
            .filter_map(|t| match t {
                TickEvent::StepStarted { tick, step } => Some(format!("{tick} start {step}")),
                TickEvent::StepFinished { tick, step } => Some(format!("{tick} end {step}")),
                _ => None,
            })
            .collect();
        runs.push((steps, e.kb.as_ref().unwrap().snapshot()));
    }
    assert_eq!(runs[0], runs[1]);
}

/// A delay holds its step back: the same plan without the delays finishes
/// in fewer ticks.
#[test]
fn a_delay_takes_ticks() {
    let dir =
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/delay_run_once");
    let ex = compile_dir(&dir, "delay_run_once");
    let w = ex.world();
    let ticks = |doc: &TreeDoc| {
        let mut e = traced(ex.engine(&w, doc, Options::default()));
        assert_eq!(e.run(100_000, |_| {}), Status::Success);
        e.tick
    };
    let xml = btc_emit::btcpp::emit(&ex.ir, false);
    let without = xml
        .lines()
        .filter(|l| !l.trim_start().starts_with("<Delay") && l.trim() != "</Delay>")
        .collect::<Vec<_>>()
        .join("\n");
    assert!(ticks(&ex.xml(&xml)) > ticks(&ex.xml(&without)));
}
