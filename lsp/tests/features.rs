//! Diagnostics, quick fixes, completion contexts, signature help,
//! formatting and file watching, driven in process through the real LSP
//! service on fixtures (`tests/fixtures/ariac` and `p3_assembler` are
//! copies of examples, so that editing an example does not break these).
//! Hover, definition, references, rename, highlights, semantic tokens,
//! inlay hints, symbols and code actions are `tests/cursor.rs` (fixtures
//! with a cursor, results drawn on the source); `tests/service.rs` has
//! their wire shapes and a smoke test over every example.

mod common;

use common::{pos, repo, uri, TestClient};
use serde_json::{json, Value};
use std::path::PathBuf;

fn fixture(path: &str) -> PathBuf {
    repo().join("lsp/tests/fixtures").join(path)
}

fn ariac() -> PathBuf {
    fixture("ariac/rules.btrules")
}

fn text_of(p: &std::path::Path) -> String {
    std::fs::read_to_string(p).unwrap()
}

/// The string `key` of each object of a list (an array `Value` or slice).
fn each<'a>(list: impl IntoIterator<Item = &'a Value>, key: &str) -> Vec<&'a str> {
    list.into_iter().map(|v| v[key].as_str().unwrap()).collect()
}

fn codes(diags: &[Value]) -> Vec<&str> {
    each(diags, "code")
}

fn array(v: &Value) -> &Vec<Value> {
    v.as_array().unwrap()
}

/// The code action titled `title` over `range` (the diagnostics given as
/// context), its edits applied to `text`.
async fn code_action(
    c: &mut TestClient,
    u: &url::Url,
    text: &str,
    range: Value,
    diagnostics: Value,
    title: &str,
) -> String {
    let actions = c
        .request(
            "textDocument/codeAction",
            json!({ "textDocument": { "uri": u }, "range": range, "context": { "diagnostics": diagnostics } }),
        )
        .await;
    let action = array(&actions)
        .iter()
        .find(|a| a["title"] == title)
        .unwrap_or_else(|| panic!("no action `{title}`: {actions:#}"));
    apply(text, &action["edit"]["changes"][u.as_str()])
}

fn range(d: &Value) -> [u64; 4] {
    let r = &d["range"];
    [
        r["start"]["line"].as_u64().unwrap(),
        r["start"]["character"].as_u64().unwrap(),
        r["end"]["line"].as_u64().unwrap(),
        r["end"]["character"].as_u64().unwrap(),
    ]
}

fn hover_text(v: &Value) -> String {
    v["contents"]["value"]
        .as_str()
        .unwrap_or_default()
        .to_owned()
}

/// Applies LSP text edits (a list) to a text.
fn apply(text: &str, edits: &Value) -> String {
    let edits: Vec<tower_lsp::lsp_types::TextEdit> = serde_json::from_value(edits.clone()).unwrap();
    btc_lsp::edits::apply(text, &edits)
}

#[tokio::test]
async fn diagnostics_appear_at_the_right_range_and_clear_when_fixed() {
    let mut c = TestClient::new().await;
    let path = ariac();
    let text = text_of(&path).replacen("        Grasp(robot", "        Grsp(robot", 1);
    let u = c.open_text(&path, &text).await;
    let diags = c.diagnostics_for(&u).await;
    // The misspelled call, and the declaration it leaves unused.
    assert_eq!(codes(&diags), ["R014", "R007"], "{diags:#?}");
    let (line, col) = pos(&text, "Grsp(", 0);
    assert_eq!(
        range(&diags[1]),
        [line as u64, col as u64, line as u64, col as u64 + 4]
    );
    assert!(diags[1]["message"]
        .as_str()
        .unwrap()
        .contains("did you mean `Grasp`?"));

    // The quick fix replaces the name.
    let fixed = code_action(
        &mut c,
        &u,
        &text,
        diags[1]["range"].clone(),
        json!([]),
        "change to `Grasp`",
    )
    .await;
    assert_eq!(fixed, text_of(&path));

    // Typing the fix clears the diagnostic.
    c.change(&u, 2, [line, col + 2, line, col + 2], "a").await;
    let diags = c.diagnostics_for(&u).await;
    assert!(diags.is_empty(), "{diags:#?}");
}

