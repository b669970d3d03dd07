//! The framing layer between the editor and tower-lsp. tower-lsp 0.20's own
//! transport ends the server on one malformed message (a body of `{`, a bad
//! Content-Length, a garbage line), buffers whatever a huge Content-Length
//! announces, and does not stop when stdin closes while a request of the
//! server's is pending. So btc reads stdin itself: [`Framer`] cuts the byte
//! stream into messages, resynchronising on the next `Content-Length`
//! header after anything it cannot read; [`check`] lets through only
//! well-formed JSON-RPC objects (tower-lsp gets nothing else) and answers
//! the rest with the JSON-RPC error, under the message's id when it has one.
//! `exit` and the end of stdin end the process at once, with the status the
//! specification asks for (0 after `shutdown`, else 1).

use serde_json::{json, Value};
use std::io::Read;

/// The largest message body read (a document of the language server's size
/// limit, JSON-escaped, fits). A larger announced length is refused without
/// buffering it.
pub const MAX_BODY: usize = 256 << 20;
/// The longest header line; longer lines are garbage.
const MAX_HEADER_LINE: usize = 8 << 10;

/// What the framer read next.
#[derive(Debug, PartialEq)]
pub enum Next {
    /// A message body (not yet checked).
    Body(Vec<u8>),
    /// Something that is not a message: skipped, and answered with a parse
    /// error (no id can be known).
    Bad(String),
    Eof,
}

/// Cuts a byte stream into `Content-Length`-framed bodies. Headers may end
/// in CRLF or LF; lines before a header that are not headers are skipped.
pub struct Framer<R> {
    input: R,
    buf: Vec<u8>,
    pos: usize,
    eof: bool,
    /// Inside a run of garbage lines (reported once per run).
    in_garbage: bool,
}

impl<R: Read> Framer<R> {
    pub fn new(input: R) -> Framer<R> {
        Framer {
            input,
            buf: Vec::new(),
            pos: 0,
            eof: false,
            in_garbage: false,
        }
    }

    /// Makes at least `n` unread bytes available (fewer at the end).
    fn fill(&mut self, n: usize) {
        if self.pos > 0 && self.pos == self.buf.len() {
            self.buf.clear();
            self.pos = 0;
        }
        while self.buf.len() - self.pos < n && !self.eof {
            if self.pos > (1 << 20) {
                self.buf.drain(..self.pos);
                self.pos = 0;
            }
            let mut chunk = [0u8; 64 << 10];
            match self.input.read(&mut chunk) {
                Ok(0) | Err(_) => self.eof = true,
                Ok(k) => self.buf.extend_from_slice(&chunk[..k]),
            }
        }
    }

    /// The next line without its `\n` (and `\r`); `None` at the end. A line
    /// longer than the limit comes back cut, as garbage.
    fn line(&mut self) -> Option<Vec<u8>> {
        let mut out = Vec::new();
        loop {
            self.fill(1);
            if self.pos == self.buf.len() {
                return (!out.is_empty()).then_some(out);
            }
            let avail = &self.buf[self.pos..];
            match avail.iter().position(|&b| b == b'\n') {
                Some(k) => {
                    if out.len() < MAX_HEADER_LINE {
                        out.extend_from_slice(&avail[..k.min(MAX_HEADER_LINE)]);
                    }
                    self.pos += k + 1;
                    if out.last() == Some(&b'\r') {
                        out.pop();
                    }
                    return Some(out);
                }
                None => {
                    if out.len() < MAX_HEADER_LINE {
                        let take = avail.len().min(MAX_HEADER_LINE - out.len());
                        out.extend_from_slice(&avail[..take]);
                    }
                    self.pos = self.buf.len();
                }
            }
        }
    }

    fn body(&mut self, n: usize) -> Option<Vec<u8>> {
        let mut out = Vec::with_capacity(n.min(1 << 20));
        while out.len() < n {
            self.fill(n - out.len());
            if self.pos == self.buf.len() {
                return None;
            }
            let take = (self.buf.len() - self.pos).min(n - out.len());
            out.extend_from_slice(&self.buf[self.pos..self.pos + take]);
            self.pos += take;
        }
        Some(out)
    }

    /// Puts bytes back in front of the unread input.
    fn unread(&mut self, bytes: &[u8]) {
        let rest = self.buf.split_off(self.pos);
        self.buf.clear();
        self.buf.extend_from_slice(bytes);
        self.buf.extend_from_slice(&rest);
        self.pos = 0;
    }

