//! The incremental database (salsa). Inputs are file texts; everything else
//! is a tracked query. Each top-level item of a rules file is a tracked
//! struct whose tree has item-relative spans, so an edit re-checks only the
//! items it changed (see the tests at the end).

use crate::path::{AsFilePath, FilePath};
use crate::project::ReadFailure;
use crate::rules::actions::ActionIndex;
use crate::rules::check::{check_item, Decls, DomainCtx, VarTypes};
use crate::rules::file_checks::{self, Finding, ItemHead, ItemUses, RuleFacts};
use crate::rules::parse::{assemble, cut_rules, parse_item_text, shift, CutRules};
use crate::rules::{ImportTarget, Item, ItemNode, ParsedRules};
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
    ("btcpp", include_str!("../stdlib/btcpp.btrules")),
    ("kb", include_str!("../stdlib/kb.btrules")),
    ("ariac", include_str!("../stdlib/ariac.btrules")),
    ("crcl", include_str!("../stdlib/crcl.btrules")),
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
            return f;
        }
        let f = SourceFile::new(self, path.clone(), text, decode);
        let mut files = ws.files(self).clone();
        files.insert(path, f);
        ws.set_files(self).to(files);
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

/// A rules file parsed, and the interned text each item was parsed from
/// (`None` for a palette's items), which [`rules_items`] points to
/// instead of copying the items.
#[derive(Clone, Debug, PartialEq, salsa::SalsaValue)]
pub struct ParsedFile<'db> {
    pub rules: ParsedRules,
    pub texts: Vec<Option<ItemText<'db>>>,
}

/// A rules file parsed. Items are parsed through [`parsed_item`], so an
/// edit re-parses only the items whose text it changed.
#[salsa::tracked(returns(ref))]
pub fn parsed_file(db: &dyn Db, file: SourceFile) -> ParsedFile<'_> {
    if is_palette(file.path(db)) {
        let (items, diagnostics) =
            crate::rules::palette::parse_palette(file.text(db), file_id(db, file));
        return ParsedFile {
            texts: vec![None; items.len()],
            rules: ParsedRules {
                items,
                comments: Vec::new(),
                diagnostics,
            },
        };
    }
    let cut = cut_file(db, file);
    let parsed = cut
        .texts
        .iter()
        .map(|t| parsed_item(db, *t).clone())
        .collect();
    ParsedFile {
        rules: assemble(cut.cut.clone(), parsed, file_id(db, file)),
        texts: cut.texts.iter().copied().map(Some).collect(),
    }
}

/// A rules file cut into items, and each item's interned text.
#[derive(Clone, Debug, PartialEq, salsa::SalsaValue)]
pub struct CutFile<'db> {
    pub cut: CutRules,
    pub texts: Vec<ItemText<'db>>,
}

#[salsa::tracked(returns(ref))]
pub fn cut_file(db: &dyn Db, file: SourceFile) -> CutFile<'_> {
    let text = file.text(db);
    let cut = cut_rules(text, file_id(db, file));
    let texts = cut
        .items
        .iter()
        .map(|&(start, end)| ItemText::new(db, file, text[start as usize..end as usize].to_owned()))
        .collect();
    CutFile { cut, texts }
}

/// Parses the items of a large rules file on two threads, ahead of the
/// queries that read them (they find the parses memoized). Items parse
/// independently, and a huge file's first parse is most of the time to its
/// first diagnostics (a 6.5 MB file: half a second of one core).
pub fn parse_ahead(db: &Database, file: SourceFile) {
    /// Below this many items a thread costs more than it saves.
    const ITEMS: usize = 2_000;
    if is_palette(file.path(db)) || !file.path(db).is_rules() {
        return;
    }
    let texts = &cut_file(db, file).texts;
    if texts.len() < ITEMS {
        return;
    }
    let (first, second) = texts.split_at(texts.len() / 2);
    let other = db.clone();
    std::thread::scope(|s| {
        s.spawn(move || {
            for t in second {
                parsed_item(&other, *t);
            }
        });
        for t in first {
            parsed_item(db, *t);
        }
    });
}

/// A rules file parsed (see [`parsed_file`]).
pub fn parsed_rules(db: &dyn Db, file: SourceFile) -> &ParsedRules {
    &parsed_file(db, file).rules
}

/// A rules file's tokens and comments (spans in file 0: positions, not
/// places), lexed once per text: every language server request reads
/// them, and lexing a huge file per request cost a large part of each.
#[derive(Clone, Debug, PartialEq)]
pub struct FileTokens {
    pub tokens: Vec<(crate::rules::lexer::Tok, Span)>,
    pub comments: Vec<crate::rules::lexer::Comment>,
}

#[salsa::tracked(returns(ref))]
pub fn rules_tokens(db: &dyn Db, file: SourceFile) -> FileTokens {
    let l = crate::rules::lexer::lex(file.text(db), 0);
    FileTokens {
        tokens: l.tokens,
        comments: l.comments,
    }
}

