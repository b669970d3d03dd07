//! `btc run`: compiles a plan (or loads a tree file) and executes it with
//! the runtime against the problem's simulated world, with injected faults.

use crate::stdout::outln;
use crate::{domain_lookup, files, paths, report, rules_cmd, Format};
use btc_agent::faults::{FaultsOnEngine, Scenario};
use btc_lang::db;
use btc_lang::path::FilePath;
use btc_lang::project::PlanSource;
use btc_pddl::diagnostic::{codes, has_errors, Diagnostic, Severity};
use btc_pddl::pipeline;
use btc_pddl::source::{FileId, Sources, Span};
use btc_pddl::state::World;
use btc_pddl::world::WorldModel;
use btc_runtime::btlog::BtlogRecorder;
use btc_runtime::observers::JsonlTrace;
use btc_runtime::{Controller, Engine, Kb, LoadError, Loaded, Options, Summary, TreeDoc};
use std::io::IsTerminal;
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::time::Duration;

/// `btc run`'s arguments.
#[derive(clap::Args)]
pub struct RunArgs {
    /// The rules file to compile the plan with.
    #[arg(required_unless_present = "tree", conflicts_with = "tree")]
    pub rules: Option<PathBuf>,
    /// A tree file to run instead: BT.CPP v4 XML or btc's JSON IR.
    #[arg(long)]
    pub tree: Option<PathBuf>,
    /// The plan to compile (with RULES); with `--replan`, the first plan
    /// (default: planned from the problem).
    #[arg(long)]
    pub plan: Option<PathBuf>,
    /// Close the loop: when the tree fails, plan again from the KB the
    /// fault left (and the goal it adjusted), compile and run again.
    #[arg(long, conflicts_with = "tree")]
    pub replan: bool,
    /// With `--replan`: plans made after failures, at most.
    #[arg(long, default_value_t = 5, requires = "replan")]
    pub max_replans: usize,
    /// The PDDL problem whose `:init` is the initial KB (default, with
    /// RULES: as `btc compile` finds it).
    #[arg(long)]
    pub problem: Option<PathBuf>,
    /// The PDDL domain (default: the rules file's, or `domain.pddl`
    /// beside the problem).
    #[arg(long)]
    pub domain: Option<PathBuf>,
    /// A fault scenario (TOML) to inject.
    #[arg(long)]
    pub faults: Option<PathBuf>,
    /// Write every status change here, as JSON Lines (atomically).
    #[arg(long)]
    pub trace: Option<PathBuf>,
    /// Write the run for Groot2 to replay, in BehaviorTree.CPP's
    /// FileLogger2 format (the name must end in `.btlog`).
    #[arg(long, conflicts_with = "replan", value_parser = btlog_path)]
    pub btlog: Option<PathBuf>,
    /// Ticks an action leaf stays RUNNING before it succeeds.
    #[arg(long, default_value_t = 1)]
    pub ticks_per_action: u32,
    /// Ticks per time unit of a timed plan: a step with duration d lasts
    /// at least d times this many ticks (0: steps take as long as their
    /// actions, durations are not simulated).
    #[arg(long, default_value_t = 0, conflicts_with = "replan")]
    pub ticks_per_time_unit: u32,
    /// Wall-clock milliseconds between ticks (also the simulated time
    /// per tick; 0: as fast as possible, 10 ms simulated).
    #[arg(long, default_value_t = 0)]
    pub tick_ms: u64,
    /// Give up (and halt the tree) after this many ticks.
    #[arg(long, default_value_t = 100_000)]
    pub max_ticks: u64,
    /// Send action leaves' commands through the queued controller thread.
    #[arg(long)]
    pub controller: bool,
    /// Run a plan that does not replay on its problem (with warnings).
    #[arg(long, conflicts_with = "tree")]
    pub allow_invalid_plan: bool,
    #[arg(long, value_enum, default_value_t)]
    pub format: Format,
}

