//! `btc test RULES`: snapshot tests of a team's own trees and runs.
//!
//! A case is a plan kept beside the rules file (or in its `plans/`
//! folder), paired with its problem as `btc compile` pairs it. Each case is
//! compiled for each target and run; each output is compared with its
//! snapshot in `snapshots/` beside the rules file, one insta-format `.snap`
//! file per case and target. A change is shown as a unified diff and its
//! new version written beside the old one as `.snap.new`; `--accept` takes
//! the new versions, `--check` writes nothing. docs/testing.md is the
//! user's page.

use crate::stdout::{out, outln};
use crate::{report, rules_cmd, Format};
use btc_agent::faults::FaultsOnEngine;
use btc_emit as emit;
use btc_lang::path::FilePath;
use btc_lang::project::PlanSource;
use btc_pddl::state::World;
use btc_runtime::observers::JsonlTrace;
use btc_runtime::{Engine, Kb, Options, TreeDoc};
use std::path::{Path, PathBuf};
use std::process::ExitCode;

pub struct TestArgs {
    pub rules: PathBuf,
    pub targets: Vec<emit::Format>,
    pub accept: bool,
    pub check: bool,
}

/// What one snapshot is of.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Target {
    Tree(emit::Format),
    Run,
}

impl Target {
    fn name(self) -> &'static str {
        match self {
            Target::Tree(f) => f.name(),
            Target::Run => "run",
        }
    }
}

/// How a snapshot compared.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Outcome {
    Same,
    New,
    Changed,
}

/// The folder where a rules file keeps its snapshots.
const SNAPSHOTS: &str = "snapshots";
/// The folder beside a rules file for cases besides the plans next to it.
const PLANS: &str = "plans";

/// Whether a file name is a plan's: `*.plan`, `*.tplan`, `plan.*`,
/// `sas_plan*`.
/// What a case's fault scenario is named after its plan's stem.
const FAULTS: &str = ".faults.toml";

fn is_plan(name: &str) -> bool {
    // A case's fault scenario (`plan.faults.toml`) is not a case.
    if name.ends_with(FAULTS) {
        return false;
    }
    name.ends_with(".plan")
        || name.ends_with(".tplan")
        || name.starts_with("plan.")
        || name.starts_with("sas_plan")
}

/// The cases of a rules file: plan paths relative to its folder, sorted.
fn cases(dir: &Path) -> Vec<String> {
    let mut out = Vec::new();
    for (sub, prefix) in [(dir.to_path_buf(), ""), (dir.join(PLANS), "plans/")] {
        for p in crate::files::list(&sub) {
            let Some(name) = p.file_name().and_then(|n| n.to_str()) else {
                continue;
            };
            if p.is_file() && is_plan(name) {
                out.push(format!("{prefix}{name}"));
            }
        }
    }
    out.sort();
    out
}

/// `rules__plan.txt__btcpp.snap` for the case `plan.txt` of `rules.btrules`.
fn snapshot_name(rules_stem: &str, case: &str, target: Target) -> String {
    format!(
        "{rules_stem}__{}__{}.snap",
        case.replace('/', "-"),
        target.name()
    )
}

/// A snapshot file: insta's header (what it is of), then the content.
fn snapshot_text(rules_name: &str, case: &str, target: Target, content: &str) -> String {
    format!(
        "---\nsource: {rules_name}\ndescription: \"btc test: case {case}, target {}\"\ninput_file: {case}\n---\n{}\n",
        target.name(),
        content.trim_end_matches('\n')
    )
}

/// The content of a snapshot file (after its header), as insta reads it.
fn snapshot_content(text: &str) -> Option<&str> {
    let rest = text.strip_prefix("---\n")?;
    let end = rest.find("\n---\n")?;
    Some(rest[end + 5..].trim_end_matches('\n'))
}

