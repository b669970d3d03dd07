//! `btc lsp` as an editor meets it on a bad day: malformed JSON-RPC of every
//! kind (it answers with the JSON-RPC error where there is an id, finds the
//! next header and keeps serving), requests out of order, a client that
//! vanishes with a request of the server's unanswered, a storm of edits
//! (positions past the end, overlapping and out-of-range ranges, 1,000
//! edits without waiting) after which the server's text is the client's,
//! and a document over the size limit.

use btc_lsp::convert::LineIndex;
mod common;

use common::{frame, Lsp};
use serde_json::{json, Value};
use std::time::Duration;
use tower_lsp::lsp_types::Position;

#[test]
fn malformed_messages_are_answered_and_the_server_keeps_serving() {
    let mut c = Lsp::start();
    c.initialize();
    let bad: Vec<Vec<u8>> = vec![
        frame(b"{"),
        frame(b"[]"),
        frame(b"{}"),
        frame(b"null"),
        frame(b"{\"jsonrpc\":\"2.0\",\"method\":\"textDocument/didOpen\",\"params\":{\"x\":\"\xff\xfe\"}}"),
        frame(br#"{"jsonrpc":"2.0","method":"textDocument/didChange","params":{"textDocument":{"uri":"file:///a.btrules","version":2},"contentChanges":[{"text":"\ud800"}]}}"#),
        b"Content-Length: -5\r\n\r\n".to_vec(),
        b"Content-Length: abc\r\n\r\n".to_vec(),
        b"Content-Type: application/json\r\n\r\n{}".to_vec(),
        b"Content-Length: 4000000000\r\n\r\n".to_vec(),
        b"this is not a header\r\n".to_vec(),
        b"\x00\x01\x02 garbage\n\n".to_vec(),
        frame(b"{\"jsonrpc\":\"2.0\",\"id\":1,\"result\":"),
    ];
    for b in &bad {
        c.raw(b);
        c.alive();
    }
    // LF-only headers are read.
    c.next_id += 1;
    let id = c.next_id;
    let body = json!({ "jsonrpc": "2.0", "id": id, "method": "workspace/symbol", "params": { "query": "" } }).to_string();
    c.raw(format!("Content-Length: {}\n\n{body}", body.len()).as_bytes());
    let r = c.wait_for(|m| m["id"] == id);
    assert!(r.get("result").is_some(), "{r}");
    // A request with an id but a bad shape gets its error under that id.
    c.send(json!({ "jsonrpc": "2.0", "id": 77, "method": "textDocument/hover", "params": 3 }));
    let r = c.wait_for(|m| m["id"] == 77);
    assert_eq!(r["error"]["code"], -32600, "{r}");
    c.send(json!({ "jsonrpc": "1.0", "id": 78, "method": "x" }));
    let r = c.wait_for(|m| m["id"] == 78);
    assert_eq!(r["error"]["code"], -32600, "{r}");
    // Unknown methods: method not found.
    let r = c.request("btc/noSuchMethod", json!({}));
    assert_eq!(r["error"]["code"], -32601, "{r}");
    // Parse errors are answered with id null.
    c.raw(&frame(b"{\"id\": 5,"));
    let r = c.wait_for(|m| m["error"]["code"] == -32700);
    assert!(r["id"].is_null());
    c.alive();
}

#[test]
fn requests_before_initialize_and_after_shutdown_are_refused() {
    let mut c = Lsp::start();
    let r = c.request("textDocument/hover", json!({ "textDocument": { "uri": "file:///x.btrules" }, "position": { "line": 0, "character": 0 } }));
    assert_eq!(r["error"]["code"], -32002, "{r}");
    c.initialize();
    let r = c.request("shutdown", Value::Null);
    assert!(r.get("result").is_some(), "{r}");
    let r = c.request("workspace/symbol", json!({ "query": "" }));
    assert_eq!(r["error"]["code"], -32600, "{r}");
    c.notify("exit", Value::Null);
    assert_eq!(c.exit_status(Duration::from_secs(10)).code(), Some(0));
}

#[test]
fn exit_without_shutdown_exits_with_1() {
    let mut c = Lsp::start();
    c.initialize();
    c.notify("exit", Value::Null);
    assert_eq!(c.exit_status(Duration::from_secs(10)).code(), Some(1));
}

#[test]
fn closing_stdin_ends_the_server_with_a_request_of_its_own_unanswered() {
    let mut c = Lsp::start();
    c.initialize();
    // After `initialized` the server asks to register file watchers; this
    // client never answers.
    c.wait_for(|m| m["method"] == "client/registerCapability");
    c.stdin = None;
    let status = c.exit_status(Duration::from_secs(10));
    assert_eq!(status.code(), Some(1));
}

/// A small deterministic generator (xorshift64*).
struct Rng(u64);

impl Rng {
    fn below(&mut self, n: u64) -> u64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        self.0.wrapping_mul(0x2545_F491_4F6C_DD1D) % n.max(1)
    }
}

