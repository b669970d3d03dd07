//! Front-end benchmarks (`cargo bench -p btc-lang --bench pddl`):
//! - a generated 100,000-step ARIAC plan: parse, parse + type, and
//!   parse + type + validate (target: >= 1,000,000 steps/s for parse + type);
//! - the whole IPC corpus: parse + check every domain and problem
//!   (target: under 50 ms), and validate every plan.

use btc_pddl::pipeline::{domain_unit, plan_unit, problem_unit, validate_units};
use btc_pddl::plan::{parse_plan, type_plan};
use btc_pddl::source::Sources;
use btc_pddl::{check_domain, check_problem, parse_domain, parse_problem};
use divan::counter::ItemsCount;
use divan::Bencher;
use std::path::{Path, PathBuf};
use std::sync::OnceLock;

// The same allocator as the `btc` binary.
#[global_allocator]
static GLOBAL: mimalloc::MiMalloc = mimalloc::MiMalloc;

fn main() {
    divan::main();
}

const DOMAIN: &str = include_str!("../../examples/ariac/domain.pddl");
const PROBLEM: &str = include_str!("../../examples/ariac/problem.pddl");
const STEPS: usize = 100_000;

fn long_plan() -> &'static str {
    static PLAN: OnceLock<String> = OnceLock::new();
    PLAN.get_or_init(|| btc_testkit::long_ariac_plan(STEPS))
}

#[divan::bench(sample_count = 20)]
fn plan_100k_parse(b: Bencher) {
    let text = long_plan();
    b.counter(ItemsCount::new(STEPS))
        .bench(|| parse_plan(divan::black_box(text), 0));
}

#[divan::bench(sample_count = 20)]
fn plan_100k_parse_and_type(b: Bencher) {
    let (domain, _) = parse_domain(DOMAIN, 1);
    let domain = domain.unwrap();
    let (dix, _) = check_domain(&domain);
    let (problem, _) = parse_problem(PROBLEM, 2);
    let (pix, _) = check_problem(&problem.unwrap(), &domain, &dix);
    let text = long_plan();
    b.counter(ItemsCount::new(STEPS)).bench(|| {
        let (plan, diags) = parse_plan(divan::black_box(text), 0);
        let (steps, tdiags) = type_plan(&plan, &domain, &dix, &pix);
        assert!(diags.is_empty() && tdiags.is_empty() && steps.len() == STEPS);
        steps
    });
}

#[divan::bench(sample_count = 10)]
fn plan_100k_parse_type_validate(b: Bencher) {
    let mut sources = Sources::new();
    let d = sources.add("domain.pddl", DOMAIN);
    let p = sources.add("problem.pddl", PROBLEM);
    let l = sources.add("plan", long_plan());
    let du = domain_unit(&sources, d);
    let pu = problem_unit(&sources, p, &du);
    b.counter(ItemsCount::new(STEPS)).bench(|| {
        let lu = plan_unit(&sources, l, &du, &pu);
        let v = validate_units(&du, &pu, &lu).unwrap();
        assert!(v.valid);
    });
}

struct Corpus {
    /// (domain text, problem text, plan texts) per problem.
    cases: Vec<(String, String, Vec<String>)>,
}

fn corpus() -> &'static Corpus {
    static C: OnceLock<Corpus> = OnceLock::new();
    C.get_or_init(|| {
        let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../shared/corpus/ipc");
        let mut dirs: Vec<PathBuf> = std::fs::read_dir(root)
            .unwrap()
            .map(|e| e.unwrap().path())
            .collect();
        dirs.sort();
        let mut cases = Vec::new();
        for dir in dirs {
            for n in ["p01", "p02"] {
                let own = dir.join(format!("{n}-domain.pddl"));
                let domain = if own.exists() {
                    own
                } else {
                    dir.join("domain.pddl")
                };
                let read = |p: PathBuf| std::fs::read_to_string(p).unwrap();
                let mut plans = vec![read(dir.join(format!("{n}.plan")))];
                if dir.join(format!("{n}.tplan")).exists() {
                    plans.push(read(dir.join(format!("{n}.tplan"))));
                }
                cases.push((read(domain), read(dir.join(format!("{n}.pddl"))), plans));
            }
        }
        Corpus { cases }
    })
}

/// Parse + check all 40 corpus problems with their domains.
#[divan::bench(sample_count = 30)]
fn corpus_parse_and_check(b: Bencher) {
    let c = corpus();
    b.counter(ItemsCount::new(c.cases.len())).bench(|| {
        for (d, p, _) in &c.cases {
            let (domain, _) = parse_domain(d, 0);
            let domain = domain.unwrap();
            let (dix, _) = check_domain(&domain);
            let (problem, _) = parse_problem(p, 1);
            divan::black_box(check_problem(&problem.unwrap(), &domain, &dix));
        }
    });
}

/// Parse + check + type + validate every corpus plan.
#[divan::bench(sample_count = 10)]
fn corpus_validate_all_plans(b: Bencher) {
    let c = corpus();
    b.bench(|| {
        for (d, p, plans) in &c.cases {
            let mut sources = Sources::new();
            let di = sources.add("d", d.clone());
            let pi = sources.add("p", p.clone());
            let du = domain_unit(&sources, di);
            let pu = problem_unit(&sources, pi, &du);
            for plan in plans {
                let li = sources.add("plan", plan.clone());
                let lu = plan_unit(&sources, li, &du, &pu);
                assert!(validate_units(&du, &pu, &lu).unwrap().valid);
            }
        }
    });
}
