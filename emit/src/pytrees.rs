//! py_trees 2.x: one self-contained Python module per compiled plan.
//!
//! The module holds a small knowledge base (the problem's objects and initial
//! facts), a PDDL evaluator for the ground conditions and effects btc
//! attaches to steps, one behaviour class per leaf node type (simulated, or
//! taken from a user module), and `create_behavior_tree()`, which builds the
//! flat (inlined) tree. Every plan step is wrapped in a `KBUpdateDecorator`
//! that applies the step's PDDL effects to the knowledge base, as in the "P3
//! assembler" generator this follows. `python3 module.py` ticks the tree to
//! completion and exits 0 on SUCCESS.
//!
//! Every name and string from rules, plans and PDDL files is written as an
//! escaped Python string literal ([`py_str`]); class names are sanitized and
//! made unique ([`py_ident`], [`Names`]); comments only ever contain escaped
//! text. The output is ASCII and deterministic.

use btc_ir::{format_float, LeafKind, Node, NodeModel, Port, PortValue, StepInfo, TreeIr};
use btc_ir::{ControlKind, Count, DecoratorKind};
use btc_pddl::logic::{InitFact, Term, TypeText};
use std::collections::{BTreeMap, BTreeSet};
use std::fmt::Write;

/// Tick bound of `main()`: at least this many, more for big trees.
const MIN_TICKS: usize = 10_000;

/// The leaf ids the module implements itself in both modes (`std::kb`).
const KB_NODES: &[&str] = &["KbHolds", "KbApply", "WaitForStep"];

/// Python's hard keywords: never identifiers.
const PY_KEYWORDS: &[&str] = &[
    "False", "None", "True", "and", "as", "assert", "async", "await", "break", "class", "continue",
    "def", "del", "elif", "else", "except", "finally", "for", "from", "global", "if", "import",
    "in", "is", "lambda", "nonlocal", "not", "or", "pass", "raise", "return", "try", "while",
    "with", "yield",
];

/// Builtins and module-level names of the generated module that a generated
/// class must not shadow.
const RESERVED: &[&str] = &[
    // builtins
    "ArithmeticError",
    "AssertionError",
    "AttributeError",
    "BaseException",
    "Ellipsis",
    "Exception",
    "ImportError",
    "IndexError",
    "KeyError",
    "LookupError",
    "NameError",
    "NotImplemented",
    "NotImplementedError",
    "OverflowError",
    "RuntimeError",
    "StopIteration",
    "SystemExit",
    "TypeError",
    "ValueError",
    "ZeroDivisionError",
    "abs",
    "all",
    "any",
    "bool",
    "callable",
    "dict",
    "enumerate",
    "float",
    "frozenset",
    "getattr",
    "hasattr",
    "int",
    "isinstance",
    "iter",
    "len",
    "list",
    "map",
    "max",
    "min",
    "next",
    "object",
    "print",
    "range",
    "repr",
    "reversed",
    "round",
    "set",
    "setattr",
    "sorted",
    "str",
    "sum",
    "super",
    "tuple",
    "type",
    "zip",
    // modules
    "py_trees",
    "sys",
    "importlib",
    // the module's own names
    "GOAL",
    "INITIAL_FACTS",
    "INITIAL_FLUENTS",
    "KB",
    "KBUpdateDecorator",
    "KbApply",
    "KbHolds",
    "KnowledgeBase",
    "MAX_TICKS",
    "NODE_CLASS_NAMES",
    "NODE_MODULE",
    "OBJECTS",
    "PlanStep",
    "PREDICATE_PARAMETER_ORDER",
    "STEPS",
    "SimulatedAction",
    "SimulatedCondition",
    "ThresholdParallel",
    "WaitForStep",
    "apply_effect",
    "create_behavior_tree",
    "goal_reached",
    "holds",
    "main",
    "objects_of_type",
    "parse_pddl",
    "update_kb",
];

/// `s` as a Python string literal: double-quoted, ASCII only, no raw line
/// breaks, so it is safe anywhere a literal goes (and inside a comment).
pub fn py_str(s: &str) -> String {
    let mut out = String::with_capacity(s.len() + 2);
    out.push('"');
    for c in s.chars() {
        match c {
            '\\' => out.push_str("\\\\"),
            '"' => out.push_str("\\\""),
            '\n' => out.push_str("\\n"),
            '\r' => out.push_str("\\r"),
            '\t' => out.push_str("\\t"),
            ' '..='~' => out.push(c),
            c if (c as u32) < 0x100 => {
                let _ = write!(out, "\\x{:02x}", c as u32);
            }
            c if (c as u32) < 0x10000 => {
                let _ = write!(out, "\\u{:04x}", c as u32);
            }
            c => {
                let _ = write!(out, "\\U{:08x}", c as u32);
            }
        }
    }
    out.push('"');
    out
}

/// `s` made a Python identifier `[A-Za-z_][A-Za-z0-9_]*` for a class name:
/// other characters become `_`; a name that would start with `_` or a digit
/// gets the prefix `Node` (no dunders, no clash with the module's private
/// names); a keyword gets a trailing `_`.
pub fn py_ident(s: &str) -> String {
    let mut out: String = s
        .chars()
        .map(|c| if c.is_ascii_alphanumeric() { c } else { '_' })
        .collect();
    if !out.starts_with(|c: char| c.is_ascii_alphabetic()) {
        out.insert_str(0, "Node");
    }
    if PY_KEYWORDS.contains(&out.as_str()) {
        out.push('_');
    }
    out
}

/// Whether `s` may be written as a keyword argument as is (ASCII, so
/// Python's NFKC normalization of identifiers cannot change it).
fn is_plain_kwarg(s: &str) -> bool {
    s.starts_with(|c: char| c.is_ascii_alphabetic() || c == '_')
        && s.chars().all(|c| c.is_ascii_alphanumeric() || c == '_')
        && !PY_KEYWORDS.contains(&s)
}

