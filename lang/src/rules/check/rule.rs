//! A rule checked against the domain: the actions its pattern names, their
//! parameters, its guards, whether any step can match it, and its template
//! or `skip` once per action a step can come from.

use super::effect::compare_effect;
use super::values::Tcx;
use super::{scope_of, unknown_name, unknown_object, Decls, DomainCtx};
use crate::rules::ast::*;
use crate::rules::matching::Captures;
use crate::rules::reach::{reach, Never, Verdict};
use btc_pddl::check::check_effect_in;
use btc_pddl::diagnostic::{closest, codes, Diagnostic};
use btc_pddl::types::TypeId;
use std::collections::BTreeSet;

/// Variables of a rule pattern typed by one PDDL action's parameters.
fn rule_vars(
    rule: &Rule,
    action: Option<(&btc_pddl::ast::Action, &DomainCtx)>,
) -> Vec<(String, Option<Vec<TypeId>>)> {
    let mut vars: Vec<(String, Option<Vec<TypeId>>)> = Vec::new();
    for (i, p) in rule.pattern.params.iter().enumerate() {
        let ty = action.and_then(|(a, c)| {
            a.params
                .get(i)
                .map(|ap| c.index.types.resolve(&ap.ty, &mut Vec::new()))
        });
        match vars.iter_mut().find(|(v, _)| *v == p.var.text) {
            // A repeated variable must fit both parameters.
            Some((_, existing)) => {
                if let (Some(e), Some(t)) = (existing.as_ref(), ty.as_ref()) {
                    if let Some((_, c)) = action {
                        if c.index.types.fits(t, e) {
                            *existing = Some(t.clone());
                        }
                    }
                }
            }
            None => vars.push((p.var.text.clone(), ty)),
        }
    }
    vars
}

/// The actions a rule's template is typed by, from what the rule can reach
/// through its tables: those a step can come from, or, for a rule that can
/// match nothing, those it names.
fn typing_actions<'d>(
    through_tables: &[&(&'d btc_pddl::ast::Action, usize, Captures, Verdict)],
) -> Vec<&'d btc_pddl::ast::Action> {
    let can: Vec<&'d btc_pddl::ast::Action> = through_tables
        .iter()
        .filter(|(_, _, _, v)| *v == Verdict::Can)
        .map(|(a, _, _, _)| *a)
        .collect();
    if !can.is_empty() {
        return can;
    }
    through_tables
        .iter()
        .filter(|(_, _, _, v)| matches!(v, Verdict::Never(_)))
        .map(|(a, _, _, _)| *a)
        .collect()
}

/// What a rule's `?variable`s are, as the checker types them: for each
/// pattern variable in order, the types (as the domain writes them) of the
/// parameter it stands for in every action the template is checked
/// against. Empty lists without a domain or a matching action.
pub fn rule_var_types(r: &Rule, decls: &Decls, ctx: Option<DomainCtx>) -> Vec<VarTypes> {
    let mut out: Vec<VarTypes> = Vec::new();
    for p in &r.pattern.params {
        if !out.iter().any(|v| v.name == p.var.text) {
            out.push(VarTypes {
                name: p.var.text.clone(),
                types: Vec::new(),
            });
        }
    }
    let Some(c) = ctx else { return out };
    let reach = reach(r, decls, c);
    let through_tables = reach.meant();
    for action in typing_actions(&through_tables) {
        for v in &mut out {
            // The parameter at the variable's first position.
            let Some(pos) = r.pattern.params.iter().position(|p| p.var.text == v.name) else {
                continue;
            };
            if let Some(ap) = action.params.get(pos) {
                let t = ap.ty.to_string();
                if !v.types.contains(&t) {
                    v.types.push(t);
                }
            }
        }
    }
    out
}

/// One of a rule's variables and the types the checker gives it.
#[derive(Clone, Debug, PartialEq, Eq, Hash)]
pub struct VarTypes {
    pub name: String,
    pub types: Vec<String>,
}

