//! Renderings of [`Diagnostic`]s: ariadne reports for terminals, JSON for
//! tools. (The LSP rendering lives in the language server.)

use crate::diagnostic::{Diagnostic, Severity};
use crate::source::{FileId, Sources, Span};
use ariadne::{Color, Config, IndexType, Label, Report, ReportKind};
use serde::Serialize;

/// At most `max` diagnostics per file, in order, each file's rest counted
/// into one closing diagnostic (F005) that says how many more there were:
/// output and rendering time stay proportional to what anyone reads.
pub fn capped(diags: &[Diagnostic], max: usize) -> Vec<Diagnostic> {
    let mut kept: std::collections::BTreeMap<FileId, usize> = Default::default();
    let mut dropped: std::collections::BTreeMap<FileId, (usize, bool)> = Default::default();
    let mut out = Vec::new();
    for d in diags {
        let n = kept.entry(d.span.file).or_default();
        if *n < max {
            *n += 1;
            out.push(d.clone());
        } else {
            let e = dropped.entry(d.span.file).or_default();
            e.0 += 1;
            e.1 |= d.is_error();
        }
    }
    for (file, (n, error)) in dropped {
        let message = format!(
            "and {n} more diagnostic{} in this file, not shown (btc shows {max} per file)",
            if n == 1 { "" } else { "s" }
        );
        let span = Span::new(file, 0, 0);
        out.push(if error {
            Diagnostic::error(crate::diagnostic::codes::MORE_DIAGNOSTICS, span, message)
        } else {
            Diagnostic::warning(crate::diagnostic::codes::MORE_DIAGNOSTICS, span, message)
        });
    }
    out
}

/// Renders diagnostics as ariadne reports into a string. A diagnostic on a
/// line longer than [`MAX_RENDERED_LINE`](crate::limits::MAX_RENDERED_LINE)
/// is shown with an excerpt of its line instead (ariadne prints whole
/// lines, and one 10 MB line per diagnostic is quadratic output).
pub fn to_terminal(diags: &[Diagnostic], sources: &Sources, color: bool) -> String {
    // One cache for all reports: building ariadne's line index copies the
    // file, so doing it per diagnostic would be quadratic.
    let mut files: Vec<FileId> = diags
        .iter()
        .flat_map(|d| std::iter::once(d.span.file).chain(d.labels.iter().map(|l| l.span.file)))
        .collect();
    files.sort_unstable();
    files.dedup();
    let mut cache = ariadne::sources(
        files
            .into_iter()
            .map(|f| (sources.get(f).path.clone(), sources.text(f).to_owned())),
    );
    let mut out = Vec::new();
    for d in diags {
        if touches_long_line(d, sources) {
            write_excerpt(d, sources, &mut out);
        } else {
            write_report(d, sources, color, &mut cache, &mut out);
        }
    }
    String::from_utf8_lossy(&out).into_owned()
}

/// The byte range of the line around `offset`, found by looking at most
/// a little past the rendering limit each way.
fn line_around(text: &str, offset: usize) -> (usize, usize, bool) {
    let max = crate::limits::MAX_RENDERED_LINE;
    let b = text.as_bytes();
    let offset = offset.min(b.len());
    let from = offset.saturating_sub(max + 1);
    let start = b[from..offset]
        .iter()
        .rposition(|&c| c == b'\n')
        .map(|k| from + k + 1);
    let to = (offset + max + 1).min(b.len());
    let end = b[offset..to]
        .iter()
        .position(|&c| c == b'\n')
        .map(|k| offset + k);
    let long = start.is_none() && from > 0 || end.is_none() && to < b.len();
    let long = long || end.unwrap_or(to) - start.unwrap_or(from) > max;
    (start.unwrap_or(from), end.unwrap_or(to), long)
}

fn touches_long_line(d: &Diagnostic, sources: &Sources) -> bool {
    std::iter::once(d.span)
        .chain(d.labels.iter().map(|l| l.span))
        .any(|s| {
            let text = sources.text(s.file);
            line_around(text, s.start as usize).2 || line_around(text, s.end as usize).2
        })
}

/// A plain report with an excerpt of a long line around the span.
fn write_excerpt(d: &Diagnostic, sources: &Sources, out: &mut Vec<u8>) {
    use std::io::Write;
    let kind = match d.severity {
        Severity::Error => "Error",
        Severity::Warning => "Warning",
    };
    let file = sources.get(d.span.file);
    let (line, col) = file.line_col(d.span.start);
    let _ = writeln!(out, "[{}] {kind}: {}", d.code, d.message);
    let _ = writeln!(out, "   ╭─[ {}:{line}:{col} ]", file.path);
    let text = &file.text;
    let at = (d.span.start as usize).min(text.len());
    let half = crate::limits::MAX_RENDERED_LINE / 2;
    let mut a = at.saturating_sub(half);
    while !text.is_char_boundary(a) {
        a -= 1;
    }
    let mut b = (at + half).min(text.len());
    while !text.is_char_boundary(b) {
        b += 1;
    }
    let piece = &text[a..b];
    let rel = at - a;
    let from = piece[..rel].rfind('\n').map_or(0, |k| k + 1);
    let to = piece[rel..].find('\n').map_or(piece.len(), |k| rel + k);
    let piece = &piece[from..to];
    let clean = |s: &str| -> String {
        s.chars()
            .map(|c| if c.is_control() { '\u{FFFD}' } else { c })
            .collect()
    };
    let before = clean(&piece[..rel - from]);
    let shown = clean(piece);
    let _ = writeln!(
        out,
        "   │ (line {line} is too long to show whole; around column {col}:)"
    );
    let _ = writeln!(out, "   │ …{shown}…");
    let pad = " ".repeat(before.chars().count() + 1);
    let _ = writeln!(out, "   │ {pad}^ {}", code_title(d.code));
    for l in &d.labels {
        let lf = sources.get(l.span.file);
        let (ll, lc) = lf.line_col(l.span.start);
        let _ = writeln!(out, "   │ {}:{ll}:{lc}: {}", lf.path, l.message);
    }
    if let Some(h) = &d.hint {
        let _ = writeln!(out, "   │ Help: {h}");
    }
    let _ = writeln!(out, "───╯");
}