/// Whether an imported file is a BT.CPP node palette (`.xml`) rather than
/// rules.
pub fn is_palette(path: &FilePath) -> bool {
    path.as_path()
        .and_then(std::path::Path::extension)
        .is_some_and(|e| e.eq_ignore_ascii_case("xml"))
}

/// The text of one top-level item of a rules file.
#[salsa::interned(debug)]
pub struct ItemText<'db> {
    #[returns(copy)]
    pub file: SourceFile,
    #[returns(ref)]
    pub text: String,
}

/// One item parsed, with spans relative to its start.
#[salsa::tracked(returns(ref))]
pub fn parsed_item<'db>(db: &'db dyn Db, item: ItemText<'db>) -> (Arc<Item>, Vec<Diagnostic>) {
    let (item, diagnostics) = parse_item_text(item.text(db), file_id(db, item.file(db)));
    (Arc::new(item), diagnostics)
}

/// One top-level item. Identified by its file and head (kind and name or
/// pattern), so inserting an item elsewhere keeps the others' identities.
#[salsa::tracked(debug)]
pub struct RulesItem<'db> {
    #[returns(copy)]
    pub file: SourceFile,
    #[returns(ref)]
    pub key: String,
    #[tracked]
    #[returns(copy)]
    pub source: ItemSource<'db>,
    #[tracked]
    #[returns(copy)]
    pub offset: u32,
}

/// Where a [`RulesItem`]'s tree is kept: the memo of the text it was
/// parsed from, or (a palette's items) its place in the parsed file.
/// Pointing there instead of holding a copy saved copying every item of a
/// huge file once more; equal texts are still one id, so an edit
/// elsewhere leaves the item's queries alone.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, salsa::SalsaValue)]
pub enum ItemSource<'db> {
    Text(ItemText<'db>),
    Palette(usize),
}

impl<'db> RulesItem<'db> {
    /// The item's tree, with spans relative to its start.
    pub fn item(self, db: &'db dyn Db) -> &'db Item {
        match self.source(db) {
            ItemSource::Text(t) => &parsed_item(db, t).0,
            ItemSource::Palette(k) => &parsed_rules(db, self.file(db)).items[k].item,
        }
    }
}

fn item_key(item: &Item) -> String {
    match item {
        Item::Domain { .. } => "domain".into(),
        Item::Problem { .. } => "problem".into(),
        Item::Import { target, .. } => match target {
            ImportTarget::Path { path } => format!("import {:?}", path.plain()),
            ImportTarget::Std { module } => format!("import std::{}", module.text),
        },
        Item::Node(n) => format!("node {}", n.name.text),
        Item::Tree(t) => format!("tree {}", t.name.text),
        Item::Table(t) => format!("table {}", t.name.text),
        Item::Rule(r) => {
            let params: Vec<String> = r
                .pattern
                .params
                .iter()
                .map(|p| p.var.text.clone())
                .collect();
            format!("rule {} {}", r.pattern.name_key(), params.join(" "))
        }
        Item::Plan { .. } => "plan".into(),
        Item::Error { .. } => "error".into(),
    }
}

/// The file's items as tracked structs. Items with the same head (many
/// rules for one action) get keys made distinct by their occurrence:
/// salsa finds a tracked struct by the hash of its key, so equal keys
/// would all land in one bucket and make this quadratic in them.
#[salsa::tracked(returns(ref))]
pub fn rules_items(db: &dyn Db, file: SourceFile) -> Vec<RulesItem<'_>> {
    let mut seen: std::collections::HashMap<String, u32> = std::collections::HashMap::new();
    let parsed = parsed_file(db, file);
    parsed
        .rules
        .items
        .iter()
        .zip(&parsed.texts)
        .enumerate()
        .map(|(k, (n, text))| {
            let mut key = item_key(&n.item);
            let count = seen.entry(key.clone()).or_insert(0);
            if *count > 0 {
                key = format!("{key} #{count}");
            }
            *count += 1;
            let source = match text {
                Some(t) => ItemSource::Text(*t),
                None => ItemSource::Palette(k),
            };
            RulesItem::new(db, file, key, source, n.offset)
        })
        .collect()
}

/// Resolves a path written in a rules file (relative to that file).
pub(crate) fn resolve(db: &dyn Db, from: SourceFile, written: &str) -> Option<SourceFile> {
    let path = from.path(db).sibling(written)?;
    db.workspace().files(db).get(&path).copied()
}

/// The path a rules file gives for its domain (or problem), as written.
pub fn declared_path(db: &dyn Db, file: SourceFile, problem: bool) -> Option<(String, Span, u32)> {
    parsed_rules(db, file)
        .items
        .iter()
        .find_map(|n| match &*n.item {
            Item::Domain { path, span } if !problem => path.plain().map(|p| (p, *span, n.offset)),
            Item::Problem { path, span } if problem => path.plain().map(|p| (p, *span, n.offset)),
            _ => None,
        })
}

#[salsa::tracked(returns(copy))]
pub fn domain_file(db: &dyn Db, rules: SourceFile) -> Option<SourceFile> {
    let (path, _, _) = declared_path(db, rules, false)?;
    resolve(db, rules, &path)
}

