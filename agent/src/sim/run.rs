//! Running trials: the cell's rules database, reused across trials, and
//! one trial built into its PDDL problem, checked, and run to its end.

use super::model::Sim;
use super::options::{TrialError, TrialOptions};
use super::report::TrialReport;
use crate::cell::{Cell, TrialProblem};
use crate::trial::{Robot, Trial};
use btc_lang::db::{self, CompileJob, Database, SourceFile};
use btc_pddl::diagnostic::{codes, Diagnostic};
use btc_pddl::pipeline;
use btc_pddl::source::Span;
use std::time::Instant;

/// A cell's rules database, reused across trials: each trial only sets the
/// problem file and the plans.
pub struct Runner<'c> {
    cell: &'c Cell,
    db: Database,
    jobs: Vec<(Robot, CompileJob, String)>,
    problem: SourceFile,
}

const PROBLEM_PATH: &str = "(trial).pddl";

impl<'c> Runner<'c> {
    /// The database with the cell's domain and rules; the rules must check.
    pub fn new(cell: &'c Cell) -> Result<Runner<'c>, TrialError> {
        Runner::with_db(cell, Database::new())
    }

    /// The same, in a database that holds other files already (the cell
    /// and trial files the CLI renders diagnostics for).
    pub fn with_db(cell: &'c Cell, mut db: Database) -> Result<Runner<'c>, TrialError> {
        let domain = db.set_file(&cell.domain_path, cell.domain_text.clone());
        let problem = db.set_file(PROBLEM_PATH, String::new());
        let mut jobs = Vec::new();
        let mut errors = Vec::new();
        for (robot, path, text) in &cell.rules {
            let rules = db.set_file(path, text.clone());
            let plan_path = format!("({}).sas_plan", robot.name());
            let plan = db.set_file(&plan_path, String::new());
            let job = CompileJob::new(&db, rules, plan, Some(problem), Some(domain));
            errors.extend(
                db::rules_diagnostics(&db, rules)
                    .iter()
                    .filter(|d| d.is_error())
                    .cloned(),
            );
            jobs.push((*robot, job, plan_path));
        }
        if !errors.is_empty() {
            return Err(TrialError::Cell(errors));
        }
        Ok(Runner {
            cell,
            db,
            jobs,
            problem,
        })
    }

    /// The database (to render diagnostics with its sources).
    pub fn db(&self) -> &Database {
        &self.db
    }

    pub fn db_mut(&mut self) -> &mut Database {
        &mut self.db
    }

    /// Runs one trial to its end.
    pub fn run(
        &mut self,
        trial: &Trial,
        name: &str,
        opts: &TrialOptions,
    ) -> Result<TrialReport, TrialError> {
        let t0 = Instant::now();
        let tp = TrialProblem::build(self.cell, trial, "trial");
        self.db.set_problem(PROBLEM_PATH, tp.written.clone());
        let pid = db::file_id(&self.db, self.problem);
        let pu = pipeline::problem_unit_of(
            Some(tp.written.problem(pid)),
            Vec::new(),
            pid,
            self.cell.domain.domain.as_ref(),
            &self.cell.domain.index,
        );
        let errors: Vec<Diagnostic> = pu
            .diagnostics
            .iter()
            .filter(|d| d.is_error())
            .cloned()
            .collect();
        if !errors.is_empty() || pu.problem.is_none() {
            let first = errors
                .first()
                .map_or("it does not parse".to_owned(), |d| d.message.clone());
            return Err(TrialError::Cell(vec![Diagnostic::error(
                codes::CELL_MAPPING,
                Span::new(pid, 0, 0),
                format!("the trial's PDDL problem, built with the cell's mapping, does not fit the cell's domain: {first}"),
            )
            .with_hint("check the cell's `[names]`, `[types]` and `[always]` against its domain")]));
        }
        let world = btc_pddl::state::World::of_checked(
            self.cell.domain.domain.as_ref().expect("checked"),
            &self.cell.domain.index,
            pu.problem.as_ref().expect("checked"),
            &pu.index,
        )
        .map_err(|m| {
            TrialError::Cell(vec![Diagnostic::error(
                codes::CELL_MAPPING,
                Span::new(pid, 0, 0),
                format!("the trial's PDDL problem cannot be evaluated: {m}"),
            )])
        })?;
        let mut sim = Sim::new(
            self.cell,
            trial,
            &tp,
            (&pu, &world),
            opts,
            &mut self.db,
            &self.jobs,
        )?;
        sim.run()?;
        let mut report = sim.report(name);
        report.elapsed_ms = t0.elapsed().as_secs_f64() * 1e3;
        Ok(report)
    }
}
