//! Commands given inputs that used to cost them without bound: memory kept
//! proportional to the input, a run's trace streamed as it goes (a killed
//! run leaves what it wrote), long runs in bounded memory, `--max-ticks 0`.

use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Output, Stdio};
use std::time::{Duration, Instant};

fn repo() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn command(args: &[&str]) -> Command {
    let mut c = Command::new(env!("CARGO_BIN_EXE_btc"));
    c.args(args)
        .env("NO_COLOR", "1")
        .current_dir(repo())
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped());
    c
}

/// The child's peak resident memory in KiB so far (`VmHWM`), if it is
/// still there to ask.
fn high_water(child: &Child) -> Option<u64> {
    let status = std::fs::read_to_string(format!("/proc/{}/status", child.id())).ok()?;
    let line = status.lines().find(|l| l.starts_with("VmHWM:"))?;
    line.split_whitespace().nth(1)?.parse().ok()
}

/// Runs `btc args` to its end and returns its status and stderr, how many
/// bytes it wrote to stdout, and the highest peak resident memory seen (sampled: the peak only grows, so the last sample
/// before the exit is within a few milliseconds of the true one).
fn peak_memory(args: &[&str]) -> (Output, u64, u64) {
    let mut child = command(args).spawn().unwrap();
    // Drain the pipes while sampling, or a chatty child blocks on them.
    let mut out = child.stdout.take().unwrap();
    let mut err = child.stderr.take().unwrap();
    let o = std::thread::spawn(move || std::io::copy(&mut out, &mut std::io::sink()));
    let e = std::thread::spawn(move || {
        let mut s = Vec::new();
        std::io::Read::read_to_end(&mut err, &mut s).map(|_| s)
    });
    let mut peak = 0;
    while child.try_wait().unwrap().is_none() {
        if let Some(kb) = high_water(&child) {
            peak = peak.max(kb);
        }
        std::thread::sleep(Duration::from_millis(2));
    }
    let status = child.wait().unwrap();
    let written = o.join().unwrap().unwrap();
    let stderr = e.join().unwrap().unwrap();
    (
        Output {
            status,
            stdout: Vec::new(),
            stderr,
        },
        written,
        peak,
    )
}

fn write(dir: &Path, name: &str, bytes: &[u8]) -> String {
    let p = dir.join(name);
    std::fs::File::create(&p).unwrap().write_all(bytes).unwrap();
    p.display().to_string()
}

/// 8 MB of NUL bytes costs a command at most 20 times its size over what
/// it needs for nothing (100 MB of NULs used to take 1.5-3.3 GB). A long
/// plan compiled is bounded by 20 times what it reads and writes: the
/// py_trees module of a plan is about 20 times the plan (a 50 MB plan used
/// to take 5.2 GB; the emitters build their output whole, so the output's
/// size counts).
#[test]
fn memory_stays_proportional_to_the_input() {
    let dir = tempfile::tempdir().unwrap();
    let size = 8 << 20;
    let nul = vec![0u8; size];
    let rules = write(dir.path(), "nul.btrules", &nul);
    let pddl = write(dir.path(), "nul.pddl", &nul);
    let plan = write(dir.path(), "nul.plan", &nul);
    let long = btc_testkit::long_ariac_plan(200_000);
    let long_plan = write(dir.path(), "long.plan", long.as_bytes());
    let (d, p, r) = (
        "examples/ariac/domain.pddl",
        "examples/ariac/problem.pddl",
        "examples/ariac/rules.btrules",
    );
    let (_, _, baseline) = peak_memory(&["check", r]);
    let cases: Vec<(Vec<&str>, usize)> = vec![
        (vec!["check", &rules], size),
        (vec!["fmt", "--check", &rules], size),
        (vec!["pddl", &pddl], size),
        (vec!["validate", d, p, &plan], size),
        (
            vec!["compile", r, "--plan", &long_plan, "--emit", "pytrees"],
            long.len(),
        ),
    ];
    for (args, input) in cases {
        let (out, written, peak) = peak_memory(&args);
        assert!(
            out.status.code().is_some(),
            "{args:?} was killed: {}",
            String::from_utf8_lossy(&out.stderr)
        );
        let grown = peak.saturating_sub(baseline) * 1024;
        assert!(
            grown <= 20 * (input as u64 + written),
            "{args:?}: {} MB over the baseline for {} MB of input and {} MB of output",
            grown >> 20,
            input >> 20,
            written >> 20
        );
    }
}

