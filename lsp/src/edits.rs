//! Formatting and code actions: quick fixes from diagnostics, and rule
//! stubs for the domain actions no rule covers (`btc_lang::stubs`, which
//! `btc stubs` writes too).

use crate::analysis::Analysis;
use crate::convert::LineIndex;
use crate::workspace::Workspace;
use btc_lang::db::{checked_domain, parsed_rules, rules_diagnostics};
use btc_lang::path::FilePath;
use btc_lang::rules::fmt::format_parsed;
use btc_pddl::diagnostic::Diagnostic;
use std::collections::HashMap;
use tower_lsp::lsp_types::{
    CodeAction, CodeActionKind, Position, Range, TextEdit, Url, WorkspaceEdit,
};

/// The whole document formatted, as one edit; `None` when the text does
/// not parse (the formatter refuses it) or is formatted already.
pub fn format(a: &Analysis) -> Option<Vec<TextEdit>> {
    let formatted = format_parsed(a.text, parsed_rules(&a.ws.db, a.file)).ok()?;
    if formatted == a.text {
        return Some(Vec::new());
    }
    let ix = a.line_index();
    Some(vec![TextEdit::new(
        Range::new(Position::new(0, 0), ix.position(a.text.len())),
        formatted,
    )])
}

fn edit(uri: &Url, edits: Vec<TextEdit>) -> WorkspaceEdit {
    WorkspaceEdit::new(HashMap::from([(uri.clone(), edits)]))
}

/// Code actions for a range of the document: each diagnostic fix there,
/// and "add rule stubs" when domain actions lack rules.
pub fn code_actions(
    a: &Analysis,
    uri: &Url,
    range: Range,
    to_lsp: &dyn Fn(&Diagnostic) -> tower_lsp::lsp_types::Diagnostic,
) -> Vec<CodeAction> {
    let ix = a.line_index();
    let file_id = btc_lang::db::file_id(&a.ws.db, a.file);
    let mut diags = rules_diagnostics(&a.ws.db, a.file).clone();
    btc_lang::project::suggest_paths(&a.ws.db, a.ws.loader(), a.file, &mut diags);
    let mut out = quick_fixes(&diags, file_id, ix, uri, range, to_lsp);
    if let Some(stubs) = btc_lang::stubs::missing(&a.ws.db, a.file) {
        let uncovered = stubs.actions.len();
        out.push(CodeAction {
            title: format!(
                "Add rule stubs for {uncovered} uncovered domain action{}",
                if uncovered == 1 { "" } else { "s" }
            ),
            kind: Some(CodeActionKind::QUICKFIX),
            edit: Some(edit(
                uri,
                vec![TextEdit::new(
                    Range::new(ix.position(a.text.len()), ix.position(a.text.len())),
                    stubs.text,
                )],
            )),
            ..CodeAction::default()
        });
    }
    out
}

/// Code actions for a range of a PDDL domain: the fixes of its own
/// diagnostics there (P102's inferred declaration, ...).
pub fn pddl_code_actions(
    ws: &Workspace,
    path: &FilePath,
    uri: &Url,
    range: Range,
    to_lsp: &dyn Fn(&Diagnostic) -> tower_lsp::lsp_types::Diagnostic,
) -> Vec<CodeAction> {
    let Some(file) = ws.file(path) else {
        return Vec::new();
    };
    let text = file.text(&ws.db);
    let ix = &LineIndex::new(text);
    let file_id = btc_lang::db::file_id(&ws.db, file);
    let checked = checked_domain(&ws.db, file);
    quick_fixes(&checked.diagnostics, file_id, ix, uri, range, to_lsp)
}

/// The fixes in this file of the diagnostics over `range`.
fn quick_fixes(
    diags: &[Diagnostic],
    file_id: btc_pddl::source::FileId,
    ix: &LineIndex,
    uri: &Url,
    range: Range,
    to_lsp: &dyn Fn(&Diagnostic) -> tower_lsp::lsp_types::Diagnostic,
) -> Vec<CodeAction> {
    let (from, to) = (ix.offset(range.start) as u32, ix.offset(range.end) as u32);
    let mut out = Vec::new();
    for d in diags {
        if d.span.file != file_id || d.span.end < from || d.span.start > to {
            continue;
        }
        for f in d.fixes.iter().filter(|f| f.span.file == file_id) {
            out.push(CodeAction {
                title: f.title.clone(),
                kind: Some(CodeActionKind::QUICKFIX),
                diagnostics: Some(vec![to_lsp(d)]),
                edit: Some(edit(
                    uri,
                    vec![TextEdit::new(ix.range(f.span), f.replacement.clone())],
                )),
                is_preferred: Some(d.fixes.len() == 1),
                ..CodeAction::default()
            });
        }
    }
    out
}

/// Where an edit lands, for tests: the text with the edits applied.
pub fn apply(text: &str, edits: &[TextEdit]) -> String {
    let ix = LineIndex::new(text);
    let mut spans: Vec<(usize, usize, &str)> = edits
        .iter()
        .map(|e| {
            (
                ix.offset(e.range.start),
                ix.offset(e.range.end),
                e.new_text.as_str(),
            )
        })
        .collect();
    spans.sort_by_key(|s| std::cmp::Reverse(s.0));
    let mut out = text.to_owned();
    for (a, b, t) in spans {
        out.replace_range(a..b, t);
    }
    out
}
