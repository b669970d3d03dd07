//! BehaviorTree.CPP v4 tree files a rules file imports (`import "move.xml"
//! as Move`, PlanSys2's per-action trees): each `<BehaviorTree>` read once
//! into the rules' own templates, so every emitter and btc's engine get the
//! imported tree through the same lowering as a `tree` of the rules.
//!
//! Reading (`read`) depends on the file alone: elements become templates
//! with spans into the XML, `{key}` attribute values become variables, a
//! `<SubTree>` becomes a call marked as one, and what btc cannot carry is
//! refused (R072) rather than approximated. Typing (`typing`) depends on the
//! importing file's declarations: a tree's ports are the blackboard keys it
//! reads, typed by the ports of the nodes (or trees) they are bound to.

mod read;
mod typing;

pub use read::{has_trees, read_trees};
pub use typing::{imported_trees, tree_names};

use super::ast::{Ident, Template};
use btc_pddl::diagnostic::Diagnostic;
use btc_pddl::source::Span;

/// The name a `<SubTree ID="X">` call carries until typing names the tree
/// it calls: `SubTree:X`, which no rules name can spell.
pub const SUBTREE_PREFIX: &str = "SubTree:";

/// The argument that stands for `_autoremap="true"` on a `<SubTree>` until
/// typing turns it into one argument per port of the called tree.
pub const AUTOREMAP: &str = "_autoremap";

/// One `<BehaviorTree ID="...">`.
#[derive(Clone, Debug, PartialEq)]
pub struct XmlTree {
    /// The `ID` as written, at its value in the XML.
    pub id: Ident,
    pub body: Vec<Template>,
    /// The `<BehaviorTree` element's opening tag.
    pub span: Span,
}

/// A BT.CPP file's trees and what is wrong with them.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct XmlTrees {
    pub trees: Vec<XmlTree>,
    /// `main_tree_to_execute` on `<root>`, when it names a tree of the file.
    pub main: Option<String>,
    pub diagnostics: Vec<Diagnostic>,
}

