use super::*;
use btc_ir::PortModel;

fn node(id: &str, kind: LeafKind, ports: &[(&str, &str)]) -> NodeModel {
    NodeModel {
        id: id.into(),
        kind,
        ports: ports
            .iter()
            .map(|(n, t)| PortModel {
                name: (*n).into(),
                direction: PortDirection::Input,
                ty: (*t).into(),
            })
            .collect(),
        formula: None,
    }
}

#[test]
fn accessors_avoid_keywords_and_base_members() {
    let m = node(
        "N",
        LeafKind::Action,
        &[
            ("robot", "robot"),
            ("class", "int"),
            ("name", "string"),
            ("name_port", "int"),
        ],
    );
    assert_eq!(
        accessors(&m),
        ["robot", "class_port", "name_port", "name_port_port"]
    );
}

#[test]
fn the_builtin_list_is_btcpp_4_10s() {
    let models = include_str!("../../../runtime/src/btcpp_builtins.xml");
    let ids: Vec<&str> = models
        .split("ID=\"")
        .skip(1)
        .map(|r| &r[..r.find('"').unwrap()])
        .collect();
    assert_eq!(ids, BTCPP_BUILTINS);
}

/// The node vocabulary's BT.CPP side is BT.CPP 4.10's: each entry's tag
/// is a built-in (so the executor refuses to register it again), a
/// `<Control>` when it takes a block and a `<Decorator>` when it takes
/// one child, and each parameter is one of its input ports, of a C++
/// type that holds the table's range.
#[test]
fn the_vocabulary_agrees_with_btcpp_4_10s_models() {
    use btc_ir::vocab::{Arity, ParamType, NODES};
    let models = include_str!("../../../runtime/src/btcpp_builtins.xml");
    for spec in NODES {
        assert!(BTCPP_BUILTINS.contains(&spec.tag), "{}", spec.tag);
        let at = models
            .find(&format!(" ID=\"{}\"", spec.tag))
            .unwrap_or_else(|| panic!("no model for {}", spec.tag));
        let element = models[..at].rsplit('<').next().unwrap();
        let want = match spec.arity {
            Arity::One => "Decorator",
            Arity::AtLeast(_) => "Control",
        };
        assert_eq!(element, want, "{}", spec.tag);
        let rest = &models[at..];
        let body = match rest.find('>') {
            Some(i) if rest[..i].ends_with('/') => "",
            _ => &rest[..rest.find(&format!("</{element}>")).unwrap()],
        };
        for p in spec.params {
            let decl = format!("<input_port name=\"{}\" type=\"", p.port);
            let ty = body
                .split(&decl)
                .nth(1)
                .and_then(|r| r.split('"').next())
                .unwrap_or_else(|| panic!("{} has no input port {}", spec.tag, p.port));
            let (min, max) = match ty {
                "int" => (i64::from(i32::MIN), i64::from(i32::MAX)),
                "unsigned int" => (0, i64::from(u32::MAX)),
                other => panic!("{}.{}: C++ type {other}", spec.tag, p.port),
            };
            assert!(
                min <= p.min && p.max <= max,
                "{}.{}: {}..={} does not fit `{ty}`",
                spec.tag,
                p.port,
                p.min,
                p.max
            );
            let unsigned = matches!(p.ty, ParamType::Millis);
            assert_eq!(ty == "unsigned int", unsigned, "{}.{}", spec.tag, p.port);
        }
    }
}

#[test]
fn literals_escape_what_cpp_reads_specially() {
    assert_eq!(literal("a\"b\\c\n?"), "\"a\\\"b\\\\c\\n?\"");
}

#[test]
fn user_file_keeps_its_classes_and_gains_missing_ones() {
    let a = node("MoveTo", LeafKind::Action, &[("robot", "robot")]);
    let b = node("Grasp", LeafKind::Action, &[]);
    let first = Spec {
        name: "ns",
        rules: "r.btrules",
        nodes: std::slice::from_ref(&a),
    };
    let mut text = user_nodes(&first);
    text = text.replace(
            "using MoveToBase::MoveToBase;",
            "using MoveToBase::MoveToBase;\n  BT::NodeStatus onStart() override { return BT::NodeStatus::SUCCESS; }",
        );
    let both = [a.clone(), b];
    let second = Spec {
        name: "ns",
        rules: "r.btrules",
        nodes: &both,
    };
    let up = update_user_nodes(&text, &second);
    assert_eq!(up.added, ["Grasp"]);
    let new = up.text.unwrap();
    assert!(new.starts_with(&text), "the user's text is kept as it was");
    assert!(new.contains("class Grasp : public GraspBase"));
    assert!(update_user_nodes(&new, &second).text.is_none());
    // MoveTo dropped from the rules: its class is stale.
    let only_b = [both[1].clone()];
    let third = Spec {
        name: "ns",
        rules: "r.btrules",
        nodes: &only_b,
    };
    let up = update_user_nodes(&new, &third);
    assert_eq!(up.stale.len(), 1);
    assert_eq!(up.stale[0].0, "MoveTo");
    assert_eq!(&new[up.stale[0].1.clone()], "MoveToBase");
}

#[test]
fn commented_out_classes_do_not_count() {
    let a = node("MoveTo", LeafKind::Action, &[]);
    let spec = Spec {
        name: "ns",
        rules: "r",
        nodes: std::slice::from_ref(&a),
    };
    let up = update_user_nodes("// class MoveTo : public MoveToBase {};\n", &spec);
    assert_eq!(up.added, ["MoveTo"]);
    assert!(up.stale.is_empty());
}

#[test]
fn reserved_and_clashing_names_are_reported() {
    let a = node("Sleep", LeafKind::Action, &[]);
    let b = node("delete", LeafKind::Action, &[]);
    let c = node("Move-To", LeafKind::Action, &[]);
    let d = node("Move_To", LeafKind::Action, &[]);
    let s = Span::new(0, 0, 1);
    let diags = check(&[(&a, s), (&b, s), (&c, s), (&d, s)]);
    let ids: Vec<&str> = diags.iter().map(|d| d.code).collect();
    assert_eq!(ids, ["C002", "C001", "C001"], "{diags:#?}");
}
