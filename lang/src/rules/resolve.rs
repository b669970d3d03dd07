//! What each name of an item refers to, as the checker sees it: calls to
//! the declared nodes and trees, ports of the callee, `?variables` to their
//! binding, captures to the pattern, table lookups to the table, names in
//! formulas and effects to the domain's predicates and objects, a rule's
//! pattern to the domain actions it matches, paths to files.
//!
//! [`resolve_item`] is a pure function over one item (spans relative to
//! it, like its tree); `crate::resolutions` turns the names into the
//! declarations' places, per item in salsa. The language server reads
//! that and resolves nothing itself.

use super::ast::*;
use super::check::{matched_actions, Decls, DomainCtx, BASIC_TYPES};
use btc_pddl::ast::{Atom, Effect, Formula, NumExpr, Term, TypeSpec, Typed};
use btc_pddl::source::Span;

/// What a name refers to. Names are as the language compares them: node,
/// tree, table, port and capture names as written, PDDL names folded.
#[derive(Clone, Debug, PartialEq, Eq, Hash)]
pub enum Target {
    /// A declared action, condition or tree.
    Callable {
        name: String,
    },
    Table {
        name: String,
    },
    /// A port of a callable; a tree's or condition's `?port` in its own
    /// body is one too.
    Port {
        owner: String,
        name: String,
    },
    /// A rule's `?variable` (or a quantifier's), bound at `binding`
    /// (relative to the item).
    Var {
        name: String,
        binding: Span,
    },
    /// A capture of a rule's pattern, bound at `binding`.
    Capture {
        name: String,
        binding: Span,
    },
    /// A PDDL action a rule's pattern matches.
    Action {
        name: String,
    },
    /// A PDDL predicate or function.
    Predicate {
        name: String,
    },
    /// A PDDL type of the domain.
    Type {
        name: String,
    },
    /// `string`, `int`, `float`, `bool`: no declaration anywhere.
    BasicType {
        name: String,
    },
    /// A constant of the domain or an object of the problem.
    Object {
        name: String,
    },
    /// The file a `domain`, `problem` or `import` path names.
    File {
        written: String,
    },
    /// `std::NAME`.
    Std {
        module: String,
    },
}

impl Target {
    /// Whether a rename may change this name: what the rules declare, not
    /// what the PDDL files, the paths or the language itself do.
    pub fn renamable(&self) -> bool {
        matches!(
            self,
            Target::Callable { .. }
                | Target::Table { .. }
                | Target::Port { .. }
                | Target::Var { .. }
                | Target::Capture { .. }
        )
    }
}

/// One name in an item: where it is written (relative to the item), what
/// it refers to, and whether this is where it is declared.
#[derive(Clone, Debug, PartialEq, Eq, Hash)]
pub struct NameRef {
    pub span: Span,
    pub target: Target,
    pub declaration: bool,
}

/// How a `?variable` is bound in the scope being walked.
#[derive(Clone, Debug)]
enum Binding {
    Local(Span),
    /// A port of the item's own tree or condition.
    Port {
        owner: String,
        port: String,
    },
}

struct Walk<'a> {
    decls: &'a Decls,
    ctx: Option<DomainCtx<'a>>,
    vars: Vec<(String, Binding)>,
    captures: Vec<(String, Span)>,
    out: Vec<NameRef>,
}

/// Every name of one item that refers to something, in the order written.
/// Names that refer to nothing (an unknown node, an unbound variable) are
/// left out: the checker reports them.
pub fn resolve_item(item: &Item, decls: &Decls, ctx: Option<DomainCtx>) -> Vec<NameRef> {
    let mut w = Walk {
        decls,
        ctx,
        vars: Vec::new(),
        captures: Vec::new(),
        out: Vec::new(),
    };
    match item {
        Item::Domain { path, .. } | Item::Problem { path, .. } => w.path(path),
        Item::Import { target, .. } => match target {
            ImportTarget::Path { path, .. } => w.path(path),
            ImportTarget::Std { module } => w.push(
                module.span,
                Target::Std {
                    module: module.text.clone(),
                },
                false,
            ),
        },
        Item::Node(n) => {
            w.declare_callable(&n.name, &n.ports);
            if let Some(f) = &n.formula {
                w.formula(f);
            }
        }
        Item::Tree(t) => {
            w.declare_callable(&t.name, &t.ports);
            w.templates(&t.body);
        }
        Item::Table(t) => w.push(
            t.name.span,
            Target::Table {
                name: t.name.text.clone(),
            },
            true,
        ),
        Item::Rule(r) => w.rule(r),
        Item::Plan { body, .. } => w.templates(body),
        Item::Error { .. } => {}
    }
    w.out.sort_by_key(|r| (r.span.start, r.span.end));
    w.out
}

