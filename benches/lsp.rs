//! Language server latency over its real protocol (`cargo bench --bench
//! lsp`): `btc lsp` runs as a child process, this drives it over stdio
//! with JSON-RPC on a 5,000-line rules file and prints percentiles of
//! - a one-character `didChange` until its `publishDiagnostics`
//!   (target: p50 < 10 ms, p99 < 30 ms);
//! - `hover` and `completion` round trips (target: < 5 ms).

use serde_json::{json, Value};
use std::io::{BufRead, BufReader, Read, Write};
use std::path::Path;
use std::process::{Command, Stdio};
use std::sync::mpsc;
use std::time::{Duration, Instant};

const ROUNDS: usize = 300;

struct Server {
    stdin: std::process::ChildStdin,
    messages: mpsc::Receiver<Value>,
    next_id: i64,
}

impl Server {
    fn send(&mut self, v: &Value) {
        let body = v.to_string();
        write!(self.stdin, "Content-Length: {}\r\n\r\n{body}", body.len()).unwrap();
        self.stdin.flush().unwrap();
    }

    fn notify(&mut self, method: &str, params: Value) {
        self.send(&json!({ "jsonrpc": "2.0", "method": method, "params": params }));
    }

    /// Sends a request and waits for its response (answering the server's
    /// own requests on the way).
    fn request(&mut self, method: &str, params: Value) -> Value {
        self.next_id += 1;
        let id = self.next_id;
        self.send(&json!({ "jsonrpc": "2.0", "id": id, "method": method, "params": params }));
        loop {
            let m = self.next();
            if m["id"] == id && m.get("method").is_none() {
                return m["result"].clone();
            }
        }
    }

    fn next(&mut self) -> Value {
        let m = self
            .messages
            .recv_timeout(Duration::from_secs(30))
            .expect("the server answers");
        if let (Some(id), Some(_)) = (m.get("id"), m.get("method")) {
            let reply = json!({ "jsonrpc": "2.0", "id": id, "result": null });
            self.send(&reply);
        }
        m
    }

    /// Waits for the diagnostics of `uri` at `version`.
    fn diagnostics(&mut self, uri: &str, version: i64) -> usize {
        loop {
            let m = self.next();
            if m["method"] == "textDocument/publishDiagnostics"
                && m["params"]["uri"] == uri
                && m["params"]["version"] == version
            {
                return m["params"]["diagnostics"].as_array().map_or(0, Vec::len);
            }
        }
    }
}

fn reader(stdout: std::process::ChildStdout, tx: mpsc::Sender<Value>) {
    let mut r = BufReader::new(stdout);
    loop {
        let mut len = 0usize;
        loop {
            let mut line = String::new();
            if r.read_line(&mut line).unwrap_or(0) == 0 {
                return;
            }
            let line = line.trim_end();
            if line.is_empty() {
                break;
            }
            if let Some(n) = line.strip_prefix("Content-Length: ") {
                len = n.parse().unwrap();
            }
        }
        let mut body = vec![0; len];
        if r.read_exact(&mut body).is_err() {
            return;
        }
        if tx.send(serde_json::from_slice(&body).unwrap()).is_err() {
            return;
        }
    }
}

fn report(what: &str, mut times: Vec<Duration>, target: &str) {
    times.sort();
    let at = |p: f64| times[((times.len() as f64 * p) as usize).min(times.len() - 1)];
    let ms = |d: Duration| d.as_secs_f64() * 1000.0;
    println!(
        "{what:<34} p50 {:>6.2} ms   p90 {:>6.2} ms   p99 {:>6.2} ms   max {:>6.2} ms   ({} rounds; target {target})",
        ms(at(0.5)),
        ms(at(0.9)),
        ms(at(0.99)),
        ms(*times.last().unwrap()),
        times.len()
    );
}

fn main() {
    // `cargo bench` passes flags such as `--bench`; there is nothing to filter.
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let path = root
        .join("lang/tests/fixtures/large.btrules")
        .canonicalize()
        .unwrap();
    let text = std::fs::read_to_string(&path).unwrap();
    assert!(text.lines().count() >= 5000);
    let uri = format!("file://{}", path.display());

    let mut child = Command::new(env!("CARGO_BIN_EXE_btc"))
        .arg("lsp")
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::null())
        .spawn()
        .expect("btc lsp starts");
    let (tx, rx) = mpsc::channel();
    let stdout = child.stdout.take().unwrap();
    std::thread::spawn(move || reader(stdout, tx));
    let mut s = Server {
        stdin: child.stdin.take().unwrap(),
        messages: rx,
        next_id: 0,
    };
    s.request("initialize", json!({ "capabilities": {} }));
    s.notify("initialized", json!({}));
    s.notify(
        "textDocument/didOpen",
        json!({ "textDocument": { "uri": uri, "languageId": "btrules", "version": 1, "text": text } }),
    );
    let n = s.diagnostics(&uri, 1);
    println!(
        "btc lsp on {} lines: {n} diagnostics published",
        text.lines().count()
    );

    // A one-character edit in the middle of the file, then its undo.
    let line = text
        .lines()
        .position(|l| l.contains("retry(3) MoveTo"))
        .unwrap()
        + 2500 / 35 * 35;
    let col = text.lines().nth(line).unwrap().find("retry(3)").unwrap() + 6;
    let mut change = Vec::new();
    for round in 0..ROUNDS {
        let version = round as i64 + 2;
        let (range, new_text) = if round % 2 == 0 {
            (
                json!({ "start": { "line": line, "character": col }, "end": { "line": line, "character": col } }),
                "0",
            )
        } else {
            (
                json!({ "start": { "line": line, "character": col }, "end": { "line": line, "character": col + 1 } }),
                "",
            )
        };
        let t = Instant::now();
        s.notify(
            "textDocument/didChange",
            json!({ "textDocument": { "uri": uri, "version": version }, "contentChanges": [{ "range": range, "text": new_text }] }),
        );
        s.diagnostics(&uri, version);
        change.push(t.elapsed());
    }
    report(
        "didChange -> publishDiagnostics",
        change,
        "p50 < 10 ms, p99 < 30 ms",
    );

    let at = json!({ "textDocument": { "uri": uri }, "position": { "line": line, "character": col + 4 } });
    let mut hover = Vec::new();
    for _ in 0..ROUNDS {
        let t = Instant::now();
        let h = s.request("textDocument/hover", at.clone());
        hover.push(t.elapsed());
        assert!(h["contents"]["value"].as_str().unwrap().contains("MoveTo"));
    }
    report("hover", hover, "< 5 ms");

    let inside = json!({ "textDocument": { "uri": uri }, "position": { "line": line, "character": col - 6 } });
    let mut completion = Vec::new();
    for _ in 0..ROUNDS {
        let t = Instant::now();
        let c = s.request("textDocument/completion", inside.clone());
        completion.push(t.elapsed());
        assert!(!c.as_array().unwrap().is_empty());
    }
    report("completion", completion, "< 5 ms");

    s.request("shutdown", Value::Null);
    s.notify("exit", Value::Null);
    let _ = child.wait();
}