fn ariadne_span(sources: &Sources, span: Span) -> (String, std::ops::Range<usize>) {
    let text = sources.text(span.file);
    // Clamp so a span past a (lossily decoded) end never panics the renderer.
    let end = (span.end as usize).min(text.len());
    let start = (span.start as usize).min(end);
    (sources.get(span.file).path.clone(), start..end)
}

fn write_report(
    d: &Diagnostic,
    sources: &Sources,
    color: bool,
    cache: &mut impl ariadne::Cache<String>,
    out: &mut Vec<u8>,
) {
    let (kind, c) = match d.severity {
        Severity::Error => (ReportKind::Error, Color::Red),
        Severity::Warning => (ReportKind::Warning, Color::Yellow),
    };
    let primary = ariadne_span(sources, d.span);
    let mut report = Report::build(kind, primary.clone())
        .with_config(
            Config::new()
                .with_index_type(IndexType::Byte)
                .with_color(color),
        )
        .with_code(d.code)
        .with_message(&d.message)
        .with_label(
            Label::new(primary)
                .with_message(code_title(d.code))
                .with_color(c),
        );
    for l in &d.labels {
        report = report.with_label(
            Label::new(ariadne_span(sources, l.span))
                .with_message(&l.message)
                .with_color(Color::Blue),
        );
    }
    if let Some(h) = &d.hint {
        report = report.with_help(h);
    }
    // Writing into a Vec cannot fail.
    let _ = report.finish().write(&mut *cache, &mut *out);
}

/// The title of a code, shown under the primary span.
pub fn code_title(code: &str) -> &'static str {
    crate::diagnostic::codes::ALL
        .iter()
        .find(|c| c.id == code)
        .map_or("here", |c| c.title)
}

/// A position for JSON consumers: 1-based line, 1-based character column.
#[derive(Serialize)]
pub struct Position {
    pub line: u32,
    pub column: u32,
    pub offset: u32,
}

#[derive(Serialize)]
pub struct JsonLabel {
    pub file: String,
    pub start: Position,
    pub end: Position,
    pub message: String,
}

#[derive(Serialize)]
pub struct JsonDiagnostic {
    pub code: &'static str,
    pub severity: Severity,
    pub message: String,
    pub file: String,
    pub start: Position,
    pub end: Position,
    pub hint: Option<String>,
    pub labels: Vec<JsonLabel>,
    /// Machine-applicable repairs (what the language server's quick fixes
    /// apply): replace `start`..`end` of `file` with `replacement`.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub fixes: Vec<JsonFix>,
}

#[derive(Serialize)]
pub struct JsonFix {
    pub title: String,
    pub file: String,
    pub start: Position,
    pub end: Position,
    pub replacement: String,
}

fn position(sources: &Sources, file: FileId, offset: u32) -> Position {
    let (line, column) = sources.get(file).line_col(offset);
    Position {
        line,
        column,
        offset,
    }
}

pub fn to_json(d: &Diagnostic, sources: &Sources) -> JsonDiagnostic {
    let f = d.span.file;
    JsonDiagnostic {
        code: d.code,
        severity: d.severity,
        message: d.message.clone(),
        file: sources.get(f).path.clone(),
        start: position(sources, f, d.span.start),
        end: position(sources, f, d.span.end),
        hint: d.hint.clone(),
        labels: d
            .labels
            .iter()
            .map(|l| JsonLabel {
                file: sources.get(l.span.file).path.clone(),
                start: position(sources, l.span.file, l.span.start),
                end: position(sources, l.span.file, l.span.end),
                message: l.message.clone(),
            })
            .collect(),
        fixes: d
            .fixes
            .iter()
            .map(|x| JsonFix {
                title: x.title.clone(),
                file: sources.get(x.span.file).path.clone(),
                start: position(sources, x.span.file, x.span.start),
                end: position(sources, x.span.file, x.span.end),
                replacement: x.replacement.clone(),
            })
            .collect(),
    }
}

/// One line per diagnostic, `file:line:col: severity[code]: message`, for
/// logs and compact test expectations.
pub fn to_short(d: &Diagnostic, sources: &Sources) -> String {
    let j = to_json(d, sources);
    let sev = match d.severity {
        Severity::Error => "error",
        Severity::Warning => "warning",
    };
    format!(
        "{}:{}:{}: {sev}[{}]: {}",
        j.file, j.start.line, j.start.column, d.code, d.message
    )
}
