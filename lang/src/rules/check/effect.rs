//! A rule's `effect` against its PDDL action's: what it leaves out or adds,
//! and the PDDL effect rewritten in the rule's variables (the quick fix).

use crate::rules::ast::*;
use btc_pddl::ast::Effect;
use btc_pddl::diagnostic::{codes, Diagnostic};
use std::collections::BTreeSet;

/// Literals of a plain effect (`and` of atoms and `not` atoms), with
/// variables replaced by their parameter positions. `None` when the effect
/// has quantified, conditional or numeric parts.
fn literals(
    effects: &[&Effect],
    position: &dyn Fn(&str) -> Option<usize>,
) -> Option<BTreeSet<(bool, String, Vec<String>)>> {
    let mut out = BTreeSet::new();
    let mut stack: Vec<&Effect> = effects.to_vec();
    while let Some(e) = stack.pop() {
        let (positive, atom) = match e {
            Effect::Add { atom } => (true, atom),
            Effect::Delete { atom, .. } => (false, atom),
            Effect::And { parts, .. } => {
                stack.extend(parts.iter());
                continue;
            }
            _ => return None,
        };
        let args = atom
            .args
            .iter()
            .map(|t| match t {
                btc_pddl::ast::Term::Var { name } => {
                    position(&name.name).map_or(format!("?{}", name.name), |i| format!("#{i}"))
                }
                btc_pddl::ast::Term::Const { name } => name.name.to_string(),
            })
            .collect();
        out.insert((positive, atom.pred.name.to_string(), args));
    }
    Some(out)
}

/// A warning when a rule's effect is not the PDDL action's effect, with the
/// PDDL effect written in the rule's variables as the hint (the quick fix).
pub(super) fn compare_effect(
    r: &Rule,
    action: &btc_pddl::ast::Action,
    effect: &Effect,
) -> Option<Diagnostic> {
    let rule_pos = |v: &str| r.pattern.params.iter().position(|p| p.var.text == v);
    let action_pos = |v: &str| action.params.iter().position(|p| p.name.name == v);
    let pddl: Vec<&Effect> = action.eff_start.iter().chain(&action.eff_end).collect();
    let mine = literals(&[effect], &rule_pos)?;
    let theirs = literals(&pddl, &action_pos)?;
    if mine == theirs {
        return None;
    }
    let show = |l: &(bool, String, Vec<String>)| show_literal(l, r);
    let missing: Vec<String> = theirs.difference(&mine).map(show).collect();
    let extra: Vec<String> = mine.difference(&theirs).map(show).collect();
    let mut parts = Vec::new();
    if !missing.is_empty() {
        parts.push(format!("it leaves out {}", missing.join(", ")));
    }
    if !extra.is_empty() {
        parts.push(format!("it adds {}", extra.join(", ")));
    }
    let rewritten = rewrite_effect(&pddl, action, r);
    Some(
        Diagnostic::warning(
            codes::R_EFFECT_DIFFERS,
            effect.span(),
            format!(
                "this effect differs from the effect of the PDDL action `{}`: {}",
                action.name.name,
                parts.join("; ")
            ),
        )
        .with_label(action.name.span, "the PDDL action")
        .with_hint(format!(
            "the PDDL effect in this rule's variables: `effect {rewritten}`"
        ))
        .with_fix("write the PDDL action's effect", effect.span(), rewritten),
    )
}

/// A literal in the rule's own variables (`#i` is parameter i).
fn show_literal((positive, pred, args): &(bool, String, Vec<String>), r: &Rule) -> String {
    let arg = |a: &String| match a.strip_prefix('#').and_then(|i| i.parse::<usize>().ok()) {
        Some(i) => r.pattern.params.get(i).map_or_else(
            || format!("parameter {}", i + 1),
            |p| format!("?{}", p.var.text),
        ),
        None => a.clone(),
    };
    let atom = format!(
        "({pred}{})",
        args.iter()
            .map(|a| format!(" {}", arg(a)))
            .collect::<String>()
    );
    if *positive {
        format!("`{atom}`")
    } else {
        format!("`(not {atom})`")
    }
}

/// The PDDL action's effect with its parameters renamed to the rule's
/// variables (by the fold: all at once, so swaps work, and quantified
/// variables are renamed out of the way).
pub fn rewrite_effect(effects: &[&Effect], action: &btc_pddl::ast::Action, r: &Rule) -> String {
    use btc_pddl::logic::{self, Renaming, Terms};
    let parts: Vec<logic::Effect> = effects.iter().map(|e| logic::Effect::from_ast(e)).collect();
    let effect = match <[logic::Effect; 1]>::try_from(parts) {
        Ok([one]) => one,
        Err(many) => logic::Effect::And(many),
    };
    let pairs: Vec<(logic::Name, logic::Name)> = action
        .params
        .iter()
        .zip(&r.pattern.params)
        .map(|(p, rp)| (logic::name(&p.name.name), logic::name(&rp.var.text)))
        .collect();
    effect.rename(&Renaming { pairs: &pairs }).to_string()
}
