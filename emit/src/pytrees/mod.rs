//! py_trees 2.x: one Python module per compiled plan.
//!
//! The module is data and leaf classes: the world (`WORLD`: types, objects,
//! derived rules, initial facts and values, goal), the plan's steps
//! (`SHAPES`, `STEPS`: conditions and effects lifted over the step's
//! arguments, so steps of one action share them), the tree as nested tuples
//! (`ROOT`, and `TREES`, one per rule, expanded when the tree is built), and
//! one documented class per leaf node type, derived from the runtime's
//! `Action` / `Condition` (or taken from the user's `--node-module`). The
//! meaning lives in `emit/python/btc_runtime.py`, which is pasted into the
//! module (`Runtime::Inline`) or imported (`Runtime::Import`). Importing the
//! module has no side effects; `python3 module.py` runs it (`main`).
//!
//! The output is ASCII and deterministic; every name and string is an
//! escaped literal ([`names::py_str`]).

mod encode;
pub mod names;

use crate::sink::{Handover, Sink};
use crate::sizing::{steps_with_nodes, StepSizer, SAMPLE_STEPS};
use crate::Part;
use btc_ir::vocab::{NodeSpec, PyTrees};
use btc_ir::Count;
use btc_ir::{push_int, Label, LabelPart, LeafKind, Node, NodeModel, Port, StepInfo, TreeIr};
use btc_pddl::logic::InitFact;
use names::{is_plain_kwarg, RESERVED};
pub use names::{push_py_str, py_ident, py_str, Names};
use std::collections::HashMap;
use std::fmt::Write;
use std::sync::Arc;

/// The runtime, as written in the project (linted and unit-tested there).
pub const RUNTIME: &str = include_str!("../../python/btc_runtime.py");

/// The module name of the runtime when it is imported.
pub const RUNTIME_MODULE: &str = "btc_runtime";

/// Tick bound of `main()`: at least this many, more for big trees.
const MIN_TICKS: usize = 10_000;

/// The leaf ids the runtime implements (`std::kb`, and the `std::btcpp`
/// leaves btc's engine implements).
const RUNTIME_LEAVES: &[&str] = &[
    "KbHolds",
    "KbApply",
    "WaitForStep",
    "AlwaysSuccess",
    "AlwaysFailure",
    "Sleep",
];

/// How the module gets the runtime.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Runtime {
    /// Pasted in: one self-contained file.
    #[default]
    Inline,
    /// `from btc_runtime import ...`: the file must be importable.
    Import,
}

#[derive(Clone, Debug, Default)]
pub struct PyOptions<'a> {
    pub runtime: Runtime,
    /// Leaf classes from this module instead of simulated ones.
    pub node_module: Option<&'a str>,
    /// Name the domain and problem files in the header.
    pub source_paths: bool,
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

/// The distinct nodes the plan's steps run, as Python, numbered as first
/// met. Told apart by their text, so that the module is the same however
/// the IR shares its nodes; found by address first, so that a node the
/// steps share is written out once.
#[derive(Default)]
struct StepNodes {
    by_address: rustc_hash::FxHashMap<*const Node, usize>,
    texts: indexmap::IndexSet<Box<str>, rustc_hash::FxBuildHasher>,
}

/// How a leaf id is built: its index in `CLASSES` and the class expression.
struct LeafClass {
    index: usize,
}

struct Emitter<'a, 'w> {
    ir: &'a TreeIr,
    out: String,
    classes: HashMap<&'a str, LeafClass>,
    trees: HashMap<&'a str, usize>,
    /// The nodes of the steps, in the order a step first names them, and
    /// each one's index in `STEP_NODES` by its address: the steps that
    /// repeat a ground action share their node, which the module writes
    /// once. (The IR is borrowed for the whole emit, so an address names
    /// one value.)
    step_nodes: std::cell::RefCell<StepNodes>,
    /// Sizes the buffer by the main tree's first steps (when it is
    /// returned whole).
    root_sizer: std::cell::RefCell<StepSizer>,
    /// Where the buffer goes at step boundaries.
    sink: std::cell::RefCell<Sink<'w>>,
}

pub fn emit(ir: &TreeIr, options: &PyOptions<'_>) -> String {
    emit_into(ir, options, Sink::none()).expect("a buffer is written without errors")
}

