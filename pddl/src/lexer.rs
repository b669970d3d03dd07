//! PDDL tokens. PDDL is case-insensitive: names, variables and keywords are
//! lower-cased here, so nothing downstream compares case again.

use crate::diagnostic::{codes, Diagnostic};
use crate::source::{FileId, Span};

#[derive(Clone, Debug, PartialEq)]
pub enum Tok {
    LParen,
    RParen,
    /// A name or an operator such as `=` or `<=`, lower-cased.
    Name(String),
    /// `?x`, stored without the `?`, lower-cased.
    Var(String),
    /// `:action`, stored without the `:`, lower-cased.
    Keyword(String),
    Number(f64),
    /// A lone `-`: the type separator (or minus in numeric expressions).
    Dash,
    /// A word with characters PDDL does not allow; reported, kept for recovery.
    Invalid(String),
}

#[derive(Clone, Debug, PartialEq)]
pub struct Token {
    pub tok: Tok,
    pub span: Span,
}

/// Whether `c` separates words: Unicode whitespace (ASCII checked first,
/// the common case).
fn is_space(c: char) -> bool {
    matches!(c, ' ' | '\t' | '\n' | '\r' | '\x0b' | '\x0c') || (!c.is_ascii() && c.is_whitespace())
}

/// The words of a text with their byte ranges: each parenthesis, and each
/// run of other characters up to whitespace, a parenthesis or a `;`, which
/// starts a comment to the end of the line. One pass over the bytes: this
/// runs before every command, so it matters for how fast `btc` starts.
fn words(text: &str) -> Vec<(&str, usize, usize)> {
    let bytes = text.as_bytes();
    let mut out = Vec::with_capacity(text.len() / 4);
    let mut chars = text.char_indices().peekable();
    while let Some((i, c)) = chars.next() {
        match c {
            '(' | ')' => out.push((&text[i..i + 1], i, i + 1)),
            ';' => {
                let end = bytes[i..]
                    .iter()
                    .position(|&b| b == b'\n')
                    .map_or(bytes.len(), |n| i + n);
                while chars.next_if(|&(j, _)| j < end).is_some() {}
            }
            c if is_space(c) => {}
            _ => {
                let mut end = text.len();
                while let Some(&(j, d)) = chars.peek() {
                    if is_space(d) || matches!(d, '(' | ')' | ';') {
                        end = j;
                        break;
                    }
                    chars.next();
                }
                out.push((&text[i..end], i, end));
            }
        }
    }
    out
}

fn is_name_char(c: char) -> bool {
    c.is_alphanumeric() || matches!(c, '-' | '_' | '.' | '@')
}

fn is_operator(word: &str) -> bool {
    matches!(word, "=" | "<" | ">" | "<=" | ">=" | "+" | "*" | "/")
}

fn looks_numeric(word: &str) -> bool {
    let b = word.as_bytes();
    match b {
        [d, ..] if d.is_ascii_digit() => true,
        [b'-' | b'+' | b'.', d, ..] if d.is_ascii_digit() => true,
        [b'-' | b'+', b'.', d, ..] if d.is_ascii_digit() => true,
        _ => false,
    }
}

fn classify(word: &str) -> Tok {
    match word {
        "(" => return Tok::LParen,
        ")" => return Tok::RParen,
        "-" => return Tok::Dash,
        w if is_operator(w) => return Tok::Name(w.to_owned()),
        _ => {}
    }
    if looks_numeric(word) {
        if let Ok(n) = word.parse::<f64>() {
            return Tok::Number(n);
        }
    }
    let (prefix, rest) = match word.as_bytes()[0] {
        b'?' => (Some('?'), &word[1..]),
        b':' => (Some(':'), &word[1..]),
        _ => (None, word),
    };
    if rest.is_empty() || !rest.chars().all(is_name_char) {
        return Tok::Invalid(word.to_owned());
    }
    let lower = if rest.is_ascii() {
        rest.to_ascii_lowercase()
    } else {
        rest.to_lowercase()
    };
    match prefix {
        Some('?') => Tok::Var(lower),
        Some(':') => Tok::Keyword(lower),
        _ => Tok::Name(lower),
    }
}

/// Splits a PDDL text into tokens. Never fails: bad words come back as
/// [`Tok::Invalid`] with a diagnostic each.
pub fn lex(text: &str, file: FileId) -> (Vec<Token>, Vec<Diagnostic>) {
    let mut diags = Vec::new();
    let mut cap = crate::diagnostic::Cap::new(codes::INVALID_TOKEN, "word that is not PDDL");
    let tokens: Vec<Token> = words(text)
        .into_iter()
        .map(|(word, start, end)| {
            let span = Span::new(file, start, end);
            let tok = classify(word);
            if matches!(tok, Tok::Invalid(_)) && cap.full() {
                cap.skip();
            } else if let Tok::Invalid(word) = &tok {
                let w = crate::diagnostic::shown(word);
                let bad = word
                    .trim_start_matches(['?', ':'])
                    .chars()
                    .find(|c| !is_name_char(*c));
                let message = match bad {
                    Some(c) => format!("`{w}` is not a PDDL name: `{c}` is not allowed in names"),
                    None => format!("`{w}` is not a PDDL name"),
                };
                cap.push(
                    &mut diags,
                    Diagnostic::error(codes::INVALID_TOKEN, span, message).with_hint(
                        "names are letters, digits, `-` and `_`; variables start with `?`, keywords with `:`",
                    ),
                );
            }
            Token { tok, span }
        })
        .collect();
    cap.finish(&mut diags, Span::new(file, text.len(), text.len()));
    (tokens, diags)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn toks(s: &str) -> Vec<Tok> {
        lex(s, 0).0.into_iter().map(|t| t.tok).collect()
    }

    #[test]
    fn classifies_words_case_insensitively() {
        assert_eq!(
            toks("(:Action Move ?X - Robot 1.5 <= -2) ; comment ()\n x"),
            vec![
                Tok::LParen,
                Tok::Keyword("action".into()),
                Tok::Name("move".into()),
                Tok::Var("x".into()),
                Tok::Dash,
                Tok::Name("robot".into()),
                Tok::Number(1.5),
                Tok::Name("<=".into()),
                Tok::Number(-2.0),
                Tok::RParen,
                Tok::Name("x".into()),
            ]
        );
    }

    #[test]
    fn reports_bad_characters_with_span() {
        let (tokens, diags) = lex("(a \"b\")", 0);
        assert_eq!(tokens.len(), 4);
        assert_eq!(diags.len(), 1);
        assert_eq!(diags[0].span, Span::new(0, 3, 6));
        assert!(diags[0].message.contains('"'));
    }

    #[test]
    fn words_end_at_whitespace_parentheses_and_comments() {
        let text = "a\x0bb\u{a0}c(d)e;f g\n\u{2003}h;";
        let ws: Vec<&str> = words(text).into_iter().map(|w| w.0).collect();
        assert_eq!(ws, ["a", "b", "c", "(", "d", ")", "e", "h"]);
        for (w, start, end) in words(text) {
            assert_eq!(&text[start..end], w);
        }
        assert!(words("; only a comment").is_empty());
        assert_eq!(
            toks("(ÄB)"),
            [Tok::LParen, Tok::Name("äb".into()), Tok::RParen]
        );
    }

    #[test]
    fn spans_are_bytes_after_multibyte_comments() {
        let (tokens, _) = lex("; á\n(x)", 0);
        assert_eq!(tokens[1].span, Span::new(0, 6, 7));
    }
}
