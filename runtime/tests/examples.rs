//! Every example runs to its goal; the final KB is read to check it. A tree
//! written as BT.CPP XML and loaded back runs exactly like its IR.

mod common;
use btc_runtime::{Options, Status, TreeDoc};
use common::*;

#[test]
fn every_example_reaches_its_goal() {
    for name in EXAMPLES {
        let ex = example(name);
        let w = ex.world();
        let mut e = traced(ex.engine(&w, &TreeDoc::from_ir(&ex.ir), Options::default()));
        let s = e.run(100_000, |_| {});
        let sum = e.summary(s);
        assert_eq!(
            s,
            Status::Success,
            "{name}: {:#?}\n{}",
            sum.records,
            jsonl(&e)
        );
        assert_eq!(sum.goal_reached, Some(true), "{name}");
        // The goal's facts are in the final KB, read directly.
        let kb = e.kb.as_ref().unwrap();
        let goal = w.goal().unwrap();
        assert!(
            kb.world.holds(&kb.state, goal, &mut Vec::new(), None),
            "{name}"
        );
        assert_eq!(sum.steps_done, sum.steps_total, "{name}");
        assert!(sum.steps_total > 0, "{name}");
        assert!(sum.records.is_empty(), "{name}: {:#?}", sum.records);
    }
}

#[test]
fn the_initial_kb_does_not_hold_the_goal() {
    // Otherwise the test above would prove nothing.
    for name in EXAMPLES {
        let ex = example(name);
        let w = ex.world();
        let e = traced(ex.engine(&w, &TreeDoc::from_ir(&ex.ir), Options::default()));
        assert_eq!(e.goal().map(|g| g.0), Some(false), "{name}");
    }
}

#[test]
fn btcpp_xml_runs_exactly_like_its_ir() {
    for name in EXAMPLES {
        let ex = example(name);
        let w = ex.world();
        for inline in [false, true] {
            let mut from_ir = if inline {
                let mut ir = ex.ir.clone();
                ir.root = ir.inlined();
                ir.trees.clear();
                TreeDoc::from_ir(&ir)
            } else {
                TreeDoc::from_ir(&ex.ir)
            };
            from_ir.steps = ex.ir.steps.clone();
            let text = btc_emit::btcpp::emit(&ex.ir, inline);
            // The XML carries the steps' effects; their conditions come
            // from the domain's actions, as `btc run --tree` does.
            let from_xml = ex.xml(&text);
            assert!(from_xml.steps.is_empty());
            let mut a = traced(ex.engine(&w, &from_ir, Options::default()));
            let mut b = traced(ex.engine(&w, &from_xml, Options::default()));
            assert_eq!(a.steps_total(), b.steps_total(), "{name}");
            let sa = a.run(100_000, |_| {});
            let sb = b.run(100_000, |_| {});
            assert_eq!(sa, Status::Success, "{name}");
            assert_eq!(sa, sb, "{name}");
            assert_eq!(a.node_count(), b.node_count(), "{name} inline={inline}");
            let (ta, tb) = (jsonl(&a), jsonl(&b));
            assert!(ta.lines().count() > 10, "{name}");
            if ta != tb {
                let d = ta.lines().zip(tb.lines()).position(|(x, y)| x != y);
                panic!(
                    "{name} inline={inline}: traces differ at line {d:?}:\n{:?}\n{:?}",
                    d.and_then(|d| ta.lines().nth(d)),
                    d.and_then(|d| tb.lines().nth(d))
                );
            }
            assert_eq!(
                a.kb.as_ref().unwrap().snapshot(),
                b.kb.as_ref().unwrap().snapshot()
            );
        }
    }
}

#[test]
fn xml_steps_check_the_domain_preconditions_like_the_ir() {
    // The part is gone, so the grasp's precondition is false: the XML tree
    // (no plan given) must fail where the IR fails, with the same record.
    let ex = example("ariac");
    let w = ex.world();
    let text = btc_emit::btcpp::emit(&ex.ir, false);
    let mut runs = Vec::new();
    for doc in [TreeDoc::from_ir(&ex.ir), ex.xml(&text)] {
        let mut e = traced(ex.engine(&w, &doc, Options::default()));
        let kb = e.kb.as_mut().unwrap();
        let part = kb.object("battery_red").unwrap();
        let gone = kb.facts_mentioning(part);
        kb.apply_keys(Vec::new(), gone);
        assert_eq!(e.run(1000, |_| {}), Status::Failure);
        runs.push((jsonl(&e), e.records.clone()));
    }
    assert!(
        runs[0].1[0].reason.contains("precondition"),
        "{:?}",
        runs[0].1
    );
    assert_eq!(runs[0], runs[1]);
}

#[test]
fn the_ir_round_trips_through_its_json() {
    for name in EXAMPLES {
        let ex = example(name);
        let text = serde_json::to_string_pretty(&ex.ir).unwrap();
        match btc_ir::json::decode(&text) {
            Ok(btc_ir::json::IrFile::Current(ir)) => assert_eq!(ir, ex.ir, "{name}"),
            other => panic!("{name}: {other:?}"),
        }
    }
}