#[tokio::test]
async fn positions_count_utf16_units_after_non_ascii_text() {
    let mut c = TestClient::new().await;
    let path = fixture("unicode/rules.btrules");
    let text = text_of(&path);
    let u = c.open(&path).await;
    let diags = c.diagnostics_for(&u).await;
    assert_eq!(codes(&diags), ["R006"]);
    let (line, col) = pos(&text, "?too", 0);
    // `𝄞𝄞` before it count 4 UTF-16 units, not 2 characters or 8 bytes.
    assert_eq!(col, 72);
    assert_eq!(range(&diags[0]), [line as u64, 72, line as u64, 76]);
    // Hover after the non-ASCII comment finds the node.
    let (l, ccol) = pos(&text, "MoveTo(robot: ?robot, target: ?too", 2);
    let h = c.at("textDocument/hover", &u, l, ccol).await;
    assert!(
        hover_text(&h).contains("action MoveTo(robot: robot, target: container)"),
        "{h}"
    );
    // An edit inside the line with the clef, in UTF-16 columns: `?too` -> `?to`.
    c.change(&u, 2, [line, 75, line, 76], "").await;
    assert!(c.diagnostics_for(&u).await.is_empty());
}

#[tokio::test]
async fn references_symbols_and_workspace_symbols() {
    let mut c = TestClient::new().await;
    let path = ariac();
    let text = text_of(&path);
    let u = c.open(&path).await;
    let (l, col) = pos(&text, "condition RobotNormal", 11);
    let refs = c
        .request(
            "textDocument/references",
            json!({ "textDocument": { "uri": u }, "position": { "line": l, "character": col }, "context": { "includeDeclaration": true } }),
        )
        .await;
    // The declaration, the plan's monitor and two rule calls.
    assert_eq!(array(&refs).len(), 4, "{refs:#?}");

    let syms = c
        .request(
            "textDocument/documentSymbol",
            json!({ "textDocument": { "uri": u } }),
        )
        .await;
    let names = each(array(&syms), "name");
    assert!(
        names.contains(&"MoveTo")
            && names.contains(&"rule (grasp ?robot ?part ?bin)")
            && names.contains(&"plan"),
        "{names:?}"
    );

    let ws = c
        .request("workspace/symbol", json!({ "query": "grasp" }))
        .await;
    let names = each(array(&ws), "name");
    assert!(
        names.contains(&"Grasp") && names.contains(&"rule (grasp ?robot ?part ?bin)"),
        "{names:?}"
    );
}

async fn labels(c: &mut TestClient, u: &url::Url, line: u32, col: u32) -> Vec<String> {
    let r = c.at("textDocument/completion", u, line, col).await;
    each(array(&r), "label")
        .into_iter()
        .map(str::to_owned)
        .collect()
}

mod url {
    pub use tower_lsp::lsp_types::Url;
}

#[tokio::test]
async fn completion_knows_its_context() {
    let mut c = TestClient::new().await;
    let path = ariac();
    let base = text_of(&path);
    // One unfinished item per context, after the example's own text.
    let extra = [
        "rule (",
        "rule (flip ?robot ?part ?c) {",
        "    Flip(robot: ?robot, ",
        "}",
        "rule (flip ?robot ?part ?c) {",
        "    ",
        "}",
        "rule (flip ?robot ?part ?c) {",
        "    Flip(robot: ?robot, part: ?part, container: ?c)",
        "    effect (and (",
        "}",
    ];
    let first = base.lines().count() as u32;
    let text = format!("{base}{}\n", extra.join("\n"));
    let u = c.open_text(&path, &text).await;
    let line = |k: u32| first + k;

    let head = labels(&mut c, &u, line(0), 6).await;
    assert_eq!(head, ["flip", "grasp", "move", "place"]);

    let ports = labels(&mut c, &u, line(2), 25).await;
    assert_eq!(ports, ["part", "container"], "ports not given yet");

    let vars = labels(&mut c, &u, line(2), 16).await;
    assert_eq!(vars, ["?robot", "?part", "?c"]);
    // Each replaces the `?` typed already, whatever the client counts as a word.
    let r = c.at("textDocument/completion", &u, line(2), 18).await;
    assert_eq!(
        r[0]["textEdit"]["range"],
        json!({ "start": { "line": line(2), "character": 16 }, "end": { "line": line(2), "character": 18 } })
    );
    assert_eq!(r[0]["textEdit"]["newText"], "?robot");

    let template = labels(&mut c, &u, line(5), 4).await;
    assert!(
        template.contains(&"MoveTo".to_owned()) && template.contains(&"sequence".to_owned()),
        "{template:?}"
    );

    let preds = labels(&mut c, &u, line(9), 17).await;
    assert!(
        preds.contains(&"attach".to_owned()) && preds.contains(&"not".to_owned()),
        "{preds:?}"
    );

    let p3 = fixture("p3_assembler/rules.btrules");
    let p3text = text_of(&p3).replacen("marker_pick[op]", "marker_pick[]", 1);
    let u3 = c.open_text(&p3, &p3text).await;
    let (l, col) = pos(&p3text, "marker_pick[]", 12);
    assert_eq!(labels(&mut c, &u3, l, col).await, ["OP1", "OP2", "OP3"]);
}

