//! Tokens of `.btrules` files. Comments are kept apart (the formatter puts
//! them back); everything else goes to the parser.

use crate::diagnostic::{codes, Diagnostic};
use crate::source::{FileId, Span};
use chumsky::prelude::*;
use std::fmt;

#[derive(Clone, Debug, PartialEq)]
pub enum Tok {
    /// A name: keywords are names too, told apart by the parser.
    Ident(String),
    /// `?x`, without the `?`.
    Var(String),
    /// A string literal's raw contents (escapes not yet processed).
    Str(String),
    Int(i64),
    Float(f64),
    Punct(&'static str),
    /// A character that starts no token; reported by the lexer.
    Error(char),
    /// A parenthesised PDDL formula, already read by the PDDL front end.
    /// Made by the parser's pre-pass, never by the lexer.
    Formula(Box<crate::pddl::ast::Formula>),
    /// A parenthesised PDDL effect (as `Formula`).
    Effect(Box<crate::pddl::ast::Effect>),
    /// A parenthesised group that did not read as PDDL (reported).
    BadPddl,
}

impl fmt::Display for Tok {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Tok::Ident(s) => write!(f, "`{s}`"),
            Tok::Var(s) => write!(f, "`?{s}`"),
            Tok::Str(_) => f.write_str("a string"),
            Tok::Int(n) => write!(f, "`{n}`"),
            Tok::Float(n) => write!(f, "`{n}`"),
            Tok::Punct(p) => write!(f, "`{p}`"),
            Tok::Error(c) => write!(f, "`{c}`"),
            Tok::Formula(_) | Tok::Effect(_) | Tok::BadPddl => f.write_str("a PDDL formula"),
        }
    }
}

#[derive(Clone, Debug, PartialEq)]
pub struct Comment {
    pub text: String,
    pub span: Span,
    /// Whether code precedes it on its line (a trailing comment).
    pub trailing: bool,
}

#[derive(Clone, Debug, PartialEq)]
enum Lexeme {
    Tok(Tok),
    Comment(String),
    /// A string with no closing quote.
    Unterminated,
}

const PUNCTS: &[&str] = &[
    "=>", "==", "!=", "::", "(", ")", "{", "}", "[", "]", ",", ":", "=", "-",
];

fn lexer<'s>() -> impl Parser<'s, &'s str, Vec<(Lexeme, SimpleSpan)>, extra::Err<Rich<'s, char>>> {
    let ident_start = any().filter(|c: &char| c.is_ascii_alphabetic() || *c == '_');
    let ident_rest = any().filter(|c: &char| c.is_ascii_alphanumeric() || *c == '_' || *c == '-');
    let ident = ident_start.then(ident_rest.repeated()).to_slice();
    let var = just('?')
        .ignore_then(ident)
        .map(|s: &str| Tok::Var(s.to_owned()));
    let digits = any()
        .filter(|c: &char| c.is_ascii_digit())
        .repeated()
        .at_least(1);
    let number = just('-')
        .or_not()
        .then(digits)
        .then(just('.').then(digits).or_not())
        .to_slice()
        .map(|s: &str| match s.parse::<i64>() {
            Ok(n) => Tok::Int(n),
            Err(_) => s.parse::<f64>().map(Tok::Float).unwrap_or(Tok::Error('0')),
        });
    let escape = just('\\').then(any()).ignored();
    let string_body = escape.or(none_of("\"\\\n").ignored()).repeated().to_slice();
    let string = just('"')
        .ignore_then(string_body)
        .then(just('"').or_not())
        .map(|(s, close): (&str, _)| match close {
            Some(_) => Lexeme::Tok(Tok::Str(s.to_owned())),
            None => Lexeme::Unterminated,
        });
    let punct = choice(
        PUNCTS
            .iter()
            .map(|p| just(*p).to(Tok::Punct(p)))
            .collect::<Vec<_>>(),
    );
    let line_comment = just("//")
        .then(any().filter(|c: &char| *c != '\n').repeated())
        .to_slice()
        .map(|s: &str| Lexeme::Comment(s.trim_end().to_owned()));
    let block_comment = just("/*")
        .then(any().and_is(just("*/").not()).repeated())
        .then(just("*/").or_not())
        .to_slice()
        .map(|s: &str| Lexeme::Comment(s.to_owned()));
    let token = choice((
        line_comment,
        block_comment,
        string,
        number.map(Lexeme::Tok),
        var.map(Lexeme::Tok),
        ident.map(|s: &str| Lexeme::Tok(Tok::Ident(s.to_owned()))),
        punct.map(Lexeme::Tok),
        any().map(|c| Lexeme::Tok(Tok::Error(c))),
    ));
    token
        .map_with(|t, e| (t, e.span()))
        .padded()
        .repeated()
        .collect()
}

