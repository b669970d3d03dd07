//! Reads the plan formats people actually have, line by line. Each line is
//! recognised by its shape, so files that mix headers and steps (planner
//! stdout) read as well as clean `sas_plan` files.
//!
//! Hand-written rather than built with chumsky: plans are line-oriented, each
//! line's shape decides its format, and reading must run at millions of steps
//! per second.

pub use super::step::{Call, PlanStep};
use crate::ast::{Name, SmolStr};
use crate::diagnostic::{codes, Diagnostic};
use crate::source::{FileId, Span};
use serde::Serialize;
use smol_str::StrExt;

mod quick;

#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum PlanFormat {
    /// Fast Downward / pyperplan: `(move a b)` lines, `; cost = N` footer.
    SasPlan,
    /// Temporal planners (OPTIC, POPF, LPG, PlanSys2): `0.000: (move a b) [1.000]`.
    Timed,
    /// Bare `move a b` lines, as printed in the ARIAC paper.
    Bare,
    /// FF's stdout: `step    0: PICK-UP B`, then `        1: STACK B A`.
    Ff,
    /// No steps at all.
    Empty,
}

#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct StatedCost {
    pub value: f64,
    pub span: Span,
}

#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Plan {
    pub format: PlanFormat,
    pub steps: Vec<PlanStep>,
    /// `; cost = N (...)` when the planner stated one.
    pub stated_cost: Option<StatedCost>,
}

/// Reads a plan. Lines that cannot be read are reported with their line and
/// column; the others are still returned.
pub fn parse_plan(text: &str, file: FileId) -> (Plan, Vec<Diagnostic>) {
    read_plan(text, file, true)
}

/// [`parse_plan`], with the fast path for common step lines or without it
/// (to test that the two agree).
fn read_plan(text: &str, file: FileId, quick: bool) -> (Plan, Vec<Diagnostic>) {
    // At most a step a line: counting them is cheaper than growing a long
    // plan's steps a dozen times.
    let lines = memchr::memchr_iter(b'\n', text.as_bytes()).count() + 1;
    let mut plan = Plan {
        format: PlanFormat::Empty,
        steps: Vec::with_capacity(lines),
        stated_cost: None,
    };
    let mut diags = Vec::new();
    let mut in_ff = false;
    let mut calls = quick::Calls::default();
    for (i, (line_start, raw)) in lines_of(text).enumerate() {
        let line = raw.strip_suffix('\r').unwrap_or(raw);
        let place = quick::Place {
            base: line_start,
            file,
            line: i as u32 + 1,
        };
        if let Some(format) = quick
            .then(|| quick::step(line, place, &mut calls, &mut plan.steps))
            .flatten()
        {
            if plan.format == PlanFormat::Empty {
                plan.format = format;
            }
            continue;
        }
        match LineReader::new(line, place).read(&mut in_ff) {
            Ok(Line::Blank) => {}
            Ok(Line::Comment) => {
                if let Some(c) = stated_cost(line, line_start, file) {
                    plan.stated_cost = Some(c);
                }
            }
            Ok(Line::Step(format, step)) => {
                if plan.format == PlanFormat::Empty {
                    plan.format = format;
                }
                plan.steps.push(step);
            }
            Err(d) => diags.push(d),
        }
    }
    if plan.steps.is_empty() && diags.is_empty() {
        diags.push(no_steps(file));
    }
    // Temporal planners do not always print in time order (LPG). A stable
    // sort takes a buffer the size of the steps before it looks at them:
    // most plans are in order already, and need none.
    let time = |s: &PlanStep| s.time.unwrap_or(0.0);
    if !plan
        .steps
        .is_sorted_by(|a, b| time(a).total_cmp(&time(b)).is_le())
    {
        plan.steps.sort_by(|a, b| time(a).total_cmp(&time(b)));
    }
    (plan, diags)
}

/// The warning on a plan of no steps (read or given as a value).
pub fn no_steps(file: FileId) -> Diagnostic {
    Diagnostic::warning(
        codes::PLAN_EMPTY,
        Span::new(file, 0, 0),
        "this plan has no steps",
    )
    .with_hint("plan steps look like `(action arg ...)`; is this the right file?")
}