/// `--btlog`'s value: Groot2 and BT.CPP's FileLogger2 open only `.btlog`.
fn btlog_path(s: &str) -> Result<PathBuf, String> {
    let p = PathBuf::from(s);
    if p.extension().is_some_and(|e| e == "btlog") {
        Ok(p)
    } else {
        Err("a Groot2 replay file's name ends in `.btlog` (Groot2 opens only those)".into())
    }
}

/// A runtime error as a diagnostic on the file it is about; the span covers
/// the word (an XML tag's name) at its offset.
fn diagnostic(e: &LoadError, file: FileId, sources: &Sources) -> Diagnostic {
    let text = sources.text(file);
    let at = e.offset.unwrap_or(0).min(text.len());
    let end = match e.offset {
        Some(_) => text[at..]
            .char_indices()
            .skip(1)
            .find(|(_, c)| c.is_whitespace() || matches!(c, '>' | '/' | '='))
            .map_or(text.len(), |(k, _)| at + k),
        None => at,
    };
    let mut d = Diagnostic::error(e.code, Span::new(file, at, end), e.message.clone());
    if let Some(h) = &e.hint {
        d = d.with_hint(h.clone());
    }
    d
}

/// Prints warnings about a loaded file (a scenario's X011); their JSON.
fn warnings(
    found: &[LoadError],
    file: FileId,
    sources: &Sources,
    format: Format,
) -> Vec<serde_json::Value> {
    let diags: Vec<Diagnostic> = found
        .iter()
        .map(|w| Diagnostic {
            severity: Severity::Warning,
            ..diagnostic(w, file, sources)
        })
        .collect();
    report::diagnostics(&diags, sources, format)
}

fn fail(diags: &[Diagnostic], sources: &Sources, format: Format) -> anyhow::Result<ExitCode> {
    let json = report::diagnostics(diags, sources, format);
    if format == Format::Json {
        outln!(
            "{}",
            serde_json::to_string_pretty(&serde_json::json!({ "ok": false, "diagnostics": json }))?
        )?;
    }
    Ok(ExitCode::from(1))
}

pub fn run(a: &RunArgs) -> anyhow::Result<ExitCode> {
    match (&a.rules, &a.tree) {
        (Some(rules), None) if a.replan => run_replan(a, rules),
        (Some(rules), None) => {
            let plan = a.plan.as_deref().ok_or_else(|| {
                anyhow::anyhow!(
                    "`btc run RULES` needs `--plan PLAN` (or `--replan` to plan from the problem, or run a tree file with `--tree`)"
                )
            })?;
            run_rules(a, rules, plan)
        }
        (None, Some(tree)) => run_tree(a, tree),
        _ => {
            anyhow::bail!("give either a rules file (with `--plan`) or `--tree TREE.xml|TREE.json`")
        }
    }
}

fn run_rules(a: &RunArgs, rules: &Path, plan: &Path) -> anyhow::Result<ExitCode> {
    let loaded = rules_cmd::load_job(
        rules,
        PlanSource::File(FilePath::new(plan)),
        a.problem.as_deref(),
        a.domain.as_deref(),
        a.allow_invalid_plan,
    )?;
    let problem = loaded.problem_shown();
    let rules_cmd::Job {
        db: database,
        loaded,
        diagnostics: mut diags,
    } = loaded;
    let job = loaded.job;
    let ir = if has_errors(&diags) {
        None
    } else {
        match db::compile(&database, job) {
            Ok(ir) => Some(ir),
            Err(errs) => {
                diags.extend(
                    errs.iter()
                        .filter(|e| !diags.contains(e))
                        .cloned()
                        .collect::<Vec<_>>(),
                );
                None
            }
        }
    };
    let mut sources = database.sources();
    let (Some(ir), Some(world)) = (ir, btc_lang::db::JobWorld::of(&database, job)) else {
        return fail(&diags, &sources, a.format);
    };
    if a.format == Format::Text {
        report::diagnostics(&diags, &sources, a.format);
    }
    let doc = TreeDoc::from_ir(ir);
    let anchor = db::file_id(&database, job.plan(&database));
    let world = world.world().map_err(anyhow::Error::msg)?;
    execute(
        a,
        &doc,
        Some(Kb::new(&world)),
        &mut sources,
        anchor,
        Some(&problem),
    )
}

