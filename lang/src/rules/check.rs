//! Checks of `.btrules` items against their declarations and the PDDL
//! domain. [`check_item`] looks at one item (spans relative to it: the
//! incremental database calls it per item); [`check_file`] does what needs
//! the whole file (duplicates, coverage, shadowing, unused names).

use super::ast::*;
use super::matching::{bind_params, match_name};
use btc_pddl::ast::{Domain, Effect, Formula};
use btc_pddl::check::{check_effect_in, check_formula_in, DomainIndex, ProblemIndex};
use btc_pddl::diagnostic::{closest, codes, Diagnostic};
use btc_pddl::source::{FileId, Span};
use btc_pddl::types::TypeId;
use std::collections::{BTreeMap, BTreeSet};

/// Declarations visible in a rules file: its own, its imports' and the
/// standard library's. The first declaration of a name wins.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Decls {
    pub nodes: BTreeMap<String, NodeDecl>,
    pub trees: BTreeMap<String, TreeDecl>,
    pub tables: BTreeMap<String, TableDecl>,
}

impl Decls {
    pub fn add_items(&mut self, items: &[ItemNode]) {
        for i in items {
            match &i.item {
                Item::Node(n) => {
                    self.nodes
                        .entry(n.name.text.clone())
                        .or_insert_with(|| n.clone());
                }
                Item::Tree(t) => {
                    self.trees
                        .entry(t.name.text.clone())
                        .or_insert_with(|| t.clone());
                }
                Item::Table(t) => {
                    self.tables
                        .entry(t.name.text.clone())
                        .or_insert_with(|| t.clone());
                }
                _ => {}
            }
        }
    }

    /// The ports of a callable: a node's or a tree's.
    pub fn ports(&self, name: &str) -> Option<&[PortDecl]> {
        self.nodes
            .get(name)
            .map(|n| n.ports.as_slice())
            .or_else(|| self.trees.get(name).map(|t| t.ports.as_slice()))
    }

    fn callables(&self) -> impl Iterator<Item = &str> {
        self.nodes
            .keys()
            .chain(self.trees.keys())
            .map(String::as_str)
    }
}

/// The PDDL side a rules file is checked against.
#[derive(Clone, Copy)]
pub struct DomainCtx<'a> {
    pub domain: &'a Domain,
    pub index: &'a DomainIndex,
    pub problem: Option<&'a ProblemIndex>,
}

pub const BASIC_TYPES: &[&str] = &["string", "int", "float", "bool"];

/// The type of a value bound to a port.
#[derive(Clone, Debug, PartialEq)]
enum VType {
    /// A PDDL variable of these types.
    Objects(Vec<TypeId>),
    /// A string literal that names an object.
    Name(String),
    Str,
    Int,
    Float,
    Bool,
    Unknown,
}

struct Tcx<'a> {
    decls: &'a Decls,
    ctx: Option<DomainCtx<'a>>,
    /// Variables in scope and their PDDL types (`None`: not known).
    vars: Vec<(String, Option<Vec<TypeId>>)>,
    /// Captures in scope and the values they take in the domain's actions.
    captures: Vec<(String, Vec<String>)>,
    in_plan: bool,
    diags: Vec<Diagnostic>,
}

