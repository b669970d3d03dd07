//! `btc check` and `btc compile`: rules files, through the incremental
//! database and the project loader (the same one the language server uses).

use crate::stdout::{self, outln};
use crate::{files, report, Format};
use btc_emit as emit;
use btc_lang::db::{self, Database, SourceFile};
use btc_lang::path::FilePath;
use btc_lang::project::{self, JobPaths, LoadedJob, PlanSource};
use btc_lang::targets;
use btc_pddl::diagnostic::{has_errors, Diagnostic, Severity};
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::sync::Arc;

/// Loads a rules file and everything it names from disk.
pub fn load_rules(db: &mut Database, path: &Path) -> anyhow::Result<SourceFile> {
    project::load_rules(db, &files::Disk, &FilePath::new(path)).map_err(|why| {
        files::unreadable_job_file(project::job::Unreadable {
            path: FilePath::new(path),
            why,
        })
    })
}

/// `domain.pddl` and `problem.pddl (named by the rules file)` for the
/// summaries; `None` when there is none.
fn shown(db: &Database, f: Option<SourceFile>, how: Option<project::ProblemChoice>) -> String {
    match (f, how) {
        (Some(f), Some(how)) => format!("{} ({how})", f.path(db)),
        (Some(f), None) => f.path(db).to_string(),
        (None, _) => "none".to_owned(),
    }
}

/// `btc check RULES`: the rules file, its imports, the domain and the
/// problem it names, with every file's diagnostics.
pub fn check(path: &Path, format: Format) -> anyhow::Result<ExitCode> {
    let mut database = Database::new();
    let rules = load_rules(&mut database, path)?;
    let mut diags = project::flatten(project::project_report(&database, rules));
    project::suggest_paths(&database, &files::Disk, rules, &mut diags);
    let domain = db::domain_file(&database, rules);
    let problem = db::problem_file(&database, rules);
    let sources = database.sources();
    let json = report::diagnostics(&diags, &sources, format);
    let (e, w) = report::count(&diags);
    match format {
        Format::Json => outln!(
            "{}",
            serde_json::to_string_pretty(&serde_json::json!({
                "ok": e == 0,
                "domain": domain.map(|f| f.path(&database).to_string()),
                "problem": problem.map(|f| f.path(&database).to_string()),
                "diagnostics": json
            }))?
        )?,
        Format::Text => {
            let items = db::parsed_rules(&database, rules).items.len();
            outln!(
                "{}: {}; {}, {}",
                path.display(),
                report::plural(items, "item"),
                report::plural(e, "error"),
                report::plural(w, "warning")
            )?;
            outln!("  domain: {}", shown(&database, domain, None))?;
            outln!("  problem: {}", shown(&database, problem, None))?;
        }
    }
    Ok(if e > 0 {
        ExitCode::from(1)
    } else {
        ExitCode::SUCCESS
    })
}

/// What `btc compile` writes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Output {
    /// The compiled tree in a format.
    Tree(emit::Format),
    /// The problem's world as a `.kb` file (for the C++ knowledge base).
    Kb,
}

pub struct CompileArgs {
    pub rules: PathBuf,
    pub plan: PathBuf,
    pub problem: Option<PathBuf>,
    pub domain: Option<PathBuf>,
    pub emit: Output,
    pub output: Option<PathBuf>,
    /// Write nothing; say whether the `-o` file would change.
    pub check: bool,
    pub options: emit::Options,
    pub allow_invalid_plan: bool,
    pub format: Format,
}

/// A compile job loaded from disk, with what it reports before lowering.
pub struct Job {
    pub db: Database,
    pub loaded: LoadedJob,
    pub diagnostics: Vec<Diagnostic>,
}

impl Job {
    pub fn job(&self) -> db::CompileJob {
        self.loaded.job
    }

    /// `problem.pddl (paired with the plan by name)`, for the summaries.
    pub fn problem_shown(&self) -> String {
        let (f, how) = self.loaded.problem.unzip();
        shown(&self.db, f, how)
    }

    pub fn problem_path(&self) -> Option<String> {
        self.loaded
            .problem
            .map(|(f, _)| f.path(&self.db).to_string())
    }
}

