//! A YAML document as a small tree with byte spans, built from
//! `saphyr_parser`'s events without recursion. Trial files are shallow
//! (six levels at most in the ARIAC format), so nesting is capped and
//! anchors and aliases, which no trial file uses, are refused: the reader
//! never meets a document it cannot walk or drop safely.

use saphyr_parser::{Event, Parser, ScalarStyle};

/// Deepest nesting of sequences and mappings a trial file may have.
pub const MAX_DEPTH: usize = 32;

/// Byte offsets into the document's text.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub struct Range {
    pub start: usize,
    pub end: usize,
}

#[derive(Clone, Debug, PartialEq)]
pub struct Node {
    pub range: Range,
    pub value: Value,
}

#[derive(Clone, Debug, PartialEq)]
pub enum Value {
    /// A scalar's text; `quoted` for '...' and "..." (and block) scalars,
    /// which YAML never reads as numbers or booleans.
    Scalar {
        text: String,
        quoted: bool,
    },
    Seq(Vec<Node>),
    Map(Vec<(Node, Node)>),
}

/// Why a text is not a document the reader takes.
#[derive(Clone, Debug, PartialEq)]
pub struct YamlError {
    pub at: usize,
    pub message: String,
}

impl Node {
    pub fn kind(&self) -> &'static str {
        match &self.value {
            Value::Scalar { text, quoted } => match scalar_kind(text, *quoted) {
                ScalarKind::Null => "nothing (null)",
                ScalarKind::Bool(_) => "a boolean",
                ScalarKind::Int(_) | ScalarKind::Float(_) => "a number",
                ScalarKind::Text => "text",
            },
            Value::Seq(_) => "a list",
            Value::Map(_) => "a mapping",
        }
    }

    pub fn as_map(&self) -> Option<&[(Node, Node)]> {
        match &self.value {
            Value::Map(m) => Some(m),
            _ => None,
        }
    }

    pub fn as_seq(&self) -> Option<&[Node]> {
        match &self.value {
            Value::Seq(s) => Some(s),
            _ => None,
        }
    }

    /// The scalar's text, whatever YAML would read it as.
    pub fn as_text(&self) -> Option<&str> {
        match &self.value {
            Value::Scalar { text, .. } => Some(text),
            _ => None,
        }
    }

    pub fn scalar(&self) -> Option<ScalarKind> {
        match &self.value {
            Value::Scalar { text, quoted } => Some(scalar_kind(text, *quoted)),
            _ => None,
        }
    }

    pub fn is_null(&self) -> bool {
        self.scalar() == Some(ScalarKind::Null)
    }
}

/// What a scalar means under YAML 1.2's core schema.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ScalarKind {
    Null,
    Bool(bool),
    Int(i64),
    Float(f64),
    Text,
}

pub fn scalar_kind(text: &str, quoted: bool) -> ScalarKind {
    if quoted {
        return ScalarKind::Text;
    }
    match text {
        "" | "~" | "null" | "Null" | "NULL" => return ScalarKind::Null,
        "true" | "True" | "TRUE" => return ScalarKind::Bool(true),
        "false" | "False" | "FALSE" => return ScalarKind::Bool(false),
        ".inf" | ".Inf" | ".INF" | "+.inf" => return ScalarKind::Float(f64::INFINITY),
        "-.inf" | "-.Inf" | "-.INF" => return ScalarKind::Float(f64::NEG_INFINITY),
        _ => {}
    }
    let digits = text.strip_prefix(['-', '+']).unwrap_or(text);
    if !digits.is_empty() && digits.bytes().all(|b| b.is_ascii_digit()) {
        if let Ok(n) = text.parse::<i64>() {
            return ScalarKind::Int(n);
        }
    }
    let numeric = digits
        .bytes()
        .all(|b| b.is_ascii_digit() || matches!(b, b'.' | b'e' | b'E' | b'-' | b'+'))
        && digits.bytes().any(|b| b.is_ascii_digit());
    if numeric {
        if let Ok(x) = text.parse::<f64>() {
            return ScalarKind::Float(x);
        }
    }
    ScalarKind::Text
}

/// Character index to byte offset (saphyr's markers count characters).
struct Offsets {
    ascii: bool,
    bytes: Vec<usize>,
}

impl Offsets {
    fn new(text: &str) -> Offsets {
        if text.is_ascii() {
            return Offsets {
                ascii: true,
                bytes: Vec::new(),
            };
        }
        let mut bytes: Vec<usize> = text.char_indices().map(|(b, _)| b).collect();
        bytes.push(text.len());
        Offsets {
            ascii: false,
            bytes,
        }
    }

    fn byte(&self, chars: usize) -> usize {
        if self.ascii {
            chars
        } else {
            self.bytes
                .get(chars)
                .copied()
                .unwrap_or_else(|| *self.bytes.last().unwrap_or(&0))
        }
    }
}

/// A container being built: its start and what it has so far.
enum Open {
    Seq(usize, Vec<Node>),
    /// A mapping and the key waiting for its value.
    Map(usize, Vec<(Node, Node)>, Option<Node>),
}

