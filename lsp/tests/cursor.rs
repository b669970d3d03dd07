//! Editor features on fixture files with a cursor, in gleam's style: each
//! case is a rules file under `tests/fixtures/cursor/<feature>/` with `$0`
//! where the cursor is (removed before the file is opened), beside a
//! domain, a problem and an imported rules file. The result is drawn on
//! the source (the ranges underlined, the cursor's file in full, other
//! files by their marked lines) and snapshotted, so a snapshot reads like
//! what the editor shows and does not depend on the examples.

use btc_lang::path::FilePath;
use btc_lsp::analysis::{Analysis, Place};
use btc_lsp::convert::LineIndex;
use btc_lsp::workspace::Workspace;
use btc_lsp::{edits, navigation, symbols};
use btc_pddl::source::Span;
use std::path::{Path, PathBuf};
use tower_lsp::lsp_types::{
    DocumentHighlightKind, DocumentSymbol, HoverContents, Position, Range, Url,
};

const CURSOR: &str = "$0";

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/fixtures/cursor")
        .canonicalize()
        .unwrap()
}

/// A case opened in a fresh workspace: its path and the cursor's offset.
struct Case {
    ws: Workspace,
    path: FilePath,
    offset: usize,
}

impl Case {
    fn open(feature: &str, name: &str) -> Case {
        let file = root().join(feature).join(format!("{name}.btrules"));
        let marked = std::fs::read_to_string(&file).unwrap();
        assert_eq!(
            marked.matches(CURSOR).count(),
            1,
            "{}: one cursor marker `{CURSOR}`",
            file.display()
        );
        let offset = marked.find(CURSOR).unwrap();
        let text = marked.replacen(CURSOR, "", 1);
        let mut ws = Workspace::new();
        let path = FilePath::new(file);
        ws.open(&path, text, 1);
        Case { ws, path, offset }
    }

    fn analysis(&self) -> Analysis<'_> {
        Analysis::new(&self.ws, &self.path).expect("a rules file")
    }
}

/// One range drawn on a file.
struct Mark {
    path: FilePath,
    span: Span,
    label: String,
}

/// A file's name as a snapshot shows it: relative to the fixtures.
fn shown(path: &FilePath) -> String {
    match path.as_path() {
        Some(p) => p
            .strip_prefix(root())
            .map_or_else(|_| path.to_string(), |r| r.display().to_string()),
        None => path.to_string(),
    }
}

/// The cursor's file with every mark underlined, then each other marked
/// file's marked lines.
fn draw(c: &Case, marks: &[Mark]) -> String {
    let mut files: Vec<&FilePath> = vec![&c.path];
    for m in marks {
        if !files.contains(&&m.path) {
            files.push(&m.path);
        }
    }
    let mut out = String::new();
    for (k, path) in files.iter().enumerate() {
        let text = c.ws.text(path).unwrap_or_default();
        out.push_str(&format!("--- {}\n", shown(path)));
        let mut start = 0usize;
        for (n, line) in text.split_inclusive('\n').enumerate() {
            let end = start + line.len();
            let here: Vec<&Mark> = marks
                .iter()
                .filter(|m| m.path == **path)
                .filter(|m| {
                    let s = m.span.start as usize;
                    (start <= s && s < end) || (s == end && n == 0 && line.is_empty())
                })
                .collect();
            if k == 0 || !here.is_empty() {
                let content = line.trim_end_matches(['\n', '\r']);
                out.push_str(&format!("{:>3} | {content}\n", n + 1));
                for m in here {
                    let col = text[start..m.span.start as usize].chars().count();
                    let stop = (m.span.end as usize).min(start + content.len());
                    let width = text
                        .get(m.span.start as usize..stop.max(m.span.start as usize))
                        .map_or(0, |s| s.chars().count())
                        .max(1);
                    out.push_str(&format!(
                        "    | {}{} {}\n",
                        " ".repeat(col),
                        "^".repeat(width),
                        m.label
                    ));
                }
            }
            start = end;
        }
    }
    out
}

fn place_mark(a: &Analysis, p: &Place, label: &str) -> Mark {
    Mark {
        path: p.file.path(&a.ws.db).clone(),
        span: p.span,
        label: label.to_owned(),
    }
}

fn span_of(a: &Analysis, r: Range) -> Span {
    let ix = a.line_index();
    Span::new(0, ix.offset(r.start), ix.offset(r.end))
}

fn here(c: &Case, span: Span, label: &str) -> Mark {
    Mark {
        path: c.path.clone(),
        span,
        label: label.to_owned(),
    }
}

