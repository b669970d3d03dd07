//! Completion and signature help. The context comes from the tokens before
//! the cursor, so it works while the item being typed does not parse.

use crate::analysis::Analysis;
use crate::syntax::{template_keywords, ITEM_KEYWORDS};
use btc_lang::db::STDLIB;
use btc_lang::rules::ast::{Item, NodeKind, PortDecl};
use btc_lang::rules::lexer::Tok;
use tower_lsp::lsp_types::{
    CompletionItem, CompletionItemKind, CompletionTextEdit, InsertTextFormat, ParameterInformation,
    ParameterLabel, SignatureHelp, SignatureInformation, TextEdit,
};

const BASIC_TYPES: &[&str] = &["string", "int", "float", "bool"];
const PDDL_CONNECTIVES: &[&str] = &["and", "not", "or", "imply", "exists", "forall", "when"];

/// Where the cursor is, as far as completion is concerned.
#[derive(Debug, PartialEq)]
pub enum Context {
    Variable,
    Predicate,
    RuleHead,
    StdModule,
    TableKey(String),
    PortName { node: String, given: Vec<String> },
    PortType,
    PortValue,
    Template,
    TopLevel,
    Nothing,
}

struct Cursor {
    /// Index of the token being typed (a name or variable the cursor is
    /// in or right after), if any.
    prefix: Option<usize>,
    /// Index of the token before that (or before the cursor).
    prev: Option<usize>,
}

fn cursor(a: &Analysis, offset: usize) -> Cursor {
    let toks = &a.syntax.tokens().toks;
    let i = a.syntax.tokens().after(offset);
    // The token that ends at or contains the cursor.
    let prefix = i.checked_sub(1).filter(|&j| {
        let (t, s) = &toks[j];
        (s.end as usize) >= offset && matches!(t, Tok::Ident(_) | Tok::Var(_))
    });
    let prefix = prefix.or_else(|| {
        toks.get(i).and_then(|(t, s)| {
            (s.start as usize == offset && matches!(t, Tok::Ident(_) | Tok::Var(_))).then_some(i)
        })
    });
    let prev = match prefix {
        Some(p) => p.checked_sub(1),
        None => i.checked_sub(1),
    };
    Cursor { prefix, prev }
}

pub fn context(a: &Analysis, offset: usize) -> Context {
    let t = &a.syntax.tokens();
    let c = cursor(a, offset);
    let before = a.text.get(..offset).unwrap_or_default();
    if matches!(c.prefix.map(|p| &t.toks[p].0), Some(Tok::Var(_))) || before.ends_with('?') {
        return Context::Variable;
    }
    let prev = c.prev;
    let punct = |k: Option<usize>| k.and_then(|k| t.punct(k));
    let ident = |k: Option<usize>| k.and_then(|k| t.ident(k));
    let back = |k: Option<usize>| k.and_then(|k| k.checked_sub(1));
    let here = c.prefix.unwrap_or(prev.map_or(0, |p| p + 1));
    if punct(prev) == Some("(") && ident(back(prev)) == Some("rule") {
        return Context::RuleHead;
    }
    if t.in_pddl(here) {
        return if punct(prev) == Some("(") {
            Context::Predicate
        } else {
            Context::Nothing
        };
    }
    if punct(prev) == Some("::") && ident(back(prev)) == Some("std") {
        return Context::StdModule;
    }
    if punct(prev) == Some("[") {
        if let Some(table) = ident(back(prev)) {
            return Context::TableKey(table.to_owned());
        }
    }
    if let Some((node, decl)) = t.enclosing_call(here) {
        if decl {
            return if punct(prev) == Some(":") {
                Context::PortType
            } else {
                Context::Nothing
            };
        }
        return match punct(prev) {
            Some("(" | ",") => {
                let open = t.open_paren(here).unwrap_or(0);
                let given = (open..here)
                    .filter(|&k| t.punct(k + 1) == Some(":"))
                    .filter_map(|k| t.ident(k).map(str::to_owned))
                    .collect();
                Context::PortName { node, given }
            }
            Some(":") => Context::PortValue,
            _ => Context::Nothing,
        };
    }
    // Inside braces of a rule, tree or plan: a template.
    let Some(item) = a.syntax.item_at(offset as u32) else {
        return Context::TopLevel;
    };
    let start = a.items[item].offset as usize;
    let mut depth = 0i32;
    for k in t.after(start)..here.min(t.toks.len()) {
        match t.punct(k) {
            Some("{") => depth += 1,
            Some("}") => depth -= 1,
            _ => {}
        }
    }
    if depth > 0 {
        let is_table = matches!(*a.items[item].item, Item::Table(_))
            || t.ident(t.after(start)) == Some("table");
        return if is_table {
            Context::Nothing
        } else {
            Context::Template
        };
    }
    let at_line_start = before.rsplit('\n').next().is_some_and(|line| {
        line.trim_start()
            .chars()
            .all(|ch| ch.is_alphanumeric() || ch == '_')
    });
    if at_line_start && depth == 0 {
        Context::TopLevel
    } else {
        Context::Nothing
    }
}

