//! Templates instantiated into IR nodes: with a step's bindings (values
//! filled in), or parametrically (values that depend on the step become a
//! tree's ports); tree declarations expanded at their calls.

use super::*;

/// Instantiates templates, either with a step's bindings (values filled in)
/// or parametrically (values that depend on the step become `{param}`s).
pub(super) struct Inst<'a> {
    pub(super) decls: &'a Decls,
    pub(super) bindings: &'a Bindings<'a>,
    pub(super) captures: &'a Captures,
    /// Parametric mode: collected parameters.
    pub(super) params: Option<Vec<(String, Value)>>,
    /// Tree ports in scope (inside a `tree` declaration).
    pub(super) tree_ports: Vec<String>,
    pub(super) used_nodes: BTreeSet<String>,
    pub(super) used_trees: BTreeSet<String>,
    /// Nesting of tree expansions (a tree may call trees).
    pub(super) depth: usize,
    /// Parameters that are decorator counts, checked at each call.
    pub(super) counts: Vec<(String, DecoratorName, DecoratorParam)>,
}

/// A tree declaration's body with the call's argument expressions put in
/// for its ports (`?port` in values and `{?port}` in strings).
fn expand_tree(decl: &TreeDecl, args: &[Arg]) -> Vec<Template> {
    let arg = |port: &str| -> Option<&Value> {
        args.iter()
            .find(|a| a.port.key.as_str() == port)
            .map(|a| &a.value)
    };
    fn value<'a>(v: &Value, arg: &dyn Fn(&str) -> Option<&'a Value>) -> Value {
        match v {
            Value::Var { name } => arg(&name.text).cloned().unwrap_or_else(|| v.clone()),
            Value::Str { value: s } => Value::Str {
                value: string(s, arg),
            },
            Value::Lookup { table, key, span } => Value::Lookup {
                table: table.clone(),
                key: Box::new(value(key, arg)),
                span: *span,
            },
            other => other.clone(),
        }
    }
    fn string<'a>(s: &StrLit, arg: &dyn Fn(&str) -> Option<&'a Value>) -> StrLit {
        let mut parts = Vec::new();
        for p in &s.parts {
            match p {
                StrPart::Var { name } => match arg(&name.text) {
                    Some(Value::Var { name: v }) => parts.push(StrPart::Var { name: v.clone() }),
                    Some(Value::Name { name: c }) => {
                        parts.push(StrPart::Capture { name: c.clone() })
                    }
                    Some(Value::Str { value }) => parts.extend(value.parts.iter().cloned()),
                    Some(Value::Int { value, .. }) => parts.push(StrPart::Text {
                        text: value.to_string(),
                    }),
                    Some(Value::Float { value, .. }) => parts.push(StrPart::Text {
                        text: format_float(*value),
                    }),
                    Some(Value::Bool { value, .. }) => parts.push(StrPart::Text {
                        text: value.to_string(),
                    }),
                    Some(v @ Value::Lookup { .. }) => parts.push(StrPart::Value {
                        value: Box::new(v.clone()),
                    }),
                    None => parts.push(p.clone()),
                },
                other => parts.push(other.clone()),
            }
        }
        // The parts are no longer the file's text: no offsets map back.
        StrLit {
            parts,
            span: s.span,
            escapes: Vec::new(),
        }
    }
    fn template<'a>(t: &Template, arg: &dyn Fn(&str) -> Option<&'a Value>) -> Template {
        match t {
            Template::Control {
                control,
                name,
                children,
                span,
            } => Template::Control {
                control: *control,
                name: name.as_ref().map(|n| string(n, arg)),
                children: children.iter().map(|c| template(c, arg)).collect(),
                span: *span,
            },
            Template::Decorator {
                decorator,
                args,
                name,
                child,
                span,
            } => Template::Decorator {
                decorator: *decorator,
                args: args
                    .iter()
                    .map(|a| DecoratorArg {
                        param: a.param.clone(),
                        value: value(&a.value, arg),
                        span: a.span,
                    })
                    .collect(),
                name: name.as_ref().map(|n| string(n, arg)),
                child: Box::new(template(child, arg)),
                span: *span,
            },
            Template::Call {
                name,
                args,
                scripts,
                label,
                span,
            } => Template::Call {
                name: name.clone(),
                scripts: scripts.clone(),
                label: label.as_ref().map(|l| string(l, arg)),
                args: args
                    .iter()
                    .map(|a| Arg {
                        port: a.port.clone(),
                        value: value(&a.value, arg),
                    })
                    .collect(),
                span: *span,
            },
            other => other.clone(),
        }
    }
    decl.body.iter().map(|t| template(t, &arg)).collect()
}

