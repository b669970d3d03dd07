//! Tokens of `.btrules` files. Comments are kept apart (the formatter puts
//! them back); everything else goes to the parser.

use btc_pddl::diagnostic::{codes, Cap, Diagnostic};
use btc_pddl::source::{FileId, Span};
use smol_str::SmolStr;
use std::fmt;

#[derive(Clone, Debug, PartialEq)]
pub enum Tok {
    /// A name: keywords are names too, told apart by the parser.
    Ident(SmolStr),
    /// `?x`, without the `?`.
    Var(SmolStr),
    /// A string literal's raw contents (escapes not yet processed).
    Str(SmolStr),
    Int(i64),
    Float(f64),
    Punct(&'static str),
    /// A character that starts no token; reported by the lexer.
    Error(char),
    /// A parenthesised PDDL formula, already read by the PDDL front end.
    /// Made by the parser's pre-pass, never by the lexer.
    Formula(Box<btc_pddl::ast::Formula>),
    /// A parenthesised PDDL effect (as `Formula`).
    Effect(Box<btc_pddl::ast::Effect>),
    /// A parenthesised group that did not read as PDDL (reported).
    BadPddl,
    /// A rule's action-name pattern (`move-{src}-to-curb`), read from the
    /// touching tokens after `rule (`. Made by the parser's pre-pass.
    NamePattern(Vec<super::ast::NamePart>),
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
            Tok::NamePattern(_) => f.write_str("an action-name pattern"),
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

pub struct Lexed {
    pub tokens: Vec<(Tok, Span)>,
    pub comments: Vec<Comment>,
    pub diagnostics: Vec<Diagnostic>,
}

const TWO_CHAR_PUNCTS: &[&str] = &["=>", "==", "!=", "::"];
const ONE_CHAR_PUNCTS: &[&str] = &["(", ")", "{", "}", "[", "]", ",", ":", "=", "-"];

/// Names may hold any letters (as PDDL names may: `İs_enabled`).
fn is_ident_start(c: char) -> bool {
    c.is_alphabetic() || c == '_'
}

fn is_ident_rest(c: char) -> bool {
    c.is_alphanumeric() || c == '_' || c == '-'
}

/// The char at byte `i` (a char boundary) and its length.
fn char_at(text: &str, i: usize) -> Option<char> {
    text[i..].chars().next()
}

/// The end of the name that starts at `i` (after its first char).
fn ident_end(text: &str, mut j: usize) -> usize {
    let b = text.as_bytes();
    while j < b.len() {
        if b[j].is_ascii() {
            if !is_ident_rest(b[j] as char) {
                break;
            }
            j += 1;
        } else {
            match char_at(text, j) {
                Some(c) if is_ident_rest(c) => j += c.len_utf8(),
                _ => break,
            }
        }
    }
    j
}

/// Whether the text at `i` starts a token (or whitespace, or a comment):
/// where a run of characters that start nothing ends.
fn starts_something(text: &str, i: usize) -> bool {
    let b = text.as_bytes();
    let c = b[i];
    c.is_ascii_whitespace()
        || c == b'"'
        || c == b'/' && matches!(b.get(i + 1), Some(b'/' | b'*'))
        || c == b'?' && char_at(text, i + 1).is_some_and(is_ident_start)
        || c.is_ascii_digit()
        || (c == b'-' && b.get(i + 1).is_some_and(u8::is_ascii_digit))
        || char_at(text, i).is_some_and(is_ident_start)
        || TWO_CHAR_PUNCTS
            .iter()
            .any(|p| b[i..].starts_with(p.as_bytes()))
        || ONE_CHAR_PUNCTS.iter().any(|p| p.as_bytes()[0] == c)
}

/// Splits a rules file into tokens and comments. Hand-written (one pass
/// over the bytes) because the language server re-lexes on every keystroke;
/// the parser on top is chumsky. Never fails: bad characters become
/// [`Tok::Error`] tokens with a diagnostic.
pub fn lex(text: &str, file: FileId) -> Lexed {
    lex_keeping(text, file)
}

/// What [`lex_each`] leaves besides the tokens it hands over.
pub struct LexedRest {
    pub comments: Vec<Comment>,
    pub diagnostics: Vec<Diagnostic>,
}

/// [`lex`] for cutting a file into items: the same tokens, spans, comments
/// and diagnostics, but each token is handed to `sink` instead of kept,
/// and a name is kept only if `keep` accepts it (others are empty, as are
/// variables and strings). Every token of a huge file is then no
/// allocation, and there is no list of them: only its items are lexed
/// again with their names.
pub fn lex_each(
    text: &str,
    file: FileId,
    keep: &dyn Fn(&str) -> bool,
    sink: &mut dyn FnMut(Tok, Span),
) -> LexedRest {
    lex_into(text, file, Some(keep), sink)
}

/// Lexes, keeping every name.
fn lex_keeping(text: &str, file: FileId) -> Lexed {
    // About one token per 8 bytes in real files: reserving for one per
    // 6 saves a huge file's token list its copies as it grows (each
    // into fresh pages), and costs nothing for what stays untouched.
    let mut tokens = Vec::with_capacity(text.len() / 6 + 4);
    let rest = lex_into(text, file, None, &mut |t, s| tokens.push((t, s)));
    Lexed {
        tokens,
        comments: rest.comments,
        diagnostics: rest.diagnostics,
    }
}

/// Lexes into `sink`, keeping every name (`keep` is `None`) or those it
/// accepts.
fn lex_into(
    text: &str,
    file: FileId,
    keep: Option<&dyn Fn(&str) -> bool>,
    sink: &mut dyn FnMut(Tok, Span),
) -> LexedRest {
    let all = keep.is_none();
    let owned = |s: &str| {
        if keep.is_none_or(|k| k(s)) {
            SmolStr::new(s)
        } else {
            SmolStr::default()
        }
    };
    let b = text.as_bytes();
    let mut out = LexedRest {
        comments: Vec::new(),
        diagnostics: Vec::new(),
    };
    let mut i = 0;
    // End of the last code token, to tell trailing comments from own-line ones.
    let mut last_code_end: Option<usize> = None;
    // Start of the current line, kept as the lexer goes (searching back for
    // it per comment would be quadratic on one long line).
    let mut line_start = 0;
    let mut errors = Cap::new(codes::R_SYNTAX, "lexical error");
    let span = |s: usize, e: usize| Span::new(file, s, e);
    while i < b.len() {
        let c = b[i];
        if c.is_ascii_whitespace() {
            i += 1;
            if c == b'\n' {
                line_start = i;
            }
            continue;
        }
        let start = i;
        // Comments
        if b[i..].starts_with(b"//") || b[i..].starts_with(b"/*") {
            let end = if b[i + 1] == b'/' {
                text[i..].find('\n').map_or(b.len(), |k| i + k)
            } else {
                text[i + 2..].find("*/").map_or(b.len(), |k| i + 2 + k + 2)
            };
            let trailing = last_code_end.is_some_and(|e| e >= line_start);
            if let Some(k) = text[start..end].rfind('\n') {
                line_start = start + k + 1;
            }
            let body = &text[start..end];
            let body = if body.starts_with("//") {
                body.trim_end()
            } else {
                body
            };
            out.comments.push(Comment {
                text: body.to_owned(),
                span: span(start, end),
                trailing,
            });
            i = end;
            continue;
        }
        let tok = if c == b'"' {
            // A string ends at an unescaped quote, or (unterminated) at the line's end.
            let mut j = i + 1;
            let mut closed = false;
            while j < b.len() && b[j] != b'\n' {
                match b[j] {
                    b'\\' if j + 1 < b.len() && b[j + 1] != b'\n' => j += 2,
                    b'"' => {
                        closed = true;
                        break;
                    }
                    _ => j += 1,
                }
            }
            let j = j.min(b.len());
            if closed {
                i = j + 1;
                Tok::Str(if all {
                    SmolStr::new(&text[start + 1..j])
                } else {
                    SmolStr::default()
                })
            } else {
                i = j;
                errors.push(
                    &mut out.diagnostics,
                    Diagnostic::error(
                        codes::R_SYNTAX,
                        span(start, j),
                        "this string has no closing `\"`",
                    )
                    .with_hint("strings end on the line they start on"),
                );
                Tok::Str(if all {
                    SmolStr::new(&text[start + 1..j])
                } else {
                    SmolStr::default()
                })
            }
        } else if c == b'?' && char_at(text, i + 1).is_some_and(is_ident_start) {
            let first = char_at(text, i + 1).map_or(1, char::len_utf8);
            let j = ident_end(text, i + 1 + first);
            i = j;
            Tok::Var(if all {
                SmolStr::new(&text[start + 1..j])
            } else {
                SmolStr::default()
            })
        } else if c.is_ascii_digit() || (c == b'-' && b.get(i + 1).is_some_and(u8::is_ascii_digit))
        {
            let mut j = i + 1;
            while j < b.len() && b[j].is_ascii_digit() {
                j += 1;
            }
            if j + 1 < b.len() && b[j] == b'.' && b[j + 1].is_ascii_digit() {
                j += 1;
                while j < b.len() && b[j].is_ascii_digit() {
                    j += 1;
                }
            }
            i = j;
            let word = &text[start..j];
            match word.parse::<i64>() {
                Ok(n) => Tok::Int(n),
                Err(_) => match word.parse::<f64>() {
                    Ok(f) => Tok::Float(f),
                    Err(_) => Tok::Error('0'),
                },
            }
        } else if let Some(first) = char_at(text, i).filter(|c| is_ident_start(*c)) {
            let j = ident_end(text, i + first.len_utf8());
            i = j;
            Tok::Ident(owned(&text[start..j]))
        } else if let Some(p) = TWO_CHAR_PUNCTS
            .iter()
            .find(|p| b[i..].starts_with(p.as_bytes()))
        {
            i += 2;
            Tok::Punct(p)
        } else if let Some(p) = ONE_CHAR_PUNCTS.iter().find(|p| p.as_bytes()[0] == c) {
            i += 1;
            Tok::Punct(p)
        } else {
            // One token and one diagnostic for a whole run of characters
            // that start nothing (10 KB of NUL bytes is one problem).
            let ch = char_at(text, i).expect("not at the end");
            i += ch.len_utf8();
            let mut more = 0usize;
            while i < b.len() && !starts_something(text, i) {
                i += char_at(text, i).map_or(1, char::len_utf8);
                more += 1;
            }
            let shown = ch.escape_debug();
            let message = match more {
                0 => format!("`{shown}` cannot start anything here"),
                n => format!(
                    "`{shown}` and the {n} character{} after it cannot start anything here",
                    if n == 1 { "" } else { "s" }
                ),
            };
            let reported = !errors.full();
            errors.push(
                &mut out.diagnostics,
                Diagnostic::error(codes::R_SYNTAX, span(start, i), message),
            );
            if !reported {
                // Past the cap a bad run leaves no token either: the parser
                // has enough errors to report, and memory stays bounded.
                continue;
            }
            Tok::Error(ch)
        };
        if !matches!(tok, Tok::Error(_)) {
            last_code_end = Some(i);
        }
        sink(tok, span(start, i));
    }
    errors.finish(&mut out.diagnostics, span(b.len(), b.len()));
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