/// Loads a rules file, a plan, and the domain and problem (see
/// `btc_lang::project::job` for which problem), and collects what the job
/// reports: every file's diagnostics, then the plan replayed on the problem
/// (errors that refuse the job, or warnings with `allow_invalid_plan`).
pub fn load_job(
    rules: &Path,
    plan: PlanSource,
    problem: Option<&Path>,
    domain: Option<&Path>,
    allow_invalid_plan: bool,
) -> anyhow::Result<Job> {
    // Replaying a long plan (a timed one especially) takes as long as
    // lowering it: on a second core the tree is lowered meanwhile,
    // memoized for `tree_of` (and unused if the job is refused).
    let lower = |db: &Database, job| {
        let _ = db::compile(db, job);
    };
    load_job_then(
        rules,
        plan,
        problem,
        domain,
        allow_invalid_plan,
        lower,
        || {},
    )
    .map(|(job, _)| job)
}

/// [`load_job`], with `meanwhile` run on a second core, on a clone of the
/// database, while the plan is replayed, and `after_replay` run on this
/// one once the replay is over, before waiting for `meanwhile`; what
/// `meanwhile` returns comes back beside the job (`None` for a plan still
/// to be made: nothing to replay, and neither runs).
fn load_job_then<T: Send>(
    rules: &Path,
    plan: PlanSource,
    problem: Option<&Path>,
    domain: Option<&Path>,
    allow_invalid_plan: bool,
    meanwhile: impl FnOnce(&Database, db::CompileJob) -> T + Send,
    after_replay: impl FnOnce(),
) -> anyhow::Result<(Job, Option<T>)> {
    let mut database = Database::new();
    let planned = matches!(plan, PlanSource::Planned(_));
    let paths = JobPaths {
        rules: FilePath::new(rules),
        plan,
        problem: problem.map(FilePath::new),
        domain: domain.map(FilePath::new),
    };
    let loaded = project::load_job_files(&mut database, &files::Disk, &paths)
        .map_err(files::unreadable_job_file)?;
    let job = loaded.job;
    let plan_file = db::file_id(&database, job.plan(&database));
    let beside = (!planned).then(|| database.clone());
    let (mut diagnostics, made) = std::thread::scope(|s| {
        let made = beside.map(|db| s.spawn(move || meanwhile(&db, job)));
        let diagnostics = diagnostics_of(&database, job, planned, plan_file, allow_invalid_plan);
        if made.is_some() {
            after_replay();
        }
        // A panic there is met again, and reported, on the way without it.
        (diagnostics, made.and_then(|m| m.join().ok()))
    });
    if project::load_neighbours_if_wanted(&mut database, &files::Disk, &loaded, &paths) {
        // The replay's advice names the problems beside the plan it fits.
        diagnostics = diagnostics_of(&database, job, planned, plan_file, allow_invalid_plan);
    }
    let job = Job {
        db: database,
        loaded,
        diagnostics,
    };
    Ok((job, made))
}

/// What checking the job and replaying its plan say.
fn diagnostics_of(
    database: &Database,
    job: db::CompileJob,
    planned: bool,
    plan_file: btc_pddl::source::FileId,
    allow_invalid_plan: bool,
) -> Vec<Diagnostic> {
    let mut diagnostics: Vec<Diagnostic> = db::job_diagnostics(database, job)
        .iter()
        // A plan still to be made has no steps yet: nothing to say about it.
        .filter(|d| !(planned && d.span.file == plan_file && d.code.starts_with('L')))
        .cloned()
        .collect();
    project::suggest_paths(
        database,
        &files::Disk,
        job.rules(database),
        &mut diagnostics,
    );
    if !planned {
        for d in project::fit::plan_validation(database, job) {
            let mut d = d.clone();
            if allow_invalid_plan {
                d.severity = Severity::Warning;
            }
            diagnostics.push(d);
        }
    }
    diagnostics
}

