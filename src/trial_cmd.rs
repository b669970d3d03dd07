//! `btc trial`: runs ARIAC 2023 trial files on a cell (the bundled one, or
//! `--cell`) with `btc_agent`'s task level, and prints the scoreboard.

use crate::stdout::{out, outln};
use crate::{files, report, Format};
use btc_agent::cell::{self, bundled, Cell};
use btc_agent::matrix;
use btc_agent::sim::{Runner, TrialError, TrialOptions, TrialReport, TrialsSummary};
use btc_agent::trial::{self, Trial};
use btc_lang::db::{self, Database};
use btc_pddl::diagnostic::{has_errors, Diagnostic};
use indicatif::{ProgressBar, ProgressStyle};
use std::io::IsTerminal;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

/// `btc trial`'s arguments.
#[derive(clap::Args)]
pub struct TrialArgs {
    /// An ARIAC 2023 trial configuration file (YAML).
    #[arg(required_unless_present = "matrix")]
    pub trial: Option<PathBuf>,
    /// The cell's `cell.toml` (default: the bundled ARIAC 2023 cell,
    /// `examples/ariac_cell/`).
    #[arg(long)]
    pub cell: Option<PathBuf>,
    /// Seeds what the trial leaves to chance (a random conveyor order, the
    /// human's moves); with `--trials`, the first seed.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Runs the trial this many times, with seeds `--seed`, `--seed`+1, ...,
    /// and prints the mean and spread.
    #[arg(long, default_value_t = 1, value_parser = clap::value_parser!(u64).range(1..=100_000))]
    pub trials: u64,
    /// Runs each task type under each agility challenge and under none (the
    /// paper's Figure 5), prints the table and writes the chart as SVG.
    #[arg(long, conflicts_with_all = ["trial", "trace"])]
    pub matrix: bool,
    /// With `--matrix`: the SVG chart's file.
    #[arg(long, default_value = "figure5.svg", requires = "matrix")]
    pub svg: PathBuf,
    /// With `--matrix`: runs per cell of the table (the paper ran 5).
    #[arg(long, default_value_t = 5, requires = "matrix", value_parser = clap::value_parser!(u64).range(1..=1000))]
    pub runs: u64,
    /// Writes the task events and every tree's status changes here, as JSON
    /// Lines (atomically; the first trial's with `--trials`).
    #[arg(long)]
    pub trace: Option<PathBuf>,
    /// Checks the world after every tick (each part in one place, no
    /// resource held twice); a violation is an error.
    #[arg(long)]
    pub check: bool,
    #[arg(long, value_enum, default_value_t)]
    pub format: Format,
}

/// A cell's files, through the bounded reader like every input.
fn read_file(p: &Path) -> Result<String, String> {
    files::read_text(p)
}

fn load_cell(db: &mut Database, a: &TrialArgs) -> anyhow::Result<Result<Cell, Vec<Diagnostic>>> {
    let r = match &a.cell {
        Some(p) => cell::load::load(db, p, &mut read_file),
        None => cell::load::load(db, Path::new(bundled::CELL_PATH), &mut bundled::read),
    };
    match r {
        Ok(c) => Ok(Ok(c)),
        Err(cell::load::LoadError::Read(p, e)) => {
            anyhow::bail!("cannot read `{}`: {e}", p.display())
        }
        Err(cell::load::LoadError::Invalid(d)) => Ok(Err(d)),
    }
}

fn fail(diags: &[Diagnostic], db: &Database, format: Format) -> anyhow::Result<ExitCode> {
    let json = report::diagnostics(diags, &db.sources(), format);
    if format == Format::Json {
        outln!(
            "{}",
            serde_json::to_string_pretty(&serde_json::json!({ "ok": false, "diagnostics": json }))?
        )?;
    }
    Ok(ExitCode::from(1))
}

fn progress(n: u64, what: &str) -> Option<ProgressBar> {
    if n < 2 || !std::io::stderr().is_terminal() {
        return None;
    }
    let pb = ProgressBar::new(n);
    pb.set_style(
        ProgressStyle::with_template(&format!("{{bar:40}} {{pos}}/{{len}} {what} {{elapsed}}"))
            .unwrap_or_else(|_| ProgressStyle::default_bar()),
    );
    Some(pb)
}

