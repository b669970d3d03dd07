//! Whether a plan's object names are the job's problem's: a plan written
//! for another problem is one diagnostic (L010) naming the problems beside
//! it that it fits, instead of an error at every unknown name.

use crate::db::{
    checked_problem, job_domain, job_problem, typed_plan, CompileJob, Db, ProblemOf, SourceFile,
};
use btc_pddl::diagnostic::Diagnostic;
use btc_pddl::plan::fit::fold_unknown_objects;
use btc_pddl::plan::NameFit;

/// The plan's typing diagnostics, with a plan for another problem reported
/// once (L010) instead of at every unknown name.
#[salsa::tracked(returns(ref))]
pub fn plan_diagnostics(db: &dyn Db, job: CompileJob) -> Vec<Diagnostic> {
    let tp = typed_plan(db, job);
    let (Some(d), Some(p)) = (job_domain(db, job), job_problem(db, job)) else {
        return tp.diagnostics.clone();
    };
    let cp = checked_problem(db, ProblemOf::new(db, p, d));
    let Some(fit) = job_name_fit(db, job) else {
        return tp.diagnostics.clone();
    };
    if fit.fits() {
        return tp.diagnostics.clone();
    }
    let fitting: Vec<String> = neighbours(db, job)
        .into_iter()
        .filter(|n| {
            NameFit::of(
                &tp.plan,
                &checked_problem(db, ProblemOf::new(db, *n, d)).index,
            )
            .fits()
        })
        .map(|n| n.path(db).to_string())
        .collect();
    if !fit.misfits(&fitting) {
        return tp.diagnostics.clone();
    }
    let objects = cp.problem.as_ref().and_then(|p| {
        let (first, last) = (p.objects.first()?, p.objects.last()?);
        Some(first.name.span.to(last.name.span))
    });
    let mut misfit = fit.diagnostic(&p.path(db).to_string(), objects, &fitting);
    if let [one] = fitting.as_slice() {
        misfit.hint = misfit.hint.map(|h| format!("{h}: pass `--problem {one}`"));
    }
    fold_unknown_objects(&tp.diagnostics, misfit)
}

/// The plan's object names weighed against the job's problem (`None`
/// without a domain and a problem). A query: the plan's report and the
/// loader's question about neighbours both read it, and it walks every
/// argument of the plan.
#[salsa::tracked(returns(ref))]
pub(super) fn job_name_fit(db: &dyn Db, job: CompileJob) -> Option<NameFit> {
    let (d, p) = (job_domain(db, job)?, job_problem(db, job)?);
    let cp = checked_problem(db, ProblemOf::new(db, p, d));
    Some(NameFit::of(&typed_plan(db, job).plan, &cp.index))
}

/// The problems beside the job's plan that the database holds, other than
/// the job's (PDDL files that parse as problems of the job's domain).
pub fn neighbours(db: &dyn Db, job: CompileJob) -> Vec<SourceFile> {
    let plan = job.plan(db);
    let (Some(d), Some(p)) = (job_domain(db, job), job_problem(db, job)) else {
        return Vec::new();
    };
    let Some(dir) = plan.path(db).dir() else {
        return Vec::new();
    };
    db.workspace()
        .files(db)
        .iter()
        .filter(|(path, f)| {
            path.has_extension("pddl") && path.dir().as_ref() == Some(&dir) && **f != p && **f != d
        })
        .map(|(_, f)| *f)
        .filter(|f| {
            checked_problem(db, ProblemOf::new(db, *f, d))
                .problem
                .is_some()
        })
        .collect()
}
