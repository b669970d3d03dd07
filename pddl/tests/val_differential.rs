//! `btc validate` against VAL, the reference validator (KCL-Planning/VAL,
//! built from `../shared/vendor/` by `integrations/val/build-val.sh`):
//! on every corpus plan, on the timed plans of `fixtures/timed/` (each case
//! of PDDL 2.1's temporal semantics, valid and not), on the example's timed
//! plan, and on four mutants of each (a step dropped, two swapped, the last
//! cut, an object replaced), the two must reach the same verdict. Where VAL
//! is wrong (`fixtures/val_defects/`), a test of its own says why btc
//! differs.

use btc_pddl::diagnostic::has_errors;
use btc_pddl::pipeline::{domain_unit, plan_unit, problem_unit, validate_units};
use btc_pddl::source::Sources;
use std::path::{Path, PathBuf};
use std::process::Command;

/// One plan to judge, written to a file (mutants to a temporary one).
struct Case {
    name: String,
    domain: PathBuf,
    problem: PathBuf,
    plan: PathBuf,
}

fn fixtures() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures")
}

/// btc's verdict: every input free of errors and the plan valid.
fn btc_valid(domain: &Path, problem: &Path, plan: &Path) -> bool {
    let mut sources = Sources::new();
    let mut add = |p: &Path| {
        let bytes = std::fs::read(p).unwrap();
        let (text, _) = btc_pddl::source::decode(&bytes);
        sources.add(p.display().to_string(), text)
    };
    let (d, p, l) = (add(domain), add(problem), add(plan));
    let du = domain_unit(&sources, d);
    let pu = problem_unit(&sources, p, &du);
    let lu = plan_unit(&sources, l, &du, &pu);
    if has_errors(&du.diagnostics) || has_errors(&pu.diagnostics) || has_errors(&lu.diagnostics) {
        return false;
    }
    validate_units(&du, &pu, &lu).is_some_and(|v| v.valid)
}

/// VAL's verdict, read from its text (it exits 0 on "Bad plan
/// description!"); `-t 0.001` is IPC's tolerance, btc's default.
fn val_valid(val: &Path, domain: &Path, problem: &Path, plan: &Path) -> bool {
    let out = Command::new(val)
        .args(["-t", "0.001"])
        .args([domain, problem, plan])
        .output()
        .unwrap_or_else(|e| panic!("{} does not run: {e}", val.display()));
    let text = String::from_utf8_lossy(&out.stdout);
    text.lines().any(|l| l.trim() == "Plan valid")
        && !text.contains("Bad plan description!")
        && !text.contains("Goal not satisfied")
        && !text.contains("Plan failed")
}

/// The step lines of a plan (not comments, not blank).
fn step_lines(text: &str) -> Vec<usize> {
    text.lines()
        .enumerate()
        .filter(|(_, l)| {
            let l = l.trim();
            !l.is_empty() && !l.starts_with(';') && l.contains('(')
        })
        .map(|(i, _)| i)
        .collect()
}

/// `(action args)` of a step line and what surrounds it (the time, the
/// duration), as byte ranges.
fn call_range(line: &str) -> (usize, usize) {
    let open = line.find('(').unwrap();
    let close = line[open..].find(')').map_or(line.len(), |c| open + c + 1);
    (open, close)
}

