//! A project: a rules file and what it names (domain, problem, imports),
//! loaded once into btc's incremental database and kept there, so checking,
//! planning and compiling again after the first time re-does only what
//! changed. Loaded from disk ([`Project::open`]) or from texts held in
//! memory ([`Project::from_texts`]).

use crate::diagnostic::{convert, Diagnostic, Error};
use crate::plan::Plan;
use crate::tree::Tree;
use btc_lang::db::{self, CompileJob, Database, JobWorld};
use btc_lang::path::FilePath;
use btc_lang::project::{self, FileLoader, JobPaths, MemoryLoader, PlanSource, ReadFailure};
use btc_pddl::diagnostic::{codes, has_errors};
use std::path::Path;

/// The disk, read up to btc's file limit.
const DISK: project::DiskLoader = project::DiskLoader {
    limit: btc_pddl::source::MAX_FILE_BYTES,
};

/// Where the plan of a compile is kept in the database.
const PLAN_FILE: &str = "<plan>";

/// The names texts are kept under by [`Project::from_texts`]: diagnostics
/// about them name these.
pub const RULES_TEXT: &str = "rules.btrules";
pub const DOMAIN_TEXT: &str = "domain.pddl";
pub const PROBLEM_TEXT: &str = "problem.pddl";

enum Files {
    Disk,
    Memory(MemoryLoader),
}

impl Files {
    fn loader(&self) -> &dyn FileLoader {
        match self {
            Files::Disk => &DISK,
            Files::Memory(m) => m,
        }
    }
}

pub struct Project {
    db: Database,
    rules: FilePath,
    files: Files,
    /// The domain given beside rules that name none (texts).
    domain: Option<FilePath>,
    /// The problem given as a text: what `plan` and `compile` use when
    /// they are given none.
    problem: Option<FilePath>,
    /// The compile job of each problem asked for so far.
    jobs: Vec<(Option<FilePath>, CompileJob)>,
}

impl Project {
    /// Loads the rules file at `rules` and the files it names.
    pub fn open(rules: impl AsRef<Path>) -> Result<Project, Error> {
        let rules = FilePath::new(rules.as_ref());
        let mut db = Database::new();
        project::load_rules(&mut db, &DISK, &rules).map_err(|why| unreadable(&rules, &why))?;
        Ok(Project {
            db,
            rules,
            files: Files::Disk,
            domain: None,
            problem: None,
            jobs: Vec::new(),
        })
    }

    /// A project from texts: the rules, the domain, and optionally the
    /// problem. They are kept under the names the rules give them (or
    /// [`DOMAIN_TEXT`], [`PROBLEM_TEXT`]); nothing is read from disk.
    pub fn from_texts(rules: &str, domain: &str, problem: Option<&str>) -> Result<Project, Error> {
        let rules_path = FilePath::new(RULES_TEXT);
        let mut db = Database::new();
        // The rules first, alone: where they expect their domain and
        // problem decides the names those texts are kept under.
        let f = db.set_file(&rules_path, rules.to_owned());
        let named = |db: &Database, problem: bool| {
            db::declared_path(db, f, problem).and_then(|(p, _, _)| rules_path.sibling(p))
        };
        let domain_named = named(&db, false);
        let problem_named = named(&db, true);
        let domain_path = domain_named
            .clone()
            .unwrap_or_else(|| FilePath::new(DOMAIN_TEXT));
        let problem_path = problem_named.unwrap_or_else(|| FilePath::new(PROBLEM_TEXT));
        let mut files = MemoryLoader::new()
            .with(rules_path.as_path().unwrap_or(Path::new(RULES_TEXT)), rules)
            .with(
                domain_path.as_path().unwrap_or(Path::new(DOMAIN_TEXT)),
                domain,
            );
        if let Some(p) = problem {
            files.insert(problem_path.as_path().unwrap_or(Path::new(PROBLEM_TEXT)), p);
        }
        project::load_rules(&mut db, &files, &rules_path)
            .map_err(|why| unreadable(&rules_path, &why))?;
        // A domain the rules do not name is loaded as a job's domain.
        if domain_named.is_none() {
            project::load_file(&mut db, &files, &domain_path)
                .map_err(|why| unreadable(&domain_path, &why))?;
        }
        if problem.is_some() {
            project::load_file(&mut db, &files, &problem_path)
                .map_err(|why| unreadable(&problem_path, &why))?;
        }
        Ok(Project {
            db,
            rules: rules_path,
            files: Files::Memory(files),
            domain: domain_named.is_none().then_some(domain_path),
            problem: problem.is_some().then_some(problem_path),
            jobs: Vec::new(),
        })
    }