impl Tcx<'_> {
    fn err(&mut self, d: Diagnostic) {
        if !self.diags.contains(&d) {
            self.diags.push(d);
        }
    }

    fn template(&mut self, t: &Template) {
        match t {
            Template::Control {
                control,
                name,
                children,
                span,
            } => {
                if let Some(n) = name {
                    self.string(n);
                }
                if let ControlKind::Parallel { success, failure } = control {
                    let n = children.len() as u32;
                    if *success > n || *failure > n || *success == 0 {
                        self.err(
                            Diagnostic::error(
                                codes::R_BAD_ARGUMENT,
                                *span,
                                format!("`parallel(success: {success}, failure: {failure})` has {n} children: the thresholds must be between 1 and {n}"),
                            )
                            .with_hint("success: how many children must succeed; failure: how many may fail before the node fails"),
                        );
                    }
                }
                for c in children {
                    self.template(c);
                }
            }
            Template::Decorator {
                decorator,
                name,
                child,
                span,
            } => {
                if let Some(n) = name {
                    self.string(n);
                }
                if matches!(
                    decorator,
                    DecoratorKind::Retry { times: 0 }
                        | DecoratorKind::Repeat { times: 0 }
                        | DecoratorKind::Timeout { ms: 0 }
                ) {
                    self.err(Diagnostic::error(
                        codes::R_BAD_ARGUMENT,
                        *span,
                        format!("`{}(0)` never runs its child", decorator.keyword()),
                    ));
                }
                self.template(child);
            }
            Template::Call { name, args, span } => self.call(name, args, *span),
            Template::Steps { span, .. } => {
                if !self.in_plan {
                    self.err(
                        Diagnostic::error(
                            codes::R_PLAN_BLOCK,
                            *span,
                            "`steps` stands only in the `plan { ... }` block",
                        )
                        .with_hint(
                            "rules and trees describe one step; the plan block arranges them",
                        ),
                    );
                }
            }
            Template::Error { .. } => {}
        }
    }

    fn call(&mut self, name: &Ident, args: &[Arg], span: Span) {
        let Some(ports) = self.decls.ports(&name.text) else {
            let candidate = closest(&name.text, self.decls.callables()).map(str::to_owned);
            self.err(
                Diagnostic::error(
                    codes::R_UNKNOWN_NODE,
                    name.span,
                    format!("no node or tree is called `{}`", name.text),
                )
                .suggest(candidate, || {
                    format!("declare it: `action {}(...)`", name.text)
                }),
            );
            for a in args {
                self.value(&a.value);
            }
            return;
        };
        let ports = ports.to_vec();
        let mut given = BTreeSet::new();
        for a in args {
            let vt = self.value(&a.value);
            let Some(port) = ports.iter().find(|p| p.name.text == a.port.text) else {
                let candidate = closest(&a.port.text, ports.iter().map(|p| p.name.text.as_str()))
                    .map(str::to_owned);
                let otherwise = || {
                    let names: Vec<String> =
                        ports.iter().map(|p| format!("`{}`", p.name.text)).collect();
                    if names.is_empty() {
                        format!("`{}` has no ports", name.text)
                    } else {
                        format!("its ports are {}", names.join(", "))
                    }
                };
                self.err(
                    Diagnostic::error(
                        codes::R_UNKNOWN_PORT,
                        a.port.span,
                        format!("`{}` has no port `{}`", name.text, a.port.text),
                    )
                    .suggest(candidate, otherwise),
                );
                continue;
            };
            if !given.insert(a.port.text.clone()) {
                self.err(Diagnostic::error(
                    codes::R_DUPLICATE,
                    a.port.span,
                    format!("port `{}` is given twice", a.port.text),
                ));
            }
            self.port_fit(port, &a.value, vt);
        }
        let missing: Vec<&PortDecl> = ports
            .iter()
            .filter(|p| !p.out && !given.contains(&p.name.text))
            .collect();
        if !missing.is_empty() {
            let names: Vec<String> = missing
                .iter()
                .map(|p| format!("`{}: {}`", p.name.text, p.ty.text))
                .collect();
            self.err(
                Diagnostic::error(
                    codes::R_MISSING_PORT,
                    span,
                    format!(
                        "`{}` needs {} {}",
                        name.text,
                        if missing.len() == 1 {
                            "the port"
                        } else {
                            "the ports"
                        },
                        names.join(", ")
                    ),
                )
                .with_hint(format!(
                    "add {}",
                    missing
                        .iter()
                        .map(|p| format!("{}: ...", p.name.text))
                        .collect::<Vec<_>>()
                        .join(", ")
                )),
            );
        }
    }

    fn string(&mut self, s: &StrLit) {
        for p in &s.parts {
            match p {
                StrPart::Var { name } => {
                    self.var(name);
                }
                StrPart::Capture { name } => {
                    self.capture(name);
                }
                StrPart::Text { .. } => {}
            }
        }
    }

    fn var(&mut self, name: &Ident) -> Option<Vec<TypeId>> {
        match self.vars.iter().find(|(v, _)| *v == name.text) {
            Some((_, t)) => t.clone(),
            None => {
                let candidate = closest(&name.text, self.vars.iter().map(|(v, _)| v.as_str()))
                    .map(|c| format!("?{c}"));
                self.err(
                    Diagnostic::error(
                        codes::R_UNBOUND,
                        name.span,
                        format!("`?{}` is not bound here", name.text),
                    )
                    .suggest(candidate, || {
                        "variables come from the rule's pattern (or the tree's ports)".into()
                    }),
                );
                None
            }
        }
    }

    fn capture(&mut self, name: &Ident) -> Option<Vec<String>> {
        match self.captures.iter().find(|(c, _)| *c == name.text) {
            Some((_, vals)) => Some(vals.clone()),
            None => {
                let candidate = closest(&name.text, self.captures.iter().map(|(c, _)| c.as_str()))
                    .map(str::to_owned);
                self.err(
                    Diagnostic::error(
                        codes::R_UNBOUND,
                        name.span,
                        format!("`{}` is not a capture of this rule", name.text),
                    )
                    .suggest(candidate, || {
                        "captures come from `{name}` parts of the rule's pattern".into()
                    }),
                );
                None
            }
        }
    }

    fn value(&mut self, v: &Value) -> VType {
        match v {
            Value::Var { name } => self.var(name).map_or(VType::Unknown, VType::Objects),
            Value::Str { value } => {
                self.string(value);
                match value.plain() {
                    Some(s) => VType::Name(s),
                    None => VType::Str,
                }
            }
            Value::Int { .. } => VType::Int,
            Value::Float { .. } => VType::Float,
            Value::Bool { .. } => VType::Bool,
            Value::Name { name } => {
                self.capture(name);
                VType::Str
            }
            Value::Lookup { table, key, span } => self.lookup(table, key, *span),
        }
    }

    fn lookup(&mut self, table: &Ident, key: &Value, span: Span) -> VType {
        let Some(t) = self.decls.tables.get(&table.text).cloned() else {
            let candidate = closest(&table.text, self.decls.tables.keys().map(String::as_str))
                .map(str::to_owned);
            self.err(
                Diagnostic::error(
                    codes::R_UNKNOWN_TABLE,
                    table.span,
                    format!("no table is called `{}`", table.text),
                )
                .suggest(candidate, || {
                    format!("declare it: `table {} {{ KEY: value }}`", table.text)
                }),
            );
            self.value(key);
            return VType::Unknown;
        };
        let has = |k: &str| t.entries.iter().any(|e| e.key.text.eq_ignore_ascii_case(k));
        let keys = || {
            t.entries
                .iter()
                .map(|e| e.key.text.clone())
                .collect::<Vec<_>>()
                .join(", ")
        };
        match key {
            Value::Name { name } => {
                if let Some(values) = self.capture(name) {
                    for val in values.iter().filter(|v| !has(v)) {
                        self.err(
                            Diagnostic::error(
                                codes::R_UNKNOWN_KEY,
                                span,
                                format!("table `{}` has no key `{}` (the capture `{}` takes it for a domain action)", table.text, val.to_uppercase(), name.text),
                            )
                            .with_hint(format!("its keys are {}; add the key, or guard the rule with `where {} in {}`", keys(), name.text, table.text)),
                        );
                    }
                }
            }
            Value::Str { value } => {
                if let Some(k) = value.plain().filter(|k| !has(k)) {
                    self.err(
                        Diagnostic::error(
                            codes::R_UNKNOWN_KEY,
                            value.span,
                            format!("table `{}` has no key `{k}`", table.text),
                        )
                        .with_hint(format!("its keys are {}", keys())),
                    );
                }
            }
            other => {
                self.value(other);
            }
        }
        match t.entries.first().map(|e| &e.value) {
            Some(Literal::Int { .. }) => VType::Int,
            Some(Literal::Float { .. }) => VType::Float,
            Some(Literal::Bool { .. }) => VType::Bool,
            Some(Literal::Str { .. } | Literal::Name { .. }) => VType::Str,
            None => VType::Unknown,
        }
    }

    fn port_fit(&mut self, port: &PortDecl, value: &Value, vt: VType) {
        let ty = port.ty.text.as_str();
        let describe = |vt: &VType, ctx: Option<DomainCtx>| match vt {
            VType::Objects(t) => match ctx {
                Some(c) => format!("an object of type `{}`", c.index.types.display(t)),
                None => "an object".to_owned(),
            },
            VType::Name(_) | VType::Str => "a string".to_owned(),
            VType::Int => "an int".to_owned(),
            VType::Float => "a float".to_owned(),
            VType::Bool => "a bool".to_owned(),
            VType::Unknown => "a value".to_owned(),
        };
        let ok = match (ty, &vt) {
            (_, VType::Unknown) => true,
            ("string", _) => true,
            ("int", VType::Int) | ("float", VType::Int | VType::Float) | ("bool", VType::Bool) => {
                true
            }
            ("int" | "float" | "bool", _) => false,
            (_, VType::Objects(have)) => match self
                .ctx
                .and_then(|c| c.index.types.id(&ty.to_lowercase()).map(|w| (c, w)))
            {
                Some((c, want)) => c.index.types.fits(have, &[want]),
                None => true, // unknown port type: reported at the declaration
            },
            (_, VType::Name(obj)) => {
                let Some(c) = self.ctx else { return };
                let obj_l = obj.to_lowercase();
                let info = c
                    .problem
                    .and_then(|p| p.objects.get(&obj_l))
                    .or_else(|| c.index.constants.get(&obj_l));
                match info {
                    Some(o) => match c.index.types.id(&ty.to_lowercase()) {
                        Some(want) => c.index.types.fits(&o.types, &[want]),
                        None => true,
                    },
                    // Without a problem, objects are unknown: checked at compile time.
                    None if c.problem.is_none() => true,
                    None => {
                        let known = c
                            .problem
                            .map(|p| {
                                p.object_names
                                    .iter()
                                    .map(String::as_str)
                                    .collect::<Vec<_>>()
                            })
                            .unwrap_or_default();
                        // The fix rewrites the whole literal, quotes included.
                        let candidate = closest(&obj_l, known.iter().copied());
                        let mut d = Diagnostic::error(codes::R_UNKNOWN_OBJECT, value.span(), format!("`{obj}` is not among the problem's objects or the domain's constants"));
                        d = match candidate {
                            Some(c) => d.with_hint(format!("did you mean `{c}`?")).with_fix(
                                format!("change to `{c}`"),
                                value.span(),
                                format!("{c:?}"),
                            ),
                            None => d.with_hint(
                                "it names no object of the problem and no constant of the domain",
                            ),
                        };
                        self.err(d);
                        return;
                    }
                }
            }
            _ => false,
        };
        if !ok {
            self.err(
                Diagnostic::error(
                    codes::R_PORT_TYPE,
                    value.span(),
                    format!(
                        "port `{}` takes a `{ty}`, but this is {}",
                        port.name.text,
                        describe(&vt, self.ctx)
                    ),
                )
                .with_label(port.span, "the port is declared here"),
            );
        }
    }
}

