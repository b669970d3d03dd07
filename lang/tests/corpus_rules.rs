//! Rules files for corpus domains (`tests/corpus_rules/DOMAIN/`): each checks
//! clean, and every corpus plan of its domain compiles through every emitter.

use btc_emit::{emit, Format, Options};
use btc_lang::db::{compile, rules_diagnostics, CompileJob, Database};
use std::path::{Path, PathBuf};

/// A rules file and its corpus plans, each with its problem.
type Case = (PathBuf, Vec<(PathBuf, PathBuf)>);

/// (rules path, [(problem path, plan path)]) per corpus domain with rules;
/// `None` (the test skipped) without the corpus.
pub fn cases() -> Option<Vec<Case>> {
    let out: Vec<Case> = btc_testkit::corpus_rules()?
        .into_iter()
        .map(|d| {
            let plans = d
                .plans
                .into_iter()
                .map(|p| {
                    let stem = p.file_stem().unwrap().to_string_lossy().into_owned();
                    (d.corpus.join(format!("{stem}.pddl")), p)
                })
                .collect();
            (d.rules, plans)
        })
        .collect();
    assert!(out.len() >= 5, "rules for at least five corpus domains");
    Some(out)
}

fn load(db: &mut Database, p: &Path) -> btc_lang::db::SourceFile {
    db.set_file(p, std::fs::read_to_string(p).unwrap())
}

#[test]
fn every_plan_of_the_covered_domains_compiles() {
    let mut compiled = 0;
    let Some(cases) = cases() else { return };
    for (rules, plans) in cases {
        let mut db = Database::new();
        let domain = rules.parent().unwrap().join(
            std::fs::read_to_string(&rules)
                .unwrap()
                .lines()
                .find_map(|l| l.strip_prefix("domain \""))
                .unwrap()
                .trim_end_matches('"'),
        );
        load(&mut db, &domain);
        let r = load(&mut db, &rules);
        let diags = rules_diagnostics(&db, r);
        assert!(diags.is_empty(), "{}: {diags:#?}", rules.display());
        for (problem, plan) in plans {
            let p = load(&mut db, &problem);
            let l = load(&mut db, &plan);
            let job = CompileJob::new(&db, r, l, Some(p), None);
            let ir = compile(&db, job)
                .as_ref()
                .unwrap_or_else(|e| panic!("{}: {e:#?}", plan.display()));
            assert!(ir
                .steps
                .iter()
                .all(|s| !s.skipped || s.logic.rule.is_none()));
            for (format, _) in Format::ALL.iter().filter(|(f, _)| *f != Format::Pytrees) {
                assert!(!emit(ir, *format, &Options::default()).is_empty());
            }
            compiled += 1;
        }
    }
    assert!(compiled >= 12, "{compiled} plans");
}