#[salsa::tracked(returns(copy))]
pub fn problem_file(db: &dyn Db, rules: SourceFile) -> Option<SourceFile> {
    let (path, _, _) = declared_path(db, rules, true)?;
    resolve(db, rules, &path)
}

/// A PDDL domain parsed and checked.
#[derive(Clone, Debug, PartialEq)]
pub struct CheckedDomain {
    pub domain: Option<Domain>,
    pub index: DomainIndex,
    pub diagnostics: Vec<Diagnostic>,
}

#[salsa::tracked(returns(ref))]
pub fn checked_domain(db: &dyn Db, file: SourceFile) -> CheckedDomain {
    let u = domain_unit_from(file.text(db), file_id(db, file));
    CheckedDomain {
        domain: u.domain,
        index: u.index,
        diagnostics: u.diagnostics,
    }
}

#[derive(Clone, Debug, PartialEq)]
pub struct CheckedProblem {
    pub problem: Option<Problem>,
    pub index: ProblemIndex,
    pub diagnostics: Vec<Diagnostic>,
}

/// A problem checked against a domain. (Inputs are salsa structs, so the
/// pair is interned.)
#[salsa::interned(debug)]
pub struct ProblemOf<'db> {
    #[returns(copy)]
    pub problem: SourceFile,
    #[returns(copy)]
    pub domain: SourceFile,
}

#[salsa::tracked(returns(ref))]
pub fn checked_problem<'db>(db: &'db dyn Db, pair: ProblemOf<'db>) -> CheckedProblem {
    let d = checked_domain(db, pair.domain(db));
    let u = problem_unit_from(
        pair.problem(db).text(db),
        file_id(db, pair.problem(db)),
        d.domain.as_ref(),
        &d.index,
    );
    CheckedProblem {
        problem: u.problem,
        index: u.index,
        diagnostics: u.diagnostics,
    }
}

/// A rules file and every file it imports, transitively, in order; import
/// errors with absolute spans. Iterative, so import cycles are harmless.
#[salsa::tracked(returns(ref))]
pub fn import_closure(db: &dyn Db, file: SourceFile) -> (Vec<SourceFile>, Vec<Diagnostic>) {
    let mut order = vec![file];
    let mut diags = Vec::new();
    let mut i = 0;
    while i < order.len() {
        let f = order[i];
        i += 1;
        for n in &parsed_rules(db, f).items {
            let Item::Import { target, span } = &*n.item else {
                continue;
            };
            let found = match target {
                ImportTarget::Std { module } => db
                    .workspace()
                    .files(db)
                    .get(&FilePath::std(&module.text))
                    .copied(),
                ImportTarget::Path { path } => path.plain().and_then(|p| resolve(db, f, &p)),
            };
            match found {
                Some(g) if !order.contains(&g) => order.push(g),
                Some(_) => {}
                None if f == file => {
                    let (what, hint) = match target {
                        ImportTarget::Std { module } => (
                            format!("there is no stdlib module `std::{}`", module.text),
                            format!(
                                "the stdlib modules are {}",
                                STDLIB
                                    .iter()
                                    .map(|(n, _)| format!("`std::{n}`"))
                                    .collect::<Vec<_>>()
                                    .join(", ")
                            ),
                        ),
                        ImportTarget::Path { path } => (
                            format!("cannot find `{}`", path.plain().unwrap_or_default()),
                            "import paths are relative to the importing file".to_owned(),
                        ),
                    };
                    let d = Diagnostic::error(codes::R_IMPORT, *span, what).with_hint(hint);
                    diags.push(shift(d, file_id(db, file), n.offset));
                }
                None => {}
            }
        }
    }
    (order, diags)
}

/// Declarations visible in a rules file: its own first, then its imports'.
#[salsa::tracked(returns(ref))]
pub fn declarations(db: &dyn Db, file: SourceFile) -> Decls {
    let mut decls = Decls::default();
    for f in &import_closure(db, file).0 {
        decls.add_items(&parsed_rules(db, *f).items);
    }
    decls
}

/// The domain's action names indexed for matching patterns.
#[salsa::tracked(returns(ref))]
pub fn action_index(db: &dyn Db, domain: SourceFile) -> ActionIndex {
    match &checked_domain(db, domain).domain {
        Some(d) => ActionIndex::new(d),
        None => ActionIndex::default(),
    }
}

/// The PDDL side a rules file's items are checked against: its domain
/// (when it can be read) and problem.
pub fn domain_ctx(db: &dyn Db, file: SourceFile) -> Option<DomainCtx<'_>> {
    let domain = domain_file(db, file)?;
    let cd = checked_domain(db, domain);
    let problem =
        problem_file(db, file).map(|p| checked_problem(db, ProblemOf::new(db, p, domain)));
    Some(DomainCtx {
        domain: cd.domain.as_ref()?,
        index: &cd.index,
        problem: problem.map(|p| &p.index),
        actions: action_index(db, domain),
    })
}

