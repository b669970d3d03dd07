//! Every IPC corpus plan of the domains with rules (`tests/corpus_rules/`,
//! plans in `../shared/corpus/ipc/`) runs to SUCCESS with its goal reached,
//! from the IR and from the BT.CPP XML written for it, with the same trace.

mod common;
use btc_lang::db::compile;
use btc_lang::db::JobWorld;
use btc_runtime::{xml, Engine, Options, Status, TreeDoc};
use common::{corpus_job, jsonl, traced};

#[test]
fn corpus_plans_run_to_their_goal() {
    let Some(domains) = btc_testkit::corpus_rules() else {
        return;
    };
    let mut ran = 0;
    for d in domains {
        let rules_text = std::fs::read_to_string(&d.rules).unwrap();
        for plan in d.plans {
            let (db, job) = corpus_job(&d.rules, &rules_text, &plan);
            let ir = compile(&db, job)
                .clone()
                .unwrap_or_else(|e| panic!("{}: {e:#?}", plan.display()));
            let jw = JobWorld::of(&db, job).unwrap();
            let w = jw.world().unwrap();
            let what = plan.display().to_string();
            let xml_text = btc_emit::btcpp::emit(&ir, false);
            let mut traces = Vec::new();
            let from_xml = xml::parse(&xml_text).unwrap().with_actions(jw.domain);
            for doc in [TreeDoc::from_ir(&ir), from_xml] {
                let mut e = Engine::build(&doc, Some(btc_runtime::Kb::new(&w)), Options::default())
                    .map(traced)
                    .unwrap_or_else(|e| panic!("{what}: {e}"));
                let s = e.run(1_000_000, |_| {});
                let sum = e.summary(s);
                assert_eq!(s, Status::Success, "{what}: {:#?}", sum.records);
                assert_eq!(sum.goal_reached, Some(true), "{what}");
                assert_eq!(sum.steps_done, sum.steps_total, "{what}");
                traces.push(jsonl(&e));
            }
            assert!(traces[0] == traces[1], "{what}: the XML runs differently");
            ran += 1;
        }
    }
    assert!(ran >= 12, "only {ran} corpus plans");
}