#[tokio::test]
async fn signature_help_marks_the_active_port() {
    let mut c = TestClient::new().await;
    let path = ariac();
    let text = text_of(&path);
    let u = c.open(&path).await;
    let (l, col) = pos(&text, "part: ?part, source: ?bin", 0);
    let s = c.at("textDocument/signatureHelp", &u, l, col).await;
    assert_eq!(
        s["signatures"][0]["label"],
        "Grasp(robot: robot, part: part, source: container)"
    );
    assert_eq!(s["activeParameter"], 1);
    let r = &s["signatures"][0]["parameters"][1]["label"];
    assert_eq!(r, &json!([20, 30]));
}

#[tokio::test]
async fn semantic_tokens_inlay_hints_and_formatting() {
    let mut c = TestClient::new().await;
    let path = ariac();
    let text = text_of(&path);
    let u = c.open(&path).await;
    let t = c
        .request(
            "textDocument/semanticTokens/full",
            json!({ "textDocument": { "uri": u } }),
        )
        .await;
    let data = array(&t["data"]);
    assert_eq!(data.len() % 5, 0);
    // The first token is the first comment: line 0, column 0, type comment.
    let comment = btc_lsp::highlight::TOKEN_TYPES
        .iter()
        .position(|t| *t == tower_lsp::lsp_types::SemanticTokenType::COMMENT)
        .unwrap();
    assert_eq!(
        &data[..5],
        &[
            json!(0),
            json!(0),
            json!(text.lines().next().unwrap().len()),
            json!(comment),
            json!(0)
        ]
    );
    assert!(data.len() / 5 > 100);

    let hints = c
        .request(
            "textDocument/inlayHint",
            json!({ "textDocument": { "uri": u }, "range": { "start": { "line": 0, "character": 0 }, "end": { "line": 200, "character": 0 } } }),
        )
        .await;
    let (l, col) = pos(&text, "?bin) {", 4);
    let h = array(&hints)
        .iter()
        .find(|h| h["position"] == json!({ "line": l, "character": col }))
        .expect("a hint after ?bin");
    assert_eq!(h["label"], ": container");

    // A badly laid out document formats to what `btc fmt` writes.
    let messy = text.replace(
        "rule (flip ?robot ?part ?c) {\n    Flip",
        "rule (flip ?robot ?part ?c)   {Flip",
    );
    c.change(&u, 2, [0, 0, 999, 0], &messy).await;
    let edits = c
        .request("textDocument/formatting", json!({ "textDocument": { "uri": u }, "options": { "tabSize": 4, "insertSpaces": true } }))
        .await;
    assert_eq!(
        apply(&messy, &edits),
        btc_lang::rules::fmt::format(&messy).unwrap()
    );
}

