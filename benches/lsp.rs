//! Language server latency over its real protocol (`cargo bench --bench
//! lsp`): `btc lsp` runs as a child process, this drives it over stdio
//! with JSON-RPC and prints, with their targets,
//! - `didOpen` until its first `publishDiagnostics`;
//! - percentiles of a one-character `didChange` until its
//!   `publishDiagnostics`;
//! - percentiles of `hover` and `completion` round trips;
//!
//! on two files: the 5,000-line ARIAC rules file (few actions, many rules
//! each; targets p50 < 10 ms, p99 < 30 ms, requests < 5 ms) and one rule
//! per action over a generated 500-action domain (issue #14: open < 30 ms,
//! edit p50 < 5 ms, p99 < 15 ms, requests < 2 ms).

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

/// A file to drive the server with: where to make the one-character edit
/// (a digit inside a rule's body, in the middle of the file), where to
/// hover (and what the hover names) and where to complete.
struct Case {
    what: String,
    path: std::path::PathBuf,
    edit: (usize, usize),
    hover: (usize, usize, &'static str),
    complete: (usize, usize),
    targets: Targets,
}

struct Targets {
    open: &'static str,
    change: &'static str,
    request: &'static str,
}

/// The line and column of the first line containing `marker` at or after
/// line `from`, and the column of `marker` in it.
fn find(text: &str, from: usize, marker: &str) -> (usize, usize) {
    text.lines()
        .enumerate()
        .skip(from)
        .find_map(|(i, l)| l.find(marker).map(|c| (i, c)))
        .unwrap()
}

fn run(case: &Case) {
    let text = std::fs::read_to_string(&case.path).unwrap();
    let uri = format!("file://{}", case.path.display());
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
    let t = Instant::now();
    s.notify(
        "textDocument/didOpen",
        json!({ "textDocument": { "uri": uri, "languageId": "btrules", "version": 1, "text": text } }),
    );
    let n = s.diagnostics(&uri, 1);
    let open = t.elapsed();
    println!("btc lsp on {}: {n} diagnostics published", case.what);
    report(
        "didOpen -> publishDiagnostics",
        vec![open],
        case.targets.open,
    );

    // A one-character edit inside a rule, then its undo.
    let (line, col) = case.edit;
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
        case.targets.change,
    );

    let (hl, hc, names) = case.hover;
    let at = json!({ "textDocument": { "uri": uri }, "position": { "line": hl, "character": hc } });
    let mut hover = Vec::new();
    for _ in 0..ROUNDS {
        let t = Instant::now();
        let h = s.request("textDocument/hover", at.clone());
        hover.push(t.elapsed());
        assert!(h["contents"]["value"].as_str().unwrap().contains(names));
    }
    report("hover", hover, case.targets.request);

    let (cl, cc) = case.complete;
    let inside =
        json!({ "textDocument": { "uri": uri }, "position": { "line": cl, "character": cc } });
    let mut completion = Vec::new();
    for _ in 0..ROUNDS {
        let t = Instant::now();
        let c = s.request("textDocument/completion", inside.clone());
        completion.push(t.elapsed());
        assert!(!c.as_array().unwrap().is_empty());
    }
    report("completion", completion, case.targets.request);

    s.request("shutdown", Value::Null);
    s.notify("exit", Value::Null);
    let _ = child.wait();
}

fn main() {
    // `cargo bench` passes flags such as `--bench`; there is nothing to filter.
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));

    // The 5,000-line file of the ARIAC domain's few actions.
    let path = root
        .join("lang/tests/fixtures/large.btrules")
        .canonicalize()
        .unwrap();
    let text = std::fs::read_to_string(&path).unwrap();
    assert!(text.lines().count() >= 5000);
    let (first, _) = find(&text, 0, "retry(3) MoveTo");
    let (line, col) = find(&text, first + 2500 / 35 * 35, "retry(3)");
    run(&Case {
        what: format!("{} lines (few actions)", text.lines().count()),
        path,
        edit: (line, col + 6),
        hover: (line, col + 10, "MoveTo"),
        complete: (line, col),
        targets: Targets {
            open: "-",
            change: "p50 < 10 ms, p99 < 30 ms",
            request: "< 5 ms",
        },
    });

    // One rule per action over a 500-action domain (issue #14).
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(
        dir.path().join("domain.pddl"),
        btc_testkit::scale::domain(500),
    )
    .unwrap();
    let rules = btc_testkit::scale::rules(500, "domain.pddl");
    let path = dir.path().join("rules.btrules");
    std::fs::write(&path, &rules).unwrap();
    let (head, _) = find(&rules, 0, "rule (inspect-251 ");
    let (line, col) = find(&rules, head, "timeout(500)");
    run(&Case {
        what: "500 rules over 500 actions".into(),
        path,
        edit: (line, col + 9),
        hover: (line, col + 15, "Inspect"),
        complete: (line, col + 13),
        targets: Targets {
            open: "< 30 ms",
            change: "p50 < 5 ms, p99 < 15 ms",
            request: "< 2 ms",
        },
    });
}