pub(super) fn check_rule(r: &Rule, decls: &Decls, ctx: Option<DomainCtx>) -> Vec<Diagnostic> {
    let mut diags: Vec<Diagnostic> = Vec::new();
    let push = |d: Diagnostic, diags: &mut Vec<Diagnostic>| {
        if !diags.contains(&d) {
            diags.push(d);
        }
    };
    check_guards(r, decls, ctx, &mut |d| push(d, &mut diags));
    let captures_of = |matched: &[&Captures]| -> Vec<(String, Vec<String>)> {
        r.pattern
            .name
            .iter()
            .filter_map(|p| match p {
                NamePart::Capture { name } => Some(name.text.clone()),
                NamePart::Lit { .. } => None,
            })
            .map(|c| {
                let vals: BTreeSet<String> = matched
                    .iter()
                    .flat_map(|caps| caps.iter().filter(|(n, _)| *n == c).map(|(_, v)| v.clone()))
                    .collect();
                (c, vals.into_iter().collect())
            })
            .collect()
    };
    let Some(c) = ctx else {
        // No domain: check the template against declarations only.
        let mut tcx = Tcx {
            decls,
            ctx: None,
            vars: rule_vars(r, None),
            captures: captures_of(&[]),
            basic: Vec::new(),
            in_plan: false,
            imported: false,
            diags: Vec::new(),
        };
        if let RuleBody::Template { body, .. } = &r.body {
            for t in body {
                tcx.template(t);
            }
        }
        diags.extend(tcx.diags);
        return diags;
    };
    if r.pattern.name.is_empty() {
        return diags; // a pattern that did not parse: reported
    }
    let reach = reach(r, decls, c);
    let through_tables = reach.meant();
    if through_tables.is_empty() {
        let written = r.pattern.name_text();
        push(
            unknown_name(
                Diagnostic::error(
                    codes::R_UNKNOWN_ACTION,
                    r.pattern.name_span(),
                    format!("the domain has no action `{written}`"),
                ),
                r.pattern.name_key().as_str(),
                c.domain.actions.iter().map(|a| a.name.as_str()),
                str::to_owned,
                || {
                    let names: Vec<&str> =
                        c.domain.actions.iter().map(|a| a.name.as_str()).collect();
                    format!("the domain's actions are {}", names.join(", "))
                },
            ),
            &mut diags,
        );
        return diags;
    }
    let captures = captures_of(
        &through_tables
            .iter()
            .map(|(_, _, caps, _)| caps)
            .collect::<Vec<_>>(),
    );
    for (action, _, _, verdict) in &through_tables {
        if *verdict == Verdict::Arity {
            let required = r.pattern.params.iter().filter(|p| !p.optional).count();
            let total = r.pattern.params.len();
            let takes = if required == total {
                format!("{total}")
            } else {
                format!("{required} to {total}")
            };
            let params: Vec<String> = action
                .params
                .iter()
                .map(|p| format!("?{}", p.name.name))
                .collect();
            push(
                Diagnostic::error(
                    codes::R_PARAM_COUNT,
                    r.pattern.span,
                    format!(
                        "`{}` has {} parameters, but this pattern takes {takes}",
                        action.name.name,
                        action.params.len()
                    ),
                )
                .with_label(action.name.span, "the action is declared here")
                .with_hint(format!(
                    "write `({} {})`",
                    action.name.name,
                    params.join(" ")
                )),
                &mut diags,
            );
        }
    }
    if let Some(never) = reach.never() {
        push(never_diagnostic(r, never, &through_tables), &mut diags);
    }
    // The template is checked once per action a step can come from (its
    // variables are typed by that action's parameters); a rule that can
    // match nothing is still checked, with the actions it names.
    let none_can = !through_tables.iter().any(|(_, _, _, v)| *v == Verdict::Can);
    for action in typing_actions(&through_tables) {
        let vars = rule_vars(r, Some((action, &c)));
        let mut tcx = Tcx {
            decls,
            ctx: Some(c),
            vars: vars.clone(),
            captures: captures.clone(),
            basic: Vec::new(),
            in_plan: false,
            imported: false,
            diags: Vec::new(),
        };
        match &r.body {
            RuleBody::Template { body, effect } => {
                for t in body {
                    tcx.template(t);
                }
                if let Some(e) = effect {
                    let scope = scope_of(&vars);
                    tcx.diags
                        .extend(check_effect_in(c.domain, c.index, c.problem, e, &scope));
                    if let Some(d) = compare_effect(r, action, e) {
                        tcx.diags.push(d);
                    }
                }
            }
            // A rule no step can match skips nothing (R040-R043 say so).
            RuleBody::Skip { .. } if none_can => {}
            RuleBody::Skip { span } => {
                let changed = crate::rules::skip::changes(r, action);
                if !changed.is_empty() {
                    tcx.diags.push(
                        Diagnostic::warning(
                            codes::R_SKIP_CHANGES,
                            *span,
                            format!(
                                "`=> skip` drops steps of `{}`, which change the world: {}",
                                action.name.name,
                                changed
                                    .iter()
                                    .map(|l| format!("`{l}`"))
                                    .collect::<Vec<_>>()
                                    .join(", ")
                            ),
                        )
                        .with_label(action.name.span, "the PDDL action")
                        .with_hint("skip only steps that change nothing, such as a move to where the robot is (`(move ?r ?x ?x)`); give the rule a template to run the step"),
                    );
                }
            }
        }
        for d in tcx.diags {
            push(d, &mut diags);
        }
    }
    diags
}

