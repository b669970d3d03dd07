//! `steps backchained`: the goal regressed through the plan (as
//! teleo-reactive programs and PA-BT do), so a tree ticked from any state
//! runs the latest step from which the rest of the plan reaches the goal.
//!
//! `R_m` is the goal; `R_{i-1}` is what must hold before step `i` for steps
//! `i..m` to reach the goal: step `i`'s conditions and whatever of `R_i` its
//! effects do not make true (at-end effects first, then at-start ones, so a
//! durative step regresses exactly as it runs). Stage `i` of the tree is
//! `Fallback(some R_j, j >= i, holds, Sequence(R_{i-1} holds, step i))`:
//! from any state it skips the steps before the latest one whose remaining
//! condition holds, runs the rest in order, and never checks achieved work
//! against effects of later steps.

use super::arrange::kb_holds;
use btc_ir::*;
use btc_pddl::logic::{Effect, Formula, Literal, Name};
use std::collections::BTreeSet;
use std::sync::Arc;

/// Why `steps backchained` cannot regress the goal through the plan: step
/// `step` makes false a literal (`what`) that the goal or a later step
/// needs, so the plan does not reach its goal.
pub(super) struct Breaks {
    pub step: usize,
    pub what: String,
}

/// A step's effect as regression sees it: the literals its plain adds and
/// deletes leave (adds win), and the predicates its quantified or
/// conditional parts may change, and whether it changes a fluent (action
/// costs aside).
#[derive(Default)]
struct StepEffect {
    lits: Vec<Literal>,
    touched: BTreeSet<Name>,
    numeric: bool,
}

impl StepEffect {
    fn of(e: &Effect) -> StepEffect {
        let mut out = StepEffect::default();
        out.collect(e, true);
        out
    }

    fn collect(&mut self, e: &Effect, plain: bool) {
        match e {
            Effect::And(parts) => parts.iter().for_each(|p| self.collect(p, plain)),
            Effect::Add(a) | Effect::Delete(a) if plain => {
                let positive = matches!(e, Effect::Add(_));
                match self.lits.iter_mut().find(|l| l.atom == *a) {
                    Some(l) => l.positive |= positive,
                    None => self.lits.push(Literal {
                        positive,
                        atom: a.clone(),
                    }),
                }
            }
            Effect::Add(a) | Effect::Delete(a) => {
                self.touched.insert(a.pred.clone());
            }
            Effect::Forall(_, x) | Effect::When(_, x) => self.collect(x, false),
            Effect::Numeric(_, f, _) if &*f.pred == "total-cost" => {}
            Effect::Numeric(..) => self.numeric = true,
        }
    }

    fn is_empty(&self) -> bool {
        self.lits.is_empty() && self.touched.is_empty() && !self.numeric
    }

    fn changes(&self, pred: &Name) -> bool {
        self.touched.contains(pred) || self.lits.iter().any(|l| l.atom.pred == *pred)
    }
}

/// A part of a remaining-plan condition: a literal, or a conjunct that is
/// not one (quantified, disjunctive, over derived predicates), by its index
/// in [`Opaque`].
#[derive(Clone, Debug, PartialEq, Eq, PartialOrd, Ord)]
enum Part {
    Lit(Literal),
    Opaque(usize),
}

/// A conjunction of parts, kept sorted and free of repeats.
type Condition = BTreeSet<Part>;

/// The conjuncts that are not literals, with the predicates they read. Such
/// a conjunct regresses unchanged through a step whose effects touch none
/// of them. Through a step that touches one, what it needs before the step
/// is not known: the necessary condition drops it (the step may achieve
/// it; it is checked where it is needed, by the goal or by the step whose
/// condition it is), the sufficient condition becomes false (nothing
/// before the step guarantees it).
#[derive(Default)]
struct Opaque {
    /// The conjunct, the predicates it reads, whether it reads a derived
    /// one or a fluent.
    parts: Vec<(Formula, BTreeSet<Name>, bool, bool)>,
}

impl Opaque {
    fn add(&mut self, f: &Formula, derived: &BTreeSet<Name>) -> Part {
        if let Some(i) = self.parts.iter().position(|(g, ..)| g == f) {
            return Part::Opaque(i);
        }
        let mut preds = BTreeSet::new();
        predicates(f, &mut preds);
        let reads_derived = preds.iter().any(|p| derived.contains(p));
        let reads_fluent = compares(f);
        self.parts
            .push((f.clone(), preds, reads_derived, reads_fluent));
        Part::Opaque(self.parts.len() - 1)
    }

