//! Differential conformance against BehaviorTree.CPP itself: seeded random
//! trees over every control node and decorator both engines support, with
//! scripted leaves (a status sequence per leaf, read through ports and
//! blackboard entries, across SubTree remapping), run tick by tick in btc's
//! engine and in real BT.CPP 4.10 (`integrations/btcpp/harness/
//! conformance.cpp`, many trees per process). Every status change of every
//! node, in order, tick by tick, must be the same in both.
//!
//! The one thing compared apart: BT.CPP's `Tree::tickRoot` resets the root
//! to IDLE after the tick that finishes the tree; btc's engine leaves the
//! root with its final status (the tree's driver, not a node, makes that
//! change). `the_tree_driver_resets_the_root_after_the_last_tick` tests it.
//!
//! `BTC_CONFORMANCE_CASES` and `BTC_CONFORMANCE_SEED` run other batches.

use btc_runtime::btlog::BtlogRecorder;
use btc_runtime::engine::TickEvent;
use btc_runtime::observers::EventLog;
use btc_runtime::{xml, Engine, Options, Status};
use std::collections::HashMap;
use std::fmt::Write as _;
use std::path::PathBuf;
use std::process::Command;

/// One status change: node (preorder), from, to.
type Change = (u32, char, char);

#[derive(Debug, PartialEq)]
struct Run {
    /// Per tick, the changes in order.
    ticks: Vec<Vec<Change>>,
    status: char,
    /// The root's reset after the last tick (BT.CPP's tickRoot).
    reset: Option<Change>,
    /// What BT.CPP threw out of the tick after the last one in `ticks`.
    thrown: Option<String>,
    /// btc's run: each node's registration ID, by preorder index.
    ids: Vec<String>,
}

fn letter(s: Status) -> char {
    match s {
        Status::Idle => 'I',
        Status::Running => 'R',
        Status::Success => 'S',
        Status::Failure => 'F',
        Status::Skipped => 'K',
    }
}

/// A case: its XML (or `file PATH`: a file both load, includes and all),
/// how many ticks at most, simulated or real ms per tick.
struct Case {
    xml: String,
    ticks: u32,
    tick_ms: u64,
}

// ---------------------------------------------------------------- btc

fn run_btc(case: &Case) -> Result<Run, String> {
    run_btc_logged(case).map(|(r, _)| r)
}

/// [`run_btc`], with the run's `.btlog` as btc writes it.
fn run_btc_logged(case: &Case) -> Result<(Run, Vec<u8>), String> {
    let doc = tree_doc(case)?;
    let opts = Options {
        ms_per_tick: case.tick_ms.max(1),
        ..Options::default()
    };
    let mut e = Engine::build(&doc, None, opts).map_err(|e| e.to_string())?;
    e.observe(EventLog::default());
    e.observe(BtlogRecorder::new(case.tick_ms.max(1)));
    let mut pos: HashMap<u32, usize> = HashMap::new();
    e.set_action_handler(
        "Scripted",
        Box::new(move |c| {
            let script = c.port("script").map(|v| v.text()).unwrap_or_default();
            let b = script.as_bytes();
            if b.is_empty() {
                return Status::Failure;
            }
            let p = pos.entry(c.node).or_insert(0);
            let ch = b[*p % b.len()];
            *p += 1;
            match ch {
                b'S' => Status::Success,
                b'R' => Status::Running,
                _ => Status::Failure,
            }
        }),
    );
    let mut run = Run {
        ticks: Vec::new(),
        status: 'R',
        reset: None,
        thrown: None,
        ids: e.meta.iter().map(|m| m.id.clone()).collect(),
    };
    let mut seen = 0;
    let mut last = Status::Running;
    for _ in 0..case.ticks {
        let s = e.tick_once();
        let mut changes = Vec::new();
        let events = &e.observer::<EventLog>().expect("observed").events;
        for t in &events[seen..] {
            if let TickEvent::Status { node, from, to, .. } = t {
                changes.push((*node, letter(*from), letter(*to)));
            }
        }
        seen = events.len();
        run.ticks.push(changes);
        run.status = letter(s);
        last = s;
        if s != Status::Running {
            break;
        }
    }
    let log = e
        .take_observer::<BtlogRecorder>()
        .expect("observed")
        .finish(&doc, &e, last, 0)
        .map_err(|e| e.to_string())?;
    Ok((run, log))
}

