//! From s-expressions to the PDDL model. Each section is parsed on its own,
//! so one malformed action does not hide problems in the others.

mod decls;
mod logic;

use super::ast::*;
use super::lexer::{lex, Tok};
use super::sexpr::{self, List, Sexp};
use crate::diagnostic::{codes, Code, Diagnostic};
use crate::source::{FileId, Span};
use serde::Serialize;

/// A parsed file: one per file, so the size difference does not matter.
#[allow(clippy::large_enum_variant)]
#[derive(Clone, Debug, PartialEq, Serialize)]
#[serde(tag = "kind", rename_all = "lowercase")]
pub enum Document {
    Domain(Domain),
    Problem(Problem),
}

/// Parses one PDDL file. Returns whatever could be recovered and every
/// syntax diagnostic; `None` only when the text holds no `(define ...)`.
pub fn parse_document(text: &str, file: FileId) -> (Option<Document>, Vec<Diagnostic>) {
    let (tokens, mut diags) = lex(text, file);
    let (forest, tree_diags) = sexpr::build(tokens);
    diags.extend(tree_diags);
    let mut p = Parser { diags };
    let doc = p.document(&forest, Span::new(file, 0, text.len()));
    (doc, p.diags)
}

/// Parses text that must be a domain.
pub fn parse_domain(text: &str, file: FileId) -> (Option<Domain>, Vec<Diagnostic>) {
    parse_kind(text, file, "domain", |doc| match doc {
        Document::Domain(d) => Ok(d),
        Document::Problem(p) => Err(p.name.span),
    })
}

/// Parses text that must be a problem.
pub fn parse_problem(text: &str, file: FileId) -> (Option<Problem>, Vec<Diagnostic>) {
    parse_kind(text, file, "problem", |doc| match doc {
        Document::Problem(p) => Ok(p),
        Document::Domain(d) => Err(d.name.span),
    })
}

/// Parses a document that must be of one kind; `pick` returns it, or the
/// span of the other kind's name.
fn parse_kind<T>(
    text: &str,
    file: FileId,
    want: &str,
    pick: impl FnOnce(Document) -> Result<T, Span>,
) -> (Option<T>, Vec<Diagnostic>) {
    let (doc, mut diags) = parse_document(text, file);
    match doc.map(pick) {
        Some(Ok(t)) => (Some(t), diags),
        Some(Err(span)) => {
            let other = if want == "domain" {
                "problem"
            } else {
                "domain"
            };
            diags.push(Diagnostic::error(
                codes::NOT_A_DEFINE,
                span,
                format!("expected a {want}, but this file defines a {other}"),
            ));
            (None, diags)
        }
        None => (None, diags),
    }
}

pub(super) struct Parser {
    pub(super) diags: Vec<Diagnostic>,
}

/// Walks the items of a list from the front.
pub(super) struct Items<'a> {
    pub(super) items: &'a [Sexp],
    pub(super) pos: usize,
    pub(super) list: Span,
}

impl<'a> Items<'a> {
    pub(super) fn new(list: &'a List, skip: usize) -> Items<'a> {
        Items {
            items: &list.items,
            pos: skip.min(list.items.len()),
            list: list.span,
        }
    }
    pub(super) fn next(&mut self) -> Option<&'a Sexp> {
        let s = self.items.get(self.pos);
        self.pos += 1;
        s
    }
    pub(super) fn peek(&self) -> Option<&'a Sexp> {
        self.items.get(self.pos)
    }
    pub(super) fn rest(&self) -> &'a [Sexp] {
        &self.items[self.pos.min(self.items.len())..]
    }
    /// Where a missing item would have been: just before the closing `)`.
    pub(super) fn end_span(&self) -> Span {
        Span {
            start: self.list.end.saturating_sub(1),
            ..self.list
        }
    }
}

pub(super) fn name_of(s: &Sexp) -> Option<Name> {
    match s {
        Sexp::Atom(t) => match &t.tok {
            Tok::Name(n) => Some(Name {
                name: n.into(),
                span: t.span,
            }),
            _ => None,
        },
        Sexp::List(_) => None,
    }
}

pub(super) fn var_of(s: &Sexp) -> Option<Name> {
    match s {
        Sexp::Atom(t) => match &t.tok {
            Tok::Var(n) => Some(Name {
                name: n.into(),
                span: t.span,
            }),
            _ => None,
        },
        Sexp::List(_) => None,
    }
}

pub(super) const OPERATORS: &[&str] = &["=", "<", ">", "<=", ">=", "+", "*", "/"];