    pub fn next_message(&mut self) -> Next {
        let mut length: Option<Result<usize, String>> = None;
        let mut headers = false;
        loop {
            let Some(line) = self.line() else {
                return Next::Eof;
            };
            if line.is_empty() {
                match length.take() {
                    None if !headers => continue, // blank lines between messages
                    None => return Next::Bad("a message without a Content-Length header".into()),
                    Some(Err(why)) => return Next::Bad(why),
                    Some(Ok(n)) => return self.framed_body(n),
                }
            }
            let text = String::from_utf8_lossy(&line);
            match text.split_once(':') {
                Some((name, value)) if is_content_length(name) => {
                    headers = true;
                    let value = value.trim();
                    length = Some(match value.parse::<u64>() {
                        Ok(n) if n as usize <= MAX_BODY && n > 0 => Ok(n as usize),
                        Ok(n) => Err(format!(
                            "Content-Length {n} is not between 1 and {MAX_BODY}"
                        )),
                        Err(_) => Err(format!("Content-Length `{value}` is not a number of bytes")),
                    });
                }
                Some((name, _))
                    if !name.is_empty()
                        && name.bytes().all(|b| b.is_ascii_alphanumeric() || b == b'-') =>
                {
                    headers = true;
                }
                _ => {
                    // Garbage: a header block starts over at the next
                    // Content-Length, even one later on this line.
                    headers = false;
                    length = None;
                    if let Some(k) = find_header(&line).filter(|k| *k > 0) {
                        let mut rest = line[k..].to_vec();
                        rest.extend_from_slice(b"\r\n");
                        self.unread(&rest);
                    }
                    if !self.in_garbage {
                        self.in_garbage = true;
                        return Next::Bad("text that is not a message header".into());
                    }
                }
            }
        }
    }

    /// A body of the announced length. If it does not read as JSON but a
    /// header starts inside it (the length was too large), the message ends
    /// there and the header is read again.
    fn framed_body(&mut self, n: usize) -> Next {
        let Some(body) = self.body(n) else {
            return Next::Eof;
        };
        if serde_json::from_slice::<serde::de::IgnoredAny>(&body).is_err() {
            if let Some(at) = find_header(&body) {
                self.unread(&body[at..]);
                return Next::Bad("a message shorter than its Content-Length".into());
            }
        }
        self.in_garbage = false;
        Next::Body(body)
    }
}

/// Header names in the base protocol are case-insensitive, as in HTTP; this
/// is wire framing, not a name from a rules file, so it needs no `Key`.
#[allow(clippy::disallowed_methods)]
fn is_content_length(name: &str) -> bool {
    name.trim().eq_ignore_ascii_case("content-length")
}

/// Where a `Content-Length:` header starts in `bytes`, if anywhere.
fn find_header(bytes: &[u8]) -> Option<usize> {
    let needle = b"Content-Length:";
    bytes.windows(needle.len()).position(|w| w == needle)
}

/// What to do with one body.
#[derive(Debug, PartialEq)]
pub enum Checked {
    /// A well-formed request, notification or response: for tower-lsp
    /// (as `body` when set: `"params": null`, which tower-lsp refuses,
    /// left out).
    Forward {
        method: Option<String>,
        body: Option<Vec<u8>>,
    },
    /// Not a message: this error response goes back to the client.
    Reply(Value),
    /// Not a message, and nothing to answer (a broken response of the
    /// client's, a notification with bad parameters).
    Drop,
}

/// JSON-RPC's error response.
pub fn error(id: Value, code: i64, message: &str) -> Value {
    json!({ "jsonrpc": "2.0", "id": id, "error": { "code": code, "message": message } })
}

pub const PARSE_ERROR: i64 = -32700;
pub const INVALID_REQUEST: i64 = -32600;

/// Checks a body: valid JSON (UTF-8, no lone surrogates), one object, the
/// JSON-RPC 2.0 shape. tower-lsp sees only what passes.
pub fn check(body: &[u8]) -> Checked {
    let v: Value = match serde_json::from_slice(body) {
        Ok(v) => v,
        Err(e) => {
            return Checked::Reply(error(Value::Null, PARSE_ERROR, &format!("not JSON: {e}")))
        }
    };
    let Some(o) = v.as_object() else {
        return Checked::Reply(error(
            Value::Null,
            INVALID_REQUEST,
            "a message is one JSON object (batches are not part of LSP)",
        ));
    };
    let id = o.get("id").cloned();
    let good_id = match &id {
        None => true,
        Some(Value::String(_)) => true,
        Some(Value::Number(n)) => n.is_i64() || n.is_u64(),
        Some(_) => false,
    };
    let reply = |why: &str| {
        let id = if good_id {
            id.clone().unwrap_or(Value::Null)
        } else {
            Value::Null
        };
        Checked::Reply(error(id, INVALID_REQUEST, why))
    };
    if o.get("jsonrpc") != Some(&json!("2.0")) {
        return reply("`jsonrpc` must be \"2.0\"");
    }
    if !good_id {
        return reply("`id` must be a number or a string");
    }
    match o.get("method") {
        Some(Value::String(m)) => {
            if !matches!(
                o.get("params"),
                None | Some(Value::Null | Value::Object(_) | Value::Array(_))
            ) {
                return if id.is_some() {
                    reply("`params` must be an object or an array")
                } else {
                    Checked::Drop
                };
            }
            let body = (o.get("params") == Some(&Value::Null)).then(|| {
                let mut o = o.clone();
                o.remove("params");
                Value::Object(o).to_string().into_bytes()
            });
            Checked::Forward {
                method: Some(m.clone()),
                body,
            }
        }
        Some(_) => reply("`method` must be a string"),
        None if id.is_some() && (o.contains_key("result") || o.contains_key("error")) => {
            Checked::Forward {
                method: None,
                body: None,
            }
        }
        None => {
            if id.is_some() {
                reply("neither a request (no `method`) nor a response")
            } else {
                Checked::Drop
            }
        }
    }
}

