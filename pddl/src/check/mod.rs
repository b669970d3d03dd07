//! Semantic checks of domains and problems, and the symbol tables that every
//! later stage (plan typing, validation, rule checking) looks names up in.

mod derived;
mod inferred;
mod requirements;

use derived::stratify;
pub use derived::{collect_derived_uses, strata_of};
use requirements::{requirements, undeclared_requirements, Feature};

use super::ast::*;
use super::types::{TypeId, TypeTable};
use crate::diagnostic::{codes, did_you_mean, Diagnostic};
use crate::source::Span;
use rustc_hash::{FxHashMap, FxHashSet};

/// A declared predicate or function: index into the domain's list and
/// resolved parameter types.
#[derive(Clone, Debug, PartialEq)]
pub struct Signature {
    pub index: usize,
    pub params: Vec<Vec<TypeId>>,
    pub span: Span,
}

/// An object or constant: its id in [`ProblemIndex::objects`] order (or
/// in [`DomainIndex::constants`]), its types and where it is declared.
#[derive(Clone, Debug, PartialEq)]
pub struct ObjectInfo {
    pub id: u32,
    pub types: Vec<TypeId>,
    pub span: Span,
}

/// What a checked domain knows by name.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct DomainIndex {
    pub types: TypeTable,
    pub predicates: FxHashMap<String, Signature>,
    pub functions: FxHashMap<String, Signature>,
    pub constants: FxHashMap<String, ObjectInfo>,
    /// Constant names in declaration order (ids index this).
    pub constant_names: Vec<String>,
    pub actions: FxHashMap<String, Signature>,
    /// Derived predicates, grouped in strata: each stratum only negates
    /// predicates of earlier strata. Entries index `domain.derived`.
    pub derived_strata: Vec<Vec<usize>>,
    pub derived: FxHashSet<String>,
    /// Requirement flags declared, with implied ones expanded.
    pub requirements: FxHashSet<String>,
}

/// What a checked problem knows: every object and constant, with ids.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ProblemIndex {
    pub objects: FxHashMap<String, ObjectInfo>,
    /// Names by id: domain constants first, then the problem's objects.
    pub object_names: Vec<String>,
    pub object_types: Vec<Vec<TypeId>>,
}

impl ProblemIndex {
    /// Every object (constants included) whose type fits `want`.
    pub fn objects_of(&self, types: &TypeTable, want: &[TypeId]) -> Vec<u32> {
        (0..self.object_names.len() as u32)
            .filter(|&i| types.fits(&self.object_types[i as usize], want))
            .collect()
    }
}

struct Checker<'a> {
    domain: &'a Domain,
    index: &'a DomainIndex,
    /// Objects of the problem being checked; `None` while checking the domain.
    problem: Option<&'a ProblemIndex>,
    diags: Vec<Diagnostic>,
    used: FxHashMap<Feature, Span>,
    durative: bool,
}

impl<'a> Checker<'a> {
    /// A checker for a formula or effect written outside the domain (in a
    /// rules file): the requirements it uses go unreported, nothing is
    /// durative.
    fn outside(
        domain: &'a Domain,
        index: &'a DomainIndex,
        problem: Option<&'a ProblemIndex>,
    ) -> Checker<'a> {
        Checker {
            domain,
            index,
            problem,
            diags: Vec::new(),
            used: FxHashMap::default(),
            durative: false,
        }
    }
}

pub type Scope = Vec<(String, Vec<TypeId>)>;

