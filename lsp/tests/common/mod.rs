//! An in-process LSP client: JSON-RPC messages into the real service,
//! server-to-client messages out of its socket. Server requests (dynamic
//! registration) are answered; published diagnostics are collected.

#![allow(dead_code)] // each test file uses a part

use futures::{SinkExt, StreamExt};
use serde_json::{json, Value};
use std::path::{Path, PathBuf};
use tokio::sync::mpsc;
use tower::{Service, ServiceExt};
use tower_lsp::jsonrpc::{Request, Response};
use tower_lsp::lsp_types::Url;
use tower_lsp::LspService;

pub struct TestClient {
    service: LspService<btc_lsp::server::Backend>,
    diagnostics: mpsc::UnboundedReceiver<Value>,
    /// The newest batch received for each other file while waiting for one.
    pending: Vec<Value>,
    next_id: i64,
}

pub fn repo() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("..")
        .canonicalize()
        .unwrap()
}

pub fn uri(path: &Path) -> Url {
    Url::from_file_path(path).unwrap()
}

impl TestClient {
    pub async fn new() -> TestClient {
        let (service, socket) = LspService::new(btc_lsp::server::Backend::new);
        let (tx, rx) = mpsc::unbounded_channel();
        let (mut stream, mut sink) = socket.split();
        tokio::spawn(async move {
            while let Some(req) = stream.next().await {
                match req.id().cloned() {
                    // A request of the server's: say yes.
                    Some(id) => {
                        let _ = sink.send(Response::from_ok(id, Value::Null)).await;
                    }
                    None if req.method() == "textDocument/publishDiagnostics" => {
                        let _ = tx.send(req.params().cloned().unwrap_or(Value::Null));
                    }
                    None => {}
                }
            }
        });
        let mut c = TestClient {
            service,
            diagnostics: rx,
            pending: Vec::new(),
            next_id: 0,
        };
        let r = c.request("initialize", json!({ "capabilities": {} })).await;
        assert!(r["capabilities"]["hoverProvider"].as_bool().unwrap());
        c.notify("initialized", json!({})).await;
        c
    }

    pub async fn request(&mut self, method: &str, params: Value) -> Value {
        self.try_request(method, params)
            .await
            .unwrap_or_else(|e| panic!("{method}: {e}"))
    }

    /// The result, or the error message.
    pub async fn try_request(&mut self, method: &str, params: Value) -> Result<Value, String> {
        self.next_id += 1;
        let req = Request::build(method.to_owned())
            .id(self.next_id)
            .params(params)
            .finish();
        let resp = self
            .service
            .ready()
            .await
            .unwrap()
            .call(req)
            .await
            .unwrap()
            .expect("a request gets a response");
        let (_, result) = resp.into_parts();
        result.map_err(|e| e.message.to_string())
    }

    pub async fn notify(&mut self, method: &str, params: Value) {
        let req = Request::build(method.to_owned()).params(params).finish();
        let resp = self.service.ready().await.unwrap().call(req).await.unwrap();
        assert!(resp.is_none());
    }

    pub async fn open(&mut self, path: &Path) -> Url {
        let text = std::fs::read_to_string(path).unwrap();
        self.open_text(path, &text).await
    }

    pub async fn open_text(&mut self, path: &Path, text: &str) -> Url {
        let u = uri(path);
        self.notify(
            "textDocument/didOpen",
            json!({ "textDocument": { "uri": u, "languageId": "btrules", "version": 1, "text": text } }),
        )
        .await;
        u
    }

    /// Replaces `range` ([line, col, line, col], UTF-16) with `text`.
    pub async fn change(&mut self, u: &Url, version: i32, range: [u32; 4], text: &str) {
        self.notify(
            "textDocument/didChange",
            json!({
                "textDocument": { "uri": u, "version": version },
                "contentChanges": [{
                    "range": { "start": { "line": range[0], "character": range[1] },
                               "end": { "line": range[2], "character": range[3] } },
                    "text": text
                }]
            }),
        )
        .await;
    }

    /// The next batch of diagnostics published for `u` (every change
    /// publishes one batch per affected file); the newest batch of each
    /// other file waits for its turn.
    pub async fn diagnostics_for(&mut self, u: &Url) -> Vec<Value> {
        if let Some(i) = self.pending.iter().position(|b| b["uri"] == json!(u)) {
            let b = self.pending.remove(i);
            return b["diagnostics"].as_array().cloned().unwrap_or_default();
        }
        loop {
            let next =
                tokio::time::timeout(std::time::Duration::from_secs(10), self.diagnostics.recv())
                    .await
                    .expect("diagnostics published in time")
                    .expect("channel open");
            if next["uri"] == json!(u) {
                return next["diagnostics"].as_array().cloned().unwrap_or_default();
            }
            self.pending.retain(|b| b["uri"] != next["uri"]);
            self.pending.push(next);
        }
    }

    /// Drops whatever diagnostics were published so far.
    pub fn drain(&mut self) -> usize {
        let mut n = self.pending.len();
        self.pending.clear();
        while self.diagnostics.try_recv().is_ok() {
            n += 1;
        }
        n
    }

    pub async fn at(&mut self, method: &str, u: &Url, line: u32, character: u32) -> Value {
        self.request(
            method,
            json!({ "textDocument": { "uri": u }, "position": { "line": line, "character": character } }),
        )
        .await
    }
}

/// Line and UTF-16 column of the first occurrence of `needle` in `text`
/// (plus `delta` characters).
pub fn pos(text: &str, needle: &str, delta: usize) -> (u32, u32) {
    let off = text
        .find(needle)
        .unwrap_or_else(|| panic!("{needle:?} not in text"));
    let before = &text[..off];
    let line = before.matches('\n').count() as u32;
    let col = before.rsplit('\n').next().unwrap().encode_utf16().count() + delta;
    (line, col as u32)
}
