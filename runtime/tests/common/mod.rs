//! Shared by the integration tests: compile an example folder as `btc run`
//! does, and build engines over its world.
#![allow(dead_code)]

use btc_ir::TreeIr;
use btc_lang::db::JobWorld;
use btc_lang::db::{self, CompileJob, Database};
use btc_pddl::state::World;
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
    let mut db = Database::new();
    let mut rules = None;
    let mut plan = None;
    let mut names: Vec<PathBuf> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.is_file())
        .collect();
    names.sort();
    for p in names {
        let name = p.file_name().unwrap().to_string_lossy().into_owned();
        let f = db.set_file(&p, std::fs::read_to_string(&p).unwrap());
        if name.starts_with("plan.") && plan.is_none() {
            plan = Some(f);
        }
        if name == "rules.btrules" {
            rules = Some(f);
        }
    }
    let problem = db.file(&dir.join("problem.pddl"));
    let job = CompileJob::new(&db, rules.unwrap(), plan.unwrap(), problem, None);
    let ir = db::compile(&db, job)
        .as_ref()
        .unwrap_or_else(|e| panic!("{name}: {e:#?}"))
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

pub fn traced() -> Options {
    Options {
        trace: true,
        ..Options::default()
    }
}