/// Checks a domain and builds its index.
pub fn check_domain(domain: &Domain) -> (DomainIndex, Vec<Diagnostic>) {
    let mut diags = Vec::new();
    let mut index = DomainIndex {
        requirements: requirements(&domain.requirements, &mut diags),
        types: TypeTable::build(domain, &mut diags),
        ..DomainIndex::default()
    };
    let mut used: FxHashMap<Feature, Span> = FxHashMap::default();
    if let Some(t) = domain.types.first() {
        used.insert(Feature::Typing, t.name.span);
    }
    // Constants
    for c in &domain.constants {
        let types = index.types.resolve(&c.ty, &mut diags);
        note_typed(c, &mut used);
        if let Some(prev) = index.constants.get(c.name.as_str()) {
            diags.push(duplicate("constant", &c.name, prev.span));
            continue;
        }
        let id = index.constant_names.len() as u32;
        index.constant_names.push(c.name.name.to_string());
        index.constants.insert(
            c.name.name.to_string(),
            ObjectInfo {
                id,
                types,
                span: c.name.span,
            },
        );
    }
    // Predicates and functions
    for (i, p) in domain.predicates.iter().enumerate() {
        let params = resolve_params(&p.params, &index.types, &mut diags, &mut used);
        declare(
            &mut index.predicates,
            "predicate",
            &p.name,
            i,
            params,
            &mut diags,
        );
    }
    for (i, f) in domain.functions.iter().enumerate() {
        used.entry(Feature::Numeric).or_insert(f.name.span);
        let params = resolve_params(&f.params, &index.types, &mut diags, &mut used);
        declare(
            &mut index.functions,
            "function",
            &f.name,
            i,
            params,
            &mut diags,
        );
    }
    for (i, a) in domain.actions.iter().enumerate() {
        let params = resolve_params(&a.params, &index.types, &mut diags, &mut used);
        if a.durative {
            used.entry(Feature::Durative).or_insert(a.name.span);
        }
        declare(&mut index.actions, "action", &a.name, i, params, &mut diags);
    }
    for d in &domain.derived {
        used.entry(Feature::Derived).or_insert(d.head.name.span);
        match index.predicates.get(d.head.name.as_str()) {
            None => diags.push(
                Diagnostic::error(
                    codes::UNKNOWN_PREDICATE,
                    d.head.name.span,
                    format!(
                        "derived predicate `{}` is not declared in `:predicates`",
                        d.head.name.name
                    ),
                )
                .with_hint(format!("add `{}` to `:predicates`", render_decl(&d.head))),
            ),
            Some(sig) if sig.params.len() != d.head.params.len() => diags.push(
                Diagnostic::error(
                    codes::WRONG_ARITY,
                    d.head.span,
                    format!(
                        "`{}` is declared with {} parameters but derived with {}",
                        d.head.name.name,
                        sig.params.len(),
                        d.head.params.len()
                    ),
                )
                .with_label(sig.span, "declared here"),
            ),
            Some(_) => {}
        }
        index.derived.insert(d.head.name.name.to_string());
    }
    index.derived_strata = stratify(domain, &index, &mut diags);

    let mut c = Checker {
        domain,
        index: &index,
        problem: None,
        diags: Vec::new(),
        used,
        durative: false,
    };
    for a in &domain.actions {
        c.durative = a.durative;
        let scope = scope_of(&a.params, &index.types);
        check_duplicate_vars(&a.params, &mut c.diags);
        for f in a.pre_start.iter().chain(&a.pre_over_all).chain(&a.pre_end) {
            c.formula(f, &scope);
        }
        for e in a.eff_start.iter().chain(&a.eff_end) {
            c.effect(e, &scope);
        }
        if let Some(d) = &a.duration {
            c.num_expr(&d.value, &scope);
        }
    }
    c.durative = false;
    for d in &domain.derived {
        let scope = scope_of(&d.head.params, &index.types);
        check_duplicate_vars(&d.head.params, &mut c.diags);
        c.formula(&d.body, &scope);
    }
    let used = std::mem::take(&mut c.used);
    diags.append(&mut c.diags);
    diags.extend(undeclared_requirements(&used, &index.requirements));
    (index, diags)
}