/// The job's tree, or `None` with what refuses it added to the job's
/// diagnostics; with `pytrees`, what a py_trees module cannot express is
/// refused too, never approximated.
pub fn tree_of(job: &mut Job, pytrees: bool) -> Option<Arc<btc_ir::TreeIr>> {
    let mut result = if has_errors(&job.diagnostics) {
        None
    } else {
        db::compile(&job.db, job.job()).as_ref().ok().cloned()
    };
    if let (Some(ir), true) = (&result, pytrees) {
        let refused = targets::refusals(&job.db, job.job(), ir, targets::Target::Pytrees);
        if !refused.is_empty() {
            job.diagnostics.extend(refused);
            result = None;
        }
    }
    if result.is_none() {
        if let Err(errs) = db::compile(&job.db, job.job()) {
            for e in errs {
                if !job.diagnostics.contains(e) {
                    job.diagnostics.push(e.clone());
                }
            }
        }
    }
    result
}

/// Records the files a tree was compiled from relative to `base`, the
/// folder of its output, so that no output depends on where btc ran or
/// how it was given its paths.
pub fn record_paths_from(ir: &mut btc_ir::TreeIr, base: &Path) {
    for p in [&mut ir.domain, &mut ir.problem, &mut ir.plan, &mut ir.rules] {
        if !p.is_empty() {
            *p = crate::paths::text(&crate::paths::relative_to(Path::new(p.as_str()), base));
        }
    }
}

pub fn compile(a: &CompileArgs) -> anyhow::Result<ExitCode> {
    expect_buffers_for(&a.plan);
    // Once the replay is over, this core writes what the other emits.
    let relay = btc_files::Relay::new();
    let (mut job, made) = load_job_then(
        &a.rules,
        PlanSource::File(FilePath::new(&a.plan)),
        a.problem.as_deref(),
        a.domain.as_deref(),
        a.allow_invalid_plan,
        |db, job| {
            let _making = relay.making();
            emit_meanwhile(db, job, a, &relay)
        },
        || relay.help(),
    )?;
    if let Some(made) = made.flatten() {
        if !has_errors(&job.diagnostics) {
            let sources = job.db.sources_for(&job.diagnostics);
            report::diagnostics(&job.diagnostics, &sources, a.format);
            let what = made.counts.summary(&job.problem_shown());
            let out = made.staged.target().to_path_buf();
            made.staged
                .commit()
                .map_err(|e| anyhow::anyhow!("cannot write `{}`: {e}", out.display()))?;
            wrote(a, &out, &what)?;
            // The process ends here: the OS reclaims the database at once.
            std::mem::forget(job);
            return Ok(ExitCode::SUCCESS);
        }
    }
    let result = tree_of(&mut job, a.emit == Output::Tree(emit::Format::Pytrees));
    let sources = job.db.sources_for(&job.diagnostics);
    let json = report::diagnostics(&job.diagnostics, &sources, a.format);
    let Some(mut ir) = result else {
        if a.format == Format::Json {
            outln!(
                "{}",
                serde_json::to_string_pretty(&serde_json::json!({
                    "ok": false,
                    "problem": job.problem_path(),
                    "diagnostics": json
                }))?
            )?;
        }
        return Ok(ExitCode::from(1));
    };
    let what = StepCounts::of(&ir).summary(&job.problem_shown());
    let current = match a.emit {
        Output::Tree(f) => {
            // A tree's emitter reads the IR alone: the plan's text, parse
            // and replay (half of what a long plan's compile holds) are
            // freed before the output is made, not kept beside it.
            drop(job);
            // Relative to the output's folder (standard output: the rules
            // file's); the IR is ours alone now: no copy.
            record_paths_from(Arc::make_mut(&mut ir), output_folder(a));
            deliver(a, &mut |w| emit::emit_to(&ir, f, &a.options, w), &what)?
        }
        Output::Kb => {
            let text = match db::JobWorld::of(&job.db, job.job()) {
                Some(w) => emit::kb::emit(w.domain, w.dix, w.problem, w.pix),
                None => anyhow::bail!(
                    "`--emit kb` needs the PDDL problem: pass `--problem PROBLEM` or name it in the rules file"
                ),
            };
            deliver(a, &mut |w| w.write_all(text.as_bytes()), &what)?
        }
    };
    // The process ends here: freeing the IR piece by piece would take time
    // the OS saves by reclaiming it at once.
    std::mem::forget(ir);
    Ok(if current {
        ExitCode::SUCCESS
    } else {
        ExitCode::from(1)
    })
}