    /// Every diagnostic of the rules file, its imports, its domain and its
    /// problem, in `btc check`'s order.
    pub fn check(&self) -> Vec<Diagnostic> {
        let Some(rules) = self.db.file(&self.rules) else {
            return Vec::new();
        };
        let diags = project::flatten(project::project_report(&self.db, rules));
        convert(&diags, &self.db.sources_for(&diags))
    }

    /// A plan for `problem` (a path; `None`: the problem given as a text,
    /// or the one the rules file names) made by btc's planner.
    pub fn plan(&mut self, problem: Option<&Path>) -> Result<Plan, Error> {
        let job = self.job(problem)?;
        self.refuse_errors(job, |d| d.span.file != self.plan_id(job))?;
        let w = self.world_of(job)?;
        let report = btc_planner::plan(w.domain, w.dix, w.problem, w.pix, &Default::default())
            .map_err(|ds| self.error(&ds))?;
        match report.outcome {
            btc_planner::Outcome::Plan(p) => Ok(Plan::from_planner(w.domain, w.pix, &p)),
            btc_planner::Outcome::Unsolvable => {
                Err(self.error(&[btc_planner::unsolvable(w.problem)]))
            }
            btc_planner::Outcome::Timeout => {
                Err(self.error(&[btc_planner::timeout(w.problem, Default::default())]))
            }
        }
    }

    /// `problem` (a path; `None` as for [`Project::plan`]) written back as
    /// PDDL with `state` as its initial state and `goal` as its goal: the
    /// knowledge base an agent holds (an [`crate::AttemptInput`]'s `state`
    /// and `goal`, or facts from perception) as a problem any planner
    /// reads. Facts are checked against the problem: a predicate, object
    /// or fluent it does not have is an error, not a line in the output.
    pub fn problem_text(
        &mut self,
        state: &[String],
        goal: &str,
        problem: Option<&Path>,
    ) -> Result<String, Error> {
        let job = self.job(problem)?;
        self.refuse_errors(job, |d| d.span.file != self.plan_id(job))?;
        let w = self.world_of(job)?;
        let world = w.world().map_err(|m| {
            Error::one(Diagnostic::without_place(
                codes::X_WORLD.id,
                format!("the problem's world does not fit together: {m}"),
                &self.rules.to_string(),
            ))
        })?;
        let bad = |m: String| {
            Error::one(Diagnostic::without_place(
                codes::X_KB.id,
                m,
                &self.rules.to_string(),
            ))
        };
        let mut init = Vec::with_capacity(state.len());
        for text in state {
            let fact = crate::executor::fact(text).map_err(&bad)?;
            let known = match &fact {
                btc_pddl::logic::InitFact::Atom(a) => world.atom_key(a).map(drop),
                btc_pddl::logic::InitFact::Value(a, _) => world.fluent_key(a).map(drop),
            };
            known.map_err(|m| bad(format!("`{text}`: {m}")))?;
            init.push(fact);
        }
        let goal = btc_pddl::logic::decode::formula(goal)
            .map_err(|m| bad(format!("the goal `{goal}` is not a PDDL condition: {m}")))?;
        Ok(btc_pddl::problem_text::problem_text(
            w.problem,
            &init,
            Some(&goal),
        ))
    }

