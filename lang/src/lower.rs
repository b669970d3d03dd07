//! Lowering: rules + a typed plan -> [`TreeIr`]. Each step is matched
//! against the rules (first match in file order), the rule's template
//! becomes a parametric tree called with the step's bindings, KB effects
//! and conditions are attached, and the `plan { ... }` template arranges the
//! steps (`steps`, `steps backchained`, `steps parallel`).

use crate::rules::ast::*;
use crate::rules::check::Decls;
use crate::rules::matching::{match_args, match_name, Bindings, Captures, ObjectTypes};
use crate::rules::name::{capture_value, Key};
use btc_ir::format_float;
use btc_ir::*;
use btc_pddl::ast::{Domain, Problem};
use btc_pddl::check::{DomainIndex, ProblemIndex};
use btc_pddl::diagnostic::{codes, Diagnostic};
use btc_pddl::logic::{self, Formula, Name};
use btc_pddl::plan::{GroundStep, Plan};
use btc_pddl::world::WorldModel;
use std::collections::{BTreeMap, BTreeSet};
use std::sync::Arc;

mod action;
mod arrange;
mod backchain;

use action::{Grounder, RuleEffect};
use arrange::kb_holds;

pub struct LowerInput<'a> {
    pub decls: &'a Decls,
    /// Rules in match order (the file's own first, then imported ones).
    pub rules: Vec<&'a Rule>,
    pub plan_template: Option<&'a [Template]>,
    pub domain: &'a Domain,
    pub dix: &'a DomainIndex,
    pub problem: &'a Problem,
    pub pix: &'a ProblemIndex,
    pub plan: &'a Plan,
    pub steps: &'a [GroundStep],
    pub domain_path: String,
    pub problem_path: String,
    pub plan_path: String,
    pub rules_path: String,
}

struct Types<'a> {
    dix: &'a DomainIndex,
    pix: &'a ProblemIndex,
}

impl ObjectTypes for Types<'_> {
    fn object_is(&self, object: &str, ty: &str) -> bool {
        match (self.pix.objects.get(object), self.dix.types.id(ty)) {
            (Some(o), Some(t)) => self.dix.types.fits(&o.types, &[t]),
            _ => false,
        }
    }
}

/// A rule's template made parametric: its tree and, per parameter, the
/// value expression a call evaluates.
struct RuleTree {
    id: String,
    /// The id as the steps that call the tree hold it (one for all).
    shared_id: Arc<str>,
    params: Vec<(String, Value)>,
    root: Node,
    typed: Vec<TypedPort>,
    /// Parameters that are decorator counts, with their ranges.
    counts: Vec<(String, DecoratorName, DecoratorParam)>,
}

