//! Output formats for the tree IR. Every emitter is a pure function from
//! [`TreeIr`] to text; names and strings from rules and plans are escaped
//! for the target language so they never break out of their place.

pub mod btcpp;
pub mod commands;
pub mod dot;
pub mod executor;
pub mod kb;
pub mod pytrees;

use btc_ir::TreeIr;

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Format {
    /// BehaviorTree.CPP v4 XML (Groot2 opens it).
    Btcpp,
    /// A py_trees 2.x Python module.
    Pytrees,
    /// The IR as JSON.
    Json,
    /// Graphviz DOT.
    Dot,
    /// Mermaid flowchart.
    Mermaid,
    /// Canonical robot commands, JSON Lines.
    Commands,
}

impl Format {
    pub const ALL: &'static [(Format, &'static str)] = &[
        (Format::Btcpp, "btcpp"),
        (Format::Pytrees, "pytrees"),
        (Format::Json, "json"),
        (Format::Dot, "dot"),
        (Format::Mermaid, "mermaid"),
        (Format::Commands, "commands"),
    ];

    pub fn name(self) -> &'static str {
        Format::ALL
            .iter()
            .find(|(f, _)| *f == self)
            .map(|(_, n)| *n)
            .expect("listed")
    }

    /// The usual file extension of the format.
    pub fn extension(self) -> &'static str {
        match self {
            Format::Btcpp => "xml",
            Format::Pytrees => "py",
            Format::Json => "json",
            Format::Dot => "dot",
            Format::Mermaid => "mmd",
            Format::Commands => "jsonl",
        }
    }
}

#[derive(Clone, Debug, Default)]
pub struct Options {
    /// One flat tree instead of a `<SubTree>` per rule (BT.CPP).
    pub inline: bool,
    /// py_trees: import leaf behaviours from this module instead of
    /// generating simulated ones.
    pub node_module: Option<String>,
}

pub fn emit(ir: &TreeIr, format: Format, options: &Options) -> String {
    match format {
        Format::Btcpp => btcpp::emit(ir, options.inline),
        Format::Pytrees => pytrees::emit(ir, options.node_module.as_deref()),
        Format::Json => serde_json::to_string_pretty(ir).expect("the IR serializes") + "\n",
        Format::Dot => dot::emit_dot(ir),
        Format::Mermaid => dot::emit_mermaid(ir),
        Format::Commands => commands::emit(ir),
    }
}
