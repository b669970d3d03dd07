//! Hover, go-to-definition, find references, highlights and rename: all
//! over the checker's resolutions (`btc_lang::resolutions`); nothing here
//! works out what a name means.

use crate::analysis::{shift, Analysis, Place};
use btc_lang::db::rules_items;
use btc_lang::resolutions::{item_resolutions, Resolved, Site};
use btc_lang::rules::ast::{Item, NodeKind};
use btc_lang::rules::name::Key;
use btc_lang::rules::resolve::Target;
use btc_pddl::source::Span;
use std::collections::HashMap;
use tower_lsp::lsp_types::{
    DocumentHighlight, DocumentHighlightKind, Hover, HoverContents, Location, MarkupContent,
    MarkupKind, TextEdit, Url, WorkspaceEdit,
};

fn code_block(lang: &str, text: &str) -> String {
    format!("```{lang}\n{}\n```", text.trim_end())
}

fn quoted(names: &[String]) -> String {
    names
        .iter()
        .map(|t| format!("`{t}`"))
        .collect::<Vec<_>>()
        .join(" or ")
}

/// The hover text at a byte offset.
pub fn hover(a: &Analysis, offset: usize) -> Option<Hover> {
    let names = a.names_at(offset);
    let Some(&(span, first)) = names.first() else {
        return keyword_hover(a, offset);
    };
    let item = a.syntax.item_at(span.start)?;
    let text = match &first.target {
        Target::Action { .. } => {
            let (dfile, _, _) = a.domain?;
            names
                .iter()
                .filter_map(|(_, r)| r.site)
                .map(|s| {
                    let p = a.place(s);
                    let action = a.domain?.1.actions.iter().find(|x| x.name.span == p.span)?;
                    Some(code_block("pddl", a.source_of(dfile, action.span)))
                })
                .collect::<Option<Vec<_>>>()?
                .join("\n\n")
        }
        Target::Var { name, .. } => match &*a.items[item].item {
            Item::Rule(r) => {
                let types = a.var_types(item, name);
                match r.pattern.params.iter().position(|p| p.var.text == *name) {
                    Some(p) if !types.is_empty() => format!(
                        "`?{name}`: {} (parameter {} of `{}`)",
                        quoted(&types),
                        p + 1,
                        r.pattern.name_text()
                    ),
                    Some(p) => format!("`?{name}`: parameter {} of the rule", p + 1),
                    None => format!("`?{name}`: bound by its quantifier"),
                }
            }
            _ => format!("`?{name}`: bound by its quantifier"),
        },
        Target::Capture { name, .. } => {
            let r = a.rule(item)?;
            let values: Vec<String> = a
                .actions_of(r)
                .iter()
                .filter_map(|act| {
                    btc_lang::rules::matching::match_name(&r.pattern.name, &act.name.name)
                        .and_then(|caps| caps.into_iter().find(|(c, _)| c == name))
                        .map(|(_, v)| format!("`{v}`"))
                })
                .collect();
            if values.is_empty() {
                format!("capture `{name}`")
            } else {
                format!("capture `{name}`: {}", values.join(", "))
            }
        }
        Target::Callable { name } => {
            let place = a.place(first.site?);
            let decl = if let Some(n) = a.decls.nodes.get(name) {
                let kind = match n.kind {
                    NodeKind::Action => "action",
                    NodeKind::Condition => "condition",
                };
                let mut s = format!(
                    "{kind} {}({})",
                    n.name.text,
                    btc_lang::rules::fmt::ports(&n.ports)
                );
                if let Some(f) = &n.formula {
                    let src = a.source_of(
                        place.file,
                        shift(f.span(), place.span.start - n.name.span.start),
                    );
                    s.push_str(&format!(" = {src}"));
                }
                s
            } else {
                let t = a.decls.trees.get(name)?;
                format!(
                    "tree {}({})",
                    t.name.text,
                    btc_lang::rules::fmt::ports(&t.ports)
                )
            };
            let origin = place.file.path(&a.ws.db);
            format!(
                "{}\n\ndeclared in `{}`",
                code_block("btrules", &decl),
                origin
                    .file_name()
                    .map_or_else(|| origin.to_string(), str::to_owned)
            )
        }
        Target::Table { name } => {
            let place = a.place(first.site?);
            let t = a.decls.tables.get(name)?;
            let off = place.span.start - t.name.span.start;
            let entries: Vec<String> = t
                .entries
                .iter()
                .map(|e| {
                    format!(
                        "{}: {}",
                        e.key.text,
                        a.source_of(place.file, shift(e.value.span(), off))
                    )
                })
                .collect();
            code_block(
                "btrules",
                &format!("table {} {{ {} }}", t.name.text, entries.join(", ")),
            )
        }
        Target::Port { owner, name } => {
            let p = a
                .decls
                .ports(owner)?
                .iter()
                .find(|p| p.name.text == *name)?;
            format!(
                "port `{}` of `{owner}`: `{}`{}",
                p.name.text,
                p.ty.text,
                if p.out { " (output)" } else { "" }
            )
        }
        Target::Predicate { .. } => {
            let (dfile, d, _) = a.domain?;
            let at = a.place(first.site?).span;
            let decl = d
                .predicates
                .iter()
                .map(|p| (&p.name, p.span))
                .chain(d.functions.iter().map(|f| (&f.name, f.span)))
                .find(|(n, _)| n.span == at)?;
            code_block("pddl", a.source_of(dfile, decl.1))
        }
        Target::Type { name } => {
            let (_, _, dix) = a.domain?;
            let id = dix.types.id(name)?;
            let parents: Vec<String> = dix
                .types
                .names()
                .filter(|t| *t != name)
                .filter(|t| dix.types.id(t).is_some_and(|p| dix.types.is_subtype(id, p)))
                .map(|t| format!("`{t}`"))
                .collect();
            if parents.is_empty() {
                format!("PDDL type `{name}`")
            } else {
                format!("PDDL type `{name}`, a kind of {}", parents.join(", "))
            }
        }
        Target::BasicType { name } => format!("`{name}`: a basic type"),
        Target::Object { name } => {
            let place = a.place(first.site?);
            let origin = place.file.path(&a.ws.db);
            format!(
                "PDDL object `{name}`, declared in `{}`",
                origin
                    .file_name()
                    .map_or_else(|| origin.to_string(), str::to_owned)
            )
        }
        Target::File { written } => match first.site {
            Some(s) => format!("`{}`", s.file(&a.ws.db).path(&a.ws.db)),
            None => format!("`{written}` is not found"),
        },
        Target::Std { module } => format!("stdlib module `std::{module}`"),
    };
    Some(Hover {
        contents: HoverContents::Markup(MarkupContent {
            kind: MarkupKind::Markdown,
            value: text,
        }),
        range: Some(a.range(span)),
    })
}