fn apply(text: &mut String, range: Option<(Position, Position)>, new: &str) {
    match range {
        Some((a, b)) => {
            let ix = LineIndex::new(text);
            let (x, y) = (ix.offset(a), ix.offset(b));
            text.replace_range(x.min(y)..x.max(y), new);
        }
        None => *text = new.to_owned(),
    }
}

#[test]
fn after_a_storm_of_edits_the_server_has_the_clients_text() {
    let mut c = Lsp::start();
    c.initialize();
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/ariac");
    let path = dir.join("rules.btrules");
    let uri = url(&path);
    let mut text = std::fs::read_to_string(&path).unwrap();
    c.notify(
        "textDocument/didOpen",
        json!({ "textDocument": { "uri": uri, "languageId": "btrules", "version": 1, "text": text } }),
    );
    let pieces = ["a", "é", "𝄞", "\n", "// x\n", "{", "}", "", "  ", "\r\n"];
    let mut rng = Rng(0x9E37_79B9_7F4A_7C15);
    for version in 2..1002 {
        let lines = text.lines().count() as u64 + 1;
        let mut changes = Vec::new();
        // One to three changes per notification, applied in order; ranges
        // may run past the end, be reversed or overlap each other.
        for _ in 0..1 + rng.below(3) {
            let pos =
                |rng: &mut Rng| Position::new(rng.below(lines + 3) as u32, rng.below(90) as u32);
            let a = pos(&mut rng);
            let b = if rng.below(2) == 0 { a } else { pos(&mut rng) };
            let b = if b.line > a.line + 2 {
                Position::new(a.line + 1, b.character)
            } else {
                b
            };
            let new = pieces[rng.below(pieces.len() as u64) as usize];
            let new = if text.len() > 20_000 { "" } else { new };
            apply(&mut text, Some((a, b)), new);
            changes.push(json!({ "range": { "start": a, "end": b }, "text": new }));
        }
        c.notify(
            "textDocument/didChange",
            json!({ "textDocument": { "uri": uri, "version": version }, "contentChanges": changes }),
        );
    }
    // The server's text: a whole-document replacement cannot be asked for,
    // but formatting a parsable text can. Replace everything with the
    // client's text plus a known tail through one more ranged edit, then
    // compare the server's formatting with the client's.
    let end = LineIndex::new(&text).position(text.len());
    let tail = "\n// the end\n";
    apply(&mut text, Some((end, end)), tail);
    c.notify(
        "textDocument/didChange",
        json!({ "textDocument": { "uri": uri, "version": 1002 },
                "contentChanges": [{ "range": { "start": end, "end": end }, "text": tail }] }),
    );
    let r = c.request(
        "textDocument/semanticTokens/full",
        json!({ "textDocument": { "uri": uri } }),
    );
    assert!(r.get("result").is_some(), "{r}");
    // Replace the whole text by ranged edits from (0,0) to past the end:
    // the server must clamp exactly as the client does.
    let original = std::fs::read_to_string(&path).unwrap();
    let far = Position::new(1_000_000, 0);
    apply(&mut text, Some((Position::new(0, 0), far)), &original);
    c.notify(
        "textDocument/didChange",
        json!({ "textDocument": { "uri": uri, "version": 1003 },
                "contentChanges": [{ "range": { "start": { "line": 0, "character": 0 }, "end": far }, "text": original }] }),
    );
    let r = c.request(
        "textDocument/formatting",
        json!({ "textDocument": { "uri": uri }, "options": { "tabSize": 4, "insertSpaces": true } }),
    );
    let mut server = text.clone();
    for e in r["result"]
        .as_array()
        .expect("the text parses, so it formats")
    {
        let range = &e["range"];
        let p = |v: &Value| {
            Position::new(
                v["line"].as_u64().unwrap() as u32,
                v["character"].as_u64().unwrap() as u32,
            )
        };
        apply(
            &mut server,
            Some((p(&range["start"]), p(&range["end"]))),
            e["newText"].as_str().unwrap(),
        );
    }
    let expected = btc_lang::rules::fmt::format(&text).unwrap();
    assert_eq!(server, expected);
}