/// Diagnostics of one item, relative to its start. Reads only the item's
/// tree, the declarations and the PDDL files, so edits elsewhere in the file
/// leave it alone.
#[salsa::tracked(returns(ref))]
pub fn item_diagnostics<'db>(db: &'db dyn Db, item: RulesItem<'db>) -> Vec<Diagnostic> {
    let file = item.file(db);
    let decls = declarations(db, file);
    check_item(
        item.item(db),
        decls,
        domain_ctx(db, file),
        file_id(db, file),
    )
}

/// A rule's variables with the types the checker gives them (empty for
/// items that are no rules): what the language server shows for a
/// `?variable` in hovers, completions and inlay hints.
#[salsa::tracked(returns(ref))]
pub fn rule_var_types<'db>(db: &'db dyn Db, item: RulesItem<'db>) -> Vec<VarTypes> {
    let Item::Rule(r) = item.item(db) else {
        return Vec::new();
    };
    let file = item.file(db);
    crate::rules::check::rule_var_types(r, declarations(db, file), domain_ctx(db, file))
}

/// What the file-level checks need of an item's head (nothing of a body).
#[salsa::tracked(returns(ref))]
pub fn item_head<'db>(db: &'db dyn Db, item: RulesItem<'db>) -> ItemHead {
    file_checks::head(item.item(db))
}

/// The names an item uses, for R014.
#[salsa::tracked(returns(ref))]
pub fn item_uses<'db>(db: &'db dyn Db, item: RulesItem<'db>) -> ItemUses {
    file_checks::uses(item.item(db))
}

/// The actions a rule can match, for R012 and R013 (`None` for items that
/// are no rules, or without a domain).
#[salsa::tracked(returns(ref))]
pub fn rule_facts<'db>(db: &'db dyn Db, item: RulesItem<'db>) -> Option<RuleFacts> {
    let Item::Rule(r) = item.item(db) else {
        return None;
    };
    let file = item.file(db);
    let ctx = domain_ctx(db, file)?;
    Some(file_checks::rule_facts(r, declarations(db, file), ctx))
}

/// The heads of a file's items, in order.
#[salsa::tracked(returns(ref))]
pub fn item_heads(db: &dyn Db, file: SourceFile) -> Vec<ItemHead> {
    rules_items(db, file)
        .iter()
        .map(|i| item_head(db, *i).clone())
        .collect()
}

/// One `domain`, one `plan`, names declared once.
#[salsa::tracked(returns(ref))]
pub fn file_structure(db: &dyn Db, file: SourceFile) -> Vec<Finding> {
    file_checks::structure(item_heads(db, file))
}

/// R012 and R013 over the file's rules.
#[salsa::tracked(returns(ref))]
pub fn file_coverage(db: &dyn Db, file: SourceFile) -> Vec<Finding> {
    let Some(domain) = domain_file(db, file) else {
        return Vec::new();
    };
    let Some(d) = &checked_domain(db, domain).domain else {
        return Vec::new();
    };
    let items = rules_items(db, file);
    let facts: Vec<(usize, &RuleFacts)> = items
        .iter()
        .enumerate()
        .filter_map(|(k, i)| rule_facts(db, *i).as_ref().map(|f| (k, f)))
        .collect();
    // A file with no rule, nor an import with one, is a file being started
    // (unless an import could not be read: it may have rules).
    let no_rules = facts.is_empty()
        && !d.actions.is_empty()
        && import_closure(db, file).1.is_empty()
        && import_closure(db, file).0.iter().all(|f| {
            !parsed_rules(db, *f)
                .items
                .iter()
                .any(|n| matches!(&*n.item, Item::Rule(_)))
        });
    if no_rules {
        return vec![Finding::NoRules {
            actions: d.actions.len(),
            file_name: file.path(db).file_name().unwrap_or("FILE").to_owned(),
        }];
    }
    file_checks::coverage(&facts, d.actions.len())
}

/// R014 over the file's declarations.
#[salsa::tracked(returns(ref))]
pub fn file_unused(db: &dyn Db, file: SourceFile) -> Vec<Finding> {
    let items = rules_items(db, file);
    let uses: Vec<&ItemUses> = items.iter().map(|i| item_uses(db, *i)).collect();
    file_checks::unused(item_heads(db, file), &uses)
}

