//! The project loader with an in-memory loader: what it reads, what it
//! notes when a file is missing or unreadable, which problem a plan gets,
//! and the order of the reports. The files are those of
//! `tests/fixtures/pairing/` (read once into memory).

use btc_lang::db::{self, Database};
use btc_lang::path::FilePath;
use btc_lang::project::{
    self, load_job, FileLoader, JobPaths, Loaded, MemoryLoader, PlanSource, ProblemChoice,
    ReadFailure,
};
use std::path::{Path, PathBuf};

fn fixtures() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../tests/fixtures/pairing")
}

fn fixture(name: &str) -> Vec<u8> {
    std::fs::read(fixtures().join(name)).unwrap()
}

/// The pairing fixture under `cell/`, in memory.
fn cell() -> MemoryLoader {
    let mut m = MemoryLoader::new();
    for e in std::fs::read_dir(fixtures()).unwrap() {
        let p = e.unwrap().path();
        m.insert(
            Path::new("cell").join(p.file_name().unwrap()),
            std::fs::read(&p).unwrap(),
        );
    }
    m
}

/// A loader that refuses some paths, as a disk does for a folder or a file
/// without read permission.
struct Refusing {
    inner: MemoryLoader,
    refused: Vec<PathBuf>,
}

impl FileLoader for Refusing {
    fn read(&self, path: &Path) -> Result<Loaded, ReadFailure> {
        if self.refused.iter().any(|r| r == path) {
            return Err(ReadFailure::Unreadable {
                reason: "permission denied".into(),
            });
        }
        self.inner.read(path)
    }

    fn list(&self, dir: &Path) -> Vec<PathBuf> {
        self.inner.list(dir)
    }
}

fn codes(db: &Database, rules: db::SourceFile) -> Vec<(String, &'static str)> {
    project::project_report(db, rules)
        .iter()
        .flat_map(|r| {
            r.diagnostics
                .iter()
                .map(move |d| (r.file.path(db).to_string(), d.code))
        })
        .collect()
}

#[test]
fn a_rules_file_brings_its_domain_and_problem() {
    let mut db = Database::new();
    let rules =
        project::load_rules(&mut db, &cell(), &FilePath::new("cell/rules.btrules")).unwrap();
    assert!(db.file("cell/domain.pddl").is_some());
    assert!(db.file("cell/p01.pddl").is_some());
    assert!(db.file("cell/p02.pddl").is_none(), "only what it names");
    let files: Vec<String> = project::project_report(&db, rules)
        .iter()
        .map(|r| r.file.path(&db).to_string())
        .collect();
    assert_eq!(
        files,
        ["cell/rules.btrules", "cell/domain.pddl", "cell/p01.pddl"]
    );
    assert!(codes(&db, rules).is_empty());
}

#[test]
fn the_problem_a_rules_file_names_is_checked() {
    let mut db = Database::new();
    let rules =
        project::load_rules(&mut db, &cell(), &FilePath::new("cell/undeclared.btrules")).unwrap();
    assert_eq!(
        codes(&db, rules),
        [("cell/p_undeclared.pddl".to_owned(), "P102")]
    );
}

#[test]
fn missing_and_unreadable_files_are_noted_and_reported() {
    let loader = cell().with(
        "lib/rules.btrules",
        "domain \"../cell/domain.pddl\"\nproblem \"gone.pddl\"\nimport \"secret.btrules\"\n",
    );
    let loader = Refusing {
        inner: loader,
        refused: vec![PathBuf::from("lib/secret.btrules")],
    };
    let mut db = Database::new();
    let rules = project::load_rules(&mut db, &loader, &FilePath::new("lib/rules.btrules")).unwrap();
    let unread = db::Db::workspace(&db).unread(&db).clone();
    assert_eq!(
        unread.get(&FilePath::new("lib/gone.pddl")),
        Some(&ReadFailure::NotFound)
    );
    assert!(matches!(
        unread.get(&FilePath::new("lib/secret.btrules")),
        Some(ReadFailure::Unreadable { .. })
    ));
    let report = project::flatten(project::project_report(&db, rules));
    let messages: Vec<String> = report
        .iter()
        .map(|d| format!("{} {}", d.code, d.message))
        .collect();
    assert_eq!(
        messages,
        [
            "R017 cannot find the problem file `gone.pddl`",
            "F001 cannot read the import `lib/secret.btrules`: permission denied",
        ]
    );
    // Once the file appears, loading again reads it.
    let fixed = cell().with(
        "lib/gone.pddl",
        std::fs::read(
            Path::new(env!("CARGO_MANIFEST_DIR")).join("../tests/fixtures/pairing/p01.pddl"),
        )
        .unwrap(),
    );
    db.forget_unread(&FilePath::new("lib/gone.pddl"));
    project::load_references(&mut db, &fixed, rules);
    assert!(db.file("lib/gone.pddl").is_some());
}

