//! A rule's `effect` is the step's effect: the final KB shows it, not the
//! PDDL action's, whether the tree runs from the IR or from the BT.CPP XML
//! written for it (fixture `tests/fixtures/rule_effect/`).

mod common;
use btc_pddl::logic::Atom;
use btc_runtime::{Options, Status, TreeDoc};
use common::*;

#[test]
fn the_final_kb_shows_the_rules_effect_from_the_ir_and_from_the_xml() {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/rule_effect");
    let ex = compile_dir(&dir, "rule_effect");
    let w = ex.world();
    // The IR's steps carry the rule's effect.
    assert_eq!(
        ex.ir.steps[0]
            .logic
            .eff_end
            .as_ref()
            .map(|e| e.to_string())
            .as_deref(),
        Some("(and (at r1 b) (marked b))")
    );
    let xml = btc_emit::btcpp::emit(&ex.ir, false);
    assert!(
        xml.contains("end_effect=\"(and (at r1 b) (marked b))\""),
        "{xml}"
    );
    // py_trees: one shape for both steps, the rule's effect lifted over the
    // step's arguments (?#0 the robot, ?#2 where it goes); the final KB of
    // the module is compared in three_way.rs.
    let module = btc_emit::pytrees::emit(&ex.ir, &Default::default());
    assert!(
        module.contains("(\":and\", (\"at\", \"?#0\", \"?#2\"), (\"marked\", \"?#2\"))"),
        "{module}"
    );
    let mut finals = Vec::new();
    for doc in [TreeDoc::from_ir(&ex.ir), ex.xml(&xml)] {
        let mut e = traced(ex.engine(&w, &doc, Options::default()));
        let s = e.run(1000, |_| {});
        assert_eq!(s, Status::Success, "{:#?}", e.records);
        assert_eq!(e.summary(s).goal_reached, Some(true));
        let kb = e.kb.as_ref().unwrap();
        let has = |p: &str, args: &[&str]| {
            kb.state
                .facts
                .contains(&kb.atom_key(&Atom::ground(p, args)).unwrap())
        };
        // The rule's effect: markers where the robot arrived...
        assert!(has("marked", &["b"]) && has("marked", &["c"]));
        // ...and no delete of where it left, unlike the PDDL action.
        assert!(has("at", &["r1", "a"]) && has("at", &["r1", "b"]));
        finals.push(kb.snapshot());
    }
    assert_eq!(finals[0], finals[1]);
}
