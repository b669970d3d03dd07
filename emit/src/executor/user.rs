//! `nodes.hpp`, the user's file: written once with a class per node, and
//! afterwards only appended to, with the classes of nodes the rules
//! declare since.

use super::*;

pub(super) fn user_class(out: &mut String, m: &NodeModel) {
    let class = class_name(&m.id);
    let base = base_name(&m.id);
    let _ = writeln!(out, "/// `{}`", declaration(m));
    let _ = writeln!(
        out,
        "class {class} : public {base}\n{{\npublic:\n  using {base}::{base};"
    );
    let accessors: Vec<String> = accessors(m)
        .into_iter()
        .zip(&m.ports)
        .filter(|(_, p)| p.direction == PortDirection::Input)
        .map(|(a, _)| format!("{a}()"))
        .collect();
    let ports = if accessors.is_empty() {
        String::new()
    } else {
        format!(" Ports: {}.", accessors.join(", "))
    };
    match m.kind {
        LeafKind::Action => {
            let _ = writeln!(
                out,
                "\n  // Simulated until you override these (see btc_nodes.hpp).{ports}\n  \
                 // BT::NodeStatus onStart() override;\n  \
                 // BT::NodeStatus onRunning() override;\n  \
                 // void onHalted() override;"
            );
        }
        LeafKind::Condition => {
            let how = if m.formula.is_some() {
                "evaluates its formula on the KB"
            } else {
                "always holds"
            };
            let _ = writeln!(
                out,
                "\n  // It {how} until you override tick().{ports}\n  // BT::NodeStatus tick() override;"
            );
        }
    }
    out.push_str("};\n\n");
}

/// The user's `nodes.hpp` as first written: a class per node.
pub fn user_nodes(spec: &Spec) -> String {
    let mut out = String::new();
    let _ = writeln!(
        out,
        "// Your nodes: one class per node of {}, deriving from the bases\n\
         // `btc executor` generates in btc_nodes.hpp. btc writes this file once\n\
         // and never overwrites it; when the rules declare new nodes, their classes\n\
         // are appended at the end. The bases' default bodies simulate the node as\n\
         // `btc run` does; override them to drive your robot.\n\
         #pragma once\n\n#include \"btc_nodes.hpp\"\n\nnamespace {}\n{{\n",
        comment(spec.rules),
        spec.name
    );
    for m in spec.nodes {
        user_class(&mut out, m);
    }
    let _ = writeln!(out, "}}  // namespace {}", spec.name);
    out
}

/// What regenerating does to the user's `nodes.hpp`.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct UserUpdate {
    /// The new text, when classes were appended.
    pub text: Option<String>,
    /// Nodes whose classes were appended.
    pub added: Vec<String>,
    /// Classes deriving from a base btc no longer generates, with the byte
    /// range of the derivation in the file.
    pub stale: Vec<(String, std::ops::Range<usize>)>,
}

/// `text` with comments blanked out (same length, so offsets stay).
pub(super) fn without_comments(text: &str) -> String {
    let b = text.as_bytes();
    let mut out = b.to_vec();
    let mut i = 0;
    while i < b.len() {
        if b[i] == b'/' && b.get(i + 1) == Some(&b'/') {
            while i < b.len() && b[i] != b'\n' {
                out[i] = b' ';
                i += 1;
            }
        } else if b[i] == b'/' && b.get(i + 1) == Some(&b'*') {
            while i < b.len() && !(b[i] == b'*' && b.get(i + 1) == Some(&b'/')) {
                if b[i] != b'\n' {
                    out[i] = b' ';
                }
                i += 1;
            }
            for _ in 0..2 {
                if i < b.len() {
                    out[i] = b' ';
                    i += 1;
                }
            }
        } else if b[i] == b'"' {
            i += 1;
            while i < b.len() && b[i] != b'"' && b[i] != b'\n' {
                if b[i] == b'\\' {
                    out[i] = b' ';
                    i += 1;
                }
                if i < b.len() {
                    out[i] = b' ';
                    i += 1;
                }
            }
            i += 1;
        } else {
            i += 1;
        }
    }
    String::from_utf8(out).unwrap_or_default()
}

/// Identifier tokens of C++ code, with their offsets.
pub(super) fn words(code: &str) -> Vec<(usize, &str)> {
    let mut out = Vec::new();
    let mut start = None;
    for (i, c) in code.char_indices() {
        let w = c.is_ascii_alphanumeric() || c == '_';
        match (w, start) {
            (true, None) => start = Some(i),
            (false, Some(s)) => {
                out.push((s, &code[s..i]));
                start = None;
            }
            _ => {}
        }
    }
    if let Some(s) = start {
        out.push((s, &code[s..]));
    }
    out
}

/// Brings the user's `nodes.hpp` up to date with the rules: a class for
/// every node that has none is appended (nothing the user wrote changes),
/// and classes that derive from a base the rules no longer give are listed.
pub fn update_user_nodes(existing: &str, spec: &Spec) -> UserUpdate {
    let code = without_comments(existing);
    let toks = words(&code);
    let mut classes: BTreeSet<&str> = BTreeSet::new();
    let mut bases: Vec<(usize, &str, &str)> = Vec::new(); // (offset, class, base)
    for w in toks.windows(2) {
        if matches!(w[0].1, "class" | "struct") {
            classes.insert(w[1].1);
        }
    }
    for (i, w) in toks.iter().enumerate() {
        if matches!(w.1, "class" | "struct") {
            if let Some((_, class)) = toks.get(i + 1) {
                // `class X : public YBase` (access specifier optional).
                let mut j = i + 2;
                if matches!(toks.get(j).map(|t| t.1), Some("final")) {
                    j += 1;
                }
                if matches!(
                    toks.get(j).map(|t| t.1),
                    Some("public" | "protected" | "private")
                ) {
                    j += 1;
                }
                if let Some((off, base)) = toks.get(j) {
                    let between = &code[w.0 + w.1.len()..*off];
                    if base.ends_with("Base") && between.contains(':') && !between.contains('{') {
                        bases.push((*off, class, base));
                    }
                }
            }
        }
    }
    let wanted: BTreeSet<String> = spec.nodes.iter().map(|m| base_name(&m.id)).collect();
    let mut update = UserUpdate::default();
    for (off, class, base) in bases {
        if !wanted.contains(base) {
            update.stale.push((class.to_owned(), off..off + base.len()));
        }
    }
    let missing: Vec<&NodeModel> = spec
        .nodes
        .iter()
        .filter(|m| !classes.contains(class_name(&m.id).as_str()))
        .collect();
    if missing.is_empty() {
        return update;
    }
    let mut text = existing.to_owned();
    if !text.ends_with('\n') {
        text.push('\n');
    }
    let _ = writeln!(
        text,
        "\n// Appended by `btc executor` for nodes the rules declare since.\nnamespace {}\n{{\n",
        spec.name
    );
    for m in &missing {
        user_class(&mut text, m);
        update.added.push(m.id.clone());
    }
    let _ = writeln!(text, "}}  // namespace {}", spec.name);
    update.text = Some(text);
    update
}