/// Variables of a rule pattern typed by one PDDL action's parameters.
fn rule_vars(
    rule: &Rule,
    action: Option<(&btc_pddl::ast::Action, &DomainCtx)>,
) -> Vec<(String, Option<Vec<TypeId>>)> {
    let mut vars: Vec<(String, Option<Vec<TypeId>>)> = Vec::new();
    for (i, p) in rule.pattern.params.iter().enumerate() {
        let ty = action.and_then(|(a, c)| {
            a.params
                .get(i)
                .map(|ap| c.index.types.resolve(&ap.ty, &mut Vec::new()))
        });
        match vars.iter_mut().find(|(v, _)| *v == p.var.text) {
            // A repeated variable must fit both parameters.
            Some((_, existing)) => {
                if let (Some(e), Some(t)) = (existing.as_ref(), ty.as_ref()) {
                    if let Some((_, c)) = action {
                        if c.index.types.fits(t, e) {
                            *existing = Some(t.clone());
                        }
                    }
                }
            }
            None => vars.push((p.var.text.clone(), ty)),
        }
    }
    vars
}

/// The domain actions a rule pattern can match, with their captures.
pub fn matched_actions<'d>(
    pattern: &Pattern,
    domain: &'d Domain,
) -> Vec<(&'d btc_pddl::ast::Action, Vec<(String, String)>)> {
    domain
        .actions
        .iter()
        .filter_map(|a| match_name(&pattern.name, &a.name.name).map(|c| (a, c)))
        .collect()
}

