//! One rules file seen with everything the editor features need: its text
//! and tokens, its parsed items, the declarations in scope, its domain.

use crate::convert::LineIndex;
use crate::syntax::FileSyntax;
use crate::workspace::Workspace;
use btc_lang::db::{
    action_index, checked_domain, declarations, parsed_rules, rule_var_types, rules_items,
    SourceFile,
};
use btc_lang::path::FilePath;
use btc_lang::resolutions::{item_resolutions, Resolved, Site};
use btc_lang::rules::ast::{Item, ItemNode, Rule};
use btc_lang::rules::check::{matched_actions, Decls};
use btc_pddl::ast::{Action, Domain};
use btc_pddl::source::Span;
use btc_pddl::DomainIndex;
use tower_lsp::lsp_types::{Location, Range, Url};

pub struct Analysis<'a> {
    pub ws: &'a Workspace,
    pub file: SourceFile,
    pub text: &'a str,
    pub items: &'a [ItemNode],
    pub decls: &'a Decls,
    pub domain: Option<(SourceFile, &'a Domain, &'a DomainIndex)>,
    pub syntax: FileSyntax<'a>,
    /// Built on first use, once per request: building one per span made
    /// symbol lists quadratic.
    lines: std::cell::OnceCell<LineIndex<'a>>,
}

/// A place in some file of the workspace.
#[derive(Clone, Debug, PartialEq)]
pub struct Place {
    pub file: SourceFile,
    pub span: Span,
}

impl<'a> Analysis<'a> {
    pub fn new(ws: &'a Workspace, path: &FilePath) -> Option<Analysis<'a>> {
        if !path.is_rules() {
            return None;
        }
        let file = ws.file(path)?;
        let db = &ws.db;
        let text = file.text(db).as_str();
        let items = parsed_rules(db, file).items.as_slice();
        let decls = declarations(db, file);
        let domain = btc_lang::db::domain_file(db, file).and_then(|d| {
            let cd = checked_domain(db, d);
            cd.domain.as_ref().map(|dom| (d, dom, &cd.index))
        });
        Some(Analysis {
            ws,
            file,
            text,
            items,
            decls,
            domain,
            syntax: FileSyntax {
                text,
                items,
                db,
                file,
                tokens: std::cell::OnceCell::new(),
            },
            lines: std::cell::OnceCell::new(),
        })
    }

    pub fn line_index(&self) -> &LineIndex<'a> {
        self.lines.get_or_init(|| LineIndex::new(self.text))
    }

    /// An LSP location of a place (`None` for stdlib files, which have no
    /// file on disk).
    pub fn location(&self, p: &Place) -> Option<Location> {
        let path = p.file.path(&self.ws.db);
        let uri = Url::from_file_path(path.as_path()?).ok()?;
        let range = if p.file == self.file {
            self.line_index().range(p.span)
        } else {
            LineIndex::new(p.file.text(&self.ws.db)).range(p.span)
        };
        Some(Location::new(uri, range))
    }

    pub fn range(&self, span: Span) -> Range {
        self.line_index().range(span)
    }

    /// The rule of item `item`, if it is one.
    pub fn rule(&self, item: usize) -> Option<&'a Rule> {
        match &*self.items.get(item)?.item {
            Item::Rule(r) => Some(r),
            _ => None,
        }
    }

    /// The domain actions a rule's pattern matches.
    pub fn actions_of(&self, r: &Rule) -> Vec<&'a Action> {
        match self.domain {
            Some((f, d, _)) => matched_actions(&r.pattern, d, action_index(&self.ws.db, f))
                .into_iter()
                .map(|(a, _)| a)
                .collect(),
            None => Vec::new(),
        }
    }

    /// The PDDL type(s) of `?var` in rule `item`, as the checker types it
    /// (`btc_lang::db::rule_var_types`): the parameter at its position in
    /// every action the rule's template is checked against.
    pub fn var_types(&self, item: usize, var: &str) -> Vec<String> {
        let Some(it) = rules_items(&self.ws.db, self.file).get(item) else {
            return Vec::new();
        };
        rule_var_types(&self.ws.db, *it)
            .iter()
            .find(|v| v.name == var)
            .map(|v| v.types.clone())
            .unwrap_or_default()
    }

    /// The names the checker resolved at a byte offset (the name under
    /// the cursor, or the one ending at it), with their absolute spans.
    /// Several when one name refers to several things (a pattern that
    /// matches several actions).
    pub fn names_at(&self, offset: usize) -> Vec<(Span, &'a Resolved<'a>)> {
        let o = offset as u32;
        let Some(k) = self.syntax.item_at(o) else {
            return Vec::new();
        };
        let all: Vec<(Span, &'a Resolved<'a>)> = self.names_of(k).collect();
        // Inside a name first; then a name that ends at the cursor.
        let inside: Vec<_> = all
            .iter()
            .filter(|(s, _)| s.start <= o && o < s.end)
            .copied()
            .collect();
        if !inside.is_empty() {
            return inside;
        }
        all.into_iter().filter(|(s, _)| s.end == o).collect()
    }

    /// The resolved names of item `k`, with absolute spans.
    pub fn names_of(&self, k: usize) -> impl Iterator<Item = (Span, &'a Resolved<'a>)> + 'a {
        let db = &self.ws.db;
        let item = rules_items(db, self.file).get(k).copied();
        let offset = self.items.get(k).map_or(0, |n| n.offset);
        item.into_iter()
            .flat_map(move |it| item_resolutions(db, it).iter())
            .map(move |r| (shift(r.span, offset), r))
    }

    /// Where a declaration is, as a place.
    pub fn place(&self, site: Site) -> Place {
        Place {
            file: site.file(&self.ws.db),
            span: site.span(&self.ws.db),
        }
    }

    /// The source text of an item declared in `file` at `span` (item
    /// relative spans already made absolute).
    pub fn source_of(&self, file: SourceFile, span: Span) -> &'a str {
        let text = file.text(&self.ws.db);
        text.get(span.start as usize..span.end as usize)
            .unwrap_or_default()
    }
}

pub fn shift(s: Span, offset: u32) -> Span {
    Span {
        start: s.start + offset,
        end: s.end + offset,
        ..s
    }
}
