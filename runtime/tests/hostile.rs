//! Trees and scenarios written to break the runtime: nesting ten times past
//! the limit (read and built on a small stack), files with very many trees,
//! and a run allowed no ticks.

use btc_pddl::diagnostic::codes;
use btc_runtime::engine::MAX_DEPTH;
use btc_runtime::{load_tree, Engine, Options, Status};
use btc_testkit::hostile::{assert_linear, on_small_stack};

fn xml(main: &str, trees: &str) -> String {
    format!(r#"<root BTCPP_format="4" main_tree_to_execute="{main}">{trees}</root>"#)
}

fn nested_xml(depth: usize) -> String {
    let body = format!(
        "{}<AlwaysSuccess/>{}",
        "<Inverter>".repeat(depth),
        "</Inverter>".repeat(depth)
    );
    xml(
        "M",
        &format!(r#"<BehaviorTree ID="M">{body}</BehaviorTree>"#),
    )
}

#[test]
fn xml_ten_times_the_limit_is_refused_on_a_small_stack() {
    let e = on_small_stack(|| load_tree(&nested_xml(10 * MAX_DEPTH)).map(|_| ()))
        .expect_err("too deep");
    assert_eq!(e.code, codes::X_TOO_DEEP);
    assert!(e.offset.is_some(), "the error points into the file");
}

/// Just under the limit, the whole way: read, built and run.
#[test]
fn xml_at_the_limit_is_read_built_and_run_on_a_small_stack() {
    let status = on_small_stack(|| {
        // The root BehaviorTree takes a level.
        let doc = btc_runtime::xml::parse(&nested_xml(MAX_DEPTH - 2)).expect("reads");
        let mut e = Engine::build(&doc, None, Options::default()).expect("builds");
        e.run(10, |_| {})
    });
    // An even number of inverters around a success.
    let expect = if (MAX_DEPTH - 2).is_multiple_of(2) {
        Status::Success
    } else {
        Status::Failure
    };
    assert_eq!(status, expect);
}

#[test]
fn json_ten_times_the_limit_is_refused_on_a_small_stack() {
    let depth = 10 * MAX_DEPTH;
    let open = r#"{"node":"control","control":{"kind":"sequence"},"name":null,"children":["#;
    let leaf = r#"{"node":"leaf","leaf":"action","id":"AlwaysSuccess","name":null,"ports":[]}"#;
    let root = format!("{}{leaf}{}", open.repeat(depth), "]}".repeat(depth));
    let text = format!(r#"{{"version":1,"main_tree":"M","root":{root}}}"#);
    let r = on_small_stack(move || load_tree(&text).map(|_| ()));
    assert!(r.is_err(), "a tree {depth} levels deep is refused");
}

/// Subtrees calling each other in a chain nest too: the engine refuses a
/// chain past its call limit (X004) rather than recursing through it.
#[test]
fn a_chain_of_subtrees_ten_times_the_limit_is_refused_on_a_small_stack() {
    let n = 10 * MAX_DEPTH;
    let mut trees: String = (0..n)
        .map(|i| {
            format!(
                r#"<BehaviorTree ID="T{i}"><SubTree ID="T{}"/></BehaviorTree>"#,
                i + 1
            )
        })
        .collect();
    trees.push_str(&format!(
        r#"<BehaviorTree ID="T{n}"><AlwaysSuccess/></BehaviorTree>"#
    ));
    let text = xml("T0", &trees);
    let r = on_small_stack(move || {
        let doc = btc_runtime::xml::parse(&text).expect("each tree is shallow");
        Engine::build(&doc, None, Options::default()).map(|_| ())
    });
    assert_eq!(r.expect_err("too deep").code, codes::X_SUBTREE);
}

/// Looking a `<BehaviorTree>` up by its ID is not a scan of the file's
/// trees: 100,000 trees used to take 22 s.
#[test]
fn many_trees_load_in_linear_time() {
    assert_linear(
        "loading a file of trees",
        5_000,
        30.0,
        |n| {
            let trees: String = (0..n)
                .map(|i| {
                    format!(
                        r#"<BehaviorTree ID="T{i}"><SubTree ID="T{}"/></BehaviorTree>"#,
                        (i + 1) % n
                    )
                })
                .collect();
            xml("T0", &trees)
        },
        |t| {
            load_tree(t).expect("loads");
        },
    );
}

/// `--max-ticks 0` ticks nothing (it used to tick once).
#[test]
fn a_run_allowed_no_ticks_ticks_nothing() {
    let doc = btc_runtime::xml::parse(&xml(
        "M",
        r#"<BehaviorTree ID="M"><AlwaysSuccess/></BehaviorTree>"#,
    ))
    .unwrap();
    let mut e = Engine::build(&doc, None, Options::default()).unwrap();
    assert_eq!(e.run(0, |_| panic!("no tick")), Status::Running);
    assert_eq!(e.summary(Status::Running).ticks, 0);
}
