//! Renderings of [`Diagnostic`]s: ariadne reports for terminals, JSON for
//! tools. (The LSP rendering lives in the language server.)

use crate::diagnostic::{Diagnostic, Severity};
use crate::source::{FileId, Sources, Span};
use ariadne::{Color, Config, IndexType, Label, Report, ReportKind};
use serde::Serialize;

/// Renders diagnostics as ariadne reports into a string.
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
        write_report(d, sources, color, &mut cache, &mut out);
    }
    String::from_utf8_lossy(&out).into_owned()
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
