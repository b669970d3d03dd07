//! A loaded tree before compilation: what the JSON IR and the XML loader
//! both produce, so the two run through one builder (and give one trace).

use btc_ir::{ControlKind, Count, DecoratorKind};
use btc_ir::{LeafKind, Node, NodeModel, PortValue, StepInfo, TreeIr};

/// What a node does. Thresholds and counts are BT.CPP's: `-1` means "all
/// children" (Parallel) or "forever" (Retry, Repeat).
#[derive(Clone, Debug, PartialEq)]
pub enum Kind {
    Sequence,
    ReactiveSequence,
    SequenceWithMemory,
    Fallback,
    ReactiveFallback,
    Parallel {
        success: i32,
        failure: i32,
    },
    Inverter,
    ForceSuccess,
    ForceFailure,
    KeepRunningUntilFailure,
    Retry(Amount<i32>),
    Repeat(Amount<i32>),
    Timeout(Amount<u64>),
    /// `IfThenElse`: a condition child, a then child, an optional else.
    IfThenElse,
    /// `WhileDoElse`: the condition is ticked again on every tick.
    WhileDoElse,
    /// `Switch2`..`Switch6`: the child whose case equals `variable`, or the
    /// last (default) child.
    Switch {
        variable: PortValue,
        cases: Vec<PortValue>,
    },
    /// `Delay`: the child is ticked once `msec` (simulated) have passed.
    Delay(Amount<u64>),
    /// `RunOnce`: the child runs to completion once; after that the node
    /// is SKIPPED (`then_skip`) or returns what the child returned.
    RunOnce {
        then_skip: bool,
    },
    /// `Precondition`: the child runs while the script `code` held when it
    /// started; otherwise the node returns `otherwise`.
    Precondition {
        code: String,
        otherwise: Verdict,
    },
    /// A call of a tree with port remapping.
    SubTree {
        id: String,
        ports: Vec<(String, PortValue)>,
        autoremap: bool,
    },
    /// The boundary of plan step `step` (0-based). Effects given here (the
    /// XML `KbStep` attributes) take the place of the step table's.
    Step {
        step: usize,
        start_effect: Option<btc_pddl::logic::Effect>,
        end_effect: Option<btc_pddl::logic::Effect>,
        /// The step's conditions as the XML gives them (`start_condition`,
        /// `over_all_condition`, `end_condition`); `None` when it gives none
        /// (they are then the domain action's, grounded from the name).
        conditions: Option<Box<StepConditions>>,
    },
    /// A leaf: built in, a KB node, or a node of the models.
    Leaf {
        id: String,
        kind: Option<LeafKind>,
        ports: Vec<(String, PortValue)>,
    },
}

/// A status a node is told to return (`Precondition`'s `else`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Verdict {
    Success,
    Failure,
    Skipped,
    Running,
}

/// The scripts BT.CPP runs around any node's tick: preconditions
/// (`_failureIf`, `_successIf`, `_skipIf`, `_while`, checked in that
/// order) and post-conditions (`_onSuccess`, `_onFailure`, `_post`,
/// `_onHalted`). Each is the script's text.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct NodeScripts {
    pub failure_if: Option<String>,
    pub success_if: Option<String>,
    pub skip_if: Option<String>,
    pub while_: Option<String>,
    pub on_success: Option<String>,
    pub on_failure: Option<String>,
    pub post: Option<String>,
    pub on_halted: Option<String>,
}

impl NodeScripts {
    /// The attribute names, in BT.CPP's order.
    pub const ATTRIBUTES: [&'static str; 8] = [
        "_failureIf",
        "_successIf",
        "_skipIf",
        "_while",
        "_onSuccess",
        "_onFailure",
        "_post",
        "_onHalted",
    ];

    /// The script of attribute `ATTRIBUTES[k]`.
    pub fn slot(&mut self, k: usize) -> &mut Option<String> {
        match k {
            0 => &mut self.failure_if,
            1 => &mut self.success_if,
            2 => &mut self.skip_if,
            3 => &mut self.while_,
            4 => &mut self.on_success,
            5 => &mut self.on_failure,
            6 => &mut self.post,
            _ => &mut self.on_halted,
        }
    }

