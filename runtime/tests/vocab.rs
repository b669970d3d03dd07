//! Every node of the vocabulary (`btc_ir::vocab::NODES`) reaches the engine
//! the same way from the IR and from BT.CPP XML written with the table's
//! tag and ports: a node added to the table that the loader, the XML
//! reader or the engine lacks fails here (or does not compile there).

use btc_ir::vocab::{Arity, NodeName, NODES};
use btc_ir::{ControlKind, Count, DecoratorKind, LeafKind, Node, NodeScripts};
use btc_runtime::engine::Engine;
use btc_runtime::spec::{default_name, from_node, Kind};
use btc_runtime::{Options, Status};

/// The parameters' values: 1 for a threshold (two children), 3 otherwise.
fn value(spec: &btc_ir::NodeSpec, i: usize) -> u32 {
    match spec.params[i].ty {
        btc_ir::vocab::ParamType::Threshold => 1,
        _ => 3,
    }
}

fn leaf() -> Node {
    Node::Leaf {
        leaf: LeafKind::Action,
        id: "AlwaysSuccess".into(),
        name: None,
        ports: Vec::new(),
        scripts: NodeScripts::default(),
    }
}

/// The entry as the rules compile it.
fn ir_node(spec: &btc_ir::NodeSpec) -> Node {
    let values: Vec<u32> = (0..spec.params.len()).map(|i| value(spec, i)).collect();
    match spec.name {
        NodeName::Control(c) => Node::Control {
            control: ControlKind::new(c, &values),
            name: None,
            children: vec![leaf(), leaf()],
            scripts: NodeScripts::default(),
        },
        NodeName::Decorator(d) => Node::Decorator {
            decorator: DecoratorKind::new(d, Count::Fixed(values.first().map_or(0, |v| *v as u64))),
            name: None,
            child: Box::new(leaf()),
            scripts: NodeScripts::default(),
        },
    }
}

/// The entry as BT.CPP XML, written from the table's tag and ports.
fn xml(spec: &btc_ir::NodeSpec) -> String {
    let attrs: String = spec
        .params
        .iter()
        .enumerate()
        .map(|(i, p)| format!(" {}=\"{}\"", p.port, value(spec, i)))
        .collect();
    let children = match spec.arity {
        Arity::One => "<AlwaysSuccess/>",
        Arity::AtLeast(_) => "<AlwaysSuccess/><AlwaysSuccess/>",
    };
    format!(
        r#"<root BTCPP_format="4" main_tree_to_execute="T"><BehaviorTree ID="T"><{tag}{attrs}>{children}</{tag}></BehaviorTree></root>"#,
        tag = spec.tag
    )
}

fn run(doc: &btc_runtime::TreeDoc) -> Status {
    let mut e = Engine::build(doc, None, Options::default()).unwrap_or_else(|e| panic!("{e}"));
    e.run(1000, |_| {})
}

#[test]
fn every_vocabulary_node_loads_from_the_ir_and_from_xml_alike_and_runs() {
    for spec in NODES {
        let from_ir = from_node(&ir_node(spec));
        let doc = btc_runtime::xml::parse(&xml(spec)).unwrap_or_else(|e| panic!("{e}"));
        let from_xml = doc.tree("T").unwrap();
        assert_eq!(from_ir.kind, from_xml.kind, "{}", spec.keyword);
        assert_eq!(from_ir.kind.vocab(), Some(spec.name), "{}", spec.keyword);
        assert_eq!(default_name(&from_ir.kind), spec.tag);
        let ports: Vec<&str> = from_ir.kind.vocab_ports().iter().map(|(p, _)| *p).collect();
        let want: Vec<&str> = spec.params.iter().map(|p| p.port).collect();
        assert_eq!(ports, want, "{}", spec.keyword);

        // The engine runs both, to the same end.
        let mut ir_doc = doc.clone();
        ir_doc.trees[0].1.kind = from_ir.kind.clone();
        let status = run(&doc);
        assert_eq!(run(&ir_doc), status, "{}", spec.keyword);
        let want = match spec.keyword {
            "inverter" | "force_failure" => Status::Failure,
            _ => Status::Success,
        };
        assert_eq!(status, want, "{}", spec.keyword);
    }
}

/// The kinds the rules language does not have are BT.CPP's own: none of
/// them claims a vocabulary entry, and none has a table tag.
#[test]
fn btcpp_only_kinds_are_not_vocabulary_nodes() {
    for k in [
        Kind::SequenceWithMemory,
        Kind::KeepRunningUntilFailure,
        Kind::IfThenElse,
        Kind::WhileDoElse,
    ] {
        assert_eq!(k.vocab(), None, "{k:?}");
        assert!(
            btc_ir::NodeSpec::by_tag(default_name(&k)).is_none(),
            "{k:?}"
        );
    }
}
