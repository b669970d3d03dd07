//! The front end's stages bundled per file: parse + check a domain, a
//! problem against it, a plan against both. Pure functions over texts held
//! in [`Sources`]; the CLI, the tests and the incremental database call these.

use crate::diagnostic::{has_errors, Diagnostic};
use crate::plan::{self, GroundStep, Plan};
use crate::source::{FileId, Sources};
use crate::state::World;
use crate::validate::{validate_with, Replay, Validation};
use crate::{ast::Domain, ast::Problem, DomainIndex, ProblemIndex};

pub struct DomainUnit {
    pub file: FileId,
    pub domain: Option<Domain>,
    pub index: DomainIndex,
    pub diagnostics: Vec<Diagnostic>,
}

pub struct ProblemUnit {
    pub file: FileId,
    pub problem: Option<Problem>,
    pub index: ProblemIndex,
    pub diagnostics: Vec<Diagnostic>,
}

pub struct PlanUnit {
    pub file: FileId,
    pub plan: Plan,
    pub steps: Vec<GroundStep>,
    pub diagnostics: Vec<Diagnostic>,
}

pub fn domain_unit(sources: &Sources, file: FileId) -> DomainUnit {
    domain_unit_from(sources.text(file), file)
}

pub fn domain_unit_from(text: &str, file: FileId) -> DomainUnit {
    let (domain, mut diagnostics) = crate::parse_domain(text, file);
    let index = match &domain {
        Some(d) => {
            let (index, diags) = crate::check_domain(d);
            diagnostics.extend(diags);
            index
        }
        None => DomainIndex::default(),
    };
    DomainUnit {
        file,
        domain,
        index,
        diagnostics,
    }
}

pub fn problem_unit(sources: &Sources, file: FileId, domain: &DomainUnit) -> ProblemUnit {
    problem_unit_from(
        sources.text(file),
        file,
        domain.domain.as_ref(),
        &domain.index,
    )
}

pub fn problem_unit_from(
    text: &str,
    file: FileId,
    domain: Option<&Domain>,
    dix: &DomainIndex,
) -> ProblemUnit {
    let (problem, diagnostics) = crate::parse_problem(text, file);
    problem_unit_of(problem, diagnostics, file, domain, dix)
}

/// A problem already made (parsed, or given as a value: see
/// [`crate::written_problem`]) checked against its domain; `diagnostics`
/// are what making it raised.
pub fn problem_unit_of(
    problem: Option<Problem>,
    mut diagnostics: Vec<Diagnostic>,
    file: FileId,
    domain: Option<&Domain>,
    dix: &DomainIndex,
) -> ProblemUnit {
    let index = match (&problem, domain) {
        (Some(p), Some(d)) => {
            let (index, diags) = crate::check_problem(p, d, dix);
            diagnostics.extend(diags);
            index
        }
        _ => ProblemIndex::default(),
    };
    ProblemUnit {
        file,
        problem,
        index,
        diagnostics,
    }
}

pub fn plan_unit(
    sources: &Sources,
    file: FileId,
    domain: &DomainUnit,
    problem: &ProblemUnit,
) -> PlanUnit {
    let (plan, mut diagnostics) = plan::parse_plan(sources.text(file), file);
    let mut steps = Vec::new();
    if let Some(d) = &domain.domain {
        let (s, diags) = plan::type_plan(&plan, d, &domain.index, &problem.index);
        steps = s;
        diagnostics.extend(diags);
    }
    PlanUnit {
        file,
        plan,
        steps,
        diagnostics,
    }
}

/// Validates a plan when every stage before it is free of errors; `None`
/// otherwise (their diagnostics say why).
pub fn validate_units(
    domain: &DomainUnit,
    problem: &ProblemUnit,
    plan: &PlanUnit,
) -> Option<Validation> {
    validate_units_with(domain, problem, plan, crate::validate::DEFAULT_EPSILON)
}

/// [`validate_units`] with a timed plan's separation tolerance.
pub fn validate_units_with(
    domain: &DomainUnit,
    problem: &ProblemUnit,
    plan: &PlanUnit,
    epsilon: f64,
) -> Option<Validation> {
    if has_errors(&domain.diagnostics)
        || has_errors(&problem.diagnostics)
        || has_errors(&plan.diagnostics)
    {
        return None;
    }
    let (d, p) = (domain.domain.as_ref()?, problem.problem.as_ref()?);
    // A checked, error-free domain and problem always make a world.
    let world = World::of_checked(d, &domain.index, p, &problem.index).ok()?;
    Some(validate_with(
        Replay::Cached,
        &world,
        d,
        p,
        &plan.plan,
        &plan.steps,
        epsilon,
    ))
}