/// A BT.CPP XML tree file and the files it `<include>`s, each read into
/// `sources` so that a diagnostic names the file it is about.
fn xml_with_includes(
    tree: &Path,
    file: FileId,
    sources: &mut Sources,
) -> Result<TreeDoc, btc_runtime::include::Located<FileId>> {
    use btc_runtime::include::{self, Opened};
    let first = Opened {
        file,
        text: sources.text(file).to_owned(),
    };
    let mut open = |p: &Path| -> Result<Opened<FileId>, String> {
        let text = files::read_text(p)?;
        let file = sources.add(p.display().to_string(), text.clone());
        Ok(Opened { file, text })
    };
    include::load(tree, first, &mut open)
}

fn run_tree(a: &RunArgs, tree: &Path) -> anyhow::Result<ExitCode> {
    let mut sources = Sources::new();
    let mut diags = Vec::new();
    let file = files::load(&mut sources, tree, &mut diags)?;
    if has_errors(&diags) {
        return fail(&diags, &sources, a.format);
    }
    let loaded = if sources.text(file).trim_start().starts_with('<') {
        match xml_with_includes(tree, file, &mut sources) {
            Ok(doc) => Loaded::Xml(doc),
            Err(l) => {
                let d = diagnostic(&l.error, l.file, &sources);
                return fail(&[d], &sources, a.format);
            }
        }
    } else {
        match btc_runtime::load_tree(sources.text(file)) {
            Ok(x) => x,
            Err(e) => return fail(&[diagnostic(&e, file, &sources)], &sources, a.format),
        }
    };
    // The world: a JSON IR carries it (unless `--problem` names another);
    // XML, and version-1 IR, run in the world of PDDL files.
    let (doc, named) = match loaded {
        Loaded::Ir(ir) if a.problem.is_none() => {
            let world = match World::new(ir.world.clone()) {
                Ok(w) => w,
                Err(m) => {
                    let e = LoadError::new(
                        codes::X_WORLD,
                        format!("the world this IR carries does not fit together: {m}"),
                    )
                    .at(0);
                    return fail(&[diagnostic(&e, file, &sources)], &sources, a.format);
                }
            };
            let doc = TreeDoc::from_ir(&ir);
            let shown = format!("{} (carried by the tree file)", ir.problem);
            return execute(
                a,
                &doc,
                Some(Kb::new(&world)),
                &mut sources,
                file,
                Some(&shown),
            );
        }
        Loaded::Ir(ir) => (Tree::Ir(ir), None),
        Loaded::IrV1(v1) => {
            let named = (v1.domain.clone(), v1.problem.clone());
            (Tree::V1(v1), Some(named))
        }
        Loaded::Xml(doc) => (Tree::Xml(doc), None),
    };
    let recorded = |p: &str| -> Option<PathBuf> {
        // Recorded paths are relative to the IR file; version 1 recorded
        // them relative to the working directory it was compiled in.
        [paths::beside(tree, p), PathBuf::from(p)]
            .into_iter()
            .find(|c| c.is_file())
    };
    let problem_path = a
        .problem
        .clone()
        .or_else(|| named.as_ref().and_then(|(_, p)| recorded(p)));
    let Some(problem_path) = problem_path else {
        return match (doc, &named) {
            (Tree::Xml(doc), _) => execute(a, &doc, None, &mut sources, file, None),
            (_, Some((_, p))) => {
                let e = LoadError::new(
                    codes::X_WORLD,
                    format!("this version-1 IR carries no world, and its problem `{p}` is not found beside it or here"),
                )
                .at(0)
                .hint("pass `--problem PROBLEM` (and `--domain DOMAIN`), or compile it again: version 2 carries its world");
                fail(&[diagnostic(&e, file, &sources)], &sources, a.format)
            }
            _ => unreachable!("a current IR without --problem ran above"),
        };
    };
    let pfile = files::load(&mut sources, &problem_path, &mut diags)?;
    let domain_path = a
        .domain
        .clone()
        .or_else(|| named.as_ref().and_then(|(d, _)| recorded(d)))
        .or_else(|| domain_lookup::for_problem(&problem_path, sources.text(pfile)))
        .ok_or_else(|| {
            anyhow::anyhow!(
                "no domain for `{}`: none beside it (`domain.pddl`, or a `.pddl` file defining its domain); pass `--domain DOMAIN`",
                problem_path.display()
            )
        })?;
    let dfile = files::load(&mut sources, &domain_path, &mut diags)?;
    let du = pipeline::domain_unit(&sources, dfile);
    let pu = pipeline::problem_unit(&sources, pfile, &du);
    diags.extend(du.diagnostics.iter().cloned());
    diags.extend(pu.diagnostics.iter().cloned());
    let (Some(domain), Some(problem)) = (&du.domain, &pu.problem) else {
        return fail(&diags, &sources, a.format);
    };
    if has_errors(&diags) {
        return fail(&diags, &sources, a.format);
    }
    let model = WorldModel::from_checked(domain, &du.index, problem, &pu.index);
    let world = World::new(model.clone()).map_err(anyhow::Error::msg)?;
    let doc = match doc {
        Tree::Xml(doc) => doc.with_actions(domain),
        Tree::Ir(ir) => TreeDoc::from_ir(&ir),
        Tree::V1(v1) => match v1.upgrade(model) {
            Ok(ir) => TreeDoc::from_ir(&ir),
            Err(m) => {
                let e = LoadError::new(codes::X_KB, m).at(0);
                return fail(&[diagnostic(&e, file, &sources)], &sources, a.format);
            }
        },
    };
    let how = if a.problem.is_some() {
        "given"
    } else {
        "named by the tree file"
    };
    let shown = format!("{} ({how})", problem_path.display());
    execute(
        a,
        &doc,
        Some(Kb::new(&world)),
        &mut sources,
        file,
        Some(&shown),
    )
}

