//! Compile speed and size at scale, against a seed-style generator in the
//! same run: `cargo bench --bench compile_scale`.
//!
//! A 100,000-step timed plan of the P3 shape (`btc_testkit::long_p3_plan`)
//! is compiled two ways:
//! - **whole process**, as a user meets it: `btc compile RULES --plan PLAN
//!   --problem PROBLEM --emit F -o FILE`, from process start to exit
//!   (reading, checking, lowering, writing the file);
//! - **in process**, from texts (parse, check, lower, emit) as `btc
//!   compile -o` does it: the database freed before the emit, the output
//!   streamed (here to a writer that counts its bytes).
//!
//! The peer is `benches/peers/p3_seed_generator.py`, the P3 seed's
//! algorithm written anew in Python, timed as a whole process on the same
//! plan. Printed per format: median times (btc's of 11, the peer's of 5)
//! and the speed-ups over the peer (whole process also the median speed-up
//! of 7 pairs, the peer and btc run one right after the other), peak heap during the in-process compile
//! next to the output's size, bytes per step next to the peer's; each with
//! its target.

use btc_emit::{emit_to, pytrees::Runtime, ByteCount, Format, Options};
use btc_lang::db::{compile, CompileJob, Database};
use std::alloc::{GlobalAlloc, Layout};
use std::path::Path;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::time::{Duration, Instant};

/// mimalloc (as the `btc` binary) with the live and the peak heap counted.
struct Counting;

static LIVE: AtomicUsize = AtomicUsize::new(0);
static PEAK: AtomicUsize = AtomicUsize::new(0);

unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, l: Layout) -> *mut u8 {
        let p = unsafe { mimalloc::MiMalloc.alloc(l) };
        let now = LIVE.fetch_add(l.size(), Ordering::Relaxed) + l.size();
        PEAK.fetch_max(now, Ordering::Relaxed);
        p
    }

    unsafe fn dealloc(&self, p: *mut u8, l: Layout) {
        LIVE.fetch_sub(l.size(), Ordering::Relaxed);
        unsafe { mimalloc::MiMalloc.dealloc(p, l) }
    }

    unsafe fn realloc(&self, p: *mut u8, l: Layout, new: usize) -> *mut u8 {
        let q = unsafe { mimalloc::MiMalloc.realloc(p, l, new) };
        if new >= l.size() {
            let now = LIVE.fetch_add(new - l.size(), Ordering::Relaxed) + new - l.size();
            PEAK.fetch_max(now, Ordering::Relaxed);
        } else {
            LIVE.fetch_sub(l.size() - new, Ordering::Relaxed);
        }
        q
    }
}

#[global_allocator]
static GLOBAL: Counting = Counting;

const STEPS: usize = 100_000;
/// The peer's runs (about a second each), and btc's: more of them, as a
/// shared 2-core VM's page faults vary from run to run by tens of ms.
const RUNS: usize = 5;
const BTC_RUNS: usize = 11;
const DOMAIN: &str = include_str!("../examples/p3_assembler/domain.pddl");
const PROBLEM: &str = include_str!("../examples/p3_assembler/problem.pddl");
const RULES: &str = include_str!("../examples/p3_assembler/rules.btrules");

fn median(mut v: Vec<Duration>) -> Duration {
    v.sort();
    v[v.len() / 2]
}

/// One compile from texts to `format`, streamed as `btc compile -o`
/// streams it (here to a writer that counts): the output's size, the peak
/// heap above what was live before it, and the time the emitter took.
fn compile_once(plan: &str, format: Format) -> (usize, usize, Duration) {
    let base = LIVE.load(Ordering::Relaxed);
    PEAK.store(base, Ordering::Relaxed);
    let mut db = Database::new();
    db.set_file("p3/domain.pddl", DOMAIN.to_owned());
    let p = db.set_file("p3/problem.pddl", PROBLEM.to_owned());
    let r = db.set_file("p3/rules.btrules", RULES.to_owned());
    let l = db.set_file("p3/plan.tplan", plan.to_owned());
    let job = CompileJob::new(&db, r, l, Some(p), None);
    let ir = compile(&db, job)
        .as_ref()
        .expect("the plan compiles")
        .clone();
    // As `btc compile` does: the emitter reads the IR alone, so the texts,
    // the parsed plan and its replay are freed before the output is built.
    drop(db);
    let options = Options {
        runtime: Runtime::Import,
        ..Options::default()
    };
    let t = Instant::now();
    let mut out = ByteCount(0);
    emit_to(&ir, format, &options, &mut out).expect("counting never fails");
    let emitting = t.elapsed();
    (out.0, PEAK.load(Ordering::Relaxed) - base, emitting)
}

/// The peer on the same plan, whole process: median time and bytes written.
fn peer(plan_path: &Path, out: &Path) -> Option<(Duration, usize)> {
    let times = (0..RUNS)
        .map(|_| peer_once(plan_path, out))
        .collect::<Option<Vec<_>>>()?;
    Some((median(times), std::fs::metadata(out).ok()?.len() as usize))
}

/// One run of the peer, whole process; `None` when it cannot run.
fn peer_once(plan_path: &Path, out: &Path) -> Option<Duration> {
    let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("benches/peers/p3_seed_generator.py");
    let t = Instant::now();
    let status = std::process::Command::new("python3")
        .arg(&script)
        .arg(plan_path)
        .arg(out)
        .stdout(std::process::Stdio::null())
        .status()
        .ok()?;
    status.success().then(|| t.elapsed())
}