/// Every diagnostic of a rules file itself (not of its PDDL files), with
/// absolute spans.
#[salsa::tracked(returns(ref))]
pub fn rules_diagnostics(db: &dyn Db, file: SourceFile) -> Vec<Diagnostic> {
    let id = file_id(db, file);
    let parsed = parsed_rules(db, file);
    let mut out = parsed.diagnostics.clone();
    out.extend(import_closure(db, file).1.iter().cloned());
    // A palette's problems are reported with the file that imports it.
    for &f in import_closure(db, file).0.iter().skip(1) {
        if is_palette(f.path(db)) {
            out.extend(parsed_rules(db, f).diagnostics.iter().cloned());
        }
    }
    for item in rules_items(db, file) {
        let offset = item.offset(db);
        out.extend(
            item_diagnostics(db, *item)
                .iter()
                .cloned()
                .map(|d| shift(d, id, offset)),
        );
    }
    let domain = domain_file(db, file);
    if let Some((path, span, offset)) = declared_path(db, file, false) {
        if domain.is_none() {
            out.push(shift(
                Diagnostic::error(
                    codes::R_NO_DOMAIN,
                    span,
                    format!("cannot find the domain file `{path}`"),
                )
                .with_hint("the path is relative to this rules file"),
                id,
                offset,
            ));
        } else if let Some(d) = domain {
            let errors = checked_domain(db, d)
                .diagnostics
                .iter()
                .filter(|d| d.is_error())
                .count();
            if errors > 0 {
                out.push(shift(
                    Diagnostic::error(codes::R_NO_DOMAIN, span, format!("the domain `{path}` has {errors} error{}; rules are checked against what could be read", if errors == 1 { "" } else { "s" })),
                    id,
                    offset,
                ));
            }
        }
    }
    if let Some((path, span, offset)) = declared_path(db, file, true) {
        if problem_file(db, file).is_none() {
            out.push(shift(
                Diagnostic::error(
                    codes::R_NO_DOMAIN,
                    span,
                    format!("cannot find the problem file `{path}`"),
                ),
                id,
                offset,
            ));
        }
    }
    let heads = item_heads(db, file);
    let offsets: Vec<u32> = rules_items(db, file).iter().map(|i| i.offset(db)).collect();
    let d = domain.and_then(|d| checked_domain(db, d).domain.as_ref());
    for f in file_structure(db, file)
        .iter()
        .chain(file_coverage(db, file))
        .chain(file_unused(db, file))
    {
        out.extend(file_checks::render(f, heads, &offsets, d, id));
    }
    out.sort_by_key(|d| (d.span.file != id, d.span.start));
    out
}

/// The items of a parsed rules file (own items only).
pub fn own_items(db: &dyn Db, file: SourceFile) -> &[ItemNode] {
    &parsed_rules(db, file).items
}

/// The PDDL domain and problem of a compile job, checked, ready for a knowledge base or a validator.
pub struct JobWorld<'db> {
    pub domain: &'db btc_pddl::Domain,
    pub dix: &'db btc_pddl::DomainIndex,
    pub problem: &'db btc_pddl::Problem,
    pub pix: &'db btc_pddl::ProblemIndex,
}

impl<'db> JobWorld<'db> {
    /// The world of the job's domain and problem, ready for evaluation.
    pub fn world(&self) -> Result<btc_pddl::state::World, String> {
        btc_pddl::state::World::of_checked(self.domain, self.dix, self.problem, self.pix)
    }

