//! The planner on the IPC corpus in `../shared/corpus/` (walked, not
//! listed): greedy search finds plans that the front end's validator
//! accepts, and A* with admissible heuristics finds the optimal costs the
//! corpus records. The benchmark (`cargo bench -p btc-planner`) runs the
//! whole corpus with both; A* here runs on the problems it solves quickly.

mod common;

use btc_planner::{Algorithm, Heuristic, Options};
use common::*;

fn corpus_problems() -> Vec<(String, String)> {
    let mut out = Vec::new();
    let mut dirs: Vec<_> = std::fs::read_dir(corpus_dir())
        .expect("corpus directory (set BTC_CORPUS to override)")
        .map(|e| e.unwrap().path())
        .filter(|p| p.is_dir())
        .collect();
    dirs.sort();
    for dir in dirs {
        let domain = dir.file_name().unwrap().to_string_lossy().into_owned();
        let mut problems: Vec<String> = std::fs::read_dir(&dir)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .filter(|n| n.ends_with(".pddl") && !n.contains("domain"))
            .map(|n| n.trim_end_matches(".pddl").to_owned())
            .filter(|stem| dir.join(format!("{stem}.plan")).exists())
            .collect();
        problems.sort();
        out.extend(problems.into_iter().map(|p| (domain.clone(), p)));
    }
    assert!(out.len() >= 40, "expected the 40 corpus problems");
    out
}

#[test]
fn greedy_search_solves_the_corpus_with_valid_plans() {
    if btc_testkit::corpus().is_none() {
        return;
    }
    let mut solved = 0;
    for (domain, problem) in corpus_problems() {
        let (d, p) = corpus_case(&domain, &problem);
        let mut l = load(&d, &p);
        let (_, cost, report) = l.solve_and_validate(&Options::default());
        assert!(cost >= 0.0);
        assert!(report.search.expanded > 0 || report.ground.operators > 0);
        solved += 1;
    }
    assert!(solved >= 40, "solved {solved}");
}

/// Problems A* with h_max solves within a second or so; the rest are in
/// the benchmark.
const ASTAR_SUBSET: &[(&str, &str)] = &[
    ("blocks", "p01"),
    ("blocks", "p02"),
    ("gripper", "p01"),
    ("logistics", "p01"),
    ("depot", "p01"),
    ("rovers", "p01"),
    ("rovers", "p02"),
    ("visitall", "p02"),
    ("storage", "p01"),
    ("storage", "p02"),
    ("elevators", "p02"),
    ("transport", "p01"),
    ("transport", "p02"),
    ("hiking", "p01"),
    ("miconic-simpleadl", "p01"),
    ("miconic-simpleadl", "p02"),
    ("psr-middle", "p01"),
    ("psr-middle", "p02"),
    ("openstacks-adl", "p01"),
    ("tidybot", "p01"),
];

#[test]
fn astar_with_an_admissible_heuristic_finds_the_recorded_optimal_costs() {
    if btc_testkit::corpus().is_none() {
        return;
    }
    let optimal = optimal_domains();
    let opts = Options {
        algorithm: Algorithm::Astar,
        heuristic: Heuristic::Max,
        timeout: None,
        ..Options::default()
    };
    let mut compared = 0;
    for &(domain, problem) in ASTAR_SUBSET {
        let (_, o1, o2) = optimal
            .iter()
            .find(|(d, _, _)| d == domain)
            .unwrap_or_else(|| panic!("{domain} is not in the corpus README"));
        let is_optimal = if problem == "p01" { *o1 } else { *o2 };
        let (d, p) = corpus_case(domain, problem);
        let mut l = load(&d, &p);
        let (_, cost, _) = l.solve_and_validate(&opts);
        let reference = stated_cost(&corpus_dir().join(domain).join(format!("{problem}.plan")));
        if is_optimal {
            assert_eq!(
                cost, reference,
                "{domain}/{problem}: A* cost vs optimal reference"
            );
            compared += 1;
        } else {
            assert!(
                cost <= reference,
                "{domain}/{problem}: A* worse than a satisficing plan"
            );
        }
    }
    assert!(compared >= 15, "compared {compared}");
}

#[test]
fn astar_with_h_max_and_with_blind_search_agree_on_small_problems() {
    if btc_testkit::corpus().is_none() {
        return;
    }
    for (domain, problem) in [
        ("gripper", "p01"),
        ("blocks", "p01"),
        ("miconic-simpleadl", "p01"),
        ("psr-middle", "p02"),
        ("visitall", "p02"),
        ("storage", "p02"),
        ("transport", "p01"),
        ("openstacks-adl", "p01"),
    ] {
        let (d, p) = corpus_case(domain, problem);
        let mut l = load(&d, &p);
        let costs: Vec<f64> = [Heuristic::Max, Heuristic::Blind]
            .into_iter()
            .map(|heuristic| {
                let opts = Options {
                    algorithm: Algorithm::Astar,
                    heuristic,
                    timeout: None,
                    ..Options::default()
                };
                l.solve_and_validate(&opts).1
            })
            .collect();
        assert_eq!(costs[0], costs[1], "{domain}/{problem}");
        // h_add and h_FF are not admissible, but their A* plans are valid
        // and no cheaper than the optimum.
        for heuristic in [Heuristic::Add, Heuristic::Ff] {
            let opts = Options {
                algorithm: Algorithm::Astar,
                heuristic,
                timeout: None,
                ..Options::default()
            };
            assert!(l.solve_and_validate(&opts).1 >= costs[0]);
        }
    }
}