/// A loaded tree still waiting for its world.
#[allow(clippy::large_enum_variant)] // one per run
enum Tree {
    Xml(TreeDoc),
    Ir(btc_ir::TreeIr),
    V1(btc_ir::json::V1),
}

/// Runs a tree; `problem` is the problem as the summary names it.
fn execute(
    a: &RunArgs,
    doc: &TreeDoc,
    kb: Option<Kb<'_>>,
    sources: &mut Sources,
    tree_file: FileId,
    problem: Option<&str>,
) -> anyhow::Result<ExitCode> {
    let opts = Options {
        ticks_per_action: a.ticks_per_action,
        ms_per_tick: if a.tick_ms > 0 { a.tick_ms } else { 10 },
    };
    let ms_per_tick = opts.ms_per_tick;
    let started = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map_or(0, |d| i64::try_from(d.as_micros()).unwrap_or(i64::MAX));
    let mut engine = match Engine::build(doc, kb, opts) {
        Ok(e) => e,
        Err(e) => return fail(&[diagnostic(&e, tree_file, sources)], sources, a.format),
    };
    if a.ticks_per_time_unit > 0 {
        engine.simulate_durations(a.ticks_per_time_unit);
    }
    // Warnings about the scenario (X011), in the JSON summary's `diagnostics`.
    let mut warned = Vec::new();
    if let Some(path) = &a.faults {
        let mut diags = Vec::new();
        let f = files::load(sources, path, &mut diags)?;
        if has_errors(&diags) {
            return fail(&diags, sources, a.format);
        }
        let added = Scenario::parse(sources.text(f)).and_then(|s| {
            engine.add_faults(&s)?;
            Ok(s.triggers_naming_nothing(&engine.action_ids()))
        });
        match added {
            Err(e) => return fail(&[diagnostic(&e, f, sources)], sources, a.format),
            Ok(never) => warned = warnings(&never, f, sources, a.format),
        }
    }
    if a.controller {
        engine.attach_controller(Controller::start(16, Duration::ZERO));
    }
    let bar = (a.format == Format::Text && std::io::stderr().is_terminal()).then(|| {
        let pb = indicatif::ProgressBar::new(engine.steps_total() as u64);
        pb.set_style(
            indicatif::ProgressStyle::with_template("{spinner} {pos}/{len} steps  {msg}")
                .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar()),
        );
        pb
    });
    let pace = Duration::from_millis(a.tick_ms);
    // The trace goes out tick by tick: bounded memory, and a killed run
    // leaves every line so far (SIGINT/SIGTERM flush it). The Groot2
    // replay is an observer of its own, so each file gets every event.
    let trace = a.trace.as_deref().map(files::stream).transpose()?;
    if trace.is_some() {
        engine.observe(JsonlTrace::default());
    }
    if a.btlog.is_some() {
        engine.observe(BtlogRecorder::new(ms_per_tick));
    }
    let stream = |e: &mut Engine<'_>, t: &btc_files::Stream| {
        if let Some(lines) = e.observer_mut::<JsonlTrace>() {
            let mut w: &btc_files::Stream = t;
            let _ = lines.drain(&mut w).and_then(|()| t.flush());
        }
    };
    let status = engine.run(a.max_ticks, |e| {
        if let Some(t) = &trace {
            stream(e, t);
        }
        if let Some(pb) = &bar {
            pb.set_position(e.steps_done() as u64);
            pb.set_message(format!("tick {}", e.tick));
        }
        if !pace.is_zero() {
            std::thread::sleep(pace);
        }
    });
    if let Some(pb) = bar {
        pb.finish_and_clear();
    }
    let commands = engine.take_controller().map(Controller::shutdown);
    if let (Some(t), Some(path)) = (trace, &a.trace) {
        stream(&mut engine, &t);
        t.finish()
            .map_err(|e| anyhow::anyhow!("cannot write `{}`: {e}", path.display()))?;
    }
    if let (Some(path), Some(replay)) = (&a.btlog, engine.take_observer::<BtlogRecorder>()) {
        match replay.finish(doc, &engine, status, started) {
            Ok(bytes) => files::write_bytes_atomically(path, &bytes)?,
            Err(e) => return fail(&[diagnostic(&e, tree_file, sources)], sources, a.format),
        }
    }
    let summary = engine.summary(status);
    match a.format {
        Format::Json => {
            let mut v = serde_json::to_value(&summary)?;
            if let Some(o) = v.as_object_mut() {
                if let Some(c) = &commands {
                    o.insert("commands".into(), serde_json::to_value(c)?);
                }
                o.insert("problem".into(), problem.into());
                if !warned.is_empty() {
                    o.insert("diagnostics".into(), warned.into());
                }
            }
            if let (Some(o), Some(kb)) = (v.as_object_mut(), &engine.kb) {
                o.insert("kb".into(), serde_json::to_value(kb.snapshot())?);
            }
            outln!("{}", serde_json::to_string_pretty(&v)?)?;
        }
        Format::Text => print_summary(&summary, problem, commands.as_ref().map(Vec::len))?,
    }
    Ok(if summary.success() {
        ExitCode::SUCCESS
    } else {
        ExitCode::from(1)
    })
}