impl Parser {
    pub(super) fn error(
        &mut self,
        code: Code,
        span: Span,
        message: impl Into<String>,
    ) -> &mut Diagnostic {
        self.diags.push(Diagnostic::error(code, span, message));
        self.diags.last_mut().expect("just pushed")
    }

    pub(super) fn expected(&mut self, what: &str, found: Option<&Sexp>, missing_at: Span) {
        match found {
            // The lexer has reported this word already.
            Some(s) if matches!(s.tok(), Some(Tok::Invalid(_))) => {}
            Some(s) => {
                let msg = format!("expected {what}, found {}", s.describe());
                self.error(codes::EXPECTED, s.span(), msg);
            }
            None => {
                self.error(codes::EXPECTED, missing_at, format!("expected {what} here"));
            }
        }
    }

    pub(super) fn unsupported(&mut self, span: Span, feature: &str) {
        self.error(
            codes::UNSUPPORTED,
            span,
            format!("{feature} is not supported by btc"),
        )
        .hint = Some("remove it, or rewrite the file without it".into());
    }

    pub(super) fn document(&mut self, forest: &[Sexp], whole: Span) -> Option<Document> {
        let mut doc = None;
        // Things outside any `(define ...)`: the first is reported, the rest
        // counted (a file of a million stray words is one problem).
        let mut stray = 0usize;
        for s in forest {
            let define = s.as_list().filter(|l| l.head() == Some("define"));
            if define.is_none() {
                stray += 1;
                if stray > 1 {
                    continue;
                }
            }
            match (define, &doc) {
                (Some(l), None) => doc = self.define(l),
                (Some(l), Some(_)) => {
                    self.error(
                        codes::NOT_A_DEFINE,
                        l.head_span(),
                        "a file holds one definition; this is a second `(define ...)`",
                    )
                    .hint = Some("put each domain and problem in a file of its own".into());
                }
                (None, _) => {
                    let msg = format!("expected `(define ...)`, found {}", s.describe());
                    self.error(codes::NOT_A_DEFINE, s.span(), msg);
                }
            }
        }
        if stray > 1 {
            let last = forest.last().map_or(whole, Sexp::span);
            self.error(
                codes::NOT_A_DEFINE,
                last,
                format!("and {} more things outside `(define ...)`", stray - 1),
            );
        }
        if doc.is_none() && forest.is_empty() {
            self.error(
                codes::NOT_A_DEFINE,
                Span {
                    end: whole.start,
                    ..whole
                },
                "the file is empty: expected `(define (domain NAME) ...)` or `(define (problem NAME) ...)`",
            );
        }
        doc
    }

    pub(super) fn define(&mut self, l: &List) -> Option<Document> {
        let mut it = Items::new(l, 1);
        let header = it.next();
        let kind = header.and_then(Sexp::as_list).and_then(|h| {
            let name = h.items.get(1).and_then(name_of);
            match (h.head(), name) {
                (Some(k @ ("domain" | "problem")), Some(n)) => {
                    if h.items.len() > 2 {
                        self.expected("`)`", h.items.get(2), h.span);
                    }
                    Some((k.to_owned(), n))
                }
                _ => None,
            }
        });
        let Some((kind, name)) = kind else {
            self.expected("`(domain NAME)` or `(problem NAME)`", header, it.end_span());
            return None;
        };
        if kind == "domain" {
            Some(Document::Domain(self.domain(name, it, l.span)))
        } else {
            Some(Document::Problem(self.problem(name, it, l.span)))
        }
    }