/// The domain actions a rule can match: by name, and by its `capture in
/// table` guards (the other guards depend on the step's objects).
pub fn rule_actions<'d>(
    r: &Rule,
    decls: &Decls,
    domain: &'d Domain,
) -> Vec<(&'d btc_pddl::ast::Action, Vec<(String, String)>)> {
    matched_actions(&r.pattern, domain)
        .into_iter()
        .filter(|(_, caps)| {
            r.guards.iter().all(|g| match g {
                Guard::InTable { key, table, .. } => match (
                    caps.iter().find(|(n, _)| *n == key.text),
                    decls.tables.get(&table.text),
                ) {
                    (Some((_, v)), Some(t)) => {
                        t.entries.iter().any(|e| e.key.text.eq_ignore_ascii_case(v))
                    }
                    _ => true,
                },
                _ => true,
            })
        })
        .collect()
}

fn scope_of(vars: &[(String, Option<Vec<TypeId>>)]) -> Vec<(String, Vec<TypeId>)> {
    vars.iter()
        .map(|(v, t)| {
            (
                v.clone(),
                t.clone().unwrap_or_else(|| vec![btc_pddl::types::OBJECT]),
            )
        })
        .collect()
}

/// Checks one item. Spans in the result are relative to the item, like its tree.
pub fn check_item(
    item: &Item,
    decls: &Decls,
    ctx: Option<DomainCtx>,
    _file: FileId,
) -> Vec<Diagnostic> {
    match item {
        Item::Rule(r) => check_rule(r, decls, ctx),
        Item::Node(n) => check_node(n, ctx),
        Item::Tree(t) => {
            let mut tcx = Tcx {
                decls,
                ctx,
                vars: port_vars(&t.ports, ctx),
                captures: Vec::new(),
                in_plan: false,
                diags: Vec::new(),
            };
            for b in &t.body {
                tcx.template(b);
            }
            let mut diags = port_type_diags(&t.ports, ctx);
            diags.extend(tcx.diags);
            diags
        }
        Item::Plan { body, span } => {
            let mut tcx = Tcx {
                decls,
                ctx,
                vars: Vec::new(),
                captures: Vec::new(),
                in_plan: true,
                diags: Vec::new(),
            };
            for b in body {
                tcx.template(b);
            }
            let steps = count_steps(body);
            if steps != 1 {
                tcx.err(
                    Diagnostic::error(
                        codes::R_PLAN_BLOCK,
                        *span,
                        if steps == 0 { "the `plan` block has no `steps`".to_owned() } else { format!("the `plan` block has `steps` {steps} times") },
                    )
                    .with_hint("write `steps` exactly once where the plan's steps go, e.g. `plan { sequence { steps } }`"),
                );
            }
            tcx.diags
        }
        Item::Table(t) => {
            let mut diags = Vec::new();
            let mut seen = BTreeSet::new();
            for e in &t.entries {
                if !seen.insert(e.key.text.to_lowercase()) {
                    diags.push(Diagnostic::error(
                        codes::R_DUPLICATE,
                        e.key.span,
                        format!("key `{}` is in table `{}` twice", e.key.text, t.name.text),
                    ));
                }
            }
            diags
        }
        Item::Domain { .. } | Item::Problem { .. } | Item::Import { .. } | Item::Error { .. } => {
            Vec::new()
        }
    }
}

fn count_steps(body: &[Template]) -> usize {
    body.iter()
        .map(|t| match t {
            Template::Steps { .. } => 1,
            Template::Control { children, .. } => count_steps(children),
            Template::Decorator { child, .. } => count_steps(std::slice::from_ref(child)),
            _ => 0,
        })
        .sum()
}

fn port_vars(ports: &[PortDecl], ctx: Option<DomainCtx>) -> Vec<(String, Option<Vec<TypeId>>)> {
    ports
        .iter()
        .map(|p| {
            let ty = ctx
                .and_then(|c| c.index.types.id(&p.ty.text.to_lowercase()))
                .map(|t| vec![t]);
            (p.name.text.to_lowercase(), ty)
        })
        .collect()
}

