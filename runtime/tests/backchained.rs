//! `steps backchained` resumes from any state: for every corpus plan of the
//! domains with rules (`tests/corpus_rules/`, plans in
//! `../shared/corpus/ipc/`), compiled with `plan { steps backchained }`, the
//! tree ticked from the state after the first k steps runs exactly the
//! remaining steps and reaches the goal; from that state with one fact a
//! later step needs deleted, it runs a suffix of the plan that starts no
//! later than step k+1 and reaches the goal, or fails with a record naming
//! the fact.

mod common;
use btc_ir::TreeIr;
use btc_lang::db::{compile, JobWorld};
use btc_pddl::logic::Formula;
use btc_pddl::state::{Key, World};
use btc_runtime::{Engine, Kb, Options, Status, TreeDoc};
use common::{corpus_job, jsonl, traced};

/// The rules text with its `plan { ... }` block (if any) replaced by
/// `plan { steps backchained }`.
fn backchained(rules: &str) -> String {
    let mut out = String::new();
    let mut depth = 0usize;
    let mut in_plan = false;
    for line in rules.lines() {
        if !in_plan && line.starts_with("plan") && line.contains('{') {
            in_plan = true;
        }
        if in_plan {
            depth += line.matches('{').count();
            depth -= line.matches('}').count().min(depth);
            if depth == 0 {
                in_plan = false;
            }
            continue;
        }
        out.push_str(line);
        out.push('\n');
    }
    out.push_str("plan { steps backchained }\n");
    out
}

/// The steps started by a run, 0-based, in order.
fn started(e: &Engine) -> Vec<usize> {
    jsonl(e)
        .lines()
        .filter_map(|l| serde_json::from_str::<serde_json::Value>(l).ok())
        .filter(|v| v["event"] == "step_started")
        .map(|v| v["step"].as_u64().unwrap() as usize - 1)
        .collect()
}

/// The KB after the first `k` steps of the plan that run (not skipped).
fn after<'w>(w: &'w World, ir: &TreeIr, run: &[usize], k: usize) -> Kb<'w> {
    let mut kb = Kb::new(w);
    for &i in &run[..k] {
        let s = &ir.steps[i];
        for e in [&s.logic.eff_start, &s.logic.eff_end].into_iter().flatten() {
            let id = kb.effect(e).unwrap();
            kb.apply(id);
        }
    }
    kb
}

/// The facts true in `kb` that steps `later` need (positive literals of
/// their conditions).
fn needed(kb: &Kb, ir: &TreeIr, later: &[usize]) -> Vec<(String, Key)> {
    let mut out: Vec<(String, Key)> = Vec::new();
    for &i in later {
        let s = &ir.steps[i];
        for f in [&s.logic.pre_start, &s.logic.pre_over_all, &s.logic.pre_end]
            .into_iter()
            .flatten()
        {
            for l in f.literals().unwrap_or_default() {
                let text = Formula::Atom(l.atom.clone()).to_string();
                let Ok(key) = kb.atom_key(&l.atom) else {
                    continue;
                };
                if l.positive
                    && kb.state.facts.contains(&key)
                    && !out.iter().any(|(t, _)| *t == text)
                {
                    out.push((text, key));
                }
            }
        }
    }
    out
}

#[test]
fn backchained_plans_resume_from_every_prefix_and_redo_what_a_lost_fact_needs() {
    let Some(domains) = btc_testkit::corpus_rules() else {
        return;
    };
    let (mut prefixes, mut deletions, mut redone, mut failed) = (0, 0, 0, 0);
    for d in domains {
        let rules_text = backchained(&std::fs::read_to_string(&d.rules).unwrap());
        // Timed plans (`.tplan`) run in parallel, not backchained.
        for plan in d
            .plans
            .iter()
            .filter(|p| p.extension().is_some_and(|e| e == "plan"))
        {
            let (db, job) = corpus_job(&d.rules, &rules_text, plan);
            let what = plan.display().to_string();
            let ir = compile(&db, job)
                .clone()
                .unwrap_or_else(|e| panic!("{what}: {e:#?}"));
            let jw = JobWorld::of(&db, job).unwrap();
            let w = jw.world().unwrap();
            let doc = TreeDoc::from_ir(&ir);
            let run: Vec<usize> = ir
                .steps
                .iter()
                .filter(|s| !s.skipped)
                .map(|s| s.index)
                .collect();
            for k in 0..=run.len() {
                let mut e = Engine::build(&doc, Some(after(&w, &ir, &run, k)), Options::default())
                    .map(traced)
                    .unwrap();
                let s = e.run(100_000, |_| {});
                assert_eq!(s, Status::Success, "{what} from step {k}: {:#?}", e.records);
                assert_eq!(e.summary(s).goal_reached, Some(true), "{what}");
                assert_eq!(started(&e), run[k..], "{what}: after {k} steps");
                prefixes += 1;

                let kb = after(&w, &ir, &run, k);
                for (fact, key) in needed(&kb, &ir, &run[k..]) {
                    let mut kb = after(&w, &ir, &run, k);
                    kb.apply_keys(Vec::new(), vec![key]);
                    let mut e = Engine::build(&doc, Some(kb), Options::default())
                        .map(traced)
                        .unwrap();
                    let s = e.run(100_000, |_| {});
                    let ran = started(&e);
                    deletions += 1;
                    if s == Status::Success {
                        assert_eq!(e.summary(s).goal_reached, Some(true), "{what}");
                        // A suffix of the plan, starting no later than k+1.
                        let from = run.len() - ran.len();
                        assert_eq!(ran, run[from..], "{what}: after {k} steps without {fact}");
                        assert!(from <= k, "{what}: after {k} without {fact}: ran {ran:?}");
                        redone += 1;
                    } else {
                        let rec = e.records.last().expect("a failure record");
                        assert!(
                            rec.reason.contains(&fact),
                            "{what}: after {k} steps without {fact}: {}",
                            rec.reason
                        );
                        failed += 1;
                    }
                }
            }
        }
    }
    eprintln!(
        "{prefixes} prefixes, {deletions} deleted facts: {redone} redone, {failed} failed naming the fact"
    );
    assert!(
        prefixes >= 100 && redone > 0,
        "{prefixes} prefixes, {redone} redone"
    );
}
