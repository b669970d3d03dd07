//! `btc validate DOMAIN PROBLEM PLAN`

use crate::{files, report, Format};
use btc_pddl::diagnostic::has_errors;
use btc_pddl::pipeline::{domain_unit, plan_unit, problem_unit, validate_units};
use btc_pddl::source::Sources;
use std::path::Path;
use std::process::ExitCode;

pub fn run(domain: &Path, problem: &Path, plan: &Path, format: Format) -> anyhow::Result<ExitCode> {
    let mut sources = Sources::new();
    let mut diags = Vec::new();
    let d = files::load(&mut sources, domain, &mut diags)?;
    let p = files::load(&mut sources, problem, &mut diags)?;
    let l = files::load(&mut sources, plan, &mut diags)?;
    let du = domain_unit(&sources, d);
    let pu = problem_unit(&sources, p, &du);
    let lu = plan_unit(&sources, l, &du, &pu);
    diags.extend(du.diagnostics.iter().cloned());
    diags.extend(pu.diagnostics.iter().cloned());
    diags.extend(lu.diagnostics.iter().cloned());
    let validation = if has_errors(&diags) {
        None
    } else {
        validate_units(&du, &pu, &lu)
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
            println!("{}", serde_json::to_string_pretty(&doc)?);
        }
        Format::Text => match &validation {
            Some(v) if v.valid => println!(
                "valid: {} reach the goal (cost {})",
                report::plural(steps, "step"),
                v.cost
            ),
            Some(v) => println!(
                "invalid: {} of {} applied",
                report::plural(v.steps_applied, "step"),
                steps
            ),
            None => {
                let (e, _) = report::count(&diags);
                println!(
                    "not validated: {} in the inputs",
                    report::plural(e, "error")
                );
            }
        },
    }
    Ok(if valid {
        ExitCode::SUCCESS
    } else {
        ExitCode::from(1)
    })
}