    /// Each remaining item must be a `(:keyword ...)` section.
    pub(super) fn sections<'a>(&mut self, it: Items<'a>) -> Vec<(&'a str, &'a List)> {
        let mut out = Vec::new();
        for s in it.rest() {
            match s.as_list() {
                Some(l) if l.items.first().and_then(Sexp::keyword).is_some() => {
                    out.push((l.items[0].keyword().expect("checked"), l));
                }
                _ => self.expected("a `(:section ...)`", Some(s), s.span()),
            }
        }
        out
    }

    pub(super) fn domain(&mut self, name: Name, it: Items, span: Span) -> Domain {
        let mut d = Domain {
            name,
            requirements: Vec::new(),
            types: Vec::new(),
            constants: Vec::new(),
            predicates: Vec::new(),
            functions: Vec::new(),
            actions: Vec::new(),
            derived: Vec::new(),
            span,
        };
        for (kw, l) in self.sections(it) {
            let body = Items::new(l, 1);
            match kw {
                "requirements" => d.requirements.extend(self.requirements(body)),
                "types" => d.types.extend(self.typed_list(body.rest(), false)),
                "constants" => d.constants.extend(self.typed_list(body.rest(), false)),
                "predicates" => {
                    for s in body.rest() {
                        if let Some(p) = self.predicate_decl(s) {
                            d.predicates.push(p);
                        }
                    }
                }
                "functions" => self.functions(body.rest(), &mut d.functions),
                "action" => d.actions.extend(self.action(l, false)),
                "durative-action" => d.actions.extend(self.action(l, true)),
                "derived" => d.derived.extend(self.derived(l)),
                "constraints" => self.unsupported(
                    l.head_span(),
                    "`:constraints` (PDDL3 trajectory constraints)",
                ),
                other => self.unknown_section(l, other, DOMAIN_SECTIONS),
            }
        }
        d
    }

    pub(super) fn unknown_section(&mut self, l: &List, kw: &str, allowed: &[&str]) {
        let msg = format!("`:{kw}` is not a section here");
        let hint =
            crate::diagnostic::did_you_mean(kw, allowed.iter().copied()).unwrap_or_else(|| {
                format!(
                    "sections here are {}",
                    allowed
                        .iter()
                        .map(|s| format!("`:{s}`"))
                        .collect::<Vec<_>>()
                        .join(", ")
                )
            });
        self.error(codes::UNKNOWN_SECTION, l.head_span(), msg).hint = Some(hint);
    }

    pub(super) fn problem(&mut self, name: Name, it: Items, span: Span) -> Problem {
        let mut p = Problem {
            name,
            domain: Name {
                name: SmolStr::default(),
                span,
            },
            requirements: Vec::new(),
            objects: Vec::new(),
            init: Vec::new(),
            goal: None,
            metric: None,
            span,
        };
        let mut saw_domain = false;
        for (kw, l) in self.sections(it) {
            let mut body = Items::new(l, 1);
            match kw {
                "domain" => match body.next().and_then(name_of) {
                    Some(n) => {
                        p.domain = n;
                        saw_domain = true;
                    }
                    None => self.expected("the domain's name", l.items.get(1), body.end_span()),
                },
                "requirements" => p.requirements.extend(self.requirements(body)),
                "objects" => p.objects.extend(self.typed_list(body.rest(), false)),
                "init" => {
                    for s in body.rest() {
                        if let Some(f) = self.init_fact(s) {
                            p.init.push(f);
                        }
                    }
                }
                "goal" => match body.next() {
                    Some(g) => p.goal = self.formula(g),
                    None => self.expected("a goal formula", None, body.end_span()),
                },
                "metric" => p.metric = self.metric(l),
                "constraints" => self.unsupported(
                    l.head_span(),
                    "`:constraints` (PDDL3 trajectory constraints)",
                ),
                other => self.unknown_section(l, other, PROBLEM_SECTIONS),
            }
        }
        if !saw_domain {
            self.error(
                codes::EXPECTED,
                p.name.span,
                "the problem does not say which domain it is for",
            )
            .hint = Some("add `(:domain NAME)` after `(problem ...)`".into());
        }
        p
    }
}

#[derive(Clone, Copy)]
pub(super) enum When {
    Start,
    OverAll,
    End,
}

const DOMAIN_SECTIONS: &[&str] = &[
    "requirements",
    "types",
    "constants",
    "predicates",
    "functions",
    "action",
    "durative-action",
    "derived",
];
const PROBLEM_SECTIONS: &[&str] = &[
    "domain",
    "requirements",
    "objects",
    "init",
    "goal",
    "metric",
];

/// Reads a PDDL goal description from an s-expression (used for formulas
/// written inside `.btrules` files).
pub fn formula_of(s: &Sexp) -> (Option<Formula>, Vec<Diagnostic>) {
    let mut p = Parser { diags: Vec::new() };
    let f = p.formula(s);
    (f, p.diags)
}

/// Reads a PDDL effect from an s-expression.
pub fn effect_of(s: &Sexp) -> (Option<Effect>, Vec<Diagnostic>) {
    let mut p = Parser { diags: Vec::new() };
    let e = p.effect(s);
    (e, p.diags)
}

/// Reads a predicate or function declaration `(name ?x - t ...)`.
pub fn predicate_decl_of(s: &Sexp) -> (Option<PredicateDecl>, Vec<Diagnostic>) {
    let mut p = Parser { diags: Vec::new() };
    let d = p.predicate_decl(s);
    (d, p.diags)
}

/// Reads a fact of `:init`: `(on a b)` or `(= (f a) 3)`.
pub fn init_fact_of(s: &Sexp) -> (Option<InitFact>, Vec<Diagnostic>) {
    let mut p = Parser { diags: Vec::new() };
    let f = p.init_fact(s);
    (f, p.diags)
}
