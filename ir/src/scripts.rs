//! The scripts BT.CPP runs around a node's tick, as the IR carries them
//! (each the script's text; the rules checker parses them, the runtime
//! compiles them). In JSON an object keyed by BT.CPP's attribute names,
//! left out when empty.

use serde::{Deserialize, Serialize};

/// The scripts BT.CPP runs around any node's tick: preconditions
/// (`_failureIf`, `_successIf`, `_skipIf`, `_while`, checked in that
/// order) and post-conditions (`_onSuccess`, `_onFailure`, `_post`,
/// `_onHalted`). Each is the script's text.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct NodeScripts {
    #[serde(
        rename = "_failureIf",
        default,
        skip_serializing_if = "Option::is_none"
    )]
    pub failure_if: Option<String>,
    #[serde(
        rename = "_successIf",
        default,
        skip_serializing_if = "Option::is_none"
    )]
    pub success_if: Option<String>,
    #[serde(rename = "_skipIf", default, skip_serializing_if = "Option::is_none")]
    pub skip_if: Option<String>,
    #[serde(rename = "_while", default, skip_serializing_if = "Option::is_none")]
    pub while_: Option<String>,
    #[serde(
        rename = "_onSuccess",
        default,
        skip_serializing_if = "Option::is_none"
    )]
    pub on_success: Option<String>,
    #[serde(
        rename = "_onFailure",
        default,
        skip_serializing_if = "Option::is_none"
    )]
    pub on_failure: Option<String>,
    #[serde(rename = "_post", default, skip_serializing_if = "Option::is_none")]
    pub post: Option<String>,
    #[serde(rename = "_onHalted", default, skip_serializing_if = "Option::is_none")]
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
        let scripts = NodeScripts {
            skip_if: Some("done == true".into()),
            on_success: Some("moves += 1".into()),
            ..NodeScripts::default()
        };
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
    fn keys_and_attributes_line_up() {
        assert_eq!(NodeScripts::key_index("skip_if"), Some(2));
        assert_eq!(NodeScripts::ATTRIBUTES[2], "_skipIf");
        assert_eq!(NodeScripts::key_index("skipIf"), None);
    }
}