fn print_summary(
    s: &Summary,
    problem: Option<&str>,
    commands: Option<usize>,
) -> anyhow::Result<()> {
    let yes = |b: bool| if b { "yes" } else { "no" };
    outln!(
        "{} after {}; {} of {} plan steps done; goal reached: {}",
        s.status.name(),
        report::plural(s.ticks as usize, "tick"),
        s.steps_done,
        s.steps_total,
        match s.goal_reached {
            Some(g) => yes(g),
            None => "no goal (no problem given)",
        }
    )?;
    outln!("  problem: {}", problem.unwrap_or("none"))?;
    if let Some(why) = &s.goal_failure {
        outln!("  goal: {why}")?;
    }
    if let Some(n) = commands {
        outln!("controller: {} executed", report::plural(n, "command"))?;
    }
    for f in &s.faults {
        let met = match f.met_at {
            Some(t) => format!("met at tick {t}"),
            None => "not met".to_owned(),
        };
        outln!("fault {} ({}): {met}; {}", f.fault, f.kind, f.ended)?;
    }
    for r in &s.records {
        outln!("{}", record_line(r))?;
    }
    Ok(())
}

/// The name of the plan the closed loop writes (it is never written to
/// disk; diagnostics about a planned plan name it).
const PLANNED: &str = "(planned).sas_plan";

