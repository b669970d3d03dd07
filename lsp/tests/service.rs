//! The requests through the real service (JSON-RPC into tower-lsp's
//! `LspService`): the wire shapes of what `tests/cursor.rs` checks on the
//! library, and a smoke test over the examples that asserts invariants
//! only (every request at every token answers, none with an internal
//! error), so changing an example breaks nothing here.

mod common;

use common::{pos, repo, TestClient};
use serde_json::{json, Value};
use std::path::{Path, PathBuf};

fn cursor_fixture(feature: &str, name: &str) -> (PathBuf, String, (u32, u32)) {
    let path = repo()
        .join("lsp/tests/fixtures/cursor")
        .join(feature)
        .join(format!("{name}.btrules"));
    let marked = std::fs::read_to_string(&path).unwrap();
    let at = pos(&marked, "$0", 0);
    (path, marked.replacen("$0", "", 1), at)
}

fn position(u: &tower_lsp::lsp_types::Url, (line, character): (u32, u32)) -> Value {
    json!({ "textDocument": { "uri": u }, "position": { "line": line, "character": character } })
}

#[tokio::test]
async fn a_pattern_matching_two_actions_has_two_definitions() {
    let mut c = TestClient::new().await;
    let (path, text, at) = cursor_fixture("definition", "head_matching_two_actions");
    let u = c.open_text(&path, &text).await;
    let d = c.request("textDocument/definition", position(&u, at)).await;
    let uris: Vec<&str> = d
        .as_array()
        .expect("several locations")
        .iter()
        .map(|l| l["uri"].as_str().unwrap())
        .collect();
    assert_eq!(uris.len(), 2, "{d:#}");
    assert!(
        uris.iter().all(|u| u.ends_with("/cursor/domain.pddl")),
        "{d:#}"
    );
}

#[tokio::test]
async fn prepare_rename_gives_the_range_or_refuses_with_an_error() {
    let caps = serde_json::to_value(btc_lsp::server::capabilities()).unwrap();
    assert_eq!(caps["renameProvider"]["prepareProvider"], true);
    assert_eq!(caps["documentHighlightProvider"], true);
    let mut c = TestClient::new().await;

    let (path, text, at) = cursor_fixture("rename", "rule_variable");
    let u = c.open_text(&path, &text).await;
    let range = c
        .request("textDocument/prepareRename", position(&u, at))
        .await;
    assert_eq!(range["start"]["line"], at.0, "{range:#}");
    assert_eq!(
        range["end"]["character"].as_u64().unwrap() - range["start"]["character"].as_u64().unwrap(),
        2,
        "`?p`: {range:#}"
    );

    let (path, text, at) = cursor_fixture("rename", "refused_pddl_predicate");
    let u = c.open_text(&path, &text).await;
    let err = c
        .try_request("textDocument/prepareRename", position(&u, at))
        .await
        .unwrap_err();
    assert!(err.contains("PDDL names"), "{err}");
}

#[tokio::test]
async fn highlights_and_a_rename_across_files() {
    let mut c = TestClient::new().await;
    let (path, text, at) = cursor_fixture("highlight", "rule_variable");
    let u = c.open_text(&path, &text).await;
    let h = c
        .request("textDocument/documentHighlight", position(&u, at))
        .await;
    let kinds: Vec<u64> = h
        .as_array()
        .unwrap()
        .iter()
        .map(|h| h["kind"].as_u64().unwrap())
        .collect();
    // The parameter is written once (3 = write) and read four times (2).
    assert_eq!(kinds, [3, 2, 2, 2, 2], "{h:#}");

    // In a fresh server: an open file that imports the same node would
    // be renamed too.
    let mut c = TestClient::new().await;
    let (path, text, at) = cursor_fixture("rename", "node_across_files");
    let u = c.open_text(&path, &text).await;
    let mut params = position(&u, at);
    params["newName"] = json!("Armed");
    let edit = c.request("textDocument/rename", params).await;
    let files: Vec<&String> = edit["changes"].as_object().unwrap().keys().collect();
    assert_eq!(files.len(), 2, "this file and the imported one: {edit:#}");
}

/// Every rules file under `dir`, recursively.
fn rules_files(dir: &Path, out: &mut Vec<PathBuf>) {
    for e in std::fs::read_dir(dir).unwrap() {
        let p = e.unwrap().path();
        if p.is_dir() {
            rules_files(&p, out);
        } else if p.extension().is_some_and(|e| e == "btrules") {
            out.push(p);
        }
    }
}

#[tokio::test]
async fn every_request_at_every_token_of_the_examples_answers() {
    let mut c = TestClient::new().await;
    let mut files = Vec::new();
    rules_files(&repo().join("examples"), &mut files);
    files.sort();
    assert!(files.len() >= 2, "{files:?}");
    let mut asked = 0;
    for path in files {
        let text = std::fs::read_to_string(&path).unwrap();
        let u = c.open_text(&path, &text).await;
        let doc = json!({ "textDocument": { "uri": u } });
        for method in [
            "textDocument/semanticTokens/full",
            "textDocument/documentSymbol",
        ] {
            c.request(method, doc.clone()).await;
        }
        let lex = btc_lang::rules::lexer::lex(&text, 0);
        for (_, span) in &lex.tokens {
            let before = &text[..span.start as usize];
            let line = before.matches('\n').count() as u32;
            let col = before.rsplit('\n').next().unwrap().encode_utf16().count() as u32;
            let p = position(&u, (line, col));
            for method in [
                "textDocument/hover",
                "textDocument/definition",
                "textDocument/documentHighlight",
                "textDocument/completion",
                "textDocument/signatureHelp",
            ] {
                c.request(method, p.clone()).await;
                asked += 1;
            }
            let mut refs = p.clone();
            refs["context"] = json!({ "includeDeclaration": true });
            c.request("textDocument/references", refs).await;
            // Refusals are invalid-params errors, never internal ones.
            if let Err(e) = c.try_request("textDocument/prepareRename", p.clone()).await {
                assert!(
                    !e.contains("btc failed"),
                    "{}:{line}:{col}: {e}",
                    path.display()
                );
            }
            asked += 2;
        }
    }
    assert!(asked > 1000, "{asked}");
}
