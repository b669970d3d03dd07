//! The server's view of the files: the salsa database of `btc check`, the
//! documents the editor has open, and the files those documents name, read
//! from disk by the project loader (`btc_lang::project`) — the same loader,
//! and the same reports, as `btc check`. Paths are the documents' absolute
//! file system paths.

use crate::convert::LineIndex;
use btc_lang::db::{file_id, Database, Db as _, SourceFile};
use btc_lang::path::FilePath;
use btc_lang::project::{self, FileLoader};
use btc_pddl::diagnostic::Diagnostic;
use std::collections::{BTreeMap, BTreeSet, HashSet};

use tower_lsp::lsp_types::TextDocumentContentChangeEvent;

/// Files larger than this are not read from disk (the CLI's limit is 1 GiB;
/// an editor has no use for more than this).
const MAX_DISK_FILE: usize = 64 << 20;

pub struct Workspace {
    pub db: Database,
    /// Open documents: path to the editor's version.
    open: BTreeMap<FilePath, i32>,
    /// Paths that had diagnostics at the last publication: they get an empty
    /// list when their problems are gone.
    published: BTreeSet<FilePath>,
    /// Open documents over [`MAX_ANALYSED`]: their text (edits still apply)
    /// while the database holds them empty.
    oversize: BTreeMap<FilePath, String>,
    loader: Box<dyn FileLoader + Send>,
}

/// The largest document the server analyses; a larger one gets one
/// diagnostic (F006) saying so, and is otherwise left alone.
pub const MAX_ANALYSED: usize = 16 << 20;

/// One file's diagnostics, ready to publish.
pub struct FileDiagnostics {
    pub path: FilePath,
    pub version: Option<i32>,
    pub diagnostics: Vec<Diagnostic>,
}

impl Default for Workspace {
    fn default() -> Self {
        Self::new()
    }
}

impl Workspace {
    /// A workspace over the disk.
    pub fn new() -> Workspace {
        Workspace::with_loader(Box::new(project::DiskLoader {
            limit: MAX_DISK_FILE,
        }))
    }

    /// A workspace whose files not open in the editor come from `loader`.
    pub fn with_loader(loader: Box<dyn FileLoader + Send>) -> Workspace {
        Workspace {
            db: Database::new(),
            open: BTreeMap::new(),
            published: BTreeSet::new(),
            oversize: BTreeMap::new(),
            loader,
        }
    }

    /// Where files not open in the editor come from.
    pub fn loader(&self) -> &dyn FileLoader {
        self.loader.as_ref()
    }

    pub fn file(&self, path: &FilePath) -> Option<SourceFile> {
        self.db.file(path)
    }

    pub fn text(&self, path: &FilePath) -> Option<&str> {
        if let Some(t) = self.oversize.get(path) {
            return Some(t);
        }
        self.db.file(path).map(|f| f.text(&self.db).as_str())
    }

    /// An editor's text into the database, unless it is too large to analyse.
    fn set_document(&mut self, path: &FilePath, text: String) -> SourceFile {
        if text.len() > MAX_ANALYSED {
            self.oversize.insert(path.clone(), text);
            self.db.set_file(path, String::new())
        } else {
            self.oversize.remove(path);
            self.db.set_file(path, text)
        }
    }

    pub fn is_open(&self, path: &FilePath) -> bool {
        self.open.contains_key(path)
    }

    pub fn open(&mut self, path: &FilePath, text: String, version: i32) {
        self.open.insert(path.clone(), version);
        let f = self.set_document(path, text);
        project::load_references(&mut self.db, self.loader.as_ref(), f);
    }

    /// Applies the editor's changes (ranges in UTF-16 positions, applied in
    /// order, each to the text the previous one left).
    pub fn change(
        &mut self,
        path: &FilePath,
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
        self.open(path, text, version);
    }

    /// The editor closed a document: what is on disk counts again.
    pub fn close(&mut self, path: &FilePath) {
        self.open.remove(path);
        self.oversize.remove(path);
        self.reload_from_disk(path);
    }

    /// A watched file changed, appeared or went away on disk. Open documents
    /// keep the editor's text.
    pub fn changed_on_disk(&mut self, path: &FilePath) {
        if !self.is_open(path) {
            self.reload_from_disk(path);
        }
    }

    fn reload_from_disk(&mut self, path: &FilePath) {
        if let Ok(f) = project::read_file(&mut self.db, self.loader.as_ref(), path) {
            project::load_references(&mut self.db, self.loader.as_ref(), f);
        }
    }

    /// Open rules documents.
    pub fn open_rules(&self) -> Vec<SourceFile> {
        self.open
            .keys()
            .filter(|p| p.is_rules())
            .filter_map(|p| self.db.file(p))
            .collect()
    }