/// `btc run RULES --replan`: the closed loop of `btc_agent::replan`.
fn run_replan(a: &RunArgs, rules: &Path) -> anyhow::Result<ExitCode> {
    if a.controller {
        anyhow::bail!("`--replan` runs the simulated world only; leave out `--controller`");
    }
    let input = match &a.plan {
        Some(p) => PlanSource::File(FilePath::new(p)),
        None => PlanSource::Planned(FilePath::new(PLANNED)),
    };
    let loaded = rules_cmd::load_job(
        rules,
        input,
        a.problem.as_deref(),
        a.domain.as_deref(),
        a.allow_invalid_plan,
    )?;
    let problem = loaded.problem_shown();
    let rules_cmd::Job {
        db: mut database,
        loaded,
        diagnostics: mut diags,
    } = loaded;
    let job = loaded.job;
    if has_errors(&diags) || btc_lang::db::JobWorld::of(&database, job).is_none() {
        return fail(&diags, &database.sources(), a.format);
    }
    // The scenario: read and parsed before the loop (its facts are checked
    // against the problem when the first tree is built).
    let mut scen_sources = Sources::new();
    let scenario = match &a.faults {
        Some(path) => {
            let mut d = Vec::new();
            let f = files::load(&mut scen_sources, path, &mut d)?;
            if has_errors(&d) {
                return fail(&d, &scen_sources, a.format);
            }
            match Scenario::parse(scen_sources.text(f)) {
                Ok(s) => {
                    // The trees of the loop call the actions the rules declare.
                    let decls = db::declarations(&database, job.rules(&database));
                    let actions: Vec<&str> = decls
                        .nodes
                        .values()
                        .filter(|n| n.kind == btc_lang::rules::ast::NodeKind::Action)
                        .map(|n| n.name.text.as_str())
                        .collect();
                    let never = s.triggers_naming_nothing(&actions);
                    warnings(&never, f, &scen_sources, a.format);
                    Some((s, f))
                }
                Err(e) => {
                    return fail(&[diagnostic(&e, f, &scen_sources)], &scen_sources, a.format)
                }
            }
        }
        None => None,
    };
    let opts = btc_agent::LoopOptions {
        engine: Options {
            ticks_per_action: a.ticks_per_action,
            ms_per_tick: if a.tick_ms > 0 { a.tick_ms } else { 10 },
        },
        trace: a.trace.is_some(),
        planner: btc_planner::Options::default(),
        max_replans: a.max_replans,
        max_ticks: a.max_ticks,
    };
    let trace = a.trace.as_deref().map(files::stream).transpose()?;
    let mut sink: Box<dyn std::io::Write> = match &trace {
        Some(t) => Box::new(t),
        None => Box::new(std::io::sink()),
    };
    let result = btc_agent::run_loop_traced(
        &mut database,
        job,
        a.plan.is_some(),
        scenario.as_ref().map(|(s, _)| s),
        &opts,
        &mut sink,
    );
    drop(sink);
    if let (Some(t), Some(path)) = (trace, &a.trace) {
        t.finish()
            .map_err(|e| anyhow::anyhow!("cannot write `{}`: {e}", path.display()))?;
    }
    let sources = database.sources();
    let summary = match result {
        Ok(s) => s,
        Err(btc_agent::LoopError::Compile(ds)) => {
            diags.extend(ds);
            return fail(&diags, &sources, a.format);
        }
        Err(btc_agent::LoopError::Tree(e)) => {
            let anchor = db::file_id(&database, job.plan(&database));
            return fail(&[diagnostic(&e, anchor, &sources)], &sources, a.format);
        }
        Err(btc_agent::LoopError::Scenario(e)) => {
            let f = scenario.map_or(0, |(_, f)| f);
            return fail(&[diagnostic(&e, f, &scen_sources)], &scen_sources, a.format);
        }
    };
    match a.format {
        Format::Json => {
            let mut v = serde_json::to_value(&summary)?;
            let json = report::diagnostics(&summary.diagnostics, &sources, a.format);
            if let Some(o) = v.as_object_mut() {
                o.insert("ok".into(), summary.success().into());
                o.insert("problem".into(), problem.into());
                o.insert("diagnostics".into(), json.into());
            }
            outln!("{}", serde_json::to_string_pretty(&v)?)?;
        }
        Format::Text => {
            report::diagnostics(&diags, &sources, a.format);
            print_loop(&summary, &problem)?;
            report::diagnostics(&summary.diagnostics, &sources, a.format);
        }
    }
    Ok(if summary.success() {
        ExitCode::SUCCESS
    } else {
        ExitCode::from(1)
    })
}

