//! Declarations: requirements, typed lists and types, predicates and
//! functions, actions (durative ones with their durations and timed
//! parts) and derived predicates.

use super::*;

impl Parser {
    pub(super) fn requirements(&mut self, it: Items) -> Vec<Name> {
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
    pub(super) fn quantified_vars(&mut self, list: &Sexp) -> Option<Vec<Typed>> {
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

    pub(super) fn typed_list(&mut self, items: &[Sexp], vars: bool) -> Vec<Typed> {
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

    pub(super) fn type_spec(&mut self, s: &Sexp) -> Option<TypeSpec> {
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

    pub(super) fn predicate_decl(&mut self, s: &Sexp) -> Option<PredicateDecl> {
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
    pub(super) fn functions(&mut self, items: &[Sexp], out: &mut Vec<FunctionDecl>) {
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

    pub(super) fn action(&mut self, l: &List, durative: bool) -> Option<Action> {
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

    pub(super) fn duration(&mut self, s: &Sexp) -> Option<Duration> {
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
    pub(super) fn timed_conditions(&mut self, s: &Sexp, a: &mut Action) {
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

    pub(super) fn timed_effects(&mut self, s: &Sexp, a: &mut Action) {
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

    pub(super) fn timed_parts<'a>(&mut self, s: &'a Sexp) -> Vec<(When, &'a Sexp)> {
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

    pub(super) fn derived(&mut self, l: &List) -> Option<Derived> {
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
}