    /// `None` when the job has no usable domain or problem.
    pub fn of(db: &'db Database, job: CompileJob) -> Option<JobWorld<'db>> {
        let d = job_domain(db, job)?;
        let p = job_problem(db, job)?;
        let cd = checked_domain(db, d);
        let cp = checked_problem(db, ProblemOf::new(db, p, d));
        Some(JobWorld {
            domain: cd.domain.as_ref()?,
            dix: &cd.index,
            problem: cp.problem.as_ref()?,
            pix: &cp.index,
        })
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    /// Loads a file of the repository under its repository-relative path.
    pub(crate) fn load(db: &mut Database, path: &str) -> SourceFile {
        let full = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("..")
            .join(path);
        let text = std::fs::read_to_string(&full).unwrap();
        db.set_file(path, text)
    }

    fn errors(db: &Database, f: SourceFile) -> Vec<String> {
        let sources = db.sources();
        rules_diagnostics(db, f)
            .iter()
            .map(|d| btc_pddl::render::to_short(d, &sources))
            .collect()
    }

    /// Rendering diagnostics copies the files they point into (spans,
    /// labels, fixes) and no other: a long plan is not copied for nothing.
    #[test]
    fn sources_for_diagnostics_hold_the_files_they_point_into() {
        use btc_pddl::diagnostic::Fix;
        let mut db = Database::new();
        let mut files = Vec::new();
        for p in ["a.pddl", "b.pddl", "c.btrules", "plan.txt"] {
            let f = db.set_file(p, format!("text of {p}"));
            files.push(file_id(&db, f));
        }
        let mut d = Diagnostic::error(codes::INVALID_TOKEN, Span::new(files[0], 0, 1), "here")
            .with_label(Span::new(files[1], 0, 1), "and there");
        d.fixes = Box::new([Fix {
            title: "fix".into(),
            span: Span::new(files[2], 0, 1),
            replacement: String::new(),
        }]);
        let kept: Vec<FileId> = db.sources_for(&[d]).iter().map(|(id, _)| id).collect();
        assert_eq!(kept, files[..3]);
        assert_eq!(db.sources_for(&[]).iter().count(), 0);
        assert!(db.sources().iter().any(|(id, _)| id == files[3]));
    }

    #[test]
    fn the_design_examples_check_clean() {
        for dir in ["examples/ariac", "examples/p3_assembler"] {
            let mut db = Database::new();
            load(&mut db, &format!("{dir}/domain.pddl"));
            load(&mut db, &format!("{dir}/problem.pddl"));
            let rules = load(&mut db, &format!("{dir}/rules.btrules"));
            assert_eq!(errors(&db, rules), Vec::<String>::new(), "{dir}");
        }
    }

    /// A file's items are its items' parses, not copies of them (copying
    /// every item of a huge file on each edit was a large part of the
    /// edit's time): before and after an edit, each item of the parsed
    /// file is the allocation its `parsed_item` memo holds.
    #[test]
    fn the_parsed_file_shares_its_items_with_their_parses() {
        let mut db = Database::new();
        load(&mut db, "examples/ariac/domain.pddl");
        let f = load(&mut db, "lang/tests/fixtures/large.btrules");
        let shared = |db: &Database| {
            let parsed = parsed_file(db, f);
            assert!(parsed.rules.items.len() > 700);
            for (n, t) in parsed.rules.items.iter().zip(&parsed.texts) {
                let t = t.expect("a rules file's items have texts");
                assert!(Arc::ptr_eq(&n.item, &parsed_item(db, t).0));
            }
            for i in rules_items(db, f) {
                let ItemSource::Text(t) = i.source(db) else {
                    panic!("not a palette")
                };
                assert!(std::ptr::eq(i.item(db), &*parsed_item(db, t).0));
            }
        };
        shared(&db);
        let first = parsed_rules(&db, f).items[5].item.clone();
        let text = format!("// a comment first\n{}", f.text(&db));
        db.set_file(&f.path(&db).clone(), text);
        shared(&db);
        // The items the edit left alone are the same allocations as before.
        assert!(Arc::ptr_eq(&first, &parsed_rules(&db, f).items[5].item));
    }

    #[test]
    fn editing_one_rule_rechecks_only_that_rule() {
        let mut db = Database::new();
        load(&mut db, "examples/ariac/domain.pddl");
        let f = load(&mut db, "lang/tests/fixtures/large.btrules");
        let items = rules_items(&db, f).len();
        assert!(items > 700);
        assert!(
            errors(&db, f).iter().all(|e| e.contains("R013")),
            "{:?}",
            &errors(&db, f)[..3]
        );
        db.start_logging();
        // Change one rule in the middle, and the text's length with it.
        let text = f.text(&db).replacen(
            "retry(3) MoveTo(robot: ?r, target: ?b)",
            "retry(30) MoveTo(robot: ?r, target: ?destination)",
            1,
        );
        db.set_file(&f.path(&db).clone(), text);
        let after = errors(&db, f);
        let log = db.take_log();
        let rechecked = log
            .iter()
            .filter(|l| l.starts_with("item_diagnostics"))
            .count();
        assert_eq!(rechecked, 1, "{log:#?}");
        let reparsed = log.iter().filter(|l| l.starts_with("parsed_item")).count();
        assert_eq!(
            reparsed, 1,
            "only the edited item is parsed again: {log:#?}"
        );
        // The file-level checks read summaries the edit left equal: they
        // do not run again over every rule.
        for query in [
            "file_coverage",
            "file_unused",
            "file_structure",
            "item_heads",
        ] {
            assert!(
                !log.iter().any(|l| l.starts_with(query)),
                "{query} ran again: {log:#?}"
            );
        }
        let summarized = log.iter().filter(|l| l.starts_with("rule_facts")).count();
        assert_eq!(summarized, 1, "{log:#?}");
        assert_eq!(after.len(), 1, "{after:?}");
        assert!(
            after[0].ends_with(":27:45: error[R006]: `?destination` is not bound here"),
            "{after:?}"
        );
    }

    #[test]
    fn a_new_rule_reruns_coverage_once() {
        let mut db = Database::new();
        load(&mut db, "examples/ariac/domain.pddl");
        let f = load(&mut db, "lang/tests/fixtures/large.btrules");
        let before = errors(&db, f).len();
        db.start_logging();
        let text = format!(
            "{}\nrule (flip ?robot ?p ?c) {{ Flip(robot: ?robot, part: ?p, container: ?c) }}\n",
            f.text(&db)
        );
        db.set_file(&f.path(&db).clone(), text);
        let after = errors(&db, f);
        let log = db.take_log();
        let count = |q: &str| log.iter().filter(|l| l.starts_with(q)).count();
        assert_eq!(count("file_coverage"), 1, "{log:#?}");
        assert_eq!(count("rule_facts"), 1, "only the new rule: {log:#?}");
        assert_eq!(after.len(), before + 1, "{after:?}");
        assert!(after.iter().any(|e| e.contains("R013")));
    }

    #[test]
    fn an_unknown_stdlib_module_and_import_cycles() {
        let mut db = Database::new();
        db.set_file(
            "a.btrules",
            "import \"b.btrules\"\nimport std::nope\naction A()\n".into(),
        );
        db.set_file("b.btrules", "import \"a.btrules\"\naction B()\n".into());
        let a = db.file("a.btrules").unwrap();
        let codes: Vec<&str> = rules_diagnostics(&db, a).iter().map(|d| d.code).collect();
        assert!(codes.contains(&"R018"));
        assert!(declarations(&db, a).nodes.contains_key("B"));
    }
}

/// What `btc compile` is asked: a rules file and a plan, with the problem
/// and domain when they are not named in the rules file.
#[salsa::input(debug)]
pub struct CompileJob {
    #[returns(copy)]
    pub rules: SourceFile,
    #[returns(copy)]
    pub plan: SourceFile,
    #[returns(copy)]
    pub problem: Option<SourceFile>,
    #[returns(copy)]
    pub domain: Option<SourceFile>,
}

/// The domain a job uses: given explicitly, or named by the rules file.
pub fn job_domain(db: &dyn Db, job: CompileJob) -> Option<SourceFile> {
    job.domain(db).or_else(|| domain_file(db, job.rules(db)))
}

pub fn job_problem(db: &dyn Db, job: CompileJob) -> Option<SourceFile> {
    job.problem(db).or_else(|| problem_file(db, job.rules(db)))
}

/// Every diagnostic a compile job raises before lowering (rules, imports,
/// domain, problem, plan), in the order of [`crate::project::job_report`].
#[salsa::tracked(returns(ref))]
pub fn job_diagnostics(db: &dyn Db, job: CompileJob) -> Vec<Diagnostic> {
    crate::project::flatten(crate::project::job_report(db, job))
}

#[derive(Clone, Debug, PartialEq)]
pub struct TypedPlan {
    pub plan: btc_pddl::plan::Plan,
    pub steps: Vec<btc_pddl::plan::GroundStep>,
    pub diagnostics: Vec<Diagnostic>,
}

#[salsa::tracked(returns(ref))]
pub fn typed_plan(db: &dyn Db, job: CompileJob) -> TypedPlan {
    let pf = job.plan(db);
    let (plan, mut diagnostics) = btc_pddl::plan::parse_plan(pf.text(db), file_id(db, pf));
    let mut steps = Vec::new();
    if let (Some(d), Some(p)) = (job_domain(db, job), job_problem(db, job)) {
        let cd = checked_domain(db, d);
        let cp = checked_problem(db, ProblemOf::new(db, p, d));
        if let Some(domain) = &cd.domain {
            let (s, diags) = btc_pddl::plan::type_plan(&plan, domain, &cd.index, &cp.index);
            steps = s;
            diagnostics.extend(diags);
        }
    }
    TypedPlan {
        plan,
        steps,
        diagnostics,
    }
}

/// Compiles a job to the tree IR, or returns why not (errors only; see
/// [`job_diagnostics`] for warnings).
///
/// The IR is shared so a caller can keep it and drop the database: a long
/// plan's text, parse and replay are half of what a compile holds, and an
/// emitter needs none of them (`btc compile` frees them before it writes).
#[salsa::tracked(returns(ref))]
pub fn compile(db: &dyn Db, job: CompileJob) -> Result<Arc<btc_ir::TreeIr>, Vec<Diagnostic>> {
    let diags = job_diagnostics(db, job);
    if btc_pddl::diagnostic::has_errors(diags) {
        return Err(diags.iter().filter(|d| d.is_error()).cloned().collect());
    }
    let rules = job.rules(db);
    let (Some(d), Some(p)) = (job_domain(db, job), job_problem(db, job)) else {
        return Err(Vec::new());
    };
    let cd = checked_domain(db, d);
    let cp = checked_problem(db, ProblemOf::new(db, p, d));
    let (Some(domain), Some(problem)) = (&cd.domain, &cp.problem) else {
        return Err(Vec::new());
    };
    let tp = typed_plan(db, job);
    let mut all_rules = Vec::new();
    let mut plan_template = None;
    for f in &import_closure(db, rules).0 {
        for n in &parsed_rules(db, *f).items {
            match &*n.item {
                Item::Rule(r) => all_rules.push(r),
                Item::Plan { body, .. } if *f == rules && plan_template.is_none() => {
                    plan_template = Some(body.as_slice())
                }
                _ => {}
            }
        }
    }
    let input = crate::lower::LowerInput {
        decls: declarations(db, rules),
        rules: all_rules,
        plan_template,
        domain,
        dix: &cd.index,
        problem,
        pix: &cp.index,
        plan: &tp.plan,
        steps: &tp.steps,
        domain_path: d.path(db).to_string(),
        problem_path: p.path(db).to_string(),
        plan_path: job.plan(db).path(db).to_string(),
        rules_path: rules.path(db).to_string(),
    };
    crate::lower::lower(&input).map(Arc::new)
}

#[cfg(test)]
mod compile_tests {
    use super::*;

    /// Loads an example folder (rules, domain, problem, the first plan).
    pub fn example_job(db: &mut Database, dir: &str) -> CompileJob {
        let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
        let mut plan = None;
        let mut rules = None;
        for e in std::fs::read_dir(root.join(dir)).unwrap() {
            let p = e.unwrap().path();
            let name = p.file_name().unwrap().to_string_lossy().into_owned();
            if !p.is_file() {
                continue;
            }
            let f = db.set_file(
                &format!("{dir}/{name}"),
                std::fs::read_to_string(&p).unwrap(),
            );
            if name.starts_with("plan.") && plan.is_none() {
                plan = Some(f);
            }
            if name == "rules.btrules" {
                rules = Some(f);
            }
        }
        let problem = db.file(&format!("{dir}/problem.pddl"));
        CompileJob::new(db, rules.unwrap(), plan.unwrap(), problem, None)
    }

    #[test]
    fn the_examples_compile() {
        for dir in ["examples/ariac", "examples/p3_assembler"] {
            let mut db = Database::new();
            let job = example_job(&mut db, dir);
            let ir = compile(&db, job)
                .as_ref()
                .unwrap_or_else(|e| panic!("{dir}: {e:#?}"));
            assert!(!ir.steps.is_empty());
            if std::env::var_os("BTC_PRINT_IR").is_some() {
                println!("{}", serde_json::to_string_pretty(ir).unwrap());
            }
        }
    }

    /// The compiled IR outlives the database without a copy: `btc
    /// compile` frees the database (a long plan's text, parse and replay)
    /// before it emits.
    #[test]
    fn the_ir_outlives_its_database() {
        let mut db = Database::new();
        let job = example_job(&mut db, "examples/p3_assembler");
        let ir = compile(&db, job).as_ref().expect("compiles").clone();
        let steps = ir.steps.len();
        drop(db);
        assert_eq!(Arc::strong_count(&ir), 1);
        assert_eq!(ir.steps.len(), steps);
    }

    /// A long plan repeats few ground actions: lowering grounds each once
    /// and its steps share the result, so the IR's logic grows with the
    /// distinct ground actions, not with the steps.
    #[test]
    fn repeated_ground_actions_share_their_logic() {
        use std::collections::{HashMap, HashSet};
        use std::sync::Arc;
        let mut db = Database::new();
        let job = example_job(&mut db, "examples/p3_assembler");
        job.plan(&db)
            .set_text(&mut db)
            .to(btc_testkit::long_p3_plan(600));
        let ir = compile(&db, job).as_ref().expect("the long plan compiles");
        assert_eq!(ir.steps.len(), 600);
        fn same<T>(a: &Option<Arc<T>>, b: &Option<Arc<T>>) -> bool {
            match (a, b) {
                (Some(a), Some(b)) => Arc::ptr_eq(a, b),
                (None, None) => true,
                _ => false,
            }
        }
        let mut first: HashMap<(&str, &[String]), &btc_ir::StepInfo> = HashMap::new();
        let mut effects = HashSet::new();
        for s in &ir.steps {
            let f = first
                .entry((&*s.logic.action, s.logic.args.as_ref()))
                .or_insert(s);
            assert!(
                same(&f.logic.pre_start, &s.logic.pre_start)
                    && same(&f.logic.pre_over_all, &s.logic.pre_over_all)
            );
            assert!(
                same(&f.logic.pre_end, &s.logic.pre_end)
                    && same(&f.logic.eff_start, &s.logic.eff_start)
            );
            assert!(same(&f.logic.eff_end, &s.logic.eff_end));
            // The step's whole logic is one value.
            assert!(Arc::ptr_eq(&f.logic, &s.logic));
            effects.extend(s.logic.eff_end.as_ref().map(Arc::as_ptr));
        }
        // Every P3 action but WAIT changes something at its end.
        assert_eq!(effects.len(), first.len() - 1);
        // And their nodes below the step boundary are one node each.
        let mut children = HashSet::new();
        ir.root.walk(&mut |n| {
            if let btc_ir::Node::Step { child, .. } = n {
                children.insert(Arc::as_ptr(child));
            }
        });
        let skipped: HashSet<_> = ir
            .steps
            .iter()
            .filter(|s| s.skipped)
            .map(|s| (&*s.logic.action, s.logic.args.as_ref()))
            .collect();
        assert_eq!(children.len(), first.len() - skipped.len());
        assert!(first.len() < 20, "{} distinct ground actions", first.len());
    }
}

#[cfg(test)]
mod parse_ahead_tests {
    use super::*;

    /// A large file's items parsed ahead on two threads are the items the
    /// file's parse then reads (none parsed again), equal to a parse on one.
    #[test]
    fn items_parsed_ahead_are_not_parsed_again() {
        let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
        let fixture = std::fs::read_to_string(root.join("tests/fixtures/large.btrules"))
            .expect("the large fixture");
        // Copies renamed, so that their items' texts differ.
        let text: String = (0..4)
            .map(|k| fixture.replace("\"move ", &format!("\"m{k} ")))
            .collect();
        let mut db = Database::new();
        let f = db.set_file("/w/huge.btrules", text.clone());
        db.start_logging();
        parse_ahead(&db, f);
        let ahead = db
            .take_log()
            .iter()
            .filter(|l| l.starts_with("parsed_item"))
            .count();
        assert!(ahead > 2_000, "{ahead} items parsed ahead");
        let parsed = parsed_rules(&db, f);
        let log = db.take_log();
        assert!(
            !log.iter().any(|l| l.starts_with("parsed_item")),
            "{log:#?}"
        );
        assert_eq!(
            *parsed,
            crate::rules::parse::parse_rules(&text, file_id(&db, f))
        );
    }
}