/// Identifiers handed out so far; [`Names::fresh`] makes a new one unique.
#[derive(Default)]
pub struct Names {
    taken: BTreeSet<String>,
}

impl Names {
    pub fn reserving(names: &[&str]) -> Names {
        Names {
            taken: names.iter().map(|s| s.to_string()).collect(),
        }
    }

    /// [`py_ident`] of `s`, with `_2`, `_3`, ... appended while taken.
    pub fn fresh(&mut self, s: &str) -> String {
        let base = py_ident(s);
        let mut name = base.clone();
        let mut k = 2;
        while self.taken.contains(&name) {
            name = format!("{base}_{k}");
            k += 1;
        }
        self.taken.insert(name.clone());
        name
    }
}

/// A port value as a Python expression.
fn py_value(v: &PortValue) -> String {
    match v {
        PortValue::Text(s) => py_str(s),
        PortValue::Int(n) => n.to_string(),
        PortValue::Float(f) => py_float(*f),
        PortValue::Bool(b) => if *b { "True" } else { "False" }.into(),
        // An unbound parameter (a call that could not be inlined): its name.
        PortValue::Param(_) => py_str(&v.to_text()),
        PortValue::Formula(_) | PortValue::Effect(_) => py_str(&v.to_text()),
    }
}

fn py_float(f: f64) -> String {
    if f.is_nan() {
        "float(\"nan\")".into()
    } else if f.is_infinite() {
        if f > 0.0 {
            "float(\"inf\")"
        } else {
            "float(\"-inf\")"
        }
        .into()
    } else {
        format_float(f)
    }
}

// ---------------------------------------------------------------------------

/// How a leaf id is built in the module.
struct LeafClass {
    /// The Python expression naming the class.
    expr: String,
    kind: LeafKind,
    formula: Option<btc_pddl::logic::Formula>,
    /// Generated here (simulated or `std::kb`), not imported.
    generated: bool,
}

struct Emitter<'a> {
    ir: &'a TreeIr,
    out: String,
    classes: BTreeMap<String, LeafClass>,
    /// Class definitions in order: (id, class name).
    class_order: Vec<(String, String)>,
    next_var: usize,
    leaf_count: usize,
}

/// The module `node_module` names, as the expression to prefix class names
/// with and the import statement(s) making it available.
fn module_import(node_module: &str) -> (String, String) {
    // `import a.b` binds `a`: it must not replace one of the module's names.
    let first = node_module.split('.').next().unwrap_or_default();
    let plain = node_module.split('.').all(is_plain_kwarg)
        && !first.starts_with('_')
        && !RESERVED.contains(&first);
    if plain {
        (node_module.to_owned(), format!("import {node_module}\n"))
    } else {
        (
            "NODE_MODULE".into(),
            format!(
                "import importlib\n\nNODE_MODULE = importlib.import_module({})\n",
                py_str(node_module)
            ),
        )
    }
}

pub fn emit(ir: &TreeIr, node_module: Option<&str>) -> String {
    let root = ir.inlined();
    let mut e = Emitter {
        ir,
        out: String::new(),
        classes: BTreeMap::new(),
        class_order: Vec::new(),
        next_var: 0,
        leaf_count: 0,
    };
    e.plan_classes(&root, node_module);
    e.header(node_module);
    e.out.push_str(RUNTIME_PDDL);
    e.knowledge_base();
    e.out.push_str(RUNTIME_KB);
    e.steps();
    e.out.push_str(RUNTIME_NODES);
    e.leaf_classes();
    e.tree(&root);
    let max_ticks = MIN_TICKS.max(e.leaf_count * 20);
    let _ = write!(
        e.out,
        "{}",
        RUNTIME_MAIN.replace("@MAX_TICKS@", &max_ticks.to_string())
    );
    e.out
}

