//! Rules files for corpus domains (`tests/corpus_rules/DOMAIN/`): each checks
//! clean, and every corpus plan of its domain compiles through every emitter.

use btc_emit::{emit, Format, Options};
use btc_lang::db::{compile, rules_diagnostics, CompileJob, Database};
use std::path::{Path, PathBuf};

fn repo() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}

/// A rules file and its corpus plans, each with its problem.
type Case = (PathBuf, Vec<(PathBuf, PathBuf)>);

/// (rules path, [(problem path, plan path)]) per corpus domain with rules;
/// `None` (the test skipped) without the corpus.
pub fn cases() -> Option<Vec<Case>> {
    let ipc = btc_testkit::corpus()?;
    let mut out = Vec::new();
    let mut dirs: Vec<PathBuf> = std::fs::read_dir(repo().join("tests/corpus_rules"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .collect();
    dirs.sort();
    for dir in dirs {
        let name = dir.file_name().unwrap().to_string_lossy().into_owned();
        let corpus = ipc.join(&name);
        let mut plans: Vec<(PathBuf, PathBuf)> = std::fs::read_dir(&corpus)
            .unwrap()
            .map(|e| e.unwrap().path())
            .filter(|p| p.extension().is_some_and(|e| e == "plan" || e == "tplan"))
            .map(|p| {
                (
                    corpus.join(format!("{}.pddl", p.file_stem().unwrap().to_string_lossy())),
                    p,
                )
            })
            .collect();
        plans.sort();
        out.push((dir.join("rules.btrules"), plans));
    }
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
            assert!(ir.steps.iter().all(|s| !s.skipped || s.rule.is_none()));
            for (format, _) in Format::ALL.iter().filter(|(f, _)| *f != Format::Pytrees) {
                assert!(!emit(ir, *format, &Options::default()).is_empty());
            }
            compiled += 1;
        }
    }
    assert!(compiled >= 12, "{compiled} plans");
}