/// Checks a problem against its checked domain and builds the object table.
pub fn check_problem(
    problem: &Problem,
    domain: &Domain,
    index: &DomainIndex,
) -> (ProblemIndex, Vec<Diagnostic>) {
    let mut diags = Vec::new();
    if !problem.domain.name.is_empty() && problem.domain.name != domain.name.name {
        diags.push(
            Diagnostic::warning(
                codes::DOMAIN_MISMATCH,
                problem.domain.span,
                format!(
                    "this problem is for domain `{}`, but it is checked against domain `{}`",
                    problem.domain.name, domain.name.name
                ),
            )
            .with_label(domain.name.span, "the domain given")
            .with_hint("pass the problem's own domain file, or fix the name in `(:domain ...)`"),
        );
    }
    let mut reqs = index.requirements.clone();
    reqs.extend(requirements(&problem.requirements, &mut diags));
    let mut pi = ProblemIndex::default();
    for name in &index.constant_names {
        let info = &index.constants[name];
        pi.object_names.push(name.clone());
        pi.object_types.push(info.types.clone());
        pi.objects.insert(name.clone(), info.clone());
    }
    for o in &problem.objects {
        let types = index.types.resolve(&o.ty, &mut diags);
        if let Some(prev) = pi.objects.get(o.name.as_str()) {
            let d = if index.constants.contains_key(o.name.as_str()) {
                Diagnostic::warning(
                    codes::DUPLICATE,
                    o.name.span,
                    format!("`{}` is already a constant of the domain", o.name.name),
                )
                .with_label(prev.span, "declared here")
            } else {
                duplicate("object", &o.name, prev.span)
            };
            diags.push(d);
            continue;
        }
        let id = pi.object_names.len() as u32;
        pi.object_names.push(o.name.name.to_string());
        pi.object_types.push(types.clone());
        pi.objects.insert(
            o.name.name.to_string(),
            ObjectInfo {
                id,
                types,
                span: o.name.span,
            },
        );
    }
    let mut c = Checker {
        domain,
        index,
        problem: Some(&pi),
        diags: Vec::new(),
        used: FxHashMap::default(),
        durative: false,
    };
    let scope = Scope::new();
    for fact in &problem.init {
        match fact {
            InitFact::Atom { atom } => {
                if c.index.derived.contains(atom.pred.as_str()) {
                    c.diags.push(
                        Diagnostic::error(
                            codes::DERIVED_EFFECT,
                            atom.pred.span,
                            format!(
                                "`{}` is a derived predicate: it cannot be listed in `:init`",
                                atom.pred.name
                            ),
                        )
                        .with_hint("derived predicates are computed from the other facts"),
                    );
                }
                c.ground(atom);
                c.atom(atom, &scope);
            }
            InitFact::Value { fluent, .. } => {
                c.ground(fluent);
                c.fluent(fluent, &scope);
            }
        }
    }
    if let Some(g) = &problem.goal {
        c.formula(g, &scope);
    }
    if let Some(m) = &problem.metric {
        c.num_expr(&m.expr, &scope);
    }
    diags.append(&mut c.diags);
    diags.extend(undeclared_requirements(&c.used, &reqs));
    (pi, diags)
}

/// Checks a condition written outside the domain (in a rules file) with the
/// given variables in scope. `problem` adds its objects to the constants.
pub fn check_formula_in(
    domain: &Domain,
    index: &DomainIndex,
    problem: Option<&ProblemIndex>,
    f: &Formula,
    scope: &[(String, Vec<TypeId>)],
) -> Vec<Diagnostic> {
    let mut c = Checker::outside(domain, index, problem);
    c.formula(f, &scope.to_vec());
    c.diags
}

/// Checks an effect written outside the domain, as [`check_formula_in`].
pub fn check_effect_in(
    domain: &Domain,
    index: &DomainIndex,
    problem: Option<&ProblemIndex>,
    e: &Effect,
    scope: &[(String, Vec<TypeId>)],
) -> Vec<Diagnostic> {
    let mut c = Checker::outside(domain, index, problem);
    c.effect(e, &scope.to_vec());
    c.diags
}

fn note_typed(t: &Typed, used: &mut FxHashMap<Feature, Span>) {
    if !matches!(t.ty, TypeSpec::Object) {
        used.entry(Feature::Typing).or_insert(t.name.span);
    }
}