impl Emitter<'_> {
    /// Assigns every leaf id a class: `std::kb` ids their fixed class, the
    /// others a sanitized, unique name (generated, or in `node_module`).
    fn plan_classes(&mut self, root: &Node, node_module: Option<&str>) {
        let mut models: Vec<NodeModel> = self.ir.nodes.clone();
        // Leaves whose model is missing still get a class.
        root.walk(&mut |n| {
            if let Node::Leaf { leaf, id, .. } = n {
                if !models.iter().any(|m| m.id == *id) {
                    models.push(NodeModel {
                        id: id.clone(),
                        kind: *leaf,
                        ports: Vec::new(),
                        formula: None,
                    });
                }
            }
        });
        let mut names = Names::reserving(RESERVED);
        let prefix = node_module.map(|m| module_import(m).0);
        for m in models {
            if self.classes.contains_key(&m.id) {
                continue;
            }
            let class = if KB_NODES.contains(&m.id.as_str()) {
                LeafClass {
                    expr: m.id.clone(),
                    kind: m.kind,
                    formula: None,
                    generated: true,
                }
            } else {
                let name = names.fresh(&m.id);
                self.class_order.push((m.id.clone(), name.clone()));
                match &prefix {
                    Some(p) => LeafClass {
                        expr: format!("{p}.{name}"),
                        kind: m.kind,
                        formula: m.formula.clone(),
                        generated: false,
                    },
                    None => LeafClass {
                        expr: name,
                        kind: m.kind,
                        formula: m.formula.clone(),
                        generated: true,
                    },
                }
            };
            self.classes.insert(m.id.clone(), class);
        }
    }

    fn header(&mut self, node_module: Option<&str>) {
        let ir = self.ir;
        let o = &mut self.out;
        o.push_str("#!/usr/bin/env python3\n");
        o.push_str("# A py_trees 2.x behaviour tree generated by btc. Do not edit.\n");
        let _ = writeln!(o, "# domain:  {}", py_str(&ir.domain));
        let _ = writeln!(o, "# problem: {}", py_str(&ir.problem));
        o.push_str(
            "#\n\
             # Run it with `python3 <this file>`: it ticks the tree until it is no\n\
             # longer RUNNING, prints the final status and whether the goal holds in\n\
             # the knowledge base, and exits 0 on SUCCESS, 1 otherwise.\n",
        );
        match node_module {
            Some(m) => {
                let _ = writeln!(
                    o,
                    "#\n# Leaf behaviours come from the module {}: each class in\n\
                     # NODE_CLASS_NAMES is constructed as `Class(node_name, **ports)`.",
                    py_str(m)
                );
            }
            None => o.push_str(
                "#\n# Leaf behaviours are simulated: an action is RUNNING on its first tick\n\
                 # and SUCCESS on the next; a condition evaluates its formula on the KB.\n",
            ),
        }
        o.push_str(
            "#\n# Needs py_trees 2.2 or later (tested with 2.2.3 and 2.6.0).\n\
             \nimport sys\n\nimport py_trees\n\n\
             if not hasattr(py_trees.decorators, \"Repeat\"):\n    \
             sys.exit(\"this module needs py_trees >= 2.2: pip install -U py_trees\")\n",
        );
        if let Some(m) = node_module {
            let (_, import) = module_import(m);
            o.push_str(&import);
        }
    }

    fn knowledge_base(&mut self) {
        let w = &self.ir.world;
        let o = &mut self.out;
        o.push_str(
            "\n\n# ---------------------------------------------------------------------------\n\
             # The problem: objects with their type, initial facts, goal\n\n",
        );
        o.push_str("OBJECTS = {\n");
        for obj in &w.objects {
            let ty = TypeText(&obj.types).to_string();
            let _ = writeln!(o, "    {}: {},", py_str(&obj.name), py_str(&ty));
        }
        o.push_str("}\n\n");

        let tuple = |head: &str, args: &[Term]| -> String {
            let mut items = vec![py_str(head)];
            items.extend(args.iter().map(|t| py_str(&t.to_string())));
            let comma = if items.len() == 1 { "," } else { "" };
            format!("({}{comma})", items.join(", "))
        };
        o.push_str("INITIAL_FACTS = frozenset(\n    [\n");
        for f in &w.init {
            if let InitFact::Atom(a) = f {
                let _ = writeln!(o, "        {},", tuple(&a.pred, &a.args));
            }
        }
        o.push_str("    ]\n)\n\n");
        o.push_str("# Numeric fluents, by ground application, with their initial values.\nINITIAL_FLUENTS = {\n");
        for f in &w.init {
            if let InitFact::Value(a, v) = f {
                let _ = writeln!(o, "    {}: {},", tuple(&a.pred, &a.args), py_float(*v));
            }
        }
        o.push_str("}\n\n");
        o.push_str(
            "# Each predicate's parameter positions, in the order facts store them.\n\
             PREDICATE_PARAMETER_ORDER = {\n",
        );
        let mut preds: Vec<_> = w.predicates.iter().collect();
        preds.sort_by(|a, b| a.name.cmp(&b.name));
        preds.dedup_by(|a, b| a.name == b.name);
        for p in preds {
            let positions: Vec<String> = (0..p.params.len()).map(|i| i.to_string()).collect();
            let _ = writeln!(o, "    {}: [{}],", py_str(&p.name), positions.join(", "));
        }
        o.push_str("}\n\n");
        let _ = writeln!(
            o,
            "GOAL = {}",
            w.goal.as_ref().map_or_else(
                || "None".into(),
                |g| format!("parse_pddl({})", py_str(&g.to_string()))
            )
        );
    }

    fn steps(&mut self) {
        let o = &mut self.out;
        o.push_str("\n\n# The plan's steps (0-based `index`), with their ground conditions and\n# effects; KBUpdateDecorator and WaitForStep read them.\nSTEPS = [\n");
        for s in &self.ir.steps {
            o.push_str(&step_literal(s));
        }
        o.push_str("]\n");
    }

    fn leaf_classes(&mut self) {
        let o = &mut self.out;
        o.push_str(
            "\n\n# ---------------------------------------------------------------------------\n\
             # Leaf behaviours, by node id\n\n",
        );
        o.push_str("NODE_CLASS_NAMES = {\n");
        for (id, name) in &self.class_order {
            let _ = writeln!(o, "    {}: {},", py_str(id), py_str(name));
        }
        o.push_str("}\n");
        for (id, name) in &self.class_order {
            let class = &self.classes[id];
            if !class.generated {
                continue;
            }
            let base = match class.kind {
                LeafKind::Action => "SimulatedAction",
                LeafKind::Condition => "SimulatedCondition",
            };
            let _ = write!(
                o,
                "\n\nclass {name}({base}):\n    NODE_ID = {}\n",
                py_str(id)
            );
            if let Some(f) = &class.formula {
                let _ = writeln!(o, "    FORMULA = parse_pddl({})", py_str(&f.to_string()));
            }
        }
    }

    fn tree(&mut self, root: &Node) {
        self.out.push_str(
            "\n\n# ---------------------------------------------------------------------------\n\
             # The tree\n\n\ndef create_behavior_tree():\n    \
             \"\"\"Builds the behaviour tree and returns its root.\"\"\"\n",
        );
        let var = self.node(root);
        let _ = writeln!(self.out, "    return {var}");
    }

    fn var(&mut self) -> String {
        self.next_var += 1;
        format!("_n{}", self.next_var)
    }

    /// Emits the statements building `n` (children first); returns its variable.
    fn node(&mut self, n: &Node) -> String {
        match n {
            Node::Control {
                control,
                name,
                children,
            } => {
                let kids: Vec<String> = children.iter().map(|c| self.node(c)).collect();
                let kids = kids.join(", ");
                let v = self.var();
                let name = py_str(name.as_deref().unwrap_or(control_name(*control)));
                let expr = match *control {
                    ControlKind::Sequence => format!(
                        "py_trees.composites.Sequence(name={name}, memory=True, children=[{kids}])"
                    ),
                    ControlKind::ReactiveSequence => format!(
                        "py_trees.composites.Sequence(name={name}, memory=False, children=[{kids}])"
                    ),
                    ControlKind::Fallback => format!(
                        "py_trees.composites.Selector(name={name}, memory=True, children=[{kids}])"
                    ),
                    ControlKind::ReactiveFallback => format!(
                        "py_trees.composites.Selector(name={name}, memory=False, children=[{kids}])"
                    ),
                    ControlKind::Parallel { success, failure } => {
                        let count = children.len();
                        if success as usize >= count {
                            format!(
                                "py_trees.composites.Parallel(name={name}, \
                                 policy=py_trees.common.ParallelPolicy.SuccessOnAll(synchronise=True), \
                                 children=[{kids}])"
                            )
                        } else if success == 1 && failure == 1 {
                            format!(
                                "py_trees.composites.Parallel(name={name}, \
                                 policy=py_trees.common.ParallelPolicy.SuccessOnOne(), \
                                 children=[{kids}])"
                            )
                        } else {
                            format!(
                                "ThresholdParallel(name={name}, success={success}, \
                                 failure={failure}, children=[{kids}])"
                            )
                        }
                    }
                };
                let _ = writeln!(self.out, "    {v} = {expr}");
                v
            }
            Node::Decorator {
                decorator,
                name,
                child,
            } => {
                let label = py_str(&name.clone().unwrap_or_else(|| decorator_name(decorator)));
                // BT.CPP ticks nothing under retry(0) / repeat(0).
                match decorator {
                    DecoratorKind::Retry {
                        times: Count::Fixed(0),
                    } => return self.constant("Failure", &label, "retry(0) never ticks its child"),
                    DecoratorKind::Repeat {
                        times: Count::Fixed(0),
                    } => {
                        return self.constant("Success", &label, "repeat(0) never ticks its child")
                    }
                    // py_trees takes the number when the tree is built.
                    _ if decorator.count().is_some_and(|c| c.fixed().is_none()) => {
                        return self.constant(
                            "Failure",
                            &label,
                            "a decorator count from a call btc could not inline",
                        )
                    }
                    _ => {}
                }
                let c = self.node(child);
                let v = self.var();
                let n = |c: &Count| c.fixed().unwrap_or_default();
                let expr = match decorator {
                    DecoratorKind::Retry { times } => format!(
                        "py_trees.decorators.Retry(name={label}, child={c}, num_failures={})",
                        n(times)
                    ),
                    DecoratorKind::Repeat { times } => format!(
                        "py_trees.decorators.Repeat(name={label}, child={c}, num_success={})",
                        n(times)
                    ),
                    DecoratorKind::Timeout { ms } => format!(
                        "py_trees.decorators.Timeout(name={label}, child={c}, duration={})",
                        format_float(n(ms) as f64 / 1000.0)
                    ),
                    DecoratorKind::Inverter => {
                        format!("py_trees.decorators.Inverter(name={label}, child={c})")
                    }
                    DecoratorKind::ForceSuccess => {
                        format!("py_trees.decorators.FailureIsSuccess(name={label}, child={c})")
                    }
                    DecoratorKind::ForceFailure => {
                        format!("py_trees.decorators.SuccessIsFailure(name={label}, child={c})")
                    }
                };
                let _ = writeln!(self.out, "    {v} = {expr}");
                v
            }
            Node::Leaf {
                id, name, ports, ..
            } => {
                self.leaf_count += 1;
                let v = self.var();
                let class = &self.classes[id].expr;
                let label = py_str(name.as_deref().unwrap_or(id));
                let _ = writeln!(self.out, "    {v} = {class}({label}{})", kwargs(ports));
                v
            }
            Node::Step { step, child } => {
                let display = self
                    .ir
                    .steps
                    .get(*step)
                    .map_or_else(|| "(?)".into(), StepInfo::display);
                let label = format!("step {}: {display}", step + 1);
                let _ = writeln!(self.out, "    # {}", py_str(&label));
                let c = self.node(child);
                let v = self.var();
                let _ = writeln!(
                    self.out,
                    "    {v} = KBUpdateDecorator(name={}, child={c}, step={step})",
                    py_str(&label)
                );
                v
            }
            Node::SubTree { id, .. } => {
                let label = py_str(&format!("unresolved subtree {id}"));
                self.constant("Failure", &label, "a call btc could not inline")
            }
        }
    }

    fn constant(&mut self, which: &str, label: &str, why: &str) -> String {
        let v = self.var();
        let _ = writeln!(
            self.out,
            "    {v} = py_trees.behaviours.{which}(name={label})  # {why}"
        );
        v
    }
}

