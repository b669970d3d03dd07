//! Printing diagnostics: ariadne on a terminal, JSON for tools.

use crate::Format;
use btc_pddl::diagnostic::Diagnostic;
use btc_pddl::render;
use btc_pddl::source::Sources;
use std::io::IsTerminal;

fn use_color() -> bool {
    std::env::var_os("NO_COLOR").is_none() && std::io::stderr().is_terminal()
}

/// Prints diagnostics to stderr in text mode; in JSON mode returns them for
/// the caller's document. At most `MAX_DIAGNOSTICS_PER_FILE` per file, the
/// rest counted (F005).
pub fn diagnostics(
    diags: &[Diagnostic],
    sources: &Sources,
    format: Format,
) -> Vec<serde_json::Value> {
    let diags = &render::capped(diags, btc_pddl::limits::MAX_DIAGNOSTICS_PER_FILE);
    match format {
        Format::Text => {
            eprint!("{}", render::to_terminal(diags, sources, use_color()));
            Vec::new()
        }
        Format::Json => diags
            .iter()
            .map(|d| {
                serde_json::to_value(render::to_json(d, sources)).expect("diagnostics serialize")
            })
            .collect(),
    }
}

pub fn count(diags: &[Diagnostic]) -> (usize, usize) {
    let errors = diags.iter().filter(|d| d.is_error()).count();
    (errors, diags.len() - errors)
}

pub fn plural(n: usize, word: &str) -> String {
    if n == 1 {
        format!("{n} {word}")
    } else {
        format!("{n} {word}s")
    }
}