fn cursor(c: &Case) -> Mark {
    here(c, Span::new(0, c.offset, c.offset), "cursor")
}

fn run(feature: &str, name: &str) {
    let c = Case::open(feature, name);
    let a = c.analysis();
    let out = match feature {
        "definition" => {
            let found = navigation::definition(&a, c.offset);
            let mut marks = vec![cursor(&c)];
            marks.extend(found.iter().map(|p| place_mark(&a, p, "definition")));
            if found.is_empty() {
                format!("no definition\n{}", draw(&c, &marks))
            } else {
                draw(&c, &marks)
            }
        }
        "references" => match navigation::references(&a, c.offset) {
            None => format!("no references\n{}", draw(&c, &[cursor(&c)])),
            Some(found) => {
                let mut marks = vec![cursor(&c)];
                marks.extend(found.iter().map(|p| place_mark(&a, p, "reference")));
                draw(&c, &marks)
            }
        },
        "rename" => {
            let new_name = if name == "invalid_new_name" {
                "9lives"
            } else {
                "renamed"
            };
            let prepared = navigation::prepare_rename(&a, c.offset);
            let shown_prepared = match &prepared {
                Ok(s) => format!("`{}`", &a.text[s.start as usize..s.end as usize]),
                Err(e) => format!("refused: {}", e.0),
            };
            match navigation::rename(&a, c.offset, new_name) {
                Err(e) => format!(
                    "prepareRename: {shown_prepared}\nrename to `{new_name}` refused: {}\n{}",
                    e.0,
                    draw(&c, &[cursor(&c)])
                ),
                Ok(edit) => {
                    let mut marks = vec![cursor(&c)];
                    let mut changes: Vec<_> =
                        edit.changes.unwrap_or_default().into_iter().collect();
                    changes.sort_by_key(|(u, _)| u.to_string());
                    for (uri, edits) in changes {
                        let path = FilePath::new(uri.to_file_path().unwrap());
                        let text = c.ws.text(&path).unwrap_or_default();
                        let ix = LineIndex::new(text);
                        for e in edits {
                            marks.push(Mark {
                                path: path.clone(),
                                span: Span::new(
                                    0,
                                    ix.offset(e.range.start),
                                    ix.offset(e.range.end),
                                ),
                                label: format!("-> {}", e.new_text),
                            });
                        }
                    }
                    let range = prepared.expect("a rename that works was prepared");
                    marks.push(here(&c, range, "prepareRename"));
                    draw(&c, &marks)
                }
            }
        }
        "hover" => match navigation::hover(&a, c.offset) {
            None => format!("no hover\n{}", draw(&c, &[cursor(&c)])),
            Some(h) => {
                let HoverContents::Markup(m) = h.contents else {
                    panic!("hovers are markdown")
                };
                let range = span_of(&a, h.range.expect("a hover names its range"));
                format!(
                    "{}\n\n{}",
                    m.value,
                    draw(&c, &[cursor(&c), here(&c, range, "hover")])
                )
            }
        },
        "highlight" => {
            let found = navigation::highlights(&a, c.offset).unwrap_or_default();
            let mut marks = vec![cursor(&c)];
            marks.extend(found.iter().map(|h| {
                let kind = if h.kind == Some(DocumentHighlightKind::WRITE) {
                    "write"
                } else {
                    "read"
                };
                here(&c, span_of(&a, h.range), kind)
            }));
            draw(&c, &marks)
        }
        "completion" => {
            let items = btc_lsp::completion::completion(&a, c.offset);
            let mut list: String = items
                .iter()
                .map(|i| {
                    format!(
                        "{}{}\n",
                        i.label,
                        i.detail
                            .as_ref()
                            .map_or_else(String::new, |d| format!("  ({d})"))
                    )
                })
                .collect();
            if list.is_empty() {
                list = "no completions\n".into();
            }
            format!("{list}\n{}", draw(&c, &[cursor(&c)]))
        }
        "semantic_tokens" => {
            let marks: Vec<Mark> = btc_lsp::highlight::classified(&a)
                .into_iter()
                .map(|(span, ty)| here(&c, span, ty.as_str()))
                .collect();
            // The encoded form must decode to the same tokens.
            assert_eq!(
                btc_lsp::highlight::semantic_tokens(&a).len(),
                marks.len(),
                "single-line tokens encode one each"
            );
            draw(&c, &marks)
        }
        "inlay_hints" => {
            let whole = Range::new(Position::new(0, 0), Position::new(u32::MAX, 0));
            let marks: Vec<Mark> = btc_lsp::highlight::inlay_hints(&a, whole)
                .into_iter()
                .map(|h| {
                    let at = a.line_index().offset(h.position);
                    let tower_lsp::lsp_types::InlayHintLabel::String(label) = h.label else {
                        panic!("string labels")
                    };
                    here(&c, Span::new(0, at, at), &format!("inlay `{label}`"))
                })
                .collect();
            if marks.is_empty() {
                format!("no inlay hints\n{}", draw(&c, &marks))
            } else {
                draw(&c, &marks)
            }
        }
        "document_symbols" => {
            fn walk(a: &Analysis, c: &Case, s: &DocumentSymbol, depth: usize, out: &mut Vec<Mark>) {
                out.push(here(
                    c,
                    span_of(a, s.selection_range),
                    &format!("{}{} ({:?})", "  ".repeat(depth), s.name, s.kind),
                ));
                for child in s.children.iter().flatten() {
                    walk(a, c, child, depth + 1, out);
                }
            }
            let mut marks = Vec::new();
            for s in symbols::document_symbols(&a) {
                walk(&a, &c, &s, 0, &mut marks);
            }
            draw(&c, &marks)
        }
        "code_actions" => {
            let uri = Url::from_file_path(c.path.as_path().unwrap()).unwrap();
            let at = a.line_index().position(c.offset);
            let lines = btc_lsp::server::Lines::new(a.ws, btc_lsp::convert::LineIndex::new(a.text));
            let conv = |d: &btc_pddl::diagnostic::Diagnostic| btc_lsp::server::to_lsp(&lines, d);
            let actions = edits::code_actions(&a, &uri, Range::new(at, at), &conv);
            let mut out = String::new();
            for act in &actions {
                out.push_str(&format!("== {}\n", act.title));
                let changes = act
                    .edit
                    .as_ref()
                    .and_then(|e| e.changes.as_ref())
                    .and_then(|ch| ch.get(&uri))
                    .cloned()
                    .unwrap_or_default();
                out.push_str(&edits::apply(a.text, &changes));
                out.push('\n');
            }
            if actions.is_empty() {
                out.push_str("no code actions\n");
            }
            out
        }
        other => panic!("no feature `{other}`"),
    };
    insta::assert_snapshot!(format!("{feature}__{name}"), out);
}

