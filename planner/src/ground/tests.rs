use super::*;
use crate::test_util::{rooms, task};

fn lit(f: u32, positive: bool) -> GF {
    GF::Lit(Lit { fact: f, positive })
}

#[test]
fn formulas_simplify_as_they_are_built() {
    assert_eq!(gand(vec![GF::True, lit(1, true)]), lit(1, true));
    assert_eq!(gand(vec![lit(1, true), GF::False]), GF::False);
    assert_eq!(gor(vec![GF::False, GF::False]), GF::False);
    assert_eq!(gor(vec![lit(1, true), GF::True]), GF::True);
    assert_eq!(
        gand(vec![gand(vec![lit(1, true), lit(2, true)]), lit(3, false)]),
        GF::And(vec![lit(1, true), lit(2, true), lit(3, false)])
    );
    assert_eq!(
        negate(gor(vec![lit(1, true), lit(2, false)])),
        GF::And(vec![lit(1, false), lit(2, true)])
    );
}

#[test]
fn regression_through_start_effects() {
    let value: FxHashMap<u32, bool> = [(1, true), (2, false)].into_iter().collect();
    let f = gand(vec![lit(1, true), lit(3, true)]);
    assert_eq!(regress(f, &value), lit(3, true));
    assert_eq!(regress(lit(2, true), &value), GF::False);
    assert_eq!(regress(lit(2, false), &value), GF::True);
}

/// The semi-naive fixpoint finds what the naive one does: the same
/// atoms, operators and axioms, on every corpus problem.
#[test]
fn semi_naive_grounding_agrees_with_naive_grounding() {
    use btc_pddl::pipeline::{domain_unit_from, problem_unit_from};
    use btc_pddl::state::World;
    let Some(corpus) = btc_testkit::corpus() else {
        return;
    };
    let mut compared = 0;
    let mut dirs: Vec<_> = std::fs::read_dir(corpus)
        .unwrap()
        .map(|e| e.unwrap().path())
        .collect();
    dirs.sort();
    for dir in dirs {
        for p in ["p01", "p02"] {
            let own = dir.join(format!("{p}-domain.pddl"));
            let d = if own.exists() {
                own
            } else {
                dir.join("domain.pddl")
            };
            let read = |f: &std::path::Path| btc_pddl::source::decode(&std::fs::read(f).unwrap()).0;
            let du = domain_unit_from(&read(&d), 0);
            let dom = du.domain.as_ref().unwrap();
            let pu = problem_unit_from(
                &read(&dir.join(format!("{p}.pddl"))),
                1,
                Some(dom),
                &du.index,
            );
            let prob = pu.problem.as_ref().unwrap();
            let init = World::of_checked(dom, &du.index, prob, &pu.index)
                .expect("a world")
                .initial_state();
            let run = |f| {
                ground_with(
                    dom,
                    &du.index,
                    &pu.index,
                    &init,
                    prob.goal.as_ref(),
                    None,
                    f,
                )
                .unwrap()
                .unwrap()
            };
            let ((a, sa), (b, sb)) = (run(Fixpoint::SemiNaive), run(Fixpoint::Naive));
            assert_eq!(sa, sb, "{}/{p}", dir.display());
            assert_eq!(a.fact_names, b.fact_names, "{}/{p}", dir.display());
            let ops = |t: &Task| {
                let mut v: Vec<_> = t
                    .operators
                    .iter()
                    .map(|o| (o.action, o.args.clone(), o.pre.clone()))
                    .collect();
                v.sort();
                v
            };
            assert_eq!(ops(&a), ops(&b), "{}/{p}", dir.display());
            assert_eq!(a.axioms.len(), b.axioms.len());
            compared += 1;
        }
    }
    assert!(compared >= 40, "compared {compared}");
}

#[test]
fn static_facts_are_compiled_away() {
    let t = rooms();
    assert!(t.fact_names.iter().all(|n| !n.starts_with("(door")));
    assert!(t.fact_names.iter().all(|n| n != "(locked)"));
    // `locked` holds, so every `go` needs the key: no auxiliary fact
    // is left for the `or`.
    assert!(t.fact_names.iter().all(|n| !n.starts_with("(aux")));
}

#[test]
fn unreachable_atoms_and_actions_are_pruned() {
    let t = task(
        include_str!("../../tests/fixtures/rooms-domain.pddl"),
        include_str!("../../tests/fixtures/rooms-unsolvable.pddl"),
    );
    // No door leads into the hall.
    assert!(!t.fact_names.iter().any(|n| n == "(at hall)"));
    // From the lab: take the key there, go to the vault, take it there.
    assert_eq!(t.operators.len(), 3, "{:?}", t.operators);
}

#[test]
fn durative_actions_fold_start_and_end() {
    let t = task(
        include_str!("../../../examples/p3_assembler/domain.pddl"),
        include_str!("../../../examples/p3_assembler/problem.pddl"),
    );
    // MOVE_TO deletes `at ?from` at start and adds `at ?to` at end.
    let mv = t
        .operators
        .iter()
        .find(|o| o.action == 0 && o.args[1] != o.args[2])
        .expect("a move");
    assert_eq!(mv.effects.iter().filter(|e| e.add).count(), 1);
    assert_eq!(mv.effects.iter().filter(|e| !e.add).count(), 1);
    // A self-move keeps the robot where it is: the end add wins.
    let stay = t
        .operators
        .iter()
        .find(|o| o.action == 0 && o.args[1] == o.args[2] && crate::task::holds(&t.init, &o.pre))
        .expect("a self-move where the robot is");
    let mut out = Vec::new();
    let mut ax = crate::task::AxiomScratch::default();
    t.apply(stay, &t.init, &mut out, &mut ax);
    assert_eq!(out, t.init);
}