/// The case's tree as btc reads it: from the text, or from the file with
/// the files it includes (relative to each file, as `btc run --tree`).
fn tree_doc(case: &Case) -> Result<btc_runtime::TreeDoc, String> {
    use btc_runtime::include::{self, Opened};
    let Some(path) = case.xml.strip_prefix("file ") else {
        return xml::parse(&case.xml).map_err(|e| e.to_string());
    };
    let path = std::path::Path::new(path.trim());
    let read = |p: &std::path::Path| std::fs::read_to_string(p).map_err(|e| e.to_string());
    let mut open = |p: &std::path::Path| -> Result<Opened<()>, String> {
        Ok(Opened {
            file: (),
            text: read(p)?,
        })
    };
    let first = Opened {
        file: (),
        text: read(path)?,
    };
    include::load(path, first, &mut open).map_err(|e| e.error.to_string())
}

// ------------------------------------------------------------- BT.CPP

fn harness() -> Option<PathBuf> {
    btc_testkit::btcpp_harness().map(|d| d.join("btc_conformance"))
}

fn run_btcpp(exe: &PathBuf, cases: &[Case], name: &str) -> Vec<Result<Run, String>> {
    run_btcpp_logged(exe, cases, name, None)
}

/// [`run_btcpp`]; with `btlog`, BT.CPP's FileLogger2 writes `btlog/cI.btlog`.
fn run_btcpp_logged(
    exe: &PathBuf,
    cases: &[Case],
    name: &str,
    btlog: Option<&std::path::Path>,
) -> Vec<Result<Run, String>> {
    let dir = btc_testkit::target_dir("btcpp/conformance");
    std::fs::create_dir_all(&dir).unwrap();
    let input = dir.join(format!("{name}.cases"));
    let mut text = String::new();
    for (i, c) in cases.iter().enumerate() {
        let _ = writeln!(
            text,
            "case c{i} {} {}\n{}\nend",
            c.ticks,
            c.tick_ms,
            c.xml.trim()
        );
    }
    std::fs::write(&input, text).unwrap();
    let mut cmd = Command::new(exe);
    if let Some(dir) = btlog {
        std::fs::create_dir_all(dir).unwrap();
        cmd.arg("--btlog").arg(dir);
    }
    let out = cmd.arg(&input).output().unwrap();
    assert!(
        out.status.success(),
        "the harness failed: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    parse_runs(&String::from_utf8_lossy(&out.stdout), cases.len())
}

fn parse_change(words: &[&str]) -> Change {
    let c = |w: &str| w.chars().next().unwrap();
    (words[0].parse().unwrap(), c(words[1]), c(words[2]))
}

fn parse_runs(out: &str, n: usize) -> Vec<Result<Run, String>> {
    let mut runs: Vec<Result<Run, String>> = Vec::with_capacity(n);
    for line in out.lines() {
        let words: Vec<&str> = line.split_whitespace().collect();
        match words.first().copied() {
            Some("case") => runs.push(Ok(Run {
                ticks: Vec::new(),
                status: 'R',
                reset: None,
                thrown: None,
                ids: Vec::new(),
            })),
            // Before the first tick: the tree is refused; after: the tick
            // threw.
            Some("error") => {
                let last = runs.last_mut().unwrap();
                match last {
                    Ok(r) if !r.ticks.is_empty() || line.contains("Exception in node") => {
                        r.thrown = Some(line[6..].to_owned());
                    }
                    _ => *last = Err(line[6..].to_owned()),
                }
            }
            Some("tick") => {
                if let Some(Ok(r)) = runs.last_mut() {
                    r.ticks.push(Vec::new());
                }
            }
            Some("status") => {
                if let Some(Ok(r)) = runs.last_mut() {
                    r.status = words[1].chars().next().unwrap();
                }
            }
            Some("reset") => {
                if let Some(Ok(r)) = runs.last_mut() {
                    r.reset = Some(parse_change(&words[1..]));
                }
            }
            Some(_) => {
                if let Some(Ok(r)) = runs.last_mut() {
                    r.ticks.last_mut().unwrap().push(parse_change(&words));
                }
            }
            None => {}
        }
    }
    assert_eq!(runs.len(), n, "the harness answered every case");
    runs
}

/// Compares one case; the message says where the runs part.
fn compare(case: &Case, btc: &Run, cpp: &Run) -> Result<(), String> {
    let mut b = btc.ticks.clone();
    let c = cpp.ticks.clone();
    b.resize(c.len().max(b.len()), Vec::new());
    for (t, (x, y)) in b.iter().zip(c.iter()).enumerate() {
        if x != y {
            return Err(format!(
                "tick {}: btc {:?}\n        BT.CPP {:?}\n{}",
                t + 1,
                x,
                y,
                case.xml
            ));
        }
    }
    if btc.ticks.len() != cpp.ticks.len() || btc.status != cpp.status {
        return Err(format!(
            "btc stopped after {} ticks with {}, BT.CPP after {} with {}\n{}",
            btc.ticks.len(),
            btc.status,
            cpp.ticks.len(),
            cpp.status,
            case.xml
        ));
    }
    Ok(())
}

/// Where BT.CPP 4.10 throws out of the tick, btc fails the node instead
/// (docs/runtime.md, intended differences): IfThenElse whose condition was
/// SKIPPED ("Something unexpected happened"), WhileDoElse whose condition
/// was SKIPPED (it returns IDLE, and setting IDLE throws). The ticks before
/// agree, and in the tick BT.CPP threw btc fails a node of that kind (for
/// IfThenElse, the one BT.CPP names).
fn compare_thrown(case: &Case, btc: &Run, cpp: &Run, what: &str) -> Result<(), String> {
    let kind = if what.contains("Something unexpected happened in IfThenElseNode") {
        "IfThenElse"
    } else if what
        .contains("Node [WhileDoElse]: you are not allowed to set manually the status to IDLE")
    {
        "WhileDoElse"
    } else {
        return Err(format!("BT.CPP threw: {what}\n{}", case.xml));
    };
    let t = cpp.ticks.len();
    let before = Run {
        ticks: btc.ticks.iter().take(t).cloned().collect(),
        status: 'R',
        reset: None,
        thrown: None,
        ids: Vec::new(),
    };
    let cpp_before = Run {
        ticks: cpp.ticks.clone(),
        status: 'R',
        reset: None,
        thrown: None,
        ids: Vec::new(),
    };
    compare(case, &before, &cpp_before)?;
    // `'Path/IfThenElse::UID' [IfThenElse]`: uids are preorder from 1.
    let named = what
        .split("' [")
        .next()
        .and_then(|p| p.rsplit("::").next())
        .and_then(|uid| uid.parse::<u32>().ok())
        .filter(|_| kind == "IfThenElse")
        .map(|uid| uid - 1);
    let failed = btc.ticks.get(t).into_iter().flatten().any(|&(n, _, to)| {
        to == 'F'
            && btc.ids.get(n as usize).is_some_and(|id| id == kind)
            && named.is_none_or(|k| k == n)
    });
    if failed {
        Ok(())
    } else {
        Err(format!(
            "tick {}: BT.CPP threw ({what}); btc failed no {kind} there: {:?}\n{}",
            t + 1,
            btc.ticks.get(t),
            case.xml
        ))
    }
}

// ---------------------------------------------------------- generator

struct Gen {
    rng: fastrand::Rng,
    subtrees: Vec<String>,
    /// Also BT.CPP's scripting and the nodes around it: Script,
    /// ScriptCondition, IfThenElse, WhileDoElse, Switch2, RunOnce,
    /// Precondition, and the pre- and post-condition attributes.
    scripting: bool,
}

const KEYS: &[&str] = &["a", "b", "c"];

impl Gen {
    fn script(&mut self) -> String {
        let n = self.rng.usize(1..=4);
        (0..n)
            .map(|_| match self.rng.u8(0..20) {
                0..=8 => 'S',
                9..=15 => 'F',
                _ => 'R',
            })
            .collect()
    }

    fn key(&mut self) -> &'static str {
        KEYS[self.rng.usize(..KEYS.len())]
    }

    /// An entry a script may read: one every tree sets first. Scripts keep
    /// to entries of their own (`x`, `y`): BT.CPP 4.10 throws (out of
    /// `tickExactlyOnce`, uncaught) when a typed port reads an entry a
    /// script created.
    fn script_key(&mut self, _params: &[&str]) -> &'static str {
        if self.rng.bool() {
            "x"
        } else {
            "y"
        }
    }

    /// A tree's root: with scripting, after the script that makes the
    /// entries scripts read.
    fn root(&mut self, out: &mut String, params: &[&str]) {
        if self.scripting {
            out.push_str(r#"<Sequence><Script code="x := 'S'; y := 'F'"/>"#);
            self.node(out, 1, params);
            out.push_str("</Sequence>");
        } else {
            self.node(out, if params.is_empty() { 0 } else { 1 }, params);
        }
    }

    /// A condition on an entry (entries hold status letters).
    fn condition(&mut self, params: &[&str]) -> String {
        let k = self.script_key(params);
        let s = self.script();
        let op = if self.rng.bool() { "==" } else { "!=" };
        format!("{k} {op} '{s}'")
    }

    /// Sometimes a pre- or post-condition attribute.
    fn guard(&mut self, params: &[&str]) -> String {
        if !self.scripting || self.rng.u8(0..100) >= 20 {
            return String::new();
        }
        let attr = ["_skipIf", "_successIf", "_failureIf", "_while"][self.rng.usize(..4)];
        let c = self.condition(params);
        let mut g = format!(r#" {attr}="{c}""#);
        if self.rng.bool() {
            let post = ["_onSuccess", "_onFailure", "_post", "_onHalted"][self.rng.usize(..4)];
            let k = self.script_key(params);
            let s = self.script();
            let _ = write!(g, r#" {post}="{k} := '{s}'""#);
        }
        g
    }

    fn leaf(&mut self, out: &mut String, params: &[&str]) {
        if self.scripting && self.rng.u8(0..100) < 20 {
            let k = self.script_key(params);
            if self.rng.bool() {
                let s = self.script();
                let _ = write!(out, r#"<Script code="{k} := '{s}'"/>"#);
            } else {
                let c = self.condition(params);
                let _ = write!(out, r#"<ScriptCondition code="{c}"/>"#);
            }
            return;
        }
        match self.rng.u8(0..100) {
            0..=44 => {
                let s = self.script();
                let _ = write!(out, r#"<Scripted script="{s}"/>"#);
            }
            45..=54 => out.push_str("<AlwaysSuccess/>"),
            55..=62 => out.push_str("<AlwaysFailure/>"),
            63..=77 => {
                let k = match params {
                    [] => self.key(),
                    ps => ps[self.rng.usize(..ps.len())],
                };
                let _ = write!(out, r#"<Scripted script="{{{k}}}"/>"#);
            }
            _ => {
                let s = self.script();
                let k = self.key();
                let _ = write!(out, r#"<SetBlackboard value="{s}" output_key="{k}"/>"#);
            }
        }
    }

    fn node(&mut self, out: &mut String, depth: u32, params: &[&str]) {
        let r = self.rng.u8(0..100);
        if depth >= 5 || (depth > 0 && r < 30) {
            return self.leaf(out, params);
        }
        if r < 40 && !self.subtrees.is_empty() {
            let id = self.subtrees[self.rng.usize(..self.subtrees.len())].clone();
            match self.rng.u8(0..3) {
                0 => {
                    let k = self.key();
                    let _ = write!(out, r#"<SubTree ID="{id}" s="{{{k}}}"/>"#);
                }
                1 => {
                    let s = self.script();
                    let _ = write!(out, r#"<SubTree ID="{id}" s="{s}"/>"#);
                }
                _ => {
                    let s = self.script();
                    let _ = write!(out, r#"<SubTree ID="{id}" s="{s}" _autoremap="true"/>"#);
                }
            }
            return;
        }
        if self.scripting && r < 50 {
            let g = self.guard(params);
            let (tag, n, extra) = match self.rng.u8(0..3) {
                0 => ("IfThenElse", self.rng.usize(2..=3), String::new()),
                1 => ("WhileDoElse", self.rng.usize(2..=3), String::new()),
                _ => {
                    let k = self.script_key(params);
                    let (a, b) = (self.script(), self.script());
                    (
                        "Switch2",
                        3,
                        format!(r#" variable="{{{k}}}" case_1="{a}" case_2="{b}""#),
                    )
                }
            };
            let _ = write!(out, "<{tag}{extra}{g}>");
            for _ in 0..n {
                self.node(out, depth + 1, params);
            }
            let _ = write!(out, "</{tag}>");
            return;
        }
        if self.scripting && r < 60 {
            let g = self.guard(params);
            let (tag, extra) = if self.rng.bool() {
                let skip = if self.rng.bool() { "true" } else { "false" };
                ("RunOnce", format!(r#" then_skip="{skip}""#))
            } else {
                let c = self.condition(params);
                let e = ["SUCCESS", "FAILURE", "SKIPPED"][self.rng.usize(..3)];
                ("Precondition", format!(r#" if="{c}" else="{e}""#))
            };
            let _ = write!(out, "<{tag}{extra}{g}>");
            self.node(out, depth + 1, params);
            let _ = write!(out, "</{tag}>");
            return;
        }
        if r < 75 {
            let n = self.rng.usize(1..=4);
            let (tag, extra) = match self.rng.u8(0..6) {
                0 => ("Sequence", String::new()),
                1 => ("ReactiveSequence", String::new()),
                2 => ("SequenceWithMemory", String::new()),
                3 => ("Fallback", String::new()),
                4 => ("ReactiveFallback", String::new()),
                _ => {
                    let mut t = |name: &str| -> String {
                        match self.rng.u8(0..4) {
                            0 => String::new(),
                            1 => format!(r#" {name}="-1""#),
                            _ => format!(r#" {name}="{}""#, self.rng.usize(1..=n)),
                        }
                    };
                    let s = t("success_count");
                    let f = t("failure_count");
                    ("Parallel", s + &f)
                }
            };
            let g = self.guard(params);
            let _ = write!(out, "<{tag}{extra}{g}>");
            for _ in 0..n {
                self.node(out, depth + 1, params);
            }
            let _ = write!(out, "</{tag}>");
            return;
        }
        let (tag, extra) = match self.rng.u8(0..7) {
            0 => ("Inverter", String::new()),
            1 => ("ForceSuccess", String::new()),
            2 => ("ForceFailure", String::new()),
            3 => ("KeepRunningUntilFailure", String::new()),
            4 => (
                "RetryUntilSuccessful",
                format!(r#" num_attempts="{}""#, self.count()),
            ),
            5 => ("Repeat", format!(r#" num_cycles="{}""#, self.count())),
            // Never fires within a case: the clocks are compared apart.
            _ => (
                "Timeout",
                format!(r#" msec="{}""#, if self.rng.bool() { 0 } else { 3_600_000 }),
            ),
        };
        let _ = write!(out, "<{tag}{extra}>");
        self.node(out, depth + 1, params);
        let _ = write!(out, "</{tag}>");
    }

    fn count(&mut self) -> i32 {
        match self.rng.u8(0..6) {
            0 => -1,
            1 => 0,
            _ => self.rng.i32(1..=4),
        }
    }

    fn tree(&mut self) -> String {
        self.subtrees.clear();
        let mut defs = String::new();
        for i in 0..self.rng.usize(0..=2) {
            let id = format!("S{i}");
            let _ = write!(defs, r#"<BehaviorTree ID="{id}">"#);
            self.root(&mut defs, &["s"]);
            defs.push_str("</BehaviorTree>");
            self.subtrees.push(id);
        }
        let mut main = String::from(r#"<BehaviorTree ID="Main">"#);
        self.root(&mut main, &[]);
        main.push_str("</BehaviorTree>");
        format!(
            r#"<root BTCPP_format="4" main_tree_to_execute="Main">{main}{defs}<TreeNodesModel><Action ID="Scripted"><input_port name="script" type="std::string"/></Action></TreeNodesModel></root>"#
        )
    }
}

fn env_or(name: &str, default: u64) -> u64 {
    std::env::var(name)
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(default)
}

fn check_all(cases: &[Case], name: &str) -> usize {
    let Some(exe) = harness() else { return 0 };
    let cpp = run_btcpp(&exe, cases, name);
    let mut failures = Vec::new();
    let mut finished = 0;
    for (i, (case, cpp)) in cases.iter().zip(&cpp).enumerate() {
        let cpp = match cpp {
            Ok(r) => r,
            Err(e) => {
                failures.push(format!("case {i}: BT.CPP refused it: {e}\n{}", case.xml));
                continue;
            }
        };
        let btc = match run_btc(case) {
            Ok(r) => r,
            Err(e) => {
                failures.push(format!("case {i}: btc refused it: {e}\n{}", case.xml));
                continue;
            }
        };
        if cpp.status != 'R' || cpp.thrown.is_some() {
            finished += 1;
        }
        let same = match &cpp.thrown {
            Some(what) => compare_thrown(case, &btc, cpp, what),
            None => compare(case, &btc, cpp),
        };
        if let Err(e) = same {
            failures.push(format!("case {i}: {e}"));
        }
    }
    // Every difference, for classifying them: the message shows three.
    let report = btc_testkit::target_dir("btcpp/conformance").join(format!("{name}.differences"));
    let _ = std::fs::write(&report, failures.join("\n\n"));
    assert!(
        failures.is_empty(),
        "{} of {} cases differ (all in {}); the first:\n{}",
        failures.len(),
        cases.len(),
        report.display(),
        failures
            .iter()
            .take(3)
            .cloned()
            .collect::<Vec<_>>()
            .join("\n\n")
    );
    finished
}

/// A random batch (`BTC_CONFORMANCE_CASES` and `BTC_CONFORMANCE_SEED`
/// override `n` and `seed`), checked against BT.CPP: it must not be
/// trivial (most trees finish, some run on).
fn random_batch(name: &str, n: u64, seed: u64, scripting: bool) {
    let n = env_or("BTC_CONFORMANCE_CASES", n) as usize;
    let seed = env_or("BTC_CONFORMANCE_SEED", seed);
    let mut g = Gen {
        rng: fastrand::Rng::with_seed(seed),
        subtrees: Vec::new(),
        scripting,
    };
    let cases: Vec<Case> = (0..n)
        .map(|_| Case {
            xml: g.tree(),
            ticks: 12,
            // No Timeout of these trees fires (0 or an hour), so no clock:
            // the harness ticks without sleeping.
            tick_ms: 0,
        })
        .collect();
    let finished = check_all(&cases, name);
    if harness().is_some() {
        assert!(
            finished > n / 3 && finished < n,
            "{finished} of {n} finished"
        );
    }
}

#[test]
fn random_trees_run_tick_for_tick_as_in_btcpp() {
    random_batch("random", 10_000, 0x6274_6370_7034, false);
}

/// Some of these trees make BT.CPP 4.10 throw (IfThenElse or WhileDoElse
/// whose condition was SKIPPED): there btc fails the node, checked by
/// [`compare_thrown`].
#[test]
fn random_trees_with_scripting_run_tick_for_tick_as_in_btcpp() {
    random_batch("scripting", 5_000, 0x7363_7269_7074, true);
}

fn one(xml_body: &str, ticks: u32, tick_ms: u64) -> Case {
    Case {
        xml: format!(
            r#"<root BTCPP_format="4" main_tree_to_execute="Main"><BehaviorTree ID="Main">{xml_body}</BehaviorTree><TreeNodesModel><Action ID="Scripted"><input_port name="script" type="std::string"/></Action></TreeNodesModel></root>"#
        ),
        ticks,
        tick_ms,
    }
}

#[test]
fn reactive_nodes_let_two_children_run_in_turn_as_btcpp_4_10_does() {
    // BT.CPP 4.10 no longer throws here by default (throw_if_multiple_running
    // is false): both engines halt the other child and go on.
    check_all(
        &[
            one(
                r#"<ReactiveSequence><Scripted script="RS"/><Scripted script="R"/></ReactiveSequence>"#,
                8,
                10,
            ),
            one(
                r#"<ReactiveFallback><Scripted script="RF"/><Scripted script="RRS"/></ReactiveFallback>"#,
                8,
                10,
            ),
        ],
        "reactive",
    );
}

#[test]
fn retry_and_repeat_forever_make_one_attempt_per_tick_as_btcpp_does() {
    // A child that finishes at once is tried again at the next tick (BT.CPP
    // returns RUNNING and signals a wake-up); one that ran and then failed
    // is tried again in the same tick.
    check_all(
        &[
            one(
                r#"<RetryUntilSuccessful num_attempts="-1"><Scripted script="FFFS"/></RetryUntilSuccessful>"#,
                8,
                10,
            ),
            one(
                r#"<Repeat num_cycles="-1"><Scripted script="SSF"/></Repeat>"#,
                8,
                10,
            ),
            one(
                r#"<RetryUntilSuccessful num_attempts="3"><Scripted script="RFRFFS"/></RetryUntilSuccessful>"#,
                8,
                10,
            ),
            one(
                r#"<Repeat num_cycles="3"><Scripted script="RSS"/></Repeat>"#,
                8,
                10,
            ),
        ],
        "forever",
    );
}

#[test]
fn timeout_and_sleep_agree_when_the_clocks_agree() {
    // BT.CPP's Timeout and Sleep use the wall clock (a timer thread); btc's
    // use simulated time (`ms_per_tick`). With the harness sleeping 100 ms
    // between ticks and btc counting 100 ms per tick, a 30 ms timeout fires
    // and a 30 ms sleep ends at the same tick in both.
    check_all(
        &[
            one(
                r#"<Timeout msec="30"><Scripted script="R"/></Timeout>"#,
                5,
                100,
            ),
            one(
                r#"<Sequence><Sleep msec="30"/><Scripted script="S"/></Sequence>"#,
                5,
                100,
            ),
            one(
                r#"<Timeout msec="250"><Sequence><Sleep msec="30"/><Scripted script="RRRRS"/></Sequence></Timeout>"#,
                8,
                100,
            ),
        ],
        "clock",
    );
}

#[test]
fn where_btcpp_throws_on_a_skipped_condition_btc_fails_the_node() {
    let Some(exe) = harness() else { return };
    let cases = [
        one(
            r#"<Sequence><Scripted script="RS"/><IfThenElse><AlwaysSuccess _skipIf="true"/><Scripted script="S"/></IfThenElse></Sequence>"#,
            5,
            10,
        ),
        one(
            r#"<Sequence><Scripted script="RS"/><WhileDoElse><AlwaysSuccess _skipIf="true"/><Scripted script="S"/></WhileDoElse></Sequence>"#,
            5,
            10,
        ),
    ];
    let cpp = run_btcpp(&exe, &cases, "thrown");
    for (case, cpp) in cases.iter().zip(&cpp) {
        let cpp = cpp.as_ref().unwrap();
        let what = cpp.thrown.as_deref().expect("BT.CPP 4.10 throws");
        assert_eq!(cpp.ticks.len(), 1, "the first tick went through");
        compare_thrown(case, &run_btc(case).unwrap(), cpp, what).unwrap();
    }
}

/// `<include path>` as BT.CPP reads it (`createTreeFromFile`, paths
/// relative to each including file) and as btc does: the same statuses
/// tick by tick.
#[test]
fn included_files_run_as_in_btcpp() {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/include");
    let case = |file: &str, ticks| Case {
        xml: format!("file {}", dir.join(file).display()),
        ticks,
        tick_ms: 0,
    };
    let cases = [case("btcpp/main.xml", 12), case("main.xml", 3)];
    check_all(&cases, "include");
    // Both finish, the included trees' scripts counted as the fixture says.
    if let Some(exe) = harness() {
        for run in run_btcpp(&exe, &cases, "include-status") {
            assert_eq!(run.unwrap().status, 'S');
        }
    }
}

#[test]
fn the_tree_driver_resets_the_root_after_the_last_tick() {
    let Some(exe) = harness() else { return };
    let cases = [
        one(r#"<Scripted script="RS"/>"#, 5, 10),
        one(r#"<Sequence><Scripted script="F"/></Sequence>"#, 5, 10),
        one(r#"<Scripted script="R"/>"#, 3, 10),
    ];
    let cpp = run_btcpp(&exe, &cases, "reset");
    for (case, cpp) in cases.iter().zip(&cpp) {
        let cpp = cpp.as_ref().unwrap();
        let btc = run_btc(case).unwrap();
        compare(case, &btc, cpp).unwrap();
        if cpp.status == 'R' {
            assert_eq!(cpp.reset, None, "a tree still running is not reset");
        } else {
            // BT.CPP's tickRoot puts the root back to IDLE; btc's root keeps
            // the final status, which `btc run` reports.
            assert_eq!(cpp.reset, Some((0, cpp.status, 'I')));
        }
    }
}

// ------------------------------------------------------------ .btlog

/// An XML element with its attributes as a set (BT.CPP keeps ports in a
/// hash map, so their order means nothing) and, for port lists, its
/// children as a set too.
#[derive(Debug, PartialEq, Eq, PartialOrd, Ord, Clone)]
struct El {
    name: String,
    attrs: std::collections::BTreeMap<String, String>,
    text: String,
    children: Vec<El>,
}

fn parse_xml(text: &str) -> El {
    use quick_xml::events::Event;
    let mut r = quick_xml::Reader::from_str(text);
    r.config_mut().trim_text(true);
    let decoder = r.decoder();
    let el = |e: &quick_xml::events::BytesStart| El {
        name: String::from_utf8_lossy(e.name().as_ref()).into_owned(),
        attrs: e
            .attributes()
            .map(|a| {
                let a = a.unwrap();
                (
                    String::from_utf8_lossy(a.key.as_ref()).into_owned(),
                    a.decode_and_unescape_value(decoder).unwrap().into_owned(),
                )
            })
            .collect(),
        text: String::new(),
        children: Vec::new(),
    };
    let mut stack: Vec<El> = vec![El {
        name: String::new(),
        attrs: Default::default(),
        text: String::new(),
        children: Vec::new(),
    }];
    loop {
        match r.read_event().unwrap() {
            Event::Start(e) => stack.push(el(&e)),
            Event::Empty(e) => stack.last_mut().unwrap().children.push(el(&e)),
            Event::Text(t) => {
                let d = t.decode().unwrap();
                stack.last_mut().unwrap().text =
                    quick_xml::escape::unescape(&d).unwrap().into_owned();
            }
            Event::End(_) => {
                let done = stack.pop().unwrap();
                stack.last_mut().unwrap().children.push(done);
            }
            Event::Eof => break,
            _ => {}
        }
    }
    let mut doc = stack.pop().unwrap();
    let mut root = doc.children.remove(0);
    for c in &mut root.children {
        if c.name == "TreeNodesModel" {
            for m in &mut c.children {
                m.children.sort();
            }
        }
    }
    root
}

/// A `.btlog` read back: its XML and its (uid, status) records, with the
/// timestamps checked to never go back.
fn read_btlog(b: &[u8]) -> (El, Vec<(u16, u8)>) {
    assert_eq!(&b[..18], b"BTCPP4-FileLogger2");
    assert_eq!(b[18], 1, "protocol");
    let n = i32::from_le_bytes(b[19..23].try_into().unwrap()) as usize;
    let xml = parse_xml(std::str::from_utf8(&b[23..23 + n]).unwrap());
    let records = &b[23 + n + 8..];
    assert_eq!(records.len() % 9, 0);
    let mut last = 0u64;
    let mut out = Vec::new();
    for r in records.chunks(9) {
        let mut t = [0u8; 8];
        t[..6].copy_from_slice(&r[..6]);
        let t = u64::from_le_bytes(t);
        assert!(t >= last, "timestamps go back");
        last = t;
        out.push((u16::from_le_bytes([r[6], r[7]]), r[8]));
    }
    (xml, out)
}

#[test]
fn btc_run_btlog_has_the_structure_btcpp_filelogger2_writes() {
    btlog_batch("btlog", 0x0062_746c_6f67, false);
}

/// With scripts: the nodes' pre- and post-condition attributes, Script's
/// `code`, Switch's `variable` and `case_N`, RunOnce's `then_skip`,
/// Precondition's `if` and `else` are in the tree as BT.CPP writes it.
#[test]
fn the_btlog_of_a_scripted_tree_carries_the_scripting_ports_as_btcpp_does() {
    btlog_batch("btlog-scripting", 0x7362_746c_6f67, true);
}

/// 300 random trees, each run by btc (`.btlog` written by btc) and by
/// BT.CPP (FileLogger2): the same XML and the same transitions.
fn btlog_batch(name: &str, seed: u64, scripting: bool) {
    let Some(exe) = harness() else { return };
    let mut g = Gen {
        rng: fastrand::Rng::with_seed(seed),
        subtrees: Vec::new(),
        scripting,
    };
    let cases: Vec<Case> = (0..300)
        .map(|_| Case {
            xml: g.tree(),
            ticks: 12,
            tick_ms: 0,
        })
        .collect();
    let dir = btc_testkit::target_dir(&format!("btcpp/conformance/{name}"));
    let _ = std::fs::remove_dir_all(&dir);
    let cpp = run_btcpp_logged(&exe, &cases, name, Some(&dir));
    let mut records = 0;
    for (i, (case, cpp)) in cases.iter().zip(&cpp).enumerate() {
        assert!(cpp.is_ok(), "case {i}: {cpp:?}");
        let (_, mine) = run_btc_logged(case).unwrap();
        let theirs = std::fs::read(dir.join(format!("c{i}.btlog"))).unwrap();
        let (x_mine, r_mine) = read_btlog(&mine);
        let (x_theirs, r_theirs) = read_btlog(&theirs);
        assert_eq!(x_mine, x_theirs, "case {i}: the XML differs\n{}", case.xml);
        assert_eq!(
            r_mine, r_theirs,
            "case {i}: the transitions differ\n{}",
            case.xml
        );
        records += r_mine.len();
    }
    assert!(records > 10 * cases.len(), "{records} transitions compared");
}

#[test]
fn the_builtin_models_btc_writes_are_btcpp_4_10s() {
    let Some(exe) = harness() else { return };
    let out = Command::new(exe).arg("--builtins").output().unwrap();
    assert!(out.status.success());
    let theirs = String::from_utf8(out.stdout).unwrap();
    let mine = include_str!("../src/btcpp_builtins.xml");
    assert_eq!(
        parse_xml(mine),
        parse_xml(&theirs),
        "runtime/src/btcpp_builtins.xml is not what BT.CPP writes: regenerate it with `btc_conformance --builtins`"
    );
}
