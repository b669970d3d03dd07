//! Node palettes: `import "nodes.xml"` reads a BehaviorTree.CPP
//! `<TreeNodesModel>` (as `BT::writeTreeNodesModelXML` writes it for a
//! factory, or a Groot2 palette) as node declarations, so a team's node
//! library is checked against without being retyped. `<Action>` and
//! `<Condition>` models become `action` and `condition` declarations; other
//! models (controls, decorators, subtrees) are not leaves a rule can call
//! and are left out. Port types map from C++ to the rules' basic types:
//! integers to `int`, `double`/`float` to `float`, `bool`, and strings
//! (and untyped or `BT::AnyTypeAllowed` ports) to `string`; any other type
//! is taken as `string` with a warning (R071). Spans point into the XML,
//! so a port type mismatch (R004) shows the palette's port.

use super::ast::{Ident, Item, ItemNode, NodeDecl, NodeKind, PortDecl};
use btc_pddl::diagnostic::{codes, Diagnostic};
use btc_pddl::source::{FileId, Span};
use quick_xml::events::{BytesStart, Event};
use quick_xml::Reader;

/// The rules type of a BT.CPP port type; `None` for a type btc cannot
/// check (it is then a `string`).
pub fn rules_type(cpp: &str) -> Option<&'static str> {
    let t = cpp.trim();
    let t = t.strip_prefix("std::").unwrap_or(t);
    Some(match t {
        "int" | "unsigned" | "unsigned int" | "long" | "unsigned long" | "long long"
        | "unsigned long long" | "short" | "unsigned short" | "int8_t" | "int16_t" | "int32_t"
        | "int64_t" | "uint8_t" | "uint16_t" | "uint32_t" | "uint64_t" | "size_t" => "int",
        "double" | "float" | "long double" => "float",
        "bool" => "bool",
        "" | "string" | "string_view" | "BT::StringView" | "BT::AnyTypeAllowed" => "string",
        s if s.starts_with("__cxx11::basic_string<char") || s.starts_with("basic_string<char") => {
            "string"
        }
        _ => return None,
    })
}

/// An attribute's value and the span of the value in the text.
pub(super) struct Attr {
    pub(super) key: String,
    pub(super) value: String,
    pub(super) span: Span,
}

/// The attributes of an element whose text starts at `at`.
pub(super) fn attrs(
    e: &BytesStart,
    r: &Reader<&[u8]>,
    text: &str,
    at: usize,
    file: FileId,
) -> Vec<Attr> {
    let raw = &text[at..];
    let end = raw.find('>').map_or(raw.len(), |k| k + 1);
    let raw = &raw[..end];
    let mut out = Vec::new();
    for a in e.attributes().flatten() {
        let key = String::from_utf8_lossy(a.key.as_ref()).into_owned();
        let value = a
            .decode_and_unescape_value(r.decoder())
            .map(|v| v.into_owned())
            .unwrap_or_default();
        // `key="value"` or `key='value'` inside the element's text.
        let span = [format!("{key}=\""), format!("{key}='")]
            .iter()
            .find_map(|p| raw.find(p.as_str()).map(|k| k + p.len()))
            .map_or(Span::new(file, at, at + end), |s| {
                let len = raw[s..].find(['"', '\'']).unwrap_or(0);
                Span::new(file, at + s, at + s + len)
            });
        out.push(Attr { key, value, span });
    }
    out
}

pub(super) fn get<'a>(attrs: &'a [Attr], key: &str) -> Option<&'a Attr> {
    attrs.iter().find(|a| a.key == key)
}

fn not_a_palette(file: FileId, at: usize, why: String) -> Diagnostic {
    Diagnostic::error(codes::R_PALETTE, Span::new(file, at, at), why).with_hint(
        "an imported .xml file is BT.CPP XML: a <TreeNodesModel> palette (`BT::writeTreeNodesModelXML`, or Groot2's), <BehaviorTree> elements, or both",
    )
}