/// The folder an output's recorded paths are relative to: the `-o` file's,
/// or for standard output the rules file's (where a project keeps its
/// outputs, and the same wherever btc runs).
fn output_folder(a: &CompileArgs) -> &Path {
    let file = a.output.as_deref().unwrap_or(&a.rules);
    file.parent().unwrap_or(Path::new(""))
}

/// Writes a compiled output where `a` sends it: the file `-o` names
/// (atomically, with the imported py_trees runtime beside it) or standard
/// output; `what` is the summary said on standard error. With `--check`,
/// writes nothing and returns whether the files are up to date.
fn deliver(
    a: &CompileArgs,
    produce: &mut btc_files::write::Produce<'_>,
    what: &str,
) -> anyhow::Result<bool> {
    let Some(out) = &a.output else {
        stdout::with(produce)?;
        eprintln!("compiled {}: {what}", a.plan.display());
        return Ok(true);
    };
    let runtime = runtime_beside(a, out);
    if a.check {
        let mut current = true;
        let mut runtime_text =
            |w: &mut dyn std::io::Write| w.write_all(emit::pytrees::RUNTIME.as_bytes());
        let outputs: [(Option<&Path>, &mut btc_files::write::Produce<'_>); 2] = [
            (Some(out), produce),
            (runtime.as_deref(), &mut runtime_text),
        ];
        for (path, produce) in outputs {
            let Some(path) = path else { continue };
            let status = match files::would_change(path, produce)? {
                btc_files::Comparison::Same => continue,
                btc_files::Comparison::Differs => "out of date",
                btc_files::Comparison::Missing => "missing",
            };
            outln!("{}: {status}", path.display())?;
            current = false;
        }
        if current {
            eprintln!("{}: up to date ({what})", out.display());
        }
        return Ok(current);
    }
    files::write_produced(out, produce)?;
    wrote(a, out, what)?;
    Ok(true)
}

/// Says that `out` was written, and writes the imported py_trees runtime
/// beside it (btc's file, always rewritten) when the output imports it.
fn wrote(a: &CompileArgs, out: &Path, what: &str) -> anyhow::Result<()> {
    eprintln!("wrote {}: {what}", out.display());
    if let Some(rt) = runtime_beside(a, out) {
        files::write_atomically(&rt, emit::pytrees::RUNTIME)?;
        eprintln!("wrote {}", rt.display());
    }
    Ok(())
}

/// An imported runtime goes beside the module, where its import finds it;
/// it is btc's file and always rewritten.
fn runtime_beside(a: &CompileArgs, out: &Path) -> Option<PathBuf> {
    (a.emit == Output::Tree(emit::Format::Pytrees)
        && a.options.runtime == emit::pytrees::Runtime::Import)
        .then(|| {
            let dir = out.parent().unwrap_or(Path::new(""));
            dir.join(format!("{}.py", emit::pytrees::RUNTIME_MODULE))
        })
}

/// An output made on the second core while the plan was replayed, in a
/// temporary file beside its target, and its plan's step counts.
struct Made {
    staged: btc_files::Staged,
    counts: StepCounts,
}

/// A tree's plan steps, and how many of them its rules skip.
#[derive(Clone, Copy)]
struct StepCounts {
    steps: usize,
    skipped: usize,
}

impl StepCounts {
    fn of(ir: &btc_ir::TreeIr) -> StepCounts {
        StepCounts {
            steps: ir.steps.len(),
            skipped: ir.steps.iter().filter(|s| s.skipped).count(),
        }
    }

    /// `N of M plan steps (K skipped); problem P`: what a compile says.
    fn summary(self, problem: &str) -> String {
        format!(
            "{} of {} plan steps ({} skipped); problem {problem}",
            self.steps - self.skipped,
            self.steps,
            self.skipped
        )
    }
}

/// A long plan's compile fills about five times the plan's size in large
/// buffers (its text, steps, typed steps, step records and nodes): their
/// pages are written in beforehand (`crate::alloc`). Short plans gain
/// nothing from it.
fn expect_buffers_for(plan: &Path) {
    const LONG_PLAN: u64 = 1 << 20;
    const MOST: u64 = 1 << 30;
    if let Ok(m) = std::fs::metadata(plan) {
        if m.len() >= LONG_PLAN {
            crate::alloc::expect_large((m.len() * 5).min(MOST) as usize);
        }
    }
}

/// For `btc compile -o FILE` of a tree: lowers the job and emits it into
/// a temporary file beside FILE, while the main thread replays the plan,
/// so that a long plan's emit is off the critical path; the output goes
/// through `relay`, for the main thread to write once it is free. `None`
/// where the output must wait for the verdict: `--check`, standard
/// output, `--emit kb`, a folder still to be created (a refused job
/// creates nothing), a target not replaced atomically, a job that does not
/// lower or that a py_trees module cannot express (the usual way then
/// reports why). Where the output waits, the tree is still lowered
/// meanwhile, memoized for that way, as [`load_job`] does.
fn emit_meanwhile<'a>(
    db: &Database,
    job: db::CompileJob,
    a: &'a CompileArgs,
    relay: &btc_files::Relay<'a>,
) -> Option<Made> {
    let folder_is_there = |out: &Path| {
        out.parent()
            .is_none_or(|d| d.as_os_str().is_empty() || d.is_dir())
    };
    let (format, out) = match (a.emit, a.output.as_deref(), a.check) {
        (Output::Tree(format), Some(out), false) if folder_is_there(out) => (format, out),
        _ => {
            let _ = db::compile(db, job);
            return None;
        }
    };
    let mut ir = db::lower_job(db, job).ok()?;
    if format == emit::Format::Pytrees
        && !targets::refusals(db, job, &ir, targets::Target::Pytrees).is_empty()
    {
        return None;
    }
    record_paths_from(&mut ir, output_folder(a));
    // Counted while the steps just lowered are in the cache, not after the
    // output has been through it.
    let counts = StepCounts::of(&ir);
    // The helper, once the replay is over, may make the output's second
    // part (a py_trees module's tree) while this thread makes its first.
    let ir = Arc::new(ir);
    let staged = btc_files::stage_file(out, &mut |file| {
        let (first, second) = match emit::parts(format) {
            [first, second] => (*first, Some(*second)),
            _ => (emit::Part::First, None),
        };
        let later = second.map(|part| {
            let ir = ir.clone();
            Box::new(move |hand: &mut btc_files::relay::Produce<'_>| {
                emit::emit_part_handing_over(&ir, format, &a.options, part, hand)
            }) as btc_files::relay::Later<'a>
        });
        relay.relay_parts(
            file,
            |hand| emit::emit_part_handing_over(&ir, format, &a.options, first, hand),
            later,
        )
    });
    let made = Made {
        staged: staged.ok()??,
        counts,
    };
    // The process ends soon: the OS reclaims the IR at once.
    std::mem::forget(ir);
    Some(made)
}

