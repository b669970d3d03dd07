//! `btc check` and the language server report the same diagnostics for the
//! same files (#10.6): every rules file of `examples/` and `tests/fixtures/`
//! is checked by `btc check --format json` and opened in a fresh `btc lsp`,
//! and each file's diagnostics — where they start and end, severity, code,
//! message and hint — must be the same, in the same order.
//!
//! The corpus domains' rules (`tests/corpus_rules/`) are compared when the
//! IPC corpus is there (skipped without it, failing under CI=true).
//!
//! Both go through `btc_lang::project::project_report`; this test is what
//! keeps a front door from drifting away from it (filtering, capping,
//! conversion of positions, files reported twice or not at all).

mod common;

use common::Lsp;
use serde_json::{json, Value};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::{Duration, Instant};
use tower_lsp::lsp_types::Url;

/// One diagnostic, as both front doors can say it: 1-based line and
/// column of its start and end (columns in characters), and the LSP's
/// message form (the hint after the message).
#[derive(Debug, PartialEq)]
struct Reported {
    start: (u64, u64),
    end: (u64, u64),
    severity: String,
    code: String,
    message: String,
}

type ByFile = BTreeMap<Url, Vec<Reported>>;

fn repo() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// Every `.btrules` file under `dir`, sorted.
fn rules_files(dir: &Path, out: &mut Vec<PathBuf>) {
    let mut entries: Vec<PathBuf> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .collect();
    entries.sort();
    for p in entries {
        if p.is_dir() {
            rules_files(&p, out);
        } else if p.extension().is_some_and(|e| e == "btrules") {
            out.push(p);
        }
    }
}

fn position(v: &Value) -> (u64, u64) {
    (v["line"].as_u64().unwrap(), v["column"].as_u64().unwrap())
}

/// What `btc check --format json` reports, by file.
fn by_check(rules: &Path) -> ByFile {
    let out = Command::new(env!("CARGO_BIN_EXE_btc"))
        .args(["check", "--format", "json"])
        .arg(rules)
        .current_dir(repo())
        .output()
        .unwrap();
    let v: Value = serde_json::from_slice(&out.stdout).unwrap_or_else(|e| {
        panic!(
            "{}: btc check wrote no JSON ({e}): {}",
            rules.display(),
            String::from_utf8_lossy(&out.stderr)
        )
    });
    let mut files = ByFile::new();
    for d in v["diagnostics"].as_array().unwrap() {
        let file = repo().join(d["file"].as_str().unwrap());
        let mut message = d["message"].as_str().unwrap().to_owned();
        if let Some(h) = d["hint"].as_str() {
            message.push_str("\nhint: ");
            message.push_str(h);
        }
        files
            .entry(Url::from_file_path(&file).unwrap())
            .or_default()
            .push(Reported {
                start: position(&d["start"]),
                end: position(&d["end"]),
                severity: d["severity"].as_str().unwrap().to_owned(),
                code: d["code"].as_str().unwrap().to_owned(),
                message,
            });
    }
    files
}

/// An LSP position (0-based, the column in UTF-16 units) as `btc check`
/// says it (1-based, the column in characters), on the file's text.
fn lsp_position(text: &str, v: &Value) -> (u64, u64) {
    let line = v["line"].as_u64().unwrap();
    let mut units = v["character"].as_u64().unwrap();
    let mut chars = 0;
    for c in text.lines().nth(line as usize).unwrap_or("").chars() {
        if units == 0 {
            break;
        }
        units = units.saturating_sub(c.len_utf16() as u64);
        chars += 1;
    }
    (line + 1, chars + 1)
}

fn lsp_reported(text: &str, d: &Value) -> Reported {
    Reported {
        start: lsp_position(text, &d["range"]["start"]),
        end: lsp_position(text, &d["range"]["end"]),
        severity: match d["severity"].as_u64() {
            Some(1) => "error",
            Some(2) => "warning",
            other => panic!("severity {other:?}"),
        }
        .to_owned(),
        code: d["code"].as_str().unwrap().to_owned(),
        message: d["message"].as_str().unwrap().to_owned(),
    }
}