/// Each line's start and text without its `\n`, as `split('\n')` cuts
/// them (an empty last line after a final `\n`), found with SIMD.
fn lines_of(text: &str) -> impl Iterator<Item = (usize, &str)> {
    let ends = memchr::memchr_iter(b'\n', text.as_bytes()).chain([text.len()]);
    let mut start = 0;
    ends.map(move |end| {
        let line = (start, &text[start..end]);
        start = end + 1;
        line
    })
}

enum Line {
    Blank,
    Comment,
    Step(PlanFormat, PlanStep),
}

struct LineReader<'a> {
    text: &'a str,
    pos: usize,
    base: usize,
    file: FileId,
    line: u32,
}

fn lower(s: &str) -> SmolStr {
    if s.is_ascii() {
        s.to_ascii_lowercase_smolstr()
    } else {
        s.to_lowercase_smolstr()
    }
}

fn is_word_byte(b: u8) -> bool {
    !(b.is_ascii_whitespace() || b == b'(' || b == b')' || b == b'[' || b == b']' || b == b';')
}

impl<'a> LineReader<'a> {
    fn new(text: &'a str, at: quick::Place) -> LineReader<'a> {
        LineReader {
            text,
            pos: 0,
            base: at.base,
            file: at.file,
            line: at.line,
        }
    }

    fn span(&self, start: usize, end: usize) -> Span {
        Span::new(self.file, self.base + start, self.base + end)
    }

    fn error(&self, at: usize, end: usize, message: impl Into<String>) -> Diagnostic {
        let end = end.max(at).min(self.text.len());
        Diagnostic::error(codes::PLAN_SYNTAX, self.span(at, end), message)
    }

    fn skip_ws(&mut self) {
        let b = self.text.as_bytes();
        while self.pos < b.len() && b[self.pos].is_ascii_whitespace() {
            self.pos += 1;
        }
    }

    fn peek(&self) -> Option<u8> {
        self.text.as_bytes().get(self.pos).copied()
    }

    /// A run of word characters; `None` at a delimiter or the end.
    fn word(&mut self) -> Option<(usize, &'a str)> {
        let text = self.text;
        let b = text.as_bytes();
        let start = self.pos;
        while self.pos < b.len() && is_word_byte(b[self.pos]) {
            self.pos += 1;
        }
        (self.pos > start).then(|| (start, &text[start..self.pos]))
    }

    fn name(&self, start: usize, w: &str) -> Result<Name, Diagnostic> {
        if let Some(c) = w
            .chars()
            .find(|c| !(c.is_alphanumeric() || matches!(c, '-' | '_' | '.' | '@')))
        {
            return Err(self
                .error(start, start + w.len(), format!("`{w}` is not a PDDL name: `{c}` is not allowed in names"))
                .with_hint("plan steps are `(action arg ...)`, `TIME: (action arg ...) [DURATION]` or `action arg ...`"));
        }
        Ok(Name {
            name: lower(w),
            span: self.span(start, start + w.len()),
        })
    }

    fn read(&mut self, in_ff: &mut bool) -> Result<Line, Diagnostic> {
        self.skip_ws();
        match self.peek() {
            None => return Ok(Line::Blank),
            Some(b';') => return Ok(Line::Comment),
            Some(b'(') => {
                return self
                    .parenthesised(None)
                    .map(|s| Line::Step(PlanFormat::SasPlan, s))
            }
            _ => {}
        }
        let save = self.pos;
        let Some((wstart, first)) = self.word() else {
            // `)`, `[` or `]` where a step should start.
            let at = self.pos;
            let c = &self.text[at..at + 1];
            return Err(self.error(
                at,
                at + 1,
                format!("unexpected `{c}` at the start of a plan line"),
            ));
        };
        // `step 0: NAME ARGS` (FF)
        if first.eq_ignore_ascii_case("step") {
            self.skip_ws();
            if let Some((_, n)) = self.word() {
                if let Some(num) = n.strip_suffix(':').or_else(|| self.colon_after(n)) {
                    if num.bytes().all(|b| b.is_ascii_digit()) && !num.is_empty() {
                        *in_ff = true;
                        return self.bare().map(|s| Line::Step(PlanFormat::Ff, s));
                    }
                }
            }
            self.pos = save;
        }
        // `TIME: (...)`, `N: NAME ARGS` (FF continuation) or `Header: ...`
        if let Some(head) = first.strip_suffix(':').or_else(|| self.colon_after(first)) {
            if let Ok(time) = head.parse::<f64>() {
                if head.starts_with('-') && time.is_finite() {
                    let after_head = self.pos;
                    self.skip_ws();
                    if self.peek() == Some(b'(') {
                        // `-0.000:` is a printing of 0; any other negative
                        // time is before the plan starts, never a comment.
                        if time != 0.0 {
                            return Err(self
                                .error(
                                    wstart,
                                    wstart + head.len(),
                                    format!("a step starts at a negative time, `{head}`"),
                                )
                                .with_hint("a plan's times start at 0"));
                        }
                        return self
                            .parenthesised(Some(0.0))
                            .map(|s| Line::Step(PlanFormat::Timed, s));
                    }
                    self.pos = after_head;
                }
                if !head.starts_with(['+', '-']) && time.is_finite() {
                    self.skip_ws();
                    if self.peek() == Some(b'(') {
                        return self
                            .parenthesised(Some(time))
                            .map(|s| Line::Step(PlanFormat::Timed, s));
                    }
                    if *in_ff {
                        return self.bare().map(|s| Line::Step(PlanFormat::Ff, s));
                    }
                    return Err(self
                        .error(
                            wstart,
                            self.text.len(),
                            "expected `(action arg ...)` after the time",
                        )
                        .with_hint("timed plans read `0.000: (action arg ...) [1.000]`"));
                }
            }
            if head.bytes().next().is_some_and(|b| b.is_ascii_alphabetic()) {
                return Ok(Line::Comment); // `Time: 0.01s`, `Plan:`, `ff: found legal plan`
            }
        }
        // A line of words: a header (`found legal plan as follows:`) or a bare step.
        if self.text.trim_end().ends_with(':') || self.text.contains(": ") {
            return Ok(Line::Comment);
        }
        self.pos = save;
        self.bare().map(|s| Line::Step(PlanFormat::Bare, s))
    }

    /// For `3 :` written with a space: consumes the `:` and returns the word.
    fn colon_after(&mut self, w: &'a str) -> Option<&'a str> {
        let save = self.pos;
        self.skip_ws();
        if self.peek() == Some(b':') {
            self.pos += 1;
            return Some(w);
        }
        self.pos = save;
        None
    }

    /// `name arg arg ...` up to the end of the line.
    fn bare(&mut self) -> Result<PlanStep, Diagnostic> {
        self.skip_ws();
        let start = self.pos;
        let mut words = Vec::new();
        loop {
            self.skip_ws();
            match self.word() {
                Some((s, w)) => words.push(self.name(s, w)?),
                None => break,
            }
        }
        if self.pos < self.text.len() {
            let at = self.pos;
            return Err(self.error(
                at,
                at + 1,
                format!("unexpected `{}` in a plan step", &self.text[at..at + 1]),
            ));
        }
        if words.is_empty() {
            return Err(self.error(start, self.text.len(), "expected an action name"));
        }
        let action = words.remove(0);
        let span = action.span.to(words.last().map_or(action.span, |w| w.span));
        Ok(PlanStep::new(action, words, None, None, self.line, span))
    }

    /// `(name arg ...)` then, optionally, `[duration]` and a `;` comment.
    fn parenthesised(&mut self, time: Option<f64>) -> Result<PlanStep, Diagnostic> {
        let open = self.pos;
        self.pos += 1;
        let mut words = Vec::new();
        loop {
            self.skip_ws();
            match self.peek() {
                Some(b')') => break,
                None => {
                    return Err(self
                        .error(open, open + 1, "this `(` is not closed on its line")
                        .with_hint("each plan step is one line: `(action arg ...)`"))
                }
                _ => match self.word() {
                    Some((s, w)) => words.push(self.name(s, w)?),
                    None => {
                        let at = self.pos;
                        return Err(self.error(
                            at,
                            at + 1,
                            format!("unexpected `{}` in a plan step", &self.text[at..at + 1]),
                        ));
                    }
                },
            }
        }
        let close = self.pos;
        self.pos += 1;
        if words.is_empty() {
            return Err(self.error(open, close + 1, "this step has no action name"));
        }
        self.skip_ws();
        let mut duration = None;
        if self.peek() == Some(b'[') {
            duration = Some(self.duration()?);
            self.skip_ws();
        }
        if let Some(b) = self.peek() {
            if b != b';' {
                let at = self.pos;
                return Err(self
                    .error(at, self.text.len(), "unexpected text after the step")
                    .with_hint("a step may be followed only by `[DURATION]` and a `;` comment"));
            }
        }
        let action = words.remove(0);
        let span = self.span(open, close + 1);
        Ok(PlanStep::new(
            action, words, time, duration, self.line, span,
        ))
    }

    /// `[1.000]` or LPG's `[D:1.00; C:4099.73]`.
    fn duration(&mut self) -> Result<f64, Diagnostic> {
        let open = self.pos;
        let Some(len) = self.text[open..].find(']') else {
            return Err(self.error(open, self.text.len(), "this `[` is not closed"));
        };
        let inner = &self.text[open + 1..open + len];
        self.pos = open + len + 1;
        let value = inner
            .split(';')
            .map(str::trim)
            .find_map(|part| part.strip_prefix("D:").or_else(|| part.strip_prefix("d:")))
            .unwrap_or(inner)
            .trim();
        value
            .parse::<f64>()
            .ok()
            .filter(|d| d.is_finite() && *d >= 0.0)
            .ok_or_else(|| {
                self.error(open, open + len + 1, format!("`{inner}` is not a duration"))
                    .with_hint("durations read `[1.000]` (or LPG's `[D:1.00; C:3.00]`)")
            })
    }
}

/// `; cost = 4 (unit cost)` as Fast Downward writes it.
fn stated_cost(line: &str, base: usize, file: FileId) -> Option<StatedCost> {
    let start = line.find("cost")?;
    let rest = line[start + 4..]
        .trim_start()
        .strip_prefix('=')?
        .trim_start();
    let end = rest.find(|c: char| c.is_whitespace()).unwrap_or(rest.len());
    let value = rest[..end].parse::<f64>().ok()?;
    Some(StatedCost {
        value,
        span: Span::new(file, base + start, base + line.trim_end().len()),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn steps(text: &str) -> (PlanFormat, Vec<String>, Vec<Diagnostic>) {
        let (plan, diags) = parse_plan(text, 0);
        let s = plan
            .steps
            .iter()
            .map(|s| {
                let mut out = s.action_name().to_string();
                for a in s.args() {
                    out.push(' ');
                    out.push_str(&a.name);
                }
                out
            })
            .collect();
        (plan.format, s, diags)
    }

    #[test]
    fn reads_sas_plan_and_cost() {
        let (plan, diags) = parse_plan(
            "(pick ball1 rooma left)\r\n(wait )\n; cost = 4 (unit cost)\n",
            0,
        );
        assert!(diags.is_empty());
        assert_eq!(plan.format, PlanFormat::SasPlan);
        assert_eq!(plan.steps.len(), 2);
        assert_eq!(plan.steps[1].arg_count(), 0);
        assert_eq!(plan.stated_cost.as_ref().unwrap().value, 4.0);
        assert_eq!(plan.steps[0].span, Span::new(0, 0, 23));
    }

    #[test]
    fn reads_the_ariac_listing() {
        let text = "Time: 0.013570785522460938s\nPlan:\nmove floor_robot curr_position bin1\ngrasp floor_robot battery_red bin1\n";
        let (format, s, diags) = steps(text);
        assert!(diags.is_empty(), "{diags:?}");
        assert_eq!(format, PlanFormat::Bare);
        assert_eq!(
            s,
            vec![
                "move floor_robot curr_position bin1",
                "grasp floor_robot battery_red bin1"
            ]
        );
    }

    #[test]
    fn reads_timed_variants_and_sorts_by_time() {
        let text = "; Version LPG-td-1.4\n; Time 0.01\n\n2.0003:   (WALK DRIVER2 S0 P2-0) [D:1.00; C:4099.73]\n0.0003:   (BOARD T1 DRIVER1 S0) [D:1.00; C:1.00]\n5.001: (navigate r w1 w3)  [5.000]\n0:\t(load r h c1)\t[2]\n";
        let (plan, diags) = parse_plan(text, 0);
        assert!(diags.is_empty(), "{diags:?}");
        assert_eq!(plan.format, PlanFormat::Timed);
        let names: Vec<_> = plan.steps.iter().map(|s| s.action_name()).collect();
        assert_eq!(names, vec!["load", "board", "walk", "navigate"]);
        assert_eq!(plan.steps[2].duration, Some(1.0));
        assert_eq!(plan.steps[3].line, 6);
    }

    #[test]
    fn reads_ff_stdout() {
        let text = "ff: found legal plan as follows\n\nstep    0: PICK-UP B\n        1: STACK B A\n     \ntime spent:    0.00 seconds instantiating 12 easy, 0 hard action templates\n";
        let (format, s, diags) = steps(text);
        assert!(diags.is_empty(), "{diags:?}");
        assert_eq!(format, PlanFormat::Ff);
        assert_eq!(s, vec!["pick-up b", "stack b a"]);
    }

    #[test]
    fn reports_bad_lines_with_position_and_keeps_going() {
        let (plan, diags) = parse_plan("(move a b\n(pick \"x\")\n(ok a)\n0.0: (x) [abc]\n", 0);
        assert_eq!(plan.steps.len(), 1);
        let at: Vec<_> = diags.iter().map(|d| (d.code, d.span.start)).collect();
        assert_eq!(at, vec![("L001", 0), ("L001", 16), ("L001", 37)]);
    }

    #[test]
    fn a_negative_time_is_an_error_and_minus_zero_is_zero() {
        let (plan, diags) = parse_plan("-0.000: (move a b) [1.000]\n-2.5: (move b a) [1.000]\n", 0);
        assert_eq!(plan.steps.len(), 1);
        assert_eq!(plan.steps[0].time, Some(0.0));
        assert!(plan.steps[0].time.unwrap().is_sign_positive());
        let at: Vec<_> = diags
            .iter()
            .map(|d| (d.code, d.span.start, d.span.end))
            .collect();
        assert_eq!(at, vec![("L001", 27, 31)]);
        assert!(
            diags[0].message.contains("negative time, `-2.5`"),
            "{}",
            diags[0].message
        );
    }

    /// Both readers on `text`, whole and line by line.
    fn assert_readers_agree(text: &str, what: &str) {
        assert_eq!(
            read_plan(text, 3, true),
            read_plan(text, 3, false),
            "{what}"
        );
        for line in text.lines() {
            assert_eq!(
                read_plan(line, 3, true),
                read_plan(line, 3, false),
                "{what}: {line:?}"
            );
        }
    }

    fn plan_files(dir: &std::path::Path, out: &mut Vec<std::path::PathBuf>) {
        for e in std::fs::read_dir(dir).unwrap() {
            let path = e.unwrap().path();
            if path.is_dir() {
                plan_files(&path, out);
            } else if path
                .extension()
                .is_some_and(|x| x == "plan" || x == "tplan" || x == "txt")
            {
                out.push(path);
            }
        }
    }

    #[test]
    fn fast_and_careful_readers_agree_on_the_repositorys_plans() {
        let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
        let mut files = Vec::new();
        plan_files(&root.join("examples"), &mut files);
        plan_files(&root.join("tests/fixtures"), &mut files);
        assert!(files.len() > 20, "{files:?}");
        for f in &files {
            let text = std::fs::read_to_string(f).unwrap();
            assert_readers_agree(&text, &f.display().to_string());
        }
    }

    const ODD_LINES: &[&str] = &[
        "(move a b)",
        "  (Move A-1 b_2 c.3 d@4)  ; note",
        "(move a b) ;",
        "(wait )",
        "()",
        "( )",
        "(move a b",
        "(move a b))",
        "(move (a) b)",
        "(move a\u{e9} b)",
        "(MOVE \u{c9}t\u{c9} b)",
        "(move \"a\" b)",
        "(move a:b c)",
        "(move a b) x",
        "(move a b)[1]",
        "(move a b) [1] ;c",
        "(move a b) [1] x",
        "(move a b) [1",
        "(move a b) [ 1 ]",
        "(move a b) [D:1.00; C:4099.73]",
        "(move a b) [-1]",
        "(move a b) [1.]",
        "(move a b) [.5]",
        "(move a b) [1e3]",
        "0: (move a b)",
        "0:(move a b)[2]",
        "0 : (move a b)",
        "00.500: (move a b) [0.25]",
        "1.: (move a b)",
        ".5: (move a b)",
        "+1: (move a b)",
        "-1: (move a b)",
        "-0.000: (move a b) [1.000]",
        "-0.5: (move a b) [1.000]",
        "-1: move a b",
        "1e2: (move a b)",
        "1.2.3: (move a b)",
        "2.001: (PICK_OP1 robot1 screwdriver tool_rack) [3.000]",
        "2.001:\t(pick r s t)\t[3.000]\t",
        "123456789012345678901234567890.5: (move a b) [1]",
        "0.1234567890123456789: (move a b) [0.30000000000000004]",
        "99999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999: (a)",
        "1: x",
        "1: (x",
        "1:",
        "step 0: PICK-UP B",
        "        1: STACK B A",
        "Time: 0.01s",
        "move a b",
        "; cost = 4 (unit cost)",
        ")",
        "[",
        "\u{c}(move a b)\u{c}",
    ];

    #[test]
    fn fast_and_careful_readers_agree_on_odd_lines() {
        for line in ODD_LINES {
            assert_readers_agree(line, "odd line");
        }
        assert_readers_agree(&ODD_LINES.join("\n"), "odd lines");
        assert_readers_agree(&ODD_LINES.join("\r\n"), "odd lines, CRLF");
    }

    /// Lines of random bytes from the characters the readers decide on.
    #[test]
    fn fast_and_careful_readers_agree_on_random_lines() {
        let alphabet: Vec<char> = "(()) [];:.:0123456789aBz-_@\t\u{e9}\"+e".chars().collect();
        let mut seed = 0x9e37_79b9_7f4a_7c15u64;
        let mut next = |n: usize| {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            (seed % n as u64) as usize
        };
        let shapes = ["(a b)", "1.5: (a b) [2]", "0: (x)", ""];
        for _ in 0..20_000 {
            let mut line: String = shapes[next(shapes.len())].into();
            for _ in 0..next(4) {
                let at = line
                    .char_indices()
                    .map(|(i, _)| i)
                    .nth(next(line.chars().count() + 1))
                    .unwrap_or(line.len());
                line.insert(at, alphabet[next(alphabet.len())]);
            }
            assert_readers_agree(&line, "random line");
        }
    }

    #[test]
    fn the_fast_path_reads_the_common_shapes() {
        let at = quick::Place {
            base: 0,
            file: 0,
            line: 1,
        };
        for line in [
            "(move a b)",
            "(move a b) ; comment",
            "2.001: (PICK_OP1 robot1 screwdriver tool_rack) [3.000]",
            "0:\t(load r h c1)\t[2]",
        ] {
            assert!(
                quick::step(line, at, &mut quick::Calls::default(), &mut Vec::new()).is_some(),
                "{line}"
            );
        }
    }

    #[test]
    fn decimals_read_as_parse_reads_them() {
        let mut seed = 12345u64;
        for _ in 0..100_000 {
            seed = seed
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            let int = (seed >> 20) % 10u64.pow((seed % 11) as u32 + 1);
            let frac_digits = ((seed >> 8) % 12) as usize;
            let frac = (seed >> 30) % 10u64.pow(frac_digits as u32);
            let s = if frac_digits == 0 {
                format!("{int}")
            } else {
                format!("{int}.{frac:0frac_digits$}")
            };
            let want: f64 = s.parse().unwrap();
            assert_eq!(
                quick::decimal(s.as_bytes()).to_bits(),
                want.to_bits(),
                "{s}"
            );
        }
        for s in [
            "0.1",
            "0.3",
            "2.001",
            "9007199254740993",
            "123456789012345.6",
            "0.000000000000001",
        ] {
            let want: f64 = s.parse().unwrap();
            assert_eq!(
                quick::decimal(s.as_bytes()).to_bits(),
                want.to_bits(),
                "{s}"
            );
        }
    }

    #[test]
    fn lines_are_cut_as_split_cuts_them() {
        for text in ["", "\n", "a", "a\n", "a\nb", "\n\na\r\n\nb\n", "é\nü"] {
            let mut offset = 0;
            let want: Vec<(usize, &str)> = text
                .split('\n')
                .map(|l| {
                    let start = offset;
                    offset += l.len() + 1;
                    (start, l)
                })
                .collect();
            assert_eq!(lines_of(text).collect::<Vec<_>>(), want, "{text:?}");
        }
    }
}
