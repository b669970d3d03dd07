//! `btc check` and `btc compile`: rules files, through the incremental
//! database.

use crate::{files, report, Format};
use btc_emit as emit;
use btc_lang::db::{self, CompileJob, Database, SourceFile};
use btc_lang::rules::{ImportTarget, Item};
use btc_pddl::diagnostic::{has_errors, Diagnostic};
use std::path::{Path, PathBuf};
use std::process::ExitCode;

/// Loads a rules file and everything it names (domain, problem, imports),
/// transitively, from disk into the database.
pub fn load_rules(
    db: &mut Database,
    path: &Path,
    diags: &mut Vec<Diagnostic>,
) -> anyhow::Result<SourceFile> {
    let root = files::load_into_db(db, path, diags)?;
    let mut pending = vec![path.to_path_buf()];
    let mut seen = std::collections::BTreeSet::new();
    while let Some(p) = pending.pop() {
        if !seen.insert(db::normalize(&p)) {
            continue;
        }
        let Some(f) = db.file(&db::normalize(&p)) else {
            continue;
        };
        let dir = p.parent().map(Path::to_path_buf).unwrap_or_default();
        let mut named: Vec<(String, bool)> = Vec::new(); // (path, is rules)
        for n in &db::parsed_rules(db, f).items {
            match &n.item {
                Item::Domain { path, .. } | Item::Problem { path, .. } => {
                    named.extend(path.plain().map(|s| (s, false)))
                }
                Item::Import {
                    target: ImportTarget::Path { path },
                    ..
                } => named.extend(path.plain().map(|s| (s, true))),
                _ => {}
            }
        }
        for (written, is_rules) in named {
            let full = dir.join(&written);
            if db.file(&db::normalize(&full)).is_none() && full.is_file() {
                // Unreadable files are reported by the checker as not found.
                let _ = files::load_into_db(db, &full, diags);
            }
            if is_rules {
                pending.push(full);
            }
        }
    }
    Ok(root)
}