    /// Every rules file the database knows (open or read as an import).
    pub fn all_rules(&self) -> Vec<SourceFile> {
        self.db
            .workspace()
            .files(&self.db)
            .iter()
            .filter(|(p, _)| matches!(p, FilePath::Disk(_)) && p.is_rules())
            .map(|(_, f)| *f)
            .collect()
    }

    /// The path of a file id.
    pub fn path_of(&self, id: btc_pddl::source::FileId) -> Option<FilePath> {
        self.db
            .workspace()
            .files(&self.db)
            .iter()
            .find(|(_, f)| file_id(&self.db, **f) == id)
            .map(|(p, _)| p.clone())
    }

    /// The reports of every open rules document (as `btc check` makes them:
    /// `btc_lang::project::project_report`) and of open PDDL domains that no
    /// rules file names, grouped by file in the reports' order; files that
    /// had diagnostics last time and have none now get an empty list.
    pub fn diagnostics(&mut self) -> Vec<FileDiagnostics> {
        let mut ids: BTreeMap<btc_pddl::source::FileId, FilePath> = BTreeMap::new();
        for (p, f) in self.db.workspace().files(&self.db) {
            ids.insert(file_id(&self.db, *f), p.clone());
        }
        let mut by_path: BTreeMap<FilePath, Vec<Diagnostic>> = BTreeMap::new();
        // A PDDL file two rules files name is reported once.
        let mut reported: HashSet<SourceFile> = HashSet::new();
        let roots = self.open_rules();
        for &r in &roots {
            for (i, section) in project::project_report(&self.db, r).iter().enumerate() {
                // An open rules file reports itself; any other file once.
                let root = i == 0;
                if !root && (roots.contains(&section.file) || !reported.insert(section.file)) {
                    continue;
                }
                by_path
                    .entry(section.file.path(&self.db).clone())
                    .or_default();
                let mut diags = section.diagnostics.clone();
                if root {
                    project::suggest_paths(&self.db, self.loader.as_ref(), r, &mut diags);
                }
                for d in &diags {
                    if let Some(p) = ids.get(&d.span.file) {
                        by_path.entry(p.clone()).or_default().push(d.clone());
                    }
                }
            }
        }
        // Open PDDL domains that no rules file names are checked alone.
        for p in self.open.keys() {
            if !p.has_extension("pddl") {
                continue;
            }
            let Some(f) = self.db.file(p) else { continue };
            if reported.contains(&f) {
                continue;
            }
            let cd = btc_lang::db::checked_domain(&self.db, f);
            let list = by_path.entry(p.clone()).or_default();
            if cd.domain.is_some() {
                list.extend(
                    project::report::read_diagnostics(&self.db, f)
                        .iter()
                        .cloned(),
                );
                list.extend(cd.diagnostics.iter().cloned());
            }
        }
        for (p, t) in &self.oversize {
            let Some(f) = self.db.file(p) else { continue };
            let id = file_id(&self.db, f);
            // Only this: the (empty) text the database holds says nothing.
            by_path.insert(p.clone(), vec![Diagnostic::error(
                btc_pddl::diagnostic::codes::DOCUMENT_TOO_LARGE,
                btc_pddl::source::Span::new(id, 0, 0),
                format!(
                    "this document has {} bytes; the language server analyses documents of at most {MAX_ANALYSED} bytes",
                    t.len()
                ),
            ).with_hint("`btc check` reads files up to 1 GiB")]);
        }
        let now: BTreeSet<FilePath> = by_path
            .iter()
            .filter(|(_, d)| !d.is_empty())
            .map(|(p, _)| p.clone())
            .collect();
        for gone in self.published.difference(&now) {
            by_path.entry(gone.clone()).or_default();
        }
        let mut out = Vec::new();
        for (path, diagnostics) in by_path {
            if matches!(path, FilePath::Std(_)) {
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
    pub fn resolve_written(&self, from: SourceFile, written: &str) -> Option<FilePath> {
        let full = from.path(&self.db).sibling(written)?;
        self.db.file(&full).map(|_| full)
    }
}

/// A workspace (files in memory) with `text` open as `/w/a.btrules` and
/// the database logging the queries it runs from here on: what the tests
/// of which work a request does start from.
#[cfg(test)]
pub fn logging_workspace(text: &str) -> (Workspace, FilePath) {
    let mut ws = Workspace::with_loader(Box::new(btc_lang::project::MemoryLoader::new()));
    let path = FilePath::new("/w/a.btrules");
    ws.open(&path, text.into(), 1);
    ws.db.start_logging();
    (ws, path)
}
