//! The incremental database (salsa). Inputs are file texts; everything else
//! is a tracked query. Each top-level item of a rules file is a tracked
//! struct whose tree has item-relative spans, so an edit re-checks only the
//! items it changed (see `tests`).
//!
//! The queries by family: [`items`] (a rules file cut into items, each
//! parsed on its own), [`pddl`] (the domain and problem a rules file names,
//! checked), [`checks`] (imports, declarations, each item's and the file's
//! checks), [`job`] (a compile job: its plan typed and compiled). This
//! module holds the inputs and the database.

mod checks;
#[cfg(test)]
mod compile_tests;
mod items;
mod job;
#[cfg(test)]
mod parse_ahead_tests;
mod pddl;
#[cfg(test)]
pub(crate) mod tests;

pub use checks::*;
pub use items::*;
pub use job::*;
pub use pddl::*;

use crate::path::{AsFilePath, FilePath};
use crate::project::ReadFailure;
use crate::rules::actions::ActionIndex;
use crate::rules::btxml::{imported_trees, tree_names, XmlTrees};
use crate::rules::check::{check_imported_tree, check_item, Decls, DomainCtx, VarTypes};
use crate::rules::file_checks::{self, Finding, ItemHead, ItemUses, RuleFacts};
use crate::rules::parse::{assemble, cut_rules, parse_item_text, shift, CutRules};
use crate::rules::{Ident, ImportTarget, Item, ItemNode, ParsedRules};
use btc_pddl::diagnostic::{codes, Diagnostic};
use btc_pddl::pipeline::{domain_unit_from, problem_unit_from};
use btc_pddl::source::{DecodeProblem, FileId, Sources, Span};
use btc_pddl::{ast::Domain, ast::Problem, DomainIndex, ProblemIndex};
use salsa::plumbing::AsId;
use salsa::Setter;
use std::collections::BTreeMap;
use std::sync::{Arc, Mutex};

/// One file's text, and what was wrong with its bytes (reported as a
/// diagnostic of the file; the text is what could be decoded).
#[salsa::input(debug)]
pub struct SourceFile {
    #[returns(ref)]
    pub path: FilePath,
    #[returns(ref)]
    pub text: String,
    #[returns(ref)]
    pub decode: Option<DecodeProblem>,
    /// A plan or problem given as a value ([`Database::set_plan`],
    /// [`Database::set_problem`]).
    #[returns(ref)]
    pub value: Option<FileValue>,
}

/// A file given as a value, not read: the compiler takes the value as it
/// is, and the file's text is only what it reads as (for diagnostics).
#[derive(Clone, Debug, PartialEq)]
pub enum FileValue {
    Plan(Arc<btc_pddl::plan::WrittenPlan>),
    Problem(Arc<btc_pddl::written_problem::WrittenProblem>),
}

/// Every file the database knows, by path, and the files a loader was
/// asked for and could not give (so that they are not asked for again
/// until they change).
#[salsa::input(debug)]
pub struct Workspace {
    #[returns(ref)]
    pub files: BTreeMap<FilePath, SourceFile>,
    #[returns(ref)]
    pub unread: BTreeMap<FilePath, ReadFailure>,
}

#[salsa::db]
pub trait Db: salsa::Database {
    fn workspace(&self) -> Workspace;
}

/// The stdlib modules built into the binary.
// Read through `lang/stdlib`, a link to the repository's `stdlib/`, so
// that the packaged crate carries the modules (`cargo package` follows it).
pub const STDLIB: &[(&str, &str)] = &[
    ("btcpp", include_str!("../../stdlib/btcpp.btrules")),
    ("kb", include_str!("../../stdlib/kb.btrules")),
    ("ariac", include_str!("../../stdlib/ariac.btrules")),
    ("crcl", include_str!("../../stdlib/crcl.btrules")),
];

#[salsa::db]
#[derive(Clone)]
pub struct Database {
    storage: salsa::Storage<Self>,
    workspace: Option<Workspace>,
    /// Names of queries executed, when logging is on (tests of incrementality).
    log: Arc<Mutex<Option<Vec<String>>>>,
}

#[salsa::db]
impl salsa::Database for Database {}

#[salsa::db]
impl Db for Database {
    fn workspace(&self) -> Workspace {
        self.workspace.expect("set in Database::new")
    }
}

impl Default for Database {
    fn default() -> Self {
        Self::new()
    }
}

impl Database {
    pub fn new() -> Database {
        let log: Arc<Mutex<Option<Vec<String>>>> = Arc::default();
        let sink = log.clone();
        let storage = salsa::Storage::new(Some(Box::new(move |event: salsa::Event| {
            if let salsa::EventKind::WillExecute { database_key } = event.kind {
                if let Some(log) = &mut *sink.lock().expect("log lock") {
                    log.push(format!("{database_key:?}"));
                }
            }
        })));
        let mut db = Database {
            storage,
            workspace: None,
            log,
        };
        let ws = Workspace::new(&db, BTreeMap::new(), BTreeMap::new());
        db.workspace = Some(ws);
        for (name, text) in STDLIB {
            db.set_file(&FilePath::std(name), text.to_string());
        }
        db
    }