/// On the initial state of every corpus problem with an optimal reference,
/// h_max <= LM-cut <= the optimal cost (LM-cut dominates h_max and is
/// admissible), and A* with LM-cut finds the optimal cost on the subset.
#[test]
fn lm_cut_lies_between_h_max_and_the_optimal_cost() {
    if btc_testkit::corpus().is_none() {
        return;
    }
    use btc_pddl::state::World;
    use btc_planner::heuristic::Evaluator;
    let optimal = optimal_domains();
    let mut checked = 0;
    for (domain, problem) in corpus_problems() {
        let Some((_, o1, o2)) = optimal.iter().find(|(d, _, _)| *d == domain) else {
            continue;
        };
        if !(if problem == "p01" { *o1 } else { *o2 }) {
            continue;
        }
        let (d, p) = corpus_case(&domain, &problem);
        let l = load(&d, &p);
        let (dom, prob) = (
            l.du.domain.as_ref().unwrap(),
            l.pu.problem.as_ref().unwrap(),
        );
        let init = World::of_checked(dom, &l.du.index, prob, &l.pu.index)
            .unwrap()
            .initial_state();
        let (task, _) = btc_planner::ground::ground(
            dom,
            &l.du.index,
            &l.pu.index,
            &init,
            prob.goal.as_ref(),
            None,
        )
        .unwrap()
        .unwrap();
        let h = |kind| {
            Evaluator::new(&task, kind, false)
                .eval(&task, &task.init)
                .expect("solvable")
        };
        let (max, lmcut) = (h(Heuristic::Max), h(Heuristic::LmCut));
        let reference = stated_cost(&corpus_dir().join(&domain).join(format!("{problem}.plan")));
        assert!(
            max <= lmcut,
            "{domain}/{problem}: h_max {max} > LM-cut {lmcut}"
        );
        assert!(
            lmcut as f64 <= reference,
            "{domain}/{problem}: LM-cut {lmcut} > optimal {reference}"
        );
        checked += 1;
    }
    assert!(checked >= 30, "checked {checked}");
    let opts = Options {
        algorithm: Algorithm::Astar,
        heuristic: Heuristic::LmCut,
        timeout: None,
        ..Options::default()
    };
    for (domain, problem) in [("logistics", "p01"), ("depot", "p02"), ("elevators", "p01")] {
        let (d, p) = corpus_case(domain, problem);
        let reference = stated_cost(&corpus_dir().join(domain).join(format!("{problem}.plan")));
        assert_eq!(load(&d, &p).solve_and_validate(&opts).1, reference);
    }
}

/// LAMA's restarts: the same plan on every run (the budget is work, not
/// time), never costlier than the first plan, and on problems where the
/// first greedy plan is poor they find the cheaper one (blocks/p01: the
/// greedy 10 steps against the optimal 6; barman/p01 and p02: 113 and 110
/// against 102 and 104, the costs lama-first finds; both reach 94 with
/// landmarks costed by their first achievers).
#[test]
fn lama_restarts_are_deterministic_and_only_make_plans_cheaper() {
    if btc_testkit::corpus().is_none() {
        return;
    }
    for (domain, problem, at_most) in [
        ("blocks", "p01", 6.0),
        ("floortile", "p01", 38.0),
        ("barman", "p01", 102.0),
        ("barman", "p02", 104.0),
        ("elevators", "p01", 42.0),
    ] {
        let (d, p) = corpus_case(domain, problem);
        let mut l = load(&d, &p);
        let (text, cost, report) = l.solve_and_validate(&Options::default());
        let first = report.search.first_cost.expect("a first plan") as f64;
        assert!(
            report.search.iterations > 1,
            "{domain}/{problem}: no restarts"
        );
        assert!(cost <= first, "{domain}/{problem}: {cost} after {first}");
        assert!(cost <= at_most, "{domain}/{problem}: cost {cost}");
        let (again, _, _) = l.solve_and_validate(&Options::default());
        assert_eq!(text, again, "{domain}/{problem}: not deterministic");
        // Without restarts, the first plan is the answer.
        let first_only = Options {
            improve: 0,
            ..Options::default()
        };
        let (_, cost0, r0) = l.solve_and_validate(&first_only);
        assert_eq!((cost0, r0.search.iterations), (first, 1));
    }
}
