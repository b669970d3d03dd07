//! Document and workspace symbols.

use crate::analysis::{shift, Analysis, Place};
use btc_lang::rules::ast::{ImportTarget, Item};
use btc_lang::rules::name::contains_folded;
use btc_pddl::source::Span;
use tower_lsp::lsp_types::{DocumentSymbol, SymbolInformation, SymbolKind};

/// One symbol of a rules file: name, kind, the whole item and its name.
pub struct ItemSymbol {
    pub name: String,
    pub detail: Option<String>,
    pub kind: SymbolKind,
    pub span: Span,
    pub name_span: Span,
}

/// The symbols of a file's items, in order.
pub fn item_symbols(a: &Analysis) -> Vec<ItemSymbol> {
    let mut out = Vec::new();
    for n in a.items {
        let o = n.offset;
        let whole = shift(n.item.span(), o);
        let (name, detail, kind, name_span) = match &*n.item {
            Item::Domain { path, span } => (
                format!("domain {}", path.plain().unwrap_or_default()),
                None,
                SymbolKind::FILE,
                *span,
            ),
            Item::Problem { path, span } => (
                format!("problem {}", path.plain().unwrap_or_default()),
                None,
                SymbolKind::FILE,
                *span,
            ),
            Item::Import { target, span } => (
                match target {
                    ImportTarget::Path { path, .. } => {
                        format!("import {}", path.plain().unwrap_or_default())
                    }
                    ImportTarget::Std { module } => format!("import std::{}", module.text),
                },
                None,
                SymbolKind::MODULE,
                *span,
            ),
            Item::Node(d) => (
                d.name.text.clone(),
                Some(
                    d.ports
                        .iter()
                        .map(|p| format!("{}: {}", p.name.text, p.ty.text))
                        .collect::<Vec<_>>()
                        .join(", "),
                ),
                match d.kind {
                    btc_lang::rules::ast::NodeKind::Action => SymbolKind::FUNCTION,
                    btc_lang::rules::ast::NodeKind::Condition => SymbolKind::BOOLEAN,
                },
                d.name.span,
            ),
            Item::Tree(t) => (t.name.text.clone(), None, SymbolKind::CLASS, t.name.span),
            Item::Table(t) => (
                t.name.text.clone(),
                Some(format!("{} entries", t.entries.len())),
                SymbolKind::ENUM,
                t.name.span,
            ),
            Item::Rule(r) => (
                format!(
                    "rule ({}{})",
                    r.pattern.name_text(),
                    r.pattern
                        .params
                        .iter()
                        .map(|p| if p.optional {
                            format!(" [?{}]", p.var.text)
                        } else {
                            format!(" ?{}", p.var.text)
                        })
                        .collect::<String>()
                ),
                None,
                SymbolKind::METHOD,
                r.pattern.name_span(),
            ),
            Item::Plan { span, .. } => ("plan".to_owned(), None, SymbolKind::NAMESPACE, *span),
            Item::Error { .. } => continue,
        };
        let name_span = shift(name_span, o);
        out.push(ItemSymbol {
            name,
            detail,
            kind,
            span: whole,
            // The selection range must lie inside the whole range.
            name_span: if name_span.start >= whole.start && name_span.end <= whole.end {
                name_span
            } else {
                whole
            },
        });
    }
    out
}

#[allow(deprecated)] // `deprecated` is a required field of the struct
pub fn document_symbols(a: &Analysis) -> Vec<DocumentSymbol> {
    item_symbols(a)
        .into_iter()
        .map(|s| DocumentSymbol {
            name: s.name,
            detail: s.detail,
            kind: s.kind,
            tags: None,
            deprecated: None,
            range: a.range(s.span),
            selection_range: a.range(s.name_span),
            children: None,
        })
        .collect()
}

/// Symbols of every rules file in the workspace whose name contains
/// `query` (case-insensitively; all for an empty query).
#[allow(deprecated)]
pub fn workspace_symbols(ws: &crate::workspace::Workspace, query: &str) -> Vec<SymbolInformation> {
    let mut out = Vec::new();
    for f in ws.all_rules() {
        let Some(a) = Analysis::new(ws, f.path(&ws.db)) else {
            continue;
        };
        for s in item_symbols(&a) {
            if !contains_folded(&s.name, query) {
                continue;
            }
            let Some(location) = a.location(&Place {
                file: f,
                span: s.name_span,
            }) else {
                continue;
            };
            out.push(SymbolInformation {
                name: s.name,
                kind: s.kind,
                tags: None,
                deprecated: None,
                location,
                container_name: None,
            });
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Symbols read the parsed items only: the file is not lexed for them
    /// (lexing a huge file again after each edit was a large part of each
    /// symbol request); what needs the tokens still gets them.
    #[test]
    fn document_symbols_do_not_lex_the_file() {
        let (ws, path) = crate::workspace::logging_workspace("action A()\ntree T() { A() }\n");
        let a = Analysis::new(&ws, &path).expect("a rules file");
        assert_eq!(document_symbols(&a).len(), 2);
        let log = ws.db.take_log();
        assert!(
            !log.iter().any(|l| l.starts_with("rules_tokens")),
            "{log:#?}"
        );
        assert!(!crate::highlight::semantic_tokens(&a).is_empty());
        let log = ws.db.take_log();
        assert!(
            log.iter().any(|l| l.starts_with("rules_tokens")),
            "{log:#?}"
        );
    }
}
