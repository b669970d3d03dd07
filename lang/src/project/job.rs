//! Loading a compile job: the rules file, the plan, and the problem the plan
//! goes with. The problem is, in this order:
//!
//! 1. the one given (`--problem`);
//! 2. the problem paired with the plan by name: `DIR/STEM.pddl` for the plan
//!    `DIR/STEM.EXT` (`p01.pddl` for `p01.plan`);
//! 3. the one the rules file names (`problem "..."`);
//! 4. `problem.pddl` beside the plan, then beside the rules file.

use super::fit::wants_neighbours;
use super::load::{load_file, load_rules};
use super::loader::{FileLoader, ReadFailure};
use crate::db::{domain_file, problem_file, CompileJob, Database, SourceFile};
use crate::path::FilePath;
use std::fmt;

/// Where the plan of a job comes from.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum PlanSource {
    /// A plan file.
    File(FilePath),
    /// A plan that does not exist yet (the closed loop plans it): an empty
    /// file under this name.
    Planned(FilePath),
}

/// The files of a job as the user named them.
#[derive(Clone, Debug)]
pub struct JobPaths {
    pub rules: FilePath,
    pub plan: PlanSource,
    pub problem: Option<FilePath>,
    pub domain: Option<FilePath>,
}

/// How the problem of a job was chosen (the summaries say it).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ProblemChoice {
    Given,
    PairedWithPlan,
    NamedByRules,
    BesidePlan,
    BesideRules,
}

impl fmt::Display for ProblemChoice {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            ProblemChoice::Given => "given",
            ProblemChoice::PairedWithPlan => "paired with the plan by name",
            ProblemChoice::NamedByRules => "named by the rules file",
            ProblemChoice::BesidePlan => "beside the plan",
            ProblemChoice::BesideRules => "beside the rules file",
        })
    }
}

#[derive(Clone, Copy, Debug)]
pub struct LoadedJob {
    pub job: CompileJob,
    /// The problem and how it was chosen (`None`: there is none).
    pub problem: Option<(SourceFile, ProblemChoice)>,
}

/// A file the user named that cannot be read.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Unreadable {
    pub path: FilePath,
    pub why: ReadFailure,
}

impl fmt::Display for Unreadable {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "cannot read `{}`: {}", self.path, self.why)
    }
}

fn named(
    db: &mut Database,
    loader: &dyn FileLoader,
    path: &FilePath,
) -> Result<SourceFile, Unreadable> {
    load_file(db, loader, path).map_err(|why| Unreadable {
        path: path.clone(),
        why,
    })
}

/// Loads a job into the database: the rules file and what it names, the
/// plan, the domain and the problem (see the module's order). When the plan
/// does not fit its problem, the problems beside the plan are loaded too,
/// so that the diagnostics can say which one it is for.
pub fn load_job(
    db: &mut Database,
    loader: &dyn FileLoader,
    paths: &JobPaths,
) -> Result<LoadedJob, Unreadable> {
    let loaded = load_job_files(db, loader, paths)?;
    load_neighbours_if_wanted(db, loader, &loaded, paths);
    Ok(loaded)
}

/// [`load_job`] without the plan's neighbours: a caller that works on the
/// job meanwhile (on another thread) loads them after, with
/// [`load_neighbours_if_wanted`].
pub fn load_job_files(
    db: &mut Database,
    loader: &dyn FileLoader,
    paths: &JobPaths,
) -> Result<LoadedJob, Unreadable> {
    let rules = load_rules(db, loader, &paths.rules).map_err(|why| Unreadable {
        path: paths.rules.clone(),
        why,
    })?;
    let (plan, plan_path) = match &paths.plan {
        PlanSource::File(p) => (named(db, loader, p)?, Some(p)),
        PlanSource::Planned(name) => (db.set_file(name, String::new()), None),
    };
    let domain = paths
        .domain
        .as_ref()
        .map(|p| named(db, loader, p))
        .transpose()?;
    let problem = match &paths.problem {
        Some(p) => Some((named(db, loader, p)?, ProblemChoice::Given)),
        None => find_problem(db, loader, rules, plan_path, &paths.rules),
    };
    let given = problem.and_then(|(f, c)| (c != ProblemChoice::NamedByRules).then_some(f));
    let job = CompileJob::new(db, rules, plan, given, domain);
    Ok(LoadedJob { job, problem })
}

/// Loads the problems beside the plan when it does not fit its own (so
/// the diagnostics can say which one it is for); whether it did.
pub fn load_neighbours_if_wanted(
    db: &mut Database,
    loader: &dyn FileLoader,
    loaded: &LoadedJob,
    paths: &JobPaths,
) -> bool {
    let wanted = matches!(paths.plan, PlanSource::File(_)) && wants_neighbours(db, loaded.job);
    if wanted {
        load_neighbours(db, loader, loaded.job.plan(db));
    }
    wanted
}

fn find_problem(
    db: &mut Database,
    loader: &dyn FileLoader,
    rules: SourceFile,
    plan: Option<&FilePath>,
    rules_path: &FilePath,
) -> Option<(SourceFile, ProblemChoice)> {
    let domain = domain_file(db, rules).map(|d| d.path(db).clone());
    let try_load = |db: &mut Database, p: Option<FilePath>| {
        let p = p.filter(|p| Some(p) != domain.as_ref())?;
        load_file(db, loader, &p).ok()
    };
    let paired = plan.and_then(|p| p.sibling(format!("{}.pddl", p.stem()?)));
    if let Some(f) = try_load(db, paired) {
        return Some((f, ProblemChoice::PairedWithPlan));
    }
    if let Some(f) = problem_file(db, rules) {
        return Some((f, ProblemChoice::NamedByRules));
    }
    if let Some(f) = try_load(db, plan.and_then(|p| p.sibling("problem.pddl"))) {
        return Some((f, ProblemChoice::BesidePlan));
    }
    try_load(db, rules_path.sibling("problem.pddl")).map(|f| (f, ProblemChoice::BesideRules))
}

/// Reads the PDDL files beside a plan that the database does not have.
fn load_neighbours(db: &mut Database, loader: &dyn FileLoader, plan: SourceFile) {
    let Some(dir) = plan.path(db).dir() else {
        return;
    };
    let Some(disk) = dir.as_path() else { return };
    for p in loader.list(disk) {
        let p = FilePath::new(p);
        if p.has_extension("pddl") {
            let _ = load_file(db, loader, &p);
        }
    }
}
