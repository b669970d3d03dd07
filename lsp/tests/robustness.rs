//! 10,000 random edits against the examples, through the real service: the
//! server must never panic, must answer every request and must publish
//! diagnostics after every change. Edits land anywhere, in UTF-16
//! positions that may split a surrogate pair, and insert pieces of tokens
//! and multi-byte characters.

mod common;

use btc_lsp::convert::LineIndex;
use common::{repo, TestClient};
use serde_json::json;
use tower_lsp::lsp_types::Position;

/// A small deterministic generator (xorshift64*), so failures reproduce.
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        self.0.wrapping_mul(0x2545_F491_4F6C_DD1D)
    }

    fn below(&mut self, n: usize) -> usize {
        (self.next() % n.max(1) as u64) as usize
    }
}

const PIECES: &[&str] = &[
    "(",
    ")",
    "{",
    "}",
    "[",
    "]",
    "?",
    "\"",
    ":",
    ",",
    "=>",
    "//",
    "/*",
    "*/",
    "\n",
    " ",
    "rule",
    "Grasp(",
    "effect (and ",
    "sequence {",
    "steps",
    "?robot",
    "é",
    "𝄞",
    "日本",
    "\u{0}",
    "\t",
    "table t { A: 1 }",
    "import std::kb\n",
    "{?x}",
    "retry(",
    "-1",
    "1.5e3",
];

/// A random position: a line near the text's, a column that may be past
/// the line's end or inside a surrogate pair.
fn position(rng: &mut Rng, text: &str) -> Position {
    let lines = text.lines().count().max(1);
    let line = rng.below(lines + 1);
    let width = text
        .lines()
        .nth(line)
        .map_or(0, |l| l.encode_utf16().count());
    Position::new(line as u32, rng.below(width + 3) as u32)
}

#[tokio::test]
async fn ten_thousand_random_edits_never_break_the_server() {
    let examples = ["ariac", "p3_assembler", "nist_kitting", "two_robots"];
    let mut rng = Rng(0x9E37_79B9_7F4A_7C15);
    let mut c = TestClient::new().await;
    let mut requests = 0;
    let mut broken = 0;
    for name in examples {
        let path = repo().join("examples").join(name).join("rules.btrules");
        let mut text = std::fs::read_to_string(&path).unwrap();
        let u = c.open_text(&path, &text).await;
        c.diagnostics_for(&u).await;
        for version in 2..2502 {
            // Delete a random range, insert a random piece (or both).
            let a = position(&mut rng, &text);
            let b = if rng.below(3) == 0 {
                a
            } else {
                let mut b = position(&mut rng, &text);
                if b.line > a.line + 3 {
                    b.line = a.line + rng.below(3) as u32;
                }
                b
            };
            let (a, b) = if (b.line, b.character) < (a.line, a.character) {
                (b, a)
            } else {
                (a, b)
            };
            let insert = if rng.below(4) == 0 {
                String::new()
            } else {
                PIECES[rng.below(PIECES.len())].to_owned()
            };
            // Keep texts of a size that stays interesting.
            let insert = if text.len() > 6000 {
                String::new()
            } else {
                insert
            };
            c.change(
                &u,
                version,
                [a.line, a.character, b.line, b.character],
                &insert,
            )
            .await;
            // The client's copy, edited the way the server edits its own.
            let ix = LineIndex::new(&text);
            let (x, y) = (ix.offset(a), ix.offset(b));
            text.replace_range(x.min(y)..x.max(y), &insert);
            // Diagnostics come after every change (panics would fail here).
            let diags = c.diagnostics_for(&u).await;
            for d in &diags {
                assert!(d["code"].is_string() && d["range"]["start"]["line"].is_u64());
            }
            broken += usize::from(diags.iter().any(|d| d["severity"] == 1));
            if version % 7 == 0 {
                let p = position(&mut rng, &text);
                let at = json!({ "textDocument": { "uri": u }, "position": p });
                for method in [
                    "textDocument/hover",
                    "textDocument/completion",
                    "textDocument/definition",
                    "textDocument/signatureHelp",
                ] {
                    c.try_request(method, at.clone()).await.ok();
                    requests += 1;
                }
                let doc = json!({ "textDocument": { "uri": u } });
                c.request("textDocument/semanticTokens/full", doc.clone())
                    .await;
                c.request("textDocument/documentSymbol", doc.clone()).await;
                let range = json!({ "start": p, "end": position(&mut rng, &text) });
                c.request(
                    "textDocument/codeAction",
                    json!({ "textDocument": { "uri": u }, "range": range, "context": { "diagnostics": [] } }),
                )
                .await;
                c.request(
                    "textDocument/inlayHint",
                    json!({ "textDocument": { "uri": u }, "range": range }),
                )
                .await;
                c.try_request(
                    "textDocument/references",
                    json!({ "textDocument": { "uri": u }, "position": p, "context": { "includeDeclaration": true } }),
                )
                .await
                .ok();
                // A rename may be refused (an error), but it must answer.
                c.try_request(
                    "textDocument/rename",
                    json!({ "textDocument": { "uri": u }, "position": p, "newName": "renamed" }),
                )
                .await
                .ok();
                c.request(
                    "textDocument/formatting",
                    json!({ "textDocument": { "uri": u }, "options": { "tabSize": 4, "insertSpaces": true } }),
                )
                .await;
                requests += 7;
            }
        }
    }
    assert!(requests > 10_000);
    // The edits do break the files: most versions have errors to report.
    assert!(broken > 5_000, "{broken}");
}
