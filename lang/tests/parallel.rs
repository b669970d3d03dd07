//! `steps parallel`: every order of steps that the parallel tree allows
//! (chains in order, `WaitForStep` edges respected) is a valid plan.

use btc_ir::{Node, PortValue, TreeIr};
use btc_lang::db::{compile, CompileJob, Database};
use btc_pddl::pipeline::{domain_unit, plan_unit, problem_unit, validate_units};
use btc_pddl::source::Sources;
use std::path::Path;

fn root() -> &'static Path {
    Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/.."))
}

fn read(p: &str) -> String {
    std::fs::read_to_string(root().join(p)).unwrap()
}

fn compile_parallel(rules: &str, problem: &str, plan: &str) -> TreeIr {
    let mut db = Database::new();
    db.set_file(
        "examples/two_robots/domain.pddl",
        read("examples/two_robots/domain.pddl"),
    );
    let r = db.set_file(rules, read(rules));
    let p = db.set_file(problem, read(problem));
    let l = db.set_file(plan, read(plan));
    let job = CompileJob::new(&db, r, l, Some(p), None);
    compile(&db, job)
        .clone()
        .unwrap_or_else(|e| panic!("{e:#?}"))
        .as_ref()
        .clone()
}

/// Edges `a -> b` (0-based steps) the tree enforces.
fn constraints(ir: &TreeIr) -> Vec<(usize, usize)> {
    let Node::Control {
        children: chains, ..
    } = &ir.root
    else {
        panic!("root is the Parallel node")
    };
    let mut edges = Vec::new();
    for chain in chains {
        let Node::Control { children, .. } = chain else {
            panic!("a chain is a Sequence")
        };
        let mut prev: Option<usize> = None;
        let mut waits = Vec::new();
        for c in children {
            match c {
                Node::Leaf { id, ports, .. } if id == "WaitForStep" => {
                    let PortValue::Int(k) = ports[0].value else {
                        panic!()
                    };
                    waits.push(k as usize - 1);
                }
                Node::Step { step, .. } => {
                    if let Some(p) = prev {
                        edges.push((p, *step));
                    }
                    edges.extend(waits.drain(..).map(|w| (w, *step)));
                    prev = Some(*step);
                }
                other => panic!("unexpected {other:?}"),
            }
        }
    }
    edges
}

fn all_orders(n: usize, edges: &[(usize, usize)]) -> Vec<Vec<usize>> {
    fn go(n: usize, edges: &[(usize, usize)], done: &mut Vec<usize>, out: &mut Vec<Vec<usize>>) {
        if done.len() == n {
            out.push(done.clone());
            return;
        }
        for s in 0..n {
            if done.contains(&s) {
                continue;
            }
            if edges.iter().any(|&(a, b)| b == s && !done.contains(&a)) {
                continue;
            }
            done.push(s);
            go(n, edges, done, out);
            done.pop();
        }
    }
    let mut out = Vec::new();
    go(n, edges, &mut Vec::new(), &mut out);
    out
}

fn check_every_order(rules: &str, problem: &str, plan: &str) -> usize {
    let ir = compile_parallel(rules, problem, plan);
    let edges = constraints(&ir);
    let orders = all_orders(ir.steps.len(), &edges);
    let mut sources = Sources::new();
    let d = sources.add("domain", read("examples/two_robots/domain.pddl"));
    let p = sources.add("problem", read(problem));
    let du = domain_unit(&sources, d);
    let pu = problem_unit(&sources, p, &du);
    for order in &orders {
        let text: String = order
            .iter()
            .map(|&i| format!("{}\n", ir.steps[i].display()))
            .collect();
        let f = sources.add("order", text.clone());
        let lu = plan_unit(&sources, f, &du, &pu);
        let v = validate_units(&du, &pu, &lu).expect("typed");
        assert!(
            v.valid,
            "this order is allowed but invalid:\n{text}{:?}",
            v.diagnostics
        );
    }
    orders.len()
}

#[test]
fn independent_robots_run_in_any_interleaving() {
    let n = check_every_order(
        "examples/two_robots/rules.btrules",
        "examples/two_robots/problem.pddl",
        "examples/two_robots/plan.plan",
    );
    // Two chains of four steps: C(8, 4) interleavings.
    assert_eq!(n, 70);
}

#[test]
fn a_hand_over_waits_for_the_other_robot() {
    let dir = "lang/tests/fixtures/parallel";
    let ir = compile_parallel(
        &format!("{dir}/rules.btrules"),
        &format!("{dir}/problem.pddl"),
        &format!("{dir}/plan.plan"),
    );
    let mut waits = 0;
    ir.root.walk(&mut |n| {
        if matches!(n, Node::Leaf { id, .. } if id == "WaitForStep") {
            waits += 1;
        }
    });
    assert!(
        waits >= 1,
        "the ceiling robot must wait for the floor robot's place"
    );
    let n = check_every_order(
        &format!("{dir}/rules.btrules"),
        &format!("{dir}/problem.pddl"),
        &format!("{dir}/plan.plan"),
    );
    assert!(n > 1, "some steps are still independent");
}