/// `, port=value, ...`; ports that are not plain identifiers go in a
/// `**{"...": value}` splat.
fn kwargs(ports: &[Port]) -> String {
    let mut plain = String::new();
    let mut other = Vec::new();
    for p in ports {
        if is_plain_kwarg(&p.name) {
            let _ = write!(plain, ", {}={}", p.name, py_value(&p.value));
        } else {
            other.push(format!("{}: {}", py_str(&p.name), py_value(&p.value)));
        }
    }
    if !other.is_empty() {
        let _ = write!(plain, ", **{{{}}}", other.join(", "));
    }
    plain
}

fn step_literal(s: &StepInfo) -> String {
    let mut out = format!(
        "    PlanStep(\n        index={},\n        action={},\n",
        s.index,
        py_str(&s.display())
    );
    let conditions = [
        ("pre_start", &s.pre_start),
        ("pre_over_all", &s.pre_over_all),
        ("pre_end", &s.pre_end),
    ];
    for (key, f) in conditions {
        if let Some(f) = f {
            let _ = writeln!(out, "        {key}={},", py_str(&f.to_string()));
        }
    }
    for (key, e) in [("eff_start", &s.eff_start), ("eff_end", &s.eff_end)] {
        if let Some(e) = e {
            let _ = writeln!(out, "        {key}={},", py_str(&e.to_string()));
        }
    }
    if let Some(d) = s.duration {
        let _ = writeln!(out, "        duration={},", py_float(d));
    }
    if s.skipped {
        out.push_str("        skipped=True,\n");
    }
    if !s.after.is_empty() {
        let after: Vec<String> = s.after.iter().map(usize::to_string).collect();
        let _ = writeln!(out, "        after=[{}],", after.join(", "));
    }
    out.push_str("    ),\n");
    out
}

