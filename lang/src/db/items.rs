//! A rules file cut into items, each item parsed on its own (memoized by
//! its text), and the items as tracked structs.

use super::*;

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
            ImportTarget::Path { path, alias } => match alias {
                Some(a) => format!("import {:?} as {}", path.plain(), a.text),
                None => format!("import {:?}", path.plain()),
            },
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