/// `btc fmt [--check] FILES`: formats in place (atomically), or with
/// `--check` lists the files that are not formatted and exits 1.
pub fn fmt(paths: &[PathBuf], check: bool) -> anyhow::Result<ExitCode> {
    let mut failed = false;
    for path in paths {
        let mut diags = Vec::new();
        let mut sources = btc_pddl::source::Sources::new();
        let id = files::load(&mut sources, path, &mut diags)?;
        let text = sources.text(id).to_owned();
        match btc_lang::rules::fmt::format(&text) {
            Err(errs) => {
                // Re-anchor the parse errors on this file for rendering.
                let errs: Vec<Diagnostic> = errs
                    .into_iter()
                    .map(|mut d| {
                        d.span.file = id;
                        d.labels.iter_mut().for_each(|l| l.span.file = id);
                        d
                    })
                    .collect();
                eprint!("{}", btc_pddl::render::to_terminal(&errs, &sources, false));
                eprintln!("{}: not formatted: it does not parse", path.display());
                failed = true;
            }
            Ok(formatted) if formatted == text => {}
            Ok(formatted) => {
                if check {
                    outln!("{}: not formatted", path.display())?;
                    failed = true;
                } else {
                    files::write_atomically(path, &formatted)?;
                    outln!("{}: formatted", path.display())?;
                }
            }
        }
    }
    Ok(if failed {
        ExitCode::from(1)
    } else {
        ExitCode::SUCCESS
    })
}
