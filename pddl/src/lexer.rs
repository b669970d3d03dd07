//! PDDL tokens. PDDL is case-insensitive: names, variables and keywords are
//! lower-cased here, so nothing downstream compares case again.

use crate::diagnostic::{codes, Diagnostic};
use crate::source::{FileId, Span};
use chumsky::prelude::*;

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

fn lexer<'s>() -> impl Parser<'s, &'s str, Vec<(&'s str, SimpleSpan)>, extra::Err<Rich<'s, char>>> {
    let comment = just(';')
        .then(any().filter(|c: &char| *c != '\n').repeated())
        .ignored();
    let whitespace = any().filter(|c: &char| c.is_whitespace()).ignored();
    let skip = choice((comment, whitespace)).repeated();
    let paren = one_of("()").to_slice();
    let word = any()
        .filter(|c: &char| !c.is_whitespace() && !matches!(c, '(' | ')' | ';'))
        .repeated()
        .at_least(1)
        .to_slice();
    choice((paren, word))
        .map_with(|s, e| (s, e.span()))
        .padded_by(skip)
        .repeated()
        .collect()
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
    let lower = rest.to_lowercase();
    match prefix {
        Some('?') => Tok::Var(lower),
        Some(':') => Tok::Keyword(lower),
        _ => Tok::Name(lower),
    }
}

/// Splits a PDDL text into tokens. Never fails: bad words come back as
/// [`Tok::Invalid`] with a diagnostic each.
pub fn lex(text: &str, file: FileId) -> (Vec<Token>, Vec<Diagnostic>) {
    let (words, errors) = lexer().parse(text).into_output_errors();
    let mut diags: Vec<Diagnostic> = errors
        .into_iter()
        .map(|e| {
            let s = e.span();
            Diagnostic::error(
                codes::INVALID_TOKEN,
                Span::new(file, s.start, s.end),
                format!("cannot read this text: {}", e.reason()),
            )
        })
        .collect();
    let mut cap = crate::diagnostic::Cap::new(codes::INVALID_TOKEN, "word that is not PDDL");
    let tokens: Vec<Token> = words
        .unwrap_or_default()
        .into_iter()
        .map(|(word, s)| {
            let span = Span::new(file, s.start, s.end);
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
    fn spans_are_bytes_after_multibyte_comments() {
        let (tokens, _) = lex("; á\n(x)", 0);
        assert_eq!(tokens[1].span, Span::new(0, 6, 7));
    }
}