/// [`emit`] streamed to `w` as it is produced.
pub fn emit_to(
    ir: &TreeIr,
    options: &PyOptions<'_>,
    w: &mut dyn std::io::Write,
) -> std::io::Result<()> {
    emit_into(ir, options, Sink::to(w)).map(drop)
}

/// [`emit_to`], its buffers handed over whole as they fill.
pub fn emit_handing_over(
    ir: &TreeIr,
    options: &PyOptions<'_>,
    hand: &mut Handover<'_>,
) -> std::io::Result<()> {
    emit_into(ir, options, Sink::hand(hand)).map(drop)
}

/// [`emit_handing_over`] of one of the module's two parts, whose texts
/// follow each other: [`Part::First`] is the plan (the header, the world
/// and the steps' rows, most of a long plan's module), [`Part::Second`]
/// the tree (the leaf classes, the trees, the steps' nodes). Neither needs
/// the other, so two threads can make them at once.
pub fn emit_part_handing_over(
    ir: &TreeIr,
    options: &PyOptions<'_>,
    part: Part,
    hand: &mut Handover<'_>,
) -> std::io::Result<()> {
    // Only the tree needs the models (a walk of the main tree).
    let models = match part {
        Part::First => Vec::new(),
        Part::Second => models(ir),
    };
    let mut e = Emitter::new(ir, Sink::hand(hand));
    match part {
        Part::First => e.plan_part(options),
        Part::Second => e.tree_part(&models, options),
    }
    e.sink.into_inner().finish(e.out).map(drop)
}

/// The leaf models, with a model for every leaf id the trees use.
fn models(ir: &TreeIr) -> Vec<NodeModel> {
    let mut models: Vec<NodeModel> = ir.nodes.clone();
    let mut add = |n: &Node| {
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
    };
    for t in &ir.trees {
        t.root.walk(&mut add);
    }
    // The main tree has one node per step at least: walk it only for
    // leaves outside the rules' trees.
    ir.root.walk_distinct(&mut add);
    models
}

fn emit_into(ir: &TreeIr, options: &PyOptions<'_>, sink: Sink<'_>) -> std::io::Result<String> {
    let models = models(ir);
    let mut e = Emitter::new(ir, sink);
    e.plan_part(options);
    e.tree_part(&models, options);
    e.sink.into_inner().finish(e.out)
}

impl<'a, 'w> Emitter<'a, 'w> {
    fn new(ir: &'a TreeIr, sink: Sink<'w>) -> Emitter<'a, 'w> {
        Emitter {
            ir,
            // Room for the first steps: the rows and the main tree are
            // sized by them as they are written.
            out: String::with_capacity(
                sink.capacity(256 * ir.steps.len().min(SAMPLE_STEPS) + 16_384),
            ),
            classes: HashMap::new(),
            trees: ir
                .trees
                .iter()
                .enumerate()
                .map(|(i, t)| (t.id.as_str(), i))
                .collect(),
            step_nodes: Default::default(),
            root_sizer: std::cell::RefCell::new(sink.sizer(steps_with_nodes(ir))),
            sink: std::cell::RefCell::new(sink),
        }
    }

    fn plan_part(&mut self, options: &PyOptions<'_>) {
        self.header(options);
        self.world();
        self.steps();
    }

    fn tree_part(&mut self, models: &'a [NodeModel], options: &PyOptions<'_>) {
        self.leaf_classes(models, options.node_module);
        self.tree();
        self.footer();
    }
}