/// The four mutants of a plan, named; none when it has fewer than two steps.
fn mutants(text: &str) -> Vec<(&'static str, String)> {
    let lines: Vec<&str> = text.lines().collect();
    let steps = step_lines(text);
    if steps.len() < 2 {
        return Vec::new();
    }
    let join = |ls: Vec<String>| ls.join("\n") + "\n";
    let owned = || lines.iter().map(|l| l.to_string()).collect::<Vec<_>>();
    let mut out = Vec::new();

    let mut dropped = owned();
    dropped.remove(steps[steps.len() / 2]);
    out.push(("drop", join(dropped)));

    // Two neighbouring steps exchange their calls; times and durations
    // stay where they are (a timed plan is read in time order).
    let (i, j) = (steps[steps.len() / 3], steps[steps.len() / 3 + 1]);
    let (a, b) = (call_range(lines[i]), call_range(lines[j]));
    let mut swapped = owned();
    swapped[i] = format!(
        "{}{}{}",
        &lines[i][..a.0],
        &lines[j][b.0..b.1],
        &lines[i][a.1..]
    );
    swapped[j] = format!(
        "{}{}{}",
        &lines[j][..b.0],
        &lines[i][a.0..a.1],
        &lines[j][b.1..]
    );
    out.push(("swap", join(swapped)));

    let mut cut = owned();
    cut.remove(*steps.last().unwrap());
    out.push(("cut", join(cut)));

    // The middle step's last argument becomes another step's last
    // argument, the first that differs.
    let last_arg = |l: &str| {
        let (o, c) = call_range(l);
        l[o + 1..c - 1]
            .split_whitespace()
            .last()
            .unwrap()
            .to_string()
    };
    let k = steps[steps.len() / 2];
    let mine = last_arg(lines[k]);
    if let Some(other) = steps
        .iter()
        .map(|&s| last_arg(lines[s]))
        .find(|o| o != &mine)
    {
        let (o, c) = call_range(lines[k]);
        let call = &lines[k][o..c];
        let at = call.rfind(&mine).unwrap();
        let mut replaced = owned();
        replaced[k] = format!(
            "{}{}{other}{}{}",
            &lines[k][..o],
            &call[..at],
            &call[at + mine.len()..],
            &lines[k][c..]
        );
        out.push(("object", join(replaced)));
    }
    out
}

/// Every case to compare: the plans and their mutants (written under
/// `scratch`).
fn cases(scratch: &Path) -> Option<Vec<Case>> {
    let mut plans = Vec::new();
    for c in btc_testkit::corpus_cases()? {
        for plan in &c.plans {
            plans.push((c.domain.clone(), c.problem.clone(), plan.clone()));
        }
    }
    let timed = fixtures().join("timed");
    for plan in btc_testkit::sorted_entries(&timed) {
        if plan.extension().is_some_and(|e| e == "tplan") {
            plans.push((timed.join("domain.pddl"), timed.join("p1.pddl"), plan));
        }
    }
    let p3 = btc_testkit::repo().join("examples/p3_assembler");
    plans.push((
        p3.join("domain.pddl"),
        p3.join("problem.pddl"),
        p3.join("plan.tplan"),
    ));
    let mut out = Vec::new();
    for (n, (domain, problem, plan)) in plans.into_iter().enumerate() {
        let text = std::fs::read_to_string(&plan).unwrap();
        let name = plan
            .strip_prefix(btc_testkit::repo().parent().unwrap())
            .unwrap_or(&plan)
            .display()
            .to_string();
        for (kind, mutant) in mutants(&text) {
            let file = scratch.join(format!("{n}-{kind}.plan"));
            std::fs::write(&file, mutant).unwrap();
            out.push(Case {
                name: format!("{name} ({kind} mutant)"),
                domain: domain.clone(),
                problem: problem.clone(),
                plan: file,
            });
        }
        out.push(Case {
            name,
            domain,
            problem,
            plan,
        });
    }
    Some(out)
}