    /// Compiles `plan` with the rules for `problem` (as [`Project::plan`]
    /// chooses it): the plan is typed against the problem and replayed on
    /// it first, as `btc compile` does, and refused when it does not fit.
    pub fn compile(&mut self, plan: &Plan, problem: Option<&Path>) -> Result<Tree, Error> {
        let job = self.job(problem)?;
        // The plan goes to the compiler as the value it is; its file holds
        // the text diagnostics show.
        self.db.set_plan(&FilePath::new(PLAN_FILE), plan.written());
        self.refuse_errors(job, |_| true)?;
        let replay: Vec<_> = project::fit::plan_validation(&self.db, job).to_vec();
        if has_errors(&replay) {
            return Err(self.error(&replay));
        }
        let ir = db::compile(&self.db, job).as_ref().map_err(|e| {
            if e.is_empty() {
                self.error(&self.job_errors(job))
            } else {
                self.error(e)
            }
        })?;
        let refusals =
            btc_lang::targets::refusals(&self.db, job, ir, btc_lang::targets::Target::Pytrees);
        Ok(Tree::new(
            ir.clone(),
            convert(&refusals, &self.db.sources_for(&refusals)),
        ))
    }

    /// The world of `problem` (as [`Project::plan`] chooses it) as the
    /// `.kb` text `btc compile --emit kb` writes: what btc's C++ knowledge
    /// base (`integrations/btcpp`) reads.
    pub fn knowledge_base(&mut self, problem: Option<&Path>) -> Result<String, Error> {
        let job = self.job(problem)?;
        self.refuse_errors(job, |d| d.span.file != self.plan_id(job))?;
        let w = self.world_of(job)?;
        Ok(btc_emit::kb::emit(w.domain, w.dix, w.problem, w.pix))
    }

    /// The database, the compile job and the world of a plan still to be
    /// made, for the closed loop ([`crate::Agent`]).
    pub(crate) fn loop_job(
        &mut self,
        problem: Option<&Path>,
    ) -> Result<(&mut Database, CompileJob), Error> {
        let job = self.job(problem)?;
        self.db.set_file(&FilePath::new(PLAN_FILE), String::new());
        self.refuse_errors(job, |d| d.span.file != self.plan_id(job))?;
        self.world_of(job)?;
        Ok((&mut self.db, job))
    }

    /// Refuses a leaf implementation for a node id the rules do not
    /// declare as an action.
    pub(crate) fn declared_action(&self, id: &str) -> Result<(), Error> {
        let declared = self.db.file(&self.rules).is_some_and(|rules| {
            db::declarations(&self.db, rules)
                .nodes
                .get(id)
                .is_some_and(|n| n.kind == btc_lang::rules::ast::NodeKind::Action)
        });
        if declared {
            return Ok(());
        }
        Err(Error::one(
            Diagnostic::without_place(
                codes::X_UNKNOWN_NODE.id,
                format!("the rules declare no action `{id}`"),
                &self.rules.to_string(),
            )
            .hint("a leaf implementation takes the action leaves of one node id the rules declare with `action NAME(...)`"),
        ))
    }

    pub(crate) fn sources_for(
        &self,
        diags: &[btc_pddl::diagnostic::Diagnostic],
    ) -> btc_pddl::source::Sources {
        self.db.sources_for(diags)
    }

    pub(crate) fn error(&self, diags: &[btc_pddl::diagnostic::Diagnostic]) -> Error {
        Error::new(convert(diags, &self.db.sources_for(diags)))
    }

    /// The compile job for a problem, loaded the first time it is asked
    /// for and kept: a job is an input of the database, and its queries'
    /// results live as long as it does, so an agent that plans and
    /// compiles thousands of times holds one job per problem, not one per
    /// call.
    fn job(&mut self, problem: Option<&Path>) -> Result<CompileJob, Error> {
        let problem = problem.map(FilePath::new).or_else(|| self.problem.clone());
        if let Some((_, job)) = self.jobs.iter().find(|(p, _)| *p == problem) {
            return Ok(*job);
        }
        let paths = JobPaths {
            rules: self.rules.clone(),
            plan: PlanSource::Planned(FilePath::new(PLAN_FILE)),
            problem: problem.clone(),
            domain: self.domain.clone(),
        };
        let loaded = project::load_job(&mut self.db, self.files.loader(), &paths)
            .map_err(|u| unreadable(&u.path, &u.why))?;
        self.jobs.push((problem, loaded.job));
        Ok(loaded.job)
    }