impl<'a> Emitter<'a, '_> {
    fn header(&mut self, options: &PyOptions<'_>) {
        let ir = self.ir;
        let o = &mut self.out;
        o.push_str("#!/usr/bin/env python3\n");
        o.push_str("# A py_trees 2.x behaviour tree generated by btc. Do not edit: derive\n");
        o.push_str("# from its classes in your own module, or pass --node-module to btc.\n");
        if options.source_paths {
            let _ = writeln!(o, "# domain:  {}", py_str(&ir.domain));
            let _ = writeln!(o, "# problem: {}", py_str(&ir.problem));
        }
        o.push_str(
            "#\n\
             # `python3 <this file> [--json] [--ticks-per-action N]` ticks the tree\n\
             # until it is no longer RUNNING and prints the final status and whether\n\
             # the goal holds (exit 0 when both do). Importing it has no side\n\
             # effects: `create_behavior_tree()` builds the tree, and\n\
             # `btc_runtime.run(root, KnowledgeBase(WORLD, PLAN), max_ticks)` runs it\n\
             # with the knowledge base on the blackboard (`/btc/kb`).\n",
        );
        match options.node_module {
            Some(m) => {
                let _ = writeln!(
                    o,
                    "#\n# Leaf behaviours come from the module {}: each class in\n\
                     # NODE_CLASS_NAMES is constructed as `Class(node_name, step=k, **ports)`\n\
                     # (k: its plan step) when it derives from btc_runtime's Action,\n\
                     # Condition, KbHolds or KbApply, as `Class(node_name, **ports)` otherwise.",
                    py_str(m)
                );
            }
            None => o.push_str(
                "#\n# Leaf behaviours are simulated as `btc run` does: an action is RUNNING\n\
                 # for `--ticks-per-action` ticks, then SUCCESS; a condition evaluates its\n\
                 # formula on the knowledge base.\n",
            ),
        }
        o.push_str(
            "#\n# Needs py_trees 2.2 or later (tested with 2.2.3 and 2.6.0).\n\nimport sys\n",
        );
        match options.runtime {
            Runtime::Inline => {
                o.push_str(
                    "\n# ---------------------------------------------------------------------------\n\
                     # btc_runtime.py, pasted in (`--runtime import` imports it instead)\n\n",
                );
                o.push_str(RUNTIME);
                o.push_str(
                    "\n# ---------------------------------------------------------------------------\n\
                     # end of btc_runtime.py\n\nrun_main = main\n",
                );
            }
            Runtime::Import => {
                o.push_str("\nfrom btc_runtime import (\n");
                for n in [
                    "Action",
                    "AlwaysFailure",
                    "AlwaysSuccess",
                    "Condition",
                    "KbApply",
                    "KbHolds",
                    "KnowledgeBase",
                    "Plan",
                    "Sleep",
                    "WaitForStep",
                    "World",
                    "build_tree",
                ] {
                    let _ = writeln!(o, "    {n},");
                }
                o.push_str(")\nfrom btc_runtime import main as run_main\n");
            }
        }
        if let Some(m) = options.node_module {
            o.push('\n');
            o.push_str(&module_import(m).1);
        }
    }

    fn world(&mut self) {
        let w = &self.ir.world;
        let o = &mut self.out;
        o.push_str(
            "\n\n# ---------------------------------------------------------------------------\n\
             # The world: types, objects, predicates, derived rules, initial state, goal\n\n\
             WORLD = World(\n    types=(\n",
        );
        let names = |ns: &[btc_pddl::logic::Name]| -> String {
            let mut s = String::from("(");
            for n in ns {
                s.push_str(&py_str(n));
                s.push_str(", ");
            }
            s.push(')');
            s
        };
        for t in &w.types {
            let _ = writeln!(o, "        ({}, {}),", py_str(&t.name), names(&t.parents));
        }
        o.push_str("    ),\n    objects=(\n");
        for ob in &w.objects {
            let _ = writeln!(o, "        ({}, {}),", py_str(&ob.name), names(&ob.types));
        }
        o.push_str("    ),\n    predicates=(\n");
        for p in &w.predicates {
            let _ = writeln!(o, "        {},", py_str(&p.name));
        }
        o.push_str("    ),\n    functions=(\n");
        for f in &w.functions {
            let _ = writeln!(o, "        {},", py_str(&f.name));
        }
        o.push_str("    ),\n    derived=(\n");
        for d in &w.derived {
            let mut params = String::from("(");
            for v in &d.head.params {
                let _ = write!(
                    params,
                    "({}, {}), ",
                    py_str(&format!("?{}", v.name)),
                    names(&v.types)
                );
            }
            params.push(')');
            let _ = writeln!(
                o,
                "        ({}, {params}, {}),",
                py_str(&d.head.name),
                encode::formula(&d.body)
            );
        }
        o.push_str("    ),\n    init=(\n");
        for f in &w.init {
            if let InitFact::Atom(a) = f {
                let _ = writeln!(o, "        {},", encode::ground_atom(a));
            }
        }
        o.push_str("    ),\n    values=(\n");
        for f in &w.init {
            if let InitFact::Value(a, v) = f {
                let _ = writeln!(
                    o,
                    "        ({}, {}),",
                    encode::ground_atom(a),
                    encode::py_float(*v)
                );
            }
        }
        o.push_str("    ),\n    goal=");
        match &w.goal {
            Some(g) => o.push_str(&encode::formula(g)),
            None => o.push_str("None"),
        }
        o.push_str(",\n)\n");
    }

    /// `SHAPES` (distinct lifted conditions and effects) and `STEPS`.
    fn steps(&mut self) {
        let mut shapes: Vec<String> = Vec::new();
        // Looked up once per step with the shape's text: SipHash of it was
        // a twentieth of the module's writing.
        let mut index: rustc_hash::FxHashMap<String, usize> = Default::default();
        // Each step's shape, by index: the rows go straight into the
        // module after the shapes, not through a second buffer as large
        // as the plan.
        let mut of_step: Vec<usize> = Vec::with_capacity(self.ir.steps.len());
        // Steps that repeat a ground action share its logic (the same
        // value, not equal copies): their shape is found once, by the
        // value's address.
        let mut by_logic: rustc_hash::FxHashMap<*const btc_ir::StepLogic, usize> =
            Default::default();
        let mut buf = String::new();
        for s in &self.ir.steps {
            let logic = Arc::as_ptr(&s.logic);
            if let Some(&k) = by_logic.get(&logic) {
                of_step.push(k);
                continue;
            }
            buf.clear();
            shape_of(s, &mut buf);
            let k = match index.get(buf.as_str()) {
                Some(&k) => k,
                None => {
                    index.insert(buf.clone(), shapes.len());
                    shapes.push(buf.clone());
                    shapes.len() - 1
                }
            };
            by_logic.insert(logic, k);
            of_step.push(k);
        }
        let o = &mut self.out;
        o.push_str(
            "\n\n# ---------------------------------------------------------------------------\n\
             # The plan. A shape is an action with its conditions and effects (at start,\n\
             # over all, at end; at start, at end) over ?#i, the step's i-th argument; a\n\
             # step is (shape, args[, duration[, skipped[, after]]]), 0-based.\n\n\
             SHAPES = (\n",
        );
        for sh in &shapes {
            o.push_str("    ");
            o.push_str(sh);
            o.push_str(",\n");
        }
        o.push_str(")\n\nSTEPS = (\n");
        let mut rows = self.sink.get_mut().sizer(self.ir.steps.len());
        // Each shared argument tuple as text, by its address.
        let mut tuples: rustc_hash::FxHashMap<usize, Box<str>> = Default::default();
        for (s, k) in self.ir.steps.iter().zip(of_step) {
            rows.start(o);
            let args = tuples
                .entry(Arc::as_ptr(&s.logic.args) as *const u8 as usize)
                .or_insert_with(|| args_tuple(&s.logic.args).into());
            row_of(s, k, args, o);
            // Room after the rows for the leaf classes and the rule trees.
            rows.written(o, 65_536);
            self.sink.get_mut().step_done(o);
        }
        o.push_str(")\n\nPLAN = Plan(SHAPES, STEPS)\n");
    }

    fn leaf_classes(&mut self, models: &'a [NodeModel], node_module: Option<&str>) {
        let mut names = Names::reserving(RESERVED);
        let prefix = node_module.map(|m| module_import(m).0);
        let mut exprs: Vec<String> = Vec::new();
        let mut table = String::new();
        let mut defs = String::new();
        for m in models {
            if self.classes.contains_key(m.id.as_str()) {
                continue;
            }
            let expr = if RUNTIME_LEAVES.contains(&m.id.as_str()) {
                m.id.clone()
            } else {
                let name = names.fresh(&m.id);
                let _ = writeln!(table, "    {}: {},", py_str(&m.id), py_str(&name));
                match &prefix {
                    Some(p) => format!("{p}.{name}"),
                    None => {
                        class_def(&mut defs, &name, m);
                        name
                    }
                }
            };
            self.classes
                .insert(m.id.as_str(), LeafClass { index: exprs.len() });
            exprs.push(format!("({}, {expr})", py_str(&m.id)));
        }
        let o = &mut self.out;
        o.push_str(
            "\n\n# ---------------------------------------------------------------------------\n\
             # Leaf behaviours, by node id\n\nNODE_CLASS_NAMES = {\n",
        );
        o.push_str(&table);
        o.push_str("}\n");
        o.push_str(&defs);
        o.push_str("\n\n# (node id, leaf class), as the tree below refers to them (by index).\nCLASSES = (\n");
        for e in &exprs {
            let _ = writeln!(o, "    {e},");
        }
        o.push_str(")\n");
    }

    fn tree(&mut self) {
        let ir = self.ir;
        let mut out = std::mem::take(&mut self.out);
        out.push_str(
            "\n\n# ---------------------------------------------------------------------------\n\
             # The tree. Nodes: (\"Q\"|\"q\"|\"F\"|\"f\", name, children) sequence, reactive\n\
             # sequence, fallback, reactive fallback; (\"P\", name, success, failure,\n\
             # children); (\"D\", kind, arg, name, child); (\"L\", class, name, ports);\n\
             # (\"S\", step, i) runs STEP_NODES[i] as plan step `step`; (\"C\", tree, args)\n\
             # / (\"K\", tree, named args) calls\n\
             # TREES[tree], (params, node); (\"$\", param) is a parameter's value.\n\n\
             TREES = (\n",
        );
        for t in &ir.trees {
            out.push_str("    (\n        (");
            for p in &t.params {
                out.push_str(&py_str(p));
                out.push_str(", ");
            }
            out.push_str("),\n        ");
            self.node(&t.root, &mut out, 2);
            out.push_str(",\n    ),\n");
        }
        out.push_str(")\n\nROOT = ");
        self.node(&ir.root, &mut out, 0);
        out.push_str(
            "\n\n# A step's node: (\"S\", step, i) runs STEP_NODES[i], which the steps\n\
             # that repeat a ground action share.\n\n\
             STEP_NODES = (\n",
        );
        let texts = std::mem::take(&mut self.step_nodes.get_mut().texts);
        for text in texts {
            out.push_str("    ");
            out.push_str(&text);
            out.push_str(",\n");
            self.sink.get_mut().step_done(&mut out);
        }
        out.push_str(")\n");
        self.out = out;
    }

    /// Writes node `n`; children of a control node go one per line at
    /// `indent + 1` levels.
    fn node(&self, n: &'a Node, o: &mut String, indent: usize) {
        match n {
            Node::Control {
                control,
                name,
                children,
                ..
            } => {
                let tag = pytrees_code(control.spec());
                o.push_str("(\"");
                o.push_str(tag);
                o.push_str("\", ");
                push_opt_name(o, name);
                o.push_str(", ");
                for v in control.params() {
                    let _ = write!(o, "{v}, ");
                }
                o.push_str("(\n");
                for c in children {
                    push_indent(o, indent + 1);
                    self.node(c, o, indent + 1);
                    o.push_str(",\n");
                }
                push_indent(o, indent);
                o.push_str("))");
            }
            Node::Decorator {
                decorator,
                name,
                child,
                ..
            } => {
                let kind = pytrees_code(decorator.spec());
                let count = decorator.count();
                // A count from the call is a parameter, filled in when the
                // tree is built.
                let arg = match count {
                    Some(Count::Fixed(n)) => n.to_string(),
                    Some(Count::Param { param }) => format!("(\"$\", {})", py_str(param)),
                    None => "0".into(),
                };
                let _ = write!(o, "(\"D\", \"{kind}\", {arg}, ");
                push_opt_name(o, name);
                o.push_str(", ");
                self.node(child, o, indent);
                o.push(')');
            }
            Node::Leaf {
                id, name, ports, ..
            } => {
                let class = self.classes.get(id.as_str()).map_or(0, |c| c.index);
                o.push_str("(\"L\", ");
                push_int(o, class);
                o.push_str(", ");
                push_opt_name(o, name);
                o.push_str(", ");
                self.ports_tuple(ports, o);
                o.push(')');
            }
            Node::Step { step, child } => {
                self.root_sizer.borrow_mut().start(o);
                o.push_str("(\"S\", ");
                push_int(o, *step);
                o.push_str(", ");
                push_int(o, self.step_node_index(child));
                o.push(')');
                // Room after the steps for the module's end.
                self.root_sizer.borrow_mut().written(o, 4096);
                self.sink.borrow_mut().step_done(o);
            }
            Node::SubTree { id, ports, .. } => match self.trees.get(id.as_str()) {
                Some(&t) => {
                    let params = &self.ir.trees[t].params;
                    let positional = params.len() == ports.len()
                        && params.iter().zip(ports).all(|(p, q)| *p == q.name);
                    if positional {
                        o.push_str("(\"C\", ");
                        push_int(o, t);
                        o.push_str(", (");
                        for p in ports {
                            encode::port_value(&p.value, o);
                            o.push_str(", ");
                        }
                        o.push_str("))");
                    } else {
                        let _ = write!(o, "(\"K\", {t}, ");
                        self.ports_tuple(ports, o);
                        o.push(')');
                    }
                }
                None => {
                    let _ = write!(o, "(\"X\", {})", py_str(id));
                }
            },
        }
    }

    /// The index in `STEP_NODES` of a step's node.
    fn step_node_index(&self, n: &'a Arc<Node>) -> usize {
        let address = Arc::as_ptr(n);
        if let Some(&i) = self.step_nodes.borrow().by_address.get(&address) {
            return i;
        }
        let mut text = String::new();
        // Nothing is handed over while the node is written aside.
        self.sink.borrow_mut().hold();
        self.node(n, &mut text, 1);
        self.sink.borrow_mut().release();
        let mut nodes = self.step_nodes.borrow_mut();
        let (i, _) = nodes.texts.insert_full(text.into_boxed_str());
        nodes.by_address.insert(address, i);
        i
    }

    /// `(("port", value), ...)`
    fn ports_tuple(&self, ports: &[Port], o: &mut String) {
        o.push('(');
        for p in ports {
            o.push('(');
            push_py_str(o, &p.name);
            o.push_str(", ");
            encode::port_value(&p.value, o);
            o.push_str("), ");
        }
        o.push(')');
    }

    fn footer(&mut self) {
        let max_ticks = MIN_TICKS.max(self.leaf_count() * 20);
        let _ = write!(
            self.out,
            "\n\n# ---------------------------------------------------------------------------\n\n\
             MAX_TICKS = {max_ticks}\n\n\n\
             def create_behavior_tree():\n    \
             \"\"\"Builds the behaviour tree and returns its root.\"\"\"\n    \
             return build_tree(ROOT, TREES, CLASSES, PLAN, STEP_NODES)\n\n\n\
             def main(argv=None):\n    \
             \"\"\"Ticks the tree to the end in a fresh knowledge base and prints the\n    \
             result; returns 0 when the tree succeeded and the goal holds.\"\"\"\n    \
             return run_main(create_behavior_tree, WORLD, PLAN, MAX_TICKS, argv)\n\n\n\
             if __name__ == \"__main__\":\n    sys.exit(main())\n"
        );
    }

    /// Leaves of the main tree with every call expanded (each tree counted
    /// once and multiplied, so this is linear in the IR).
    fn leaf_count(&self) -> usize {
        /// Leaves per tree, and per child that steps share (each counted
        /// once, however many steps repeat it).
        #[derive(Default)]
        struct Memo<'t> {
            trees: HashMap<&'t str, usize>,
            steps: rustc_hash::FxHashMap<*const Node, usize>,
        }
        // Trees are counted in dependency order by recursion with a depth
        // bound (calls nest at most `MAX_CALL_DEPTH` deep).
        fn count<'t>(ir: &'t TreeIr, n: &'t Node, memo: &mut Memo<'t>, depth: usize) -> usize {
            match n {
                Node::Leaf { .. } => 1,
                Node::Control { children, .. } => {
                    children.iter().map(|c| count(ir, c, memo, depth)).sum()
                }
                Node::Decorator { child, .. } => count(ir, child, memo, depth),
                Node::Step { child, .. } => {
                    if let Some(&k) = memo.steps.get(&Arc::as_ptr(child)) {
                        return k;
                    }
                    let k = count(ir, child, memo, depth);
                    memo.steps.insert(Arc::as_ptr(child), k);
                    k
                }
                Node::SubTree { id, .. } => {
                    if let Some(&k) = memo.trees.get(id.as_str()) {
                        return k;
                    }
                    let k = match ir.tree(id) {
                        Some(t) if depth < btc_ir::MAX_CALL_DEPTH => {
                            count(ir, &t.root, memo, depth + 1)
                        }
                        _ => 1,
                    };
                    memo.trees.insert(id.as_str(), k);
                    k
                }
            }
        }
        count(self.ir, &self.ir.root, &mut Memo::default(), 0)
    }
}