/// The node declarations of a palette, each an item with absolute spans
/// (offset 0), and what is wrong with it. A file of trees without a
/// `<TreeNodesModel>` declares no nodes and is not wrong for it: its trees
/// are read by `btxml`.
pub fn parse_palette(text: &str, file: FileId) -> (Vec<ItemNode>, Vec<Diagnostic>) {
    let mut items = Vec::new();
    let mut diags = Vec::new();
    let mut r = Reader::from_str(text);
    r.config_mut().trim_text(true);
    let mut depth = 0usize;
    let mut models_at: Option<usize> = None;
    let mut saw_models = false;
    let mut current: Option<NodeDecl> = None;
    loop {
        let before = r.buffer_position() as usize;
        let ev = match r.read_event() {
            Ok(ev) => ev,
            Err(e) => {
                diags.push(not_a_palette(
                    file,
                    r.error_position() as usize,
                    format!("this XML file is not well-formed: {e}"),
                ));
                return (items, diags);
            }
        };
        let (start, empty) = match &ev {
            Event::Start(e) => (Some(e.clone()), false),
            Event::Empty(e) => (Some(e.clone()), true),
            _ => (None, false),
        };
        if let Some(e) = start {
            // Where the element's `<` is.
            let at = text[before..].find('<').map_or(before, |k| before + k);
            let name = String::from_utf8_lossy(e.name().as_ref()).into_owned();
            let a = attrs(&e, &r, text, at, file);
            match (models_at, current.is_some()) {
                (None, _) if name == "TreeNodesModel" => {
                    saw_models = true;
                    if !empty {
                        models_at = Some(depth);
                    }
                }
                (Some(m), false) if depth == m + 1 => {
                    let kind = match name.as_str() {
                        "Action" => Some(NodeKind::Action),
                        "Condition" => Some(NodeKind::Condition),
                        _ => None,
                    };
                    match (kind, get(&a, "ID")) {
                        (Some(kind), Some(id)) => {
                            let decl = NodeDecl {
                                kind,
                                name: Ident::new(id.value.clone(), id.span),
                                ports: Vec::new(),
                                formula: None,
                                span: id.span,
                            };
                            if empty {
                                items.push(ItemNode {
                                    offset: 0,
                                    item: std::sync::Arc::new(Item::Node(decl)),
                                });
                            } else {
                                current = Some(decl);
                            }
                        }
                        (Some(_), None) => diags.push(not_a_palette(
                            file,
                            at,
                            format!("this <{name}> has no `ID`"),
                        )),
                        (None, _) => {}
                    }
                }
                (Some(m), true) if depth == m + 2 => {
                    let out = match name.as_str() {
                        "input_port" => Some(false),
                        "output_port" | "inout_port" => Some(true),
                        _ => None,
                    };
                    if let Some(out) = out {
                        match get(&a, "name") {
                            Some(n) => {
                                let (ty, span) = match get(&a, "type") {
                                    Some(t) => (t.value.clone(), t.span),
                                    None => (String::new(), n.span),
                                };
                                let mapped = match rules_type(&ty) {
                                    Some(m) => m,
                                    None => {
                                        diags.push(
                                            Diagnostic::warning(
                                                codes::R_PALETTE_TYPE,
                                                span,
                                                format!(
                                                    "port `{}`: btc cannot check values of the C++ type `{ty}`; it takes them as strings",
                                                    n.value
                                                ),
                                            )
                                            .with_hint("btc checks int, float (double), bool and string ports"),
                                        );
                                        "string"
                                    }
                                };
                                if let Some(d) = current.as_mut() {
                                    d.ports.push(PortDecl {
                                        out,
                                        name: Ident::new(n.value.clone(), n.span),
                                        ty: Ident::new(mapped.to_owned(), span),
                                        span: n.span,
                                    });
                                }
                            }
                            None => diags.push(not_a_palette(
                                file,
                                at,
                                format!("this <{name}> has no `name`"),
                            )),
                        }
                    }
                }
                _ => {}
            }
            if !empty {
                depth += 1;
            }
            continue;
        }
        match ev {
            Event::End(_) => {
                depth = depth.saturating_sub(1);
                if let Some(m) = models_at {
                    if depth == m + 1 {
                        if let Some(d) = current.take() {
                            items.push(ItemNode {
                                offset: 0,
                                item: std::sync::Arc::new(Item::Node(d)),
                            });
                        }
                    }
                    if depth == m {
                        models_at = None;
                    }
                }
            }
            Event::Eof => {
                if depth > 0 {
                    diags.push(not_a_palette(
                        file,
                        text.len(),
                        "this XML file ends inside an element that is never closed".to_owned(),
                    ));
                    return (items, diags);
                }
                break;
            }
            _ => {}
        }
    }
    if !saw_models && !super::btxml::has_trees(text) {
        diags.push(not_a_palette(
            file,
            0,
            "this XML has neither a <TreeNodesModel> nor a <BehaviorTree>: it declares no nodes and no trees".to_owned(),
        ));
    }
    (items, diags)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn btcpp_port_types_map_to_rules_types() {
        assert_eq!(rules_type("int"), Some("int"));
        assert_eq!(rules_type("unsigned int"), Some("int"));
        assert_eq!(rules_type("double"), Some("float"));
        assert_eq!(rules_type("bool"), Some("bool"));
        assert_eq!(rules_type("std::string"), Some("string"));
        assert_eq!(
            rules_type(
                "std::__cxx11::basic_string<char, std::char_traits<char>, std::allocator<char> >"
            ),
            Some("string")
        );
        assert_eq!(rules_type(""), Some("string"));
        assert_eq!(rules_type("BT::AnyTypeAllowed"), Some("string"));
        assert_eq!(rules_type("geometry_msgs::msg::Pose"), None);
    }

    #[test]
    fn actions_and_conditions_become_declarations_with_spans_in_the_xml() {
        let text = r#"<root BTCPP_format="4">
  <TreeNodesModel>
    <Action ID="MoveTo">
      <input_port name="robot" type="std::string">a robot</input_port>
      <input_port name="speed" type="double"/>
      <output_port name="arrived" type="bool"/>
    </Action>
    <Condition ID="Ready"/>
    <Decorator ID="KbStep"><input_port name="step" type="int"/></Decorator>
    <Action ID="Pose"><input_port name="pose" type="Pose2D"/></Action>
  </TreeNodesModel>
</root>"#;
        let (items, diags) = parse_palette(text, 7);
        let decls: Vec<&NodeDecl> = items
            .iter()
            .map(|i| match &*i.item {
                Item::Node(n) => n,
                _ => unreachable!(),
            })
            .collect();
        let names: Vec<&str> = decls.iter().map(|d| d.name.text.as_str()).collect();
        assert_eq!(names, ["MoveTo", "Ready", "Pose"]);
        let m = decls[0];
        assert_eq!(m.kind, NodeKind::Action);
        let ports = crate::rules::ast::port_triples(&m.ports);
        assert_eq!(
            ports,
            [
                ("robot", "string", false),
                ("speed", "float", false),
                ("arrived", "bool", true)
            ]
        );
        let s = m.ports[1].ty.span;
        assert_eq!(&text[s.start as usize..s.end as usize], "double");
        assert_eq!(s.file, 7);
        let n = m.name.span;
        assert_eq!(&text[n.start as usize..n.end as usize], "MoveTo");
        assert_eq!(decls[1].kind, NodeKind::Condition);
        assert_eq!(diags.len(), 1);
        assert_eq!(diags[0].code, "R071");
    }

    #[test]
    fn broken_xml_and_xml_without_models_are_refused() {
        let (_, d) = parse_palette("<root><TreeNodesModel>", 0);
        assert_eq!(d[0].code, "R070");
        let (items, d) = parse_palette("<root BTCPP_format=\"4\"/>", 0);
        assert!(items.is_empty());
        assert_eq!(d[0].code, "R070");
    }
}