    fn plan_id(&self, job: CompileJob) -> u32 {
        db::file_id(&self.db, job.plan(&self.db))
    }

    fn job_errors(&self, job: CompileJob) -> Vec<btc_pddl::diagnostic::Diagnostic> {
        db::job_diagnostics(&self.db, job)
            .iter()
            .filter(|d| d.is_error())
            .cloned()
            .collect()
    }

    /// Refuses a job whose files have errors (among those `keep` keeps).
    fn refuse_errors(
        &self,
        job: CompileJob,
        keep: impl Fn(&btc_pddl::diagnostic::Diagnostic) -> bool,
    ) -> Result<(), Error> {
        let errors: Vec<_> = self.job_errors(job).into_iter().filter(keep).collect();
        if errors.is_empty() {
            Ok(())
        } else {
            Err(self.error(&errors))
        }
    }

    fn world_of(&self, job: CompileJob) -> Result<JobWorld<'_>, Error> {
        JobWorld::of(&self.db, job).ok_or_else(|| {
            Error::one(
                Diagnostic::without_place(
                    codes::R_NO_DOMAIN.id,
                    "planning needs a PDDL domain and problem, and this project has no problem",
                    &self.rules.to_string(),
                )
                .hint("name it in the rules file (`problem \"problem.pddl\"`) or pass one"),
            )
        })
    }
}

/// A file the caller named that cannot be read, as btc's F001/F002.
fn unreadable(path: &FilePath, why: &ReadFailure) -> Error {
    let code = match why {
        ReadFailure::NotAFile { .. } => codes::FILE_NOT_REGULAR,
        _ => codes::FILE_UNREADABLE,
    };
    Error::one(Diagnostic::without_place(
        code.id,
        format!("cannot read `{path}`: {why}"),
        &path.to_string(),
    ))
}

/// [`crate::plan`]: the domain and problem read and checked as `btc plan`
/// reads them, then planned.
pub(crate) fn plan_files(domain: &Path, problem: &Path) -> Result<Plan, Error> {
    use btc_pddl::pipeline::{domain_unit, problem_unit};
    let mut sources = btc_pddl::source::Sources::new();
    let mut read = |p: &Path| -> Result<u32, Error> {
        let loaded = DISK
            .read(p)
            .map_err(|why| unreadable(&FilePath::new(p), &why))?;
        Ok(sources.add(p.display().to_string(), loaded.text))
    };
    let d = read(domain)?;
    let p = read(problem)?;
    let du = domain_unit(&sources, d);
    let pu = problem_unit(&sources, p, &du);
    let mut diags: Vec<_> = du
        .diagnostics
        .iter()
        .chain(&pu.diagnostics)
        .cloned()
        .collect();
    let fail = |diags: &[btc_pddl::diagnostic::Diagnostic]| Error::new(convert(diags, &sources));
    let (Some(dom), Some(prob)) = (&du.domain, &pu.problem) else {
        return Err(fail(&diags));
    };
    if has_errors(&diags) {
        return Err(fail(&diags));
    }
    let report = btc_planner::plan(dom, &du.index, prob, &pu.index, &Default::default())
        .map_err(|ds| fail(&ds))?;
    match report.outcome {
        btc_planner::Outcome::Plan(p) => Ok(Plan::from_planner(dom, &pu.index, &p)),
        btc_planner::Outcome::Unsolvable => {
            diags.push(btc_planner::unsolvable(prob));
            Err(fail(&diags))
        }
        btc_planner::Outcome::Timeout => {
            diags.push(btc_planner::timeout(prob, Default::default()));
            Err(fail(&diags))
        }
    }
}
