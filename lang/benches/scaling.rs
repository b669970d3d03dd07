//! How `btc check` scales with the size of a rules file (`cargo bench -p
//! btc-lang --bench scaling`): a domain of N actions and a rules file with
//! one rule per action (`btc_testkit::scale`), checked from scratch in a
//! fresh database, for N = 50, 500 and 5,000. Prints the median time of
//! each and the growth per tenfold size next to its targets (issue #14):
//! N = 500 under 20 ms, and each tenfold step within 1.5x of linear (at
//! most 15x the time). `BTC_SCALE_SIZES=50,500` picks other sizes.
//!
//! Each size gets two medians: wall-clock time, and the CPU time of the
//! checking thread (the check runs on one thread). On a machine shared
//! with other work the wall clock also counts the time the thread waited
//! for a core, so the targets are compared with the CPU time, which is
//! what the check itself costs.

use btc_lang::db::{rules_diagnostics, Database};
use std::time::{Duration, Instant};

// The same allocator as the `btc` binary.
#[global_allocator]
static GLOBAL: mimalloc::MiMalloc = mimalloc::MiMalloc;

/// The CPU time this thread has used.
fn thread_cpu() -> Duration {
    let mut t = libc::timespec {
        tv_sec: 0,
        tv_nsec: 0,
    };
    // SAFETY: `t` is a valid timespec for the call to fill in.
    let rc = unsafe { libc::clock_gettime(libc::CLOCK_THREAD_CPUTIME_ID, &mut t) };
    assert_eq!(rc, 0, "clock_gettime(CLOCK_THREAD_CPUTIME_ID)");
    Duration::new(t.tv_sec as u64, t.tv_nsec as u32)
}

/// One check: (wall time, CPU time, diagnostics).
fn check_once(domain: &str, rules: &str) -> (Duration, Duration, usize) {
    let (wall, cpu) = (Instant::now(), thread_cpu());
    let mut db = Database::new();
    db.set_file("scale/domain.pddl", domain.to_owned());
    let f = db.set_file("scale/rules.btrules", rules.to_owned());
    let n = rules_diagnostics(&db, f).len();
    (wall.elapsed(), thread_cpu() - cpu, n)
}

fn median(mut times: Vec<Duration>) -> Duration {
    times.sort();
    times[times.len() / 2]
}

/// Medians (wall, CPU) of enough runs to take about a second (at least 3).
fn median_check(n: usize) -> (Duration, Duration, usize) {
    let domain = btc_testkit::scale::domain(n);
    let rules = btc_testkit::scale::rules(n, "domain.pddl");
    let (first, _, diags) = check_once(&domain, &rules);
    let runs = (Duration::from_secs(1).as_nanos() / first.as_nanos().max(1)).clamp(3, 200);
    let (walls, cpus): (Vec<Duration>, Vec<Duration>) = (0..runs)
        .map(|_| {
            let (w, c, _) = check_once(&domain, &rules);
            (w, c)
        })
        .unzip();
    (median(walls), median(cpus), diags)
}

fn main() {
    let sizes: Vec<usize> = std::env::var("BTC_SCALE_SIZES")
        .ok()
        .map(|s| s.split(',').filter_map(|n| n.trim().parse().ok()).collect())
        .unwrap_or_else(|| vec![50, 500, 5000]);
    let ms = |d: Duration| d.as_secs_f64() * 1000.0;
    let mut prev: Option<(usize, Duration)> = None;
    for &n in &sizes {
        let (wall, cpu, diags) = median_check(n);
        let target = if n == 500 { "   (target < 20 ms)" } else { "" };
        println!(
            "btc check, {n:>5} rules over {n:>5} actions: {:>9.2} ms CPU median{target} ({:.2} ms wall), {diags} diagnostics",
            ms(cpu),
            ms(wall)
        );
        if let Some((pn, pt)) = prev {
            let size = n as f64 / pn as f64;
            let time = cpu.as_secs_f64() / pt.as_secs_f64();
            println!(
                "  {pn} -> {n} rules: CPU time x{time:.2} for size x{size:.1}: {:.2}x linear   (target <= 1.5x)",
                time / size
            );
        }
        prev = Some((n, cpu));
    }
}
