//! The scripts BT.CPP runs around a node's tick, as the IR carries them
//! (each the script's text; the rules checker parses them, the runtime
//! compiles them). In JSON an object keyed by BT.CPP's attribute names,
//! left out when empty.

use serde::{Deserialize, Serialize};

/// The scripts BT.CPP runs around any node's tick: preconditions
/// (`_failureIf`, `_successIf`, `_skipIf`, `_while`, checked in that
/// order) and post-conditions (`_onSuccess`, `_onFailure`, `_post`,
/// `_onHalted`). Each is the script's text.
///
/// Almost every node has none, and a compiled plan has hundreds of
/// thousands of nodes: the eight slots live behind one pointer, allocated
/// when the first script is set, so a node without scripts pays 8 bytes.
#[derive(Clone, Debug, Default, Serialize, Deserialize)]
#[serde(from = "Slots", into = "Slots")]
pub struct NodeScripts {
    slots: Option<Box<Slots>>,
}

/// The slots as they are written, under BT.CPP's attribute names.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
struct Slots {
    #[serde(
        rename = "_failureIf",
        default,
        skip_serializing_if = "Option::is_none"
    )]
    failure_if: Option<String>,
    #[serde(
        rename = "_successIf",
        default,
        skip_serializing_if = "Option::is_none"
    )]
    success_if: Option<String>,
    #[serde(rename = "_skipIf", default, skip_serializing_if = "Option::is_none")]
    skip_if: Option<String>,
    #[serde(rename = "_while", default, skip_serializing_if = "Option::is_none")]
    while_: Option<String>,
    #[serde(
        rename = "_onSuccess",
        default,
        skip_serializing_if = "Option::is_none"
    )]
    on_success: Option<String>,
    #[serde(
        rename = "_onFailure",
        default,
        skip_serializing_if = "Option::is_none"
    )]
    on_failure: Option<String>,
    #[serde(rename = "_post", default, skip_serializing_if = "Option::is_none")]
    post: Option<String>,
    #[serde(rename = "_onHalted", default, skip_serializing_if = "Option::is_none")]
    on_halted: Option<String>,
}

static NO_SLOTS: Slots = Slots {
    failure_if: None,
    success_if: None,
    skip_if: None,
    while_: None,
    on_success: None,
    on_failure: None,
    post: None,
    on_halted: None,
};

impl From<Slots> for NodeScripts {
    fn from(s: Slots) -> NodeScripts {
        NodeScripts {
            slots: (s != NO_SLOTS).then(|| Box::new(s)),
        }
    }
}

impl From<NodeScripts> for Slots {
    fn from(s: NodeScripts) -> Slots {
        s.slots.map(|b| *b).unwrap_or_default()
    }
}

/// Equal when the same scripts are given (an emptied slot equals none).
impl PartialEq for NodeScripts {
    fn eq(&self, other: &NodeScripts) -> bool {
        self.slots() == other.slots()
    }
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

    /// The names `.btrules` gives them (`MoveTo(...) [skip_if: "..."]`),
    /// in the same order.
    pub const KEYS: [&'static str; 8] = [
        "failure_if",
        "success_if",
        "skip_if",
        "while",
        "on_success",
        "on_failure",
        "post",
        "on_halted",
    ];

    /// The index of a `.btrules` key in [`NodeScripts::KEYS`].
    pub fn key_index(key: &str) -> Option<usize> {
        NodeScripts::KEYS.iter().position(|k| *k == key)
    }

    /// The script of attribute `ATTRIBUTES[k]`.
    pub fn slot(&mut self, k: usize) -> &mut Option<String> {
        let s = self.slots.get_or_insert_with(Box::default);
        match k {
            0 => &mut s.failure_if,
            1 => &mut s.success_if,
            2 => &mut s.skip_if,
            3 => &mut s.while_,
            4 => &mut s.on_success,
            5 => &mut s.on_failure,
            6 => &mut s.post,
            _ => &mut s.on_halted,
        }
    }

    /// The scripts given, with their attribute names, in BT.CPP's order.
    pub fn given(&self) -> impl Iterator<Item = (&'static str, &str)> {
        let s = self.slots();
        [
            &s.failure_if,
            &s.success_if,
            &s.skip_if,
            &s.while_,
            &s.on_success,
            &s.on_failure,
            &s.post,
            &s.on_halted,
        ]
        .into_iter()
        .zip(NodeScripts::ATTRIBUTES)
        .filter_map(|(s, a)| Some((a, s.as_deref()?)))
    }

    pub fn is_empty(&self) -> bool {
        self.slots.as_deref().is_none_or(|s| *s == NO_SLOTS)
    }

    fn slots(&self) -> &Slots {
        self.slots.as_deref().unwrap_or(&NO_SLOTS)
    }
}

#[cfg(test)]
mod tests {
    use crate::{LeafKind, Node, NodeScripts};

    fn leaf(scripts: NodeScripts) -> Node {
        Node::Leaf {
            leaf: LeafKind::Action,
            id: "MoveTo".into(),
            name: None,
            ports: Vec::new(),
            scripts,
        }
    }

    #[test]
    fn scripts_round_trip_under_btcpp_names() {
        let mut scripts = NodeScripts::default();
        *scripts.slot(NodeScripts::key_index("skip_if").unwrap()) = Some("done == true".into());
        *scripts.slot(NodeScripts::key_index("on_success").unwrap()) = Some("moves += 1".into());
        let text = serde_json::to_string(&leaf(scripts.clone())).unwrap();
        assert!(text.contains(r#""scripts":{"_skipIf":"done == true","_onSuccess":"moves += 1"}"#));
        let back: Node = serde_json::from_str(&text).unwrap();
        assert_eq!(back, leaf(scripts));
    }

    #[test]
    fn a_node_without_scripts_writes_and_reads_none() {
        let text = serde_json::to_string(&leaf(NodeScripts::default())).unwrap();
        assert!(!text.contains("scripts"), "{text}");
        let older = r#"{"node":"leaf","leaf":"action","id":"MoveTo","name":null,"ports":[]}"#;
        let back: Node = serde_json::from_str(older).unwrap();
        assert_eq!(back, leaf(NodeScripts::default()));
    }

    #[test]
    fn a_node_without_scripts_pays_one_pointer() {
        assert_eq!(
            std::mem::size_of::<NodeScripts>(),
            std::mem::size_of::<usize>()
        );
        let mut s = NodeScripts::default();
        *s.slot(0) = Some("x".into());
        *s.slot(0) = None;
        assert!(s.is_empty());
        assert_eq!(s, NodeScripts::default());
    }

    #[test]
    fn keys_and_attributes_line_up() {
        assert_eq!(NodeScripts::key_index("skip_if"), Some(2));
        assert_eq!(NodeScripts::ATTRIBUTES[2], "_skipIf");
        assert_eq!(NodeScripts::key_index("skipIf"), None);
    }
}