impl<'a> Inst<'a> {
    /// An instantiation with `bindings` and `captures` (parametric, its
    /// parameters collected, when `parametric`).
    pub(super) fn new(
        decls: &'a Decls,
        bindings: &'a Bindings<'a>,
        captures: &'a Captures,
        parametric: bool,
    ) -> Inst<'a> {
        Inst {
            decls,
            bindings,
            captures,
            params: parametric.then(Vec::new),
            tree_ports: Vec::new(),
            used_nodes: BTreeSet::new(),
            used_trees: BTreeSet::new(),
            depth: 0,
            counts: Vec::new(),
        }
    }

    fn lookup_var(&self, v: &str) -> Option<&str> {
        self.bindings.iter().find(|(n, _)| *n == v).map(|(_, o)| *o)
    }

    fn lookup_capture(&self, c: &str) -> Option<&str> {
        self.captures
            .iter()
            .find(|(n, _)| n == c)
            .map(|(_, v)| v.as_str())
    }

    /// Parametric mode: the parameter standing for this value.
    fn param_for(&mut self, v: &Value, preferred: &str) -> PortValue {
        let params = self.params.as_mut().expect("parametric mode");
        let key = value_key(v);
        if let Some((name, _)) = params.iter().find(|(_, e)| value_key(e) == key) {
            return PortValue::Param(name.clone());
        }
        let mut name = preferred.to_owned();
        let mut n = 1;
        while params.iter().any(|(p, _)| *p == name) {
            n += 1;
            name = format!("{preferred}_{n}");
        }
        params.push((name.clone(), v.clone()));
        PortValue::Param(name)
    }

    fn depends_on_step(v: &Value) -> bool {
        match v {
            Value::Var { .. } | Value::Name { .. } => true,
            Value::Str { value } => value.plain().is_none(),
            Value::Lookup { key, .. } => Self::depends_on_step(key),
            _ => false,
        }
    }

    /// A port's value; `port` names the parameter a computed value becomes.
    fn value(&mut self, v: &Value, port: &str) -> PortValue {
        if self.tree_ports.is_empty() && self.params.is_some() && Self::depends_on_step(v) {
            let preferred = match v {
                Value::Var { name } | Value::Name { name } => name.text.clone(),
                _ => port.to_owned(),
            };
            return self.param_for(v, &preferred);
        }
        self.eval(v)
    }

    /// A value with the step's bindings (or tree ports) filled in.
    pub(super) fn eval(&self, v: &Value) -> PortValue {
        match v {
            Value::Var { name } => {
                if self.tree_ports.contains(&name.text) {
                    return PortValue::Param(name.text.clone());
                }
                PortValue::Text(self.lookup_var(&name.text).unwrap_or_default().to_owned())
            }
            Value::Name { name } => PortValue::Text(capture_value(
                self.lookup_capture(&name.text).unwrap_or(&name.text),
            )),
            Value::Str { value } => PortValue::Text(self.string(value)),
            Value::Int { value, .. } => PortValue::Int(*value),
            Value::Float { value, .. } => PortValue::Float(*value),
            Value::Bool { value, .. } => PortValue::Bool(*value),
            Value::Lookup { table, key, .. } => {
                let key = match self.eval(key) {
                    PortValue::Text(t) => t,
                    other => other.to_text(),
                };
                let entry = self
                    .decls
                    .tables
                    .get(&table.text)
                    .and_then(|t| t.entries.iter().find(|e| e.key.key == Key::new(&key)));
                match entry.map(|e| &e.value) {
                    Some(Literal::Int { value, .. }) => PortValue::Int(*value),
                    Some(Literal::Float { value, .. }) => PortValue::Float(*value),
                    Some(Literal::Bool { value, .. }) => PortValue::Bool(*value),
                    Some(Literal::Str { value }) => PortValue::Text(self.string(value)),
                    Some(Literal::Name { name }) => PortValue::Text(name.text.clone()),
                    None => PortValue::Text(String::new()),
                }
            }
        }
    }

    fn string(&self, s: &StrLit) -> String {
        let mut out = String::new();
        for p in &s.parts {
            match p {
                StrPart::Text { text } => out.push_str(text),
                StrPart::Var { name } => match self.lookup_var(&name.text) {
                    Some(o) if self.params.is_none() || !self.tree_ports.is_empty() => {
                        out.push_str(o)
                    }
                    _ => {
                        out.push('{');
                        out.push_str(&name.text);
                        out.push('}');
                    }
                },
                StrPart::Capture { name } => match self.lookup_capture(&name.text) {
                    Some(c) if self.params.is_none() => out.push_str(&capture_value(c)),
                    _ => {
                        out.push('{');
                        out.push_str(&name.text);
                        out.push('}');
                    }
                },
                StrPart::Value { value } => out.push_str(&self.eval(value).to_text()),
            }
        }
        out
    }

    /// A node name. In a rule's parametric tree, each part that depends on
    /// the step becomes a parameter of the tree (each call fills it in);
    /// otherwise every part is the step's value.
    fn name(&mut self, s: &Option<StrLit>) -> Option<Label> {
        let s = s.as_ref()?;
        let parametric = self.params.is_some() && self.tree_ports.is_empty();
        let mut label = Label {
            parts: Default::default(),
        };
        for p in &s.parts {
            let v = match p {
                StrPart::Text { text } => {
                    label.push_text(text);
                    continue;
                }
                StrPart::Var { name } => Value::Var { name: name.clone() },
                StrPart::Capture { name } => Value::Name { name: name.clone() },
                StrPart::Value { value } => (**value).clone(),
            };
            let preferred = match &v {
                Value::Var { name } | Value::Name { name } => name.text.clone(),
                Value::Lookup { table, .. } => table.text.clone(),
                _ => "name".to_owned(),
            };
            match if parametric && Self::depends_on_step(&v) {
                self.param_for(&v, &preferred)
            } else {
                self.eval(&v)
            } {
                PortValue::Param(p) => label.parts.push(LabelPart::Param(p)),
                other => label.push_text(&other.to_text()),
            }
        }
        if label.parts.is_empty() {
            label.push_text("");
        }
        Some(label)
    }

    /// A decorator of the IR: its argument evaluated, or (in a rule's
    /// parametric tree, when it depends on the step) a parameter of the
    /// tree that each step's call fills in. The checker has made sure the
    /// argument is a whole number in range (R004, R023).
    fn decorator(&mut self, d: DecoratorName, args: &[DecoratorArg]) -> DecoratorKind {
        let count = |this: &mut Self, param: &str| -> Count {
            let (Some(a), Some(range)) = (args.first(), d.param()) else {
                return Count::Fixed(0);
            };
            let v = this.value(&a.value, param);
            if let Some(n) = count_in_range(&v, range) {
                return Count::Fixed(n);
            }
            // A parameter, or (in a rule's tree) a value the checker could
            // not see; each call's value is checked where the step is.
            let p = match v {
                PortValue::Param(p) => p,
                _ if this.params.is_some() => match this.param_for(&a.value, param) {
                    PortValue::Param(p) => p,
                    _ => unreachable!("param_for gives a parameter"),
                },
                _ => return Count::Fixed(0),
            };
            if this.params.is_some() && this.tree_ports.is_empty() {
                this.counts.push((p.clone(), d, range));
            }
            Count::Param { param: p }
        };
        let count = match d.param() {
            Some(p) => count(self, p.name),
            None => Count::Fixed(0),
        };
        DecoratorKind::new(d, count)
    }

    pub(super) fn templates(
        &mut self,
        ts: &[Template],
        steps: &dyn Fn(StepsMode) -> Vec<Node>,
    ) -> Vec<Node> {
        ts.iter().flat_map(|t| self.template(t, steps)).collect()
    }

    fn template(&mut self, t: &Template, steps: &dyn Fn(StepsMode) -> Vec<Node>) -> Vec<Node> {
        match t {
            Template::Control {
                control,
                name,
                children,
                ..
            } => {
                let name = self.name(name);
                vec![Node::Control {
                    scripts: Default::default(),
                    control: *control,
                    name,
                    children: self.templates(children, steps),
                }]
            }
            Template::Decorator {
                decorator,
                args,
                name,
                child,
                ..
            } => {
                let name = self.name(name);
                let kind = self.decorator(*decorator, args);
                let mut kids = self.template(child, steps);
                let child = if kids.len() == 1 {
                    kids.remove(0)
                } else {
                    Node::sequence(kids)
                };
                vec![Node::Decorator {
                    scripts: Default::default(),
                    decorator: kind,
                    name,
                    child: Box::new(child),
                }]
            }
            Template::Call {
                name,
                args,
                scripts: attrs,
                label,
                ..
            } => {
                let scripts = node_scripts(attrs);
                if let Some(decl) = self.decls.trees.get(&name.text) {
                    // Declared trees expand at the call: BT.CPP cannot fill
                    // `{port}` inside a longer string, so a tree whose body
                    // interpolates its ports cannot be a shared <SubTree>.
                    self.used_trees.insert(name.text.clone());
                    if self.depth >= btc_ir::MAX_CALL_DEPTH {
                        return Vec::new();
                    }
                    let body = expand_tree(decl, args);
                    self.depth += 1;
                    let nodes = self.templates(&body, steps);
                    self.depth -= 1;
                    if scripts.is_empty() {
                        return nodes;
                    }
                    // The scripts go around the whole expanded body, as
                    // they would around a <SubTree>.
                    return vec![Node::Control {
                        control: ControlKind::Sequence,
                        name: None,
                        children: nodes,
                        scripts,
                    }];
                }
                let ports: Vec<Port> = args
                    .iter()
                    .map(|a| Port {
                        name: a.port.text.clone(),
                        value: self.value(&a.value, &a.port.text),
                    })
                    .collect();
                self.used_nodes.insert(name.text.clone());
                let leaf = match self.decls.nodes.get(&name.text).map(|n| n.kind) {
                    Some(NodeKind::Condition) => LeafKind::Condition,
                    _ => LeafKind::Action,
                };
                let label = self.name(label);
                vec![Node::Leaf {
                    scripts,
                    leaf,
                    id: name.text.clone(),
                    name: label,
                    ports,
                }]
            }
            Template::Script {
                condition, code, ..
            } => {
                let (leaf, id) = if *condition {
                    (LeafKind::Condition, "ScriptCondition")
                } else {
                    (LeafKind::Action, "Script")
                };
                vec![Node::Leaf {
                    leaf,
                    id: id.into(),
                    name: None,
                    ports: vec![Port {
                        name: "code".into(),
                        value: PortValue::Text(script_code(code)),
                    }],
                    scripts: NodeScripts::default(),
                }]
            }
            Template::Steps { mode, .. } => steps(*mode),
            Template::Error { .. } => Vec::new(),
        }
    }
}