/// Parses a single-document YAML text into a [`Node`] tree. An empty
/// document is a null scalar.
pub fn parse(text: &str) -> Result<Node, YamlError> {
    let off = Offsets::new(text);
    let mut stack: Vec<Open> = Vec::new();
    let mut root: Option<Node> = None;
    let mut documents = 0;
    for ev in Parser::new_from_str(text) {
        let (ev, span) = ev.map_err(|e| YamlError {
            at: off.byte(e.marker().index()),
            message: e.info().to_owned(),
        })?;
        let start = off.byte(span.start.index());
        let end = off.byte(span.end.index()).max(start);
        let done = match ev {
            Event::StreamStart | Event::StreamEnd | Event::DocumentEnd | Event::Nothing => None,
            Event::DocumentStart(_) => {
                documents += 1;
                if documents > 1 {
                    return Err(YamlError {
                        at: start,
                        message: "a trial file holds one YAML document; this is a second".into(),
                    });
                }
                None
            }
            Event::Alias(_) => {
                return Err(YamlError {
                    at: start,
                    message: "aliases (`*name`) are not part of the trial format".into(),
                })
            }
            Event::Scalar(v, style, anchor, _) => {
                if anchor != 0 {
                    return Err(anchor_error(start));
                }
                Some(Node {
                    range: Range { start, end },
                    value: Value::Scalar {
                        text: v.into_owned(),
                        quoted: style != ScalarStyle::Plain,
                    },
                })
            }
            Event::SequenceStart(anchor, _) | Event::MappingStart(anchor, _) => {
                if anchor != 0 {
                    return Err(anchor_error(start));
                }
                if stack.len() >= MAX_DEPTH {
                    return Err(YamlError {
                        at: start,
                        message: format!(
                            "lists and mappings are nested deeper than {MAX_DEPTH} levels"
                        ),
                    });
                }
                stack.push(if matches!(ev, Event::SequenceStart(..)) {
                    Open::Seq(start, Vec::new())
                } else {
                    Open::Map(start, Vec::new(), None)
                });
                None
            }
            Event::SequenceEnd | Event::MappingEnd => match stack.pop() {
                Some(Open::Seq(s, items)) => Some(Node {
                    range: Range {
                        start: s,
                        end: end.max(items.last().map_or(s, |n| n.range.end)),
                    },
                    value: Value::Seq(items),
                }),
                Some(Open::Map(s, items, _)) => Some(Node {
                    range: Range {
                        start: s,
                        end: end.max(items.last().map_or(s, |(_, v)| v.range.end)),
                    },
                    value: Value::Map(items),
                }),
                None => None,
            },
        };
        if let Some(node) = done {
            match stack.last_mut() {
                Some(Open::Seq(_, items)) => items.push(node),
                Some(Open::Map(_, items, key)) => match key.take() {
                    Some(k) => items.push((k, node)),
                    None => *key = Some(node),
                },
                None => root = Some(node),
            }
        }
    }
    Ok(root.unwrap_or(Node {
        range: Range::default(),
        value: Value::Scalar {
            text: String::new(),
            quoted: false,
        },
    }))
}

fn anchor_error(at: usize) -> YamlError {
    YamlError {
        at,
        message: "anchors (`&name`) are not part of the trial format".into(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_trial_snippet_becomes_a_tree_with_byte_ranges() {
        let text =
            "time_limit: -1\nkitting_trays:\n  tray_ids: [1, 6]\n  slots: [2, 4]\nname: 'é x'\n";
        let n = parse(text).unwrap();
        let m = n.as_map().unwrap();
        assert_eq!(m.len(), 3);
        assert_eq!(m[0].0.as_text(), Some("time_limit"));
        assert_eq!(m[0].1.scalar(), Some(ScalarKind::Int(-1)));
        let trays = m[1].1.as_map().unwrap();
        assert_eq!(trays[0].1.as_seq().unwrap().len(), 2);
        let six = &trays[0].1.as_seq().unwrap()[1];
        assert_eq!(&text[six.range.start..six.range.end], "6");
        // Quoted text is text; offsets are bytes past non-ASCII text.
        let name = &m[2].1;
        assert_eq!(name.scalar(), Some(ScalarKind::Text));
        assert_eq!(name.as_text(), Some("é x"));
        assert_eq!(&text[name.range.start..name.range.end], "'é x'");
    }

    #[test]
    fn scalars_follow_the_core_schema() {
        assert_eq!(scalar_kind("0.15", false), ScalarKind::Float(0.15));
        assert_eq!(scalar_kind("pi/6", false), ScalarKind::Text);
        assert_eq!(scalar_kind("3", true), ScalarKind::Text);
        assert_eq!(scalar_kind("true", false), ScalarKind::Bool(true));
        assert_eq!(scalar_kind("", false), ScalarKind::Null);
        assert_eq!(scalar_kind("1e3", false), ScalarKind::Float(1000.0));
    }

    #[test]
    fn deep_nesting_aliases_and_syntax_errors_are_refused() {
        let deep = "[".repeat(MAX_DEPTH + 1) + &"]".repeat(MAX_DEPTH + 1);
        assert!(parse(&deep).unwrap_err().message.contains("nested deeper"));
        let deep = "[".repeat(100_000);
        assert!(parse(&deep).is_err());
        assert!(parse("a: &x 1\nb: *x\n").is_err());
        let e = parse("a: [1, 2\nb: 3\n").unwrap_err();
        assert!(e.at > 0, "{e:?}");
        assert!(parse("").unwrap().is_null());
    }
}
