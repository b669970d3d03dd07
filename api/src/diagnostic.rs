//! Diagnostics as plain values: what went wrong, where (a path and 1-based
//! line and column), and what to do about it. Nothing here borrows the
//! compiler's database, so an embedder can keep, send or print them.

use btc_pddl::render;
use btc_pddl::source::Sources;
use serde::Serialize;
use std::fmt;

#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Severity {
    Error,
    Warning,
}

/// A place in a file: 1-based line and character column.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
pub struct Position {
    pub line: u32,
    pub column: u32,
}

/// A machine-applicable repair: replace `start..end` of `path` with
/// `replacement` (what the language server offers as a quick fix).
#[derive(Clone, Debug, PartialEq, Eq, Serialize)]
pub struct Fix {
    pub title: String,
    pub path: String,
    pub start: Position,
    pub end: Position,
    pub replacement: String,
}

/// A secondary place a diagnostic points at (an earlier definition...).
#[derive(Clone, Debug, PartialEq, Eq, Serialize)]
pub struct Label {
    pub path: String,
    pub start: Position,
    pub end: Position,
    pub message: String,
}

#[derive(Clone, Debug, PartialEq, Eq, Serialize)]
pub struct Diagnostic {
    /// The stable code (`R003`, `P102`...), documented in docs/language.md.
    pub code: String,
    pub severity: Severity,
    pub message: String,
    /// The file as btc was given it (`<rules>`, `<domain>`... for texts).
    pub path: String,
    pub start: Position,
    pub end: Position,
    pub hint: Option<String>,
    pub labels: Vec<Label>,
    pub fixes: Vec<Fix>,
}

impl Diagnostic {
    pub fn is_error(&self) -> bool {
        self.severity == Severity::Error
    }

    /// The line and column of the start, for the common case.
    pub fn line(&self) -> u32 {
        self.start.line
    }

    pub fn column(&self) -> u32 {
        self.start.column
    }

    /// A diagnostic that has no place in a file (an input that is not a
    /// file: an agent's goal, a handler's answer).
    pub(crate) fn without_place(code: &str, message: impl Into<String>, path: &str) -> Diagnostic {
        let at = Position { line: 0, column: 0 };
        Diagnostic {
            code: code.to_owned(),
            severity: Severity::Error,
            message: message.into(),
            path: path.to_owned(),
            start: at,
            end: at,
            hint: None,
            labels: Vec::new(),
            fixes: Vec::new(),
        }
    }

    pub(crate) fn hint(mut self, hint: impl Into<String>) -> Diagnostic {
        self.hint = Some(hint.into());
        self
    }
}

impl fmt::Display for Diagnostic {
    /// `path:line:column: error[CODE]: message`, as `btc` prints in short.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let sev = match self.severity {
            Severity::Error => "error",
            Severity::Warning => "warning",
        };
        write!(
            f,
            "{}:{}:{}: {sev}[{}]: {}",
            self.path, self.start.line, self.start.column, self.code, self.message
        )?;
        if let Some(h) = &self.hint {
            write!(f, " (hint: {h})")?;
        }
        Ok(())
    }
}

/// Bad input: the diagnostics that say why (errors first; warnings that
/// came with them follow).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Error {
    pub diagnostics: Vec<Diagnostic>,
}

impl Error {
    pub(crate) fn new(mut diagnostics: Vec<Diagnostic>) -> Error {
        diagnostics.sort_by_key(|d| !d.is_error());
        Error { diagnostics }
    }

    pub(crate) fn one(d: Diagnostic) -> Error {
        Error {
            diagnostics: vec![d],
        }
    }

    pub fn errors(&self) -> impl Iterator<Item = &Diagnostic> {
        self.diagnostics.iter().filter(|d| d.is_error())
    }
}

impl fmt::Display for Error {
    /// The first error, and how many more there are.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self.diagnostics.first() {
            Some(d) => {
                write!(f, "{d}")?;
                let more = self.errors().count().saturating_sub(1);
                if more > 0 {
                    write!(
                        f,
                        " (and {more} more error{})",
                        if more == 1 { "" } else { "s" }
                    )?;
                }
                Ok(())
            }
            None => f.write_str("btc refused the input without saying why"),
        }
    }
}

impl std::error::Error for Error {}

/// The compiler's diagnostics as plain values, placed in `sources`.
pub(crate) fn convert(
    diags: &[btc_pddl::diagnostic::Diagnostic],
    sources: &Sources,
) -> Vec<Diagnostic> {
    diags.iter().map(|d| one(d, sources)).collect()
}

fn one(d: &btc_pddl::diagnostic::Diagnostic, sources: &Sources) -> Diagnostic {
    let j = render::to_json(d, sources);
    let pos = |p: &render::Position| Position {
        line: p.line,
        column: p.column,
    };
    Diagnostic {
        code: j.code.to_owned(),
        severity: match j.severity {
            btc_pddl::diagnostic::Severity::Error => Severity::Error,
            btc_pddl::diagnostic::Severity::Warning => Severity::Warning,
        },
        message: j.message,
        path: j.file,
        start: pos(&j.start),
        end: pos(&j.end),
        hint: j.hint,
        labels: j
            .labels
            .iter()
            .map(|l| Label {
                path: l.file.clone(),
                start: pos(&l.start),
                end: pos(&l.end),
                message: l.message.clone(),
            })
            .collect(),
        fixes: j
            .fixes
            .iter()
            .map(|x| Fix {
                title: x.title.clone(),
                path: x.file.clone(),
                start: pos(&x.start),
                end: pos(&x.end),
                replacement: x.replacement.clone(),
            })
            .collect(),
    }
}
