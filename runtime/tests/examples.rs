//! Every example runs to its goal; the final KB is read to check it. A tree
//! written as BT.CPP XML and loaded back runs exactly like its IR.

mod common;
use btc_runtime::{xml, Status, TreeDoc};
use common::*;

#[test]
fn every_example_reaches_its_goal() {
    for name in EXAMPLES {
        let ex = example(name);
        let w = ex.world();
        let mut e = ex.engine(&w, &TreeDoc::from_ir(&ex.ir), traced());
        let s = e.run(100_000, |_| {});
        let sum = e.summary(s);
        assert_eq!(
            s,
            Status::Success,
            "{name}: {:#?}\n{}",
            sum.records,
            e.trace_jsonl()
        );
        assert_eq!(sum.goal_reached, Some(true), "{name}");
        // The goal's facts are in the final KB, read directly.
        let kb = e.kb.as_ref().unwrap();
        let goal = w.problem.goal.as_ref().unwrap();
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
        let e = ex.engine(&w, &TreeDoc::from_ir(&ex.ir), traced());
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
            let text = btc_lang::emit::btcpp::emit(&ex.ir, inline);
            let mut from_xml = xml::parse(&text).unwrap_or_else(|e| panic!("{name}: {e}"));
            // The XML carries effects, not preconditions: give it the plan.
            from_xml.steps = ex.ir.steps.clone();
            let mut a = ex.engine(&w, &from_ir, traced());
            let mut b = ex.engine(&w, &from_xml, traced());
            let sa = a.run(100_000, |_| {});
            let sb = b.run(100_000, |_| {});
            assert_eq!(sa, Status::Success, "{name}");
            assert_eq!(sa, sb, "{name}");
            assert_eq!(a.node_count(), b.node_count(), "{name} inline={inline}");
            let (ta, tb) = (a.trace_jsonl(), b.trace_jsonl());
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
