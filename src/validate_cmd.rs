//! `btc validate DOMAIN PROBLEM PLAN`

use crate::stdout::outln;
use crate::{files, report, Format};
use btc_lang::project::FileLoader;
use btc_pddl::diagnostic::has_errors;
use btc_pddl::pipeline::{
    domain_unit, plan_unit, problem_unit, validate_units_with, DomainUnit, PlanUnit, ProblemUnit,
};
use btc_pddl::plan::fit::fold_unknown_objects;
use btc_pddl::plan::NameFit;
use btc_pddl::source::Sources;
use std::path::Path;

/// A plan for another problem is one L010 (naming the problems beside the
/// plan that have every object it names), not an L004 per unknown name.
fn fold_misfit(
    sources: &mut Sources,
    du: &DomainUnit,
    pu: &ProblemUnit,
    lu: &mut PlanUnit,
    plan: &Path,
    problem: &Path,
) {
    let fit = NameFit::of(&lu.plan, &pu.index);
    if fit.fits() {
        return;
    }
    let dir = plan.parent().filter(|d| !d.as_os_str().is_empty());
    let mut fitting = Vec::new();
    for other in files::Disk.list(dir.unwrap_or(Path::new("."))) {
        let same = |p: &Path| std::fs::canonicalize(p).ok() == std::fs::canonicalize(&other).ok();
        if other.extension().is_none_or(|e| e != "pddl") || same(problem) {
            continue;
        }
        let Ok(id) = files::load(sources, &other, &mut Vec::new()) else {
            continue;
        };
        let ou = problem_unit(sources, id, du);
        if ou.problem.is_some() && NameFit::of(&lu.plan, &ou.index).fits() {
            fitting.push(btc_lang::path::FilePath::new(&other).to_string());
        }
    }
    if fit.misfits(&fitting) {
        let objects = pu
            .problem
            .as_ref()
            .and_then(|p| Some(p.objects.first()?.name.span.to(p.objects.last()?.name.span)));
        let d = fit.diagnostic(&problem.display().to_string(), objects, &fitting);
        lu.diagnostics = fold_unknown_objects(&lu.diagnostics, d);
    }
}
use std::process::ExitCode;

pub fn run(
    domain: &Path,
    problem: &Path,
    plan: &Path,
    epsilon: f64,
    format: Format,
) -> anyhow::Result<ExitCode> {
    if !(epsilon.is_finite() && epsilon > 0.0) {
        anyhow::bail!("--epsilon must be a positive number of seconds, not {epsilon}");
    }
    let mut sources = Sources::new();
    let mut diags = Vec::new();
    let d = files::load(&mut sources, domain, &mut diags)?;
    let p = files::load(&mut sources, problem, &mut diags)?;
    let l = files::load(&mut sources, plan, &mut diags)?;
    let du = domain_unit(&sources, d);
    let pu = problem_unit(&sources, p, &du);
    let mut lu = plan_unit(&sources, l, &du, &pu);
    fold_misfit(&mut sources, &du, &pu, &mut lu, plan, problem);
    diags.extend(du.diagnostics.iter().cloned());
    diags.extend(pu.diagnostics.iter().cloned());
    diags.extend(lu.diagnostics.iter().cloned());
    let validation = if has_errors(&diags) {
        None
    } else {
        validate_units_with(&du, &pu, &lu, epsilon)
    };
    if let Some(v) = &validation {
        diags.extend(v.diagnostics.iter().cloned());
    }
    let valid = validation.as_ref().is_some_and(|v| v.valid);
    let json = report::diagnostics(&diags, &sources, format);
    let steps = lu.plan.steps.len();
    match format {
        Format::Json => {
            let doc = serde_json::json!({
                "valid": valid,
                "steps": steps,
                "steps_applied": validation.as_ref().map(|v| v.steps_applied),
                "cost": validation.as_ref().map(|v| v.cost),
                "plan_format": lu.plan.format,
                "diagnostics": json,
            });
            outln!("{}", serde_json::to_string_pretty(&doc)?)?;
        }
        Format::Text => match &validation {
            Some(v) if v.valid => outln!(
                "valid: {} reach the goal (cost {})",
                report::plural(steps, "step"),
                v.cost
            )?,
            Some(v) => outln!(
                "invalid: {} of {} applied",
                report::plural(v.steps_applied, "step"),
                steps
            )?,
            None => {
                let (e, _) = report::count(&diags);
                outln!(
                    "not validated: {} in the inputs",
                    report::plural(e, "error")
                )?;
            }
        },
    }
    Ok(if valid {
        ExitCode::SUCCESS
    } else {
        ExitCode::from(1)
    })
}
