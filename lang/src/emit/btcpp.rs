//! BehaviorTree.CPP v4 XML. The main tree calls one `<BehaviorTree>` per
//! rule through `<SubTree>` with port remapping (or, with `inline`, is one
//! flat tree); every leaf and subtree is declared in `<TreeNodesModel>` so
//! Groot2 opens the file. A plan step is a `KbStep` decorator carrying the
//! step's effects; the KB conditions btc adds are `KbHolds` leaves.
//!
//! `SubTree` elements get no `name` attribute: Groot2's monitor crashes on it.

use crate::ir::*;
use crate::rules::ast::{ControlKind, DecoratorKind};
use quick_xml::events::attributes::Attribute;
use quick_xml::events::{BytesDecl, BytesEnd, BytesStart, Event};
use quick_xml::Writer;

/// Escapes text for an XML attribute value. Newlines and tabs become
/// character references (a parser would fold them into spaces otherwise);
/// characters XML 1.0 forbids become U+FFFD.
pub fn escape_attr(s: &str) -> std::borrow::Cow<'_, str> {
    let plain = |c: char| {
        !matches!(
            c,
            '&' | '<' | '>' | '"' | '\'' | '\u{0}'..='\u{1F}' | '\u{FFFE}' | '\u{FFFF}'
        )
    };
    if s.chars().all(plain) {
        return std::borrow::Cow::Borrowed(s);
    }
    let mut out = String::with_capacity(s.len() + 8);
    for c in s.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\'' => out.push_str("&apos;"),
            '\n' => out.push_str("&#10;"),
            '\r' => out.push_str("&#13;"),
            '\t' => out.push_str("&#9;"),
            c if (c as u32) < 0x20 || c == '\u{FFFE}' || c == '\u{FFFF}' => out.push('\u{FFFD}'),
            c => out.push(c),
        }
    }
    std::borrow::Cow::Owned(out)
}

/// An XML element name from an id: ids are BT.CPP node names, which user
/// rules spell freely; anything not allowed in a name becomes `_`.
pub fn element_name(id: &str) -> String {
    let mut out: String = id
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || c == '_' || c == '-' || c == '.' {
                c
            } else {
                '_'
            }
        })
        .collect();
    if !out.starts_with(|c: char| c.is_ascii_alphabetic() || c == '_') {
        out.insert(0, '_');
    }
    out
}

struct Xml {
    w: Writer<Vec<u8>>,
}

impl Xml {
    fn start(&mut self, name: &str, attrs: &[(&str, String)], empty: bool) {
        let mut e = BytesStart::new(name);
        for (k, v) in attrs {
            let escaped = escape_attr(v);
            e.push_attribute(Attribute::from((k.as_bytes(), escaped.as_bytes())));
        }
        let ev = if empty {
            Event::Empty(e)
        } else {
            Event::Start(e)
        };
        self.w
            .write_event(ev)
            .expect("writing to a Vec cannot fail");
    }

    fn end(&mut self, name: &str) {
        self.w
            .write_event(Event::End(BytesEnd::new(name)))
            .expect("writing to a Vec cannot fail");
    }
}

fn control_tag(c: ControlKind) -> (&'static str, Vec<(&'static str, String)>) {
    match c {
        ControlKind::Sequence => ("Sequence", vec![]),
        ControlKind::ReactiveSequence => ("ReactiveSequence", vec![]),
        ControlKind::Fallback => ("Fallback", vec![]),
        ControlKind::ReactiveFallback => ("ReactiveFallback", vec![]),
        ControlKind::Parallel { success, failure } => (
            "Parallel",
            vec![
                ("success_count", success.to_string()),
                ("failure_count", failure.to_string()),
            ],
        ),
    }
}

fn decorator_tag(d: DecoratorKind) -> (&'static str, Vec<(&'static str, String)>) {
    match d {
        DecoratorKind::Retry { times } => (
            "RetryUntilSuccessful",
            vec![("num_attempts", times.to_string())],
        ),
        DecoratorKind::Repeat { times } => ("Repeat", vec![("num_cycles", times.to_string())]),
        DecoratorKind::Timeout { ms } => ("Timeout", vec![("msec", ms.to_string())]),
        DecoratorKind::Inverter => ("Inverter", vec![]),
        DecoratorKind::ForceSuccess => ("ForceSuccess", vec![]),
        DecoratorKind::ForceFailure => ("ForceFailure", vec![]),
    }
}

