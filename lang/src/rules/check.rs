//! Checks of `.btrules` items against their declarations and the PDDL
//! domain. [`check_item`] looks at one item (spans relative to it: the
//! incremental database calls it per item); what needs the whole file
//! (duplicates, coverage, shadowing, unused names) is in `file_checks`.

use super::actions::ActionIndex;
use super::ast::*;
use super::matching::Captures;
use super::name::{capture_value, Key};
use super::reach::{reach, Never, Verdict};
use btc_ir::NodeScripts;
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
            match &*i.item {
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
    /// The domain's action names, indexed for patterns.
    pub actions: &'a ActionIndex,
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
    /// Tree ports of basic types (`int`, `string`, ...), as variables.
    basic: Vec<(String, VType)>,
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
                args,
                name,
                child,
                span,
            } => {
                if let Some(n) = name {
                    self.string(n);
                }
                self.decorator_args(*decorator, args, *span);
                self.template(child);
            }
            Template::Call {
                name,
                args,
                scripts,
                span,
            } => {
                self.call(name, args, *span);
                self.script_attrs(scripts);
            }
            Template::Script { code, .. } => self.script_text(code),
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

    /// A call's `[key: "script", ...]`: BT.CPP's attributes, each once.
    fn script_attrs(&mut self, scripts: &[ScriptAttr]) {
        let mut seen: Vec<&str> = Vec::new();
        for a in scripts {
            let key = a.key.text.as_str();
            if NodeScripts::key_index(key).is_none() {
                let mut d = Diagnostic::error(
                    codes::R_SCRIPT_KEY,
                    a.key.span,
                    format!("`{key}` is not a pre- or post-condition BT.CPP runs around a node"),
                );
                d = match closest(key, NodeScripts::KEYS.iter().copied()) {
                    Some(c) => d.with_hint(format!("did you mean `{c}`?")),
                    None => d.with_hint(format!(
                        "a node takes {}",
                        NodeScripts::KEYS.map(|k| format!("`{k}`")).join(", ")
                    )),
                };
                self.err(d);
            } else if seen.contains(&key) {
                self.err(
                    Diagnostic::error(
                        codes::R_SCRIPT_TWICE,
                        a.key.span,
                        format!("this node gives `{key}` twice"),
                    )
                    .with_hint("join the two scripts with `;` in one string"),
                );
            }
            seen.push(key);
            self.script_text(&a.code);
        }
    }

    /// A script is BT.CPP code, passed through as written: `{...}` in it
    /// would be a btc interpolation BT.CPP never sees. Its syntax is
    /// checked here, so that a script BT.CPP (and `btc run`) would refuse
    /// when it loads the tree is shown at the token in the string.
    fn script_text(&mut self, code: &StrLit) {
        if let Some(text) = code.plain() {
            if let Err(e) = btc_script::parse(&text) {
                self.err(script_syntax(code, &text, &e));
            }
        } else {
            self.err(
                Diagnostic::error(
                    codes::R_SCRIPT_TEXT,
                    code.span,
                    "a script cannot interpolate `{...}`: it is BT.CPP code, run as written",
                )
                .with_hint(
                    "read values from blackboard entries in the script, or write `\\{` for a brace",
                ),
            );
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

    /// A decorator's arguments against its parameter: one value (by
    /// position or by the parameter's name) that is a whole number in the
    /// parameter's range, or none for decorators without a parameter.
    fn decorator_args(&mut self, d: DecoratorName, args: &[DecoratorArg], span: Span) {
        let word = d.keyword();
        let Some(param) = d.param() else {
            if let Some(a) = args.first() {
                self.value(&a.value);
                self.err(
                    Diagnostic::error(
                        codes::R_BAD_ARGUMENT,
                        a.span,
                        format!("`{word}` takes no argument"),
                    )
                    .with_hint(format!("write `{word}` and then the node it decorates")),
                );
            }
            return;
        };
        let Some(arg) = args.first() else {
            self.err(
                Diagnostic::error(
                    codes::R_BAD_ARGUMENT,
                    span,
                    format!("`{word}` needs its number of {}", param.what),
                )
                .with_hint(format!(
                    "write `{word}(3) ...` or `{word}({}: ...) ...`",
                    param.name
                )),
            );
            return;
        };
        for extra in &args[1..] {
            self.value(&extra.value);
            self.err(Diagnostic::error(
                codes::R_BAD_ARGUMENT,
                extra.span,
                format!("`{word}` takes one argument, its `{}`", param.name),
            ));
        }
        if let Some(p) = arg.param.as_ref().filter(|p| p.text != param.name) {
            self.err(
                Diagnostic::error(
                    codes::R_BAD_ARGUMENT,
                    p.span,
                    format!(
                        "`{word}` has no parameter `{}`; its parameter is `{}`",
                        p.text, param.name
                    ),
                )
                .with_fix(
                    format!("change to `{}`", param.name),
                    p.span,
                    param.name,
                ),
            );
        }
        let vt = self.value(&arg.value);
        let range = |n: i64| n >= param.min && n <= param.max;
        let out_of_range = |n: i64| {
            Diagnostic::error(
                codes::R_BAD_ARGUMENT,
                arg.value.span(),
                if n < param.min {
                    format!(
                        "`{word}({n})` never runs its child: it needs at least {} {}",
                        param.min, param.what
                    )
                } else {
                    format!("`{word}` takes at most {} {}", param.max, param.what)
                },
            )
        };
        match (&arg.value, vt) {
            (Value::Int { value, .. }, _) if !range(*value) => self.err(out_of_range(*value)),
            (_, VType::Int | VType::Unknown) => {}
            // A capture of digits (`wait_{ms}` matching `wait_30`) is a number.
            (Value::Name { name }, _)
                if self
                    .capture_values(name)
                    .is_some_and(|vs| vs.iter().all(|v| v.parse::<i64>().is_ok_and(range))) => {}
            (value, vt) => {
                let what = describe_vtype(&vt, self.ctx);
                self.err(
                    Diagnostic::error(
                        codes::R_PORT_TYPE,
                        value.span(),
                        format!(
                            "`{word}`'s `{}` takes a whole number of {}, but this is {what}",
                            param.name, param.what
                        ),
                    )
                    .with_hint("a number, a table lookup with numbers, a capture of digits, or an `int` port of a tree"),
                );
            }
        }
        // The table values a lookup can give must be in range too.
        if let Value::Lookup { table, key, .. } = &arg.value {
            let keys: Option<Vec<Key>> = match &**key {
                Value::Name { name } => self
                    .capture_values(name)
                    .map(|vs| vs.iter().map(|v| Key::new(v)).collect()),
                Value::Str { value } => value.plain().map(|k| vec![Key::new(&k)]),
                _ => None,
            };
            let bad: Vec<String> = self
                .decls
                .tables
                .get(&table.text)
                .map(|t| {
                    t.entries
                        .iter()
                        .filter(|e| keys.as_ref().is_none_or(|ks| ks.contains(&e.key.key)))
                        .filter_map(|e| match &e.value {
                            Literal::Int { value, .. } if !range(*value) => {
                                Some(format!("{value} for `{}`", e.key.text))
                            }
                            _ => None,
                        })
                        .collect()
                })
                .unwrap_or_default();
            if !bad.is_empty() {
                self.err(Diagnostic::error(
                    codes::R_BAD_ARGUMENT,
                    arg.value.span(),
                    format!(
                        "table `{}` can give `{word}` {}, outside its range {} to {}",
                        table.text,
                        bad.join(", "),
                        param.min,
                        param.max
                    ),
                ));
            }
        }
    }

    /// The values a capture takes over the domain's actions (`None` when it
    /// is not a capture of this rule).
    fn capture_values(&self, name: &Ident) -> Option<&[String]> {
        self.captures
            .iter()
            .find(|(c, _)| *c == name.text)
            .map(|(_, v)| v.as_slice())
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
                // Checked where the call that spliced it in wrote it.
                StrPart::Text { .. } | StrPart::Value { .. } => {}
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
            Value::Var { name } => {
                let objects = self.var(name);
                match self.basic.iter().find(|(v, _)| *v == name.text) {
                    Some((_, t)) => t.clone(),
                    None => objects.map_or(VType::Unknown, VType::Objects),
                }
            }
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

    /// R024: with the problem known, the objects a `?variable` key can
    /// stand for (by its type) that the table has no key for; the compile
    /// of a plan that reaches one of them fails, or leaves the port empty.
    fn objects_without_key(&mut self, t: &TableDecl, var: &Ident, span: Span) {
        let Some(c) = self.ctx else { return };
        let Some(problem) = c.problem else { return };
        let Some(Some(types)) = self
            .vars
            .iter()
            .find(|(v, _)| *v == var.text)
            .map(|(_, t)| t.clone())
        else {
            return;
        };
        let missing: Vec<&str> = problem
            .objects_of(&c.index.types, &types)
            .into_iter()
            .map(|i| problem.object_names[i as usize].as_str())
            .filter(|o| !t.entries.iter().any(|e| e.key.key == Key::new(o)))
            .collect();
        let Some(first) = missing.first() else { return };
        let shown: Vec<String> = missing.iter().take(5).map(|o| format!("`{o}`")).collect();
        let more = match missing.len() {
            n if n > 5 => format!(" and {} more", n - 5),
            _ => String::new(),
        };
        self.err(
            Diagnostic::warning(
                codes::R_LOOKUP_OBJECT,
                span,
                format!(
                    "table `{}` has no key for {}{more}, which `?{}` can stand for in the problem",
                    t.name.text,
                    shown.join(", "),
                    var.text
                ),
            )
            .with_hint(format!(
                "add `{first}: ...` to table `{}`; a step with such an object gets no value",
                t.name.text
            )),
        );
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
        let has = |k: &str| t.entries.iter().any(|e| e.key.key == Key::new(k));
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
                                format!("table `{}` has no key `{}` (the capture `{}` takes it for a domain action)", table.text, capture_value(val), name.text),
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
            Value::Var { name } => {
                self.value(key);
                self.objects_without_key(&t, name, span);
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
        let pddl_ty = port.ty.key.as_str();
        let ok = match (ty, &vt) {
            (_, VType::Unknown) => true,
            ("string", _) => true,
            ("int", VType::Int) | ("float", VType::Int | VType::Float) | ("bool", VType::Bool) => {
                true
            }
            ("int" | "float" | "bool", _) => false,
            (_, VType::Objects(have)) => match self
                .ctx
                .and_then(|c| c.index.types.id(pddl_ty).map(|w| (c, w)))
            {
                Some((c, want)) => c.index.types.fits(have, &[want]),
                None => true, // unknown port type: reported at the declaration
            },
            (_, VType::Name(obj)) => {
                let Some(c) = self.ctx else { return };
                let obj_l = Key::new(obj);
                let info = c
                    .problem
                    .and_then(|p| p.objects.get(obj_l.as_str()))
                    .or_else(|| c.index.constants.get(obj_l.as_str()));
                match info {
                    Some(o) => match c.index.types.id(pddl_ty) {
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
                        let candidate = closest(obj_l.as_str(), known.iter().copied());
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
                        "port `{}` takes a `{}`, but this is {}",
                        port.name.text,
                        port.ty.text,
                        describe_vtype(&vt, self.ctx)
                    ),
                )
                .with_label(port.span, "the port is declared here"),
            );
        }
    }
}

fn describe_vtype(vt: &VType, ctx: Option<DomainCtx>) -> String {
    match vt {
        VType::Objects(t) => match ctx {
            Some(c) => format!("an object of type `{}`", c.index.types.display(t)),
            None => "an object".to_owned(),
        },
        VType::Name(_) | VType::Str => "a string".to_owned(),
        VType::Int => "an int".to_owned(),
        VType::Float => "a float".to_owned(),
        VType::Bool => "a bool".to_owned(),
        VType::Unknown => "a value".to_owned(),
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

/// The domain actions a rule pattern's name matches, with their captures
/// (in domain order).
pub fn matched_actions<'d>(
    pattern: &Pattern,
    domain: &'d Domain,
    actions: &ActionIndex,
) -> Vec<(&'d btc_pddl::ast::Action, Captures)> {
    actions
        .matches(&pattern.name, domain)
        .into_iter()
        .map(|(i, c)| (&domain.actions[i], c))
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

/// R123 for a plain script literal `code` (whose text is `text`) that does
/// not parse: the span is the bad token's in the file, through the
/// literal's escapes; at the end of the script, the closing quote.
fn script_syntax(code: &StrLit, text: &str, e: &btc_script::SyntaxError) -> Diagnostic {
    let span = if e.problem == btc_script::Problem::Empty {
        code.span
    } else if e.span.is_empty() {
        let at = code.source_offset(text.len());
        Span::new(code.span.file, at, at + 1)
    } else {
        Span::new(
            code.span.file,
            code.source_offset(e.span.start),
            code.source_offset(e.span.end),
        )
    };
    Diagnostic::error(
        codes::R_SCRIPT_SYNTAX,
        span,
        format!("this script does not parse: {}", e.describe()),
    )
    .with_hint(
        "the script is BT.CPP's scripting language, described in docs/runtime.md (*Scripts*)",
    )
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
                basic: basic_ports(&t.ports),
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
                basic: Vec::new(),
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
                if !seen.insert(&e.key.key) {
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
                .and_then(|c| c.index.types.id(p.ty.key.as_str()))
                .map(|t| vec![t]);
            (p.name.key.clone().into_string(), ty)
        })
        .collect()
}

/// Tree ports of basic types, as the variables the tree's body uses.
fn basic_ports(ports: &[PortDecl]) -> Vec<(String, VType)> {
    ports
        .iter()
        .filter_map(|p| {
            let t = match p.ty.key.as_str() {
                "int" => VType::Int,
                "float" => VType::Float,
                "bool" => VType::Bool,
                "string" => VType::Str,
                _ => return None,
            };
            Some((p.name.key.clone().into_string(), t))
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
            if c.index.types.id(p.ty.key.as_str()).is_none() {
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

/// The actions a rule's template is typed by, from what the rule can reach
/// through its tables: those a step can come from, or, for a rule that can
/// match nothing, those it names.
fn typing_actions<'d>(
    through_tables: &[&(&'d btc_pddl::ast::Action, usize, Captures, Verdict)],
) -> Vec<&'d btc_pddl::ast::Action> {
    let can: Vec<&'d btc_pddl::ast::Action> = through_tables
        .iter()
        .filter(|(_, _, _, v)| *v == Verdict::Can)
        .map(|(a, _, _, _)| *a)
        .collect();
    if !can.is_empty() {
        return can;
    }
    through_tables
        .iter()
        .filter(|(_, _, _, v)| matches!(v, Verdict::Never(_)))
        .map(|(a, _, _, _)| *a)
        .collect()
}

/// What a rule's `?variable`s are, as the checker types them: for each
/// pattern variable in order, the types (as the domain writes them) of the
/// parameter it stands for in every action the template is checked
/// against. Empty lists without a domain or a matching action.
pub fn rule_var_types(r: &Rule, decls: &Decls, ctx: Option<DomainCtx>) -> Vec<VarTypes> {
    let mut out: Vec<VarTypes> = Vec::new();
    for p in &r.pattern.params {
        if !out.iter().any(|v| v.name == p.var.text) {
            out.push(VarTypes {
                name: p.var.text.clone(),
                types: Vec::new(),
            });
        }
    }
    let Some(c) = ctx else { return out };
    let reach = reach(r, decls, c);
    let through_tables = reach.meant();
    for action in typing_actions(&through_tables) {
        for v in &mut out {
            // The parameter at the variable's first position.
            let Some(pos) = r.pattern.params.iter().position(|p| p.var.text == v.name) else {
                continue;
            };
            if let Some(ap) = action.params.get(pos) {
                let t = ap.ty.to_string();
                if !v.types.contains(&t) {
                    v.types.push(t);
                }
            }
        }
    }
    out
}

/// One of a rule's variables and the types the checker gives it.
#[derive(Clone, Debug, PartialEq, Eq, Hash)]
pub struct VarTypes {
    pub name: String,
    pub types: Vec<String>,
}

fn check_rule(r: &Rule, decls: &Decls, ctx: Option<DomainCtx>) -> Vec<Diagnostic> {
    let mut diags: Vec<Diagnostic> = Vec::new();
    let push = |d: Diagnostic, diags: &mut Vec<Diagnostic>| {
        if !diags.contains(&d) {
            diags.push(d);
        }
    };
    check_guards(r, decls, ctx, &mut |d| push(d, &mut diags));
    let captures_of = |matched: &[&Captures]| -> Vec<(String, Vec<String>)> {
        r.pattern
            .name
            .iter()
            .filter_map(|p| match p {
                NamePart::Capture { name } => Some(name.text.clone()),
                NamePart::Lit { .. } => None,
            })
            .map(|c| {
                let vals: BTreeSet<String> = matched
                    .iter()
                    .flat_map(|caps| caps.iter().filter(|(n, _)| *n == c).map(|(_, v)| v.clone()))
                    .collect();
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
            basic: Vec::new(),
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
    if r.pattern.name.is_empty() {
        return diags; // a pattern that did not parse: reported
    }
    let reach = reach(r, decls, c);
    let through_tables = reach.meant();
    if through_tables.is_empty() {
        let written = r.pattern.name_text();
        let candidate = closest(
            r.pattern.name_key().as_str(),
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
    let captures = captures_of(
        &through_tables
            .iter()
            .map(|(_, _, caps, _)| caps)
            .collect::<Vec<_>>(),
    );
    for (action, _, _, verdict) in &through_tables {
        if *verdict == Verdict::Arity {
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
        }
    }
    if let Some(never) = reach.never() {
        push(never_diagnostic(r, never, &through_tables), &mut diags);
    }
    // The template is checked once per action a step can come from (its
    // variables are typed by that action's parameters); a rule that can
    // match nothing is still checked, with the actions it names.
    let none_can = !through_tables.iter().any(|(_, _, _, v)| *v == Verdict::Can);
    for action in typing_actions(&through_tables) {
        let vars = rule_vars(r, Some((action, &c)));
        let mut tcx = Tcx {
            decls,
            ctx: Some(c),
            vars: vars.clone(),
            captures: captures.clone(),
            basic: Vec::new(),
            in_plan: false,
            diags: Vec::new(),
        };
        match &r.body {
            RuleBody::Template { body, effect } => {
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
            // A rule no step can match skips nothing (R040-R043 say so).
            RuleBody::Skip { .. } if none_can => {}
            RuleBody::Skip { span } => {
                let changed = super::skip::changes(r, action);
                if !changed.is_empty() {
                    tcx.diags.push(
                        Diagnostic::warning(
                            codes::R_SKIP_CHANGES,
                            *span,
                            format!(
                                "`=> skip` drops steps of `{}`, which change the world: {}",
                                action.name.name,
                                changed
                                    .iter()
                                    .map(|l| format!("`{l}`"))
                                    .collect::<Vec<_>>()
                                    .join(", ")
                            ),
                        )
                        .with_label(action.name.span, "the PDDL action")
                        .with_hint("skip only steps that change nothing, such as a move to where the robot is (`(move ?r ?x ?x)`); give the rule a template to run the step"),
                    );
                }
            }
        }
        for d in tcx.diags {
            push(d, &mut diags);
        }
    }
    diags
}

/// Guards refer to the pattern's variables and captures, to the domain's
/// types, to declared tables, and to objects of the domain or problem.
fn check_guards(r: &Rule, decls: &Decls, ctx: Option<DomainCtx>, push: &mut dyn FnMut(Diagnostic)) {
    for g in &r.guards {
        let vars: Vec<&Ident> = match g {
            Guard::Ne { left, right, .. } | Guard::Eq { left, right, .. } => {
                [left, right].into_iter().filter_map(Operand::var).collect()
            }
            Guard::IsType { var, .. } => vec![var],
            Guard::InTable { .. } => vec![],
        };
        for v in vars {
            if !r.pattern.params.iter().any(|p| p.var.text == v.text) {
                push(Diagnostic::error(
                    codes::R_UNBOUND,
                    v.span,
                    format!("`?{}` is not a parameter of this rule's pattern", v.text),
                ));
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
                    push(Diagnostic::error(
                        codes::R_UNBOUND,
                        key.span,
                        format!("`{}` is not a capture of this rule's pattern", key.text),
                    ));
                }
                if !decls.tables.contains_key(&table.text) {
                    push(Diagnostic::error(
                        codes::R_UNKNOWN_TABLE,
                        table.span,
                        format!("no table is called `{}`", table.text),
                    ));
                }
            }
            Guard::IsType { ty, .. } => {
                if let Some(c) = ctx {
                    if c.index.types.id(ty.key.as_str()).is_none() {
                        let d = Diagnostic::error(
                            codes::R_UNKNOWN_TYPE,
                            ty.span,
                            format!("`{}` is not a type of the domain", ty.text),
                        );
                        push(match closest(ty.key.as_str(), c.index.types.names()) {
                            Some(t) => d.suggest(Some(t.to_owned()), String::new),
                            None => d,
                        });
                    }
                }
            }
            Guard::Ne { left, right, .. } | Guard::Eq { left, right, .. } => {
                let Some(c) = ctx else { continue };
                for o in [left, right] {
                    if let Operand::Object { name } = o {
                        if let Some(d) = unknown_object(name, c) {
                            push(d);
                        }
                    }
                }
            }
        }
    }
}

/// R020 for an object name that neither the domain's constants nor the
/// problem (when there is one) has.
fn unknown_object(name: &Ident, c: DomainCtx) -> Option<Diagnostic> {
    let k = name.key.as_str();
    if c.index.constants.contains_key(k) {
        return None;
    }
    let p = c.problem?; // without a problem, objects are unknown here
    if p.objects.contains_key(k) {
        return None;
    }
    let known = p
        .object_names
        .iter()
        .chain(&c.index.constant_names)
        .map(String::as_str);
    let candidate = closest(k, known);
    let d = Diagnostic::error(
        codes::R_UNKNOWN_OBJECT,
        name.span,
        format!(
            "`{}` is not among the problem's objects or the domain's constants",
            name.text
        ),
    );
    Some(match candidate {
        Some(cand) => d.with_hint(format!("did you mean `{cand}`?")).with_fix(
            format!("change to `{cand}`"),
            name.span,
            format!("{cand:?}"),
        ),
        None => d.with_hint("it names no object of the problem and no constant of the domain"),
    })
}

/// The warning for a rule that no step can match, from the reason found
/// for the first action it names.
fn never_diagnostic(
    r: &Rule,
    never: &Never,
    named: &[&(&btc_pddl::ast::Action, usize, Captures, Verdict)],
) -> Diagnostic {
    let action = named
        .iter()
        .find(|(_, _, _, v)| matches!(v, Verdict::Never(n) if n == never))
        .map(|(a, _, _, _)| a.name.name.as_str())
        .unwrap_or_default();
    let others = named.len().saturating_sub(1);
    let also = if others == 0 {
        String::new()
    } else {
        format!(
            " (and no step of the {others} other action{} its pattern names can match)",
            if others == 1 { "" } else { "s" }
        )
    };
    let hint = "a rule no step can match runs nothing; fix or remove the guard, or remove the rule";
    match never {
        Never::SameObject { guard } => Diagnostic::warning(
            codes::R_CONTRADICTION,
            *guard,
            format!("this rule never matches: both sides of this `!=` are always the same object{also}"),
        )
        .with_hint(hint),
        Never::TwoObjects { first, second } => Diagnostic::warning(
            codes::R_CONTRADICTION,
            *second,
            format!("this rule never matches: one parameter would have to be two different objects{also}"),
        )
        .with_label(*first, "the other object")
        .with_hint(hint),
        Never::TypeGuard { guard, var, ty, has } => Diagnostic::warning(
            codes::R_GUARD_TYPE,
            *guard,
            format!("this rule never matches: `?{var}` is a `{has}` in `{action}`, and no `{has}` is a `{ty}`{also}"),
        )
        .with_hint(hint),
        Never::Disjoint { var, first, second } => Diagnostic::warning(
            codes::R_DISJOINT,
            second.0,
            format!("this rule never matches: `?{var}` would be one object that is both a `{}` and a `{}` in `{action}`, and the domain's types share none{also}", first.1, second.1),
        )
        .with_label(first.0, format!("a `{}` here", first.1))
        .with_hint(if r.guards.iter().any(|g| matches!(g, Guard::Eq { .. })) {
            hint
        } else {
            "a repeated variable asks for the same object twice; use two variables"
        }),
        Never::ObjectType { object, name, has, want } => Diagnostic::warning(
            codes::R_GUARD_OBJECT,
            *object,
            format!("this rule never matches: `{name}` is a `{has}`, and the parameter it is compared with takes a `{want}` in `{action}`{also}"),
        )
        .with_hint(hint),
    }
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
                btc_pddl::ast::Term::Const { name } => name.name.to_string(),
            })
            .collect();
        out.insert((positive, atom.pred.name.to_string(), args));
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

/// The PDDL action's effect with its parameters renamed to the rule's
/// variables (by the fold: all at once, so swaps work, and quantified
/// variables are renamed out of the way).
pub fn rewrite_effect(effects: &[&Effect], action: &btc_pddl::ast::Action, r: &Rule) -> String {
    use btc_pddl::logic::{self, Renaming, Terms};
    let parts: Vec<logic::Effect> = effects.iter().map(|e| logic::Effect::from_ast(e)).collect();
    let effect = match <[logic::Effect; 1]>::try_from(parts) {
        Ok([one]) => one,
        Err(many) => logic::Effect::And(many),
    };
    let pairs: Vec<(logic::Name, logic::Name)> = action
        .params
        .iter()
        .zip(&r.pattern.params)
        .map(|(p, rp)| (logic::name(&p.name.name), logic::name(&rp.var.text)))
        .collect();
    effect.rename(&Renaming { pairs: &pairs }).to_string()
}

/// The formula a condition node is defined by, if any (for the runtime).
pub fn condition_formula<'a>(decls: &'a Decls, name: &str) -> Option<&'a Formula> {
    decls.nodes.get(name).and_then(|n| n.formula.as_ref())
}
