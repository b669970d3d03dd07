//! How `btc check` scales with the size of a rules file (`cargo bench -p
//! btc-lang --bench scaling`): a domain of N actions and a rules file with
//! one rule per action (`btc_testkit::scale`), checked from scratch in a
//! fresh database, for N = 50, 500 and 5,000. Prints the median time of
//! each and the growth per tenfold size next to its targets (issue #14):
//! N = 500 under 20 ms, and each tenfold step within 1.5x of linear (at
//! most 15x the time). `BTC_SCALE_SIZES=50,500` picks other sizes.

use btc_lang::db::{rules_diagnostics, Database};
use std::time::{Duration, Instant};

// The same allocator as the `btc` binary.
#[global_allocator]
static GLOBAL: mimalloc::MiMalloc = mimalloc::MiMalloc;

fn check_once(domain: &str, rules: &str) -> (Duration, usize) {
    let t = Instant::now();
    let mut db = Database::new();
    db.set_file("scale/domain.pddl", domain.to_owned());
    let f = db.set_file("scale/rules.btrules", rules.to_owned());
    let n = rules_diagnostics(&db, f).len();
    (t.elapsed(), n)
}

/// Median of enough runs to take about a second (at least 3).
fn median_check(n: usize) -> (Duration, usize) {
    let domain = btc_testkit::scale::domain(n);
    let rules = btc_testkit::scale::rules(n, "domain.pddl");
    let (first, diags) = check_once(&domain, &rules);
    let runs = (Duration::from_secs(1).as_nanos() / first.as_nanos().max(1)).clamp(3, 200);
    let mut times: Vec<Duration> = (0..runs).map(|_| check_once(&domain, &rules).0).collect();
    times.sort();
    (times[times.len() / 2], diags)
}

fn main() {
    let sizes: Vec<usize> = std::env::var("BTC_SCALE_SIZES")
        .ok()
        .map(|s| s.split(',').filter_map(|n| n.trim().parse().ok()).collect())
        .unwrap_or_else(|| vec![50, 500, 5000]);
    let ms = |d: Duration| d.as_secs_f64() * 1000.0;
    let mut prev: Option<(usize, Duration)> = None;
    for &n in &sizes {
        let (t, diags) = median_check(n);
        let target = if n == 500 { "   (target < 20 ms)" } else { "" };
        println!(
            "btc check, {n:>5} rules over {n:>5} actions: {:>9.2} ms median, {diags} diagnostics{target}",
            ms(t)
        );
        if let Some((pn, pt)) = prev {
            let size = n as f64 / pn as f64;
            let time = t.as_secs_f64() / pt.as_secs_f64();
            println!(
                "  {pn} -> {n} rules: time x{time:.2} for size x{size:.1}: {:.2}x linear   (target <= 1.5x)",
                time / size
            );
        }
        prev = Some((n, t));
    }
}
