//! The whole IPC corpus in `../shared/corpus/` (found by walking it, not by a
//! list): every domain and problem checks with zero errors and every plan
//! validates; mutated plans are caught at the right step.

use btc_pddl::diagnostic::{has_errors, Diagnostic};
use btc_pddl::pipeline::{
    domain_unit, plan_unit, problem_unit, validate_units, DomainUnit, ProblemUnit,
};
use btc_pddl::render::to_short;
use btc_pddl::source::Sources;
use std::path::Path;

use btc_testkit::CorpusCase as Case;

/// Every corpus case; `None` (the test skipped) without the corpus.
fn cases() -> Option<Vec<Case>> {
    let out = btc_testkit::corpus_cases()?;
    assert!(
        out.len() >= 40,
        "expected the 40 corpus problems, found {}",
        out.len()
    );
    Some(out)
}

fn load(sources: &mut Sources, path: &Path) -> u32 {
    let bytes = std::fs::read(path).unwrap();
    let (text, problem) = btc_pddl::source::decode(&bytes);
    assert!(problem.is_none(), "{}: {problem:?}", path.display());
    sources.add(path.display().to_string(), text)
}

fn errors(diags: &[Diagnostic], sources: &Sources) -> Vec<String> {
    diags
        .iter()
        .filter(|d| d.is_error())
        .map(|d| to_short(d, sources))
        .collect()
}

fn units(case: &Case, sources: &mut Sources) -> (DomainUnit, ProblemUnit) {
    let d = load(sources, &case.domain);
    let p = load(sources, &case.problem);
    let du = domain_unit(sources, d);
    let pu = problem_unit(sources, p, &du);
    (du, pu)
}

