//! A loaded tree before compilation: what the JSON IR and the XML loader
//! both produce, so the two run through one builder (and give one trace).

use btc_ir::vocab::NodeName;
pub use btc_ir::NodeScripts;
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
        variable: Box<PortValue>,
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
        start_effect: Option<Box<btc_pddl::logic::Effect>>,
        end_effect: Option<Box<btc_pddl::logic::Effect>>,
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
    let none = NodeScripts::default();
    let (kind, name, children, scripts) = match n {
        Node::Control {
            control,
            name,
            children,
            scripts,
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
            scripts,
        ),
        Node::Decorator {
            decorator,
            name,
            child,
            scripts,
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
            scripts,
        ),
        Node::Leaf {
            leaf,
            id,
            name,
            ports: ps,
            scripts,
        } => (
            Kind::Leaf {
                id: id.clone(),
                kind: Some(*leaf),
                ports: ports(ps),
            },
            name.as_ref().map(ToString::to_string),
            Vec::new(),
            scripts,
        ),
        Node::SubTree {
            id,
            ports: ps,
            scripts,
        } => (
            Kind::SubTree {
                id: id.clone(),
                ports: ports(ps),
                autoremap: false,
            },
            None,
            Vec::new(),
            scripts,
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
            &none,
        ),
    };
    SNode {
        kind,
        name,
        children,
        scripts: scripts.clone(),
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
/// A vocabulary node's is the table's BT.CPP tag; the others are BT.CPP
/// nodes only the XML reader makes.
pub fn default_name(k: &Kind) -> &str {
    if let Some(name) = k.vocab() {
        return name.spec().tag;
    }
    match k {
        Kind::SequenceWithMemory => "SequenceWithMemory",
        Kind::KeepRunningUntilFailure => "KeepRunningUntilFailure",
        Kind::IfThenElse => "IfThenElse",
        Kind::WhileDoElse => "WhileDoElse",
        Kind::Switch { cases, .. } => match cases.len() {
            2 => "Switch2",
            3 => "Switch3",
            4 => "Switch4",
            5 => "Switch5",
            _ => "Switch6",
        },
        Kind::Precondition { .. } => "Precondition",
        Kind::SubTree { id, .. } => id,
        Kind::Step { .. } => "KbStep",
        Kind::Leaf { id, .. } => id,
        // Answered by `vocab` above.
        Kind::Sequence
        | Kind::ReactiveSequence
        | Kind::Fallback
        | Kind::ReactiveFallback
        | Kind::Parallel { .. }
        | Kind::Inverter
        | Kind::ForceSuccess
        | Kind::ForceFailure
        | Kind::Retry(_)
        | Kind::Repeat(_)
        | Kind::Timeout(_)
        | Kind::Delay(_)
        | Kind::RunOnce { .. } => unreachable!("a vocabulary node's name is its tag"),
    }
}

impl Kind {
    /// The node of the vocabulary ([`btc_ir::vocab::NODES`]) this kind
    /// runs, or `None` for a BT.CPP node the rules language does not have.
    /// No wildcard: a new kind has to say which it is.
    pub fn vocab(&self) -> Option<NodeName> {
        use btc_ir::{ControlName as C, DecoratorName as D};
        Some(match self {
            Kind::Sequence => NodeName::Control(C::Sequence),
            Kind::ReactiveSequence => NodeName::Control(C::ReactiveSequence),
            Kind::Fallback => NodeName::Control(C::Fallback),
            Kind::ReactiveFallback => NodeName::Control(C::ReactiveFallback),
            Kind::Parallel { .. } => NodeName::Control(C::Parallel),
            Kind::Inverter => NodeName::Decorator(D::Inverter),
            Kind::ForceSuccess => NodeName::Decorator(D::ForceSuccess),
            Kind::ForceFailure => NodeName::Decorator(D::ForceFailure),
            Kind::Retry(_) => NodeName::Decorator(D::Retry),
            Kind::Repeat(_) => NodeName::Decorator(D::Repeat),
            Kind::Timeout(_) => NodeName::Decorator(D::Timeout),
            Kind::Delay(_) => NodeName::Decorator(D::Delay),
            Kind::RunOnce { .. } => NodeName::Decorator(D::RunOnce),
            Kind::SequenceWithMemory
            | Kind::KeepRunningUntilFailure
            | Kind::IfThenElse
            | Kind::WhileDoElse
            | Kind::Switch { .. }
            | Kind::Precondition { .. }
            | Kind::SubTree { .. }
            | Kind::Step { .. }
            | Kind::Leaf { .. } => return None,
        })
    }

    /// A vocabulary node's parameters as BT.CPP's ports hold them: the
    /// table's port names with this node's values, in the table's order
    /// (empty for the others).
    pub fn vocab_ports(&self) -> Vec<(&'static str, String)> {
        let values: Vec<String> = match self {
            Kind::Parallel { success, failure } => vec![success.to_string(), failure.to_string()],
            Kind::Retry(k) | Kind::Repeat(k) => vec![k.to_string()],
            Kind::Timeout(ms) | Kind::Delay(ms) => vec![ms.to_string()],
            _ => Vec::new(),
        };
        let params = self.vocab().map_or(&[][..], |n| n.spec().params);
        debug_assert_eq!(params.len(), values.len(), "{self:?}");
        params.iter().map(|p| p.port).zip(values).collect()
    }
}

#[cfg(test)]
mod size_tests {
    use super::*;

    /// A parsed document holds one `SNode` per element, and a parent's
    /// children vector copies them as it grows: rare, large variants sit
    /// behind a pointer.
    #[test]
    fn nodes_stay_small() {
        // 280 bytes (Kind 208) before the step's effects and the switch's
        // variable were boxed; loading 10,001 nodes copied them about twice.
        assert!(
            std::mem::size_of::<Kind>() <= 56,
            "Kind: {}",
            std::mem::size_of::<Kind>()
        );
        assert!(
            std::mem::size_of::<SNode>() <= 128,
            "SNode: {}",
            std::mem::size_of::<SNode>()
        );
    }
}