#[tokio::test]
async fn quick_fixes_write_the_pddl_effect_and_rule_stubs() {
    let mut c = TestClient::new().await;
    let path = ariac();
    let text = text_of(&path).replace(
        "(on ?part ?agv) (not (attach ?part ?robot))",
        "(on ?part ?agv)",
    );
    let u = c.open_text(&path, &text).await;
    let diags = c.diagnostics_for(&u).await;
    assert_eq!(codes(&diags), ["R005"]);
    let fixed = code_action(
        &mut c,
        &u,
        &text,
        diags[0]["range"].clone(),
        json!(diags),
        "write the PDDL action's effect",
    )
    .await;
    assert!(
        fixed.contains("effect (and (not (attach ?part ?robot)) (on ?part ?agv))"),
        "{fixed}"
    );
    c.change(&u, 2, [0, 0, 999, 0], &fixed).await;
    assert!(c.diagnostics_for(&u).await.is_empty());

    // Stubs for the three uncovered actions, which then check clean.
    let stubs = fixture("stubs/rules.btrules");
    let stext = text_of(&stubs);
    let us = c.open(&stubs).await;
    let with_stubs = code_action(
        &mut c,
        &us,
        &stext,
        json!({ "start": { "line": 0, "character": 0 }, "end": { "line": 0, "character": 0 } }),
        json!([]),
        "Add rule stubs for 3 uncovered domain actions",
    )
    .await;
    assert!(with_stubs.contains("rule (grasp ?robot ?part ?container) {\n    Grasp(robot: ?robot, part: ?part, container: ?container)\n}"), "{with_stubs}");
    let mut db = btc_lang::db::Database::new();
    db.set_file("d/domain.pddl", text_of(&fixture("ariac/domain.pddl")));
    let f = db.set_file(
        "d/rules.btrules",
        with_stubs.replace("../ariac/domain.pddl", "domain.pddl"),
    );
    let left: Vec<&str> = btc_lang::db::rules_diagnostics(&db, f)
        .iter()
        .map(|d| d.code)
        .collect();
    assert!(left.is_empty(), "{left:?}");
}

#[tokio::test]
async fn a_domain_changed_on_disk_rechecks_the_rules_that_use_it() {
    let dir = tempfile::tempdir().unwrap();
    for f in ["rules.btrules", "domain.pddl"] {
        std::fs::copy(fixture("ariac").join(f), dir.path().join(f)).unwrap();
    }
    let mut c = TestClient::new().await;
    let u = c.open(&dir.path().join("rules.btrules")).await;
    assert!(c.diagnostics_for(&u).await.is_empty());
    let domain = dir.path().join("domain.pddl");
    let changed = text_of(&domain).replace("(:action grasp", "(:action grab");
    std::fs::write(&domain, changed).unwrap();
    c.notify(
        "workspace/didChangeWatchedFiles",
        json!({ "changes": [{ "uri": uri(&domain), "type": 2 }] }),
    )
    .await;
    let diags = c.diagnostics_for(&u).await;
    assert_eq!(codes(&diags), ["R002"], "{diags:#?}");
    assert!(diags[0]["message"].as_str().unwrap().contains("grasp"));
}

#[tokio::test]
async fn a_domain_edited_in_the_editor_rechecks_the_rules_and_reports_its_own_errors() {
    let mut c = TestClient::new().await;
    let u = c.open(&ariac()).await;
    assert!(c.diagnostics_for(&u).await.is_empty());
    let domain = fixture("ariac/domain.pddl");
    let ud = url::Url::from_file_path(&domain).unwrap();
    assert_eq!(codes(&c.diagnostics_for(&ud).await), ["P108"]);
    let text = text_of(&domain).replace("(:action place", "(:action put");
    let ud = c.open_text(&domain, &text).await;
    // The rules now name an action the domain lacks...
    let diags = c.diagnostics_for(&u).await;
    assert_eq!(codes(&diags), ["R002"], "{diags:#?}");
    // ... and the domain gets its own warning and the action no rule covers.
    let dd = c.diagnostics_for(&ud).await;
    assert_eq!(codes(&dd), ["R012", "P108"]);
    // Undoing the edit clears the rules file again.
    c.notify(
        "textDocument/didChange",
        json!({ "textDocument": { "uri": ud, "version": 2 }, "contentChanges": [{ "text": text_of(&domain) }] }),
    )
    .await;
    assert!(c.diagnostics_for(&u).await.is_empty());
}

#[tokio::test]
async fn an_undeclared_predicate_is_declared_by_its_quick_fix() {
    let mut c = TestClient::new().await;
    let domain = fixture("ariac/domain.pddl");
    let declared = text_of(&domain);
    let text = declared.replace("\n    (flip_on ?part - part ?container - container)", "");
    assert_ne!(text, declared);
    let ud = c.open_text(&domain, &text).await;
    let diags = c.diagnostics_for(&ud).await;
    let p102 = diags.iter().find(|d| d["code"] == "P102").unwrap();
    let fixed = code_action(
        &mut c,
        &ud,
        &text,
        p102["range"].clone(),
        json!([]),
        "declare `(flip_on ?part - part ?container - container)`",
    )
    .await;
    assert_eq!(fixed, declared);
}