    fn touched_by(&self, i: usize, eff: &StepEffect) -> bool {
        let (_, preds, reads_derived, reads_fluent) = &self.parts[i];
        // A derived predicate may depend on anything a step changes.
        (*reads_derived && !eff.is_empty())
            || (*reads_fluent && eff.numeric)
            || preds.iter().any(|p| eff.changes(p))
    }
}

fn compares(f: &Formula) -> bool {
    match f {
        Formula::Compare(..) => true,
        Formula::Atom(_) | Formula::Equal(..) => false,
        Formula::Not(x) | Formula::Exists(_, x) | Formula::Forall(_, x) => compares(x),
        Formula::And(ps) | Formula::Or(ps) => ps.iter().any(compares),
        Formula::Imply(l, r) => compares(l) || compares(r),
    }
}

fn predicates(f: &Formula, out: &mut BTreeSet<Name>) {
    match f {
        Formula::Atom(a) => {
            out.insert(a.pred.clone());
        }
        Formula::Equal(..) | Formula::Compare(..) => {}
        Formula::Not(x) | Formula::Exists(_, x) | Formula::Forall(_, x) => predicates(x, out),
        Formula::And(ps) | Formula::Or(ps) => ps.iter().for_each(|p| predicates(p, out)),
        Formula::Imply(l, r) => {
            predicates(l, out);
            predicates(r, out);
        }
    }
}

/// A condition's conjuncts as parts (equalities, static in a ground
/// formula, left out).
fn condition(f: &Formula, derived: &BTreeSet<Name>, opaque: &mut Opaque) -> Vec<Part> {
    let mut out = Vec::new();
    for c in f.conjuncts() {
        match c.literals() {
            Some(lits) if lits.iter().all(|l| !derived.contains(&l.atom.pred)) => {
                out.extend(lits.into_iter().map(Part::Lit));
            }
            _ => out.push(opaque.add(c, derived)),
        }
    }
    out
}

/// Which remaining-plan condition a regression computes.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Bound {
    /// What must hold for the rest of the plan to run: a conjunct a step
    /// may achieve in ways regression cannot follow is dropped.
    Necessary,
    /// What guarantees the rest of the plan runs: such a conjunct makes
    /// it false (`None`).
    Sufficient,
}

/// `r` regressed through effect `eff`: literals the effect makes true are
/// dropped; a literal it makes false cannot hold after it (`Err` names it;
/// a valid plan never does this); a literal or conjunct over a predicate
/// its quantified or conditional parts change, or over a derived one it
/// may change, is dropped or makes the condition false, by `bound`.
fn regress(
    r: &Condition,
    eff: &StepEffect,
    opaque: &Opaque,
    bound: Bound,
) -> Result<Option<Condition>, Literal> {
    let mut out = Condition::new();
    for p in r {
        let touched = match p {
            Part::Lit(l) => match eff.lits.iter().find(|e| e.atom == l.atom) {
                Some(e) if e.positive == l.positive => continue,
                Some(_) => return Err(l.clone()),
                None => eff.touched.contains(&l.atom.pred),
            },
            Part::Opaque(i) => opaque.touched_by(*i, eff),
        };
        match (touched, bound) {
            (false, _) => {
                out.insert(p.clone());
            }
            (true, Bound::Necessary) => {}
            (true, Bound::Sufficient) => return Ok(None),
        }
    }
    Ok(Some(out))
}

/// One step's conditions as parts and effects as outcomes.
struct PlainStep {
    pre_start: Vec<Part>,
    pre_later: Vec<Part>,
    eff_start: StepEffect,
    eff_end: StepEffect,
}

fn plain_step(info: &StepInfo, derived: &BTreeSet<Name>, opaque: &mut Opaque) -> PlainStep {
    let mut cond = |f: &Option<Arc<Formula>>| match f {
        None => Vec::new(),
        Some(f) => condition(f, derived, opaque),
    };
    let mut pre_later = cond(&info.logic.pre_over_all);
    pre_later.extend(cond(&info.logic.pre_end));
    let pre_start = cond(&info.logic.pre_start);
    let eff = |e: &Option<Arc<Effect>>| e.as_deref().map(StepEffect::of).unwrap_or_default();
    PlainStep {
        pre_start,
        pre_later,
        eff_start: eff(&info.logic.eff_start),
        eff_end: eff(&info.logic.eff_end),
    }
}