fn resolve_params(
    params: &[Typed],
    types: &TypeTable,
    diags: &mut Vec<Diagnostic>,
    used: &mut FxHashMap<Feature, Span>,
) -> Vec<Vec<TypeId>> {
    params
        .iter()
        .map(|p| {
            note_typed(p, used);
            types.resolve(&p.ty, diags)
        })
        .collect()
}

/// Variables' types without reporting again (resolve_params reported).
fn scope_of(params: &[Typed], types: &TypeTable) -> Scope {
    params
        .iter()
        .map(|p| {
            (
                p.name.name.to_string(),
                types.resolve(&p.ty, &mut Vec::new()),
            )
        })
        .collect()
}

fn check_duplicate_vars(params: &[Typed], diags: &mut Vec<Diagnostic>) {
    let mut seen: FxHashMap<&str, Span> = FxHashMap::default();
    for p in params {
        if let Some(prev) = seen.insert(p.name.as_str(), p.name.span) {
            diags.push(duplicate(
                "parameter",
                &Name {
                    name: smol_str::format_smolstr!("?{}", p.name.name),
                    span: p.name.span,
                },
                prev,
            ));
        }
    }
}

/// Enters a predicate, function or action in its table; a second
/// declaration of the name is an error pointing at the first.
fn declare(
    table: &mut FxHashMap<String, Signature>,
    what: &str,
    name: &Name,
    index: usize,
    params: Vec<Vec<TypeId>>,
    diags: &mut Vec<Diagnostic>,
) {
    if let Some(prev) = table.get(name.as_str()) {
        diags.push(duplicate(what, name, prev.span));
        return;
    }
    table.insert(
        name.name.to_string(),
        Signature {
            index,
            params,
            span: name.span,
        },
    );
}

fn duplicate(what: &str, name: &Name, first: Span) -> Diagnostic {
    Diagnostic::error(
        codes::DUPLICATE,
        name.span,
        format!("{what} `{}` is defined twice", name.name),
    )
    .with_label(first, "first defined here")
    .with_hint("remove or rename one of them")
}

fn render_decl(p: &PredicateDecl) -> String {
    let mut s = format!("({}", p.name.name);
    for t in &p.params {
        s.push_str(&format!(" ?{} - {}", t.name.name, t.ty));
    }
    s.push(')');
    s
}

