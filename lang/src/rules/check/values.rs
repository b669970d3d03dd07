//! The scope a template is checked in ([`Tcx`]: the variables, captures
//! and basic-typed ports it may name) and the values bound in it: names
//! looked up, types, table lookups and their keys, and whether a value
//! fits its port or decorator parameter.

use super::{unknown_name, unknown_object, Decls, DomainCtx};
use crate::rules::ast::*;
use crate::rules::name::{capture_value, Key};
use btc_pddl::diagnostic::{closest, codes, Diagnostic};
use btc_pddl::source::Span;
use btc_pddl::types::TypeId;

/// The type of a value bound to a port.
#[derive(Clone, Debug, PartialEq)]
pub(super) enum VType {
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

/// What a template is checked in: the declarations, the domain, the
/// variables, captures and basic-typed ports in scope, and the findings.
pub(super) struct Tcx<'a> {
    pub(super) decls: &'a Decls,
    pub(super) ctx: Option<DomainCtx<'a>>,
    /// Variables in scope and their PDDL types (`None`: not known).
    pub(super) vars: Vec<(String, Option<Vec<TypeId>>)>,
    /// Captures in scope and the values they take in the domain's actions.
    pub(super) captures: Vec<(String, Vec<String>)>,
    /// Tree ports of basic types (`int`, `string`, ...), as variables.
    pub(super) basic: Vec<(String, VType)>,
    pub(super) in_plan: bool,
    /// Checking a tree imported from BT.CPP XML: a node nothing declares
    /// is R075, whose hint names palettes.
    pub(super) imported: bool,
    pub(super) diags: Vec<Diagnostic>,
}

impl Tcx<'_> {
    pub(super) fn err(&mut self, d: Diagnostic) {
        if !self.diags.contains(&d) {
            self.diags.push(d);
        }
    }

    pub(super) fn string(&mut self, s: &StrLit) {
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

    pub(super) fn var(&mut self, name: &Ident) -> Option<Vec<TypeId>> {
        match self.vars.iter().find(|(v, _)| *v == name.text) {
            Some((_, t)) => t.clone(),
            None => {
                let unbound = unknown_name(
                    Diagnostic::error(
                        codes::R_UNBOUND,
                        name.span,
                        format!("`?{}` is not bound here", name.text),
                    ),
                    &name.text,
                    self.vars.iter().map(|(v, _)| v.as_str()),
                    |c| format!("?{c}"),
                    || "variables come from the rule's pattern (or the tree's ports)".into(),
                );
                self.err(unbound);
                None
            }
        }
    }

    pub(super) fn capture(&mut self, name: &Ident) -> Option<Vec<String>> {
        match self.captures.iter().find(|(c, _)| *c == name.text) {
            Some((_, vals)) => Some(vals.clone()),
            None => {
                let unbound = unknown_name(
                    Diagnostic::error(
                        codes::R_UNBOUND,
                        name.span,
                        format!("`{}` is not a capture of this rule", name.text),
                    ),
                    &name.text,
                    self.captures.iter().map(|(c, _)| c.as_str()),
                    str::to_owned,
                    || "captures come from `{name}` parts of the rule's pattern".into(),
                );
                self.err(unbound);
                None
            }
        }
    }

    /// A decorator's arguments against its parameter: one value (by
    /// position or by the parameter's name) that is a whole number in the
    /// parameter's range, or none for decorators without a parameter.
    pub(super) fn decorator_args(&mut self, d: DecoratorName, args: &[DecoratorArg], span: Span) {
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
    pub(super) fn capture_values(&self, name: &Ident) -> Option<&[String]> {
        self.captures
            .iter()
            .find(|(c, _)| *c == name.text)
            .map(|(_, v)| v.as_slice())
    }

    pub(super) fn value(&mut self, v: &Value) -> VType {
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
    pub(super) fn objects_without_key(&mut self, t: &TableDecl, var: &Ident, span: Span) {
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

    pub(super) fn lookup(&mut self, table: &Ident, key: &Value, span: Span) -> VType {
        let Some(t) = self.decls.tables.get(&table.text).cloned() else {
            self.err(unknown_name(
                Diagnostic::error(
                    codes::R_UNKNOWN_TABLE,
                    table.span,
                    format!("no table is called `{}`", table.text),
                ),
                &table.text,
                self.decls.tables.keys().map(String::as_str),
                str::to_owned,
                || format!("declare it: `table {} {{ KEY: value }}`", table.text),
            ));
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

    pub(super) fn port_fit(&mut self, port: &PortDecl, value: &Value, vt: VType) {
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
                        self.err(unknown_object(obj, value.span(), candidate));
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

pub(super) fn describe_vtype(vt: &VType, ctx: Option<DomainCtx>) -> String {
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