/// A `publishDiagnostics` notification's file and list.
fn published(m: &Value) -> (Url, Vec<Reported>) {
    let at = Url::parse(m["params"]["uri"].as_str().unwrap()).unwrap();
    let bytes = std::fs::read(at.to_file_path().unwrap()).unwrap_or_default();
    let text = String::from_utf8_lossy(&bytes);
    let list = m["params"]["diagnostics"]
        .as_array()
        .unwrap()
        .iter()
        .map(|d| lsp_reported(&text, d))
        .collect();
    (at, list)
}

/// What the language server publishes once `rules` is opened with its
/// text from disk: the last list per file, until every file `expected`
/// names has been published and a request sent after that is answered.
fn by_lsp(rules: &Path, text: &str, expected: &ByFile) -> ByFile {
    let mut c = Lsp::start();
    c.initialize();
    let uri = Url::from_file_path(rules).unwrap();
    c.notify(
        "textDocument/didOpen",
        json!({ "textDocument": {
            "uri": uri.as_str(), "languageId": "btrules", "version": 1, "text": text
        } }),
    );
    let mut files = ByFile::new();
    let mut seen_root = false;
    let deadline = Instant::now() + Duration::from_secs(30);
    while !seen_root || expected.keys().any(|u| !files.contains_key(u)) {
        let left = deadline.saturating_duration_since(Instant::now());
        let m = c.out.recv_timeout(left).unwrap_or_else(|_| {
            panic!(
                "{}: the server published {:?} of {:?} within 30 s",
                rules.display(),
                files.keys().collect::<Vec<_>>(),
                expected.keys().collect::<Vec<_>>()
            )
        });
        if m["method"] != "textDocument/publishDiagnostics" {
            continue;
        }
        let (at, list) = published(&m);
        seen_root |= at == uri;
        files.insert(at, list);
    }
    // Anything else published in the same round arrives before the answer.
    c.next_id += 1;
    let id = c.next_id;
    c.send(json!({ "jsonrpc": "2.0", "id": id, "method": "workspace/symbol", "params": { "query": "" } }));
    loop {
        let m = c.out.recv_timeout(Duration::from_secs(30)).unwrap();
        if m["id"] == id && m.get("method").is_none() {
            break;
        }
        if m["method"] == "textDocument/publishDiagnostics" {
            let (at, list) = published(&m);
            files.insert(at, list);
        }
    }
    files.retain(|_, l| !l.is_empty());
    files
}

#[test]
fn btc_check_and_the_language_server_agree_on_every_rules_file() {
    let mut all = Vec::new();
    rules_files(&repo().join("examples"), &mut all);
    rules_files(&repo().join("tests/fixtures"), &mut all);
    assert!(all.len() > 40, "{} rules files", all.len());
    // The corpus domains' rules name their domains in the shared corpus.
    if btc_testkit::corpus().is_some() {
        rules_files(&repo().join("tests/corpus_rules"), &mut all);
    }
    let mut compared = 0;
    let mut disagreements = Vec::new();
    for rules in &all {
        // An editor decodes the documents it opens: a rules file that is
        // not UTF-8 reaches the server as other text than `btc check` reads.
        let Ok(text) = std::fs::read_to_string(rules) else {
            continue;
        };
        let check = by_check(rules);
        let lsp = by_lsp(rules, &text, &check);
        compared += 1;
        if check != lsp {
            disagreements.push(format!(
                "{}:\n  btc check: {check:#?}\n  btc lsp: {lsp:#?}",
                rules.display()
            ));
        }
    }
    assert!(compared > 40, "only {compared} files compared");
    assert!(
        disagreements.is_empty(),
        "{} of {compared} rules files disagree:\n{}",
        disagreements.len(),
        disagreements.join("\n")
    );
}
