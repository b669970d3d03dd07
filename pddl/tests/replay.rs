//! The cached replay against the general one: for the examples' plans, the
//! fixtures in `tests/fixtures/replay/` and the timed ones in
//! `tests/fixtures/timed/`, the IPC corpus' plans, and plans
//! mutated to fail at every step, both give the same `Validation` (the same
//! cost, steps and diagnostics, to the letter). The fixtures' expected
//! outcomes are also stated, so that a fault both replays share shows.

use btc_pddl::diagnostic::has_errors;
use btc_pddl::pipeline::{domain_unit, plan_unit, problem_unit, DomainUnit, ProblemUnit};
use btc_pddl::source::Sources;
use btc_pddl::state::World;
use btc_pddl::validate::{validate, Replay, Validation};
use std::path::{Path, PathBuf};

/// A domain and problem, checked, with the world they make.
struct Setting {
    sources: Sources,
    domain: DomainUnit,
    problem: ProblemUnit,
    world: World,
}

impl Setting {
    fn load(domain: &Path, problem: &Path) -> Setting {
        let mut sources = Sources::new();
        let d = sources.add(domain.display().to_string(), read(domain));
        let p = sources.add(problem.display().to_string(), read(problem));
        let domain = domain_unit(&sources, d);
        let problem = problem_unit(&sources, p, &domain);
        assert!(!has_errors(&domain.diagnostics), "{:?}", domain.diagnostics);
        assert!(
            !has_errors(&problem.diagnostics),
            "{:?}",
            problem.diagnostics
        );
        let world = World::of_checked(
            domain.domain.as_ref().unwrap(),
            &domain.index,
            problem.problem.as_ref().unwrap(),
            &problem.index,
        )
        .unwrap();
        Setting {
            sources,
            domain,
            problem,
            world,
        }
    }

    /// Replays a plan's text both ways; panics unless they agree.
    fn replay(&mut self, name: &str, text: &str) -> Validation {
        let f = self.sources.add(name, text.to_owned());
        let plan = plan_unit(&self.sources, f, &self.domain, &self.problem);
        assert!(
            !has_errors(&plan.diagnostics),
            "{name}: {:?}",
            plan.diagnostics
        );
        let by = |replay| {
            validate(
                replay,
                &self.world,
                self.domain.domain.as_ref().unwrap(),
                self.problem.problem.as_ref().unwrap(),
                &plan.plan,
                &plan.steps,
            )
        };
        let (cached, general) = (by(Replay::Cached), by(Replay::General));
        assert_eq!(cached, general, "{name}: the replays differ\n{text}");
        assert_eq!(
            cached.cost.to_bits(),
            general.cost.to_bits(),
            "{name}: the costs differ"
        );
        cached
    }

    /// Replays the plan and, for each step, the plan without it, with it
    /// twice, and with it swapped with the next: mutants that fail at
    /// (or after) every step. Returns how many plans were replayed.
    fn replay_with_mutants(&mut self, name: &str, text: &str) -> usize {
        self.replay(name, text);
        let steps: Vec<&str> = text
            .lines()
            .filter(|l| l.contains('(') && !l.trim_start().starts_with(';'))
            .collect();
        let mut replayed = 1;
        for k in 0..steps.len() {
            let mut dropped = steps.clone();
            dropped.remove(k);
            let mut doubled = steps.clone();
            doubled.insert(k, steps[k]);
            let mut mutants = vec![("dropped", dropped), ("doubled", doubled)];
            if k + 1 < steps.len() {
                let mut swapped = steps.clone();
                swapped.swap(k, k + 1);
                mutants.push(("swapped", swapped));
            }
            for (how, m) in mutants {
                self.replay(&format!("{name} ({how} step {})", k + 1), &m.join("\n"));
                replayed += 1;
            }
        }
        replayed
    }
}

fn read(path: &Path) -> String {
    std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

fn fixtures() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/replay")
}

/// What a fixture plan's replay must give.
struct Expected {
    plan: &'static str,
    valid: bool,
    steps_applied: usize,
    /// The diagnostics' codes, in order.
    codes: &'static [&'static str],
}

const LIGHTS: &[Expected] = &[
    Expected {
        plan: "valid.plan",
        valid: true,
        steps_applied: 12,
        codes: &[],
    },
    // `toggle l1` turned the light on the first time and off the second:
    // its conditional effects are not the same at every use.
    Expected {
        plan: "toggled-off.plan",
        valid: false,
        steps_applied: 4,
        codes: &["V001"],
    },
    // `wear` has a value for l1 only.
    Expected {
        plan: "no-wear.plan",
        valid: false,
        steps_applied: 5,
        codes: &["V004"],
    },
    Expected {
        plan: "same-light.plan",
        valid: false,
        steps_applied: 1,
        codes: &["V001"],
    },
    Expected {
        plan: "different-lights.plan",
        valid: false,
        steps_applied: 3,
        codes: &["V001"],
    },
    Expected {
        plan: "neither.plan",
        valid: false,
        steps_applied: 0,
        codes: &["V001"],
    },
    // The cost reaches 10 after ten toggles.
    Expected {
        plan: "too-dear.plan",
        valid: false,
        steps_applied: 11,
        codes: &["V001"],
    },
    // `toggle` (general) switches l1 off between two cached `switch_on l1`.
    Expected {
        plan: "switched-twice.plan",
        valid: false,
        steps_applied: 3,
        codes: &["V001"],
    },
    Expected {
        plan: "goal-missed.plan",
        valid: false,
        steps_applied: 3,
        codes: &["V002"],
    },
    Expected {
        plan: "wrong-cost.plan",
        valid: true,
        steps_applied: 3,
        codes: &["V003"],
    },
];

