//! From s-expressions to the PDDL model. Each section is parsed on its own,
//! so one malformed action does not hide problems in the others.

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

struct Parser {
    diags: Vec<Diagnostic>,
}

/// Walks the items of a list from the front.
struct Items<'a> {
    items: &'a [Sexp],
    pos: usize,
    list: Span,
}

impl<'a> Items<'a> {
    fn new(list: &'a List, skip: usize) -> Items<'a> {
        Items {
            items: &list.items,
            pos: skip.min(list.items.len()),
            list: list.span,
        }
    }
    fn next(&mut self) -> Option<&'a Sexp> {
        let s = self.items.get(self.pos);
        self.pos += 1;
        s
    }
    fn peek(&self) -> Option<&'a Sexp> {
        self.items.get(self.pos)
    }
    fn rest(&self) -> &'a [Sexp] {
        &self.items[self.pos.min(self.items.len())..]
    }
    /// Where a missing item would have been: just before the closing `)`.
    fn end_span(&self) -> Span {
        Span {
            start: self.list.end.saturating_sub(1),
            ..self.list
        }
    }
}

fn name_of(s: &Sexp) -> Option<Name> {
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

fn var_of(s: &Sexp) -> Option<Name> {
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

const OPERATORS: &[&str] = &["=", "<", ">", "<=", ">=", "+", "*", "/"];

impl Parser {
    fn error(&mut self, code: Code, span: Span, message: impl Into<String>) -> &mut Diagnostic {
        self.diags.push(Diagnostic::error(code, span, message));
        self.diags.last_mut().expect("just pushed")
    }

    fn expected(&mut self, what: &str, found: Option<&Sexp>, missing_at: Span) {
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

    fn unsupported(&mut self, span: Span, feature: &str) {
        self.error(
            codes::UNSUPPORTED,
            span,
            format!("{feature} is not supported by btc"),
        )
        .hint = Some("remove it, or rewrite the file without it".into());
    }

    fn document(&mut self, forest: &[Sexp], whole: Span) -> Option<Document> {
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

    fn define(&mut self, l: &List) -> Option<Document> {
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
    fn sections<'a>(&mut self, it: Items<'a>) -> Vec<(&'a str, &'a List)> {
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

    fn domain(&mut self, name: Name, it: Items, span: Span) -> Domain {
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

    fn unknown_section(&mut self, l: &List, kw: &str, allowed: &[&str]) {
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

    fn problem(&mut self, name: Name, it: Items, span: Span) -> Problem {
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

    fn requirements(&mut self, it: Items) -> Vec<Name> {
        let mut out = Vec::new();
        for s in it.rest() {
            match s.keyword() {
                Some(k) => out.push(Name {
                    name: k.into(),
                    span: s.span(),
                }),
                None => self.expected("a requirement such as `:strips`", Some(s), s.span()),
            }
        }
        out
    }

    /// `a b - t c - (either u v) d` (names) or `?x ?y - t` (variables).
    /// The variable list of a quantifier (`forall`, `exists`).
    fn quantified_vars(&mut self, list: &Sexp) -> Option<Vec<Typed>> {
        match list.as_list() {
            Some(vl) => Some(self.typed_list(&vl.items, true)),
            None => {
                self.expected(
                    "a variable list such as `(?x - t)`",
                    Some(list),
                    list.span(),
                );
                None
            }
        }
    }

    fn typed_list(&mut self, items: &[Sexp], vars: bool) -> Vec<Typed> {
        let mut out: Vec<Typed> = Vec::new();
        let mut pending = 0usize; // trailing entries of `out` still waiting for a type
        let mut i = 0;
        while i < items.len() {
            let s = &items[i];
            i += 1;
            if matches!(s.tok(), Some(Tok::Dash)) {
                let ty = match items.get(i) {
                    Some(t) => {
                        i += 1;
                        self.type_spec(t)
                    }
                    None => {
                        self.expected("a type after `-`", None, s.span());
                        None
                    }
                };
                if pending == 0 {
                    self.error(
                        codes::EXPECTED,
                        s.span(),
                        "`-` with nothing before it to give a type to",
                    );
                }
                if let Some(ty) = ty {
                    let n = out.len();
                    for t in &mut out[n - pending..] {
                        t.ty = ty.clone();
                    }
                }
                pending = 0;
                continue;
            }
            let name = if vars { var_of(s) } else { name_of(s) };
            match name {
                Some(name) => {
                    out.push(Typed {
                        name,
                        ty: TypeSpec::Object,
                    });
                    pending += 1;
                }
                None => {
                    let what = if vars {
                        "a variable such as `?x`"
                    } else {
                        "a name"
                    };
                    self.expected(what, Some(s), s.span());
                }
            }
        }
        out
    }

    fn type_spec(&mut self, s: &Sexp) -> Option<TypeSpec> {
        if let Some(name) = name_of(s) {
            return Some(TypeSpec::Named { name });
        }
        if let Some(l) = s.as_list().filter(|l| l.head() == Some("either")) {
            let names: Vec<Name> = l.items[1..]
                .iter()
                .filter_map(|t| {
                    let n = name_of(t);
                    if n.is_none() {
                        self.expected("a type name", Some(t), t.span());
                    }
                    n
                })
                .collect();
            if names.is_empty() {
                self.expected("at least one type in `(either ...)`", None, l.span);
                return None;
            }
            return Some(TypeSpec::Either {
                names,
                span: l.span,
            });
        }
        self.expected("a type name or `(either ...)`", Some(s), s.span());
        None
    }

    fn predicate_decl(&mut self, s: &Sexp) -> Option<PredicateDecl> {
        let Some(l) = s.as_list() else {
            self.expected("a predicate such as `(on ?x ?y)`", Some(s), s.span());
            return None;
        };
        let Some(name) = l.items.first().and_then(name_of) else {
            self.expected("a predicate name", l.items.first(), l.span);
            return None;
        };
        let params = self.typed_list(&l.items[1..], true);
        Some(PredicateDecl {
            name,
            params,
            span: l.span,
        })
    }

    /// `(f ?x - t) (g) - number (h) - t`
    fn functions(&mut self, items: &[Sexp], out: &mut Vec<FunctionDecl>) {
        let mut pending = 0usize;
        let mut i = 0;
        while i < items.len() {
            let s = &items[i];
            i += 1;
            if matches!(s.tok(), Some(Tok::Dash)) {
                match items.get(i).and_then(name_of) {
                    Some(ty) => {
                        if ty.name != "number" {
                            self.unsupported(
                                ty.span,
                                &format!("the object-valued function type `{}`", ty.name),
                            );
                        }
                        let n = out.len();
                        for f in &mut out[n - pending..] {
                            f.ty = ty.clone();
                        }
                        i += 1;
                    }
                    None => self.expected("`number` after `-`", items.get(i), s.span()),
                }
                pending = 0;
                continue;
            }
            if let Some(p) = self.predicate_decl(s) {
                out.push(FunctionDecl {
                    ty: Name {
                        name: "number".into(),
                        span: p.name.span,
                    },
                    name: p.name,
                    params: p.params,
                    span: p.span,
                });
                pending += 1;
            }
        }
    }

    fn action(&mut self, l: &List, durative: bool) -> Option<Action> {
        let mut it = Items::new(l, 1);
        let Some(name) = it.peek().and_then(name_of) else {
            self.expected("the action's name", it.peek(), it.end_span());
            return None;
        };
        it.next();
        let mut a = Action {
            name,
            params: Vec::new(),
            durative,
            duration: None,
            pre_start: Vec::new(),
            pre_over_all: Vec::new(),
            pre_end: Vec::new(),
            eff_start: Vec::new(),
            eff_end: Vec::new(),
            span: l.span,
        };
        let allowed: &[&str] = if durative {
            &["parameters", "duration", "condition", "effect"]
        } else {
            &["parameters", "precondition", "effect"]
        };
        let mut seen: Vec<String> = Vec::new();
        while let Some(key) = it.next() {
            let Some(kw) = key.keyword() else {
                self.expected("a keyword such as `:parameters`", Some(key), key.span());
                continue;
            };
            if !allowed.contains(&kw) {
                let hint = crate::diagnostic::did_you_mean(kw, allowed.iter().copied());
                let kind = if durative {
                    "a durative action"
                } else {
                    "an action"
                };
                let d = self.error(
                    codes::UNKNOWN_SECTION,
                    key.span(),
                    format!("`:{kw}` does not belong in {kind}"),
                );
                d.hint = hint;
                it.next();
                continue;
            }
            if seen.iter().any(|s| s == kw) {
                self.error(
                    codes::DUPLICATE,
                    key.span(),
                    format!("`:{kw}` is given twice"),
                );
            }
            seen.push(kw.to_owned());
            let Some(value) = it.next() else {
                self.expected(&format!("a value for `:{kw}`"), None, key.span());
                break;
            };
            match kw {
                "parameters" => match value.as_list() {
                    Some(pl) => a.params = self.typed_list(&pl.items, true),
                    None => self.expected(
                        "a parameter list such as `(?x - t)`",
                        Some(value),
                        value.span(),
                    ),
                },
                "precondition" => a.pre_start.extend(self.formula(value)),
                "effect" if !durative => a.eff_end.extend(self.effect(value)),
                "duration" => a.duration = self.duration(value),
                "condition" => self.timed_conditions(value, &mut a),
                "effect" => self.timed_effects(value, &mut a),
                _ => unreachable!("filtered by `allowed`"),
            }
        }
        Some(a)
    }

    fn duration(&mut self, s: &Sexp) -> Option<Duration> {
        let l = s.as_list()?;
        if l.items.is_empty() {
            return None;
        }
        match l.head() {
            Some("=")
                if l.items.len() == 3
                    && matches!(l.items[1].tok(), Some(Tok::Var(v)) if v == "duration") =>
            {
                let value = self.num_expr(&l.items[2])?;
                Some(Duration {
                    value,
                    span: l.span,
                })
            }
            Some("<=" | ">=" | "<" | ">" | "and") => {
                self.unsupported(l.span, "a duration inequality (`:duration-inequalities`)");
                None
            }
            _ => {
                self.expected("`(= ?duration VALUE)`", Some(s), s.span());
                None
            }
        }
    }

    /// Splits `(and (at start F) (over all G) ...)` into the action's lists.
    fn timed_conditions(&mut self, s: &Sexp, a: &mut Action) {
        for (when, body) in self.timed_parts(s) {
            if let Some(f) = self.formula(body) {
                match when {
                    When::Start => a.pre_start.push(f),
                    When::OverAll => a.pre_over_all.push(f),
                    When::End => a.pre_end.push(f),
                }
            }
        }
    }

    fn timed_effects(&mut self, s: &Sexp, a: &mut Action) {
        for (when, body) in self.timed_parts(s) {
            if let Some(e) = self.effect(body) {
                match when {
                    When::Start => a.eff_start.push(e),
                    When::End => a.eff_end.push(e),
                    When::OverAll => {
                        self.unsupported(body.span(), "an `over all` effect (continuous change)");
                    }
                }
            }
        }
    }

    fn timed_parts<'a>(&mut self, s: &'a Sexp) -> Vec<(When, &'a Sexp)> {
        let Some(l) = s.as_list() else {
            self.expected(
                "`(at start ...)`, `(at end ...)` or `(over all ...)`",
                Some(s),
                s.span(),
            );
            return Vec::new();
        };
        if l.items.is_empty() {
            return Vec::new();
        }
        if l.head() == Some("and") {
            return l.items[1..]
                .iter()
                .flat_map(|p| self.timed_parts(p))
                .collect();
        }
        let word = |i: usize| l.items.get(i).and_then(name_of).map(|n| n.name);
        let when = match (word(0).as_deref(), word(1).as_deref()) {
            (Some("at"), Some("start")) => Some(When::Start),
            (Some("at"), Some("end")) => Some(When::End),
            (Some("over"), Some("all")) => Some(When::OverAll),
            _ => None,
        };
        match (when, l.items.get(2)) {
            (Some(w), Some(body)) if l.items.len() == 3 => vec![(w, body)],
            _ => {
                self.expected(
                    "`(at start ...)`, `(at end ...)` or `(over all ...)`",
                    Some(s),
                    s.span(),
                );
                Vec::new()
            }
        }
    }

    fn derived(&mut self, l: &List) -> Option<Derived> {
        let Some(head) = l.items.get(1) else {
            self.expected("the derived predicate `(name ?x ...)`", None, l.span);
            return None;
        };
        let head = self.predicate_decl(head)?;
        let Some(body) = l.items.get(2) else {
            self.expected("the derived predicate's formula", None, l.span);
            return None;
        };
        if let Some(extra) = l.items.get(3) {
            self.expected("`)`", Some(extra), extra.span());
        }
        let body = self.formula(body)?;
        Some(Derived {
            head,
            body,
            span: l.span,
        })
    }

    fn term(&mut self, s: &Sexp) -> Option<Term> {
        if let Some(name) = var_of(s) {
            return Some(Term::Var { name });
        }
        if let Some(name) = name_of(s) {
            return Some(Term::Const { name });
        }
        self.expected("a variable or an object name", Some(s), s.span());
        None
    }

    fn atom(&mut self, l: &List) -> Option<Atom> {
        let pred = name_of(&l.items[0])?;
        let args = l.items[1..].iter().filter_map(|s| self.term(s)).collect();
        Some(Atom {
            pred,
            args,
            span: l.span,
        })
    }

    fn formula(&mut self, s: &Sexp) -> Option<Formula> {
        let Some(l) = s.as_list() else {
            self.expected("a formula such as `(on ?x ?y)`", Some(s), s.span());
            return None;
        };
        let span = l.span;
        let Some(head) = l.head() else {
            if l.items.is_empty() {
                return Some(Formula::truth(span)); // `()`: nothing required
            }
            self.expected(
                "a predicate or a connective such as `and`",
                l.items.first(),
                span,
            );
            return None;
        };
        let args = &l.items[1..];
        let arity = |p: &mut Parser, n: usize| {
            if args.len() != n {
                let msg = format!(
                    "`{head}` takes {n} argument{}, found {}",
                    if n == 1 { "" } else { "s" },
                    args.len()
                );
                p.error(codes::EXPECTED, span, msg);
                false
            } else {
                true
            }
        };
        if l.items[0].keyword().is_some() {
            self.expected("a formula", Some(&l.items[0]), l.items[0].span());
            return None;
        }
        Some(match head {
            "and" => Formula::And {
                parts: args.iter().filter_map(|a| self.formula(a)).collect(),
                span,
            },
            "or" => Formula::Or {
                parts: args.iter().filter_map(|a| self.formula(a)).collect(),
                span,
            },
            "not" => {
                if !arity(self, 1) {
                    return None;
                }
                Formula::Not {
                    formula: Box::new(self.formula(&args[0])?),
                    span,
                }
            }
            "imply" => {
                if !arity(self, 2) {
                    return None;
                }
                let left = self.formula(&args[0]);
                let right = self.formula(&args[1]);
                Formula::Imply {
                    left: Box::new(left?),
                    right: Box::new(right?),
                    span,
                }
            }
            "exists" | "forall" => {
                if !arity(self, 2) {
                    return None;
                }
                let vars = self.quantified_vars(&args[0])?;
                let body = Box::new(self.formula(&args[1])?);
                if head == "exists" {
                    Formula::Exists { vars, body, span }
                } else {
                    Formula::Forall { vars, body, span }
                }
            }
            "=" if args.iter().all(|a| a.as_list().is_none()) => {
                if !arity(self, 2) {
                    return None;
                }
                let left = self.term(&args[0]);
                let right = self.term(&args[1]);
                Formula::Equal {
                    left: left?,
                    right: right?,
                    span,
                }
            }
            "=" | "<" | "<=" | ">" | ">=" => {
                if !arity(self, 2) {
                    return None;
                }
                let op = match head {
                    "=" => Comparison::Eq,
                    "<" => Comparison::Lt,
                    "<=" => Comparison::Le,
                    ">" => Comparison::Gt,
                    _ => Comparison::Ge,
                };
                let left = self.num_expr(&args[0]);
                let right = self.num_expr(&args[1]);
                Formula::Compare {
                    op,
                    left: left?,
                    right: right?,
                    span,
                }
            }
            "preference" => {
                self.unsupported(span, "`preference` (PDDL3 preferences)");
                return None;
            }
            "at" | "over"
                if args.len() == 2
                    && name_of(&args[0])
                        .is_some_and(|n| matches!(n.name.as_str(), "start" | "end" | "all")) =>
            {
                self.error(codes::EXPECTED, span, "a timed condition is allowed only directly under a durative action's `:condition`");
                return None;
            }
            h if OPERATORS.contains(&h) => {
                self.expected("a formula", Some(s), span);
                return None;
            }
            _ => Formula::Atom {
                atom: self.atom(l)?,
            },
        })
    }

    fn effect(&mut self, s: &Sexp) -> Option<Effect> {
        let Some(l) = s.as_list() else {
            self.expected("an effect such as `(on ?x ?y)`", Some(s), s.span());
            return None;
        };
        let span = l.span;
        let Some(head) = l.head() else {
            if l.items.is_empty() {
                return Some(Effect::empty(span));
            }
            self.expected(
                "a predicate or `and`, `not`, `forall`, `when`",
                l.items.first(),
                span,
            );
            return None;
        };
        if l.items[0].keyword().is_some() {
            self.expected("an effect", Some(&l.items[0]), l.items[0].span());
            return None;
        }
        let args = &l.items[1..];
        let count = |p: &mut Parser, n: usize| {
            if args.len() != n {
                p.error(
                    codes::EXPECTED,
                    span,
                    format!("`{head}` takes {n} arguments, found {}", args.len()),
                );
                false
            } else {
                true
            }
        };
        Some(match head {
            "and" => Effect::And {
                parts: args.iter().filter_map(|a| self.effect(a)).collect(),
                span,
            },
            "not" => {
                if !count(self, 1) {
                    return None;
                }
                match args[0]
                    .as_list()
                    .filter(|al| al.head().is_some() && al.items[0].keyword().is_none())
                {
                    Some(al) => Effect::Delete {
                        atom: self.atom(al)?,
                        span,
                    },
                    None => {
                        self.expected(
                            "an atom such as `(on ?x ?y)` inside `not`",
                            Some(&args[0]),
                            args[0].span(),
                        );
                        return None;
                    }
                }
            }
            "forall" => {
                if !count(self, 2) {
                    return None;
                }
                let vars = self.quantified_vars(&args[0])?;
                Effect::Forall {
                    vars,
                    body: Box::new(self.effect(&args[1])?),
                    span,
                }
            }
            "when" => {
                if !count(self, 2) {
                    return None;
                }
                let condition = self.formula(&args[0]);
                let body = self.effect(&args[1]);
                Effect::When {
                    condition: condition?,
                    body: Box::new(body?),
                    span,
                }
            }
            "assign" | "increase" | "decrease" | "scale-up" | "scale-down" => {
                if !count(self, 2) {
                    return None;
                }
                let op = match head {
                    "assign" => AssignOp::Assign,
                    "increase" => AssignOp::Increase,
                    "decrease" => AssignOp::Decrease,
                    "scale-up" => AssignOp::ScaleUp,
                    _ => AssignOp::ScaleDown,
                };
                let fluent = match args[0].as_list().filter(|fl| fl.head().is_some()) {
                    Some(fl) => self.atom(fl)?,
                    None => {
                        self.expected(
                            "a function such as `(total-cost)`",
                            Some(&args[0]),
                            args[0].span(),
                        );
                        return None;
                    }
                };
                Effect::Numeric {
                    op,
                    fluent,
                    value: self.num_expr(&args[1])?,
                    span,
                }
            }
            "at" if args.len() == 2
                && matches!(args[0].tok(), Some(Tok::Name(n)) if n == "start" || n == "end") =>
            {
                self.error(
                    codes::EXPECTED,
                    span,
                    "a timed effect is allowed only directly under a durative action's `:effect`",
                );
                return None;
            }
            h if OPERATORS.contains(&h) || h == "or" || h == "exists" || h == "imply" => {
                self.expected(
                    "an effect (`and`, `not`, `forall`, `when`, a numeric update or an atom)",
                    Some(s),
                    span,
                );
                return None;
            }
            _ => Effect::Add {
                atom: self.atom(l)?,
            },
        })
    }

    fn num_expr(&mut self, s: &Sexp) -> Option<NumExpr> {
        match s {
            Sexp::Atom(t) => match &t.tok {
                Tok::Number(value) => Some(NumExpr::Number {
                    value: *value,
                    span: t.span,
                }),
                Tok::Var(v) if v == "duration" => Some(NumExpr::Duration { span: t.span }),
                _ => {
                    self.expected(
                        "a number or a function such as `(total-cost)`",
                        Some(s),
                        t.span,
                    );
                    None
                }
            },
            Sexp::List(l) => {
                let span = l.span;
                let op = match l.items.first().and_then(Sexp::tok) {
                    Some(Tok::Dash) => Some(NumOp::Sub),
                    Some(Tok::Name(n)) => match n.as_str() {
                        "+" => Some(NumOp::Add),
                        "*" => Some(NumOp::Mul),
                        "/" => Some(NumOp::Div),
                        _ => None,
                    },
                    _ => None,
                };
                match op {
                    Some(NumOp::Sub) if l.items.len() == 2 => {
                        let expr = Box::new(self.num_expr(&l.items[1])?);
                        Some(NumExpr::Neg { expr, span })
                    }
                    Some(op) if l.items.len() >= 3 => {
                        // (+ a b c) folds left: ((a + b) + c)
                        let mut acc = self.num_expr(&l.items[1])?;
                        for r in &l.items[2..] {
                            let right = self.num_expr(r)?;
                            acc = NumExpr::Binary {
                                op,
                                left: Box::new(acc),
                                right: Box::new(right),
                                span,
                            };
                        }
                        Some(acc)
                    }
                    Some(_) => {
                        self.expected("two operands", None, span);
                        None
                    }
                    None => match l.head() {
                        Some(_) if l.items[0].keyword().is_none() => {
                            Some(NumExpr::Fluent { app: self.atom(l)? })
                        }
                        _ => {
                            self.expected("a numeric expression", Some(s), span);
                            None
                        }
                    },
                }
            }
        }
    }

    fn init_fact(&mut self, s: &Sexp) -> Option<InitFact> {
        let Some(l) = s
            .as_list()
            .filter(|l| l.head().is_some() && l.items[0].keyword().is_none())
        else {
            self.expected("a fact such as `(on a b)`", Some(s), s.span());
            return None;
        };
        match l.head() {
            Some("=") if l.items.len() == 3 && l.items[1].as_list().is_some() => {
                let fl = l.items[1].as_list().expect("checked");
                let fluent = match fl.head() {
                    Some(_) => self.atom(fl)?,
                    None => {
                        self.expected(
                            "a function such as `(total-cost)`",
                            Some(&l.items[1]),
                            fl.span,
                        );
                        return None;
                    }
                };
                match l.items[2].tok() {
                    Some(Tok::Number(value)) => Some(InitFact::Value {
                        fluent,
                        value: *value,
                        span: l.span,
                    }),
                    _ => {
                        self.expected("a number", Some(&l.items[2]), l.items[2].span());
                        None
                    }
                }
            }
            Some("at")
                if l.items.len() == 3 && matches!(l.items[1].tok(), Some(Tok::Number(_))) =>
            {
                self.unsupported(
                    l.span,
                    "a timed initial literal (`:timed-initial-literals`)",
                );
                None
            }
            Some("not") => {
                self.error(
                    codes::EXPECTED,
                    l.span,
                    "`:init` lists only what is true; leave out what is false",
                )
                .hint = Some("PDDL assumes that facts not listed in `:init` are false".into());
                None
            }
            Some(h) if OPERATORS.contains(&h) || h == "and" => {
                self.expected("a fact such as `(on a b)`", Some(s), l.span);
                None
            }
            _ => Some(InitFact::Atom {
                atom: self.atom(l)?,
            }),
        }
    }

    fn metric(&mut self, l: &List) -> Option<Metric> {
        let optimize = match l
            .items
            .get(1)
            .and_then(name_of)
            .as_ref()
            .map(|n| n.name.as_str())
        {
            Some("minimize") => Optimize::Minimize,
            Some("maximize") => Optimize::Maximize,
            _ => {
                self.expected("`minimize` or `maximize`", l.items.get(1), l.span);
                return None;
            }
        };
        let Some(e) = l.items.get(2) else {
            self.expected("the expression to optimize", None, l.span);
            return None;
        };
        let expr = self.num_expr(e)?;
        Some(Metric {
            optimize,
            expr,
            span: l.span,
        })
    }
}

#[derive(Clone, Copy)]
enum When {
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