fn forever(trace: &Path, max_ticks: &str) -> Command {
    command(&[
        "run",
        "--tree",
        "tests/fixtures/run/forever.xml",
        "--max-ticks",
        max_ticks,
        "--trace",
        trace.to_str().unwrap(),
    ])
}

/// Every line of a trace file is a whole JSON object.
fn trace_lines(trace: &Path) -> usize {
    let text = std::fs::read_to_string(trace).unwrap();
    assert!(text.is_empty() || text.ends_with('\n'), "a cut line");
    for l in text.lines() {
        serde_json::from_str::<serde_json::Value>(l).unwrap();
    }
    text.lines().count()
}

fn signalled_run_keeps_its_trace(signal: &str) {
    let dir = tempfile::tempdir().unwrap();
    let trace = dir.path().join("trace.jsonl");
    let mut child = forever(&trace, "1000000000").spawn().unwrap();
    // Wait until the run has written part of its trace.
    let t = Instant::now();
    while std::fs::metadata(&trace).map_or(0, |m| m.len()) < 4096 {
        assert!(t.elapsed() < Duration::from_secs(60), "no trace written");
        std::thread::sleep(Duration::from_millis(20));
    }
    let ok = Command::new("kill")
        .args(["-s", signal, &child.id().to_string()])
        .status()
        .unwrap();
    assert!(ok.success());
    let status = child.wait().unwrap();
    assert!(!status.success(), "{signal} ends the run");
    assert!(trace_lines(&trace) > 10);
    // The trace is the only file left: no temporary one.
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);
}

#[test]
fn sigterm_leaves_the_trace_written_so_far() {
    signalled_run_keeps_its_trace("TERM");
}

#[test]
fn sigint_leaves_the_trace_written_so_far() {
    signalled_run_keeps_its_trace("INT");
}

/// Ten times the ticks, written to the trace as they go, take about the
/// same memory (a run of 2M ticks used to hold 1.66 GB of trace).
#[test]
fn a_long_traced_run_holds_bounded_memory() {
    let dir = tempfile::tempdir().unwrap();
    let peak = |ticks: &str| {
        let trace = dir.path().join(format!("{ticks}.jsonl"));
        let cmd = forever(&trace, ticks);
        let args: Vec<String> = cmd
            .get_args()
            .map(|a| a.to_string_lossy().into_owned())
            .collect();
        let args: Vec<&str> = args.iter().map(String::as_str).collect();
        let (out, _, kb) = peak_memory(&args);
        assert_eq!(out.status.code(), Some(1), "still running at the end");
        (kb, trace_lines(&trace))
    };
    let (small, small_lines) = peak("20000");
    let (large, large_lines) = peak("200000");
    assert!(
        large_lines >= 9 * small_lines,
        "{small_lines} -> {large_lines}"
    );
    assert!(
        (large as f64) < 1.5 * small as f64,
        "10x the ticks took {small} KiB -> {large} KiB"
    );
}

/// `--max-ticks 0` ticks nothing and says the tree was still running (it
/// used to tick once).
#[test]
fn max_ticks_zero_runs_no_tick() {
    let out = command(&[
        "run",
        "--tree",
        "tests/fixtures/run/forever.xml",
        "--max-ticks",
        "0",
        "--format",
        "json",
    ])
    .output()
    .unwrap();
    assert_eq!(out.status.code(), Some(1));
    let s: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(s["ticks"], 0);
    assert_eq!(s["status"], "RUNNING");
}
