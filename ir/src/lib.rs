//! The tree IR: what a compiled plan is, independent of any output format.
//! Emitters and the runtime read it; it round-trips through JSON.
//!
//! A step's subtree is a call of the rule's parametric tree (a BT.CPP
//! `<SubTree>` with port remapping); [`TreeIr::inlined`] expands every call
//! for formats and engines that want one flat tree.
//!
//! PDDL is structured here: conditions, effects and the world are
//! `btc_pddl::logic` values. In JSON a formula is its PDDL text, decoded
//! once when the IR is read ([`json`]).

use btc_pddl::logic::{Effect, Formula};
use btc_pddl::world::WorldModel;
use rustc_hash::FxHashSet;
use serde::{Deserialize, Serialize};
use std::collections::HashSet;
use std::sync::Arc;
pub use thin_vec::ThinVec;

pub mod json;
mod label;
mod nodes;
mod scripts;
pub mod vocab;
pub use label::{Label, LabelPart};
pub use nodes::{ControlKind, Count, DecoratorKind};
pub use scripts::NodeScripts;
pub use vocab::{ControlName, DecoratorName, NodeSpec};

/// The version of the IR's JSON encoding (`"ir_version"`). Version 1 (PDDL
/// as strings, no world) is still read: [`json::decode`].
pub const IR_VERSION: u32 = 2;

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", content = "value", rename_all = "lowercase")]
pub enum PortValue {
    Text(String),
    Int(i64),
    Float(f64),
    Bool(bool),
    /// A port of the enclosing tree (`{name}` in BT.CPP).
    Param(String),
    /// A ground PDDL condition (`KbHolds`' `formula`). Behind a pointer, as
    /// is the effect: a port is almost always text, and a plan's calls hold
    /// several ports per step, which would otherwise each be as wide as a
    /// formula. Shared: steps that repeat a ground action share its
    /// conditions (see [`StepInfo`]).
    Formula(Arc<Formula>),
    /// A ground PDDL effect (`KbApply`'s `effect`).
    Effect(Arc<Effect>),
}

impl PortValue {
    /// The value as BT.CPP writes it in an attribute.
    pub fn to_text(&self) -> String {
        match self {
            PortValue::Text(s) => s.clone(),
            PortValue::Int(n) => n.to_string(),
            PortValue::Float(f) => format_float(*f),
            PortValue::Bool(b) => b.to_string(),
            PortValue::Param(p) => format!("{{{p}}}"),
            PortValue::Formula(f) => f.to_string(),
            PortValue::Effect(e) => e.to_string(),
        }
    }
}

/// Floats always with a decimal point (`1.0`, not `1`).
pub fn format_float(f: f64) -> String {
    let mut s = String::new();
    push_float(&mut s, f);
    s
}

/// [`format_float`] appended to `out`: a long plan writes a duration per
/// step, and a `String` for each was a tenth of its emit.
pub fn push_float(out: &mut String, f: f64) {
    if f.fract() == 0.0 && f.is_finite() && f.abs() < 1e15 {
        // As `{f:.1}` writes it, through integer formatting: `{:.1}` takes
        // the exact (big-number) path.
        if f.is_sign_negative() && f == 0.0 {
            out.push('-');
        }
        push_int(out, f as i64);
        out.push_str(".0");
    } else {
        use std::fmt::Write;
        let _ = write!(out, "{f}");
    }
}