const ROOMS: &[Expected] = &[
    Expected {
        plan: "derived-valid.plan",
        valid: true,
        steps_applied: 6,
        codes: &[],
    },
    Expected {
        plan: "derived-dark.plan",
        valid: false,
        steps_applied: 2,
        codes: &["V001"],
    },
];

fn check_fixtures(domain: &str, problem: &str, expected: &[Expected]) -> usize {
    let dir = fixtures();
    let mut s = Setting::load(&dir.join(domain), &dir.join(problem));
    let mut replayed = 0;
    for e in expected {
        let text = read(&dir.join(e.plan));
        let v = s.replay(e.plan, &text);
        let codes: Vec<&str> = v.diagnostics.iter().map(|d| d.code).collect();
        assert_eq!(
            (v.valid, v.steps_applied, codes.as_slice()),
            (e.valid, e.steps_applied, e.codes),
            "{}: {:?}",
            e.plan,
            v.diagnostics
        );
        replayed += s.replay_with_mutants(e.plan, &text);
    }
    replayed
}

#[test]
fn state_dependent_effects_and_conditions_replay_alike() {
    assert!(check_fixtures("domain.pddl", "problem.pddl", LIGHTS) > 100);
}

#[test]
fn derived_predicates_replay_alike() {
    check_fixtures("derived-domain.pddl", "derived-problem.pddl", ROOMS);
}

#[test]
fn the_valid_fixture_costs_what_its_numeric_effects_add_up_to() {
    let dir = fixtures();
    let mut s = Setting::load(&dir.join("domain.pddl"), &dir.join("problem.pddl"));
    let v = s.replay("valid.plan", &read(&dir.join("valid.plan")));
    assert_eq!(v.cost, 11.0);
}

#[test]
fn the_examples_plans_and_their_mutants_replay_alike() {
    let examples = Path::new(env!("CARGO_MANIFEST_DIR")).join("../examples");
    let mut replayed = 0;
    for dir in btc_testkit::sorted_entries(&examples)
        .into_iter()
        .filter(|d| d.is_dir())
    {
        let (domain, problem) = (dir.join("domain.pddl"), dir.join("problem.pddl"));
        if !domain.exists() || !problem.exists() {
            continue;
        }
        let plans: Vec<PathBuf> = btc_testkit::sorted_entries(&dir)
            .into_iter()
            .filter(|p| file_name(p).starts_with("plan."))
            .collect();
        let mut s = Setting::load(&domain, &problem);
        for plan in plans {
            replayed += s.replay_with_mutants(&plan.display().to_string(), &read(&plan));
        }
    }
    assert!(replayed > 80, "only {replayed} example plans replayed");
}

/// Timed plans: concurrent and overlapping actions, `over all` conditions
/// broken by another action's event, wrong durations; their mutants put
/// two steps at one time, drop one, or swap two.
#[test]
fn the_timed_fixtures_and_their_mutants_replay_alike() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/timed");
    let mut s = Setting::load(&dir.join("domain.pddl"), &dir.join("p1.pddl"));
    let mut replayed = 0;
    let mut refused = 0;
    for plan in btc_testkit::sorted_entries(&dir)
        .into_iter()
        .filter(|p| file_name(p).starts_with("p1.") && file_name(p).ends_with(".tplan"))
    {
        let text = read(&plan);
        refused += usize::from(!s.replay(&file_name(&plan), &text).valid);
        replayed += s.replay_with_mutants(&file_name(&plan), &text);
    }
    assert!(replayed > 100, "only {replayed} timed plans replayed");
    assert!(refused >= 5, "only {refused} fixtures refused");
}

#[test]
fn the_corpus_plans_and_their_mutants_replay_alike() {
    let Some(cases) = btc_testkit::corpus_cases() else {
        return;
    };
    let mut replayed = 0;
    for case in cases {
        let mut s = Setting::load(&case.domain, &case.problem);
        for plan in &case.plans {
            replayed += s.replay_with_mutants(&plan.display().to_string(), &read(plan));
        }
    }
    assert!(replayed > 1000, "only {replayed} corpus plans replayed");
}

fn file_name(p: &Path) -> String {
    p.file_name().unwrap().to_string_lossy().into_owned()
}
