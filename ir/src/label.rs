//! A node's name as the rules wrote it: text, and in a rule's parametric
//! tree the values each call passes (the tree's parameters) in between.
//! Calls fill the parameters ([`Label::fill`]); a format that has no
//! interpolation in names (BT.CPP's `name`, Groot2) writes the name with
//! each parameter as `?param`, the subtree port that carries its value
//! ([`Label`]'s `Display`).
//!
//! In JSON a name without parameters is a string (as every name was before
//! labels had parts); one with parameters is a list of parts,
//! `[{"text": "move "}, {"param": "r"}]`.

use crate::{Port, PortValue};
use serde::{Deserialize, Serialize};
use std::fmt;
use thin_vec::{thin_vec, ThinVec};

#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Label {
    /// One pointer wide: every node has an `Option<Label>`, and a long
    /// plan's main tree has a node per step.
    pub parts: ThinVec<LabelPart>,
}

#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum LabelPart {
    Text(String),
    /// A parameter of the enclosing tree.
    Param(String),
}

impl Label {
    /// A name that is text only.
    pub fn text(s: impl Into<String>) -> Label {
        Label {
            parts: thin_vec![LabelPart::Text(s.into())],
        }
    }

    /// Appends text, joining it to the text before.
    pub fn push_text(&mut self, t: &str) {
        match self.parts.last_mut() {
            Some(LabelPart::Text(last)) => last.push_str(t),
            _ => self.parts.push(LabelPart::Text(t.to_owned())),
        }
    }

    /// The name as text when no part of it depends on a call.
    pub fn as_text(&self) -> Option<String> {
        let mut out = String::new();
        for p in &self.parts {
            match p {
                LabelPart::Text(t) => out.push_str(t),
                LabelPart::Param(_) => return None,
            }
        }
        Some(out)
    }

    /// The name with each parameter as `{param}`, for an executor that
    /// fills names from each call's arguments (the py_trees runtime).
    pub fn braced(&self) -> String {
        let mut out = String::new();
        for p in &self.parts {
            match p {
                LabelPart::Text(t) => out.push_str(t),
                LabelPart::Param(p) => {
                    out.push('{');
                    out.push_str(p);
                    out.push('}');
                }
            }
        }
        out
    }

    /// The parameters it reads, in order.
    pub fn params(&self) -> impl Iterator<Item = &str> {
        self.parts.iter().filter_map(|p| match p {
            LabelPart::Param(p) => Some(p.as_str()),
            LabelPart::Text(_) => None,
        })
    }

    /// The name with the call's values put in for its parameters; a value
    /// that is itself a parameter of the caller stays one.
    pub fn fill(&self, args: &[Port]) -> Label {
        let mut out = Label {
            parts: ThinVec::with_capacity(self.parts.len()),
        };
        for p in &self.parts {
            match p {
                LabelPart::Text(t) => out.push_text(t),
                LabelPart::Param(name) => match args.iter().find(|a| a.name == *name) {
                    Some(Port {
                        value: PortValue::Param(outer),
                        ..
                    }) => out.parts.push(LabelPart::Param(outer.clone())),
                    Some(a) => out.push_text(&a.value.to_text()),
                    None => out.parts.push(p.clone()),
                },
            }
        }
        out
    }
}

impl From<&str> for Label {
    fn from(s: &str) -> Label {
        Label::text(s)
    }
}

impl From<String> for Label {
    fn from(s: String) -> Label {
        Label::text(s)
    }
}

/// The name as a format without interpolation shows it: parameters as
/// `?param`.
impl fmt::Display for Label {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        for p in &self.parts {
            match p {
                LabelPart::Text(t) => f.write_str(t)?,
                LabelPart::Param(p) => write!(f, "?{p}")?,
            }
        }
        Ok(())
    }
}

#[derive(Serialize, Deserialize)]
#[serde(untagged)]
enum Encoded {
    Text(String),
    Parts(Vec<LabelPart>),
}

impl Serialize for Label {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        match self.as_text() {
            Some(t) => Encoded::Text(t),
            None => Encoded::Parts(self.parts.to_vec()),
        }
        .serialize(s)
    }
}

impl<'de> Deserialize<'de> for Label {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Label, D::Error> {
        Ok(match Encoded::deserialize(d)? {
            Encoded::Text(t) => Label::text(t),
            Encoded::Parts(parts) => Label {
                parts: parts.into(),
            },
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn label(parts: &[(&str, bool)]) -> Label {
        Label {
            parts: parts
                .iter()
                .map(|(s, param)| match param {
                    true => LabelPart::Param(s.to_string()),
                    false => LabelPart::Text(s.to_string()),
                })
                .collect(),
        }
    }

    #[test]
    fn a_call_fills_its_values_and_passes_on_its_own_parameters() {
        let l = label(&[("move ", false), ("r", true), (" to ", false), ("to", true)]);
        let args = [
            Port {
                name: "r".into(),
                value: PortValue::Text("floor_robot".into()),
            },
            Port {
                name: "to".into(),
                value: PortValue::Param("dest".into()),
            },
        ];
        let filled = l.fill(&args);
        assert_eq!(
            filled,
            label(&[("move floor_robot to ", false), ("dest", true)])
        );
        assert_eq!(filled.to_string(), "move floor_robot to ?dest");
        assert_eq!(filled.as_text(), None);
        let done = filled.fill(&[Port {
            name: "dest".into(),
            value: PortValue::Int(3),
        }]);
        assert_eq!(done.as_text().as_deref(), Some("move floor_robot to 3"));
    }

    #[test]
    fn json_keeps_plain_names_as_strings() {
        let plain = Label::text("pick {x}");
        assert_eq!(serde_json::to_string(&plain).unwrap(), r#""pick {x}""#);
        let l = label(&[("pick ", false), ("x", true)]);
        let json = serde_json::to_string(&l).unwrap();
        assert_eq!(json, r#"[{"text":"pick "},{"param":"x"}]"#);
        assert_eq!(serde_json::from_str::<Label>(&json).unwrap(), l);
        assert_eq!(
            serde_json::from_str::<Label>(r#""pick {x}""#).unwrap(),
            plain
        );
    }
}
