//! Hover, go-to-definition, find references and rename.

use crate::analysis::{shift, Analysis, Place};
use crate::syntax::Symbol;
use btc_lang::db::file_id;
use btc_lang::rules::ast::{Item, NodeKind};
use btc_lang::rules::name::Key;
use btc_pddl::source::Span;
use std::collections::HashMap;
use tower_lsp::lsp_types::{
    Hover, HoverContents, Location, MarkupContent, MarkupKind, TextEdit, Url, WorkspaceEdit,
};

fn code_block(lang: &str, text: &str) -> String {
    format!("```{lang}\n{}\n```", text.trim_end())
}

/// The hover text at a byte offset.
pub fn hover(a: &Analysis, offset: usize) -> Option<Hover> {
    let (sym, span) = a.syntax.symbol_at(offset)?;
    let text = match &sym {
        Symbol::RuleHead { item } => {
            let r = a.rule(*item)?;
            let actions = a.actions_of(r);
            if actions.is_empty() {
                format!(
                    "`{}`: no action of the domain matches",
                    r.pattern.name_text()
                )
            } else {
                let (dfile, _, _) = a.domain?;
                actions
                    .iter()
                    .map(|act| code_block("pddl", a.source_of(dfile, act.span)))
                    .collect::<Vec<_>>()
                    .join("\n\n")
            }
        }
        Symbol::Var { item, name } => match &a.items[*item].item {
            Item::Rule(r) => {
                let types = a.var_types(*item, name);
                let pos = r.pattern.params.iter().position(|p| p.var.text == *name);
                match (pos, types.is_empty()) {
                    (Some(p), false) => format!(
                        "`?{name}`: {} (parameter {} of `{}`)",
                        types
                            .iter()
                            .map(|t| format!("`{t}`"))
                            .collect::<Vec<_>>()
                            .join(" or "),
                        p + 1,
                        r.pattern.name_text()
                    ),
                    (Some(p), true) => format!("`?{name}`: parameter {} of the rule", p + 1),
                    (None, _) => format!("`?{name}` is not a parameter of this rule"),
                }
            }
            Item::Tree(t) => match t.ports.iter().find(|p| p.name.text == *name) {
                Some(p) => format!(
                    "`?{name}`: `{}` (a port of tree `{}`)",
                    p.ty.text, t.name.text
                ),
                None => format!("`?{name}` is not a port of tree `{}`", t.name.text),
            },
            _ => format!("`?{name}`"),
        },
        Symbol::Capture { item, name } => {
            let r = a.rule(*item)?;
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
        Symbol::Node { name, .. } => {
            let (place, item) = a.declaration(name, false)?;
            let decl = match item {
                Item::Node(n) => {
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
                }
                Item::Tree(t) => {
                    format!(
                        "tree {}({})",
                        t.name.text,
                        btc_lang::rules::fmt::ports(&t.ports)
                    )
                }
                _ => return None,
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
        Symbol::Table { name, .. } => {
            let (place, _) = a.declaration(name, true)?;
            let Item::Table(t) = a.declaration(name, true)?.1 else {
                return None;
            };
            let entries: Vec<String> = t
                .entries
                .iter()
                .map(|e| {
                    let off = place.span.start - t.name.span.start;
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
        Symbol::Port { node, port, .. } => {
            let ports = a.decls.ports(node)?;
            let p = ports.iter().find(|p| p.name.text == *port)?;
            format!(
                "port `{}` of `{node}`: `{}`{}",
                p.name.text,
                p.ty.text,
                if p.out { " (output)" } else { "" }
            )
        }
        Symbol::Predicate { name } => {
            let (dfile, d, _) = a.domain?;
            let p = d.predicates.iter().find(|p| p.name.name == *name)?;
            code_block("pddl", a.source_of(dfile, p.span))
        }
        Symbol::Type { name } => {
            let (_, _, dix) = a.domain?;
            let key = Key::new(name);
            let lower = key.as_str();
            match dix.types.id(lower) {
                Some(id) => {
                    let parents: Vec<&str> = dix
                        .types
                        .names()
                        .filter(|t| *t != lower)
                        .filter(|t| dix.types.id(t).is_some_and(|p| dix.types.is_subtype(id, p)))
                        .collect();
                    if parents.is_empty() {
                        format!("PDDL type `{lower}`")
                    } else {
                        format!(
                            "PDDL type `{lower}`, a kind of {}",
                            parents
                                .iter()
                                .map(|p| format!("`{p}`"))
                                .collect::<Vec<_>>()
                                .join(", ")
                        )
                    }
                }
                None => format!("`{name}`: a basic type"),
            }
        }
        Symbol::Path { written } => match a.ws.resolve_written(a.file, written) {
            Some(p) => format!("`{p}`"),
            None => format!("`{written}` is not found"),
        },
        Symbol::Std { module } => format!("stdlib module `std::{module}`"),
        Symbol::Keyword => return None,
    };
    Some(Hover {
        contents: HoverContents::Markup(MarkupContent {
            kind: MarkupKind::Markdown,
            value: text,
        }),
        range: Some(a.range(span)),
    })
}

/// Where the symbol at `offset` is defined.
pub fn definition(a: &Analysis, offset: usize) -> Option<Place> {
    let (sym, _) = a.syntax.symbol_at(offset)?;
    match sym {
        Symbol::RuleHead { item } => {
            let r = a.rule(item)?;
            let (dfile, _, _) = a.domain?;
            let act = *a.actions_of(r).first()?;
            Some(Place {
                file: dfile,
                span: act.name.span,
            })
        }
        Symbol::Var { item, name } => {
            let n = &a.items[item];
            let span = match &n.item {
                Item::Rule(r) => {
                    r.pattern
                        .params
                        .iter()
                        .find(|p| p.var.text == name)?
                        .var
                        .span
                }
                Item::Tree(t) => t.ports.iter().find(|p| p.name.text == name)?.name.span,
                _ => return None,
            };
            Some(Place {
                file: a.file,
                span: shift(span, n.offset),
            })
        }
        Symbol::Capture { item, name } => {
            let n = &a.items[item];
            let r = a.rule(item)?;
            let span = r.pattern.name.iter().find_map(|p| match p {
                btc_lang::rules::ast::NamePart::Capture { name: c } if c.text == name => {
                    Some(c.span)
                }
                _ => None,
            })?;
            Some(Place {
                file: a.file,
                span: shift(span, n.offset),
            })
        }
        Symbol::Node { name, .. } => a.declaration(&name, false).map(|(p, _)| p),
        Symbol::Table { name, .. } => a.declaration(&name, true).map(|(p, _)| p),
        Symbol::Port { node, port, .. } => {
            let (place, item) = a.declaration(&node, false)?;
            let (ports, name_span) = match item {
                Item::Node(n) => (&n.ports, n.name.span),
                Item::Tree(t) => (&t.ports, t.name.span),
                _ => return None,
            };
            let p = ports.iter().find(|p| p.name.text == port)?;
            Some(Place {
                file: place.file,
                span: shift(p.name.span, place.span.start - name_span.start),
            })
        }
        Symbol::Predicate { name } => {
            let (dfile, d, _) = a.domain?;
            let p = d.predicates.iter().find(|p| p.name.name == name)?;
            Some(Place {
                file: dfile,
                span: p.name.span,
            })
        }
        Symbol::Type { name } => {
            let (dfile, d, _) = a.domain?;
            let key = Key::new(&name);
            let t = d.types.iter().find(|t| t.name.name == key.as_str())?;
            Some(Place {
                file: dfile,
                span: t.name.span,
            })
        }
        Symbol::Path { written } => {
            let path = a.ws.resolve_written(a.file, &written)?;
            let f = a.ws.file(&path)?;
            Some(Place {
                file: f,
                span: Span::new(file_id(&a.ws.db, f), 0, 0),
            })
        }
        Symbol::Std { .. } | Symbol::Keyword => None,
    }
}

/// Every place that names the same thing as the symbol at `offset`
/// (declaration included), across the rules files in scope.
pub fn references(a: &Analysis, offset: usize) -> Option<Vec<Place>> {
    let (sym, _) = a.syntax.symbol_at(offset)?;
    let mut out = Vec::new();
    match &sym {
        Symbol::Var { item, name } | Symbol::Capture { item, name } => {
            let var = matches!(sym, Symbol::Var { .. });
            let n = &a.items[*item];
            let end = a
                .items
                .get(item + 1)
                .map_or(a.text.len() as u32, |m| m.offset);
            for (i, (_, s)) in a.syntax.tokens.toks.iter().enumerate() {
                if s.start < n.offset || s.end > end {
                    continue;
                }
                let same = match a.syntax.classify(i) {
                    Some(Symbol::Var { name: m, .. }) if var => m == *name,
                    Some(Symbol::Capture { name: m, .. }) => !var && m == *name,
                    _ => false,
                };
                // A bare capture use (`marker[op]`) is a name token too.
                let bare = !var
                    && matches!(&a.syntax.tokens.toks[i].0, btc_lang::rules::lexer::Tok::Ident(t) if t == name)
                    && !a.syntax.tokens.in_pddl(i);
                if same || bare {
                    out.push(Place {
                        file: a.file,
                        span: *s,
                    });
                }
            }
            for s in a.syntax.interpolations(*item, name, var) {
                out.push(Place {
                    file: a.file,
                    span: s,
                });
            }
        }
        Symbol::Node { name, .. }
        | Symbol::Table { name, .. }
        | Symbol::Port { port: name, .. } => {
            for f in a.ws.all_rules() {
                let Some(other) = Analysis::new(a.ws, f.path(&a.ws.db)) else {
                    continue;
                };
                // Only files that see the same declaration.
                if !other.closure().iter().any(|g| a.closure().contains(g)) {
                    continue;
                }
                for (i, (_, s)) in other.syntax.tokens.toks.iter().enumerate() {
                    let same = match (&sym, other.syntax.classify(i)) {
                        (Symbol::Node { .. }, Some(Symbol::Node { name: m, .. })) => m == *name,
                        (Symbol::Table { .. }, Some(Symbol::Table { name: m, .. })) => m == *name,
                        (
                            Symbol::Port { node, .. },
                            Some(Symbol::Port {
                                node: n2, port: p2, ..
                            }),
                        ) => n2 == *node && p2 == *name,
                        _ => false,
                    };
                    if same {
                        out.push(Place { file: f, span: *s });
                    }
                }
            }
        }
        Symbol::Predicate { .. } | Symbol::RuleHead { .. } | Symbol::Type { .. } => {
            // References of PDDL names within the rules in scope.
            for (i, (_, s)) in a.syntax.tokens.toks.iter().enumerate() {
                if a.syntax.classify(i).as_ref() == Some(&sym) {
                    out.push(Place {
                        file: a.file,
                        span: *s,
                    });
                }
            }
            if let Some(def) = definition(a, offset) {
                out.insert(0, def);
            }
        }
        Symbol::Path { .. } | Symbol::Std { .. } | Symbol::Keyword => return None,
    }
    out.sort_by_key(|p| (p.file.path(&a.ws.db).clone(), p.span.start));
    out.dedup();
    Some(out)
}

/// Why a rename cannot be done.
#[derive(Debug, PartialEq)]
pub struct RenameError(pub String);

/// The edits that rename the symbol at `offset` (variables, captures,
/// nodes, trees, tables, ports) to `new_name`.
pub fn rename(a: &Analysis, offset: usize, new_name: &str) -> Result<WorkspaceEdit, RenameError> {
    let Some((sym, _)) = a.syntax.symbol_at(offset) else {
        return Err(RenameError("nothing to rename here".into()));
    };
    let bare = new_name.trim_start_matches('?');
    let valid = bare.starts_with(|c: char| c.is_alphabetic() || c == '_')
        && bare
            .chars()
            .all(|c| c.is_alphanumeric() || c == '_' || c == '-');
    if !valid {
        return Err(RenameError(format!("`{new_name}` is not a valid name")));
    }
    let replacement = match sym {
        Symbol::Var { .. } => format!("?{}", Key::new(bare)),
        Symbol::Capture { .. } | Symbol::Node { .. } | Symbol::Table { .. } | Symbol::Port { .. } => {
            bare.to_owned()
        }
        _ => {
            return Err(RenameError(
                "only variables, captures, nodes, trees, tables and ports can be renamed here (PDDL names live in the domain)".into(),
            ))
        }
    };
    let places = references(a, offset).unwrap_or_default();
    let mut changes: HashMap<Url, Vec<TextEdit>> = HashMap::new();
    for p in places {
        // Interpolations (`{?x}`) cover the name without braces.
        let Some(loc) = a.location(&p) else {
            return Err(RenameError(
                "the name is declared in the stdlib, which cannot be edited".into(),
            ));
        };
        let Location { uri, range } = loc;
        changes
            .entry(uri)
            .or_default()
            .push(TextEdit::new(range, replacement.clone()));
    }
    Ok(WorkspaceEdit::new(changes))
}