/// An integer appended to `out` in decimal, as `{n}` writes it but
/// without the formatting machinery (numbers are most of a plan's rows).
pub fn push_int(out: &mut String, n: impl itoa::Integer) {
    out.push_str(itoa::Buffer::new().format(n));
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Port {
    pub name: String,
    pub value: PortValue,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum LeafKind {
    Action,
    Condition,
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "node", rename_all = "lowercase")]
pub enum Node {
    Control {
        control: ControlKind,
        name: Option<Label>,
        children: Vec<Node>,
        /// BT.CPP's pre- and post-condition scripts around the node.
        #[serde(default, skip_serializing_if = "NodeScripts::is_empty")]
        scripts: NodeScripts,
    },
    Decorator {
        decorator: DecoratorKind,
        name: Option<Label>,
        child: Box<Node>,
        /// BT.CPP's pre- and post-condition scripts around the node.
        #[serde(default, skip_serializing_if = "NodeScripts::is_empty")]
        scripts: NodeScripts,
    },
    Leaf {
        leaf: LeafKind,
        id: String,
        name: Option<Label>,
        ports: Vec<Port>,
        /// BT.CPP's pre- and post-condition scripts around the node.
        #[serde(default, skip_serializing_if = "NodeScripts::is_empty")]
        scripts: NodeScripts,
    },
    /// A call of a [`TreeDef`].
    SubTree {
        id: String,
        ports: Vec<Port>,
        /// BT.CPP's pre- and post-condition scripts around the node.
        #[serde(default, skip_serializing_if = "NodeScripts::is_empty")]
        scripts: NodeScripts,
    },
    /// The boundary of plan step `step` (0-based): its at-start effects apply
    /// when it starts, its at-end effects when `child` succeeds. The steps
    /// that repeat a ground action share their `child` (a long plan
    /// repeats few), and emitters write a shared child once.
    Step { step: usize, child: Arc<Node> },
}

impl Node {
    pub fn sequence(children: Vec<Node>) -> Node {
        Node::Control {
            control: ControlKind::Sequence,
            name: None,
            children,
            scripts: NodeScripts::default(),
        }
    }

    /// [`Node::walk`] that goes into a child that steps share once, for
    /// passes that collect what a tree uses: a long plan's steps share few
    /// children.
    pub fn walk_distinct<'a>(&'a self, f: &mut impl FnMut(&'a Node)) {
        /// The shared children seen: a set, and in front of it a small
        /// table of recent ones (a step's child is nearly always one a
        /// recent step had), which answers most steps without hashing.
        struct Seen {
            recent: [*const Node; 64],
            all: FxHashSet<*const Node>,
        }
        impl Seen {
            fn first_time(&mut self, p: *const Node) -> bool {
                let slot = &mut self.recent[(p as usize >> 4) % 64];
                if *slot == p {
                    return false;
                }
                *slot = p;
                self.all.insert(p)
            }
        }
        fn go<'a>(n: &'a Node, f: &mut impl FnMut(&'a Node), seen: &mut Seen) {
            f(n);
            match n {
                Node::Control { children, .. } => children.iter().for_each(|c| go(c, f, seen)),
                Node::Decorator { child, .. } => go(child, f, seen),
                Node::Step { child, .. } => {
                    if seen.first_time(Arc::as_ptr(child)) {
                        go(child, f, seen)
                    }
                }
                Node::Leaf { .. } | Node::SubTree { .. } => {}
            }
        }
        let mut seen = Seen {
            recent: [std::ptr::null(); 64],
            all: FxHashSet::default(),
        };
        go(self, f, &mut seen)
    }

    /// Calls `f` on this node and every node below it (not into subtrees).
    pub fn walk<'a>(&'a self, f: &mut impl FnMut(&'a Node)) {
        f(self);
        match self {
            Node::Control { children, .. } => children.iter().for_each(|c| c.walk(f)),
            Node::Decorator { child, .. } => child.walk(f),
            Node::Step { child, .. } => child.walk(f),
            Node::Leaf { .. } | Node::SubTree { .. } => {}
        }
    }
}

/// A parametric tree: a rule's template, or a `tree` declaration.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct TreeDef {
    pub id: String,
    pub params: Vec<String>,
    pub root: Node,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum PortDirection {
    Input,
    Output,
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct PortModel {
    pub name: String,
    pub direction: PortDirection,
    /// A PDDL type, or string / int / float / bool.
    pub ty: String,
}

impl PortModel {
    /// The C++ type BT.CPP holds the port's values in (and names in a
    /// TreeNodesModel): `int`, `double` for `float`, `bool`, and
    /// `std::string` for strings and PDDL objects.
    pub fn cpp_type(&self) -> &'static str {
        match self.ty.as_str() {
            "int" => "int",
            "float" => "double",
            "bool" => "bool",
            _ => "std::string",
        }
    }
}

/// A leaf node type the tree uses, with its ports (BT.CPP's TreeNodesModel).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct NodeModel {
    pub id: String,
    pub kind: LeafKind,
    pub ports: Vec<PortModel>,
    /// For a condition defined by a formula: a formula over `?port`
    /// variables.
    pub formula: Option<Formula>,
}

/// One plan step as compiled: where it is in the plan, and its logic.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(from = "StepWire", into = "StepWire")]
pub struct StepInfo {
    pub index: usize,
    /// 1-based line in the plan file.
    pub line: u32,
    pub skipped: bool,
    pub time: Option<f64>,
    pub duration: Option<f64>,
    /// Steps that must finish before this one (`steps parallel`, `steps
    /// scheduled`). One pointer wide, as most steps have none and a long
    /// plan has many.
    pub after: ThinVec<usize>,
    /// Shared between the steps that repeat a ground action (plans repeat
    /// them a lot: a long plan would otherwise hold one copy of each per
    /// step); in JSON each step writes its own.
    pub logic: Arc<StepLogic>,
}