/// Instantiates templates, either with a step's bindings (values filled in)
/// or parametrically (values that depend on the step become `{param}`s).
struct Inst<'a> {
    decls: &'a Decls,
    bindings: &'a Bindings<'a>,
    captures: &'a Captures,
    /// Parametric mode: collected parameters.
    params: Option<Vec<(String, Value)>>,
    /// Tree ports in scope (inside a `tree` declaration).
    tree_ports: Vec<String>,
    used_nodes: BTreeSet<String>,
    used_trees: BTreeSet<String>,
    /// Nesting of tree expansions (a tree may call trees).
    depth: usize,
    /// Parameters that are decorator counts, checked at each call.
    counts: Vec<(String, DecoratorName, DecoratorParam)>,
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
                span,
            } => Template::Call {
                name: name.clone(),
                scripts: scripts.clone(),
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

impl Inst<'_> {
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
    fn eval(&self, v: &Value) -> PortValue {
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

    fn templates(&mut self, ts: &[Template], steps: &dyn Fn(StepsMode) -> Vec<Node>) -> Vec<Node> {
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
                vec![Node::Leaf {
                    scripts,
                    leaf,
                    id: name.text.clone(),
                    name: None,
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
fn count_in_range(v: &PortValue, range: DecoratorParam) -> Option<u64> {
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

/// A BT.CPP-safe id for a rule: `rule_PICK_op`.
fn rule_id(r: &Rule, taken: &BTreeSet<String>) -> String {
    let base: String = format!("rule_{}", r.pattern.name_text())
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || c == '_' {
                c
            } else {
                '_'
            }
        })
        .collect::<String>()
        .replace("__", "_")
        .trim_end_matches('_')
        .to_owned();
    let mut id = base.clone();
    let mut n = 2;
    while taken.contains(&id) {
        id = format!("{base}_{n}");
        n += 1;
    }
    id
}

/// How a ground action lowers: the rule tree it calls (`None`: skipped),
/// its effects (a rule's `effect` replaces the action's) and the step's
/// node below its `Step` boundary.
#[derive(Clone)]
struct Lowered {
    logic: Arc<StepLogic>,
    child: Option<Arc<Node>>,
}

/// What the steps of one call (the same action and the same shared
/// argument list, as typing gives the steps that write the same call) have
/// in common: found at the call's first step, then looked up once a step.
struct CallParts {
    action: Arc<str>,
    args: Arc<[String]>,
    ground: action::Ground,
    lowered: Option<Lowered>,
}

/// A step's call: its action and the address of its shared argument list.
type CallKey = (usize, *const u32);

fn call_key(g: &GroundStep) -> CallKey {
    (g.action, Arc::as_ptr(&g.args) as *const u32)
}

/// Remembers how the call of step `g` lowered, for the steps that repeat
/// it: by the call, and by its action and objects for steps that repeat
/// it in another call (written otherwise).
fn remember<'a>(
    calls: &mut rustc_hash::FxHashMap<CallKey, CallParts>,
    lowered: &mut rustc_hash::FxHashMap<(usize, &'a [u32]), Lowered>,
    g: &'a GroundStep,
    done: Lowered,
) {
    if let Some(parts) = calls.get_mut(&call_key(g)) {
        parts.lowered = Some(done.clone());
    }
    lowered.insert((g.action, &g.args[..]), done);
}

/// Lowers a plan; every problem is reported at the plan line of its step.
pub fn lower(input: &LowerInput) -> Result<TreeIr, Vec<Diagnostic>> {
    let mut diags = Vec::new();
    let types = Types {
        dix: input.dix,
        pix: input.pix,
    };
    let tables = |name: &str| input.decls.tables.get(name).cloned();
    let mut grounder = Grounder::default();
    // Each ground action's lowering, for the steps that repeat it: which
    // rule, which tree call and guard, which effects depend on the action
    // and its objects only, never on the step's place in the plan.
    let mut lowered: rustc_hash::FxHashMap<(usize, &[u32]), Lowered> = Default::default();
    // Steps with the same objects share their names, and with the same
    // action its name.
    let mut action_names: rustc_hash::FxHashMap<usize, Arc<str>> = Default::default();
    let mut arg_names: rustc_hash::FxHashMap<&[u32], Arc<[String]>> = Default::default();
    // The same, by call: one lookup a step instead of one a table.
    let mut calls: rustc_hash::FxHashMap<CallKey, CallParts> = Default::default();
    let mut rule_effects: BTreeMap<usize, RuleEffect> = BTreeMap::new();
    let mut rule_trees: Vec<(usize, RuleTree)> = Vec::new(); // by rule index
    let mut taken = BTreeSet::new();
    let mut used_nodes = BTreeSet::new();
    let mut used_trees = BTreeSet::new();
    let mut infos = Vec::with_capacity(input.steps.len());
    let mut name_matches: BTreeMap<(usize, usize), Option<Captures>> = BTreeMap::new();
    let mut step_nodes: Vec<Option<Node>> = Vec::with_capacity(input.steps.len());
    let no_bindings = Bindings::new();
    let no_captures = Captures::new();
    let object_names: Vec<Name> = input
        .pix
        .object_names
        .iter()
        .map(|n| logic::name(n))
        .collect();

    for (k, g) in input.steps.iter().enumerate() {
        let step = &input.plan.steps[g.step];
        let action = &input.domain.actions[g.action];
        let parts = calls.entry(call_key(g)).or_insert_with(|| CallParts {
            action: action_names
                .entry(g.action)
                .or_insert_with(|| action.name.name.as_str().into())
                .clone(),
            args: arg_names
                .entry(&g.args[..])
                .or_insert_with(|| {
                    g.args
                        .iter()
                        .map(|&o| input.pix.object_names[o as usize].clone())
                        .collect()
                })
                .clone(),
            ground: grounder.ground(input.domain, g.action, &g.args, &object_names),
            lowered: lowered.get(&(g.action, &g.args[..])).cloned(),
        });
        let repeated = parts.lowered.clone();
        let ground = parts.ground.clone();
        let place = |skipped: bool, logic: Arc<StepLogic>| StepInfo {
            index: k,
            line: step.line,
            skipped,
            time: step.time,
            duration: step.duration,
            after: Default::default(),
            logic,
        };
        let mut logic = StepLogic {
            action: parts.action.clone(),
            args: parts.args.clone(),
            rule: None,
            pre_start: ground.pre_start,
            pre_over_all: ground.pre_over_all,
            pre_end: ground.pre_end,
            eff_start: ground.eff_start,
            eff_end: ground.eff_end,
        };
        if let Some(r) = repeated {
            infos.push(place(r.logic.rule.is_none(), r.logic));
            step_nodes.push(r.child.map(|child| Node::Step { step: k, child }));
            continue;
        }
        let diags_before = diags.len();
        let args = logic.args.clone();
        // Names match once per (rule, action); steps repeat actions a lot.
        let found = input.rules.iter().enumerate().find_map(|(ri, r)| {
            let caps = name_matches
                .entry((ri, g.action))
                .or_insert_with(|| match_name(&r.pattern.name, &action.name.name))
                .as_ref()?;
            match_args(r, caps, &args, &tables, &types).map(|b| (ri, *r, b))
        });
        let Some((ri, rule, bindings)) = found else {
            let named: Vec<&&Rule> = input
                .rules
                .iter()
                .filter(|r| match_name(&r.pattern.name, &action.name.name).is_some())
                .collect();
            let hint = if named.is_empty() {
                format!(
                    "add a rule for it: `rule ({} {}) {{ ... }}`",
                    action.name.name,
                    action
                        .params
                        .iter()
                        .map(|p| format!("?{}", p.name.name))
                        .collect::<Vec<_>>()
                        .join(" ")
                )
            } else {
                match named.len() {
                    1 => format!("the rule for `{}` does not fit this step: its parameter count or `where` guard rules it out", action.name.name),
                    n => format!("{n} rules for `{}` exist, but their parameter counts or `where` guards rule this step out", action.name.name),
                }
            };
            diags.push(
                Diagnostic::error(
                    codes::R_NO_RULE,
                    step.span,
                    format!("step {} `{}`: no rule matches it", k + 1, logic.display()),
                )
                .with_hint(hint),
            );
            infos.push(place(false, Arc::new(logic)));
            step_nodes.push(None);
            continue;
        };
        let RuleBody::Template { body, effect } = &rule.body else {
            let logic = Arc::new(logic);
            let done = Lowered {
                logic: logic.clone(),
                child: None,
            };
            remember(&mut calls, &mut lowered, g, done);
            infos.push(place(true, logic));
            step_nodes.push(None);
            continue;
        };
        // A rule's `effect` is the step's effect, in every target: it takes
        // the place of the PDDL action's (at start and at end), applied
        // when the step succeeds.
        if let Some(e) = effect {
            let lifted = rule_effects.entry(ri).or_insert_with(|| RuleEffect::new(e));
            match lifted.ground(&bindings) {
                Ok(e) => {
                    logic.eff_start = None;
                    logic.eff_end = e.map(Arc::new);
                }
                Err(var) => {
                    diags.push(
                        Diagnostic::error(
                            codes::R_EFFECT_UNBOUND,
                            step.span,
                            format!(
                                "step {} `{}`: its rule's effect reads `?{var}`, which this step leaves out",
                                k + 1,
                                logic.display()
                            ),
                        )
                        .with_hint("an optional parameter the step does not give cannot stand in the rule's `effect`; write a rule for the shorter form"),
                    );
                }
            }
        }
        let pos = match rule_trees.iter().position(|(i, _)| *i == ri) {
            Some(p) => p,
            None => {
                let id = rule_id(rule, &taken);
                taken.insert(id.clone());
                let mut inst = Inst {
                    decls: input.decls,
                    bindings: &no_bindings,
                    captures: &no_captures,
                    params: Some(Vec::new()),
                    tree_ports: Vec::new(),
                    used_nodes: BTreeSet::new(),
                    used_trees: BTreeSet::new(),
                    depth: 0,
                    counts: Vec::new(),
                };
                let mut nodes = inst.templates(body, &|_| Vec::new());
                let root = if nodes.len() == 1 {
                    nodes.remove(0)
                } else {
                    Node::sequence(nodes)
                };
                used_nodes.extend(inst.used_nodes);
                used_trees.extend(inst.used_trees);
                rule_trees.push((
                    ri,
                    RuleTree {
                        shared_id: id.as_str().into(),
                        id,
                        params: inst.params.unwrap_or_default(),
                        typed: typed_ports(&root, input),
                        counts: inst.counts,
                        root,
                    },
                ));
                rule_trees.len() - 1
            }
        };
        let rt = &rule_trees[pos].1;
        let captures = name_matches[&(ri, g.action)]
            .as_ref()
            .expect("the rule's name matched this action");
        let call_inst = Inst {
            decls: input.decls,
            bindings: &bindings,
            captures,
            params: None,
            tree_ports: Vec::new(),
            used_nodes: BTreeSet::new(),
            used_trees: BTreeSet::new(),
            depth: 0,
            counts: Vec::new(),
        };
        let ports: Vec<Port> = rt
            .params
            .iter()
            .map(|(name, expr)| Port {
                name: name.clone(),
                value: call_inst.eval(expr),
            })
            .collect();
        // A decorator count that depends on the step must be a number in
        // its range (a table may lack the key of this step's object).
        for (param, d, range) in &rt.counts {
            let Some(v) = ports.iter().find(|p| p.name == *param).map(|p| &p.value) else {
                continue;
            };
            if count_in_range(v, *range).is_none() {
                // A lookup is named with the key this step gives it.
                let lookup =
                    rt.params
                        .iter()
                        .find(|(n, _)| n == param)
                        .and_then(|(_, e)| match e {
                            Value::Lookup { table, key, .. } => {
                                Some((table.text.clone(), call_inst.eval(key).to_text()))
                            }
                            _ => None,
                        });
                let (got, hint) = match (v, &lookup) {
                    (PortValue::Text(t), Some((table, key))) if t.is_empty() => (
                        format!("no value: table `{table}` has no key `{key}`"),
                        format!("add `{key}: N` to table `{table}`"),
                    ),
                    (PortValue::Text(t), None) if t.is_empty() => (
                        "no value".to_owned(),
                        "a table lookup gives no value for a key the table does not have; add the key".to_owned(),
                    ),
                    (other, _) => (
                        format!("`{}`, which is not a number of {} from {} to {}", other.to_text(), range.what, range.min, range.max),
                        format!("give a number of {} from {} to {}", range.what, range.min, range.max),
                    ),
                };
                diags.push(
                    Diagnostic::error(
                        codes::R_BAD_ARGUMENT,
                        step.span,
                        format!(
                            "step {} `{}`: `{}` gets {got}",
                            k + 1,
                            logic.display(),
                            d.keyword(),
                        ),
                    )
                    .with_hint(hint),
                );
            }
        }
        // Objects bound to PDDL-typed ports must fit the port's type.
        check_port_types(
            &rt.typed,
            &ports,
            input,
            &types,
            &mut |port, node, obj, ty| {
                diags.push(
                Diagnostic::error(
                    codes::R_STEP_TYPE,
                    step.span,
                    format!("step {} `{}`: `{obj}` does not fit port `{port}` of `{node}`, which takes a `{ty}`", k + 1, logic.display()),
                )
                .with_hint("narrow the rule with a guard such as `where ?x - TYPE`, or widen the port's type"),
            );
            },
        );
        logic.rule = Some(rt.shared_id.clone());
        let mut child = Node::SubTree {
            scripts: Default::default(),
            id: rt.id.clone(),
            ports,
        };
        if let Some(over) = &logic.pre_over_all {
            child = Node::Control {
                scripts: Default::default(),
                control: ControlKind::ReactiveSequence,
                name: Some(format!("while {over}").into()),
                children: vec![kb_holds(over.clone(), None), child],
            };
        }
        let child = Arc::new(child);
        // A step with a diagnostic is not reused: each step reports its own.
        if diags.len() == diags_before {
            let logic = Arc::new(logic);
            let done = Lowered {
                logic: logic.clone(),
                child: Some(Arc::clone(&child)),
            };
            remember(&mut calls, &mut lowered, g, done);
            infos.push(place(false, logic));
        } else {
            infos.push(place(false, Arc::new(logic)));
        }
        step_nodes.push(Some(Node::Step { step: k, child }));
    }
    if !diags.is_empty() {
        return Err(diags);
    }

    // Parallel mode needs the partial order.
    let template = input.plan_template;
    let uses_parallel = template.is_some_and(|t| uses_mode(t, StepsMode::Parallel));
    if uses_parallel {
        arrange::order_steps(&mut infos);
    }
    let mut used_kb = BTreeSet::new();
    // The plan template holds `steps` once (R022): the step nodes move into
    // it instead of being copied.
    let step_nodes = std::cell::RefCell::new(step_nodes);
    let arrange_diags = std::cell::RefCell::new(Vec::new());
    let goal = input.problem.goal.as_ref().map(Formula::from_ast);
    let derived = backchain::derived_predicates(input.domain);
    let arranged = |mode: StepsMode| -> Vec<Node> {
        let nodes = std::mem::take(&mut *step_nodes.borrow_mut());
        match mode {
            StepsMode::InOrder => {
                // Collected in place (a `Node` is as wide as an
                // `Option<Node>`): `flatten` would copy every step's node
                // into a second, growing buffer.
                let mut nodes = nodes;
                nodes.retain(Option::is_some);
                nodes.into_iter().map(Option::unwrap).collect()
            }
            StepsMode::Backchained => {
                match backchain::stages(nodes, &infos, goal.as_ref(), &derived) {
                    Ok(stages) => stages,
                    Err(e) => {
                        arrange_diags
                            .borrow_mut()
                            .push(backchain_diagnostic(e, input));
                        Vec::new()
                    }
                }
            }
            StepsMode::Parallel => vec![arrange::parallel(&nodes, &infos)],
        }
    };
    let root = match template {
        Some(t) => {
            let mut inst = Inst {
                decls: input.decls,
                bindings: &no_bindings,
                captures: &no_captures,
                params: None,
                tree_ports: Vec::new(),
                used_nodes: BTreeSet::new(),
                used_trees: BTreeSet::new(),
                depth: 0,
                counts: Vec::new(),
            };
            let mut nodes = inst.templates(t, &arranged);
            used_nodes.extend(inst.used_nodes);
            used_trees.extend(inst.used_trees);
            if nodes.len() == 1 {
                nodes.remove(0)
            } else {
                Node::sequence(nodes)
            }
        }
        None => Node::sequence(arranged(StepsMode::InOrder)),
    };
    let arrange_diags = arrange_diags.into_inner();
    if !arrange_diags.is_empty() {
        return Err(arrange_diags);
    }
    root.walk_distinct(&mut |n| {
        if let Node::Leaf { id, .. } = n {
            used_kb.insert(id.clone());
        }
    });
    for (_, rt) in &rule_trees {
        rt.root.walk(&mut |n| {
            if let Node::Leaf { id, .. } = n {
                used_kb.insert(id.clone());
            }
        });
    }
    let trees: Vec<TreeDef> = rule_trees
        .into_iter()
        .map(|(_, rt)| TreeDef {
            id: rt.id,
            params: rt.params.into_iter().map(|(n, _)| n).collect(),
            root: rt.root,
        })
        .collect();
    used_nodes.extend(used_kb);
    let nodes = node_models(input.decls, &used_nodes);
    let mut ir = TreeIr {
        version: IR_VERSION,
        domain: input.domain_path.clone(),
        problem: input.problem_path.clone(),
        plan: input.plan_path.clone(),
        rules: input.rules_path.clone(),
        main_tree: "MainTree".into(),
        root,
        trees,
        nodes,
        steps: infos,
        world: WorldModel::from_checked(input.domain, input.dix, input.problem, input.pix),
    };
    let expand = ir.trees_timed_by_port();
    ir.expand_calls(&expand);
    Ok(ir)
}

/// `steps backchained` on a plan it cannot regress the goal through, at the
/// step's plan line.
fn backchain_diagnostic(e: backchain::Breaks, input: &LowerInput) -> Diagnostic {
    let span = input.plan.steps[input.steps[e.step].step].span;
    Diagnostic::error(
        codes::R_BACKCHAIN,
        span,
        format!(
            "step {} makes `{}` false, which the goal or a later step needs: `steps backchained` cannot regress the goal through it",
            e.step + 1,
            e.what
        ),
    )
    .with_hint("the plan does not reach its goal from this step on; plan again, or use `steps` to run it as written")
}

fn uses_mode(ts: &[Template], mode: StepsMode) -> bool {
    ts.iter().any(|t| match t {
        Template::Steps { mode: m, .. } => *m == mode,
        Template::Control { children, .. } => uses_mode(children, mode),
        Template::Decorator { child, .. } => uses_mode(std::slice::from_ref(child), mode),
        _ => false,
    })
}

/// A leaf port of a rule tree whose declared type is a PDDL type, with the
/// value bound to it (a parameter or a constant).
struct TypedPort {
    port: String,
    node: String,
    ty: String,
    value: PortValue,
}

/// The PDDL-typed ports of a rule tree, found once per rule.
fn typed_ports(root: &Node, input: &LowerInput) -> Vec<TypedPort> {
    let mut out = Vec::new();
    root.walk(&mut |n| {
        let Node::Leaf { id, ports, .. } = n else {
            return;
        };
        let Some(decl) = input.decls.nodes.get(id) else {
            return;
        };
        for p in ports {
            let Some(pd) = decl.ports.iter().find(|d| d.name.text == p.name) else {
                continue;
            };
            let ty = pd.ty.key.clone().into_string();
            if crate::rules::check::BASIC_TYPES.contains(&ty.as_str())
                || input.dix.types.id(&ty).is_none()
            {
                continue;
            }
            out.push(TypedPort {
                port: p.name.clone(),
                node: id.clone(),
                ty,
                value: p.value.clone(),
            });
        }
    });
    out
}

/// Reports objects bound to PDDL-typed ports that do not fit the port's type.
fn check_port_types(
    typed: &[TypedPort],
    call: &[Port],
    input: &LowerInput,
    types: &Types,
    report: &mut dyn FnMut(&str, &str, &str, &str),
) {
    for t in typed {
        let value = match &t.value {
            PortValue::Param(name) => call.iter().find(|c| c.name == *name).map(|c| &c.value),
            other => Some(other),
        };
        if let Some(PortValue::Text(obj)) = value {
            if input.pix.objects.contains_key(obj) && !types.object_is(obj, &t.ty) {
                report(&t.port, &t.node, obj, &t.ty);
            }
        }
    }
}

fn node_models(decls: &Decls, used: &BTreeSet<String>) -> Vec<NodeModel> {
    used.iter()
        .filter_map(|id| {
            let n = decls.nodes.get(id).cloned().or_else(|| kb_decl(id))?;
            Some(node_model(id, &n))
        })
        .collect()
}

/// The IR's model of a declared node: its kind, ports and formula.
pub fn node_model(id: &str, n: &NodeDecl) -> NodeModel {
    NodeModel {
        id: id.to_owned(),
        kind: match n.kind {
            NodeKind::Action => LeafKind::Action,
            NodeKind::Condition => LeafKind::Condition,
        },
        ports: n
            .ports
            .iter()
            .map(|p| PortModel {
                name: p.name.text.clone(),
                direction: if p.out {
                    PortDirection::Output
                } else {
                    PortDirection::Input
                },
                ty: p.ty.text.clone(),
            })
            .collect(),
        formula: n.formula.as_ref().map(Formula::from_ast),
    }
}

/// The `std::kb` declarations btc itself emits, available without import.
fn kb_decl(id: &str) -> Option<NodeDecl> {
    let parsed = crate::rules::parse_rules(include_str!("../stdlib/kb.btrules"), 0);
    parsed
        .items
        .into_iter()
        .find_map(|i| match std::sync::Arc::unwrap_or_clone(i.item) {
            Item::Node(n) if n.name.text == id => Some(n),
            _ => None,
        })
}