    /// The scripts given, with their attribute names, in BT.CPP's order.
    pub fn given(&self) -> impl Iterator<Item = (&'static str, &str)> {
        [
            &self.failure_if,
            &self.success_if,
            &self.skip_if,
            &self.while_,
            &self.on_success,
            &self.on_failure,
            &self.post,
            &self.on_halted,
        ]
        .into_iter()
        .zip(NodeScripts::ATTRIBUTES)
        .filter_map(|(s, a)| Some((a, s.as_deref()?)))
    }

    pub fn is_empty(&self) -> bool {
        *self == NodeScripts::default()
    }
}

/// A step's ground conditions, by when they are checked.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct StepConditions {
    pub start: Option<btc_pddl::logic::Formula>,
    pub over_all: Option<btc_pddl::logic::Formula>,
    pub end: Option<btc_pddl::logic::Formula>,
}

/// A decorator's count or duration: written out, or read from a
/// blackboard entry (`{key}`, a port of the enclosing tree) each time the
/// node is ticked, as BT.CPP reads it.
#[derive(Clone, Debug, PartialEq)]
pub enum Amount<T> {
    Fixed(T),
    Entry(String),
}

/// As BT.CPP's `config().input_ports` holds it: the number, or the entry
/// in braces.
impl<T: std::fmt::Display> std::fmt::Display for Amount<T> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Amount::Fixed(n) => write!(f, "{n}"),
            Amount::Entry(key) => write!(f, "{{{key}}}"),
        }
    }
}

#[derive(Clone, Debug, PartialEq)]
pub struct SNode {
    pub kind: Kind,
    pub name: Option<String>,
    pub children: Vec<SNode>,
    /// Pre- and post-condition scripts.
    pub scripts: NodeScripts,
    /// Byte offset of the node in its source file, when it has one.
    pub at: Option<usize>,
}

impl SNode {
    /// A leaf without ports, name or source position.
    pub fn leaf(id: &str) -> SNode {
        SNode {
            kind: Kind::Leaf {
                id: id.into(),
                kind: None,
                ports: Vec::new(),
            },
            name: None,
            children: Vec::new(),
            scripts: NodeScripts::default(),
            at: None,
        }
    }
}

/// A whole document: its trees, the leaf models and the plan steps.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct TreeDoc {
    pub main: String,
    pub trees: Vec<(String, SNode)>,
    pub models: Vec<NodeModel>,
    /// The compiled plan's steps (preconditions, effects) when known.
    pub steps: Vec<StepInfo>,
    /// The domain's actions, for `KbStep`s of a tree file without a step
    /// table (BT.CPP XML): their conditions are the action's, grounded.
    pub actions: Vec<btc_pddl::logic::ActionSchema>,
}

impl TreeDoc {
    pub fn tree(&self, id: &str) -> Option<&SNode> {
        self.trees.iter().find(|(t, _)| t == id).map(|(_, n)| n)
    }

    /// The document with the domain's actions, for a tree file whose
    /// `KbStep`s come without a step table.
    pub fn with_actions(mut self, domain: &btc_pddl::Domain) -> TreeDoc {
        self.actions = domain
            .actions
            .iter()
            .map(btc_pddl::logic::ActionSchema::from_ast)
            .collect();
        self
    }

    pub fn model(&self, id: &str) -> Option<&NodeModel> {
        self.models.iter().find(|m| m.id == id)
    }

    /// The document for btc's IR: the main tree and one tree per rule.
    pub fn from_ir(ir: &TreeIr) -> TreeDoc {
        let mut trees = vec![(ir.main_tree.clone(), from_node(&ir.root))];
        trees.extend(ir.trees.iter().map(|t| (t.id.clone(), from_node(&t.root))));
        TreeDoc {
            main: ir.main_tree.clone(),
            trees,
            models: ir.nodes.clone(),
            steps: ir.steps.clone(),
            actions: Vec::new(),
        }
    }
}

pub(crate) fn line_col_offset(text: &str, line: usize, col: usize) -> usize {
    let start: usize = text
        .split_inclusive('\n')
        .take(line.saturating_sub(1))
        .map(str::len)
        .sum();
    (start + col.saturating_sub(1)).min(text.len())
}

fn ports(ps: &[btc_ir::Port]) -> Vec<(String, PortValue)> {
    ps.iter()
        .map(|p| (p.name.clone(), p.value.clone()))
        .collect()
}