/// A body framed for the wire.
pub fn frame(body: &[u8]) -> Vec<u8> {
    let mut out = format!("Content-Length: {}\r\n\r\n", body.len()).into_bytes();
    out.extend_from_slice(body);
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn all(input: &[u8]) -> Vec<Next> {
        let mut f = Framer::new(input);
        let mut out = Vec::new();
        loop {
            match f.next_message() {
                Next::Eof => return out,
                n => out.push(n),
            }
        }
    }

    #[test]
    fn reads_crlf_and_lf_headers_and_skips_garbage() {
        let got = all(b"Content-Length: 2\r\n\r\n{}garbage line\nContent-Length: 2\n\n[]");
        assert_eq!(got[0], Next::Body(b"{}".to_vec()));
        assert!(matches!(got[1], Next::Bad(_)));
        assert_eq!(got.last(), Some(&Next::Body(b"[]".to_vec())));
    }

    #[test]
    fn bad_lengths_are_refused_and_the_next_header_is_found() {
        for header in [
            "Content-Length: -5",
            "Content-Length: x",
            "Content-Length: 4000000000",
            "Content-Type: a",
        ] {
            let text = format!("{header}\r\n\r\nContent-Length: 2\r\n\r\n{{}}");
            let got = all(text.as_bytes());
            assert!(matches!(got[0], Next::Bad(_)), "{header}: {got:?}");
            assert_eq!(got.last(), Some(&Next::Body(b"{}".to_vec())), "{header}");
        }
    }

    #[test]
    fn a_too_large_length_stops_at_the_next_header() {
        let got = all(b"Content-Length: 30\r\n\r\n{\"a\"Content-Length: 2\r\n\r\n{}xxxxxxxxxxxxxx");
        assert!(matches!(got[0], Next::Bad(_)), "{got:?}");
        assert_eq!(got[1], Next::Body(b"{}".to_vec()));
    }

    #[test]
    fn checks_the_json_rpc_shape() {
        assert!(matches!(check(b"{"), Checked::Reply(_)));
        assert!(matches!(check(b"[]"), Checked::Reply(_)));
        assert!(matches!(check(b"\"\\ud800\""), Checked::Reply(_)));
        assert!(matches!(
            check(
                b"{\"jsonrpc\":\"2.0\",\"id\":1,\"method\":\"x\",\"params\":{\"t\":\"\\ud800\"}}"
            ),
            Checked::Reply(_)
        ));
        assert!(matches!(
            check(b"{\"jsonrpc\":\"2.0\",\"id\":1,\"method\":\"x\",\"params\":{\"t\":\"\xff\"}}"),
            Checked::Reply(_)
        ));
        match check(b"{\"jsonrpc\":\"2.0\",\"id\":7,\"params\":1,\"method\":\"m\"}") {
            Checked::Reply(v) => assert_eq!(v["id"], 7),
            other => panic!("{other:?}"),
        }
        assert_eq!(
            check(b"{\"jsonrpc\":\"2.0\",\"method\":\"initialized\",\"params\":{}}"),
            Checked::Forward {
                method: Some("initialized".into()),
                body: None
            }
        );
        match check(b"{\"jsonrpc\":\"2.0\",\"id\":2,\"method\":\"shutdown\",\"params\":null}") {
            Checked::Forward { body: Some(b), .. } => {
                assert!(!String::from_utf8(b).unwrap().contains("params"))
            }
            other => panic!("{other:?}"),
        }
        assert_eq!(
            check(b"{\"jsonrpc\":\"2.0\",\"id\":1,\"result\":null}"),
            Checked::Forward {
                method: None,
                body: None
            }
        );
        assert_eq!(check(b"{\"jsonrpc\":\"2.0\"}"), Checked::Drop);
    }
}