/// A call's `[key: "script"]` as BT.CPP's attributes (the checker has
/// reported unknown keys and repeats: the first of each is kept).
fn node_scripts(attrs: &[ScriptAttr]) -> NodeScripts {
    let mut out = NodeScripts::default();
    for a in attrs {
        if let Some(k) = NodeScripts::key_index(&a.key.text) {
            out.slot(k).get_or_insert_with(|| script_code(&a.code));
        }
    }
    out
}

/// A script string's code (one that interpolates is reported; its text
/// parts are kept).
fn script_code(code: &StrLit) -> String {
    code.parts
        .iter()
        .filter_map(|p| match p {
            StrPart::Text { text } => Some(text.as_str()),
            _ => None,
        })
        .collect()
}

/// A value as a decorator's count, when it is a whole number in range.
pub(super) fn count_in_range(v: &PortValue, range: DecoratorParam) -> Option<u64> {
    let n = match v {
        PortValue::Int(n) => *n,
        PortValue::Text(t) => t.parse().ok()?,
        _ => return None,
    };
    (range.min..=range.max)
        .contains(&n)
        .then(|| u64::try_from(n).ok())
        .flatten()
}

/// A value's identity without its spans: two uses of `?robot` are one
/// parameter.
fn value_key(v: &Value) -> String {
    match v {
        Value::Var { name } => format!("?{}", name.text),
        Value::Name { name } => format!("capture {}", name.text),
        Value::Str { value } => {
            let parts: Vec<String> = value
                .parts
                .iter()
                .map(|p| match p {
                    StrPart::Text { text } => format!("{text:?}"),
                    StrPart::Var { name } => format!("?{}", name.text),
                    StrPart::Capture { name } => format!("{{{}}}", name.text),
                    StrPart::Value { value } => format!("{{{}}}", value_key(value)),
                })
                .collect();
            format!("string {}", parts.join(" "))
        }
        Value::Int { value, .. } => format!("int {value}"),
        Value::Float { value, .. } => format!("float {value}"),
        Value::Bool { value, .. } => format!("bool {value}"),
        Value::Lookup { table, key, .. } => format!("{}[{}]", table.text, value_key(key)),
    }
}