/// `R_0 ..= R_m` for `steps` (the plan's steps that are not skipped, in
/// order), each `None` where it is false; `Err((i, literal))` when step
/// `i` makes false a literal that the rest of the plan needs.
fn remaining(
    goal: &[Part],
    steps: &[PlainStep],
    opaque: &Opaque,
    bound: Bound,
) -> Result<Vec<Option<Condition>>, (usize, Literal)> {
    let mut conds = vec![None; steps.len() + 1];
    let mut r: Option<Condition> = Some(goal.iter().cloned().collect());
    conds[steps.len()] = r.clone();
    for (i, s) in steps.iter().enumerate().rev() {
        let Some(after) = &r else {
            // False stays false through every earlier step.
            break;
        };
        let mut next = match regress(after, &s.eff_end, opaque, bound).map_err(|l| (i, l))? {
            Some(c) => c,
            None => {
                r = None;
                continue;
            }
        };
        next.extend(s.pre_later.iter().cloned());
        r = regress(&next, &s.eff_start, opaque, bound).map_err(|l| (i, l))?;
        if let Some(c) = r.as_mut() {
            c.extend(s.pre_start.iter().cloned());
        }
        conds[i] = r.clone();
    }
    Ok(conds)
}

fn to_formula(c: &Condition, opaque: &Opaque) -> Formula {
    let parts = c
        .iter()
        .map(|p| match p {
            Part::Lit(l) => l.to_formula(),
            Part::Opaque(i) => opaque.parts[*i].0.clone(),
        })
        .collect();
    Formula::conjunction(parts).unwrap_or_else(Formula::truth)
}

/// The disjunction of `conds`, leaving out any that implies another (a
/// superset of its literals): it adds nothing to the disjunction.
fn any_of(conds: &[&Condition], opaque: &Opaque) -> Formula {
    let mut kept: Vec<&Condition> = Vec::new();
    for c in conds {
        if kept.iter().any(|k| k.is_subset(c)) {
            continue;
        }
        kept.retain(|k| !c.is_subset(k));
        kept.push(c);
    }
    match kept.as_slice() {
        [one] => to_formula(one, opaque),
        many => Formula::Or(many.iter().map(|c| to_formula(c, opaque)).collect()),
    }
}

/// The derived predicates of the domain (a remaining condition cannot
/// regress through what they are derived from).
pub(super) fn derived_predicates(domain: &btc_pddl::ast::Domain) -> BTreeSet<Name> {
    domain
        .derived
        .iter()
        .map(|d| btc_pddl::logic::name(&d.head.name.name))
        .collect()
}