macro_rules! cases {
    ($($feature:ident: [$($case:ident),* $(,)?];)*) => {
        $(mod $feature {
            $(#[test]
            fn $case() {
                super::run(stringify!($feature), stringify!($case));
            })*
        })*

        /// Every fixture has its test, and every test its fixture.
        #[test]
        fn every_fixture_is_a_case() {
            let mut listed: Vec<String> = vec![$($(format!("{}/{}", stringify!($feature), stringify!($case)),)*)*];
            listed.sort();
            let mut found = Vec::new();
            for dir in std::fs::read_dir(root()).unwrap() {
                let dir = dir.unwrap().path();
                if !dir.is_dir() {
                    continue;
                }
                for f in std::fs::read_dir(&dir).unwrap() {
                    let f = f.unwrap().path();
                    found.push(format!(
                        "{}/{}",
                        dir.file_name().unwrap().to_string_lossy(),
                        f.file_stem().unwrap().to_string_lossy()
                    ));
                }
            }
            found.sort();
            assert_eq!(found, listed);
        }
    };
}

cases! {
    definition: [
        call_in_tree, call_into_import, capture_use, domain_path,
        head_matching_two_actions, keyword_has_none, object_in_guard, port_of_call,
        predicate_in_effect, rule_head, rule_variable, stdlib_module, table_in_import,
        tree_port_variable, type_of_port, unknown_node,
    ];
    references: [
        capture, condition_across_files, nothing_at_a_keyword, predicate,
        rule_variable_with_interpolation, tree_port,
    ];
    rename: [
        capture, invalid_new_name, node_across_files, refused_pddl_predicate,
        refused_rule_head, refused_stdlib_node, rule_variable, tree_port,
    ];
    hover: [
        capture, head_matching_two_actions, keyword_as_port_name, keyword_delay,
        keyword_parallel, keyword_retry, node_from_import, port, predicate,
        pddl_type, rule_variable, table, tree_port_variable,
    ];
    highlight: [rule_variable, tree];
    completion: [port_names, rule_head, template_call, variable_in_call];
    semantic_tokens: [broken_item, rules];
    inlay_hints: [no_domain, rules];
    document_symbols: [rules, with_errors];
    code_actions: [misspelled_node, stubs_for_uncovered_actions];
}
