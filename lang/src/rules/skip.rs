//! `=> skip` drops a step and its effects, so the reference says to skip
//! only steps that change nothing (a move to where the robot already is).
//! This finds what a skipped step of an action would have changed, under
//! what the rule pins down: its repeated variables and `==` guards.

use super::ast::{Guard, Operand, Rule};
use super::matching::bind_params;
use btc_pddl::ast::{Action, Atom, Effect, Formula, Term};
use std::collections::BTreeSet;

/// A ground-ish literal: predicate and arguments, each a rule variable
/// (`?x`, after `==` guards) or an object.
type Lit = (String, Vec<String>);

/// The effects of `a` that a step matched by `r` can change, written in the
/// rule's variables; empty when every effect is already what the
/// precondition requires (or there is none). Action costs are not changes.
pub fn changes(r: &Rule, a: &Action) -> Vec<String> {
    let Some(slots) = bind_params(&r.pattern, a.params.len()) else {
        return Vec::new();
    };
    // Rule variables made equal by `==` share one name; a variable equal to
    // an object is that object.
    let mut same: Vec<(String, String)> = Vec::new();
    let canon = |v: &str, same: &[(String, String)]| -> String {
        let mut cur = format!("?{v}");
        while let Some((_, to)) = same.iter().find(|(from, _)| *from == cur) {
            cur = to.clone();
        }
        cur
    };
    for g in &r.guards {
        if let Guard::Eq { left, right, .. } = g {
            let side = |o: &Operand, same: &[(String, String)]| match o {
                Operand::Var { name } => canon(&name.text, same),
                Operand::Object { name } => name.key.as_str().to_owned(),
            };
            let (l, rt) = (side(left, &same), side(right, &same));
            if l != rt {
                // Objects are never renamed: variables go to them.
                let (from, to) = if l.starts_with('?') { (l, rt) } else { (rt, l) };
                same.push((from, to));
            }
        }
    }
    let term = |t: &Term| -> Option<String> {
        match t {
            Term::Const { name } => Some(name.name.to_string()),
            Term::Var { name } => {
                let k = a.params.iter().position(|p| p.name.name == name.name)?;
                Some(canon(&r.pattern.params[slots[k]].var.text, &same))
            }
        }
    };
    let lit = |atom: &Atom| -> Option<Lit> {
        let args: Option<Vec<String>> = atom.args.iter().map(term).collect();
        Some((atom.pred.name.to_string(), args?))
    };
    let (mut pre_pos, mut pre_neg) = (BTreeSet::new(), BTreeSet::new());
    for f in a.pre_start.iter().chain(&a.pre_over_all) {
        preconditions(f, &lit, &mut pre_pos, &mut pre_neg);
    }
    let (mut adds, mut deletes, mut other) = (BTreeSet::new(), BTreeSet::new(), Vec::new());
    let mut stack: Vec<&Effect> = a.eff_start.iter().chain(&a.eff_end).collect();
    while let Some(e) = stack.pop() {
        match e {
            Effect::And { parts, .. } => stack.extend(parts),
            Effect::Add { atom } => match lit(atom) {
                Some(l) => {
                    adds.insert(l);
                }
                None => other.push(e.to_string()),
            },
            Effect::Delete { atom, .. } => match lit(atom) {
                Some(l) => {
                    deletes.insert(l);
                }
                None => other.push(e.to_string()),
            },
            Effect::Numeric { fluent, .. } if fluent.pred.name == "total-cost" => {}
            _ => other.push(e.to_string()),
        }
    }
    let show = |(p, args): &Lit| {
        let mut s = format!("({p}");
        for a in args {
            s.push(' ');
            s.push_str(a);
        }
        s.push(')');
        s
    };
    let mut out: Vec<String> = adds
        .iter()
        .filter(|l| !pre_pos.contains(*l))
        .map(show)
        .collect();
    out.extend(
        deletes
            .iter()
            .filter(|l| !adds.contains(*l) && !pre_neg.contains(*l))
            .map(|l| format!("(not {})", show(l))),
    );
    out.extend(other);
    out
}

/// The literals a precondition requires (conjunctions of atoms and negated
/// atoms; anything else requires nothing this check can use).
fn preconditions(
    f: &Formula,
    lit: &dyn Fn(&Atom) -> Option<Lit>,
    pos: &mut BTreeSet<Lit>,
    neg: &mut BTreeSet<Lit>,
) {
    match f {
        Formula::Atom { atom } => pos.extend(lit(atom)),
        Formula::Not { formula, .. } => {
            if let Formula::Atom { atom } = &**formula {
                neg.extend(lit(atom));
            }
        }
        Formula::And { parts, .. } => {
            for p in parts {
                preconditions(p, lit, pos, neg);
            }
        }
        _ => {}
    }
}
