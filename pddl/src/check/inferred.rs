//! The declaration a use of an undeclared predicate implies (P102's fix):
//! each argument typed as the use types it (a variable by its parameter or
//! quantifier, an object or constant by its declaration), and where to
//! put it in the domain's text.

use super::Scope;
use crate::ast::{Atom, Domain, Term};
use crate::check::{DomainIndex, ProblemIndex};
use crate::source::Span;

/// `(NAME ?a - t ...)` for a use of NAME. Variables keep their names;
/// an object or a repeated variable is named after its type. Without
/// `:types`, no types are written.
pub fn declaration(
    atom: &Atom,
    scope: &Scope,
    index: &DomainIndex,
    problem: Option<&ProblemIndex>,
    typed: bool,
) -> String {
    let mut names: Vec<String> = Vec::new();
    let mut out = format!("({}", atom.pred.name);
    for a in &atom.args {
        let types = match a {
            Term::Var { name } => scope
                .iter()
                .rev()
                .find(|(v, _)| *v == name.name)
                .map(|(_, t)| t.clone()),
            Term::Const { name } => problem
                .and_then(|p| p.objects.get(name.as_str()))
                .or_else(|| index.constants.get(name.as_str()))
                .map(|o| o.types.clone()),
        };
        let ty = match &types {
            Some(t) if !t.is_empty() => index.types.display(t),
            _ => "object".to_owned(),
        };
        let wanted = match a {
            Term::Var { name } => name.name.to_string(),
            Term::Const { .. } => ty.trim_start_matches("(either ").to_owned(),
        };
        let wanted: String = wanted
            .chars()
            .map(|c| {
                if c.is_alphanumeric() || c == '_' || c == '-' {
                    c
                } else {
                    '_'
                }
            })
            .collect();
        let mut name = wanted.clone();
        let mut n = 2;
        while names.contains(&name) {
            name = format!("{wanted}{n}");
            n += 1;
        }
        out.push_str(&format!(" ?{name}"));
        if typed {
            out.push_str(&format!(" - {ty}"));
        }
        names.push(name);
    }
    out.push(')');
    out
}

/// Where a declaration goes and the text to insert there: after the last
/// declared predicate, or as a new `(:predicates ...)` before the first
/// action (or derived predicate). `None` for a domain with neither.
pub fn insertion(domain: &Domain, decl: &str) -> Option<(Span, String)> {
    if let Some(last) = domain.predicates.last() {
        let at = Span {
            start: last.span.end,
            ..last.span
        };
        return Some((at, format!("\n    {decl}")));
    }
    let first = domain
        .actions
        .first()
        .map(|a| a.span)
        .or_else(|| domain.derived.first().map(|d| d.span))?;
    let at = Span {
        end: first.start,
        ..first
    };
    Some((at, format!("(:predicates {decl})\n  ")))
}