fn control_name(c: ControlKind) -> &'static str {
    match c {
        ControlKind::Sequence => "Sequence",
        ControlKind::ReactiveSequence => "ReactiveSequence",
        ControlKind::Fallback => "Fallback",
        ControlKind::ReactiveFallback => "ReactiveFallback",
        ControlKind::Parallel { .. } => "Parallel",
    }
}

fn decorator_name(d: &DecoratorKind) -> String {
    match d {
        DecoratorKind::Retry { times } => format!("Retry({times})"),
        DecoratorKind::Repeat { times } => format!("Repeat({times})"),
        DecoratorKind::Timeout { ms } => format!("Timeout({ms} ms)"),
        DecoratorKind::Inverter => "Inverter".into(),
        DecoratorKind::ForceSuccess => "ForceSuccess".into(),
        DecoratorKind::ForceFailure => "ForceFailure".into(),
    }
}

// ---------------------------------------------------------------------------
// The fixed parts of the module.

const RUNTIME_PDDL: &str = r##"

# ---------------------------------------------------------------------------
# A small PDDL evaluator. Formulas and effects are ground PDDL text parsed once
# into nested tuples: "(on a b)" -> ("on", "a", "b"). Names are lower-cased
# (PDDL is case-insensitive). Conditions may use and, or, not, imply, =,
# exists, forall and numeric comparisons; effects and, not, forall, when and
# assign / increase / decrease / scale-up / scale-down.

_NUMERIC_OPS = ("+", "-", "*", "/")
_COMPARISONS = ("<", "<=", ">", ">=")
_NUMERIC_EFFECTS = ("assign", "increase", "decrease", "scale-up", "scale-down")


def parse_pddl(text):
    """Parses one PDDL expression into nested tuples of lower-case names."""
    tokens = text.replace("(", " ( ").replace(")", " ) ").lower().split()
    stack = [[]]
    for token in tokens:
        if token == "(":
            stack.append([])
        elif token == ")":
            if len(stack) == 1:
                raise ValueError("unbalanced ')' in PDDL text %r" % (text,))
            done = tuple(stack.pop())
            stack[-1].append(done)
        else:
            stack[-1].append(token)
    if len(stack) != 1 or len(stack[0]) != 1:
        raise ValueError("expected one PDDL expression in %r" % (text,))
    return stack[0][0]


def _as_fact(expr):
    return expr if isinstance(expr, tuple) else (expr,)


def _term(term, env):
    if env and isinstance(term, str) and term in env:
        return env[term]
    return term


def _ground(atom, env):
    """An atom with its ?variables replaced: a fact tuple."""
    return tuple(_term(t, env) for t in _as_fact(atom))


def _typed_vars(spec):
    """`(?x ?y - t ?z)` -> [("?x", "t"), ("?y", "t"), ("?z", "object")]."""
    items = list(spec) if isinstance(spec, tuple) else [spec]
    out, pending, i = [], [], 0
    while i < len(items):
        if items[i] == "-" and i + 1 < len(items):
            out.extend((v, items[i + 1]) for v in pending)
            pending = []
            i += 2
        else:
            pending.append(items[i])
            i += 1
    out.extend((v, "object") for v in pending)
    return out


def objects_of_type(ty):
    """The objects of type `ty` (a name or `(either ...)`).

    Limitation: btc gives each object only its own (leaf) type, not the type
    hierarchy, so `object` means every object and any other type matches
    exactly: a quantifier over a supertype sees only objects declared with
    that very type.
    """
    names = set(ty[1:]) if isinstance(ty, tuple) and ty[:1] == ("either",) else {ty}
    if "object" in names:
        return list(_OBJECT_TYPES)
    return [o for o, t in _OBJECT_TYPES.items() if t in names]


def _bindings(spec, env):
    envs = [dict(env or {})]
    for var, ty in _typed_vars(spec):
        envs = [dict(e, **{var: o}) for e in envs for o in objects_of_type(ty)]
    return envs


def _number(kb, expr, env):
    if isinstance(expr, (int, float)):
        return float(expr)
    if isinstance(expr, str):
        value = _term(expr, env)
        if isinstance(value, (int, float)):
            return float(value)
        try:
            return float(value)
        except ValueError:
            return kb.fluents.get((value,), 0.0)
    head = expr[0] if expr else None
    try:
        if head in _NUMERIC_OPS and len(expr) == 3:
            a, b = _number(kb, expr[1], env), _number(kb, expr[2], env)
            if head == "+":
                return a + b
            if head == "-":
                return a - b
            if head == "*":
                return a * b
            return a / b
        if head == "-" and len(expr) == 2:
            return -_number(kb, expr[1], env)
    except ZeroDivisionError:
        return float("nan")
    return kb.fluents.get(_ground(expr, env), 0.0)


def _is_name(term):
    if not isinstance(term, str):
        return False
    try:
        float(term)
    except ValueError:
        return True
    return False