/// Storm check at the level of the text itself: random edits then a
/// formatting of a text that must equal the client's copy exactly.
#[test]
fn rapid_edits_inside_a_comment_leave_the_same_text() {
    let mut c = Lsp::start();
    c.initialize();
    let path =
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/ariac/rules.btrules");
    let uri = url(&path);
    let mut text = std::fs::read_to_string(&path).unwrap();
    text.push_str("// ");
    c.notify(
        "textDocument/didOpen",
        json!({ "textDocument": { "uri": uri, "languageId": "btrules", "version": 1, "text": text } }),
    );
    let last_line = text.lines().count() as u32 - 1;
    let mut rng = Rng(42);
    for version in 2..1002 {
        let width = text.lines().last().unwrap().encode_utf16().count() as u64;
        let a = Position::new(last_line, 3 + rng.below(width.saturating_sub(2)) as u32);
        let b = Position::new(last_line, a.character + rng.below(3) as u32);
        let new = ["x", "é", "𝄞", "", "yz"][rng.below(5) as usize];
        apply(&mut text, Some((a, b)), new);
        c.notify(
            "textDocument/didChange",
            json!({ "textDocument": { "uri": uri, "version": version },
                    "contentChanges": [{ "range": { "start": a, "end": b }, "text": new }] }),
        );
    }
    let r = c.request(
        "textDocument/formatting",
        json!({ "textDocument": { "uri": uri }, "options": { "tabSize": 4, "insertSpaces": true } }),
    );
    let mut server = text.clone();
    for e in r["result"].as_array().expect("formats") {
        let range = &e["range"];
        let p = |v: &Value| {
            Position::new(
                v["line"].as_u64().unwrap() as u32,
                v["character"].as_u64().unwrap() as u32,
            )
        };
        apply(
            &mut server,
            Some((p(&range["start"]), p(&range["end"]))),
            e["newText"].as_str().unwrap(),
        );
    }
    assert_eq!(server, btc_lang::rules::fmt::format(&text).unwrap());
}

fn url(p: &std::path::Path) -> String {
    tower_lsp::lsp_types::Url::from_file_path(p)
        .unwrap()
        .to_string()
}

#[test]
fn a_document_over_the_limit_is_not_analysed_and_says_so() {
    let mut c = Lsp::start();
    c.initialize();
    let uri = "file:///tmp/huge.btrules";
    let text = "// padding\n".repeat(btc_lsp::workspace::MAX_ANALYSED / 11 + 10);
    c.notify(
        "textDocument/didOpen",
        json!({ "textDocument": { "uri": uri, "languageId": "btrules", "version": 1, "text": text } }),
    );
    let d = c.wait_for(|m| {
        m["method"] == "textDocument/publishDiagnostics" && m["params"]["uri"] == uri
    });
    let codes: Vec<&str> = d["params"]["diagnostics"]
        .as_array()
        .unwrap()
        .iter()
        .map(|d| d["code"].as_str().unwrap())
        .collect();
    assert_eq!(codes, ["F006"]);
    c.alive();
}