/// The run of a compiled tree in its problem's world, as text: the order
/// in which steps start and end, faults, the final status and whether the
/// goal holds. Ticks are left out: a snapshot of the order changes when
/// the behaviour does, not when a node is added that takes no tick.
/// The fault scenario of a case: `STEM.faults.toml` beside its plan.
fn scenario_of(plan: &Path) -> anyhow::Result<Option<(PathBuf, btc_agent::faults::Scenario)>> {
    let path = plan.with_extension(&FAULTS[1..]);
    if !path.is_file() {
        return Ok(None);
    }
    let text =
        crate::files::read_text(&path).map_err(|e| anyhow::anyhow!("{}: {e}", path.display()))?;
    let scenario = btc_agent::faults::Scenario::parse(&text)
        .map_err(|e| anyhow::anyhow!("{}: {e}", path.display()))?;
    Ok(Some((path, scenario)))
}

fn run_text(
    ir: &btc_ir::TreeIr,
    faults: Option<&(PathBuf, btc_agent::faults::Scenario)>,
) -> anyhow::Result<String> {
    let world = World::new(ir.world.clone()).map_err(anyhow::Error::msg)?;
    let doc = TreeDoc::from_ir(ir);
    let mut engine = Engine::build(&doc, Some(Kb::new(&world)), Options::default())
        .map_err(|e| anyhow::anyhow!("the tree does not load in the runtime: {}", e.message))?;
    if let Some((path, scenario)) = faults {
        engine
            .add_faults(scenario)
            .map_err(|e| anyhow::anyhow!("{}: {e}", path.display()))?;
    }
    engine.observe(JsonlTrace::default());
    let status = engine.run(100_000, |_| {});
    // The trace's step, fault and record events, in their order.
    let lines = engine
        .take_observer::<JsonlTrace>()
        .map(JsonlTrace::into_text)
        .unwrap_or_default();
    let lines = lines.as_bytes();
    let mut out = String::new();
    for line in lines.split(|b| *b == b'\n').filter(|l| !l.is_empty()) {
        let mut v: serde_json::Value = serde_json::from_slice(line)?;
        let field = |v: &serde_json::Value, k: &str| v[k].as_str().unwrap_or("?").to_owned();
        let text = match v["event"].as_str() {
            Some("step_started") => format!("start {}", field(&v, "action")),
            Some("step_finished") => format!("end   {}", field(&v, "action")),
            Some(e @ ("fault_triggered" | "fault_ended")) => {
                format!(
                    "{} {} ({})",
                    e.replace('_', " "),
                    field(&v, "fault"),
                    field(&v, "kind")
                )
            }
            Some("fault_record") => {
                if let Some(o) = v.as_object_mut() {
                    o.remove("event");
                    o.remove("tick");
                }
                format!("record {v}")
            }
            _ => continue,
        };
        out.push_str(&text);
        out.push('\n');
    }
    let s = engine.summary(status);
    out.push_str(&format!(
        "status: {}; {} of {} steps done\ngoal: {}\n",
        s.status.name(),
        s.steps_done,
        s.steps_total,
        match (s.goal_reached, &s.goal_failure) {
            (Some(true), _) => "reached".to_owned(),
            (Some(false), Some(why)) => format!("not reached: {why}"),
            (Some(false), None) => "not reached".to_owned(),
            (None, _) => "no goal".to_owned(),
        }
    ));
    Ok(out)
}

/// A unified diff of a snapshot's old and new content.
fn diff(old: &str, new: &str, name: &str) -> String {
    similar::TextDiff::from_lines(old, new)
        .unified_diff()
        .context_radius(3)
        .header(&format!("{name} (stored)"), &format!("{name} (new)"))
        .to_string()
}

/// Compares one output with its snapshot and writes what the mode says.
fn compare(a: &TestArgs, path: &Path, text: &str, content: &str) -> anyhow::Result<Outcome> {
    let pending = PathBuf::from(format!("{}.new", path.display()));
    let stored = std::fs::read_to_string(path).ok();
    let old = stored.as_deref().and_then(snapshot_content);
    let outcome = match old {
        Some(old) if old == content.trim_end_matches('\n') => Outcome::Same,
        Some(_) => Outcome::Changed,
        None => Outcome::New,
    };
    if a.check {
        return Ok(outcome);
    }
    let write_snapshot = outcome == Outcome::New || (outcome == Outcome::Changed && a.accept);
    if write_snapshot {
        crate::files::write_atomically(path, text)?;
    }
    if outcome == Outcome::Changed && !a.accept {
        crate::files::write_atomically(&pending, text)?;
    } else if pending.exists() {
        std::fs::remove_file(&pending)
            .map_err(|e| anyhow::anyhow!("cannot remove `{}`: {e}", pending.display()))?;
    }
    Ok(outcome)
}