def holds(kb, formula, env=None):
    """Whether `formula` holds in `kb`, with `env` binding ?variables."""
    if isinstance(formula, str):
        return (_term(formula, env),) in kb.facts
    if not formula:
        return True
    head, args = formula[0], formula[1:]
    if head == "and":
        return all(holds(kb, a, env) for a in args)
    if head == "or":
        return any(holds(kb, a, env) for a in args)
    if head == "not" and len(args) == 1:
        return not holds(kb, args[0], env)
    if head == "imply" and len(args) == 2:
        return not holds(kb, args[0], env) or holds(kb, args[1], env)
    if head == "exists" and len(args) == 2:
        return any(holds(kb, args[1], e) for e in _bindings(args[0], env))
    if head == "forall" and len(args) == 2:
        return all(holds(kb, args[1], e) for e in _bindings(args[0], env))
    if head == "=" and len(args) == 2:
        a, b = _term(args[0], env), _term(args[1], env)
        if _is_name(a) and _is_name(b):
            return a == b
        return _number(kb, args[0], env) == _number(kb, args[1], env)
    if head in _COMPARISONS and len(args) == 2:
        a, b = _number(kb, args[0], env), _number(kb, args[1], env)
        if head == "<":
            return a < b
        if head == "<=":
            return a <= b
        if head == ">":
            return a > b
        return a >= b
    return _ground(formula, env) in kb.facts


def _collect(kb, effect, env, adds, deletes, numeric):
    if isinstance(effect, str) or not effect:
        if effect:
            adds.append(_ground(effect, env))
        return
    head, args = effect[0], effect[1:]
    if head == "and":
        for a in args:
            _collect(kb, a, env, adds, deletes, numeric)
    elif head == "not" and len(args) == 1:
        deletes.append(_ground(args[0], env))
    elif head == "forall" and len(args) == 2:
        for e in _bindings(args[0], env):
            _collect(kb, args[1], e, adds, deletes, numeric)
    elif head == "when" and len(args) == 2:
        if holds(kb, args[0], env):
            _collect(kb, args[1], env, adds, deletes, numeric)
    elif head in _NUMERIC_EFFECTS and len(args) == 2:
        numeric.append((head, _ground(args[0], env), _number(kb, args[1], env)))
    else:
        adds.append(_ground(effect, env))


def apply_effect(kb, effect, env=None):
    """Applies a PDDL effect: every part is evaluated in the state before it,
    then deletes are applied before adds (PDDL semantics)."""
    adds, deletes, numeric = [], [], []
    _collect(kb, effect, env, adds, deletes, numeric)
    for fact in deletes:
        update_kb(kb, fact[0], fact[1:], False)
    for fact in adds:
        update_kb(kb, fact[0], fact[1:], True)
    for op, fluent, value in numeric:
        old = kb.fluents.get(fluent, 0.0)
        if op == "assign":
            new = value
        elif op == "increase":
            new = old + value
        elif op == "decrease":
            new = old - value
        elif op == "scale-up":
            new = old * value
        else:
            new = old / value if value else float("nan")
        kb.fluents[fluent] = new
"##;

const RUNTIME_KB: &str = r##"

# ---------------------------------------------------------------------------
# The knowledge base: the current PDDL state


_OBJECT_TYPES = {name.lower(): ty.lower() for name, ty in OBJECTS.items()}


def update_kb(kb, predicate, args, value):
    """Makes one fact true (`value`) or false. `args` are in the order of
    PREDICATE_PARAMETER_ORDER; an arity it does not expect is reported."""
    args = tuple(args)
    order = PREDICATE_PARAMETER_ORDER.get(predicate)
    if order is not None:
        if len(order) == len(args):
            args = tuple(args[i] for i in order)
        else:
            sys.stderr.write(
                "warning: %r takes %d arguments, got %r\n" % (predicate, len(order), args)
            )
    fact = (predicate,) + args
    if value:
        kb.facts.add(fact)
    else:
        kb.facts.discard(fact)


class KnowledgeBase:
    """The facts (tuples) and numeric fluents true now, and which plan steps
    have started and finished."""

    def __init__(self):
        self.reset()

    def reset(self):
        self.facts = set(INITIAL_FACTS)
        self.fluents = dict(INITIAL_FLUENTS)
        self.started_steps = set()
        self.finished_steps = set()

    def holds(self, formula, env=None):
        return holds(self, formula, env)

    def apply(self, effect, env=None):
        apply_effect(self, effect, env)


KB = KnowledgeBase()


def goal_reached(kb=None):
    """Whether the problem's goal holds (True when it has none)."""
    return GOAL is None or holds(kb or KB, GOAL)


class PlanStep:
    """One plan step: its conditions and effects, parsed."""

    def __init__(
        self,
        index,
        action,
        pre_start=None,
        pre_over_all=None,
        pre_end=None,
        eff_start=None,
        eff_end=None,
        duration=None,
        skipped=False,
        after=(),
    ):
        def parsed(text):
            return None if text is None else parse_pddl(text)

        self.index = index
        self.action = action
        self.pre_start = parsed(pre_start)
        self.pre_over_all = parsed(pre_over_all)
        self.pre_end = parsed(pre_end)
        self.eff_start = parsed(eff_start)
        self.eff_end = parsed(eff_end)
        self.duration = duration
        self.skipped = skipped
        self.after = tuple(after)
        # `?duration` in a durative action's effects.
        self.env = {} if duration is None else {"?duration": duration}
"##;

const RUNTIME_NODES: &str = r##"

# ---------------------------------------------------------------------------
# Behaviours that read and write the knowledge base


def _warn(message):
    sys.stderr.write("warning: %s\n" % (message,))