fn port_type_diags(ports: &[PortDecl], ctx: Option<DomainCtx>) -> Vec<Diagnostic> {
    let mut diags = Vec::new();
    let mut seen = BTreeSet::new();
    for p in ports {
        if !seen.insert(p.name.text.clone()) {
            diags.push(Diagnostic::error(
                codes::R_DUPLICATE,
                p.name.span,
                format!("port `{}` is declared twice", p.name.text),
            ));
        }
        let ty = p.ty.text.as_str();
        if BASIC_TYPES.contains(&ty) {
            continue;
        }
        if let Some(c) = ctx {
            if c.index.types.id(&ty.to_lowercase()).is_none() {
                let candidates: Vec<&str> = c
                    .index
                    .types
                    .names()
                    .chain(BASIC_TYPES.iter().copied())
                    .collect();
                let candidate = closest(ty, candidates.iter().copied()).map(str::to_owned);
                diags.push(
                    Diagnostic::error(
                        codes::R_UNKNOWN_TYPE,
                        p.ty.span,
                        format!("`{ty}` is neither a type of the domain nor a basic type"),
                    )
                    .suggest(candidate, || {
                        "port types are the domain's types or string, int, float, bool".into()
                    }),
                );
            }
        }
    }
    diags
}

fn check_node(n: &NodeDecl, ctx: Option<DomainCtx>) -> Vec<Diagnostic> {
    let mut diags = port_type_diags(&n.ports, ctx);
    if let (Some(f), Some(c)) = (&n.formula, ctx) {
        let scope = scope_of(&port_vars(&n.ports, Some(c)));
        diags.extend(check_formula_in(c.domain, c.index, c.problem, f, &scope));
    }
    diags
}

fn check_rule(r: &Rule, decls: &Decls, ctx: Option<DomainCtx>) -> Vec<Diagnostic> {
    let mut diags: Vec<Diagnostic> = Vec::new();
    let push = |d: Diagnostic, diags: &mut Vec<Diagnostic>| {
        if !diags.contains(&d) {
            diags.push(d);
        }
    };
    // Guards refer to the pattern's variables and captures.
    for g in &r.guards {
        let vars: Vec<&Ident> = match g {
            Guard::Ne { left, right, .. } | Guard::Eq { left, right, .. } => vec![left, right],
            Guard::IsType { var, .. } => vec![var],
            Guard::InTable { .. } => vec![],
        };
        for v in vars {
            if !r.pattern.params.iter().any(|p| p.var.text == v.text) {
                push(
                    Diagnostic::error(
                        codes::R_UNBOUND,
                        v.span,
                        format!("`?{}` is not a parameter of this rule's pattern", v.text),
                    ),
                    &mut diags,
                );
            }
        }
        match g {
            Guard::InTable { key, table, .. } => {
                if !r
                    .pattern
                    .name
                    .iter()
                    .any(|p| matches!(p, NamePart::Capture { name } if name.text == key.text))
                {
                    push(
                        Diagnostic::error(
                            codes::R_UNBOUND,
                            key.span,
                            format!("`{}` is not a capture of this rule's pattern", key.text),
                        ),
                        &mut diags,
                    );
                }
                if !decls.tables.contains_key(&table.text) {
                    push(
                        Diagnostic::error(
                            codes::R_UNKNOWN_TABLE,
                            table.span,
                            format!("no table is called `{}`", table.text),
                        ),
                        &mut diags,
                    );
                }
            }
            Guard::IsType { ty, .. } => {
                if let Some(c) = ctx {
                    if c.index.types.id(&ty.text.to_lowercase()).is_none() {
                        let d = Diagnostic::error(
                            codes::R_UNKNOWN_TYPE,
                            ty.span,
                            format!("`{}` is not a type of the domain", ty.text),
                        );
                        push(
                            match closest(&ty.text.to_lowercase(), c.index.types.names()) {
                                Some(t) => d.suggest(Some(t.to_owned()), String::new),
                                None => d,
                            },
                            &mut diags,
                        );
                    }
                }
            }
            _ => {}
        }
    }
    let captures_of = |matched: &[(&btc_pddl::ast::Action, Vec<(String, String)>)]| -> Vec<(String, Vec<String>)> {
        r.pattern
            .name
            .iter()
            .filter_map(|p| match p {
                NamePart::Capture { name } => Some(name.text.clone()),
                NamePart::Lit { .. } => None,
            })
            .map(|c| {
                let vals: BTreeSet<String> = matched.iter().flat_map(|(_, caps)| caps.iter().filter(|(n, _)| *n == c).map(|(_, v)| v.clone())).collect();
                (c, vals.into_iter().collect())
            })
            .collect()
    };
    let Some(c) = ctx else {
        // No domain: check the template against declarations only.
        let mut tcx = Tcx {
            decls,
            ctx: None,
            vars: rule_vars(r, None),
            captures: captures_of(&[]),
            in_plan: false,
            diags: Vec::new(),
        };
        if let RuleBody::Template { body, .. } = &r.body {
            for t in body {
                tcx.template(t);
            }
        }
        diags.extend(tcx.diags);
        return diags;
    };
    let matched = rule_actions(r, decls, c.domain);
    if matched.is_empty() {
        let written = r.pattern.name_text();
        let candidate = closest(
            &written.to_lowercase(),
            c.domain.actions.iter().map(|a| a.name.as_str()),
        )
        .map(str::to_owned);
        push(
            Diagnostic::error(
                codes::R_UNKNOWN_ACTION,
                r.pattern.name_span(),
                format!("the domain has no action `{written}`"),
            )
            .suggest(candidate, || {
                let names: Vec<&str> = c.domain.actions.iter().map(|a| a.name.as_str()).collect();
                format!("the domain's actions are {}", names.join(", "))
            }),
            &mut diags,
        );
        return diags;
    }
    let captures = captures_of(&matched);
    for (action, _) in &matched {
        if bind_params(&r.pattern, action.params.len()).is_none() {
            let required = r.pattern.params.iter().filter(|p| !p.optional).count();
            let total = r.pattern.params.len();
            let takes = if required == total {
                format!("{total}")
            } else {
                format!("{required} to {total}")
            };
            let params: Vec<String> = action
                .params
                .iter()
                .map(|p| format!("?{}", p.name.name))
                .collect();
            push(
                Diagnostic::error(
                    codes::R_PARAM_COUNT,
                    r.pattern.span,
                    format!(
                        "`{}` has {} parameters, but this pattern takes {takes}",
                        action.name.name,
                        action.params.len()
                    ),
                )
                .with_label(action.name.span, "the action is declared here")
                .with_hint(format!(
                    "write `({} {})`",
                    action.name.name,
                    params.join(" ")
                )),
                &mut diags,
            );
            continue;
        }
        let vars = rule_vars(r, Some((action, &c)));
        let mut tcx = Tcx {
            decls,
            ctx: Some(c),
            vars: vars.clone(),
            captures: captures.clone(),
            in_plan: false,
            diags: Vec::new(),
        };
        if let RuleBody::Template { body, effect } = &r.body {
            for t in body {
                tcx.template(t);
            }
            if let Some(e) = effect {
                let scope = scope_of(&vars);
                tcx.diags
                    .extend(check_effect_in(c.domain, c.index, c.problem, e, &scope));
                if let Some(d) = compare_effect(r, action, e) {
                    tcx.diags.push(d);
                }
            }
        }
        for d in tcx.diags {
            push(d, &mut diags);
        }
    }
    diags
}