/// Converts an IR node; the IR nests at most a few dozen levels (its
/// templates are written by hand), so recursion is fine here.
pub fn from_node(n: &Node) -> SNode {
    let (kind, name, children) = match n {
        Node::Control {
            control,
            name,
            children,
        } => (
            match control {
                ControlKind::Sequence => Kind::Sequence,
                ControlKind::ReactiveSequence => Kind::ReactiveSequence,
                ControlKind::Fallback => Kind::Fallback,
                ControlKind::ReactiveFallback => Kind::ReactiveFallback,
                ControlKind::Parallel { success, failure } => Kind::Parallel {
                    success: clamp(*success),
                    failure: clamp(*failure),
                },
            },
            name.as_ref().map(ToString::to_string),
            children.iter().map(from_node).collect(),
        ),
        Node::Decorator {
            decorator,
            name,
            child,
        } => (
            match decorator {
                DecoratorKind::Retry { times } => Kind::Retry(amount(times, clamp)),
                DecoratorKind::Repeat { times } => Kind::Repeat(amount(times, clamp)),
                DecoratorKind::Timeout { ms } => Kind::Timeout(amount(ms, |n| n)),
                DecoratorKind::Inverter => Kind::Inverter,
                DecoratorKind::ForceSuccess => Kind::ForceSuccess,
                DecoratorKind::ForceFailure => Kind::ForceFailure,
                DecoratorKind::Delay { ms } => Kind::Delay(amount(ms, |n| n)),
                DecoratorKind::RunOnce => Kind::RunOnce { then_skip: true },
            },
            name.as_ref().map(ToString::to_string),
            vec![from_node(child)],
        ),
        Node::Leaf {
            leaf,
            id,
            name,
            ports: ps,
        } => (
            Kind::Leaf {
                id: id.clone(),
                kind: Some(*leaf),
                ports: ports(ps),
            },
            name.as_ref().map(ToString::to_string),
            Vec::new(),
        ),
        Node::SubTree { id, ports: ps } => (
            Kind::SubTree {
                id: id.clone(),
                ports: ports(ps),
                autoremap: false,
            },
            None,
            Vec::new(),
        ),
        Node::Step { step, child } => (
            Kind::Step {
                step: *step,
                start_effect: None,
                end_effect: None,
                conditions: None,
            },
            None,
            vec![from_node(child)],
        ),
    };
    SNode {
        kind,
        name,
        children,
        scripts: Default::default(),
        at: None,
    }
}

fn clamp(n: impl TryInto<i32>) -> i32 {
    n.try_into().unwrap_or(i32::MAX)
}

fn amount<T>(c: &Count, fixed: impl Fn(u64) -> T) -> Amount<T> {
    match c {
        Count::Fixed(n) => Amount::Fixed(fixed(*n)),
        Count::Param { param } => Amount::Entry(param.clone()),
    }
}

/// The name BT.CPP gives a node without a `name`: its registration ID.
pub fn default_name(k: &Kind) -> &str {
    match k {
        Kind::Sequence => "Sequence",
        Kind::ReactiveSequence => "ReactiveSequence",
        Kind::SequenceWithMemory => "SequenceWithMemory",
        Kind::Fallback => "Fallback",
        Kind::ReactiveFallback => "ReactiveFallback",
        Kind::Parallel { .. } => "Parallel",
        Kind::Inverter => "Inverter",
        Kind::ForceSuccess => "ForceSuccess",
        Kind::ForceFailure => "ForceFailure",
        Kind::KeepRunningUntilFailure => "KeepRunningUntilFailure",
        Kind::Retry(_) => "RetryUntilSuccessful",
        Kind::Repeat(_) => "Repeat",
        Kind::Timeout(_) => "Timeout",
        Kind::IfThenElse => "IfThenElse",
        Kind::WhileDoElse => "WhileDoElse",
        Kind::Switch { cases, .. } => match cases.len() {
            2 => "Switch2",
            3 => "Switch3",
            4 => "Switch4",
            5 => "Switch5",
            _ => "Switch6",
        },
        Kind::Delay(_) => "Delay",
        Kind::RunOnce { .. } => "RunOnce",
        Kind::Precondition { .. } => "Precondition",
        Kind::SubTree { id, .. } => id,
        Kind::Step { .. } => "KbStep",
        Kind::Leaf { id, .. } => id,
    }
}