class KBUpdateDecorator(py_trees.decorators.Decorator):
    """The boundary of a plan step: applies the step's at-start effects when
    its subtree first starts and its at-end effects when the subtree first
    succeeds (each once), and records the step as started / finished."""

    def __init__(self, name, child, step):
        super().__init__(name=name, child=child)
        self.step = STEPS[step]

    def initialise(self):
        step = self.step
        if step.index in KB.started_steps:
            return
        KB.started_steps.add(step.index)
        if step.pre_start is not None and not KB.holds(step.pre_start, step.env):
            _warn("step %d %s starts but its precondition does not hold" % (step.index + 1, step.action))
        if step.eff_start is not None:
            KB.apply(step.eff_start, step.env)

    def update(self):
        status = self.decorated.status
        step = self.step
        if status == py_trees.common.Status.SUCCESS and step.index not in KB.finished_steps:
            if step.pre_end is not None and not KB.holds(step.pre_end, step.env):
                _warn("step %d %s ends but its end condition does not hold" % (step.index + 1, step.action))
            if step.eff_end is not None:
                KB.apply(step.eff_end, step.env)
            KB.finished_steps.add(step.index)
        return status


def _port_text(value):
    """A port value as a PDDL name."""
    if isinstance(value, bool):
        return "true" if value else "false"
    return str(value).lower()


class SimulatedAction(py_trees.behaviour.Behaviour):
    """A stand-in for a robot action: RUNNING on its first tick, SUCCESS on
    the next."""

    NODE_ID = None

    def __init__(self, name, /, **ports):
        super().__init__(name=name)
        self.ports = ports
        self._ticks = 0

    def initialise(self):
        self._ticks = 0

    def update(self):
        self._ticks += 1
        if self._ticks == 1:
            return py_trees.common.Status.RUNNING
        return py_trees.common.Status.SUCCESS


class SimulatedCondition(py_trees.behaviour.Behaviour):
    """A condition: its FORMULA (PDDL over ?port variables) evaluated on the
    knowledge base with the port values substituted; SUCCESS without one."""

    NODE_ID = None
    FORMULA = None

    def __init__(self, name, /, **ports):
        super().__init__(name=name)
        self.ports = ports
        self.env = {"?" + str(k).lower(): _port_text(v) for k, v in ports.items()}

    def update(self):
        if self.FORMULA is None or KB.holds(self.FORMULA, self.env):
            return py_trees.common.Status.SUCCESS
        return py_trees.common.Status.FAILURE


class _KbNode(py_trees.behaviour.Behaviour):
    def __init__(self, name, text):
        super().__init__(name=name)
        try:
            self.expr = parse_pddl(str(text))
            self.error = None
        except ValueError as e:
            self.expr = None
            self.error = str(e)


class KbHolds(_KbNode):
    """std::kb KbHolds: SUCCESS when `formula` holds in the KB."""

    def __init__(self, name, /, formula="", **ports):
        super().__init__(name, formula)

    def update(self):
        if self.expr is None:
            self.feedback_message = self.error
            return py_trees.common.Status.FAILURE
        if KB.holds(self.expr):
            return py_trees.common.Status.SUCCESS
        return py_trees.common.Status.FAILURE


class KbApply(_KbNode):
    """std::kb KbApply: applies `effect` to the KB; SUCCESS."""

    def __init__(self, name, /, effect="", **ports):
        super().__init__(name, effect)

    def update(self):
        if self.expr is None:
            self.feedback_message = self.error
            return py_trees.common.Status.FAILURE
        KB.apply(self.expr)
        return py_trees.common.Status.SUCCESS


class WaitForStep(py_trees.behaviour.Behaviour):
    """std::kb WaitForStep: RUNNING until plan step `step` (1-based) has
    finished; a skipped step counts as finished."""

    def __init__(self, name, /, step=0, **ports):
        super().__init__(name=name)
        try:
            self.index = int(step) - 1
        except (TypeError, ValueError):
            self.index = -1

    def update(self):
        if not 0 <= self.index < len(STEPS):
            self.feedback_message = "no such step"
            return py_trees.common.Status.FAILURE
        if self.index in KB.finished_steps or STEPS[self.index].skipped:
            return py_trees.common.Status.SUCCESS
        return py_trees.common.Status.RUNNING


class ThresholdParallel(py_trees.composites.Composite):
    """A BT.CPP-style parallel for thresholds py_trees' policies lack: ticks
    every unfinished child each tick; SUCCESS once `success` children have
    succeeded, FAILURE once `failure` children have failed or enough have
    failed that `success` is out of reach. Finished children are not ticked
    again until the parallel restarts; running ones are stopped when it ends."""

    def __init__(self, name, success, failure, children=None):
        super().__init__(name=name, children=children)
        self.success = success
        self.failure = failure

    def tick(self):
        done = (py_trees.common.Status.SUCCESS, py_trees.common.Status.FAILURE)
        if self.status != py_trees.common.Status.RUNNING:
            for child in self.children:
                if child.status != py_trees.common.Status.INVALID:
                    child.stop(py_trees.common.Status.INVALID)
            self.current_child = None
            self.initialise()
        for child in self.children:
            if child.status not in done:
                yield from child.tick()
        succeeded = sum(1 for c in self.children if c.status == py_trees.common.Status.SUCCESS)
        failed = sum(1 for c in self.children if c.status == py_trees.common.Status.FAILURE)
        need = min(self.success, len(self.children))
        if succeeded >= need:
            new_status = py_trees.common.Status.SUCCESS
        elif failed >= self.failure or len(self.children) - failed < need:
            new_status = py_trees.common.Status.FAILURE
        else:
            new_status = py_trees.common.Status.RUNNING
        self.current_child = self.children[-1] if self.children else None
        if new_status != py_trees.common.Status.RUNNING:
            self.stop(new_status)
        self.status = new_status
        yield self

    def stop(self, new_status=py_trees.common.Status.INVALID):
        for child in self.children:
            if child.status == py_trees.common.Status.RUNNING:
                child.stop(py_trees.common.Status.INVALID)
        py_trees.composites.Composite.stop(self, new_status)
"##;

const RUNTIME_MAIN: &str = r##"

# ---------------------------------------------------------------------------

MAX_TICKS = @MAX_TICKS@