#[test]
fn undecodable_bytes_are_a_diagnostic_of_their_file() {
    let loader = cell().with(
        "cell/latin1.btrules",
        b"domain \"domain.pddl\"\n// caf\xE9\n".to_vec(),
    );
    let mut db = Database::new();
    let rules =
        project::load_rules(&mut db, &loader, &FilePath::new("cell/latin1.btrules")).unwrap();
    // (and, the file having no rules yet, R025 says how to start)
    assert_eq!(
        codes(&db, rules),
        [
            ("cell/latin1.btrules".to_owned(), "F002"),
            ("cell/latin1.btrules".to_owned(), "R025")
        ]
    );
}

fn problem_of(loader: &MemoryLoader, plan: &str, problem: Option<&str>) -> (String, ProblemChoice) {
    let mut db = Database::new();
    let paths = JobPaths {
        rules: FilePath::new("cell/rules.btrules"),
        plan: PlanSource::File(FilePath::new(plan)),
        problem: problem.map(FilePath::new),
        domain: None,
    };
    let job = load_job(&mut db, loader, &paths).unwrap();
    let (f, how) = job.problem.unwrap();
    assert_eq!(Some(f), db::job_problem(&db, job.job));
    (f.path(&db).to_string(), how)
}

#[test]
fn a_plan_pairs_with_its_problem_in_the_documented_order() {
    let m = cell();
    assert_eq!(
        problem_of(&m, "cell/p02.plan", Some("cell/p03.pddl")),
        ("cell/p03.pddl".into(), ProblemChoice::Given)
    );
    assert_eq!(
        problem_of(&m, "cell/p02.plan", None),
        ("cell/p02.pddl".into(), ProblemChoice::PairedWithPlan)
    );
    let m = m.with("runs/plan.txt", "(go r1 a b)\n");
    assert_eq!(
        problem_of(&m, "runs/plan.txt", None),
        ("cell/p01.pddl".into(), ProblemChoice::NamedByRules)
    );
    // A rules file that names no problem: `problem.pddl` beside the plan,
    // else beside the rules file.
    let unnamed = "domain \"domain.pddl\"\naction Go(robot: robot, target: station)\nrule (go ?r ?a ?b) { Go(robot: ?r, target: ?b) }\n";
    let m = cell()
        .with("cell/rules.btrules", unnamed)
        .with("cell/problem.pddl", fixture("p03.pddl"))
        .with("runs/plan.txt", "(go r1 c b)\n");
    assert_eq!(
        problem_of(&m, "runs/plan.txt", None),
        ("cell/problem.pddl".into(), ProblemChoice::BesideRules)
    );
    let m = m.with("runs/problem.pddl", fixture("p03.pddl"));
    assert_eq!(
        problem_of(&m, "runs/plan.txt", None),
        ("runs/problem.pddl".into(), ProblemChoice::BesidePlan)
    );
}

#[test]
fn a_plan_for_another_problem_is_one_diagnostic_naming_the_right_one() {
    let mut db = Database::new();
    let paths = JobPaths {
        rules: FilePath::new("cell/rules.btrules"),
        plan: PlanSource::File(FilePath::new("cell/p02.plan")),
        problem: Some(FilePath::new("cell/p01.pddl")),
        domain: None,
    };
    let job = load_job(&mut db, &cell(), &paths).unwrap().job;
    let diags = db::job_diagnostics(&db, job);
    assert_eq!(diags.iter().map(|d| d.code).collect::<Vec<_>>(), ["L010"]);
    assert_eq!(
        diags[0].hint.as_deref(),
        Some("`cell/p02.pddl` beside it has every object the plan names: pass `--problem cell/p02.pddl`")
    );
}

#[test]
fn a_plan_whose_names_exist_but_whose_steps_fail_is_caught() {
    let mut db = Database::new();
    let paths = JobPaths {
        rules: FilePath::new("cell/rules.btrules"),
        plan: PlanSource::File(FilePath::new("cell/p01.plan")),
        problem: Some(FilePath::new("cell/p03.pddl")),
        domain: None,
    };
    let job = load_job(&mut db, &cell(), &paths).unwrap().job;
    assert!(db::job_diagnostics(&db, job).is_empty());
    let v = project::fit::plan_validation(&db, job);
    assert_eq!(v.iter().map(|d| d.code).collect::<Vec<_>>(), ["V001"]);
    assert!(v[0]
        .hint
        .as_deref()
        .unwrap()
        .contains("valid for `cell/p01.pddl`"));
    // The library's compile does not replay plans (the closed loop compiles
    // plans made from a fault's state); `btc compile` refuses on V001.
    assert!(db::compile(&db, job).is_ok());
}