fn push_indent(o: &mut String, levels: usize) {
    for _ in 0..levels {
        o.push_str("    ");
    }
}

/// A node's name; the module fills a tree's parameters in at each call.
/// Written in place: most names are one piece of text (a step's guard
/// names one per step), which needs no braced copy.
fn push_opt_name(o: &mut String, name: &Option<Label>) {
    let Some(n) = name else {
        return o.push_str("None");
    };
    match n.parts.as_slice() {
        [LabelPart::Text(t)] => push_py_str(o, t),
        _ => push_py_str(o, &n.braced()),
    }
}

/// `(action, pre_start, pre_over_all, pre_end, eff_start, eff_end)`, lifted.
fn shape_of(s: &StepInfo, out: &mut String) {
    out.push('(');
    push_py_str(out, &s.logic.action);
    let mut e = encode::Encoder {
        out,
        args: &s.logic.args,
    };
    for f in [&s.logic.pre_start, &s.logic.pre_over_all, &s.logic.pre_end] {
        e.out.push_str(", ");
        e.opt_formula(f.as_deref());
    }
    for x in [&s.logic.eff_start, &s.logic.eff_end] {
        e.out.push_str(", ");
        e.opt_effect(x.as_deref());
    }
    out.push(')');
}

/// `("a", "b", )`: a step's arguments as a Python tuple.
fn args_tuple(args: &[String]) -> String {
    let mut out = String::from("(");
    for a in args {
        push_py_str(&mut out, a);
        out.push_str(", ");
    }
    out.push(')');
    out
}

