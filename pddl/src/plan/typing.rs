//! Resolves every plan argument to an object of the problem (or a constant
//! of the domain) and checks it against the action's parameter types, as the
//! NIST executor does with the problem's `:objects`.

use super::parse::Plan;
use super::step::{Call, PlanStep};
use crate::ast::Domain;
use crate::check::{DomainIndex, ProblemIndex};
use crate::diagnostic::{codes, did_you_mean, Diagnostic};
use rustc_hash::FxHashMap;
use serde::Serialize;
use std::sync::Arc;

/// A plan step with its action and arguments resolved to ids.
#[derive(Clone, Debug, PartialEq, Eq, Serialize)]
pub struct GroundStep {
    /// Index into `plan.steps`.
    pub step: usize,
    /// Index into `domain.actions`.
    pub action: usize,
    /// Object ids (see [`ProblemIndex::object_names`]); shared by the
    /// steps that make the same call.
    pub args: Arc<[u32]>,
}

/// Types every step; steps with an error are left out of the result and
/// reported at their plan line.
pub fn type_plan(
    plan: &Plan,
    domain: &Domain,
    dix: &DomainIndex,
    pix: &ProblemIndex,
) -> (Vec<GroundStep>, Vec<Diagnostic>) {
    let mut out = Vec::with_capacity(plan.steps.len());
    let mut diags = Vec::new();
    // A call that typed once types again the same way; a call with an
    // error is typed at each step, which reports it there.
    let mut typed: FxHashMap<*const Call, (usize, Arc<[u32]>)> = FxHashMap::default();
    for (i, step) in plan.steps.iter().enumerate() {
        if let Some((action, args)) = typed.get(&Arc::as_ptr(&step.call)) {
            out.push(GroundStep {
                step: i,
                action: *action,
                args: args.clone(),
            });
        } else if let Some(g) = type_step(i, step, domain, dix, pix, &mut diags) {
            typed.insert(Arc::as_ptr(&step.call), (g.action, g.args.clone()));
            out.push(g);
        }
    }
    (out, diags)
}

fn type_step(
    i: usize,
    step: &PlanStep,
    domain: &Domain,
    dix: &DomainIndex,
    pix: &ProblemIndex,
    diags: &mut Vec<Diagnostic>,
) -> Option<GroundStep> {
    let Some(sig) = dix.actions.get(step.action_name()) else {
        let name = step.action();
        let d = Diagnostic::error(
            codes::PLAN_UNKNOWN_ACTION,
            name.span,
            format!("step {}: the domain has no action `{}`", i + 1, name.name),
        );
        diags.push(
            match did_you_mean(&name.name, dix.actions.keys().map(String::as_str)) {
                Some(h) => d.with_hint(h),
                None => d.with_hint("is this plan for another domain?"),
            },
        );
        return None;
    };
    let action = &domain.actions[sig.index];
    if step.arg_count() != sig.params.len() {
        let params: Vec<String> = action
            .params
            .iter()
            .map(|p| format!("?{} - {}", p.name.name, p.ty))
            .collect();
        diags.push(
            Diagnostic::error(
                codes::PLAN_ARITY,
                step.span,
                format!(
                    "step {}: `{}` takes {} argument{}, but the plan gives {}",
                    i + 1,
                    step.action_name(),
                    sig.params.len(),
                    if sig.params.len() == 1 { "" } else { "s" },
                    step.arg_count()
                ),
            )
            .with_label(
                action.name.span,
                format!("`{}` is declared here", step.action_name()),
            )
            .with_hint(format!("its parameters are ({})", params.join(" "))),
        );
        return None;
    }
    let mut args = Vec::with_capacity(step.arg_count());
    let mut ok = true;
    for (k, (arg, want)) in step.args().zip(&sig.params).enumerate() {
        let Some(obj) = pix.objects.get(arg.as_str()) else {
            let d = Diagnostic::error(
                codes::PLAN_UNKNOWN_OBJECT,
                arg.span,
                format!(
                    "step {}: `{}` is not an object of the problem or a constant of the domain",
                    i + 1,
                    arg.name
                ),
            );
            diags.push(
                match did_you_mean(&arg.name, pix.object_names.iter().map(String::as_str)) {
                    Some(h) => d.with_hint(h),
                    None => d.with_hint("is this plan for another problem?"),
                },
            );
            ok = false;
            continue;
        };
        if !dix.types.fits(&obj.types, want) {
            let p = &action.params[k];
            diags.push(
                Diagnostic::error(
                    codes::PLAN_TYPE,
                    arg.span,
                    format!(
                        "step {}: `{}` is a `{}`, but parameter `?{}` of `{}` takes a `{}`",
                        i + 1,
                        arg.name,
                        dix.types.display(&obj.types),
                        p.name.name,
                        step.action_name(),
                        dix.types.display(want)
                    ),
                )
                .with_label(obj.span, format!("`{}` is declared here", arg.name))
                .with_label(p.name.span, "the parameter is declared here"),
            );
            ok = false;
            continue;
        }
        args.push(obj.id);
    }
    ok.then_some(GroundStep {
        step: i,
        action: sig.index,
        args: args.into(),
    })
}
