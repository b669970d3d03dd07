use super::*;
use crate::spec::{Kind, SNode, TreeDoc};

fn leaf(id: &str) -> SNode {
    SNode::leaf(id)
}

#[test]
fn a_failure_made_by_a_decorator_is_recorded_as_its_own() {
    // An earlier, recovered failure must not be blamed.
    let fallback = SNode {
        kind: Kind::Fallback,
        name: None,
        children: vec![leaf("AlwaysFailure"), leaf("AlwaysSuccess")],
        scripts: Default::default(),
        at: None,
    };
    let inverter = SNode {
        kind: Kind::Inverter,
        name: Some("not done".into()),
        children: vec![leaf("AlwaysSuccess")],
        scripts: Default::default(),
        at: None,
    };
    let root = SNode {
        kind: Kind::Sequence,
        name: None,
        children: vec![fallback, inverter],
        scripts: Default::default(),
        at: None,
    };
    let doc = TreeDoc {
        main: "M".into(),
        trees: vec![("M".into(), root)],
        ..TreeDoc::default()
    };
    let mut e = Engine::build(&doc, None, Options::default()).unwrap();
    assert_eq!(e.run(10, |_| {}), Status::Failure);
    assert_eq!(e.records.len(), 1);
    assert_eq!(e.records[0].node_name, "not done");
    assert_eq!(e.records[0].reason, "its child succeeded (Inverter)");
}

#[test]
fn an_empty_tree_of_one_leaf_runs() {
    let doc = TreeDoc {
        main: "M".into(),
        trees: vec![(
            "M".into(),
            SNode {
                kind: Kind::Leaf {
                    id: "AlwaysFailure".into(),
                    kind: None,
                    ports: Vec::new(),
                },
                name: None,
                children: Vec::new(),
                scripts: Default::default(),
                at: None,
            },
        )],
        ..TreeDoc::default()
    };
    let mut e = Engine::build(&doc, None, Options::default()).unwrap();
    assert_eq!(e.run(10, |_| {}), Status::Failure);
    assert_eq!(e.records.len(), 1);
    assert_eq!(e.records[0].reason, "AlwaysFailure");
}