    /// Adds a file or replaces its text (an editor's text, or a test's).
    pub fn set_file(&mut self, path: &(impl AsFilePath + ?Sized), text: String) -> SourceFile {
        self.set_read_file(path.to_file_path(), text, None)
    }

    /// Adds a file as a loader read it: its decoded text and what was wrong
    /// with its bytes.
    pub fn set_read_file(
        &mut self,
        path: FilePath,
        text: String,
        decode: Option<DecodeProblem>,
    ) -> SourceFile {
        let ws = self.workspace();
        if ws.unread(self).contains_key(&path) {
            let mut unread = ws.unread(self).clone();
            unread.remove(&path);
            ws.set_unread(self).to(unread);
        }
        if let Some(&f) = ws.files(self).get(&path) {
            if f.text(self) != &text {
                f.set_text(self).to(text);
            }
            if f.decode(self) != &decode {
                f.set_decode(self).to(decode);
            }
            if f.value(self).is_some() {
                f.set_value(self).to(None);
            }
            return f;
        }
        let f = SourceFile::new(self, path.clone(), text, decode, None);
        let mut files = ws.files(self).clone();
        files.insert(path, f);
        ws.set_files(self).to(files);
        f
    }

    /// Adds or replaces a plan given as a value (a planner's): the file
    /// at `path` holds the text it reads as, for diagnostics, and the
    /// compiler takes the value without reading the text.
    pub fn set_plan(
        &mut self,
        path: &(impl AsFilePath + ?Sized),
        plan: btc_pddl::plan::WrittenPlan,
    ) -> SourceFile {
        let f = self.set_file(path, plan.text().to_owned());
        f.set_value(self).to(Some(FileValue::Plan(Arc::new(plan))));
        f
    }

    /// Adds or replaces a problem given as a value (a program's world, the
    /// trial's cell): as [`Database::set_plan`], the file holds the text it
    /// reads as and the compiler checks the value without parsing it.
    pub fn set_problem(
        &mut self,
        path: &(impl AsFilePath + ?Sized),
        problem: btc_pddl::written_problem::WrittenProblem,
    ) -> SourceFile {
        let f = self.set_file(path, problem.text().to_owned());
        f.set_value(self)
            .to(Some(FileValue::Problem(Arc::new(problem))));
        f
    }

    /// Forgets a file (deleted on disk); rules that name it report it missing.
    pub fn remove_file(&mut self, path: &(impl AsFilePath + ?Sized)) {
        let path = path.to_file_path();
        let ws = self.workspace();
        if ws.files(self).contains_key(&path) {
            let mut files = ws.files(self).clone();
            files.remove(&path);
            ws.set_files(self).to(files);
        }
    }

    /// Notes that a loader could not give this file (and forgets its text).
    pub fn set_unread(&mut self, path: FilePath, why: ReadFailure) {
        self.remove_file(&path);
        let ws = self.workspace();
        if ws.unread(self).get(&path) != Some(&why) {
            let mut unread = ws.unread(self).clone();
            unread.insert(path, why);
            ws.set_unread(self).to(unread);
        }
    }

    /// Forgets that a file could not be read (it changed on disk: ask again).
    pub fn forget_unread(&mut self, path: &FilePath) {
        let ws = self.workspace();
        if ws.unread(self).contains_key(path) {
            let mut unread = ws.unread(self).clone();
            unread.remove(path);
            ws.set_unread(self).to(unread);
        }
    }

    pub fn file(&self, path: &(impl AsFilePath + ?Sized)) -> Option<SourceFile> {
        self.workspace()
            .files(self)
            .get(&path.to_file_path())
            .copied()
    }

    /// Every file as [`Sources`] with the ids diagnostics use, for rendering.
    pub fn sources(&self) -> Sources {
        self.sources_where(|_| true)
    }

    /// The files `diags` point into (their spans, labels and fixes), to
    /// render them: a long plan's text is not copied to say nothing.
    pub fn sources_for(&self, diags: &[Diagnostic]) -> Sources {
        let used: std::collections::BTreeSet<FileId> = diags
            .iter()
            .flat_map(|d| {
                std::iter::once(d.span.file)
                    .chain(d.labels.iter().map(|l| l.span.file))
                    .chain(d.fixes.iter().map(|f| f.span.file))
            })
            .collect();
        self.sources_where(|id| used.contains(&id))
    }

    fn sources_where(&self, keep: impl Fn(FileId) -> bool) -> Sources {
        let mut s = Sources::new();
        for f in self.workspace().files(self).values() {
            let id = file_id(self, *f);
            if keep(id) {
                s.insert(id, f.path(self).to_string(), f.text(self).clone());
            }
        }
        s
    }

    pub fn start_logging(&self) {
        *self.log.lock().expect("log lock") = Some(Vec::new());
    }

    pub fn take_log(&self) -> Vec<String> {
        self.log
            .lock()
            .expect("log lock")
            .as_mut()
            .map(std::mem::take)
            .unwrap_or_default()
    }
}

/// The id spans use for a file: its salsa id, stable while the file exists.
pub fn file_id(_db: &dyn Db, f: SourceFile) -> FileId {
    f.as_id().index()
}
