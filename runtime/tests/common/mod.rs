//! Shared by the integration tests: compile an example folder as `btc run`
//! does, and build engines over its world.
#![allow(dead_code)]

use btc_ir::TreeIr;
use btc_lang::db::JobWorld;
use btc_lang::db::{self, CompileJob, Database};
use btc_pddl::state::World;
use btc_runtime::engine::TickEvent;
use btc_runtime::observers::{EventLog, JsonlTrace};
use btc_runtime::{Engine, Options, TreeDoc};
use std::path::{Path, PathBuf};

pub fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}

pub fn fixture(name: &str) -> String {
    let p = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/fixtures")
        .join(name);
    std::fs::read_to_string(&p).unwrap_or_else(|e| panic!("{}: {e}", p.display()))
}

/// A corpus plan set up for compiling: the rules (given as text, which
/// may differ from the file's), the domain their `domain` line names, the
/// plan and the problem of the plan's stem beside it.
pub fn corpus_job(rules: &Path, rules_text: &str, plan: &Path) -> (Database, CompileJob) {
    let mut db = Database::new();
    let key = |p: &Path| btc_lang::path::FilePath::new(p);
    let dir = rules.parent().unwrap();
    let written = rules_text
        .lines()
        .find_map(|l| l.strip_prefix("domain \""))
        .unwrap()
        .trim_end_matches('"');
    let domain = dir.join(written);
    db.set_file(&key(&domain), std::fs::read_to_string(&domain).unwrap());
    let r = db.set_file(&key(rules), rules_text.to_owned());
    let stem = plan.file_stem().unwrap().to_string_lossy().into_owned();
    let problem = plan.with_file_name(format!("{stem}.pddl"));
    let p = db.set_file(&key(&problem), std::fs::read_to_string(&problem).unwrap());
    let l = db.set_file(&key(plan), std::fs::read_to_string(plan).unwrap());
    let job = CompileJob::new(&db, r, l, Some(p), None);
    (db, job)
}

pub const EXAMPLES: &[&str] = &["ariac", "nist_kitting", "p3_assembler", "two_robots"];

/// An example folder loaded and compiled (rules, its first plan, problem).
pub struct Example {
    pub db: Database,
    pub job: CompileJob,
    pub ir: TreeIr,
}

pub fn example(name: &str) -> Example {
    compile_dir(&root().join("examples").join(name), name)
}

/// A folder with `rules.btrules`, `problem.pddl`, a domain and a `plan.*`,
/// compiled (`name` for messages).
pub fn compile_dir(dir: &Path, name: &str) -> Example {
    let mut plans: Vec<PathBuf> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| {
            p.file_name()
                .unwrap()
                .to_string_lossy()
                .starts_with("plan.")
        })
        .collect();
    plans.sort();
    let plan = plans
        .first()
        .unwrap_or_else(|| panic!("{name}: no plan.* file"));
    load(&dir.join("rules.btrules"), plan, &dir.join("problem.pddl"))
}

/// Compiles `rules` with `plan` and `problem`; every file of the rules'
/// folder and the domain the rules file names are loaded.
pub fn load(rules: &Path, plan: &Path, problem: &Path) -> Example {
    let mut db = Database::new();
    let dir = rules.parent().unwrap();
    let text = std::fs::read_to_string(rules).unwrap();
    let extra: Vec<PathBuf> = text
        .lines()
        .find_map(|l| l.trim().strip_prefix("domain \""))
        .map(|d| dir.join(d.trim_end_matches('"')))
        .into_iter()
        .collect();
    // The folder's files and those of its folders (the BT.CPP trees a
    // rules file imports from `trees/`).
    let mut names: Vec<PathBuf> = Vec::new();
    for p in std::fs::read_dir(dir).unwrap().map(|e| e.unwrap().path()) {
        if p.is_file() {
            names.push(p);
        } else if p.is_dir() {
            names.extend(
                std::fs::read_dir(&p)
                    .unwrap()
                    .map(|e| e.unwrap().path())
                    .filter(|p| p.is_file()),
            );
        }
    }
    names.extend(extra);
    names.extend([plan.to_path_buf(), problem.to_path_buf()]);
    names.sort();
    names.dedup();
    for p in &names {
        db.set_file(
            &btc_lang::path::FilePath::new(p),
            std::fs::read_to_string(p).unwrap(),
        );
    }
    let file = |p: &Path| db.file(&btc_lang::path::FilePath::new(p)).unwrap();
    let job = CompileJob::new(&db, file(rules), file(plan), Some(file(problem)), None);
    let ir = db::compile(&db, job)
        .as_ref()
        .unwrap_or_else(|e| panic!("{}: {e:#?}", rules.display()))
        .as_ref()
        .clone();
    Example { db, job, ir }
}

impl Example {
    pub fn job_world(&self) -> JobWorld<'_> {
        JobWorld::of(&self.db, self.job).expect("the example has a domain and a problem")
    }

    /// The example's world, ready for a knowledge base.
    pub fn world(&self) -> World {
        self.job_world().world().unwrap_or_else(|e| panic!("{e}"))
    }

    /// A BT.CPP XML tree of the example, with its domain's actions.
    pub fn xml(&self, text: &str) -> TreeDoc {
        btc_runtime::xml::parse(text)
            .unwrap_or_else(|e| panic!("{e}"))
            .with_actions(self.job_world().domain)
    }

    /// An engine over the example's world for `doc`.
    pub fn engine<'a>(&self, w: &'a World, doc: &TreeDoc, opts: Options) -> Engine<'a> {
        Engine::build(doc, Some(btc_runtime::Kb::new(w)), opts).unwrap_or_else(|e| panic!("{e}"))
    }
}

/// The engine with a log of its events and its JSON Lines trace
/// registered ([`events`], [`jsonl`] read them).
pub fn traced(mut e: Engine<'_>) -> Engine<'_> {
    e.observe(EventLog::default());
    e.observe(JsonlTrace::default());
    e
}

/// The events of a [`traced`] engine so far.
pub fn events<'e>(e: &'e Engine<'_>) -> &'e [TickEvent] {
    &e.observer::<EventLog>()
        .expect("the engine is traced")
        .events
}

/// The JSON Lines trace of a [`traced`] engine so far.
pub fn jsonl(e: &Engine<'_>) -> String {
    e.observer::<JsonlTrace>()
        .expect("the engine is traced")
        .text()
        .to_owned()
}