const BTC: &str = env!("CARGO_BIN_EXE_btc");

/// `btc compile` of the plan as a whole process writing `out`: the median
/// time from spawn to exit.
fn whole_process(plan_path: &Path, format: Format, out: &Path) -> Duration {
    median(
        (0..BTC_RUNS)
            .map(|_| btc_once(plan_path, format, out))
            .collect(),
    )
}

/// How many times the peer and btc run one right after the other.
const PAIRS: usize = 7;

/// The median of the speed-ups of btc's whole process over the peer's,
/// each from a pair of runs one right after the other: on a shared VM
/// whose speed drifts from minute to minute, a pair meets the same host.
fn paired_speedup(plan_path: &Path, format: Format, out: &Path, peer_out: &Path) -> Option<f64> {
    let mut ratios = Vec::with_capacity(PAIRS);
    for _ in 0..PAIRS {
        let peer = peer_once(plan_path, peer_out)?;
        let btc = btc_once(plan_path, format, out);
        ratios.push(peer.as_secs_f64() / btc.as_secs_f64());
    }
    ratios.sort_by(f64::total_cmp);
    Some(ratios[PAIRS / 2])
}

/// One run of `btc compile`, whole process: the time from spawn to exit.
fn btc_once(plan_path: &Path, format: Format, out: &Path) -> Duration {
    let example = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/p3_assembler");
    let t = Instant::now();
    let status = std::process::Command::new(BTC)
        .arg("compile")
        .arg(example.join("rules.btrules"))
        .arg("--plan")
        .arg(plan_path)
        .arg("--problem")
        .arg(example.join("problem.pddl"))
        .args(["--emit", format.name(), "-o"])
        .arg(out)
        .stderr(std::process::Stdio::null())
        .status()
        .expect("btc runs");
    let took = t.elapsed();
    assert!(status.success(), "btc compile --emit {}", format.name());
    took
}

fn mb(bytes: usize) -> f64 {
    bytes as f64 / 1e6
}

fn main() {
    // `cargo test --benches` runs this with `--bench` absent: stay quick.
    if !std::env::args().any(|a| a == "--bench") {
        println!("compile_scale: run with `cargo bench` for figures");
        return;
    }
    let plan = btc_testkit::long_p3_plan(STEPS);
    let dir = std::env::temp_dir().join(format!("btc-compile-scale-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let plan_path = dir.join("plan.tplan");
    std::fs::write(&plan_path, &plan).unwrap();
    let peer = peer(&plan_path, &dir.join("peer.py"));
    match peer {
        Some((t, bytes)) => println!(
            "peer (seed-style Python generator): {STEPS} steps in {:.0} ms, {:.1} MB ({:.0} bytes/step)",
            t.as_secs_f64() * 1e3,
            mb(bytes),
            bytes as f64 / STEPS as f64
        ),
        None => println!("peer: python3 could not run the seed-style generator"),
    }
    for (format, speed_target) in [
        (Format::Pytrees, Some(20.0)),
        (Format::Btcpp, Some(25.0)),
        (Format::Json, None),
    ] {
        let mut times = Vec::new();
        let mut emit_times = Vec::new();
        let mut out = (0, 0);
        for _ in 0..BTC_RUNS {
            let t = Instant::now();
            let (len, peak, emitting) = compile_once(&plan, format);
            times.push(t.elapsed());
            emit_times.push(emitting);
            out = (len, peak);
        }
        let t = median(times);
        let (len, peak) = out;
        let whole = whole_process(
            &plan_path,
            format,
            &dir.join(format!("out.{}", format.extension())),
        );
        let mut line = format!(
            "{:8}: whole process {:.0} ms",
            format.name(),
            whole.as_secs_f64() * 1e3
        );
        if let Some((pt, _)) = peer.filter(|_| speed_target.is_some()) {
            line += &format!(
                " = {:.1}x the peer's median",
                pt.as_secs_f64() / whole.as_secs_f64()
            );
            let out = dir.join(format!("paired.{}", format.extension()));
            if let Some(r) = paired_speedup(&plan_path, format, &out, &dir.join("paired-peer.py")) {
                line +=
                    &format!(", {r:.1}x in {PAIRS} pairs run one after the other (target >= 20x)");
            }
        }
        line += &format!(
            "; in process {:.0} ms (emitting {:.0} ms of it)",
            t.as_secs_f64() * 1e3,
            median(emit_times).as_secs_f64() * 1e3
        );
        if let (Some((pt, _)), Some(target)) = (peer, speed_target) {
            line += &format!(
                " = {:.1}x the peer (target >= {target}x)",
                pt.as_secs_f64() / t.as_secs_f64()
            );
        }
        line += &format!(
            "; peak heap {:.0} MB for {:.1} MB out = {:.2}x (target <= 2x)",
            mb(peak),
            mb(len),
            peak as f64 / len as f64
        );
        if let (Some((_, pb)), Format::Pytrees) = (peer, format) {
            line += &format!(
                "; {:.0} bytes/step = {:.2}x the peer's (target <= 1.2x)",
                len as f64 / STEPS as f64,
                len as f64 / pb as f64
            );
        }
        println!("{line}");
    }
    let _ = std::fs::remove_dir_all(&dir);
}