impl Walk<'_> {
    fn push(&mut self, span: Span, target: Target, declaration: bool) {
        self.out.push(NameRef {
            span,
            target,
            declaration,
        });
    }

    fn path(&mut self, path: &StrLit) {
        if let Some(written) = path.plain() {
            self.push(path.span, Target::File { written }, false);
        }
    }

    /// A node's or tree's name and ports; the ports are the body's variables.
    fn declare_callable(&mut self, name: &Ident, ports: &[PortDecl]) {
        self.push(
            name.span,
            Target::Callable {
                name: name.text.clone(),
            },
            true,
        );
        for p in ports {
            self.push(
                p.name.span,
                Target::Port {
                    owner: name.text.clone(),
                    name: p.name.text.clone(),
                },
                true,
            );
            self.type_name(&p.ty);
            self.vars.push((
                p.name.key.clone().into_string(),
                Binding::Port {
                    owner: name.text.clone(),
                    port: p.name.text.clone(),
                },
            ));
        }
    }

    fn type_name(&mut self, ty: &Ident) {
        if BASIC_TYPES.contains(&ty.text.as_str()) {
            self.push(
                ty.span,
                Target::BasicType {
                    name: ty.text.clone(),
                },
                false,
            );
        } else if self
            .ctx
            .is_some_and(|c| c.index.types.id(ty.key.as_str()).is_some())
        {
            self.push(
                ty.span,
                Target::Type {
                    name: ty.key.to_string(),
                },
                false,
            );
        }
    }

    fn rule(&mut self, r: &Rule) {
        if let Some(c) = self.ctx {
            let actions = matched_actions(&r.pattern, c.domain, c.actions);
            for part in &r.pattern.name {
                if let NamePart::Lit { span, .. } = part {
                    for (a, _) in &actions {
                        self.push(
                            *span,
                            Target::Action {
                                name: a.name.name.to_string(),
                            },
                            false,
                        );
                    }
                }
            }
        }
        for part in &r.pattern.name {
            if let NamePart::Capture { name } = part {
                let first = !self.captures.iter().any(|(c, _)| *c == name.text);
                if first {
                    self.captures.push((name.text.clone(), name.span));
                }
                self.capture(name, first);
            }
        }
        for p in &r.pattern.params {
            let first = !self.vars.iter().any(|(v, _)| *v == p.var.text);
            if first {
                self.vars
                    .push((p.var.text.clone(), Binding::Local(p.var.span)));
            }
            self.var(&p.var.text, p.var.span, first);
        }
        for g in &r.guards {
            match g {
                Guard::Ne { left, right, .. } | Guard::Eq { left, right, .. } => {
                    for o in [left, right] {
                        match o {
                            Operand::Var { name } => self.var(&name.text, name.span, false),
                            Operand::Object { name } => self.object(name.key.as_str(), name.span),
                        }
                    }
                }
                Guard::IsType { var, ty, .. } => {
                    self.var(&var.text, var.span, false);
                    self.type_name(ty);
                }
                Guard::InTable { key, table, .. } => {
                    self.capture(key, false);
                    self.table(table);
                }
            }
        }
        if let RuleBody::Template { body, effect } = &r.body {
            self.templates(body);
            if let Some(e) = effect {
                self.effect(e);
            }
        }
    }

    fn var(&mut self, name: &str, span: Span, declaration: bool) {
        let Some((_, b)) = self.vars.iter().rev().find(|(v, _)| v == name) else {
            return;
        };
        let target = match b {
            Binding::Local(binding) => Target::Var {
                name: name.to_owned(),
                binding: *binding,
            },
            Binding::Port { owner, port } => Target::Port {
                owner: owner.clone(),
                name: port.clone(),
            },
        };
        self.push(span, target, declaration);
    }

    fn capture(&mut self, name: &Ident, declaration: bool) {
        if let Some((_, binding)) = self.captures.iter().find(|(c, _)| *c == name.text) {
            let target = Target::Capture {
                name: name.text.clone(),
                binding: *binding,
            };
            self.push(name.span, target, declaration);
        }
    }

    fn table(&mut self, name: &Ident) {
        if self.decls.tables.contains_key(&name.text) {
            self.push(
                name.span,
                Target::Table {
                    name: name.text.clone(),
                },
                false,
            );
        }
    }

    fn object(&mut self, name: &str, span: Span) {
        let known = self.ctx.is_some_and(|c| {
            c.index.constants.contains_key(name)
                || c.problem.is_some_and(|p| p.objects.contains_key(name))
        });
        if known {
            self.push(
                span,
                Target::Object {
                    name: name.to_owned(),
                },
                false,
            );
        }
    }

    fn templates(&mut self, ts: &[Template]) {
        Template::walk_all(ts, &mut |t| self.template(t));
    }

    /// One template's own names (the walk goes inside it).
    fn template(&mut self, t: &Template) {
        match t {
            Template::Control { name, .. } => {
                if let Some(n) = name {
                    self.string(n);
                }
            }
            Template::Decorator { args, name, .. } => {
                for a in args {
                    self.value(&a.value);
                }
                if let Some(n) = name {
                    self.string(n);
                }
            }
            Template::Call { name, args, .. } => {
                let ports = self.decls.ports(&name.text);
                if ports.is_some() {
                    self.push(
                        name.span,
                        Target::Callable {
                            name: name.text.clone(),
                        },
                        false,
                    );
                }
                for a in args {
                    if ports.is_some_and(|ps| ps.iter().any(|p| p.name.text == a.port.text)) {
                        self.push(
                            a.port.span,
                            Target::Port {
                                owner: name.text.clone(),
                                name: a.port.text.clone(),
                            },
                            false,
                        );
                    }
                    self.value(&a.value);
                }
            }
            Template::Steps { .. } | Template::Error { .. } | Template::Script { .. } => {}
        }
    }

    fn string(&mut self, s: &StrLit) {
        for p in &s.parts {
            match p {
                StrPart::Var { name } => self.var(&name.text, name.span, false),
                StrPart::Capture { name } => self.capture(name, false),
                StrPart::Text { .. } | StrPart::Value { .. } => {}
            }
        }
    }

    fn value(&mut self, v: &Value) {
        match v {
            Value::Var { name } => self.var(&name.text, name.span, false),
            Value::Str { value } => self.string(value),
            Value::Name { name } => self.capture(name, false),
            Value::Lookup { table, key, .. } => {
                self.table(table);
                self.value(key);
            }
            Value::Int { .. } | Value::Float { .. } | Value::Bool { .. } => {}
        }
    }

    /// Quantified variables shadow the outer ones inside `body`.
    fn quantified(&mut self, vars: &[Typed], body: impl FnOnce(&mut Self)) {
        let depth = self.vars.len();
        for v in vars {
            self.vars
                .push((v.name.name.to_string(), Binding::Local(v.name.span)));
            self.var(&v.name.name, v.name.span, true);
            self.type_spec(&v.ty);
        }
        body(self);
        self.vars.truncate(depth);
    }

    fn type_spec(&mut self, t: &TypeSpec) {
        let names = match t {
            TypeSpec::Object => return,
            TypeSpec::Named { name } => std::slice::from_ref(name),
            TypeSpec::Either { names, .. } => names.as_slice(),
        };
        for n in names {
            if self
                .ctx
                .is_some_and(|c| c.index.types.id(&n.name).is_some())
            {
                self.push(
                    n.span,
                    Target::Type {
                        name: n.name.to_string(),
                    },
                    false,
                );
            }
        }
    }

    fn atom(&mut self, a: &Atom) {
        let known = self.ctx.is_some_and(|c| {
            c.index.predicates.contains_key(a.pred.name.as_str())
                || c.index.functions.contains_key(a.pred.name.as_str())
        });
        if known {
            self.push(
                a.pred.span,
                Target::Predicate {
                    name: a.pred.name.to_string(),
                },
                false,
            );
        }
        for t in &a.args {
            self.term(t);
        }
    }

    fn term(&mut self, t: &Term) {
        match t {
            Term::Var { name } => self.var(&name.name, name.span, false),
            Term::Const { name } => self.object(&name.name, name.span),
        }
    }

    fn num(&mut self, e: &NumExpr) {
        match e {
            NumExpr::Fluent { app } => self.atom(app),
            NumExpr::Binary { left, right, .. } => {
                self.num(left);
                self.num(right);
            }
            NumExpr::Neg { expr, .. } => self.num(expr),
            NumExpr::Number { .. } | NumExpr::Duration { .. } => {}
        }
    }

    fn formula(&mut self, f: &Formula) {
        match f {
            Formula::Atom { atom } => self.atom(atom),
            Formula::Equal { left, right, .. } => {
                self.term(left);
                self.term(right);
            }
            Formula::Not { formula, .. } => self.formula(formula),
            Formula::And { parts, .. } | Formula::Or { parts, .. } => {
                for p in parts {
                    self.formula(p);
                }
            }
            Formula::Imply { left, right, .. } => {
                self.formula(left);
                self.formula(right);
            }
            Formula::Exists { vars, body, .. } | Formula::Forall { vars, body, .. } => {
                self.quantified(vars, |w| w.formula(body));
            }
            Formula::Compare { left, right, .. } => {
                self.num(left);
                self.num(right);
            }
        }
    }

    fn effect(&mut self, e: &Effect) {
        match e {
            Effect::Add { atom } | Effect::Delete { atom, .. } => self.atom(atom),
            Effect::And { parts, .. } => {
                for p in parts {
                    self.effect(p);
                }
            }
            Effect::Forall { vars, body, .. } => self.quantified(vars, |w| w.effect(body)),
            Effect::When {
                condition, body, ..
            } => {
                self.formula(condition);
                self.effect(body);
            }
            Effect::Numeric { fluent, value, .. } => {
                self.atom(fluent);
                self.num(value);
            }
        }
    }
}