pub fn run(a: &TrialArgs) -> anyhow::Result<ExitCode> {
    let mut db = Database::new();
    let c = match load_cell(&mut db, a)? {
        Ok(c) => c,
        Err(d) => return fail(&d, &db, a.format),
    };
    if a.matrix {
        return run_matrix(a, &c, db);
    }
    let path = a
        .trial
        .as_deref()
        .expect("clap requires a trial without --matrix");
    let mut diags = Vec::new();
    let f = files::load_into_db(&mut db, path, &mut diags)?;
    let text = f.text(&db).clone();
    let (t, more) = trial::read(&text, db::file_id(&db, f));
    diags.extend(more);
    let Some(t) = t.filter(|_| !has_errors(&diags)) else {
        return fail(&diags, &db, a.format);
    };
    let mut runner = match Runner::with_db(&c, db) {
        Ok(r) => r,
        Err(e) => return error(e, &Database::new(), a.format),
    };
    // Warnings (fields not simulated, insufficient parts...) first.
    let warnings = report::diagnostics(&diags, &runner.db().sources(), a.format);
    let name = path.file_name().map_or_else(
        || path.display().to_string(),
        |n| n.to_string_lossy().into_owned(),
    );
    let pb = progress(a.trials, "trials");
    let mut runs = Vec::new();
    for k in 0..a.trials {
        let opts = TrialOptions {
            seed: a.seed + k,
            trace: k == 0 && a.trace.is_some(),
            check: a.check,
            ..TrialOptions::default()
        };
        match runner.run(&t, &name, &opts) {
            Ok(r) => runs.push(r),
            Err(e) => return error(e, runner.db(), a.format),
        }
        if let Some(pb) = &pb {
            pb.inc(1);
        }
    }
    if let Some(pb) = pb {
        pb.finish_and_clear();
    }
    if let (Some(p), Some(first)) = (&a.trace, runs.first()) {
        files::write_atomically(p, &first.trace)?;
    }
    let all_in = runs
        .iter()
        .all(|r| r.orders.iter().all(|o| o.submitted.is_some()));
    match a.format {
        Format::Json => {
            let mut doc = serde_json::json!({ "ok": all_in, "diagnostics": warnings });
            if runs.len() == 1 {
                doc["report"] = serde_json::to_value(&runs[0])?;
            } else {
                doc["summary"] = serde_json::to_value(TrialsSummary::of(&runs))?;
                doc["runs"] = serde_json::to_value(&runs)?;
            }
            outln!("{}", serde_json::to_string_pretty(&doc)?)?;
        }
        Format::Text => {
            if runs.len() == 1 {
                print_report(&runs[0], &t)?;
            } else {
                print_summary(&runs, &TrialsSummary::of(&runs))?;
            }
        }
    }
    Ok(if all_in {
        ExitCode::SUCCESS
    } else {
        ExitCode::from(1)
    })
}

fn error(e: TrialError, db: &Database, format: Format) -> anyhow::Result<ExitCode> {
    match e {
        TrialError::Cell(d) => fail(&d, db, format),
        TrialError::Inconsistent { tick, what } => {
            anyhow::bail!("the simulated world broke an invariant at tick {tick}: {what}")
        }
    }
}

fn secs(x: Option<f64>) -> String {
    x.map_or_else(|| "-".to_owned(), |s| format!("{s:.0} s"))
}

