//! `.btrules` benchmarks (`cargo bench -p btc-lang --bench rules`):
//! - compile a 100,000-step ARIAC plan to BT.CPP XML, end to end from texts
//!   (target: >= 500,000 steps/s);
//! - check a 5,000-line rules file from scratch, and again after a one-rule
//!   edit (the incremental path the language server takes).

use btc_emit::{emit, Format, Options};
use btc_lang::db::{compile, rules_diagnostics, CompileJob, Database};
use divan::counter::ItemsCount;
use divan::Bencher;

// The same allocator as the `btc` binary.
#[global_allocator]
static GLOBAL: mimalloc::MiMalloc = mimalloc::MiMalloc;

fn main() {
    divan::main();
}

const DOMAIN: &str = include_str!("../../examples/ariac/domain.pddl");
const PROBLEM: &str = include_str!("../../examples/ariac/problem.pddl");
const RULES: &str = include_str!("../../examples/ariac/rules.btrules");
const LARGE: &str = include_str!("../tests/fixtures/large.btrules");
const STEPS: usize = 100_000;

fn long_plan() -> String {
    btc_testkit::long_ariac_plan(STEPS)
}

#[divan::bench(sample_count = 10)]
fn compile_100k_steps_to_btcpp(b: Bencher) {
    let plan = long_plan();
    b.counter(ItemsCount::new(STEPS)).bench(|| {
        let mut db = Database::new();
        db.set_file("ariac/domain.pddl", DOMAIN.to_owned());
        let p = db.set_file("ariac/problem.pddl", PROBLEM.to_owned());
        let r = db.set_file("ariac/rules.btrules", RULES.to_owned());
        let l = db.set_file("ariac/plan.txt", plan.clone());
        let job = CompileJob::new(&db, r, l, Some(p), None);
        let ir = compile(&db, job).as_ref().expect("compiles");
        let xml = emit(ir, Format::Btcpp, &Options::default());
        assert!(xml.len() > STEPS * 100);
        xml.len()
    });
}

fn large_db() -> (Database, btc_lang::db::SourceFile) {
    let mut db = Database::new();
    db.set_file("examples/ariac/domain.pddl", DOMAIN.to_owned());
    let f = db.set_file("lang/tests/fixtures/large.btrules", LARGE.to_owned());
    (db, f)
}

#[divan::bench(sample_count = 10)]
fn check_5000_lines_from_scratch(b: Bencher) {
    assert!(LARGE.lines().count() >= 5000);
    b.bench(|| {
        let (db, f) = large_db();
        rules_diagnostics(&db, f).len()
    });
}

#[divan::bench(sample_count = 30)]
fn check_5000_lines_after_one_rule_edit(b: Bencher) {
    let (mut db, f) = large_db();
    rules_diagnostics(&db, f);
    let mut n = 0u32;
    b.bench_local(|| {
        // Alternate between two versions of one rule in the middle.
        n += 1;
        let text = if n.is_multiple_of(2) {
            LARGE.to_owned()
        } else {
            LARGE.replacen("retry(3) MoveTo", "retry(4) MoveTo", 1)
        };
        db.set_file("lang/tests/fixtures/large.btrules", text);
        rules_diagnostics(&db, f).len()
    });
}
