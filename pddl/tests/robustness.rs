//! Bad input never panics: truncated files, unbalanced parentheses, unknown
//! requirements, bytes that are not UTF-8, huge files and deep nesting all
//! come back as diagnostics.

use btc_pddl::diagnostic::{has_errors, Diagnostic};
use btc_pddl::pipeline::{domain_unit, plan_unit, problem_unit, validate_units};
use btc_pddl::render::to_terminal;
use btc_pddl::source::{decode, Sources};
use std::path::PathBuf;

/// The corpus's PDDL files; `None` (the test skipped) without the corpus.
fn corpus_files() -> Option<Vec<PathBuf>> {
    let root = btc_testkit::corpus()?;
    let mut out = Vec::new();
    for dir in std::fs::read_dir(root).unwrap() {
        for f in std::fs::read_dir(dir.unwrap().path()).unwrap() {
            let p = f.unwrap().path();
            if p.extension().is_some_and(|e| e == "pddl") {
                out.push(p);
            }
        }
    }
    out.sort();
    Some(out)
}

const ARIAC_DOMAIN: &str = include_str!("../../examples/ariac/domain.pddl");
const ARIAC_PROBLEM: &str = include_str!("../../examples/ariac/problem.pddl");

/// Runs the whole front end on one PDDL text (as a domain, or as a problem
/// of the ARIAC domain) and a plan text, rendering every diagnostic.
fn run_all(pddl: &str, plan: &str) -> Vec<Diagnostic> {
    let mut sources = Sources::new();
    let d = sources.add("domain.pddl", ARIAC_DOMAIN);
    let p = sources.add("problem.pddl", ARIAC_PROBLEM);
    let x = sources.add("input.pddl", pddl);
    let l = sources.add("plan.txt", plan);
    let du = domain_unit(&sources, d);
    let pu = problem_unit(&sources, p, &du);
    let xu = domain_unit(&sources, x);
    let xp = problem_unit(&sources, x, &du);
    let lu = plan_unit(&sources, l, &du, &pu);
    let mut diags = xu.diagnostics;
    diags.extend(xp.diagnostics);
    diags.extend(lu.diagnostics.iter().cloned());
    if let Some(v) = validate_units(&du, &pu, &lu) {
        diags.extend(v.diagnostics);
    }
    let _ = to_terminal(&diags, &sources, false);
    diags
}

fn char_boundary(s: &str, mut i: usize) -> usize {
    while !s.is_char_boundary(i) {
        i -= 1;
    }
    i
}

#[test]
fn truncated_corpus_files_report_errors() {
    let Some(files) = corpus_files() else { return };
    for path in files {
        let text = std::fs::read_to_string(&path).unwrap();
        let trimmed = text.trim_end().len();
        for k in 1..40 {
            let cut = char_boundary(&text, trimmed * k / 40);
            let diags = run_all(&text[..cut], &text[..cut]);
            // Cutting a `(define ...)` short always leaves a `(` unclosed.
            assert!(
                diags.iter().any(|d| d.code == "P002" || d.code == "P008"),
                "{} cut at {cut}: no P002",
                path.display()
            );
        }
    }
}

#[test]
fn unbalanced_parentheses_anywhere_are_reported() {
    let text = ARIAC_DOMAIN;
    let parens: Vec<usize> = text.match_indices(['(', ')']).map(|(i, _)| i).collect();
    for (n, &i) in parens.iter().enumerate().step_by(3) {
        // Drop one parenthesis, or double it.
        let dropped = format!("{}{}", &text[..i], &text[i + 1..]);
        let doubled = format!("{}{}", &text[..i + 1], &text[i..]);
        for t in [dropped, doubled] {
            let diags = run_all(&t, &t);
            assert!(has_errors(&diags), "paren {n} at {i}: no error");
        }
    }
}

#[test]
fn unknown_requirements_are_named() {
    let t = ARIAC_DOMAIN.replace(":strips :typing", ":strips :typing :quantum-effects");
    let diags = run_all(&t, "");
    let d = diags.iter().find(|d| d.code == "P007").expect("P007");
    assert!(d.message.contains(":quantum-effects"));
}

#[test]
fn bytes_that_are_not_utf8_are_decoded_and_reported() {
    let mut bytes = ARIAC_DOMAIN.as_bytes().to_vec();
    bytes.splice(300..300, [0xFF, 0xFE, 0xC3]);
    let (text, problem) = decode(&bytes);
    assert!(problem.is_some());
    let diags = run_all(&text, &text);
    assert!(has_errors(&diags));
    // Random bytes everywhere.
    let mut seed = 0x9E3779B97F4A7C15u64;
    let noise: Vec<u8> = (0..20_000)
        .map(|_| {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            (seed >> 24) as u8
        })
        .collect();
    let (text, _) = decode(&noise);
    run_all(&text, &text);
}