/// `btc check RULES`: the rules file, its imports and its PDDL files. Object
/// names are checked when the rules file names a `problem`.
pub fn check(path: &Path, format: Format) -> anyhow::Result<ExitCode> {
    let mut database = Database::new();
    let mut diags = Vec::new();
    let rules = load_rules(&mut database, path, &mut diags)?;
    diags.extend(db::rules_diagnostics(&database, rules).iter().cloned());
    if let Some(d) = db::domain_file(&database, rules) {
        diags.extend(db::checked_domain(&database, d).diagnostics.iter().cloned());
    }
    let sources = database.sources();
    let json = report::diagnostics(&diags, &sources, format);
    let (e, w) = report::count(&diags);
    match format {
        Format::Json => println!(
            "{}",
            serde_json::to_string_pretty(
                &serde_json::json!({ "ok": e == 0, "diagnostics": json })
            )?
        ),
        Format::Text => {
            let items = db::parsed_rules(&database, rules).items.len();
            println!(
                "{}: {}; {}, {}",
                path.display(),
                report::plural(items, "item"),
                report::plural(e, "error"),
                report::plural(w, "warning")
            );
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
    pub options: emit::Options,
    pub format: Format,
}

/// Loads a rules file, a plan, and the problem and domain (given, named by
/// the rules file, or `problem.pddl` beside the plan or the rules) into a
/// fresh database; file-level problems go to `diags`.
pub fn load_job(
    rules_path: &Path,
    plan_path: &Path,
    problem_path: Option<&Path>,
    domain_path: Option<&Path>,
    diags: &mut Vec<Diagnostic>,
) -> anyhow::Result<(Database, CompileJob)> {
    load_job_with(
        rules_path,
        PlanInput::File(plan_path),
        problem_path,
        domain_path,
        diags,
    )
}

/// Where a job's plan comes from.
pub enum PlanInput<'a> {
    /// A plan file on disk.
    File(&'a Path),
    /// A plan that does not exist yet (the closed loop plans it): an empty
    /// file under this name; the plan reader's diagnostics about it (L006,
    /// no steps) are left out.
    Planned(&'a str),
}

pub fn load_job_with(
    rules_path: &Path,
    plan_input: PlanInput,
    problem_path: Option<&Path>,
    domain_path: Option<&Path>,
    diags: &mut Vec<Diagnostic>,
) -> anyhow::Result<(Database, CompileJob)> {
    let mut database = Database::new();
    let rules = load_rules(&mut database, rules_path, diags)?;
    let (plan, plan_path) = match plan_input {
        PlanInput::File(p) => (files::load_into_db(&mut database, p, diags)?, Some(p)),
        PlanInput::Planned(name) => (database.set_file(name, String::new()), None),
    };
    let problem_path = problem_path.map(Path::to_path_buf).or_else(|| {
        if db::declared_path(&database, rules, true).is_some() {
            return None;
        }
        [plan_path.and_then(Path::parent), rules_path.parent()]
            .into_iter()
            .flatten()
            .map(|d| d.join("problem.pddl"))
            .find(|p| p.is_file())
    });
    let problem = problem_path
        .as_deref()
        .map(|p| files::load_into_db(&mut database, p, diags))
        .transpose()?;
    let domain = domain_path
        .map(|p| files::load_into_db(&mut database, p, diags))
        .transpose()?;
    let job = CompileJob::new(&database, rules, plan, problem, domain);
    let planned = plan_path.is_none().then(|| db::file_id(&database, plan));
    diags.extend(
        db::job_diagnostics(&database, job)
            .iter()
            .filter(|d| Some(d.span.file) != planned || !d.code.starts_with('L'))
            .cloned(),
    );
    Ok((database, job))
}

pub fn compile(a: &CompileArgs) -> anyhow::Result<ExitCode> {
    let mut diags = Vec::new();
    let (database, job) = load_job(
        &a.rules,
        &a.plan,
        a.problem.as_deref(),
        a.domain.as_deref(),
        &mut diags,
    )?;
    let result = if has_errors(&diags) {
        None
    } else {
        db::compile(&database, job).as_ref().ok()
    };
    if result.is_none() {
        if let Err(errs) = db::compile(&database, job) {
            for e in errs {
                if !diags.contains(e) {
                    diags.push(e.clone());
                }
            }
        }
    }
    let sources = database.sources();
    let json = report::diagnostics(&diags, &sources, a.format);
    let Some(ir) = result else {
        if a.format == Format::Json {
            println!(
                "{}",
                serde_json::to_string_pretty(
                    &serde_json::json!({ "ok": false, "diagnostics": json })
                )?
            );
        }
        return Ok(ExitCode::from(1));
    };
    let text = match (&a.output, a.emit) {
        // A JSON IR records its PDDL files relative to itself.
        (Some(out), Output::Tree(f @ emit::Format::Json)) => {
            let mut ir = ir.clone();
            let dir = out.parent().unwrap_or(Path::new(""));
            for p in [&mut ir.domain, &mut ir.problem] {
                *p = crate::paths::text(&crate::paths::relative_to(Path::new(p.as_str()), dir));
            }
            emit::emit(&ir, f, &a.options)
        }
        (_, Output::Tree(f)) => emit::emit(ir, f, &a.options),
        (_, Output::Kb) => match db::JobWorld::of(&database, job) {
            Some(w) => emit::kb::emit(w.domain, w.dix, w.problem, w.pix),
            None => anyhow::bail!(
                "`--emit kb` needs the PDDL problem: pass `--problem PROBLEM` or name it in the rules file"
            ),
        },
    };
    match &a.output {
        Some(out) => {
            files::write_atomically(out, &text)?;
            let steps = ir.steps.iter().filter(|s| !s.skipped).count();
            eprintln!(
                "wrote {} ({} of {} plan steps, {} skipped)",
                out.display(),
                report::plural(steps, "step"),
                ir.steps.len(),
                ir.steps.len() - steps
            );
        }
        None => print!("{text}"),
    }
    Ok(ExitCode::SUCCESS)
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
                    println!("{}: not formatted", path.display());
                    failed = true;
                } else {
                    files::write_atomically(path, &formatted)?;
                    println!("{}: formatted", path.display());
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