pub struct Lexed {
    pub tokens: Vec<(Tok, Span)>,
    pub comments: Vec<Comment>,
    pub diagnostics: Vec<Diagnostic>,
}

pub fn lex(text: &str, file: FileId) -> Lexed {
    let (lexemes, errors) = lexer().parse(text).into_output_errors();
    let mut out = Lexed {
        tokens: Vec::new(),
        comments: Vec::new(),
        diagnostics: errors
            .into_iter()
            .map(|e| {
                let s = e.span();
                Diagnostic::error(
                    codes::R_SYNTAX,
                    Span::new(file, s.start, s.end),
                    format!("cannot read this text: {}", e.reason()),
                )
            })
            .collect(),
    };
    let mut last_code_line_end = None::<usize>;
    for (lexeme, s) in lexemes.unwrap_or_default() {
        let span = Span::new(file, s.start, s.end);
        match lexeme {
            Lexeme::Comment(text_) => {
                let line_start = text[..s.start].rfind('\n').map_or(0, |i| i + 1);
                let trailing = last_code_line_end.is_some_and(|e| e >= line_start);
                out.comments.push(Comment {
                    text: text_,
                    span,
                    trailing,
                });
            }
            Lexeme::Unterminated => {
                out.diagnostics.push(
                    Diagnostic::error(codes::R_SYNTAX, span, "this string has no closing `\"`")
                        .with_hint("strings end on the line they start on"),
                );
                out.tokens
                    .push((Tok::Str(text[s.start + 1..s.end].to_owned()), span));
                last_code_line_end = Some(s.end);
            }
            Lexeme::Tok(Tok::Error(c)) => {
                out.diagnostics.push(Diagnostic::error(
                    codes::R_SYNTAX,
                    span,
                    format!("`{c}` cannot start anything here"),
                ));
                out.tokens.push((Tok::Error(c), span));
            }
            Lexeme::Tok(t) => {
                out.tokens.push((t, span));
                last_code_line_end = Some(s.end);
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn toks(s: &str) -> Vec<Tok> {
        lex(s, 0).tokens.into_iter().map(|t| t.0).collect()
    }

    #[test]
    fn lexes_a_rule_head_with_a_capture() {
        assert_eq!(
            toks("rule (PICK_{op} ?a [?loc]) => skip"),
            vec![
                Tok::Ident("rule".into()),
                Tok::Punct("("),
                Tok::Ident("PICK_".into()),
                Tok::Punct("{"),
                Tok::Ident("op".into()),
                Tok::Punct("}"),
                Tok::Var("a".into()),
                Tok::Punct("["),
                Tok::Var("loc".into()),
                Tok::Punct("]"),
                Tok::Punct(")"),
                Tok::Punct("=>"),
                Tok::Ident("skip".into()),
            ]
        );
    }

    #[test]
    fn keeps_comments_apart_and_marks_trailing_ones() {
        let l = lex("// head\naction A() // tail\n/* block */ x", 0);
        assert_eq!(l.comments.len(), 3);
        assert!(!l.comments[0].trailing);
        assert!(l.comments[1].trailing);
        assert!(!l.comments[2].trailing);
        assert_eq!(l.tokens.len(), 5);
    }

    #[test]
    fn numbers_strings_and_errors() {
        assert_eq!(
            toks("1.5 -3 \"a\\\"b\""),
            vec![Tok::Float(1.5), Tok::Int(-3), Tok::Str("a\\\"b".into())]
        );
        let l = lex("x # y \"open", 0);
        assert_eq!(l.diagnostics.len(), 2);
    }
}