#[test]
fn btc_validate_agrees_with_val() {
    let Some(val) = btc_testkit::val() else {
        return;
    };
    let scratch = tempdir();
    let Some(cases) = cases(&scratch) else {
        return;
    };
    // Two workers: VAL is a process per case, and CI has two cores.
    let verdicts: Vec<(bool, bool)> = std::thread::scope(|s| {
        let halves: Vec<_> = cases
            .chunks(cases.len().div_ceil(2))
            .map(|chunk| {
                let val = &val;
                s.spawn(move || {
                    chunk
                        .iter()
                        .map(|c| {
                            (
                                btc_valid(&c.domain, &c.problem, &c.plan),
                                val_valid(val, &c.domain, &c.problem, &c.plan),
                            )
                        })
                        .collect::<Vec<_>>()
                })
            })
            .collect();
        halves.into_iter().flat_map(|h| h.join().unwrap()).collect()
    });
    let mut differ = Vec::new();
    let (mut valid, mut invalid) = (0, 0);
    for (c, (btc, val)) in cases.iter().zip(&verdicts) {
        if btc != val {
            differ.push(format!(
                "{}: btc says {}, VAL says {}",
                c.name,
                verdict(*btc),
                verdict(*val)
            ));
        } else if *btc {
            valid += 1;
        } else {
            invalid += 1;
        }
    }
    let _ = std::fs::remove_dir_all(&scratch);
    eprintln!(
        "btc validate and VAL agree on {} of {} cases ({valid} valid, {invalid} invalid)",
        cases.len() - differ.len(),
        cases.len()
    );
    assert!(
        differ.is_empty(),
        "btc validate and VAL disagree on {} of {} cases:\n{}",
        differ.len(),
        cases.len(),
        differ.join("\n")
    );
    // Both verdicts occur among the timed plans, and the comparison is not
    // vacuous.
    assert!(
        valid >= 20 && invalid >= 20,
        "{valid} valid, {invalid} invalid"
    );
}

fn verdict(valid: bool) -> &'static str {
    if valid {
        "valid"
    } else {
        "invalid"
    }
}

fn tempdir() -> PathBuf {
    let dir = std::env::temp_dir().join(format!("btc-val-diff-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// btc's codes for a plan of `fixtures/val_defects/`, errors only.
fn btc_error_codes(plan: &str) -> Vec<&'static str> {
    let dir = fixtures().join("val_defects");
    let mut sources = Sources::new();
    let mut add = |p: &Path| {
        let text = std::fs::read_to_string(p).unwrap();
        sources.add(p.display().to_string(), text)
    };
    let (d, p, l) = (
        add(&dir.join("domain.pddl")),
        add(&dir.join("p1.pddl")),
        add(&dir.join(plan)),
    );
    let du = domain_unit(&sources, d);
    let pu = problem_unit(&sources, p, &du);
    let lu = plan_unit(&sources, l, &du, &pu);
    let mut diags: Vec<_> = [&du.diagnostics, &pu.diagnostics, &lu.diagnostics]
        .into_iter()
        .flatten()
        .cloned()
        .collect();
    if !has_errors(&diags) {
        diags.extend(validate_units(&du, &pu, &lu).unwrap().diagnostics);
    }
    diags
        .iter()
        .filter(|d| d.is_error())
        .map(|d| d.code)
        .collect()
}

/// VAL's verdict on a plan of `fixtures/val_defects/`, or `None` (skipped)
/// without VAL.
fn val_on_defect(plan: &str) -> Option<bool> {
    let val = btc_testkit::val()?;
    let dir = fixtures().join("val_defects");
    Some(val_valid(
        &val,
        &dir.join("domain.pddl"),
        &dir.join("p1.pddl"),
        &dir.join(plan),
    ))
}

/// VAL drops the arguments of a step beyond its action's parameters (in an
/// untyped domain) and goes on; btc refuses the step, which names no action
/// the domain has.
#[test]
fn val_drops_extra_arguments_btc_refuses_the_step() {
    let Some(val) = val_on_defect("p1.extra-argument.plan") else {
        return;
    };
    assert!(val, "VAL no longer accepts a step with an extra argument");
    assert_eq!(btc_error_codes("p1.extra-argument.plan"), ["L003"]);
}

/// VAL stops reading a plan at a line it cannot parse and judges the steps
/// before it alone; btc reads the whole plan, and the step after that line
/// fails.
#[test]
fn val_stops_at_an_unreadable_line_btc_reads_on() {
    let Some(val) = val_on_defect("p1.unreadable-line.plan") else {
        return;
    };
    assert!(
        val,
        "VAL no longer accepts a plan cut short by a line without parentheses"
    );
    assert_eq!(btc_error_codes("p1.unreadable-line.plan"), ["V001"]);
}