/// What a step does, the same for every step of its ground action.
#[derive(Clone, Debug, PartialEq)]
pub struct StepLogic {
    pub action: Arc<str>,
    pub args: Arc<[String]>,
    /// The id of the rule tree it calls; `None` for a skipped step.
    pub rule: Option<Arc<str>>,
    /// Ground conditions and effects, by when they apply. The effects are
    /// the step's: its rule's `effect` when the rule gives one, else the
    /// PDDL action's.
    pub pre_start: Option<Arc<Formula>>,
    pub pre_over_all: Option<Arc<Formula>>,
    pub pre_end: Option<Arc<Formula>>,
    pub eff_start: Option<Arc<Effect>>,
    pub eff_end: Option<Arc<Effect>>,
}

/// A step as JSON has it: every field of the step and its logic, in the
/// order IR files have always had them.
#[derive(Serialize, Deserialize)]
struct StepWire {
    index: usize,
    line: u32,
    action: Arc<str>,
    args: Arc<[String]>,
    time: Option<f64>,
    duration: Option<f64>,
    rule: Option<Arc<str>>,
    skipped: bool,
    pre_start: Option<Arc<Formula>>,
    pre_over_all: Option<Arc<Formula>>,
    pre_end: Option<Arc<Formula>>,
    eff_start: Option<Arc<Effect>>,
    eff_end: Option<Arc<Effect>>,
    after: Vec<usize>,
}

impl From<StepWire> for StepInfo {
    fn from(w: StepWire) -> StepInfo {
        StepInfo {
            index: w.index,
            line: w.line,
            skipped: w.skipped,
            time: w.time,
            duration: w.duration,
            after: w.after.into(),
            logic: Arc::new(StepLogic {
                action: w.action,
                args: w.args,
                rule: w.rule,
                pre_start: w.pre_start,
                pre_over_all: w.pre_over_all,
                pre_end: w.pre_end,
                eff_start: w.eff_start,
                eff_end: w.eff_end,
            }),
        }
    }
}

impl From<StepInfo> for StepWire {
    fn from(s: StepInfo) -> StepWire {
        let l = Arc::unwrap_or_clone(s.logic);
        StepWire {
            index: s.index,
            line: s.line,
            action: l.action,
            args: l.args,
            time: s.time,
            duration: s.duration,
            rule: l.rule,
            skipped: s.skipped,
            pre_start: l.pre_start,
            pre_over_all: l.pre_over_all,
            pre_end: l.pre_end,
            eff_start: l.eff_start,
            eff_end: l.eff_end,
            after: s.after.into(),
        }
    }
}

impl StepInfo {
    /// `(action arg ...)`
    pub fn display(&self) -> String {
        self.logic.display()
    }

    /// `step N: (action arg ...)`, N 1-based: how records and traces name
    /// the step.
    pub fn label(&self) -> String {
        format!("step {}: {}", self.index + 1, self.display())
    }
}

impl StepLogic {
    /// `(action arg ...)`
    pub fn display(&self) -> String {
        let mut s = format!("({}", self.action);
        for a in self.args.iter() {
            s.push(' ');
            s.push_str(a);
        }
        s.push(')');
        s
    }
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct TreeIr {
    #[serde(rename = "ir_version")]
    pub version: u32,
    /// The PDDL files it was compiled from (relative to the JSON file's
    /// folder when written with `-o`); informative: the world is
    /// [`TreeIr::world`].
    pub domain: String,
    pub problem: String,
    /// The plan and the rules file it was compiled from, recorded like the
    /// PDDL files; empty (and left out of the JSON) in files written before
    /// btc recorded them.
    #[serde(default, skip_serializing_if = "String::is_empty")]
    pub plan: String,
    #[serde(default, skip_serializing_if = "String::is_empty")]
    pub rules: String,
    pub main_tree: String,
    pub root: Node,
    pub trees: Vec<TreeDef>,
    pub nodes: Vec<NodeModel>,
    pub steps: Vec<StepInfo>,
    /// The world the tree runs in: types, objects, signatures, derived
    /// rules, initial facts and values, goal.
    pub world: WorldModel,
}

/// Deepest chain of subtree calls [`TreeIr::inlined`] expands.
pub const MAX_CALL_DEPTH: usize = 32;

impl TreeIr {
    pub fn tree(&self, id: &str) -> Option<&TreeDef> {
        self.trees.iter().find(|t| t.id == id)
    }