/// Literals of a plain effect (`and` of atoms and `not` atoms), with
/// variables replaced by their parameter positions. `None` when the effect
/// has quantified, conditional or numeric parts.
fn literals(
    effects: &[&Effect],
    position: &dyn Fn(&str) -> Option<usize>,
) -> Option<BTreeSet<(bool, String, Vec<String>)>> {
    let mut out = BTreeSet::new();
    let mut stack: Vec<&Effect> = effects.to_vec();
    while let Some(e) = stack.pop() {
        let (positive, atom) = match e {
            Effect::Add { atom } => (true, atom),
            Effect::Delete { atom, .. } => (false, atom),
            Effect::And { parts, .. } => {
                stack.extend(parts.iter());
                continue;
            }
            _ => return None,
        };
        let args = atom
            .args
            .iter()
            .map(|t| match t {
                btc_pddl::ast::Term::Var { name } => {
                    position(&name.name).map_or(format!("?{}", name.name), |i| format!("#{i}"))
                }
                btc_pddl::ast::Term::Const { name } => name.name.clone(),
            })
            .collect();
        out.insert((positive, atom.pred.name.clone(), args));
    }
    Some(out)
}

/// A warning when a rule's effect is not the PDDL action's effect, with the
/// PDDL effect written in the rule's variables as the hint (the quick fix).
fn compare_effect(r: &Rule, action: &btc_pddl::ast::Action, effect: &Effect) -> Option<Diagnostic> {
    let rule_pos = |v: &str| r.pattern.params.iter().position(|p| p.var.text == v);
    let action_pos = |v: &str| action.params.iter().position(|p| p.name.name == v);
    let pddl: Vec<&Effect> = action.eff_start.iter().chain(&action.eff_end).collect();
    let mine = literals(&[effect], &rule_pos)?;
    let theirs = literals(&pddl, &action_pos)?;
    if mine == theirs {
        return None;
    }
    let show = |l: &(bool, String, Vec<String>)| show_literal(l, r);
    let missing: Vec<String> = theirs.difference(&mine).map(show).collect();
    let extra: Vec<String> = mine.difference(&theirs).map(show).collect();
    let mut parts = Vec::new();
    if !missing.is_empty() {
        parts.push(format!("it leaves out {}", missing.join(", ")));
    }
    if !extra.is_empty() {
        parts.push(format!("it adds {}", extra.join(", ")));
    }
    let rewritten = rewrite_effect(&pddl, action, r);
    Some(
        Diagnostic::warning(
            codes::R_EFFECT_DIFFERS,
            effect.span(),
            format!(
                "this effect differs from the effect of the PDDL action `{}`: {}",
                action.name.name,
                parts.join("; ")
            ),
        )
        .with_label(action.name.span, "the PDDL action")
        .with_hint(format!(
            "the PDDL effect in this rule's variables: `effect {rewritten}`"
        ))
        .with_fix("write the PDDL action's effect", effect.span(), rewritten),
    )
}

/// A literal in the rule's own variables (`#i` is parameter i).
fn show_literal((positive, pred, args): &(bool, String, Vec<String>), r: &Rule) -> String {
    let arg = |a: &String| match a.strip_prefix('#').and_then(|i| i.parse::<usize>().ok()) {
        Some(i) => r.pattern.params.get(i).map_or_else(
            || format!("parameter {}", i + 1),
            |p| format!("?{}", p.var.text),
        ),
        None => a.clone(),
    };
    let atom = format!(
        "({pred}{})",
        args.iter()
            .map(|a| format!(" {}", arg(a)))
            .collect::<String>()
    );
    if *positive {
        format!("`{atom}`")
    } else {
        format!("`(not {atom})`")
    }
}