#[test]
fn a_50_megabyte_problem_and_plan_are_read() {
    let mut problem = String::from(
        "(define (problem big) (:domain ariac_domain)\n (:objects floor_robot - robot\n",
    );
    let mut i = 0;
    while problem.len() < 20_000_000 {
        problem.push_str(&format!("  part{i} - part bin{i} - container\n"));
        i += 1;
    }
    problem.push_str(" )\n (:init (is_enabled floor_robot)\n");
    let mut k = 0;
    while problem.len() < 50_000_000 {
        problem.push_str(&format!("  (on part{} bin{})\n", k % i, k % i));
        k += 1;
    }
    problem.push_str(" )\n (:goal (on part0 bin0)))\n");
    assert!(problem.len() >= 50_000_000);
    let mut sources = Sources::new();
    let d = sources.add("domain.pddl", ARIAC_DOMAIN);
    let p = sources.add("big.pddl", problem);
    let du = domain_unit(&sources, d);
    let pu = problem_unit(&sources, p, &du);
    assert!(!has_errors(&pu.diagnostics));
    assert_eq!(pu.index.object_names.len(), 2 * i + 1);

    let line = "(move floor_robot curr_position bin1)\n";
    let plan = line.repeat(50_000_000 / line.len() + 1);
    let l = sources.add("big.plan", plan);
    let ap = sources.add("problem.pddl", ARIAC_PROBLEM);
    let pu = problem_unit(&sources, ap, &du);
    let lu = plan_unit(&sources, l, &du, &pu);
    assert!(!has_errors(&lu.diagnostics));
    assert_eq!(lu.steps.len(), 50_000_000 / line.len() + 1);
    let v = validate_units(&du, &pu, &lu).unwrap();
    assert!(!v.valid);
    assert_eq!(v.steps_applied, 1);
}

#[test]
fn ten_thousand_levels_of_nesting_do_not_overflow() {
    let n = 10_000;
    let deep = format!(
        "{}(attach ?part ?robot){}",
        "(not ".repeat(n),
        ")".repeat(n)
    );
    let domain = format!(
        "(define (domain d) (:requirements :strips :negative-preconditions) (:predicates (attach ?part ?robot))\n (:action a :parameters (?part ?robot) :precondition {deep} :effect (attach ?part ?robot)))"
    );
    let diags = run_all(&domain, &deep);
    assert!(diags.iter().any(|d| d.code == "P004"));
    // The same depth in a goal, in an effect, and as a bare list.
    let goal = ARIAC_PROBLEM.replace(
        "(:goal (on battery_red agv1))",
        &format!(
            "(:goal {}(on battery_red agv1){})",
            "(and ".repeat(n),
            ")".repeat(n)
        ),
    );
    assert!(run_all(&goal, "").iter().any(|d| d.code == "P004"));
    let parens = format!("{}{}", "(".repeat(n), ")".repeat(n));
    assert!(run_all(&parens, &parens).iter().any(|d| d.code == "P004"));
    let unclosed = "(".repeat(n);
    assert!(has_errors(&run_all(&unclosed, &unclosed)));
}

#[test]
fn empty_and_blank_inputs_are_reported() {
    for t in [
        "",
        "   \n\t",
        "; only a comment\n",
        ")",
        "(",
        "()",
        "(define)",
        "(define (domain))",
        "(define (problem p))",
    ] {
        let diags = run_all(t, t);
        assert!(has_errors(&diags), "{t:?}: no error");
    }
}

/// A file of stray words costs a bounded number of diagnostics: the lexer
/// keeps 100 bad words and counts the rest, the parser reports the first
/// thing outside `(define ...)` and counts the rest.
#[test]
fn stray_words_make_a_bounded_number_of_diagnostics() {
    for text in ["\0 ".repeat(200_000), "word ".repeat(200_000)] {
        let (_, diags) = btc_pddl::parse_document(&text, 0);
        assert!(diags.len() <= 110, "{}", diags.len());
        assert!(
            diags.iter().any(|d| d.message.contains("more")),
            "{diags:#?}"
        );
    }
}

/// "did you mean" on huge names is not quadratic in their length (a 10 MB
/// name used to take 16 s): names and candidates past the bound go
/// unmeasured, and a typo of a short name is still found.
#[test]
fn suggestions_for_huge_names_take_linear_time() {
    use btc_pddl::diagnostic::closest;
    btc_testkit::hostile::assert_linear(
        "suggesting a name",
        100_000,
        30.0,
        |n| {
            (
                "a".repeat(n),
                ["a".repeat(n - 1), "b".repeat(n), "holds".to_owned()],
            )
        },
        |(name, candidates)| {
            assert_eq!(closest(name, candidates.iter().map(String::as_str)), None);
            assert_eq!(
                closest("hodls", candidates.iter().map(String::as_str)),
                Some("holds")
            );
        },
    );
}