/// A node keyword of a template (`retry`, `parallel`...): the vocabulary's
/// summary, shape, BT.CPP element and parameters. Only where the word is a
/// template's keyword: not a port name (`delay: 3`), not in a call's
/// parentheses or a PDDL formula.
fn keyword_hover(a: &Analysis, offset: usize) -> Option<Hover> {
    // The item's tokens are enough: the checks below stop at its braces.
    let item_tokens = a.syntax.item_tokens(offset as u32)?;
    let t = &crate::syntax::Tokens::of(&item_tokens);
    let i = t.at(offset)?;
    let spec = btc_ir::NodeSpec::by_keyword(t.ident(i)?)?;
    if t.punct(i + 1) == Some(":") || t.open_paren(i).is_some() || t.in_pddl(i) {
        return None;
    }
    let item = a.syntax.item_at(t.toks[i].1.start)?;
    if !matches!(*a.items[item].item, Item::Rule(_) | Item::Tree(_)) {
        return None;
    }
    let mut text = format!(
        "{} — {}\n\nBT.CPP `<{}>`",
        spec.shape(),
        spec.summary,
        spec.tag
    );
    for p in spec.params {
        text.push_str(&format!("\n- {}", p.describe()));
    }
    Some(Hover {
        contents: HoverContents::Markup(MarkupContent {
            kind: MarkupKind::Markdown,
            value: text,
        }),
        range: Some(a.range(t.toks[i].1)),
    })
}

/// Where the name at `offset` is declared: one place, or several for a
/// pattern that matches several actions.
pub fn definition(a: &Analysis, offset: usize) -> Vec<Place> {
    let mut out: Vec<Place> = Vec::new();
    for (_, r) in a.names_at(offset) {
        if let Some(s) = r.site {
            let p = a.place(s);
            if !out.contains(&p) {
                out.push(p);
            }
        }
    }
    out
}

/// The name at `offset`, the one whose declaration the others share.
fn site_at<'a>(a: &Analysis<'a>, offset: usize) -> Option<(&'a Resolved<'a>, Site<'a>)> {
    a.names_at(offset)
        .into_iter()
        .find_map(|(_, r)| r.site.map(|s| (r, s)))
}

/// Every place that names the same declaration as the name at `offset`
/// (the declaration included, when it is in a rules file the server
/// knows), in every rules file the server knows; variables and captures
/// only within their item.
pub fn references(a: &Analysis, offset: usize) -> Option<Vec<Place>> {
    let (r, site) = site_at(a, offset)?;
    let db = &a.ws.db;
    let mut out = Vec::new();
    let mut scan = |file, item| {
        let o = btc_lang::db::RulesItem::offset(item, db);
        for other in item_resolutions(db, item) {
            if other.site == Some(site) {
                out.push(Place {
                    file,
                    span: shift(other.span, o),
                });
            }
        }
    };
    match (&r.target, site) {
        (Target::Var { .. } | Target::Capture { .. }, Site::Item { item, .. }) => {
            scan(item.file(db), item)
        }
        _ => {
            for f in a.ws.all_rules() {
                for &item in rules_items(db, f) {
                    scan(f, item);
                }
            }
        }
    }
    // A declaration outside the rules files (the domain) counts too.
    let decl = a.place(site);
    if !out.contains(&decl) && matches!(site, Site::File { .. }) && decl.span.end > 0 {
        out.push(decl);
    }
    out.sort_by_key(|p| (p.file.path(db).clone(), p.span.start));
    out.dedup();
    Some(out)
}

