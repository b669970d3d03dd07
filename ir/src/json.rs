//! The IR's JSON boundary: version 2 is [`TreeIr`] as serde writes it
//! (formulas as PDDL text, decoded here, once); version 1 files (PDDL as
//! strings, no world, `"version": 1`) are still read, and upgraded once a
//! world is at hand ([`V1::upgrade`]).

use crate::{Node, NodeModel, PortValue, StepInfo, TreeDef, TreeIr, IR_VERSION};
use btc_pddl::logic::decode;
use btc_pddl::world::WorldModel;
use serde::Deserialize;
use std::sync::Arc;

/// A JSON IR file as read.
#[derive(Clone, Debug, PartialEq)]
#[allow(clippy::large_enum_variant)] // one per file read
pub enum IrFile {
    Current(TreeIr),
    V1(V1),
}

/// A version-1 file: everything but the world, whose PDDL files it names.
#[derive(Clone, Debug, PartialEq, Deserialize)]
pub struct V1 {
    pub version: u32,
    pub domain: String,
    pub problem: String,
    pub main_tree: String,
    pub root: Node,
    pub trees: Vec<TreeDef>,
    pub nodes: Vec<NodeModel>,
    pub steps: Vec<StepInfo>,
}

/// Why a JSON text is no IR btc reads: a message, and the 1-based line and
/// column it points at (0 when it points nowhere).
#[derive(Clone, Debug, PartialEq)]
pub struct DecodeError {
    pub message: String,
    pub line: usize,
    pub column: usize,
}

impl From<serde_json::Error> for DecodeError {
    fn from(e: serde_json::Error) -> Self {
        DecodeError {
            message: e.to_string(),
            line: e.line(),
            column: e.column(),
        }
    }
}

#[derive(Deserialize)]
struct Version {
    ir_version: Option<u32>,
    version: Option<u32>,
}

/// Reads an IR file of any version btc writes or wrote.
pub fn decode(text: &str) -> Result<IrFile, DecodeError> {
    let v: Version = serde_json::from_str(text)?;
    match (v.ir_version, v.version) {
        (Some(IR_VERSION), _) => Ok(IrFile::Current(serde_json::from_str(text)?)),
        (None, Some(1)) => Ok(IrFile::V1(serde_json::from_str(text)?)),
        (Some(n), _) | (None, Some(n)) => Err(DecodeError {
            message: format!("this IR is version {n}; this btc reads versions 1 and {IR_VERSION}"),
            line: 0,
            column: 0,
        }),
        (None, None) => Err(DecodeError {
            message: "no `ir_version` field".into(),
            line: 0,
            column: 0,
        }),
    }
}

impl V1 {
    /// The file as the current IR, in `world` (from the PDDL files it
    /// names). Version 1 wrote `KbHolds` / `KbApply` formulas as text
    /// ports: they are decoded here.
    pub fn upgrade(self, world: WorldModel) -> Result<TreeIr, String> {
        Ok(TreeIr {
            version: IR_VERSION,
            domain: self.domain,
            problem: self.problem,
            plan: String::new(),
            rules: String::new(),
            main_tree: self.main_tree,
            root: upgrade_node(self.root)?,
            trees: self
                .trees
                .into_iter()
                .map(|t| {
                    Ok(TreeDef {
                        root: upgrade_node(t.root)?,
                        ..t
                    })
                })
                .collect::<Result<_, String>>()?,
            nodes: self.nodes,
            steps: self.steps,
            world,
        })
    }
}

fn upgrade_node(n: Node) -> Result<Node, String> {
    Ok(match n {
        Node::Leaf {
            leaf,
            id,
            name,
            mut ports,
            scripts,
        } => {
            let key = match id.as_str() {
                "KbHolds" => Some("formula"),
                "KbApply" => Some("effect"),
                _ => None,
            };
            for p in &mut ports {
                if let (Some(k), PortValue::Text(t)) = (key, &p.value) {
                    if p.name != k {
                        continue;
                    }
                    p.value = match k {
                        "formula" => PortValue::Formula(Arc::new(
                            decode::formula(t).map_err(|m| format!("`{id}`: `{t}`: {m}"))?,
                        )),
                        _ => PortValue::Effect(Arc::new(
                            decode::effect(t).map_err(|m| format!("`{id}`: `{t}`: {m}"))?,
                        )),
                    };
                }
            }
            Node::Leaf {
                leaf,
                id,
                name,
                ports,
                scripts,
            }
        }
        Node::Control {
            control,
            name,
            children,
            scripts,
        } => Node::Control {
            control,
            name,
            scripts,
            children: children
                .into_iter()
                .map(upgrade_node)
                .collect::<Result<_, _>>()?,
        },
        Node::Decorator {
            decorator,
            name,
            child,
            scripts,
        } => Node::Decorator {
            decorator,
            name,
            scripts,
            child: Box::new(upgrade_node(*child)?),
        },
        Node::Step { step, child } => Node::Step {
            step,
            child: Arc::new(upgrade_node(Arc::unwrap_or_clone(child))?),
        },
        other @ Node::SubTree { .. } => other,
    })
}