    pub fn node_model(&self, id: &str) -> Option<&NodeModel> {
        self.nodes.iter().find(|n| n.id == id)
    }

    /// The main tree with every subtree call expanded.
    pub fn inlined(&self) -> Node {
        self.inline_node(&self.root, &[], 0, None)
    }

    /// Writes the calls of the trees in `ids` out in place (each call
    /// becomes the called tree's body, its arguments filled in) and drops
    /// those trees; calls of other trees stay calls.
    pub fn expand_calls(&mut self, ids: &HashSet<String>) {
        if ids.is_empty() {
            return;
        }
        let only = Some(ids);
        self.root = self.inline_node(&self.root, &[], 0, only);
        let trees: Vec<TreeDef> = self
            .trees
            .iter()
            .filter(|t| !ids.contains(&t.id))
            .map(|t| TreeDef {
                id: t.id.clone(),
                params: t.params.clone(),
                root: self.inline_node(&t.root, &[], 0, only),
            })
            .collect();
        self.trees = trees;
    }

    /// The trees whose `Timeout` (or other duration) takes it from a port, and the
    /// trees that call them. BehaviorTree.CPP 4.10 stores a number passed
    /// to a `<SubTree>` port as an `int` entry while `Timeout`'s `msec`
    /// port is `unsigned`, so such a tree would not load there: lowering
    /// expands these calls (`expand_calls`) for every target alike, so
    /// that every executor runs the same tree.
    pub fn trees_timed_by_port(&self) -> HashSet<String> {
        fn uses(n: &Node, set: &HashSet<String>) -> bool {
            match n {
                Node::Decorator {
                    decorator, child, ..
                } => {
                    // BT.CPP's durations (`Timeout`, `Delay`) are unsigned.
                    let unsigned = decorator
                        .spec()
                        .params
                        .first()
                        .is_some_and(|p| p.ty == vocab::ParamType::Millis);
                    (unsigned && matches!(decorator.count(), Some(Count::Param { .. })))
                        || uses(child, set)
                }
                Node::Control { children, .. } => children.iter().any(|c| uses(c, set)),
                Node::Step { child, .. } => uses(child, set),
                Node::SubTree { id, .. } => set.contains(id),
                Node::Leaf { .. } => false,
            }
        }
        let mut set = HashSet::new();
        // A fixpoint: each pass adds the callers of the trees found so far.
        loop {
            let before = set.len();
            for t in &self.trees {
                if !set.contains(&t.id) && uses(&t.root, &set) {
                    set.insert(t.id.clone());
                }
            }
            if set.len() == before {
                return set;
            }
        }
    }

    fn inline_node(
        &self,
        n: &Node,
        args: &[Port],
        depth: usize,
        only: Option<&HashSet<String>>,
    ) -> Node {
        let subst = |ports: &[Port]| -> Vec<Port> {
            ports
                .iter()
                .map(|p| Port {
                    name: p.name.clone(),
                    value: substitute(&p.value, args),
                })
                .collect()
        };
        match n {
            Node::Control {
                control,
                name,
                children,
                scripts,
            } => Node::Control {
                control: *control,
                scripts: scripts.clone(),
                name: name.as_ref().map(|s| s.fill(args)),
                children: children
                    .iter()
                    .map(|c| self.inline_node(c, args, depth, only))
                    .collect(),
            },
            Node::Decorator {
                decorator,
                name,
                child,
                scripts,
            } => Node::Decorator {
                scripts: scripts.clone(),
                decorator: match decorator.count() {
                    Some(Count::Param { param }) => match count_of(param, args) {
                        Some(c) => decorator.with_count(c),
                        None => decorator.clone(),
                    },
                    _ => decorator.clone(),
                },
                name: name.as_ref().map(|s| s.fill(args)),
                child: Box::new(self.inline_node(child, args, depth, only)),
            },
            Node::Leaf {
                leaf,
                id,
                name,
                ports,
                scripts,
            } => Node::Leaf {
                leaf: *leaf,
                scripts: scripts.clone(),
                id: id.clone(),
                name: name.as_ref().map(|s| s.fill(args)),
                ports: subst(ports),
            },
            Node::Step { step, child } => Node::Step {
                step: *step,
                child: Arc::new(self.inline_node(child, args, depth, only)),
            },
            Node::SubTree { id, ports, scripts } => match self.tree(id) {
                Some(def) if depth < MAX_CALL_DEPTH && only.is_none_or(|ids| ids.contains(id)) => {
                    let root = self.inline_node(&def.root, &subst(ports), depth + 1, only);
                    if scripts.is_empty() {
                        root
                    } else {
                        // The call's scripts go around the whole subtree,
                        // not merged into its root's own: a one-child
                        // sequence returns, and halts, as its child does.
                        Node::Control {
                            control: ControlKind::Sequence,
                            name: None,
                            children: vec![root],
                            scripts: scripts.clone(),
                        }
                    }
                }
                _ => Node::SubTree {
                    id: id.clone(),
                    ports: subst(ports),
                    scripts: scripts.clone(),
                },
            },
        }
    }
}

fn substitute(v: &PortValue, args: &[Port]) -> PortValue {
    match v {
        PortValue::Param(p) => args
            .iter()
            .find(|a| a.name == *p)
            .map_or_else(|| v.clone(), |a| a.value.clone()),
        other => other.clone(),
    }
}

/// What a call passes for a decorator's count parameter: a number, or a
/// port of the calling tree (`None` when it passes no whole number).
fn count_of(param: &str, args: &[Port]) -> Option<Count> {
    match &args.iter().find(|a| a.name == param)?.value {
        PortValue::Int(n) => u64::try_from(*n).ok().map(Count::Fixed),
        PortValue::Text(t) => t.parse().ok().map(Count::Fixed),
        PortValue::Param(p) => Some(Count::Param { param: p.clone() }),
        _ => None,
    }
}

#[cfg(test)]
mod float_tests {
    use super::format_float;