/// The places in this file that name what the name at `offset` names;
/// the declaration is a write, the others reads.
pub fn highlights(a: &Analysis, offset: usize) -> Option<Vec<DocumentHighlight>> {
    let (_, site) = site_at(a, offset)?;
    let decl = a.place(site);
    Some(
        references(a, offset)?
            .into_iter()
            .filter(|p| p.file == a.file)
            .map(|p| DocumentHighlight {
                range: a.range(p.span),
                kind: Some(if p == decl {
                    DocumentHighlightKind::WRITE
                } else {
                    DocumentHighlightKind::READ
                }),
            })
            .collect(),
    )
}

/// Why a rename cannot be done.
#[derive(Debug, PartialEq)]
pub struct RenameError(pub String);

/// The name at `offset` if it can be renamed: its span, or why not.
pub fn prepare_rename(a: &Analysis, offset: usize) -> Result<Span, RenameError> {
    let names = a.names_at(offset);
    let Some((span, r)) = names.first() else {
        return Err(RenameError("nothing to rename here".into()));
    };
    if !r.target.renamable() {
        return Err(RenameError(match r.target {
            Target::Action { .. }
            | Target::Predicate { .. }
            | Target::Type { .. }
            | Target::Object { .. } => {
                "PDDL names cannot be renamed here: they live in the domain or the problem".into()
            }
            _ => "only variables, captures, nodes, trees, tables and ports can be renamed".into(),
        }));
    }
    let Some(site) = r.site else {
        return Err(RenameError("nothing to rename here".into()));
    };
    if a.location(&a.place(site)).is_none() {
        return Err(RenameError(
            "the name is declared in the stdlib, which cannot be edited".into(),
        ));
    }
    Ok(*span)
}

/// The edits that rename the name at `offset` (variables, captures,
/// nodes, trees, tables, ports) to `new_name`, in every file that uses it.
pub fn rename(a: &Analysis, offset: usize, new_name: &str) -> Result<WorkspaceEdit, RenameError> {
    prepare_rename(a, offset)?;
    let bare = new_name.trim_start_matches('?');
    let valid = bare.starts_with(|c: char| c.is_alphabetic() || c == '_')
        && bare
            .chars()
            .all(|c| c.is_alphanumeric() || c == '_' || c == '-');
    if !valid {
        return Err(RenameError(format!("`{new_name}` is not a valid name")));
    }
    let is_var = matches!(
        a.names_at(offset).first().map(|(_, r)| &r.target),
        Some(Target::Var { .. })
    );
    // Variables are folded, like every PDDL name.
    let bare = if is_var {
        Key::new(bare).into_string()
    } else {
        bare.to_owned()
    };
    let places = references(a, offset).unwrap_or_default();
    let mut changes: HashMap<Url, Vec<TextEdit>> = HashMap::new();
    for p in places {
        let Some(Location { uri, range }) = a.location(&p) else {
            return Err(RenameError(
                "the name is used in the stdlib, which cannot be edited".into(),
            ));
        };
        // A tree's port is `name` where declared and `?name` in its body.
        let written = a.source_of(p.file, p.span);
        let replacement = if written.starts_with('?') {
            format!("?{bare}")
        } else {
            bare.clone()
        };
        changes
            .entry(uri)
            .or_default()
            .push(TextEdit::new(range, replacement));
    }
    Ok(WorkspaceEdit::new(changes))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A keyword's hover lexes the item under the cursor, not the file
    /// (a huge file's lex made every such hover cost a tenth of a second),
    /// and its range is still in the file's terms.
    #[test]
    fn keyword_hover_lexes_only_its_item() {
        let text = "action A()\n// a comment\ntree T() { retry(2) A() }\ntree U() { A() }\n";
        let (ws, path) = crate::workspace::logging_workspace(text);
        let a = Analysis::new(&ws, &path).expect("a rules file");
        let at = text.find("retry").expect("in the text");
        let h = hover(&a, at + 2).expect("a keyword hover");
        let log = ws.db.take_log();
        assert!(
            !log.iter().any(|l| l.starts_with("rules_tokens")),
            "{log:#?}"
        );
        let HoverContents::Markup(m) = h.contents else {
            panic!("markdown")
        };
        assert!(m.value.contains("RetryUntilSuccessful"), "{}", m.value);
        let start = a.range(btc_pddl::source::Span::new(0, at, at + 5));
        assert_eq!(h.range, Some(start));
    }
}