fn item(
    label: impl Into<String>,
    kind: CompletionItemKind,
    detail: Option<String>,
) -> CompletionItem {
    CompletionItem {
        label: label.into(),
        kind: Some(kind),
        detail,
        ..CompletionItem::default()
    }
}

fn signature(name: &str, ports: &[PortDecl]) -> String {
    format!("{name}({})", btc_lang::rules::fmt::ports(ports))
}

/// Variables in scope at `offset`: a rule's parameters, a tree's ports.
fn variables(a: &Analysis, offset: usize) -> Vec<CompletionItem> {
    let Some(ix) = a.syntax.item_at(offset as u32) else {
        return Vec::new();
    };
    match &*a.items[ix].item {
        Item::Rule(r) => r
            .pattern
            .params
            .iter()
            .map(|p| {
                let ty = a.var_types(ix, &p.var.text);
                item(
                    format!("?{}", p.var.text),
                    CompletionItemKind::VARIABLE,
                    (!ty.is_empty()).then(|| ty.join(" | ")),
                )
            })
            .collect(),
        Item::Tree(t) => t
            .ports
            .iter()
            .map(|p| {
                item(
                    format!("?{}", p.name.text),
                    CompletionItemKind::VARIABLE,
                    Some(p.ty.text.clone()),
                )
            })
            .collect(),
        _ => {
            // The item does not parse yet: the variables of its pattern.
            let start = a.items[ix].offset;
            a.syntax
                .tokens()
                .toks
                .iter()
                .filter(|(_, s)| s.start >= start && (s.end as usize) < offset)
                .filter_map(|(t, _)| match t {
                    Tok::Var(v) if !v.is_empty() => Some(format!("?{v}")),
                    _ => None,
                })
                .fold(Vec::new(), |mut seen, v| {
                    if !seen.contains(&v) {
                        seen.push(v);
                    }
                    seen
                })
                .into_iter()
                .map(|v| item(v, CompletionItemKind::VARIABLE, None))
                .collect()
        }
    }
}

pub fn completion(a: &Analysis, offset: usize) -> Vec<CompletionItem> {
    let mut out = Vec::new();
    match context(a, offset) {
        Context::Variable => {
            out = variables(a, offset);
            // Replace the whole `?name` typed so far: clients that do not
            // count `?` as part of a word would otherwise insert `??name`.
            let t = &a.syntax.tokens();
            let c = cursor(a, offset);
            let start = match c.prefix.map(|p| &t.toks[p]) {
                Some((Tok::Var(_), s)) => s.start as usize,
                _ => offset.saturating_sub(1),
            };
            let ix = a.line_index();
            let range = tower_lsp::lsp_types::Range::new(ix.position(start), ix.position(offset));
            for c in &mut out {
                c.text_edit = Some(CompletionTextEdit::Edit(TextEdit::new(
                    range,
                    c.label.clone(),
                )));
            }
        }
        Context::Predicate => {
            if let Some((_, d, _)) = a.domain {
                for p in &d.predicates {
                    let params: Vec<String> = p
                        .params
                        .iter()
                        .map(|t| format!("?{} - {}", t.name.name, t.ty))
                        .collect();
                    out.push(item(
                        p.name.name.clone(),
                        CompletionItemKind::FUNCTION,
                        Some(format!("({} {})", p.name.name, params.join(" "))),
                    ));
                }
            }
            for k in PDDL_CONNECTIVES {
                out.push(item(*k, CompletionItemKind::KEYWORD, None));
            }
        }
        Context::RuleHead => {
            if let Some((_, d, _)) = a.domain {
                for act in &d.actions {
                    let params: Vec<String> = act
                        .params
                        .iter()
                        .map(|p| format!("?{}", p.name.name))
                        .collect();
                    let mut c = item(
                        act.name.name.clone(),
                        CompletionItemKind::METHOD,
                        Some(format!("({} {})", act.name.name, params.join(" "))),
                    );
                    c.insert_text = Some(format!("{} {}", act.name.name, params.join(" ")));
                    out.push(c);
                }
            }
        }
        Context::StdModule => {
            for (name, _) in STDLIB {
                out.push(item(*name, CompletionItemKind::MODULE, None));
            }
        }
        Context::TableKey(table) => {
            if let Some(t) = a.decls.tables.get(&table) {
                for e in &t.entries {
                    out.push(item(
                        e.key.text.clone(),
                        CompletionItemKind::ENUM_MEMBER,
                        None,
                    ));
                }
            }
        }
        Context::PortName { node, given } => {
            if let Some(ports) = a.decls.ports(&node) {
                for p in ports.iter().filter(|p| !given.contains(&p.name.text)) {
                    let mut c = item(
                        p.name.text.clone(),
                        CompletionItemKind::PROPERTY,
                        Some(p.ty.text.clone()),
                    );
                    c.insert_text = Some(format!("{}: ", p.name.text));
                    out.push(c);
                }
            }
        }
        Context::PortType => {
            for t in BASIC_TYPES {
                out.push(item(*t, CompletionItemKind::TYPE_PARAMETER, None));
            }
            if let Some((_, _, dix)) = a.domain {
                for t in dix.types.names() {
                    out.push(item(t, CompletionItemKind::CLASS, Some("PDDL type".into())));
                }
            }
        }
        Context::PortValue => {
            out = variables(a, offset);
            for name in a.decls.tables.keys() {
                out.push(item(
                    name.clone(),
                    CompletionItemKind::ENUM,
                    Some("table".into()),
                ));
            }
        }
        Context::Template => {
            for (name, n) in &a.decls.nodes {
                let kind = match n.kind {
                    NodeKind::Action => CompletionItemKind::FUNCTION,
                    NodeKind::Condition => CompletionItemKind::INTERFACE,
                };
                out.push(call_item(name, &n.ports, kind));
            }
            for (name, t) in &a.decls.trees {
                out.push(call_item(name, &t.ports, CompletionItemKind::CLASS));
            }
            for k in template_keywords() {
                out.push(item(k, CompletionItemKind::KEYWORD, None));
            }
        }
        Context::TopLevel => {
            for k in ITEM_KEYWORDS {
                out.push(item(*k, CompletionItemKind::KEYWORD, None));
            }
        }
        Context::Nothing => {}
    }
    out
}

