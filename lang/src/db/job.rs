//! A compile job: a rules file and a plan, the plan typed against the
//! job's problem, and the compile to the tree IR.

use super::*;

/// The PDDL domain and problem of a compile job, checked, ready for a knowledge base or a validator.
pub struct JobWorld<'db> {
    pub domain: &'db btc_pddl::Domain,
    pub dix: &'db btc_pddl::DomainIndex,
    pub problem: &'db btc_pddl::Problem,
    pub pix: &'db btc_pddl::ProblemIndex,
}

impl<'db> JobWorld<'db> {
    /// The world of the job's domain and problem, ready for evaluation.
    pub fn world(&self) -> Result<btc_pddl::state::World, String> {
        btc_pddl::state::World::of_checked(self.domain, self.dix, self.problem, self.pix)
    }

    /// `None` when the job has no usable domain or problem.
    pub fn of(db: &'db Database, job: CompileJob) -> Option<JobWorld<'db>> {
        let d = job_domain(db, job)?;
        let p = job_problem(db, job)?;
        let cd = checked_domain(db, d);
        let cp = checked_problem(db, ProblemOf::new(db, p, d));
        Some(JobWorld {
            domain: cd.domain.as_ref()?,
            dix: &cd.index,
            problem: cp.problem.as_ref()?,
            pix: &cp.index,
        })
    }
}

/// What `btc compile` is asked: a rules file and a plan, with the problem
/// and domain when they are not named in the rules file.
#[salsa::input(debug)]
pub struct CompileJob {
    #[returns(copy)]
    pub rules: SourceFile,
    #[returns(copy)]
    pub plan: SourceFile,
    #[returns(copy)]
    pub problem: Option<SourceFile>,
    #[returns(copy)]
    pub domain: Option<SourceFile>,
}

/// The domain a job uses: given explicitly, or named by the rules file.
pub fn job_domain(db: &dyn Db, job: CompileJob) -> Option<SourceFile> {
    job.domain(db).or_else(|| domain_file(db, job.rules(db)))
}

pub fn job_problem(db: &dyn Db, job: CompileJob) -> Option<SourceFile> {
    job.problem(db).or_else(|| problem_file(db, job.rules(db)))
}

/// Every diagnostic a compile job raises before lowering (rules, imports,
/// domain, problem, plan), in the order of [`crate::project::job_report`].
#[salsa::tracked(returns(ref))]
pub fn job_diagnostics(db: &dyn Db, job: CompileJob) -> Vec<Diagnostic> {
    crate::project::flatten(crate::project::job_report(db, job))
}

#[derive(Clone, Debug, PartialEq)]
pub struct TypedPlan {
    pub plan: btc_pddl::plan::Plan,
    pub steps: Vec<btc_pddl::plan::GroundStep>,
    pub diagnostics: Vec<Diagnostic>,
}

#[salsa::tracked(returns(ref))]
pub fn typed_plan(db: &dyn Db, job: CompileJob) -> TypedPlan {
    let pf = job.plan(db);
    let file = file_id(db, pf);
    let (plan, mut diagnostics) = match pf.value(db) {
        Some(crate::db::FileValue::Plan(w)) => {
            let diags = if w.is_empty() {
                vec![btc_pddl::plan::parse::no_steps(file)]
            } else {
                Vec::new()
            };
            (w.plan(file), diags)
        }
        _ => btc_pddl::plan::parse_plan(pf.text(db), file),
    };
    let mut steps = Vec::new();
    if let (Some(d), Some(p)) = (job_domain(db, job), job_problem(db, job)) {
        let cd = checked_domain(db, d);
        let cp = checked_problem(db, ProblemOf::new(db, p, d));
        if let Some(domain) = &cd.domain {
            let (s, diags) = btc_pddl::plan::type_plan(&plan, domain, &cd.index, &cp.index);
            steps = s;
            diagnostics.extend(diags);
        }
    }
    TypedPlan {
        plan,
        steps,
        diagnostics,
    }
}

/// Compiles a job to the tree IR, or returns why not (errors only; see
/// [`job_diagnostics`] for warnings).
///
/// The IR is shared so a caller can keep it and drop the database: a long
/// plan's text, parse and replay are half of what a compile holds, and an
/// emitter needs none of them (`btc compile` frees them before it writes).
#[salsa::tracked(returns(ref))]
pub fn compile(db: &dyn Db, job: CompileJob) -> Result<Arc<btc_ir::TreeIr>, Vec<Diagnostic>> {
    lower_job(db, job).map(Arc::new)
}

/// [`compile`], not memoized: the IR is the caller's alone (no copy to
/// change it), and the database keeps none. `btc compile -o` lowers and
/// emits this way on a second core while the plan is replayed.
pub fn lower_job(db: &dyn Db, job: CompileJob) -> Result<btc_ir::TreeIr, Vec<Diagnostic>> {
    let diags = job_diagnostics(db, job);
    if btc_pddl::diagnostic::has_errors(diags) {
        return Err(diags.iter().filter(|d| d.is_error()).cloned().collect());
    }
    let rules = job.rules(db);
    let (Some(d), Some(p)) = (job_domain(db, job), job_problem(db, job)) else {
        return Err(Vec::new());
    };
    let cd = checked_domain(db, d);
    let cp = checked_problem(db, ProblemOf::new(db, p, d));
    let (Some(domain), Some(problem)) = (&cd.domain, &cp.problem) else {
        return Err(Vec::new());
    };
    let tp = typed_plan(db, job);
    let mut all_rules = Vec::new();
    let mut plan_template = None;
    for f in &import_closure(db, rules).0 {
        for n in &parsed_rules(db, *f).items {
            match &*n.item {
                Item::Rule(r) => all_rules.push(r),
                Item::Plan { body, .. } if *f == rules && plan_template.is_none() => {
                    plan_template = Some(body.as_slice())
                }
                _ => {}
            }
        }
    }
    let input = crate::lower::LowerInput {
        decls: declarations(db, rules),
        rules: all_rules,
        plan_template,
        domain,
        dix: &cd.index,
        problem,
        pix: &cp.index,
        plan: &tp.plan,
        steps: &tp.steps,
        domain_path: d.path(db).to_string(),
        problem_path: p.path(db).to_string(),
        plan_path: job.plan(db).path(db).to_string(),
        rules_path: rules.path(db).to_string(),
    };
    crate::lower::lower(&input)
}