    /// The integer path writes what `{:.1}` and `{}` would.
    #[test]
    fn floats_keep_their_text() {
        for f in [
            0.0f64,
            -0.0,
            1.0,
            -1.0,
            2.5,
            1e14,
            -1e14,
            999_999_999_999_999.0,
            1e15,
            1e20,
            0.1,
            3.000_1,
        ] {
            let expected = if f.fract() == 0.0 && f.abs() < 1e15 {
                format!("{f:.1}")
            } else {
                format!("{f}")
            };
            assert_eq!(format_float(f), expected, "{f}");
        }
        assert_eq!(format_float(-0.0), "-0.0");
        assert_eq!(format_float(3.0), "3.0");
    }
}

#[cfg(test)]
mod walk_tests {
    use super::*;

    /// A long plan holds a main-tree node and a `StepInfo` per step, and a
    /// py_trees compile holds them beside its output: their widths are
    /// what keeps its peak within 2x the output (#14).
    #[test]
    fn a_step_costs_the_ir_at_most_136_bytes() {
        assert!(std::mem::size_of::<Node>() <= 72);
        assert!(std::mem::size_of::<StepInfo>() <= 64);
        assert_eq!(std::mem::size_of::<Option<Label>>(), 8);
    }

    fn leaf(id: &str) -> Node {
        Node::Leaf {
            leaf: LeafKind::Action,
            id: id.to_owned(),
            name: None,
            ports: Vec::new(),
            scripts: NodeScripts::default(),
        }
    }

    /// Every step is visited, and each shared child (and what is below it)
    /// once, however the steps interleave their children: many children,
    /// so that some share a slot of the table of recent ones.
    #[test]
    fn walk_distinct_visits_each_shared_child_once() {
        let children: Vec<Arc<Node>> = (0..300)
            .map(|i| Arc::new(Node::sequence(vec![leaf(&format!("a{i}")), leaf("b")])))
            .collect();
        let mut order = Vec::new();
        let mut x = 7u64;
        for k in 0..5000 {
            x = x
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            let i = if k % 3 == 0 {
                k % 300
            } else {
                (x >> 33) as usize % 300
            };
            order.push(i);
        }
        let root = Node::sequence(
            order
                .iter()
                .enumerate()
                .map(|(step, &i)| Node::Step {
                    step,
                    child: children[i].clone(),
                })
                .collect(),
        );
        let (mut steps, mut leaves) = (0, std::collections::HashMap::<String, usize>::new());
        root.walk_distinct(&mut |n| match n {
            Node::Step { .. } => steps += 1,
            Node::Leaf { id, .. } => *leaves.entry(id.clone()).or_default() += 1,
            _ => {}
        });
        assert_eq!(steps, order.len());
        let used: std::collections::BTreeSet<_> = order.iter().collect();
        for i in 0..300 {
            let want = usize::from(used.contains(&i));
            assert_eq!(leaves.get(&format!("a{i}")).copied().unwrap_or(0), want);
        }
        assert_eq!(leaves["b"], used.len());
    }
}