fn with_name(
    mut attrs: Vec<(&'static str, String)>,
    name: &Option<String>,
) -> Vec<(&'static str, String)> {
    if let Some(n) = name {
        attrs.insert(0, ("name", n.clone()));
    }
    attrs
}

fn node(x: &mut Xml, n: &Node, ir: &TreeIr) {
    match n {
        Node::Control {
            control,
            name,
            children,
        } => {
            let (tag, attrs) = control_tag(*control);
            let attrs = with_name(attrs, name);
            if children.is_empty() {
                x.start(tag, &attrs, true);
                return;
            }
            x.start(tag, &attrs, false);
            for c in children {
                node(x, c, ir);
            }
            x.end(tag);
        }
        Node::Decorator {
            decorator,
            name,
            child,
        } => {
            let (tag, attrs) = decorator_tag(*decorator);
            x.start(tag, &with_name(attrs, name), false);
            node(x, child, ir);
            x.end(tag);
        }
        Node::Leaf {
            id, name, ports, ..
        } => {
            let tag = element_name(id);
            let mut attrs: Vec<(&str, String)> = Vec::new();
            if let Some(n) = name {
                attrs.push(("name", n.clone()));
            }
            for p in ports {
                attrs.push((p.name.as_str(), p.value.to_text()));
            }
            x.start(&tag, &attrs, true);
        }
        Node::SubTree { id, ports } => {
            let mut attrs: Vec<(&str, String)> = vec![("ID", id.clone())];
            for p in ports {
                attrs.push((p.name.as_str(), p.value.to_text()));
            }
            x.start("SubTree", &attrs, true);
        }
        Node::Step { step, child } => {
            let info = ir.steps.get(*step);
            let name = info.map_or_else(
                || format!("step {}", step + 1),
                |s| format!("step {}: {}", step + 1, s.display()),
            );
            let attrs = vec![
                ("name", name),
                ("step", (step + 1).to_string()),
                (
                    "start_effect",
                    info.and_then(|s| s.eff_start.clone()).unwrap_or_default(),
                ),
                (
                    "end_effect",
                    info.and_then(|s| s.eff_end.clone()).unwrap_or_default(),
                ),
            ];
            x.start("KbStep", &attrs, false);
            node(x, child, ir);
            x.end("KbStep");
        }
    }
}

fn port_type(ty: &str) -> &str {
    match ty {
        "int" => "int",
        "float" => "double",
        "bool" => "bool",
        _ => "std::string",
    }
}

/// The XML document for a compiled plan.
pub fn emit(ir: &TreeIr, inline: bool) -> String {
    // Sized up front: growing a buffer of tens of megabytes by doubling
    // costs more (copies, fresh pages) than writing it.
    let estimate = 4096 + ir.steps.len() * 320 + ir.trees.len() * 2048;
    let mut x = Xml {
        w: Writer::new_with_indent(Vec::with_capacity(estimate), b' ', 2),
    };
    x.w.write_event(Event::Decl(BytesDecl::new("1.0", Some("UTF-8"), None)))
        .expect("vec");
    x.start(
        "root",
        &[
            ("BTCPP_format", "4".into()),
            ("main_tree_to_execute", ir.main_tree.clone()),
        ],
        false,
    );
    x.start("BehaviorTree", &[("ID", ir.main_tree.clone())], false);
    if inline {
        node(&mut x, &ir.inlined(), ir);
    } else {
        node(&mut x, &ir.root, ir);
    }
    x.end("BehaviorTree");
    if !inline {
        for t in &ir.trees {
            x.start("BehaviorTree", &[("ID", t.id.clone())], false);
            node(&mut x, &t.root, ir);
            x.end("BehaviorTree");
        }
    }
    x.start("TreeNodesModel", &[], false);
    for m in &ir.nodes {
        let tag = match m.kind {
            LeafKind::Action => "Action",
            LeafKind::Condition => "Condition",
        };
        let mut attrs = vec![("ID", element_name(&m.id))];
        if let Some(f) = &m.formula {
            attrs.push(("description", format!("holds when {f}")));
        }
        if m.ports.is_empty() {
            x.start(tag, &attrs, true);
            continue;
        }
        x.start(tag, &attrs, false);
        for p in &m.ports {
            let kind = match p.direction {
                PortDirection::Input => "input_port",
                PortDirection::Output => "output_port",
            };
            let mut pa = vec![
                ("name", p.name.clone()),
                ("type", port_type(&p.ty).to_owned()),
            ];
            if !matches!(p.ty.as_str(), "int" | "float" | "bool" | "string") {
                pa.push(("description", format!("a PDDL object of type {}", p.ty)));
            }
            x.start(kind, &pa, true);
        }
        x.end(tag);
    }
    // The step decorator btc emits around every plan step.
    if ir.steps.iter().any(|s| !s.skipped) {
        x.start("Decorator", &[("ID", "KbStep".into()), ("description", "a plan step: applies its PDDL effects to the KB when it starts and when its child succeeds".into())], false);
        x.start(
            "input_port",
            &[("name", "step".into()), ("type", "int".into())],
            true,
        );
        x.start(
            "input_port",
            &[
                ("name", "start_effect".into()),
                ("type", "std::string".into()),
            ],
            true,
        );
        x.start(
            "input_port",
            &[
                ("name", "end_effect".into()),
                ("type", "std::string".into()),
            ],
            true,
        );
        x.end("Decorator");
    }
    if !inline {
        for t in &ir.trees {
            if t.params.is_empty() {
                x.start("SubTree", &[("ID", t.id.clone())], true);
                continue;
            }
            x.start("SubTree", &[("ID", t.id.clone())], false);
            for p in &t.params {
                x.start("input_port", &[("name", p.clone())], true);
            }
            x.end("SubTree");
        }
    }
    x.end("TreeNodesModel");
    x.end("root");
    let mut out = String::from_utf8(x.w.into_inner()).expect("we wrote UTF-8");
    out.push('\n');
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn escapes_everything_that_could_break_out() {
        assert_eq!(
            escape_attr("a\"b'c<d>&e\nf"),
            "a&quot;b&apos;c&lt;d&gt;&amp;e&#10;f"
        );
        assert_eq!(escape_attr("</BehaviorTree>"), "&lt;/BehaviorTree&gt;");
        assert_eq!(escape_attr("x\u{1}y"), "x\u{FFFD}y");
        assert_eq!(escape_attr("日本ü"), "日本ü");
    }

    #[test]
    fn element_names_are_valid() {
        assert_eq!(element_name("MoveTo"), "MoveTo");
        assert_eq!(element_name("1st node"), "_1st_node");
        assert_eq!(element_name("a<b"), "a_b");
    }
}
