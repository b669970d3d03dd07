//! Script tokens. Numbers glued to letters (`3foo`), `65.` and an
//! unterminated string are error tokens, as in BT.CPP.

use super::{Problem, SyntaxError};
use std::ops::Range;

#[derive(Clone, Debug, PartialEq)]
pub(super) enum Tok {
    Int(i64),
    Real(f64),
    Str(String),
    Bool(bool),
    Ident(String),
    /// An operator or punctuation, by its text.
    Op(&'static str),
    End,
}

const TWO: [&str; 12] = [
    "..", "&&", "||", "==", "!=", "<=", ">=", ":=", "+=", "-=", "*=", "/=",
];
const ONE: [&str; 17] = [
    "+", "-", "*", "/", "&", "|", "^", "~", "!", "<", ">", "=", "?", ":", "(", ")", ";",
];

fn ident_start(c: u8) -> bool {
    c.is_ascii_alphabetic() || c == b'_' || c == b'@'
}

fn ident_char(c: u8) -> bool {
    c.is_ascii_alphanumeric() || c == b'_'
}

/// The tokens of `src` with their byte ranges; the last is `End`.
pub(super) fn tokens(src: &str) -> Result<Vec<(Tok, Range<usize>)>, SyntaxError> {
    let b = src.as_bytes();
    let mut out = Vec::new();
    let mut i = 0;
    let bad = |at: usize, end: usize| SyntaxError {
        problem: Problem::BadToken(src[at..end].to_owned()),
        span: at..end,
    };
    while i < b.len() {
        let c = b[i];
        let start = i;
        if matches!(c, b' ' | b'\t' | b'\n' | b'\r') {
            i += 1;
            continue;
        }
        if c == b'\'' {
            let Some(end) = src[i + 1..].find('\'') else {
                return Err(SyntaxError {
                    problem: Problem::Unterminated(src[start..].to_owned()),
                    span: start..src.len(),
                });
            };
            out.push((
                Tok::Str(src[i + 1..i + 1 + end].to_owned()),
                start..i + end + 2,
            ));
            i += end + 2;
            continue;
        }
        if c.is_ascii_digit() {
            let (tok, end) = number(src, i).map_err(|end| bad(start, end))?;
            out.push((tok, start..end));
            i = end;
            continue;
        }
        if ident_start(c) {
            i += 1;
            while i < b.len() && ident_char(b[i]) {
                i += 1;
            }
            let w = &src[start..i];
            out.push((
                match w {
                    "true" => Tok::Bool(true),
                    "false" => Tok::Bool(false),
                    _ => Tok::Ident(w.to_owned()),
                },
                start..i,
            ));
            continue;
        }
        if let Some(op) = TWO.iter().find(|op| src[i..].starts_with(**op)) {
            out.push((Tok::Op(op), start..start + 2));
            i += 2;
            continue;
        }
        if let Some(op) = ONE.iter().find(|op| op.as_bytes()[0] == c) {
            out.push((Tok::Op(op), start..start + 1));
            i += 1;
            continue;
        }
        let len = src[i..].chars().next().map_or(1, char::len_utf8);
        return Err(bad(start, start + len));
    }
    out.push((Tok::End, b.len()..b.len()));
    Ok(out)
}

/// A number at `i`: the token and where it ends, or (an error token) where
/// the bad text ends.
fn number(src: &str, mut i: usize) -> Result<(Tok, usize), usize> {
    let b = src.as_bytes();
    let at = |i: usize| b.get(i).copied().unwrap_or(0);
    let garbage = |mut i: usize| {
        while ident_char(at(i)) || at(i) == b'.' {
            i += 1;
        }
        i
    };
    let start = i;
    if at(i) == b'0' && matches!(at(i + 1), b'x' | b'X') {
        i += 2;
        let digits = i;
        while at(i).is_ascii_hexdigit() {
            i += 1;
        }
        if i == digits || ident_char(at(i)) || at(i) == b'.' {
            return Err(garbage(i));
        }
        return i64::from_str_radix(&src[digits..i], 16)
            .map(|n| (Tok::Int(n), i))
            .map_err(|_| i);
    }
    while at(i).is_ascii_digit() {
        i += 1;
    }
    let mut real = false;
    if at(i) == b'.' && at(i + 1) != b'.' {
        if !at(i + 1).is_ascii_digit() {
            return Err(garbage(i + 1));
        }
        real = true;
        i += 1;
        while at(i).is_ascii_digit() {
            i += 1;
        }
    }
    if matches!(at(i), b'e' | b'E') {
        real = true;
        i += 1;
        if matches!(at(i), b'+' | b'-') {
            i += 1;
        }
        if !at(i).is_ascii_digit() {
            return Err(i);
        }
        while at(i).is_ascii_digit() {
            i += 1;
        }
    }
    if ident_start(at(i)) {
        while ident_char(at(i)) {
            i += 1;
        }
        return Err(i);
    }
    let text = &src[start..i];
    if real {
        // Out of a double's range: BT.CPP refuses the literal.
        match text.parse::<f64>() {
            Ok(f) if f.is_finite() => Ok((Tok::Real(f), i)),
            _ => Err(i),
        }
    } else {
        // Out of range: BT.CPP's from_chars leaves 0 there.
        Ok((Tok::Int(text.parse().unwrap_or(0)), i))
    }
}