#[test]
fn every_domain_and_problem_checks_and_every_plan_validates() {
    let mut plans = 0;
    let mut failures = Vec::new();
    let Some(cases) = cases() else { return };
    for case in cases {
        let mut sources = Sources::new();
        let (du, pu) = units(&case, &mut sources);
        failures.extend(errors(&du.diagnostics, &sources));
        failures.extend(errors(&pu.diagnostics, &sources));
        for plan in &case.plans {
            plans += 1;
            let f = load(&mut sources, plan);
            let lu = plan_unit(&sources, f, &du, &pu);
            failures.extend(errors(&lu.diagnostics, &sources));
            match validate_units(&du, &pu, &lu) {
                Some(v) if v.valid && v.diagnostics.is_empty() => {}
                Some(v) => failures.extend(v.diagnostics.iter().map(|d| to_short(d, &sources))),
                None => failures.push(format!("{}: not validated", plan.display())),
            }
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
    assert!(plans >= 42, "expected at least 42 plans, found {plans}");
}

/// Corpus plans made by a satisficing planner (lama-first, see the corpus
/// README): dropping a step from them may leave a valid plan.
const SATISFICING: &[&str] = &["childsnack", "assembly"];

struct Mutant {
    text: String,
    /// 0-based index of the first step that may fail.
    first_suspect: usize,
}

fn plan_lines(text: &str) -> Vec<String> {
    text.lines()
        .filter(|l| l.trim_start().starts_with('('))
        .map(str::to_owned)
        .collect()
}

/// Validates a mutated plan; returns the index of the failing step (the
/// steps' count when only the goal fails), or `None` when it is valid.
fn failing_step(
    sources: &mut Sources,
    du: &DomainUnit,
    pu: &ProblemUnit,
    text: &str,
) -> Option<usize> {
    let f = sources.add("mutant.plan", text.to_owned());
    let lu = plan_unit(sources, f, du, pu);
    assert!(
        !has_errors(&lu.diagnostics),
        "{:?}",
        errors(&lu.diagnostics, sources)
    );
    let v = validate_units(du, pu, &lu).unwrap();
    if v.valid {
        return None;
    }
    let d = &v.diagnostics[0];
    if d.code == "V001" {
        // The diagnostic must point at the failing step's line.
        let line = sources.get(f).line_col(d.span.start).0 as usize;
        assert_eq!(line, v.steps_applied + 1, "{}", d.message);
        Some(v.steps_applied)
    } else {
        assert_eq!(d.code, "V002");
        Some(lu.plan.steps.len())
    }
}

#[test]
fn dropped_and_swapped_steps_are_caught_at_the_right_step() {
    let (mut dropped, mut swapped) = (0, 0);
    let Some(cases) = cases() else { return };
    for case in cases {
        let mut sources = Sources::new();
        let (du, pu) = units(&case, &mut sources);
        let domain_name = case.dir.file_name().unwrap().to_string_lossy().into_owned();
        for plan in case
            .plans
            .iter()
            .filter(|p| p.extension().unwrap() == "plan")
        {
            let text = std::fs::read_to_string(plan).unwrap();
            let unit_cost = text.contains("(unit cost)");
            let steps = plan_lines(&text);
            let mut mutants = Vec::new();
            for k in 0..steps.len() {
                let mut s = steps.clone();
                s.remove(k);
                mutants.push((
                    true,
                    Mutant {
                        text: s.join("\n"),
                        first_suspect: k,
                    },
                ));
                if k + 1 < steps.len() && steps[k] != steps[k + 1] {
                    let mut s = steps.clone();
                    s.swap(k, k + 1);
                    mutants.push((
                        false,
                        Mutant {
                            text: s.join("\n"),
                            first_suspect: k,
                        },
                    ));
                }
            }
            for (is_drop, m) in mutants {
                let fail = failing_step(&mut sources, &du, &pu, &m.text);
                if let Some(at) = fail {
                    // Steps before the mutation are untouched and still apply.
                    assert!(
                        at >= m.first_suspect,
                        "{}: failure at {at}, mutation at {}",
                        plan.display(),
                        m.first_suspect
                    );
                    if is_drop {
                        dropped += 1
                    } else {
                        swapped += 1
                    }
                } else if is_drop && unit_cost && !SATISFICING.contains(&domain_name.as_str()) {
                    panic!(
                        "{}: dropping step {} of an optimal unit-cost plan left it valid",
                        plan.display(),
                        m.first_suspect + 1
                    );
                }
            }
        }
    }
    eprintln!("dropped {dropped} swapped {swapped}");
    assert!(
        dropped > 500 && swapped > 300,
        "dropped {dropped}, swapped {swapped}"
    );
}

#[test]
fn an_argument_of_another_type_is_a_typing_error_at_its_step() {
    let mut mutated = 0;
    let Some(cases) = cases() else { return };
    for case in cases {
        let mut sources = Sources::new();
        let (du, pu) = units(&case, &mut sources);
        let domain = du.domain.as_ref().unwrap();
        for plan in case
            .plans
            .iter()
            .filter(|p| p.extension().unwrap() == "plan")
        {
            let text = std::fs::read_to_string(plan).unwrap();
            let steps = plan_lines(&text);
            let f = load(&mut sources, plan);
            let lu = plan_unit(&sources, f, &du, &pu);
            for (k, g) in lu.steps.iter().enumerate() {
                let action = &domain.actions[g.action];
                let sig = &du.index.actions[action.name.as_str()];
                for (j, want) in sig.params.iter().enumerate() {
                    // An object whose type cannot stand for this parameter.
                    let Some(other) = (0..pu.index.object_names.len())
                        .find(|&o| !du.index.types.fits(&pu.index.object_types[o], want))
                    else {
                        continue;
                    };
                    let mut args: Vec<String> = g
                        .args
                        .iter()
                        .map(|&o| pu.index.object_names[o as usize].clone())
                        .collect();
                    args[j] = pu.index.object_names[other].clone();
                    let mut s = steps.clone();
                    s[k] = format!("({} {})", action.name.name, args.join(" "));
                    let m = sources.add("mutant.plan", s.join("\n"));
                    let mu = plan_unit(&sources, m, &du, &pu);
                    let errs: Vec<&Diagnostic> =
                        mu.diagnostics.iter().filter(|d| d.is_error()).collect();
                    assert_eq!(
                        errs.len(),
                        1,
                        "{}",
                        errors(&mu.diagnostics, &sources).join("\n")
                    );
                    assert_eq!(errs[0].code, "L005");
                    assert_eq!(
                        sources.get(m).line_col(errs[0].span.start).0 as usize,
                        k + 1
                    );
                    mutated += 1;
                    break;
                }
            }
        }
    }
    eprintln!("mutated {mutated}");
    assert!(mutated > 300, "only {mutated} type mutations");
}
