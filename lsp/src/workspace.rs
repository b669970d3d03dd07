//! The server's view of the files: the salsa database of `btc check`, the
//! documents the editor has open, and the PDDL files and imports those
//! documents name, read from disk. Paths in the database are absolute file
//! system paths (the stdlib's are `std::NAME`).

use crate::convert::LineIndex;
use btc_lang::db::{
    checked_domain, checked_problem, domain_file, file_id, normalize, parsed_rules, problem_file,
    rules_diagnostics, Database, Db as _, ProblemOf, SourceFile,
};
use btc_lang::rules::{ImportTarget, Item};
use btc_pddl::diagnostic::Diagnostic;
use std::collections::{BTreeMap, BTreeSet};
use std::path::Path;
use tower_lsp::lsp_types::TextDocumentContentChangeEvent;

/// Files larger than this are not read from disk (the CLI's limit is 1 GiB;
/// an editor has no use for more than this).
const MAX_DISK_FILE: usize = 64 << 20;

pub struct Workspace {
    pub db: Database,
    /// Open documents: path to the editor's version.
    open: BTreeMap<String, i32>,
    /// Paths that had diagnostics at the last publication: they get an empty
    /// list when their problems are gone.
    published: BTreeSet<String>,
    /// Open documents over [`MAX_ANALYSED`]: their text (edits still apply)
    /// while the database holds them empty.
    oversize: BTreeMap<String, String>,
}

/// The largest document the server analyses; a larger one gets one
/// diagnostic (F006) saying so, and is otherwise left alone.
pub const MAX_ANALYSED: usize = 16 << 20;

/// One file's diagnostics, ready to publish.
pub struct FileDiagnostics {
    pub path: String,
    pub version: Option<i32>,
    pub diagnostics: Vec<Diagnostic>,
}

impl Default for Workspace {
    fn default() -> Self {
        Self::new()
    }
}

impl Workspace {
    pub fn new() -> Workspace {
        Workspace {
            db: Database::new(),
            open: BTreeMap::new(),
            published: BTreeSet::new(),
            oversize: BTreeMap::new(),
        }
    }

    pub fn is_rules(path: &str) -> bool {
        path.ends_with(".btrules") || path.starts_with("std::")
    }

    pub fn file(&self, path: &str) -> Option<SourceFile> {
        self.db.file(path)
    }

    pub fn text(&self, path: &str) -> Option<&str> {
        if let Some(t) = self.oversize.get(path) {
            return Some(t);
        }
        self.db.file(path).map(|f| f.text(&self.db).as_str())
    }

    /// An editor's text into the database, unless it is too large to analyse.
    fn set_document(&mut self, path: &str, text: String) {
        if text.len() > MAX_ANALYSED {
            self.db.set_file(path, String::new());
            self.oversize.insert(path.to_owned(), text);
        } else {
            self.oversize.remove(path);
            self.db.set_file(path, text);
        }
    }

    pub fn is_open(&self, path: &str) -> bool {
        self.open.contains_key(path)
    }

    pub fn open(&mut self, path: &str, text: String, version: i32) {
        self.open.insert(path.to_owned(), version);
        self.set_document(path, text);
        self.load_dependencies(path);
    }

    /// Applies the editor's changes (ranges in UTF-16 positions, applied in
    /// order, each to the text the previous one left).
    pub fn change(
        &mut self,
        path: &str,
        changes: Vec<TextDocumentContentChangeEvent>,
        version: i32,
    ) {
        let mut text = self.text(path).unwrap_or_default().to_owned();
        for c in changes {
            match c.range {
                Some(r) => {
                    let ix = LineIndex::new(&text);
                    let (a, b) = (ix.offset(r.start), ix.offset(r.end));
                    let (a, b) = (a.min(b), a.max(b));
                    text.replace_range(a..b, &c.text);
                }
                None => text = c.text,
            }
        }
        self.open.insert(path.to_owned(), version);
        self.set_document(path, text);
        self.load_dependencies(path);
    }

    /// The editor closed a document: what is on disk counts again.
    pub fn close(&mut self, path: &str) {
        self.open.remove(path);
        self.oversize.remove(path);
        self.reload_from_disk(path);
    }

    /// A watched file changed, appeared or went away on disk. Open documents
    /// keep the editor's text.
    pub fn changed_on_disk(&mut self, path: &str) {
        if !self.is_open(path) {
            self.reload_from_disk(path);
        }
    }

    fn reload_from_disk(&mut self, path: &str) {
        match read(Path::new(path)) {
            Some(text) => {
                self.db.set_file(path, text);
                self.load_dependencies(path);
            }
            None => self.db.remove_file(path),
        }
    }

    /// Reads the domain, problem and imports a rules file names (and theirs)
    /// from disk when the database does not have them yet.
    fn load_dependencies(&mut self, path: &str) {
        let mut todo = vec![path.to_owned()];
        let mut seen = BTreeSet::new();
        while let Some(p) = todo.pop() {
            if !Workspace::is_rules(&p) || !seen.insert(p.clone()) {
                continue;
            }
            let Some(f) = self.db.file(&p) else { continue };
            let dir = Path::new(&p)
                .parent()
                .map(Path::to_path_buf)
                .unwrap_or_default();
            let mut wanted = Vec::new();
            for n in &parsed_rules(&self.db, f).items {
                match &n.item {
                    Item::Domain { path, .. } | Item::Problem { path, .. } => {
                        wanted.extend(path.plain())
                    }
                    Item::Import {
                        target: ImportTarget::Path { path },
                        ..
                    } => wanted.extend(path.plain()),
                    _ => {}
                }
            }
            for w in wanted {
                let full = normalize(&dir.join(&w));
                if self.db.file(&full).is_none() {
                    if let Some(text) = read(Path::new(&full)) {
                        self.db.set_file(&full, text);
                    }
                }
                todo.push(full);
            }
        }
    }