impl XmlTrees {
    /// The tree an `as` name stands for: the `main_tree_to_execute`, or the
    /// only tree of the file.
    pub fn main_tree(&self) -> Option<&XmlTree> {
        match &self.main {
            Some(m) => self.trees.iter().find(|t| &t.id.text == m),
            None if self.trees.len() == 1 => self.trees.first(),
            None => None,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rules::ast::{Item, NodeDecl, NodeKind, PortDecl, Value};
    use crate::rules::decls::Decls;

    fn node(name: &str, ports: &[(&str, &str, bool)]) -> NodeDecl {
        let id = |t: &str| Ident::new(t.to_owned(), Span::new(0, 0, 0));
        NodeDecl {
            kind: NodeKind::Action,
            name: id(name),
            ports: ports
                .iter()
                .map(|(n, t, out)| PortDecl {
                    out: *out,
                    name: id(n),
                    ty: id(t),
                    span: Span::new(0, 0, 0),
                })
                .collect(),
            formula: None,
            span: Span::new(0, 0, 0),
        }
    }

    const TRANSPORT: &str = r#"<root BTCPP_format="4" main_tree_to_execute="MainTree">
  <BehaviorTree ID="MainTree">
    <Sequence name="transport">
      <SubTree ID="Carry" _autoremap="true"/>
      <Report done="{arrived}"/>
    </Sequence>
  </BehaviorTree>
  <BehaviorTree ID="Carry">
    <Retry num_attempts="2"><Transport robot="{arg0}" speed="0.5" to="{arg3}"/></Retry>
  </BehaviorTree>
</root>"#;

    #[test]
    fn trees_become_declarations_with_their_entries_as_typed_ports() {
        let x = read_trees(TRANSPORT, 3);
        // `Retry` is the rules keyword, not BT.CPP's tag: refused.
        assert_eq!(x.diagnostics.len(), 1, "{:?}", x.diagnostics);
        assert_eq!(x.diagnostics[0].code, "R072");
        let x = read_trees(
            &TRANSPORT
                .replace("Retry ", "RetryUntilSuccessful ")
                .replace("</Retry>", "</RetryUntilSuccessful>"),
            3,
        );
        assert!(x.diagnostics.is_empty(), "{:?}", x.diagnostics);
        assert_eq!(x.main.as_deref(), Some("MainTree"));
        let mut decls = Decls::default();
        decls.nodes.insert(
            "Transport".into(),
            node(
                "Transport",
                &[
                    ("robot", "robot", false),
                    ("speed", "float", false),
                    ("to", "zone", false),
                ],
            ),
        );
        decls
            .nodes
            .insert("Report".into(), node("Report", &[("done", "bool", true)]));
        let alias = Ident::new("TransportTree".into(), Span::new(0, 0, 0));
        let names = typing::tree_names(&x, Some(&alias)).unwrap();
        assert_eq!(names, ["TransportTree", "TransportTree::Carry"]);
        let trees = imported_trees(&x, &names, &decls);
        let main = trees
            .iter()
            .find(|t| t.name.text == "TransportTree")
            .unwrap();
        let ports = crate::rules::ast::port_triples(&main.ports);
        // Through `_autoremap`, the called tree's ports; `arrived` only
        // written by an output port.
        assert_eq!(
            ports,
            [
                ("arg0", "robot", false),
                ("arg3", "zone", false),
                ("arrived", "bool", true)
            ]
        );
        // The SubTree call is named and its ports remapped by name.
        let mut seen = Vec::new();
        Template::walk_all(&main.body, &mut |t| {
            if let Template::Call { name, args, .. } = t {
                seen.push((
                    name.text.clone(),
                    args.iter().map(|a| a.port.text.clone()).collect::<Vec<_>>(),
                ));
            }
        });
        assert_eq!(
            seen[0],
            (
                "TransportTree::Carry".to_owned(),
                vec!["arg0".to_owned(), "arg3".to_owned()]
            )
        );
        // A literal is read as its port's type: `speed="0.5"` is a float.
        let carry = trees
            .iter()
            .find(|t| t.name.text == "TransportTree::Carry")
            .unwrap();
        let mut speed = None;
        Template::walk_all(&carry.body, &mut |t| {
            if let Template::Call { args, .. } = t {
                speed = args
                    .iter()
                    .find(|a| a.port.text == "speed")
                    .map(|a| a.value.clone());
            }
        });
        assert!(matches!(speed, Some(Value::Float { value, .. }) if value == 0.5));
        // The tag's span is in the XML.
        let Template::Control { span, .. } = &main.body[0] else {
            panic!("{:?}", main.body)
        };
        assert_eq!(
            &TRANSPORT[span.start as usize..span.end as usize],
            "Sequence"
        );
        let _ = Item::Tree(main.clone());
    }

    #[test]
    fn unknown_subtrees_cycles_and_unpicked_main_trees_are_reported() {
        let x = read_trees(
            r#"<root BTCPP_format="4"><BehaviorTree ID="A"><SubTree ID="B"/></BehaviorTree>
<BehaviorTree ID="B"><SubTree ID="A"/></BehaviorTree>
<BehaviorTree ID="C"><SubTree ID="Bee"/></BehaviorTree></root>"#,
            0,
        );
        let codes: Vec<&str> = x.diagnostics.iter().map(|d| d.code).collect();
        assert_eq!(codes, ["R073", "R073", "R073"], "{:?}", x.diagnostics);
        assert!(x.diagnostics[0].hint.as_deref().unwrap().contains("`B`"));
        let alias = Ident::new("T".into(), Span::new(0, 0, 0));
        assert!(typing::tree_names(&x, Some(&alias)).is_err());
        assert_eq!(typing::tree_names(&x, None).unwrap(), ["A", "B", "C"]);
    }
}