/// A node or tree, inserted as a call with a placeholder per input port.
fn call_item(name: &str, ports: &[PortDecl], kind: CompletionItemKind) -> CompletionItem {
    let args: Vec<String> = ports
        .iter()
        .enumerate()
        .map(|(i, p)| format!("{}: ${}", p.name.text, i + 1))
        .collect();
    CompletionItem {
        label: name.to_owned(),
        kind: Some(kind),
        detail: Some(signature(name, ports)),
        insert_text: Some(format!("{name}({})", args.join(", "))),
        insert_text_format: Some(InsertTextFormat::SNIPPET),
        ..CompletionItem::default()
    }
}

/// Signature help inside a node or tree call's parentheses.
pub fn signature_help(a: &Analysis, offset: usize) -> Option<SignatureHelp> {
    let t = &a.syntax.tokens();
    let here = t.after(offset);
    let (node, decl) = t.enclosing_call(here)?;
    if decl {
        return None;
    }
    let ports = a.decls.ports(&node)?;
    let label = signature(&node, ports);
    // Parameter labels as offsets into the label (UTF-16, as LSP counts).
    let mut params = Vec::new();
    let mut pos = node.encode_utf16().count() + 1;
    for (i, p) in ports.iter().enumerate() {
        let text = format!(
            "{}{}: {}",
            if p.out { "out " } else { "" },
            p.name.text,
            p.ty.text
        );
        let len = text.encode_utf16().count();
        params.push(ParameterInformation {
            label: ParameterLabel::LabelOffsets([pos as u32, (pos + len) as u32]),
            documentation: None,
        });
        pos += len + if i + 1 < ports.len() { 2 } else { 0 };
    }
    // The active port: the last `name:` before the cursor, else by commas.
    let open = t.open_paren(here)?;
    let mut active = 0usize;
    let mut commas = 0usize;
    let mut named = None;
    for k in open + 1..here {
        match t.punct(k) {
            Some(",") => commas += 1,
            Some(":") => {
                if let Some(n) = k.checked_sub(1).and_then(|j| t.ident(j)) {
                    named = ports.iter().position(|p| p.name.text == n);
                }
            }
            _ => {}
        }
    }
    if let Some(n) = named {
        active = n;
    }
    if t.punct(here.saturating_sub(1)) == Some(",") || named.is_none() {
        active = commas.min(ports.len().saturating_sub(1));
    }
    Some(SignatureHelp {
        signatures: vec![SignatureInformation {
            label,
            documentation: None,
            parameters: Some(params),
            active_parameter: Some(active as u32),
        }],
        active_signature: Some(0),
        active_parameter: Some(active as u32),
    })
}