    /// Open rules documents.
    pub fn open_rules(&self) -> Vec<SourceFile> {
        self.open
            .keys()
            .filter(|p| Workspace::is_rules(p))
            .filter_map(|p| self.db.file(p))
            .collect()
    }

    /// Every rules file the database knows (open or read as an import).
    pub fn all_rules(&self) -> Vec<SourceFile> {
        self.db
            .workspace()
            .files(&self.db)
            .iter()
            .filter(|(p, _)| p.ends_with(".btrules"))
            .map(|(_, f)| *f)
            .collect()
    }

    /// The path of a file id.
    pub fn path_of(&self, id: btc_pddl::source::FileId) -> Option<String> {
        self.db
            .workspace()
            .files(&self.db)
            .iter()
            .find(|(_, f)| file_id(&self.db, **f) == id)
            .map(|(p, _)| p.clone())
    }

    /// Diagnostics of every open rules document and of the PDDL files they
    /// name (and of open PDDL domains), grouped by file; files that had
    /// diagnostics last time and have none now get an empty list.
    pub fn diagnostics(&mut self) -> Vec<FileDiagnostics> {
        let mut by_path: BTreeMap<String, Vec<Diagnostic>> = BTreeMap::new();
        let mut ids: BTreeMap<btc_pddl::source::FileId, String> = BTreeMap::new();
        for (p, f) in self.db.workspace().files(&self.db) {
            ids.insert(file_id(&self.db, *f), p.clone());
        }
        let add = |d: &Diagnostic, by_path: &mut BTreeMap<String, Vec<Diagnostic>>| {
            if let Some(p) = ids.get(&d.span.file) {
                let list = by_path.entry(p.clone()).or_default();
                if !list.contains(d) {
                    list.push(d.clone());
                }
            }
        };
        let mut pddl_seen = std::collections::HashSet::new();
        for r in self.open_rules() {
            by_path.entry(r.path(&self.db).clone()).or_default();
            for d in rules_diagnostics(&self.db, r) {
                add(d, &mut by_path);
            }
            let domain = domain_file(&self.db, r);
            if let Some(d) = domain {
                if pddl_seen.insert(d) {
                    for x in &checked_domain(&self.db, d).diagnostics {
                        add(x, &mut by_path);
                    }
                }
                if let Some(p) = problem_file(&self.db, r) {
                    if pddl_seen.insert(p) {
                        for x in
                            &checked_problem(&self.db, ProblemOf::new(&self.db, p, d)).diagnostics
                        {
                            add(x, &mut by_path);
                        }
                    }
                }
            }
        }
        // Open PDDL domains that no rules file names are checked alone.
        for p in self.open.keys() {
            if !p.ends_with(".pddl") {
                continue;
            }
            let Some(f) = self.db.file(p) else { continue };
            if pddl_seen.contains(&f) {
                continue;
            }
            by_path.entry(p.clone()).or_default();
            let cd = checked_domain(&self.db, f);
            if cd.domain.is_some() {
                for x in &cd.diagnostics {
                    add(x, &mut by_path);
                }
            }
        }
        for (p, t) in &self.oversize {
            let Some(f) = self.db.file(p) else { continue };
            let id = file_id(&self.db, f);
            // Only this: the (empty) text the database holds says nothing.
            by_path.insert(p.clone(), Vec::new());
            by_path.entry(p.clone()).or_default().push(Diagnostic::error(
                btc_pddl::diagnostic::codes::DOCUMENT_TOO_LARGE,
                btc_pddl::source::Span::new(id, 0, 0),
                format!(
                    "this document has {} bytes; the language server analyses documents of at most {MAX_ANALYSED} bytes",
                    t.len()
                ),
            ).with_hint("`btc check` reads files up to 1 GiB"));
        }
        let mut out = Vec::new();
        let now: BTreeSet<String> = by_path
            .iter()
            .filter(|(_, d)| !d.is_empty())
            .map(|(p, _)| p.clone())
            .collect();
        for gone in self.published.difference(&now) {
            by_path.entry(gone.clone()).or_default();
        }
        for (path, diagnostics) in by_path {
            if path.starts_with("std::") {
                continue;
            }
            out.push(FileDiagnostics {
                version: self.open.get(&path).copied(),
                path,
                diagnostics,
            });
        }
        self.published = now;
        out
    }

    /// Where a rules file's `domain` / `problem` / import string points.
    pub fn resolve_written(&self, from: SourceFile, written: &str) -> Option<String> {
        let dir = Path::new(from.path(&self.db))
            .parent()
            .map(Path::to_path_buf)
            .unwrap_or_default();
        let full = normalize(&dir.join(written));
        self.db.file(&full).map(|_| full)
    }
}

/// A file's text from disk, or `None` when it cannot be read as text
/// (through the CLI's bounded reader: devices and folders are refused,
/// nothing is read past the limit).
fn read(path: &Path) -> Option<String> {
    let bytes = btc_files::read(path, MAX_DISK_FILE).ok()?;
    Some(btc_pddl::source::decode(&bytes).0)
}