/// Guards refer to the pattern's variables and captures, to the domain's
/// types, to declared tables, and to objects of the domain or problem.
fn check_guards(r: &Rule, decls: &Decls, ctx: Option<DomainCtx>, push: &mut dyn FnMut(Diagnostic)) {
    for g in &r.guards {
        let vars: Vec<&Ident> = match g {
            Guard::Ne { left, right, .. } | Guard::Eq { left, right, .. } => {
                [left, right].into_iter().filter_map(Operand::var).collect()
            }
            Guard::IsType { var, .. } => vec![var],
            Guard::InTable { .. } => vec![],
        };
        for v in vars {
            if !r.pattern.params.iter().any(|p| p.var.text == v.text) {
                push(Diagnostic::error(
                    codes::R_UNBOUND,
                    v.span,
                    format!("`?{}` is not a parameter of this rule's pattern", v.text),
                ));
            }
        }
        match g {
            Guard::InTable { key, table, .. } => {
                if !r
                    .pattern
                    .name
                    .iter()
                    .any(|p| matches!(p, NamePart::Capture { name } if name.text == key.text))
                {
                    push(Diagnostic::error(
                        codes::R_UNBOUND,
                        key.span,
                        format!("`{}` is not a capture of this rule's pattern", key.text),
                    ));
                }
                if !decls.tables.contains_key(&table.text) {
                    push(Diagnostic::error(
                        codes::R_UNKNOWN_TABLE,
                        table.span,
                        format!("no table is called `{}`", table.text),
                    ));
                }
            }
            Guard::IsType { ty, .. } => {
                if let Some(c) = ctx {
                    if c.index.types.id(ty.key.as_str()).is_none() {
                        let d = Diagnostic::error(
                            codes::R_UNKNOWN_TYPE,
                            ty.span,
                            format!("`{}` is not a type of the domain", ty.text),
                        );
                        push(match closest(ty.key.as_str(), c.index.types.names()) {
                            Some(t) => d.suggest(Some(t.to_owned()), String::new),
                            None => d,
                        });
                    }
                }
            }
            Guard::Ne { left, right, .. } | Guard::Eq { left, right, .. } => {
                let Some(c) = ctx else { continue };
                for o in [left, right] {
                    if let Operand::Object { name } = o {
                        if let Some(d) = object_in_scope(name, c) {
                            push(d);
                        }
                    }
                }
            }
        }
    }
}

/// R020 for an object name that neither the domain's constants nor the
/// problem (when there is one) has.
fn object_in_scope(name: &Ident, c: DomainCtx) -> Option<Diagnostic> {
    let k = name.key.as_str();
    if c.index.constants.contains_key(k) {
        return None;
    }
    let p = c.problem?; // without a problem, objects are unknown here
    if p.objects.contains_key(k) {
        return None;
    }
    let known = p
        .object_names
        .iter()
        .chain(&c.index.constant_names)
        .map(String::as_str);
    Some(unknown_object(&name.text, name.span, closest(k, known)))
}

/// The warning for a rule that no step can match, from the reason found
/// for the first action it names.
fn never_diagnostic(
    r: &Rule,
    never: &Never,
    named: &[&(&btc_pddl::ast::Action, usize, Captures, Verdict)],
) -> Diagnostic {
    let action = named
        .iter()
        .find(|(_, _, _, v)| matches!(v, Verdict::Never(n) if n == never))
        .map(|(a, _, _, _)| a.name.name.as_str())
        .unwrap_or_default();
    let others = named.len().saturating_sub(1);
    let also = if others == 0 {
        String::new()
    } else {
        format!(
            " (and no step of the {others} other action{} its pattern names can match)",
            if others == 1 { "" } else { "s" }
        )
    };
    let hint = "a rule no step can match runs nothing; fix or remove the guard, or remove the rule";
    match never {
        Never::SameObject { guard } => Diagnostic::warning(
            codes::R_CONTRADICTION,
            *guard,
            format!("this rule never matches: both sides of this `!=` are always the same object{also}"),
        )
        .with_hint(hint),
        Never::TwoObjects { first, second } => Diagnostic::warning(
            codes::R_CONTRADICTION,
            *second,
            format!("this rule never matches: one parameter would have to be two different objects{also}"),
        )
        .with_label(*first, "the other object")
        .with_hint(hint),
        Never::TypeGuard { guard, var, ty, has } => Diagnostic::warning(
            codes::R_GUARD_TYPE,
            *guard,
            format!("this rule never matches: `?{var}` is a `{has}` in `{action}`, and no `{has}` is a `{ty}`{also}"),
        )
        .with_hint(hint),
        Never::Disjoint { var, first, second } => Diagnostic::warning(
            codes::R_DISJOINT,
            second.0,
            format!("this rule never matches: `?{var}` would be one object that is both a `{}` and a `{}` in `{action}`, and the domain's types share none{also}", first.1, second.1),
        )
        .with_label(first.0, format!("a `{}` here", first.1))
        .with_hint(if r.guards.iter().any(|g| matches!(g, Guard::Eq { .. })) {
            hint
        } else {
            "a repeated variable asks for the same object twice; use two variables"
        }),
        Never::ObjectType { object, name, has, want } => Diagnostic::warning(
            codes::R_GUARD_OBJECT,
            *object,
            format!("this rule never matches: `{name}` is a `{has}`, and the parameter it is compared with takes a `{want}` in `{action}`{also}"),
        )
        .with_hint(hint),
    }
}