/// The PDDL action's effect with its parameters renamed to the rule's variables.
pub fn rewrite_effect(effects: &[&Effect], action: &btc_pddl::ast::Action, r: &Rule) -> String {
    let text = match effects {
        [one] => one.to_string(),
        many => format!(
            "(and {})",
            many.iter()
                .map(|e| e.to_string())
                .collect::<Vec<_>>()
                .join(" ")
        ),
    };
    // Rename through placeholders so `?a`->`?b`, `?b`->`?a` swaps work.
    let mut out = text;
    let mut renames = Vec::new();
    for (i, p) in action.params.iter().enumerate() {
        if let Some(rp) = r.pattern.params.get(i) {
            renames.push((
                format!("?{}", p.name.name),
                format!("\u{0}{i}\u{0}"),
                format!("?{}", rp.var.text),
            ));
        }
    }
    for (from, mid, _) in &renames {
        out = replace_var(&out, from, mid);
    }
    for (_, mid, to) in &renames {
        out = out.replace(mid.as_str(), to);
    }
    out
}

fn replace_var(text: &str, var: &str, with: &str) -> String {
    let mut out = String::new();
    let mut rest = text;
    while let Some(i) = rest.find(var) {
        let after = rest[i + var.len()..].chars().next();
        let whole = !after.is_some_and(|c| c.is_alphanumeric() || c == '_' || c == '-');
        out.push_str(&rest[..i]);
        out.push_str(if whole { with } else { var });
        rest = &rest[i + var.len()..];
    }
    out.push_str(rest);
    out
}

/// File-level checks; spans absolute. `items` are this file's items.
pub fn check_file(
    items: &[ItemNode],
    decls: &Decls,
    ctx: Option<DomainCtx>,
    file: FileId,
) -> Vec<Diagnostic> {
    let abs = |s: Span, off: u32| Span {
        start: s.start + off,
        end: s.end + off,
        file,
    };
    let mut diags = Vec::new();
    // `domain` and `plan` items.
    let domains: Vec<&ItemNode> = items
        .iter()
        .filter(|i| matches!(i.item, Item::Domain { .. }))
        .collect();
    if domains.is_empty() {
        diags.push(
            Diagnostic::error(
                codes::R_NO_DOMAIN,
                Span::new(file, 0, 0),
                "this rules file does not say which PDDL domain it is for",
            )
            .with_hint("add `domain \"domain.pddl\"` (a path relative to this file)"),
        );
    }
    for extra in domains.iter().skip(1) {
        diags.push(Diagnostic::error(
            codes::R_DUPLICATE,
            abs(extra.item.span(), extra.offset),
            "a rules file names one domain; this is a second `domain`",
        ));
    }
    for extra in items
        .iter()
        .filter(|i| matches!(i.item, Item::Plan { .. }))
        .skip(1)
    {
        diags.push(Diagnostic::error(
            codes::R_PLAN_BLOCK,
            abs(extra.item.span(), extra.offset),
            "a rules file has one `plan` block; this is a second one",
        ));
    }
    // Duplicate declarations in this file.
    let mut seen: BTreeMap<String, Span> = BTreeMap::new();
    for i in items {
        let name = match &i.item {
            Item::Node(n) => &n.name,
            Item::Tree(t) => &t.name,
            Item::Table(t) => &t.name,
            _ => continue,
        };
        let span = abs(name.span, i.offset);
        if let Some(first) = seen.get(&name.text) {
            diags.push(
                Diagnostic::error(
                    codes::R_DUPLICATE,
                    span,
                    format!("`{}` is declared twice", name.text),
                )
                .with_label(*first, "first declared here")
                .with_hint("nodes, trees and tables share one namespace; rename one of them"),
            );
        } else {
            seen.insert(name.text.clone(), span);
        }
    }
    let rules: Vec<(&Rule, u32)> = items
        .iter()
        .filter_map(|i| match &i.item {
            Item::Rule(r) => Some((r, i.offset)),
            _ => None,
        })
        .collect();
    // Coverage and shadowing need the domain.
    if let Some(c) = ctx {
        if !rules.is_empty() {
            // A misspelled rule is reported (R002) with the action it likely
            // meant; that action is not reported again as uncovered.
            let action_names: Vec<&str> =
                c.domain.actions.iter().map(|a| a.name.as_str()).collect();
            let meant: BTreeSet<&str> = rules
                .iter()
                .filter(|(r, _)| matched_actions(&r.pattern, c.domain).is_empty())
                .filter_map(|(r, _)| {
                    closest(
                        &r.pattern.name_text().to_lowercase(),
                        action_names.iter().copied(),
                    )
                })
                .collect();
            for a in c
                .domain
                .actions
                .iter()
                .filter(|a| !meant.contains(a.name.as_str()))
            {
                if !rules
                    .iter()
                    .any(|(r, _)| match_name(&r.pattern.name, &a.name.name).is_some())
                {
                    let params: Vec<String> = a
                        .params
                        .iter()
                        .map(|p| format!("?{}", p.name.name))
                        .collect();
                    diags.push(
                        Diagnostic::warning(
                            codes::R_UNCOVERED,
                            a.name.span,
                            format!("no rule covers the action `{}`", a.name.name),
                        )
                        .with_hint(format!(
                            "add `rule ({} {}) {{ ... }}`, or `=> skip` to drop its steps",
                            a.name.name,
                            params.join(" ")
                        )),
                    );
                }
            }
        }
        // Only a rule without guards or repeated variables can shadow.
        let shadowers: Vec<usize> = (0..rules.len())
            .filter(|&i| can_shadow(rules[i].0))
            .collect();
        for (j, (later, loff)) in rules.iter().enumerate() {
            if let Some((earlier, eoff)) = shadowers
                .iter()
                .take_while(|&&i| i < j)
                .map(|&i| &rules[i])
                .find(|(e, _)| shadows(e, later, c.domain))
            {
                diags.push(
                    Diagnostic::warning(codes::R_SHADOWED, abs(later.pattern.span, *loff), "this rule never applies: an earlier rule matches every step it matches")
                        .with_label(abs(earlier.pattern.span, *eoff), "the earlier rule")
                        .with_hint("the first rule that matches a step wins; move this rule up, or add a guard to the earlier one"),
                );
            }
        }
    }
    // Declarations of this file that nothing refers to (unknowable when an
    // item did not parse).
    let used = references(items);
    let broken = items.iter().any(|i| has_error_node(&i.item));
    for i in items.iter().filter(|_| !broken) {
        let (kind, name) = match &i.item {
            Item::Node(n) => ("node", &n.name),
            Item::Tree(t) => ("tree", &t.name),
            Item::Table(t) => ("table", &t.name),
            _ => continue,
        };
        if !used.contains(&name.text) {
            diags.push(
                Diagnostic::warning(
                    codes::R_UNUSED,
                    abs(name.span, i.offset),
                    format!("{kind} `{}` is declared but never used", name.text),
                )
                .with_hint("remove it, or use it in a rule"),
            );
        }
    }
    let _ = decls;
    diags
}