/// The stages of `steps backchained`: one per step node that is not
/// skipped.
pub(super) fn stages(
    step_nodes: Vec<Option<Node>>,
    infos: &[StepInfo],
    goal: Option<&Formula>,
    derived: &BTreeSet<Name>,
) -> Result<Vec<Node>, Breaks> {
    let mut opaque = Opaque::default();
    let goal = goal.map_or_else(Vec::new, |g| condition(g, derived, &mut opaque));
    let run: Vec<(Node, &StepInfo)> = step_nodes
        .into_iter()
        .zip(infos)
        .filter_map(|(n, info)| n.map(|n| (n, info)))
        .collect();
    let plain = run
        .iter()
        .map(|(_, info)| plain_step(info, derived, &mut opaque))
        .collect::<Vec<_>>();
    let breaks = |(i, l): (usize, Literal)| Breaks {
        step: run[i].1.index,
        what: l.to_formula().to_string(),
    };
    // Necessary conditions never become false.
    let conds: Vec<Condition> = remaining(&goal, &plain, &opaque, Bound::Necessary)
        .map_err(breaks)?
        .into_iter()
        .map(Option::unwrap_or_default)
        .collect();
    let enough = remaining(&goal, &plain, &opaque, Bound::Sufficient).map_err(breaks)?;
    let mut out = Vec::with_capacity(run.len());
    for (i, (node, info)) in run.into_iter().enumerate() {
        let label = info.index + 1;
        // A step is skipped only when a later stage is sure to finish the
        // plan; it is tried when the rest of the plan may still run.
        let later: Vec<&Condition> = enough[i + 1..].iter().flatten().collect();
        let not_needed = (!later.is_empty()).then(|| any_of(&later, &opaque));
        let ready = to_formula(&conds[i], &opaque);
        // Before the first step: whether the plan can resume from here at
        // all, so a state none of its steps can continue from fails with
        // what each remaining condition lacks.
        let mut first = Vec::new();
        if i == 0 {
            let all: Vec<&Condition> = conds.iter().collect();
            first.push(kb_holds(
                Arc::new(any_of(&all, &opaque)),
                Some("plan can resume?".into()),
            ));
        }
        out.push(Node::Control {
            scripts: Default::default(),
            control: ControlKind::Fallback,
            name: Some(format!("step {label} {}", info.display()).into()),
            children: not_needed
                .map(|f| kb_holds(Arc::new(f), Some(format!("step {label} not needed?"))))
                .into_iter()
                .chain([Node::Control {
                    scripts: Default::default(),
                    control: ControlKind::Sequence,
                    name: None,
                    children: first
                        .into_iter()
                        .chain([
                            kb_holds(Arc::new(ready), Some(format!("step {label} ready?"))),
                            node,
                        ])
                        .collect(),
                }])
                .collect(),
        });
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use btc_pddl::logic::Atom;

    fn lit(positive: bool, pred: &str, args: &[&str]) -> Literal {
        Literal {
            positive,
            atom: Atom::ground(pred, args),
        }
    }

    fn step(pre: Vec<Literal>, eff: Vec<Literal>) -> PlainStep {
        PlainStep {
            pre_start: pre.into_iter().map(Part::Lit).collect(),
            pre_later: Vec::new(),
            eff_start: StepEffect::default(),
            eff_end: StepEffect {
                lits: eff,
                ..StepEffect::default()
            },
        }
    }

    #[test]
    fn a_later_step_that_re_adds_a_deleted_fact_does_not_undo_an_earlier_one() {
        // switch_on deletes (calibrated i); calibrate re-adds it. After both,
        // switch_on's remaining condition does not ask for (power_avail s).
        let on = step(
            vec![lit(true, "power_avail", &["s"])],
            vec![
                lit(true, "power_on", &["i"]),
                lit(false, "calibrated", &["i"]),
                lit(false, "power_avail", &["s"]),
            ],
        );
        let cal = step(
            vec![lit(true, "power_on", &["i"])],
            vec![lit(true, "calibrated", &["i"])],
        );
        let goal = vec![Part::Lit(lit(true, "calibrated", &["i"]))];
        let none = Opaque::default();
        let conds = remaining(&goal, &[on, cal], &none, Bound::Sufficient)
            .ok()
            .unwrap();
        let show = |c: &Option<Condition>| to_formula(c.as_ref().unwrap(), &none).to_string();
        assert_eq!(show(&conds[2]), "(calibrated i)");
        assert_eq!(show(&conds[1]), "(power_on i)");
        assert_eq!(show(&conds[0]), "(power_avail s)");
    }

    #[test]
    fn a_step_that_breaks_what_later_steps_need_makes_the_regression_unsatisfiable() {
        let s = step(Vec::new(), vec![lit(false, "p", &[])]);
        let goal = [Part::Lit(lit(true, "p", &[]))];
        let err = remaining(&goal, &[s], &Opaque::default(), Bound::Necessary)
            .err()
            .unwrap();
        assert_eq!(err, (0, lit(true, "p", &[])));
    }

    #[test]
    fn a_disjunction_keeps_only_the_weakest_conditions() {
        let a: Condition = [Part::Lit(lit(true, "p", &[]))].into_iter().collect();
        let ab: Condition = [lit(true, "p", &[]), lit(true, "q", &[])]
            .into_iter()
            .map(Part::Lit)
            .collect();
        assert_eq!(any_of(&[&ab, &a], &Opaque::default()).to_string(), "(p)");
    }

    #[test]
    fn a_quantified_goal_part_regresses_unchanged_until_a_step_touches_it() {
        let mut opaque = Opaque::default();
        let f = btc_pddl::logic::decode::formula("(forall (?x) (q ?x))").unwrap();
        let goal = vec![opaque.add(&f, &BTreeSet::new())];
        let steps = || {
            [
                step(Vec::new(), vec![lit(true, "q", &["a"])]),
                step(Vec::new(), vec![lit(true, "p", &[])]),
            ]
        };
        let show = |c: &Option<Condition>| c.as_ref().map(|c| to_formula(c, &opaque).to_string());
        let may = remaining(&goal, &steps(), &opaque, Bound::Necessary)
            .ok()
            .unwrap();
        assert_eq!(show(&may[2]).unwrap(), "(forall (?x) (q ?x))");
        assert_eq!(show(&may[1]).unwrap(), "(forall (?x) (q ?x))");
        assert_eq!(show(&may[0]).unwrap(), "(and)");
        // Nothing before the step that touches it guarantees the goal.
        let sure = remaining(&goal, &steps(), &opaque, Bound::Sufficient)
            .ok()
            .unwrap();
        assert_eq!(show(&sure[1]).unwrap(), "(forall (?x) (q ?x))");
        assert_eq!(show(&sure[0]), None);
    }
}