fn print_report(r: &TrialReport, t: &Trial) -> anyhow::Result<()> {
    outln!(
        "trial {} (seed {}): {:.0} s, score {} of {}; {}",
        r.trial,
        r.seed,
        r.seconds,
        r.score,
        r.best,
        r.stopped
    )?;
    outln!()?;
    outln!(
        "{:<12} {:<9} {:<5} {:<14} {:>9} {:>9} {:>7} {:>7} {:>7} {:>6}  faults",
        "order",
        "type",
        "prio",
        "state",
        "announced",
        "submitted",
        "time",
        "score",
        "tasks",
        "reass."
    )?;
    for o in &r.orders {
        outln!(
            "{:<12} {:<9} {:<5} {:<14} {:>9} {:>9} {:>7} {:>7} {:>7} {:>6}  {}",
            o.id,
            o.ty.name(),
            if o.priority { "high" } else { "-" },
            o.state,
            secs(o.announced),
            secs(o.submitted),
            secs(o.time),
            format!("{}/{}", o.score, o.best),
            format!("{}/{}", o.done, o.part_tasks),
            o.reassignments,
            if o.faults.is_empty() {
                "-".to_owned()
            } else {
                o.faults
                    .iter()
                    .map(|f| f.challenge.clone())
                    .collect::<Vec<_>>()
                    .join(", ")
            }
        )?;
    }
    outln!()?;
    // Timings (planning) are in the JSON report only: they vary from run
    // to run.
    outln!(
        "{:<14} {:>7} {:>10} {:>7} {:>6}",
        "agent",
        "busy",
        "tasks done",
        "failed",
        "plans"
    )?;
    for a in &r.agents {
        outln!(
            "{:<14} {:>7} {:>10} {:>7} {:>6}",
            a.robot,
            format!("{:.0} s", a.busy),
            a.tasks_done,
            a.tasks_failed,
            a.plans
        )?;
    }
    if !r.challenges.is_empty() {
        outln!()?;
        outln!("challenges:")?;
        for c in &r.challenges {
            let at = c.met.map_or_else(String::new, |m| format!(" at {m:.0} s"));
            outln!("  {}{at}: {}", c.challenge, c.ended)?;
        }
    }
    let failed: Vec<_> = r
        .tasks
        .iter()
        .filter_map(|task| match &task.state {
            btc_agent::sim::tasks::TaskState::Failed { cause, .. } => Some((task, cause)),
            _ => None,
        })
        .collect();
    if !failed.is_empty() {
        outln!()?;
        outln!("part tasks not done:")?;
        for (task, cause) in failed {
            outln!(
                "  task {} of {} ({}): {}",
                task.id,
                t.orders[task.order].id,
                task.work.describe(),
                cause
            )?;
        }
    }
    Ok(())
}

fn print_summary(runs: &[TrialReport], s: &TrialsSummary) -> anyhow::Result<()> {
    outln!(
        "trial {}: {} runs (seeds {}..{}); score {:.2} ± {:.2} (min {}, max {}); time {:.1} ± {:.1} s",
        s.trial,
        runs.len(),
        s.seeds.first().copied().unwrap_or(0),
        s.seeds.last().copied().unwrap_or(0),
        s.score.mean,
        s.score.sd,
        s.score.min,
        s.score.max,
        s.seconds.mean,
        s.seconds.sd
    )?;
    outln!()?;
    outln!(
        "{:<12} {:>16} {:>18} {:>10}",
        "order",
        "score",
        "time",
        "submitted"
    )?;
    for o in &s.orders {
        outln!(
            "{:<12} {:>16} {:>18} {:>10}",
            o.id,
            format!("{:.2} ± {:.2}", o.score.mean, o.score.sd),
            format!("{:.1} ± {:.1} s", o.time.mean, o.time.sd),
            format!("{}/{}", o.submitted, runs.len())
        )?;
    }
    Ok(())
}

fn run_matrix(a: &TrialArgs, c: &Cell, db: Database) -> anyhow::Result<ExitCode> {
    let mut runner = match Runner::with_db(c, db) {
        Ok(r) => r,
        Err(e) => return error(e, &Database::new(), a.format),
    };
    let plan = matrix::cells(a.runs as usize);
    let pb = progress(plan.len() as u64, "trials");
    let mut on = |_: usize| {
        if let Some(pb) = &pb {
            pb.inc(1);
        }
    };
    let m = match matrix::run(&mut runner, a.seed, a.runs as usize, a.check, &mut on) {
        Ok(m) => m,
        Err(e) => return error(e, runner.db(), a.format),
    };
    if let Some(pb) = pb {
        pb.finish_and_clear();
    }
    files::write_atomically(&a.svg, &matrix::svg(&m))?;
    match a.format {
        Format::Json => outln!(
            "{}",
            serde_json::to_string_pretty(
                &serde_json::json!({ "ok": true, "matrix": m, "svg": a.svg })
            )?
        )?,
        Format::Text => {
            out!("{}", matrix::table(&m))?;
            outln!()?;
            outln!("chart: {}", a.svg.display())?;
        }
    }
    Ok(ExitCode::SUCCESS)
}
