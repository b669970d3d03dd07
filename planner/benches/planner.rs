//! Planner benchmarks (`cargo bench -p btc-planner`):
//! - the ARIAC per-part problem (`examples/ariac`), grounding + search
//!   (target: well under 1 ms), and the same from the texts (parse + check
//!   + plan);
//! - every corpus problem with a stored plan, greedy search with h_FF (the
//!   default), and A* with h_max on the problems it solves quickly.
//!
//! Before the timings, a table with one run per corpus problem prints the
//! search statistics (ground actions, expanded and generated states, plan
//! cost, time); `BTC_BENCH_TABLE=0` skips it. `BTC_BENCH_OPTIMAL=1` adds
//! a table for A* with LM-cut and with h_max (60 s limit per problem, so
//! several minutes).

use btc_pddl::pipeline::{domain_unit, problem_unit, DomainUnit, ProblemUnit};
use btc_pddl::source::Sources;
use btc_planner::{Algorithm, Heuristic, Options, Outcome};
use divan::Bencher;
use std::path::{Path, PathBuf};
use std::time::Instant;

#[global_allocator]
static GLOBAL: mimalloc::MiMalloc = mimalloc::MiMalloc;

const ARIAC_DOMAIN: &str = include_str!("../../examples/ariac/domain.pddl");
const ARIAC_PROBLEM: &str = include_str!("../../examples/ariac/problem.pddl");

fn corpus_dir() -> PathBuf {
    std::env::var_os("BTC_CORPUS")
        .map(PathBuf::from)
        .unwrap_or_else(|| Path::new(env!("CARGO_MANIFEST_DIR")).join("../../shared/corpus/ipc"))
}

/// `domain/pNN` for every corpus problem with a stored plan.
fn problems() -> Vec<String> {
    let mut out = Vec::new();
    let Ok(rd) = std::fs::read_dir(corpus_dir()) else {
        return out;
    };
    let mut dirs: Vec<PathBuf> = rd
        .map(|e| e.unwrap().path())
        .filter(|p| p.is_dir())
        .collect();
    dirs.sort();
    for dir in dirs {
        let name = dir.file_name().unwrap().to_string_lossy().into_owned();
        let mut ps: Vec<String> = std::fs::read_dir(&dir)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .filter(|n| n.ends_with(".plan"))
            .map(|n| n.trim_end_matches(".plan").to_owned())
            .collect();
        ps.sort();
        out.extend(ps.into_iter().map(|p| format!("{name}/{p}")));
    }
    out
}

struct Loaded {
    du: DomainUnit,
    pu: ProblemUnit,
}

fn units(domain: &str, problem: &str) -> Loaded {
    let mut sources = Sources::new();
    let d = sources.add("domain.pddl", domain);
    let p = sources.add("problem.pddl", problem);
    let du = domain_unit(&sources, d);
    let pu = problem_unit(&sources, p, &du);
    Loaded { du, pu }
}

fn load(name: &str) -> Loaded {
    let (dom, prob) = name.split_once('/').unwrap();
    let dir = corpus_dir().join(dom);
    let own = dir.join(format!("{prob}-domain.pddl"));
    let d = if own.exists() {
        own
    } else {
        dir.join("domain.pddl")
    };
    let read = |p: &Path| btc_pddl::source::decode(&std::fs::read(p).unwrap()).0;
    units(&read(&d), &read(&dir.join(format!("{prob}.pddl"))))
}

fn plan(l: &Loaded, opts: &Options) -> btc_planner::Report {
    btc_planner::plan(
        l.du.domain.as_ref().unwrap(),
        &l.du.index,
        l.pu.problem.as_ref().unwrap(),
        &l.pu.index,
        opts,
    )
    .expect("the planner accepts the problem")
}

const ASTAR: Options = Options {
    algorithm: Algorithm::Astar,
    heuristic: Heuristic::Max,
    timeout: None,
    improve: 0,
};

/// Problems where A* with h_max takes over a second; benchmarked with
/// greedy search only.
const ASTAR_SLOW: &[&str] = &[
    "assembly/p01",
    "assembly/p02",
    "barman/p01",
    "barman/p02",
    "childsnack/p01",
    "childsnack/p02",
    "floortile/p01",
    "floortile/p02",
    "tidybot/p02",
];

fn main() {
    if std::env::var("BTC_BENCH_TABLE").as_deref() != Ok("0") {
        table();
    }
    divan::main();
}