impl Checker<'_> {
    fn use_feature(&mut self, f: Feature, span: Span) {
        self.used.entry(f).or_insert(span);
    }

    fn term(&mut self, t: &Term, scope: &Scope) -> Option<Vec<TypeId>> {
        match t {
            Term::Var { name } => match scope.iter().rev().find(|(v, _)| *v == name.name) {
                Some((_, types)) => Some(types.clone()),
                None => {
                    let d = Diagnostic::error(
                        codes::UNBOUND_VARIABLE,
                        name.span,
                        format!("variable `?{}` is not bound here", name.name),
                    );
                    let hint = crate::diagnostic::closest(
                        &name.name,
                        scope.iter().map(|(v, _)| v.as_str()),
                    )
                    .map(|c| format!("did you mean `?{c}`?"))
                    .unwrap_or_else(|| "declare it in `:parameters` or in a quantifier".into());
                    self.diags.push(d.with_hint(hint));
                    None
                }
            },
            Term::Const { name } => {
                if let Some(o) = self.problem.and_then(|p| p.objects.get(name.as_str())) {
                    return Some(o.types.clone());
                }
                if let Some(c) = self.index.constants.get(name.as_str()) {
                    return Some(c.types.clone());
                }
                let (what, hint) = match self.problem {
                    Some(p) => (
                        "an object of the problem or a constant of the domain",
                        did_you_mean(&name.name, p.object_names.iter().map(String::as_str)),
                    ),
                    None => (
                        "a constant of the domain",
                        did_you_mean(
                            &name.name,
                            self.index.constant_names.iter().map(String::as_str),
                        ),
                    ),
                };
                let d = Diagnostic::error(
                    codes::UNKNOWN_OBJECT,
                    name.span,
                    format!("`{}` is not {what}", name.name),
                );
                self.diags.push(match hint {
                    Some(h) => d.with_hint(h),
                    None if self.problem.is_none() => d.with_hint(format!(
                        "declare it in `(:constants ...)`, or use a variable `?{}`",
                        name.name
                    )),
                    None => d.with_hint("declare it in `(:objects ...)`"),
                });
                None
            }
        }
    }

    /// Terms in `:init` must be objects.
    fn ground(&mut self, atom: &Atom) {
        for a in &atom.args {
            if let Term::Var { name } = a {
                self.diags.push(Diagnostic::error(
                    codes::NOT_GROUND,
                    name.span,
                    format!(
                        "`?{}` is a variable, but `:init` lists facts about objects",
                        name.name
                    ),
                ));
            }
        }
    }

    fn args(&mut self, what: &str, atom: &Atom, sig: &Signature, decl_span: Span, scope: &Scope) {
        if atom.args.len() != sig.params.len() {
            let n = sig.params.len();
            self.diags.push(
                Diagnostic::error(
                    codes::WRONG_ARITY,
                    atom.span,
                    format!(
                        "{what} `{}` takes {n} argument{}, but {} {} given",
                        atom.pred.name,
                        if n == 1 { "" } else { "s" },
                        atom.args.len(),
                        if atom.args.len() == 1 { "is" } else { "are" }
                    ),
                )
                .with_label(decl_span, "declared here"),
            );
            for a in &atom.args {
                self.term(a, scope);
            }
            return;
        }
        for (i, (a, want)) in atom.args.iter().zip(&sig.params).enumerate() {
            let Some(have) = self.term(a, scope) else {
                continue;
            };
            if !self.index.types.fits(&have, want) {
                let t = &self.index.types;
                self.diags.push(
                    Diagnostic::error(
                        codes::TYPE_MISMATCH,
                        a.span(),
                        format!(
                            "`{a}` has type `{}`, but argument {} of `{}` must be `{}`",
                            t.display(&have),
                            i + 1,
                            atom.pred.name,
                            t.display(want)
                        ),
                    )
                    .with_label(decl_span, "declared here"),
                );
            }
        }
    }

    fn atom(&mut self, atom: &Atom, scope: &Scope) {
        match self.index.predicates.get(atom.pred.as_str()) {
            Some(sig) => {
                let span = self.domain.predicates[sig.index].span;
                self.args("predicate", atom, sig, span, scope)
            }
            None => {
                let d = Diagnostic::error(
                    codes::UNKNOWN_PREDICATE,
                    atom.pred.span,
                    format!(
                        "predicate `{}` is not declared in the domain",
                        atom.pred.name
                    ),
                );
                let decl = inferred::declaration(
                    atom,
                    scope,
                    self.index,
                    self.problem,
                    !self.domain.types.is_empty(),
                );
                let hint = did_you_mean(
                    &atom.pred.name,
                    self.index.predicates.keys().map(String::as_str),
                )
                .unwrap_or_else(|| format!("declare it in `(:predicates ...)`: `{decl}`"));
                let d = d.with_hint(hint);
                self.diags
                    .push(match inferred::insertion(self.domain, &decl) {
                        Some((at, text)) => d.with_fix(format!("declare `{decl}`"), at, text),
                        None => d,
                    });
                for a in &atom.args {
                    self.term(a, scope);
                }
            }
        }
    }

    fn fluent(&mut self, app: &Atom, scope: &Scope) {
        self.use_feature(Feature::Numeric, app.span);
        match self.index.functions.get(app.pred.as_str()) {
            Some(sig) => {
                let span = self.domain.functions[sig.index].span;
                self.args("function", app, sig, span, scope)
            }
            None if app.pred.name == "total-time" && app.args.is_empty() => {}
            None => {
                let d = Diagnostic::error(
                    codes::UNKNOWN_FUNCTION,
                    app.pred.span,
                    format!("function `{}` is not declared in the domain", app.pred.name),
                );
                let hint = did_you_mean(
                    &app.pred.name,
                    self.index.functions.keys().map(String::as_str),
                )
                .unwrap_or_else(|| "declare it in `(:functions ...)`".into());
                self.diags.push(d.with_hint(hint));
            }
        }
    }

    fn num_expr(&mut self, e: &NumExpr, scope: &Scope) {
        match e {
            NumExpr::Number { .. } => {}
            NumExpr::Fluent { app } => self.fluent(app, scope),
            NumExpr::Duration { span } => {
                if !self.durative {
                    self.diags.push(Diagnostic::error(
                        codes::UNBOUND_VARIABLE,
                        *span,
                        "`?duration` exists only in durative actions",
                    ));
                }
            }
            NumExpr::Binary { left, right, .. } => {
                self.num_expr(left, scope);
                self.num_expr(right, scope);
            }
            NumExpr::Neg { expr, .. } => self.num_expr(expr, scope),
        }
    }

    fn quantified(&mut self, vars: &[Typed], scope: &Scope) -> Scope {
        check_duplicate_vars(vars, &mut self.diags);
        let mut inner = scope.clone();
        for v in vars {
            inner.push((
                v.name.name.to_string(),
                self.index.types.resolve(&v.ty, &mut self.diags),
            ));
            note_typed(v, &mut self.used);
        }
        inner
    }

    fn formula(&mut self, f: &Formula, scope: &Scope) {
        match f {
            Formula::Atom { atom } => self.atom(atom, scope),
            Formula::Equal { left, right, span } => {
                self.use_feature(Feature::Equality, *span);
                self.term(left, scope);
                self.term(right, scope);
            }
            Formula::Not { formula, span } => {
                self.use_feature(Feature::Negation, *span);
                self.formula(formula, scope);
            }
            Formula::And { parts, .. } => {
                for p in parts {
                    self.formula(p, scope);
                }
            }
            Formula::Or { parts, span } => {
                self.use_feature(Feature::Disjunction, *span);
                for p in parts {
                    self.formula(p, scope);
                }
            }
            Formula::Imply { left, right, span } => {
                self.use_feature(Feature::Disjunction, *span);
                self.formula(left, scope);
                self.formula(right, scope);
            }
            Formula::Exists { vars, body, span } => {
                self.use_feature(Feature::Existential, *span);
                let inner = self.quantified(vars, scope);
                self.formula(body, &inner);
            }
            Formula::Forall { vars, body, span } => {
                self.use_feature(Feature::Universal, *span);
                let inner = self.quantified(vars, scope);
                self.formula(body, &inner);
            }
            Formula::Compare { left, right, .. } => {
                self.num_expr(left, scope);
                self.num_expr(right, scope);
            }
        }
    }

    fn effect(&mut self, e: &Effect, scope: &Scope) {
        match e {
            Effect::Add { atom } | Effect::Delete { atom, .. } => {
                if self.index.derived.contains(atom.pred.as_str()) {
                    self.diags.push(
                        Diagnostic::error(
                            codes::DERIVED_EFFECT,
                            atom.pred.span,
                            format!(
                                "`{}` is a derived predicate: actions cannot change it",
                                atom.pred.name
                            ),
                        )
                        .with_hint("change the facts it is derived from instead"),
                    );
                }
                self.atom(atom, scope)
            }
            Effect::And { parts, .. } => {
                for p in parts {
                    self.effect(p, scope);
                }
            }
            Effect::Forall { vars, body, span } => {
                self.use_feature(Feature::ConditionalEffects, *span);
                let inner = self.quantified(vars, scope);
                self.effect(body, &inner);
            }
            Effect::When {
                condition,
                body,
                span,
            } => {
                self.use_feature(Feature::ConditionalEffects, *span);
                self.formula(condition, scope);
                self.effect(body, scope);
            }
            Effect::Numeric { fluent, value, .. } => {
                self.fluent(fluent, scope);
                self.num_expr(value, scope);
            }
        }
    }
}
