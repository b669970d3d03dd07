//! Shared by the planner's integration tests: finding the corpus, loading
//! a domain and problem, planning, and validating what the planner wrote
//! with the front end's validator.

#![allow(dead_code)]

use btc_pddl::diagnostic::Diagnostic;
use btc_pddl::pipeline::{domain_unit, plan_unit, problem_unit, validate_units};
use btc_pddl::pipeline::{DomainUnit, ProblemUnit};
use btc_pddl::render::to_short;
use btc_pddl::source::Sources;
use btc_pddl::validate::schedule::Schedule;
use btc_planner::{Options, Outcome, Report};
use std::path::{Path, PathBuf};

/// Where the corpus is; a test that reads it first asks
/// `btc_testkit::corpus()`, which skips it when the corpus is missing.
pub fn corpus_dir() -> PathBuf {
    btc_testkit::corpus_path()
}

pub fn repo_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}

/// The domain file of a corpus problem: `pNN-domain.pddl` or `domain.pddl`.
pub fn corpus_case(domain: &str, problem: &str) -> (PathBuf, PathBuf) {
    let dir = corpus_dir().join(domain);
    let own = dir.join(format!("{problem}-domain.pddl"));
    let d = if own.exists() {
        own
    } else {
        dir.join("domain.pddl")
    };
    (d, dir.join(format!("{problem}.pddl")))
}

pub struct Loaded {
    pub sources: Sources,
    pub du: DomainUnit,
    pub pu: ProblemUnit,
}

pub fn load(domain: &Path, problem: &Path) -> Loaded {
    let mut sources = Sources::new();
    let read = |p: &Path| {
        let (text, _) = btc_pddl::source::decode(&std::fs::read(p).unwrap());
        text
    };
    let d = sources.add(domain.display().to_string(), read(domain));
    let p = sources.add(problem.display().to_string(), read(problem));
    let du = domain_unit(&sources, d);
    let pu = problem_unit(&sources, p, &du);
    let errors: Vec<String> = du
        .diagnostics
        .iter()
        .chain(&pu.diagnostics)
        .filter(|d| d.is_error())
        .map(|d| to_short(d, &sources))
        .collect();
    assert!(errors.is_empty(), "{}", errors.join("\n"));
    Loaded { sources, du, pu }
}

impl Loaded {
    pub fn plan(&self, opts: &Options) -> Result<Report, Vec<Diagnostic>> {
        btc_planner::plan(
            self.du.domain.as_ref().unwrap(),
            &self.du.index,
            self.pu.problem.as_ref().unwrap(),
            &self.pu.index,
            opts,
        )
    }

    /// A plan as `btc plan` writes it: a `sas_plan`, or for a domain with
    /// durative actions a timed plan scheduled from it.
    pub fn plan_text(&self, plan: &btc_planner::Plan) -> String {
        let domain = self.du.domain.as_ref().unwrap();
        match self.schedule(plan) {
            Some(s) => btc_planner::to_timed_plan(domain, &self.pu.index, plan, &s),
            None => btc_planner::to_sas_plan(domain, &self.pu.index, plan),
        }
    }

    /// The plan's schedule, for a domain with durative actions.
    pub fn schedule(&self, plan: &btc_planner::Plan) -> Option<Schedule> {
        btc_planner::schedule_plan(
            self.du.domain.as_ref().unwrap(),
            &self.du.index,
            self.pu.problem.as_ref().unwrap(),
            &self.pu.index,
            plan,
        )
        .unwrap()
    }

    /// Plans, writes the `sas_plan` text, validates it; returns the text
    /// and the validated cost.
    pub fn solve_and_validate(&mut self, opts: &Options) -> (String, f64, Report) {
        let report = self.plan(opts).unwrap_or_else(|ds| {
            panic!(
                "{}",
                ds.iter()
                    .map(|d| to_short(d, &self.sources))
                    .collect::<Vec<_>>()
                    .join("\n")
            )
        });
        let Outcome::Plan(plan) = &report.outcome else {
            panic!("no plan: {:?}", report.outcome);
        };
        let text = self.plan_text(plan);
        let f = self.sources.add("planned.plan", text.clone());
        let lu = plan_unit(&self.sources, f, &self.du, &self.pu);
        let v = validate_units(&self.du, &self.pu, &lu).expect("plan types");
        assert!(
            v.valid && v.diagnostics.is_empty(),
            "invalid plan:\n{text}\n{}",
            v.diagnostics
                .iter()
                .map(|d| to_short(d, &self.sources))
                .collect::<Vec<_>>()
                .join("\n")
        );
        (text, v.cost, report)
    }
}

/// The cost stated on the last line of a stored plan (`; cost = N ...`).
pub fn stated_cost(plan_file: &Path) -> f64 {
    let text = std::fs::read_to_string(plan_file).unwrap();
    let line = text
        .lines()
        .rev()
        .find(|l| l.starts_with("; cost = "))
        .expect("a cost line");
    line["; cost = ".len()..]
        .split_whitespace()
        .next()
        .unwrap()
        .parse()
        .unwrap()
}

/// For each corpus domain, whether its stored plans come from an optimal
/// search, read from the configuration column of the corpus README's plan
/// table (`lmcut` and `blind` are A*, `lama-first` is not).
pub fn optimal_domains() -> Vec<(String, bool, bool)> {
    let readme = std::fs::read_to_string(corpus_dir().join("../README.md")).unwrap();
    let mut out = Vec::new();
    let mut in_table = false;
    for line in readme.lines() {
        if line.starts_with("| Domain | p01: config") {
            in_table = true;
            continue;
        }
        if in_table && !line.starts_with('|') {
            break;
        }
        if !in_table || line.starts_with("|---") {
            continue;
        }
        let cells: Vec<&str> = line.split('|').map(str::trim).collect();
        let optimal = |c: &str| {
            let config = c.split(',').next().unwrap_or("").trim();
            config == "lmcut" || config == "blind"
        };
        out.push((cells[1].to_owned(), optimal(cells[2]), optimal(cells[3])));
    }
    assert!(out.len() >= 20, "the README's plan table was not found");
    out
}