/// The loop's text summary (timings are in `--format json` only, so the
/// text is the same from run to run).
fn print_loop(s: &btc_agent::LoopSummary, problem: &str) -> anyhow::Result<()> {
    for at in &s.attempts {
        let how = if at.source == "given" {
            "the given plan".to_owned()
        } else {
            format!("planned, {} expanded", at.expanded)
        };
        outln!(
            "plan {} ({}, {how}) for {}:",
            at.attempt,
            report::plural(at.plan.len(), "step"),
            at.goal
        )?;
        for (i, step) in at.plan.iter().enumerate() {
            outln!("  {}. {step}", i + 1)?;
        }
        outln!(
            "  {} at tick {} (ticks {}-{}); {} of {} plan steps done",
            if at.preempted {
                "PREEMPTED"
            } else {
                at.status.name()
            },
            at.end_tick,
            at.start_tick + 1,
            at.end_tick,
            at.steps_done,
            at.steps_total
        )?;
        for r in &at.records {
            outln!("  {}", record_line(r))?;
        }
        if at.status == btc_runtime::Status::Success && !at.preempted && at.goal != s.goal {
            outln!("  the priority order is done; planning for the whole goal")?;
        }
        if at.waited_ticks > 0 {
            outln!(
                "  waited {} for the faults in effect to end",
                report::plural(at.waited_ticks as usize, "tick")
            )?;
        }
        if let Some((k, rp)) = s
            .replans
            .iter()
            .enumerate()
            .find(|(_, r)| r.after_attempt == at.attempt)
        {
            let from = match (&rp.from_step, &rp.action) {
                (Some(_), Some(a)) => format!(" from {a}"),
                _ => String::new(),
            };
            outln!("replan {} at tick {}{from}: {}", k + 1, rp.tick, rp.why)?;
            for adj in &rp.adjustments {
                outln!("  goal: {adj}")?;
            }
        }
    }
    for f in &s.faults {
        let met = match f.met_at {
            Some(t) => format!("met at tick {t}"),
            None => "not met".to_owned(),
        };
        outln!("fault {} ({}): {met}; {}", f.fault, f.kind, f.ended)?;
    }
    for u in &s.unreachable {
        let by = if u.faults.is_empty() {
            String::new()
        } else {
            format!(" (fault: {})", u.faults.join(", "))
        };
        outln!("unreachable: {}{by}", u.literal)?;
    }
    outln!(
        "goal {}: {} after {}, {}, {}",
        s.goal,
        if s.goal_reached {
            "reached"
        } else {
            "not reached"
        },
        report::plural(s.ticks as usize, "tick"),
        report::plural(s.attempts.len(), "plan"),
        report::plural(s.replans.len(), "replan"),
    )?;
    outln!("  problem: {problem}")?;
    if let Some(why) = &s.goal_failure {
        outln!("  goal: {why}")?;
    }
    if let Some(why) = &s.stopped {
        outln!("stopped: {why}")?;
    }
    Ok(())
}

/// One fault record as the summaries print it.
fn record_line(r: &btc_runtime::FaultRecord) -> String {
    let step = r
        .action
        .as_deref()
        .map(|a| format!(" in {a}"))
        .unwrap_or_default();
    let faults = if r.faults.is_empty() {
        String::new()
    } else {
        format!(" [fault: {}]", r.faults.join(", "))
    };
    format!(
        "record: tick {}: `{}` ({}){step} failed: {}{faults}",
        r.tick, r.node_name, r.node_id, r.reason
    )
}