fn row_of(s: &StepInfo, shape: usize, args: &str, out: &mut String) {
    out.push_str("    (");
    push_int(out, shape);
    out.push_str(", ");
    out.push_str(args);
    let extra = s.skipped || !s.after.is_empty();
    if s.duration.is_some() || extra {
        out.push_str(", ");
        match s.duration {
            Some(d) => encode::push_py_float(out, d),
            None => out.push_str("None"),
        }
    }
    if extra {
        out.push_str(if s.skipped { ", True, (" } else { ", False, (" });
        for a in &s.after {
            push_int(out, *a);
            out.push_str(", ");
        }
        out.push(')');
    }
    out.push_str("),\n");
}

/// A generated leaf class, documented for the user who derives from it.
fn class_def(o: &mut String, name: &str, m: &NodeModel) {
    let base = match m.kind {
        LeafKind::Action => "Action",
        LeafKind::Condition => "Condition",
    };
    let ports: Vec<String> = m
        .ports
        .iter()
        .map(|p| format!("{}: {}", p.name, p.ty))
        .collect();
    let doc = format!(
        "{} `{}`{}.",
        match m.kind {
            LeafKind::Action => "Action",
            LeafKind::Condition => "Condition",
        },
        m.id,
        if ports.is_empty() {
            String::new()
        } else {
            format!(" (ports: {})", ports.join(", "))
        }
    );
    let how = match (m.kind, &m.formula) {
        (LeafKind::Action, _) => {
            "Simulated: RUNNING for ticks_per_action ticks, then SUCCESS. Override\n    \
             update() with the real behaviour (self.ports holds the port values)."
        }
        (LeafKind::Condition, Some(_)) => {
            "Evaluates FORMULA on the knowledge base with the ports' objects."
        }
        (LeafKind::Condition, None) => "SUCCESS until you override update().",
    };
    // The docstring holds escaped text only: `py_str` without its quotes.
    let lit = py_str(&doc);
    let _ = write!(
        o,
        "\n\nclass {name}({base}):\n    \"\"\"{}\n\n    {how}\n    \"\"\"\n\n    NODE_ID = {}\n",
        &lit[1..lit.len() - 1],
        py_str(&m.id)
    );
    if let Some(f) = &m.formula {
        let _ = writeln!(o, "    FORMULA = {}", encode::formula(f));
    }
}

#[cfg(test)]
mod tests;

/// The tuple code of a node the py_trees target can express; the target
/// refuses rules with the others before anything is emitted (E001).
fn pytrees_code(spec: &NodeSpec) -> &'static str {
    match spec.pytrees {
        PyTrees::Built { code, .. } => code,
        PyTrees::NotExpressible { .. } => spec.keyword,
    }
}
