//! A string literal's raw text read into parts: escapes processed, and
//! `{?var}` / `{capture}` interpolations cut out.

use super::*;

/// Splits a string literal's raw text at `{?var}` / `{capture}` and
/// processes escapes. `start` is the offset of the opening quote.
pub(super) fn interpolate(
    raw: &str,
    file: FileId,
    start: usize,
) -> Result<StrLit, (String, SimpleSpan)> {
    let mut parts = Vec::new();
    let mut text = String::new();
    let base = start + 1;
    let mut escapes = Vec::new();
    // The text's length in the parts before `text`.
    let mut done = 0;
    let mut chars = raw.char_indices().peekable();
    while let Some((i, c)) = chars.next() {
        match c {
            '\\' => match chars.next() {
                Some((_, c @ ('n' | 't' | '\\' | '"' | '{' | '}'))) => {
                    escapes.push((done + text.len()) as u32);
                    text.push(match c {
                        'n' => '\n',
                        't' => '\t',
                        c => c,
                    });
                }
                Some((j, c)) => {
                    return Err((format!("`\\{c}` is not an escape; use `\\\\`, `\\\"`, `\\n`, `\\t`, `\\{{` or `\\}}`"), SimpleSpan::from(base + i..base + j + c.len_utf8())))
                }
                None => return Err(("a string cannot end with `\\`".into(), SimpleSpan::from(base + i..base + i + 1))),
            },
            '{' => {
                let close = raw[i..].find('}').map(|k| i + k);
                let Some(close) = close else {
                    return Err(("`{` opens an interpolation that is never closed; write `\\{` for a brace".into(), SimpleSpan::from(base + i..base + i + 1)));
                };
                let inner = &raw[i + 1..close];
                let span = Span::new(file, base + i + 1, base + close);
                let (is_var, name) = match inner.strip_prefix('?') {
                    Some(v) => (true, v),
                    None => (false, inner),
                };
                if name.is_empty() || !name.chars().all(|c| c.is_ascii_alphanumeric() || c == '_' || c == '-') {
                    return Err((format!("`{{{inner}}}` is not `{{?variable}}` or `{{capture}}`"), SimpleSpan::from(base + i..base + close + 1)));
                }
                if !text.is_empty() {
                    done += text.len();
                    parts.push(StrPart::Text { text: std::mem::take(&mut text) });
                }
                parts.push(if is_var {
                    StrPart::Var { name: Ident::new(Key::new(name).into_string(), span) }
                } else {
                    StrPart::Capture { name: Ident::new(name.to_owned(), span) }
                });
                while chars.peek().is_some_and(|(k, _)| *k <= close) {
                    chars.next();
                }
            }
            c => text.push(c),
        }
    }
    if !text.is_empty() || parts.is_empty() {
        parts.push(StrPart::Text { text });
    }
    Ok(StrLit {
        parts: exact(parts),
        span: Span::new(file, start, start + raw.len() + 2),
        escapes,
    })
}