fn table() {
    stats_table("gbfs + h_FF", &Options::default());
    if std::env::var("BTC_BENCH_OPTIMAL").as_deref() == Ok("1") {
        for heuristic in [Heuristic::LmCut, Heuristic::Max] {
            let opts = Options {
                algorithm: Algorithm::Astar,
                heuristic,
                timeout: Some(std::time::Duration::from_secs(60)),
                ..Options::default()
            };
            stats_table(&format!("astar + {heuristic:?}"), &opts);
        }
    }
}

fn stats_table(title: &str, opts: &Options) {
    println!(
        "{:<24} {:>8} {:>10} {:>10} {:>8} {:>10}   ({title})",
        "problem", "actions", "expanded", "generated", "cost", "ms"
    );
    let cases = problems()
        .into_iter()
        .map(|name| (load(&name), name))
        .chain([(units(ARIAC_DOMAIN, ARIAC_PROBLEM), "examples/ariac".into())]);
    for (l, name) in cases {
        let t = Instant::now();
        let r = plan(&l, opts);
        let ms = t.elapsed().as_secs_f64() * 1e3;
        let cost = match &r.outcome {
            Outcome::Plan(p) => (p.base_cost + p.cost as f64).to_string(),
            other => format!("{other:?}"),
        };
        println!(
            "{name:<24} {:>8} {:>10} {:>10} {cost:>8} {ms:>10.3}",
            r.ground.operators, r.search.expanded, r.search.generated
        );
    }
}

#[divan::bench]
fn ariac_plan(b: Bencher) {
    let l = units(ARIAC_DOMAIN, ARIAC_PROBLEM);
    b.bench(|| {
        let r = plan(&l, &Options::default());
        assert!(matches!(r.outcome, Outcome::Plan(_)));
        r
    });
}

#[divan::bench]
fn ariac_parse_check_plan(b: Bencher) {
    b.bench(|| {
        let l = units(divan::black_box(ARIAC_DOMAIN), ARIAC_PROBLEM);
        plan(&l, &Options::default())
    });
}

#[divan::bench]
fn ariac_plan_astar_hmax(b: Bencher) {
    let l = units(ARIAC_DOMAIN, ARIAC_PROBLEM);
    b.bench(|| plan(&l, &ASTAR));
}

#[divan::bench]
fn ariac_plan_astar_lmcut(b: Bencher) {
    let l = units(ARIAC_DOMAIN, ARIAC_PROBLEM);
    let opts = Options {
        heuristic: Heuristic::LmCut,
        ..ASTAR
    };
    b.bench(|| plan(&l, &opts));
}

#[divan::bench(args = problems(), sample_count = 3, sample_size = 1)]
fn corpus_gbfs_ff(b: Bencher, name: &str) {
    let l = load(name);
    b.bench(|| {
        let r = plan(&l, &Options::default());
        assert!(matches!(r.outcome, Outcome::Plan(_)), "{name}");
        r
    });
}

fn astar_problems() -> Vec<String> {
    problems()
        .into_iter()
        .filter(|p| !ASTAR_SLOW.contains(&p.as_str()))
        .collect()
}

/// Problems where A* with LM-cut takes over a second (barman: also for
/// Fast Downward, see the corpus README), or that it plans with h_max
/// (conditional effects).
const LMCUT_SLOW: &[&str] = &[
    "assembly/p01",
    "assembly/p02",
    "barman/p01",
    "barman/p02",
    "childsnack/p01",
    "childsnack/p02",
    "tidybot/p02",
];

fn lmcut_problems() -> Vec<String> {
    problems()
        .into_iter()
        .filter(|p| !LMCUT_SLOW.contains(&p.as_str()))
        .collect()
}

#[divan::bench(args = lmcut_problems(), sample_count = 3, sample_size = 1)]
fn corpus_astar_lmcut(b: Bencher, name: &str) {
    let l = load(name);
    let opts = Options {
        heuristic: Heuristic::LmCut,
        ..ASTAR
    };
    b.bench(|| {
        let r = plan(&l, &opts);
        assert!(matches!(r.outcome, Outcome::Plan(_)), "{name}");
        r
    });
}

#[divan::bench(args = astar_problems(), sample_count = 3, sample_size = 1)]
fn corpus_astar_hmax(b: Bencher, name: &str) {
    let l = load(name);
    b.bench(|| {
        let r = plan(&l, &ASTAR);
        assert!(matches!(r.outcome, Outcome::Plan(_)), "{name}");
        r
    });
}