/// Whether `earlier` matches every step `later` matches: same or wider name
/// set over the domain's actions, no guards, no repeated variables, and
/// every argument count `later` accepts.
/// Whether a rule matches every step its pattern names: no guards and no
/// repeated variables.
fn can_shadow(r: &Rule) -> bool {
    let mut vars = BTreeSet::new();
    r.guards.is_empty() && r.pattern.params.iter().all(|p| vars.insert(&p.var.text))
}

fn shadows(earlier: &Rule, later: &Rule, domain: &Domain) -> bool {
    if !earlier.guards.is_empty() {
        return false;
    }
    let mut vars = BTreeSet::new();
    if !earlier
        .pattern
        .params
        .iter()
        .all(|p| vars.insert(&p.var.text))
    {
        return false;
    }
    let later_actions = matched_actions(&later.pattern, domain);
    if later_actions.is_empty() {
        return false;
    }
    later_actions.iter().all(|(a, _)| {
        match_name(&earlier.pattern.name, &a.name.name).is_some()
            && (0..=later.pattern.params.len())
                .filter(|&n| bind_params(&later.pattern, n).is_some())
                .all(|n| bind_params(&earlier.pattern, n).is_some())
    })
}

/// Whether an item, or a template inside it, did not parse.
fn has_error_node(item: &Item) -> bool {
    fn t(x: &Template) -> bool {
        match x {
            Template::Error { .. } => true,
            Template::Control { children, .. } => children.iter().any(t),
            Template::Decorator { child, .. } => t(child),
            _ => false,
        }
    }
    match item {
        Item::Error { .. } => true,
        Item::Rule(Rule {
            body: RuleBody::Template { body, .. },
            ..
        }) => body.iter().any(t),
        Item::Tree(tr) => tr.body.iter().any(t),
        Item::Plan { body, .. } => body.iter().any(t),
        _ => false,
    }
}

/// Names of nodes, trees and tables that templates, guards and lookups use.
pub fn references(items: &[ItemNode]) -> BTreeSet<String> {
    fn value(v: &Value, out: &mut BTreeSet<String>) {
        if let Value::Lookup { table, key, .. } = v {
            out.insert(table.text.clone());
            value(key, out);
        }
    }
    fn template(t: &Template, out: &mut BTreeSet<String>) {
        match t {
            Template::Control { children, .. } => children.iter().for_each(|c| template(c, out)),
            Template::Decorator { child, .. } => template(child, out),
            Template::Call { name, args, .. } => {
                out.insert(name.text.clone());
                for a in args {
                    value(&a.value, out);
                }
            }
            _ => {}
        }
    }
    let mut out = BTreeSet::new();
    for i in items {
        match &i.item {
            Item::Rule(r) => {
                for g in &r.guards {
                    if let Guard::InTable { table, .. } = g {
                        out.insert(table.text.clone());
                    }
                }
                if let RuleBody::Template { body, .. } = &r.body {
                    body.iter().for_each(|t| template(t, &mut out));
                }
            }
            Item::Tree(t) => t.body.iter().for_each(|b| template(b, &mut out)),
            Item::Plan { body, .. } => body.iter().for_each(|b| template(b, &mut out)),
            _ => {}
        }
    }
    out
}

/// The formula a condition node is defined by, if any (for the runtime).
pub fn condition_formula<'a>(decls: &'a Decls, name: &str) -> Option<&'a Formula> {
    decls.nodes.get(name).and_then(|n| n.formula.as_ref())
}
