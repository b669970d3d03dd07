//! The plan reader's fast path: the step lines planners print nearly all
//! of, `(name arg ...)` and `TIME: (name arg ...) [DURATION]`, read byte by
//! byte. Anything it is not sure of (other shapes, non-ASCII names, odd
//! numbers, every error) it leaves to the careful reader, which alone
//! reports problems; so on the lines it accepts it must read exactly what
//! the careful reader reads (a test in `super::tests` compares them).

use super::{Line, PlanFormat, PlanStep};
use crate::ast::Name;
use crate::source::{FileId, Span};

/// Where a line is: what spans and steps need of it.
#[derive(Clone, Copy)]
pub(super) struct Place {
    pub base: usize,
    pub file: FileId,
    pub line: u32,
}

impl Place {
    fn span(self, start: usize, end: usize) -> Span {
        Span::new(self.file, self.base + start, self.base + end)
    }
}

/// The step on `text`, or `None` for the careful reader to decide.
pub(super) fn step(text: &str, at: Place) -> Option<Line> {
    let b = text.as_bytes();
    let mut pos = skip_ws(b, 0);
    let time = if b.get(pos)?.is_ascii_digit() {
        let (t, after) = number(b, pos)?;
        if b.get(after) != Some(&b':') {
            return None;
        }
        pos = skip_ws(b, after + 1);
        Some(t)
    } else {
        None
    };
    if b.get(pos) != Some(&b'(') {
        return None;
    }
    let open = pos;
    let (mut words, close) = names(text, open + 1, at)?;
    let (duration, end) = duration(b, skip_ws(b, close + 1))?;
    // Only a comment may follow.
    if end < b.len() && b[end] != b';' {
        return None;
    }
    let action = words.remove(0);
    let format = match time {
        Some(_) => PlanFormat::Timed,
        None => PlanFormat::SasPlan,
    };
    Some(Line::Step(
        format,
        PlanStep {
            action,
            args: words,
            time,
            duration,
            line: at.line,
            span: at.span(open, close + 1),
        },
    ))
}

fn skip_ws(b: &[u8], mut pos: usize) -> usize {
    while pos < b.len() && b[pos].is_ascii_whitespace() {
        pos += 1;
    }
    pos
}

/// The ASCII bytes of PDDL names; the careful reader also takes other
/// alphanumeric characters, and lower-cases them its own way.
fn is_name_byte(c: u8) -> bool {
    c.is_ascii_alphanumeric() || matches!(c, b'-' | b'_' | b'.' | b'@')
}

/// The names from `pos` to the `)`, which must be on the line, and the
/// `)`'s position; at least one name.
fn names(text: &str, mut pos: usize, at: Place) -> Option<(Vec<Name>, usize)> {
    let b = text.as_bytes();
    let mut words = Vec::with_capacity(4);
    loop {
        pos = skip_ws(b, pos);
        if *b.get(pos)? == b')' {
            break;
        }
        let start = pos;
        while pos < b.len() && is_name_byte(b[pos]) {
            pos += 1;
        }
        // A name ends at a space or the `)`; anything else is not a
        // name the fast path knows.
        let next = *b.get(pos)?;
        if pos == start || !(next.is_ascii_whitespace() || next == b')') {
            return None;
        }
        words.push(Name {
            name: text[start..pos].to_ascii_lowercase(),
            span: at.span(start, pos),
        });
    }
    (!words.is_empty()).then_some((words, pos))
}

/// An optional `[DURATION]` at `pos`, and where the line goes on after it.
fn duration(b: &[u8], pos: usize) -> Option<(Option<f64>, usize)> {
    if b.get(pos) != Some(&b'[') {
        return Some((None, pos));
    }
    let (d, after) = number(b, pos + 1)?;
    if b.get(after) != Some(&b']') {
        return None;
    }
    Some((Some(d), skip_ws(b, after + 1)))
}

/// `DIGITS` or `DIGITS.DIGITS` at `pos`: its finite value and its end.
fn number(b: &[u8], pos: usize) -> Option<(f64, usize)> {
    let int_end = digits_end(b, pos);
    let mut end = int_end;
    if b.get(int_end) == Some(&b'.') {
        end = digits_end(b, int_end + 1);
        if end == int_end + 1 {
            return None;
        }
    }
    if int_end == pos {
        return None;
    }
    let v = decimal(&b[pos..end]);
    v.is_finite().then_some((v, end))
}

fn digits_end(b: &[u8], mut pos: usize) -> usize {
    while pos < b.len() && b[pos].is_ascii_digit() {
        pos += 1;
    }
    pos
}

/// Exact powers of ten: every one up to 1e22 is a double.
const POW10: [f64; 23] = [
    1e0, 1e1, 1e2, 1e3, 1e4, 1e5, 1e6, 1e7, 1e8, 1e9, 1e10, 1e11, 1e12, 1e13, 1e14, 1e15, 1e16,
    1e17, 1e18, 1e19, 1e20, 1e21, 1e22,
];

/// The value of `DIGITS[.DIGITS]`, as `str::parse::<f64>` reads it. With
/// at most 15 digits the digits and the power of ten are exact doubles, so
/// one division is correctly rounded (Clinger's fast path), as `parse` is;
/// longer numbers go through `parse`.
pub(super) fn decimal(s: &[u8]) -> f64 {
    let mut mantissa: u64 = 0;
    let (mut count, mut frac, mut after_dot) = (0usize, 0usize, false);
    for &c in s {
        if c == b'.' {
            after_dot = true;
            continue;
        }
        mantissa = mantissa.wrapping_mul(10).wrapping_add(u64::from(c - b'0'));
        count += 1;
        frac += usize::from(after_dot);
    }
    if count <= 15 {
        return mantissa as f64 / POW10[frac];
    }
    std::str::from_utf8(s)
        .ok()
        .and_then(|t| t.parse().ok())
        .unwrap_or(f64::NAN)
}