pub fn run(a: &TestArgs) -> anyhow::Result<ExitCode> {
    let dir = match a.rules.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    let rules_name = a
        .rules
        .file_name()
        .and_then(|n| n.to_str())
        .ok_or_else(|| anyhow::anyhow!("`{}` is not a rules file", a.rules.display()))?;
    let rules_stem = rules_name.strip_suffix(".btrules").unwrap_or(rules_name);
    let cases = cases(dir);
    if cases.is_empty() {
        anyhow::bail!(
            "no cases for `{}`: keep plans (`*.plan`, `plan.*`...) beside it or in `{}`",
            a.rules.display(),
            dir.join(PLANS).display()
        );
    }
    let snapshots = dir.join(SNAPSHOTS);
    if !a.check {
        std::fs::create_dir_all(&snapshots)
            .map_err(|e| anyhow::anyhow!("cannot create `{}`: {e}", snapshots.display()))?;
    }
    let mut targets: Vec<Target> = a.targets.iter().map(|f| Target::Tree(*f)).collect();
    targets.push(Target::Run);
    let (mut same, mut new, mut changed, mut failed) = (0, 0, 0, 0);
    for case in &cases {
        let mut job = rules_cmd::load_job(
            &a.rules,
            PlanSource::File(FilePath::new(dir.join(case))),
            None,
            None,
            false,
        )?;
        let pytrees = a.targets.contains(&emit::Format::Pytrees);
        let Some(mut ir) = rules_cmd::tree_of(&mut job, pytrees) else {
            let sources = job.db.sources_for(&job.diagnostics);
            report::diagnostics(&job.diagnostics, &sources, Format::Text);
            outln!("{case}: does not compile")?;
            failed += 1;
            continue;
        };
        drop(job);
        let faults = scenario_of(&dir.join(case))?;
        rules_cmd::record_paths_from(std::sync::Arc::make_mut(&mut ir), dir);
        for &target in &targets {
            let content = match target {
                Target::Tree(f) => emit::emit(&ir, f, &emit::Options::default()),
                Target::Run => run_text(&ir, faults.as_ref())?,
            };
            let name = snapshot_name(rules_stem, case, target);
            let path = snapshots.join(&name);
            let text = snapshot_text(rules_name, case, target, &content);
            match compare(a, &path, &text, &content)? {
                Outcome::Same => same += 1,
                Outcome::New => {
                    new += 1;
                    let verb = if a.check { "missing" } else { "new, written" };
                    outln!("{case} {}: {verb} ({})", target.name(), path.display())?;
                }
                Outcome::Changed => {
                    changed += 1;
                    let stored = std::fs::read_to_string(&path).unwrap_or_default();
                    let old = snapshot_content(&stored).unwrap_or_default();
                    let verb = match (a.accept, a.check) {
                        (_, true) => "changed",
                        (true, false) => "changed, accepted",
                        (false, false) => "changed (new version in .snap.new)",
                    };
                    outln!("{case} {}: {verb}", target.name())?;
                    if !a.accept {
                        out!(
                            "{}",
                            diff(
                                &format!("{old}\n"),
                                &format!("{}\n", content.trim_end_matches('\n')),
                                &name
                            )
                        )?;
                    }
                }
            }
        }
    }
    outln!(
        "btc test {}: {} cases; {} unchanged, {} new, {} changed, {} not compiled",
        a.rules.display(),
        cases.len(),
        same,
        new,
        changed,
        failed
    )?;
    let failing = failed > 0 || (changed > 0 && !a.accept) || (a.check && (new > 0 || changed > 0));
    Ok(if failing {
        ExitCode::from(1)
    } else {
        ExitCode::SUCCESS
    })
}
