//! Every IPC corpus plan of the domains with rules (`tests/corpus_rules/`,
//! plans in `../shared/corpus/ipc/`) runs to SUCCESS with its goal reached,
//! from the IR and from the BT.CPP XML written for it, with the same trace.

mod common;
use btc_lang::db::JobWorld;
use btc_lang::db::{compile, CompileJob, Database};
use btc_runtime::{xml, Engine, Status, TreeDoc};
use common::{root, traced};
use std::path::{Path, PathBuf};

#[test]
fn corpus_plans_run_to_their_goal() {
    let Some(ipc) = btc_testkit::corpus() else {
        return;
    };
    let root = root();
    let mut dirs: Vec<PathBuf> = std::fs::read_dir(root.join("tests/corpus_rules"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .collect();
    dirs.sort();
    let mut ran = 0;
    for dir in dirs {
        let name = dir.file_name().unwrap().to_string_lossy().into_owned();
        let rules_path = dir.join("rules.btrules");
        let rules_text = std::fs::read_to_string(&rules_path).unwrap();
        let written = rules_text
            .lines()
            .find_map(|l| l.strip_prefix("domain \""))
            .unwrap()
            .trim_end_matches('"');
        let corpus = ipc.join(&name);
        let mut plans: Vec<PathBuf> = std::fs::read_dir(&corpus)
            .unwrap()
            .map(|e| e.unwrap().path())
            .filter(|p| p.extension().is_some_and(|e| e == "plan" || e == "tplan"))
            .collect();
        plans.sort();
        for plan in plans {
            let mut db = Database::new();
            let key = |p: &Path| btc_lang::path::FilePath::new(p);
            db.set_file(
                &key(&dir.join(written)),
                std::fs::read_to_string(dir.join(written)).unwrap(),
            );
            let r = db.set_file(&key(&rules_path), rules_text.clone());
            let stem = plan.file_stem().unwrap().to_string_lossy().into_owned();
            let problem = corpus.join(format!("{stem}.pddl"));
            let p = db.set_file(&key(&problem), std::fs::read_to_string(&problem).unwrap());
            let l = db.set_file(&key(&plan), std::fs::read_to_string(&plan).unwrap());
            let job = CompileJob::new(&db, r, l, Some(p), None);
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
                let mut e = Engine::build(&doc, Some(btc_runtime::Kb::new(&w)), traced())
                    .unwrap_or_else(|e| panic!("{what}: {e}"));
                let s = e.run(1_000_000, |_| {});
                let sum = e.summary(s);
                assert_eq!(s, Status::Success, "{what}: {:#?}", sum.records);
                assert_eq!(sum.goal_reached, Some(true), "{what}");
                assert_eq!(sum.steps_done, sum.steps_total, "{what}");
                traces.push(e.trace_jsonl());
            }
            assert!(traces[0] == traces[1], "{what}: the XML runs differently");
            ran += 1;
        }
    }
    assert!(ran >= 12, "only {ran} corpus plans");
}
