//! Whether a job's plan is for the job's problem: its steps replayed from
//! the problem's initial state (V001, V002), once the job's report
//! ([`super::report`], which holds the names' fit, [`super::misfit`]) has
//! no errors.

use super::misfit::{job_name_fit, neighbours};
use super::report::{flatten, job_report};
use crate::db::{
    checked_domain, checked_problem, job_domain, job_problem, typed_plan, CompileJob, Db,
    ProblemOf, SourceFile,
};
use crate::path::FilePath;
use btc_pddl::diagnostic::{has_errors, Diagnostic};

/// The plan replayed from the problem's initial state: the first step whose
/// precondition fails (V001), or the goal it does not reach (V002). Empty
/// while the job has errors (the steps are not all typed then).
#[salsa::tracked(returns(ref))]
pub fn plan_validation(db: &dyn Db, job: CompileJob) -> Vec<Diagnostic> {
    if has_errors(&flatten(job_report(db, job))) {
        return Vec::new();
    }
    let Some(p) = job_problem(db, job) else {
        return Vec::new();
    };
    let Some(mut diags) = replay_on_problem(db, job).clone() else {
        return Vec::new();
    };
    if diags.is_empty() {
        return diags;
    }
    let valid: Vec<String> = neighbours(db, job)
        .into_iter()
        .filter(|n| replay(db, job, *n).is_some_and(|d| d.is_empty()))
        .map(|n| n.path(db).to_string())
        .collect();
    let advice = match valid.as_slice() {
        [] => format!(
            "the plan was replayed on `{}`; `--allow-invalid-plan` compiles it anyway",
            p.path(db)
        ),
        [one] => format!("the plan is valid for `{one}` beside it: pass `--problem {one}`"),
        many => format!(
            "the plan is valid for {}",
            many.iter()
                .map(|m| format!("`{m}`"))
                .collect::<Vec<_>>()
                .join(", ")
        ),
    };
    for d in &mut diags {
        d.hint = Some(match d.hint.take() {
            Some(h) => format!("{h}; {advice}"),
            None => advice.clone(),
        });
    }
    diags
}

/// The plan replayed on the job's own problem. A query of its own: loading
/// the problems beside the plan changes the workspace, which runs
/// [`plan_validation`] again, and a long plan's replay should not run
/// again with it.
#[salsa::tracked(returns(ref))]
fn replay_on_problem(db: &dyn Db, job: CompileJob) -> Option<Vec<Diagnostic>> {
    replay(db, job, job_problem(db, job)?)
}

/// The plan replayed on `problem` from its initial state (its steps typed
/// again for a problem other than the job's); `None` when the plan or the
/// world cannot be built for it.
fn replay(db: &dyn Db, job: CompileJob, problem: SourceFile) -> Option<Vec<Diagnostic>> {
    let d = job_domain(db, job)?;
    let cd = checked_domain(db, d);
    let cp = checked_problem(db, ProblemOf::new(db, problem, d));
    let (domain, prob) = (cd.domain.as_ref()?, cp.problem.as_ref()?);
    let tp = typed_plan(db, job);
    // The job's steps are borrowed, never copied: a copy of a long plan
    // cost more than replaying it.
    let retyped;
    let steps = if Some(problem) == job_problem(db, job) {
        &tp.steps
    } else {
        let (steps, diags) = btc_pddl::plan::type_plan(&tp.plan, domain, &cd.index, &cp.index);
        if has_errors(&diags) {
            return None;
        }
        retyped = steps;
        &retyped
    };
    let v = btc_pddl::validate::validate_plan(domain, prob, &cd.index, &cp.index, &tp.plan, steps);
    // A world the logic layer cannot build is reported by the checks.
    v.ok().map(|v| v.diagnostics)
}

/// Whether looking at the problems beside the plan could say more: the
/// plan names objects the problem lacks, or does not replay on it.
pub fn wants_neighbours(db: &dyn Db, job: CompileJob) -> bool {
    let Some(fit) = job_name_fit(db, job) else {
        return false;
    };
    !fit.fits() || !plan_validation(db, job).is_empty()
}

/// The folder a plan's neighbours are in.
pub fn plan_dir(db: &dyn Db, job: CompileJob) -> Option<FilePath> {
    job.plan(db).path(db).dir()
}