def main():
    """Ticks the tree until it is no longer RUNNING (at most MAX_TICKS times)
    and exits 0 on SUCCESS, 1 otherwise."""
    KB.reset()
    root = create_behavior_tree()
    tree = py_trees.trees.BehaviourTree(root)
    tree.setup()
    ticks = 0
    while ticks < MAX_TICKS:
        tree.tick()
        ticks += 1
        if root.status != py_trees.common.Status.RUNNING:
            break
    print("ticks: %d" % ticks)
    print("final status: %s" % root.status.name)
    print("goal reached: %s" % goal_reached())
    sys.exit(0 if root.status == py_trees.common.Status.SUCCESS else 1)


if __name__ == "__main__":
    main()
"##;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn strings_are_escaped() {
        assert_eq!(py_str("plain"), "\"plain\"");
        assert_eq!(py_str("a\"b"), "\"a\\\"b\"");
        assert_eq!(py_str("a'b"), "\"a'b\"");
        assert_eq!(py_str("'''"), "\"'''\"");
        assert_eq!(py_str("\"\"\""), "\"\\\"\\\"\\\"\"");
        assert_eq!(py_str("back\\slash"), "\"back\\\\slash\"");
        assert_eq!(py_str("\\"), "\"\\\\\"");
        assert_eq!(py_str("line\nbreak\r\t"), "\"line\\nbreak\\r\\t\"");
        assert_eq!(py_str("</script>"), "\"</script>\"");
        assert_eq!(py_str("ü"), "\"\\xfc\"");
        assert_eq!(py_str("日本"), "\"\\u65e5\\u672c\"");
        assert_eq!(py_str("🤖"), "\"\\U0001f916\"");
        assert_eq!(py_str("\0\u{7f}\u{2028}"), "\"\\x00\\x7f\\u2028\"");
        assert_eq!(py_str(""), "\"\"");
    }

    #[test]
    fn escaped_strings_are_one_ascii_line() {
        let hostile = "x\"\"\"y'''z\\\n# comment\r\n</b>\u{2028}\u{85}ü日本\\";
        let lit = py_str(hostile);
        assert!(lit.is_ascii());
        assert!(!lit.contains('\n') && !lit.contains('\r'));
        assert!(lit.starts_with('"') && lit.ends_with('"'));
        // No unescaped quote inside: every `"` in the body follows a `\`
        // that is itself not escaped.
        let body = &lit[1..lit.len() - 1];
        let mut escaped = false;
        for c in body.chars() {
            if escaped {
                escaped = false;
            } else if c == '\\' {
                escaped = true;
            } else {
                assert_ne!(c, '"', "unescaped quote in {lit}");
            }
        }
        assert!(!escaped, "dangling backslash in {lit}");
    }

    #[test]
    fn identifiers_are_sanitized() {
        assert_eq!(py_ident("MoveTo"), "MoveTo");
        assert_eq!(py_ident("move_to2"), "move_to2");
        assert_eq!(py_ident("Move-To"), "Move_To");
        assert_eq!(py_ident("3d"), "Node3d");
        assert_eq!(py_ident(""), "Node");
        assert_eq!(py_ident("_private"), "Node_private");
        assert_eq!(py_ident("__name__"), "Node__name__");
        assert_eq!(py_ident("class"), "class_");
        assert_eq!(py_ident("None"), "None_");
        assert_eq!(py_ident("a\"b'''c\"\"\"d"), "a_b___c___d");
        assert_eq!(py_ident("x\ny</z>"), "x_y__z_");
        assert_eq!(py_ident("Größe"), "Gr__e");
        assert_eq!(py_ident("日本"), "Node__");
        assert_eq!(py_ident("a\\b"), "a_b");
        for s in ["", "日本", "\"", "1", "a b", "\n", "if", "🤖x"] {
            let id = py_ident(s);
            assert!(id.starts_with(|c: char| c.is_ascii_alphabetic()), "{id}");
            assert!(id.chars().all(|c| c.is_ascii_alphanumeric() || c == '_'));
            assert!(!PY_KEYWORDS.contains(&id.as_str()));
        }
    }

    #[test]
    fn identifiers_are_unique() {
        let mut names = Names::reserving(RESERVED);
        assert_eq!(names.fresh("Move-To"), "Move_To");
        assert_eq!(names.fresh("Move To"), "Move_To_2");
        assert_eq!(names.fresh("Move_To"), "Move_To_3");
        assert_eq!(names.fresh("日本"), "Node__");
        assert_eq!(names.fresh("中国"), "Node___2");
        // Names the module uses itself are never handed out.
        assert_eq!(names.fresh("print"), "print_2");
        assert_eq!(names.fresh("KnowledgeBase"), "KnowledgeBase_2");
        assert_eq!(names.fresh("py_trees"), "py_trees_2");
    }

    #[test]
    fn keyword_arguments_fall_back_to_a_splat() {
        let port = |name: &str, v: &str| Port {
            name: name.into(),
            value: PortValue::Text(v.into()),
        };
        assert_eq!(kwargs(&[port("robot", "r1")]), ", robot=\"r1\"");
        assert_eq!(
            kwargs(&[port("a", "x"), port("class", "y"), port("größe", "z\n")]),
            ", a=\"x\", **{\"class\": \"y\", \"gr\\xf6\\xdfe\": \"z\\n\"}"
        );
    }

    #[test]
    fn module_names_are_imported_safely() {
        assert_eq!(
            module_import("my_nodes"),
            ("my_nodes".into(), "import my_nodes\n".into())
        );
        assert_eq!(module_import("pkg.nodes").0, "pkg.nodes");
        for clash in ["sys", "KB", "py_trees.x", "_warn", "main"] {
            assert_eq!(module_import(clash).0, "NODE_MODULE", "{clash}");
        }
        let (prefix, import) = module_import("my-nodes\"\nimport os");
        assert_eq!(prefix, "NODE_MODULE");
        assert!(import.contains("importlib.import_module(\"my-nodes\\\"\\nimport os\")"));
    }
}
