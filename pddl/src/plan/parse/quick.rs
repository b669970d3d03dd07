//! The plan reader's fast path: the step lines planners print nearly all
//! of, `(name arg ...)` and `TIME: (name arg ...) [DURATION]`, read byte by
//! byte. Anything it is not sure of (other shapes, non-ASCII names, odd
//! numbers, every error) it leaves to the careful reader, which alone
//! reports problems; so on the lines it accepts it must read exactly what
//! the careful reader reads (a test in `super::tests` compares them).

use super::{Call, PlanFormat, PlanStep};
use crate::ast::{Name, SmolStr};
use crate::source::{FileId, Span};
use rustc_hash::FxHashMap;
use smol_str::StrExt;
use std::sync::Arc;

/// The calls read so far, by their text from `(` to `)`: a call written
/// again (byte for byte) is the same call at another place, so it is
/// neither read nor stored again.
pub(super) type Calls<'a> = FxHashMap<&'a str, Arc<Call>>;

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

/// Reads the step on `text` onto `steps`, with the plan format its line
/// shows; `None` (and nothing added) for the careful reader to decide.
/// The step goes straight to its place: built on the stack and returned
/// through two enums, its optional times were copied three times, each
/// copy a store-to-load stall (a fifth of a 100,000-step plan's read).
pub(super) fn step<'a>(
    text: &'a str,
    at: Place,
    calls: &mut Calls<'a>,
    steps: &mut Vec<PlanStep>,
) -> Option<PlanFormat> {
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
    let close = open + memchr::memchr(b')', &b[open..])?;
    let call = match calls.get(&text[open..=close]) {
        Some(call) => call.clone(),
        None => {
            let (action, after) = name(text, open + 1, at)?;
            let (args, end) = args(text, after, at)?;
            // Names stop at spaces and `)`: the first `)` ends them.
            debug_assert_eq!(end, close);
            let call = Arc::new(Call::new(action, args, at.span(open, close + 1)));
            calls.insert(&text[open..=close], call.clone());
            call
        }
    };
    let (duration, end) = duration(b, skip_ws(b, close + 1))?;
    // Only a comment may follow.
    if end < b.len() && b[end] != b';' {
        return None;
    }
    let format = match time {
        Some(_) => PlanFormat::Timed,
        None => PlanFormat::SasPlan,
    };
    steps.push(PlanStep {
        call,
        time,
        duration,
        line: at.line,
        span: at.span(open, close + 1),
    });
    Some(format)
}

/// What the fast path tells apart in a byte (flags: an upper-case letter
/// is a name byte too).
const OTHER: u8 = 0;
const NAME: u8 = 1;
const UPPER: u8 = 2;
const SPACE: u8 = 4;

/// Each byte's class, looked up once per byte. Names are the ASCII bytes
/// of PDDL names; the careful reader also takes other alphanumeric
/// characters, and lower-cases them its own way.
static CLASS: [u8; 256] = {
    let mut t = [OTHER; 256];
    let mut i = 0;
    while i < 256 {
        let c = i as u8;
        if c.is_ascii_uppercase() {
            t[i] = NAME | UPPER;
        } else if c.is_ascii_alphanumeric() || matches!(c, b'-' | b'_' | b'.' | b'@') {
            t[i] = NAME;
        } else if c.is_ascii_whitespace() {
            t[i] = SPACE;
        }
        i += 1;
    }
    t
};

fn skip_ws(b: &[u8], mut pos: usize) -> usize {
    while pos < b.len() && CLASS[b[pos] as usize] == SPACE {
        pos += 1;
    }
    pos
}

/// The name after the spaces at `pos`, and where it ends; `None` unless
/// it ends at a space or a `)` (anything else is not a name the fast path
/// knows).
fn name(text: &str, pos: usize, at: Place) -> Option<(Name, usize)> {
    let b = text.as_bytes();
    let start = skip_ws(b, pos);
    let (mut end, mut seen) = (start, OTHER);
    while end < b.len() && CLASS[b[end] as usize] & NAME != 0 {
        seen |= CLASS[b[end] as usize];
        end += 1;
    }
    let next = *b.get(end)?;
    if end == start || !(next == b')' || CLASS[next as usize] == SPACE) {
        return None;
    }
    let written = &text[start..end];
    // Most arguments are written in lower case already.
    let name = if seen & UPPER != 0 {
        written.to_ascii_lowercase_smolstr()
    } else {
        SmolStr::new(written)
    };
    let name = Name {
        name,
        span: at.span(start, end),
    };
    Some((name, end))
}

/// The names from `pos` to the `)`, which must be on the line, and the
/// `)`'s position.
fn args(text: &str, mut pos: usize, at: Place) -> Option<(Vec<Name>, usize)> {
    let b = text.as_bytes();
    let mut args = Vec::with_capacity(4);
    loop {
        pos = skip_ws(b, pos);
        if *b.get(pos)? == b')' {
            return Some((args, pos));
        }
        let (arg, end) = name(text, pos, at)?;
        args.push(arg);
        pos = end;
    }
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
    let mut d = Digits::default();
    let int_end = d.read(b, pos);
    if int_end == pos {
        return None;
    }
    let mut end = int_end;
    if b.get(int_end) == Some(&b'.') {
        end = d.read(b, int_end + 1);
        d.frac = end - (int_end + 1);
        if d.frac == 0 {
            return None;
        }
    }
    let v = d.value(&b[pos..end]);
    v.is_finite().then_some((v, end))
}

/// The digits of a number read so far.
#[derive(Default)]
struct Digits {
    mantissa: u64,
    count: usize,
    frac: usize,
}

impl Digits {
    /// Reads the digits from `pos`; returns where they end.
    fn read(&mut self, b: &[u8], mut pos: usize) -> usize {
        while let Some(c) = b.get(pos).filter(|c| c.is_ascii_digit()) {
            self.mantissa = self
                .mantissa
                .wrapping_mul(10)
                .wrapping_add(u64::from(c - b'0'));
            self.count += 1;
            pos += 1;
        }
        pos
    }

    /// The value of `text`, whose digits these are, as `str::parse::<f64>`
    /// reads it. With at most 15 digits the digits and the power of ten are
    /// exact doubles, so one division is correctly rounded (Clinger's fast
    /// path), as `parse` is; longer numbers go through `parse`.
    fn value(&self, text: &[u8]) -> f64 {
        if self.count <= 15 {
            return self.mantissa as f64 / POW10[self.frac];
        }
        std::str::from_utf8(text)
            .ok()
            .and_then(|t| t.parse().ok())
            .unwrap_or(f64::NAN)
    }
}

/// Exact powers of ten: every one up to 1e22 is a double.
const POW10: [f64; 23] = [
    1e0, 1e1, 1e2, 1e3, 1e4, 1e5, 1e6, 1e7, 1e8, 1e9, 1e10, 1e11, 1e12, 1e13, 1e14, 1e15, 1e16,
    1e17, 1e18, 1e19, 1e20, 1e21, 1e22,
];

/// The value of `DIGITS[.DIGITS]` (for tests: what [`number`] reads).
#[cfg(test)]
pub(super) fn decimal(s: &[u8]) -> f64 {
    number(s, 0).map_or(f64::NAN, |(v, _)| v)
}
