//! Whether a plan is for a problem at all. A plan written for another
//! problem names objects this one lacks; reporting each use (L004, with a
//! "did you mean" among this problem's objects) would bury the one fact
//! that matters, so the object names are weighed together first.

use super::parse::Plan;
use crate::ast::Name;
use crate::check::ProblemIndex;
use crate::diagnostic::{codes, Diagnostic};
use crate::source::Span;

/// The object names of a plan against a problem's objects and constants.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct NameFit {
    /// Distinct argument names in the plan.
    pub names: usize,
    /// Names the problem does not have, each at its first use, in order.
    pub unknown: Vec<Name>,
}

impl NameFit {
    pub fn of(plan: &Plan, pix: &ProblemIndex) -> NameFit {
        // Plans are the user's own files, not hostile input: no need for
        // SipHash's flooding resistance on a name per argument.
        let mut seen = rustc_hash::FxHashSet::default();
        let mut unknown = Vec::new();
        // A call seen before has no name not seen before.
        let mut calls = rustc_hash::FxHashSet::default();
        for step in &plan.steps {
            if !calls.insert(std::sync::Arc::as_ptr(&step.call)) {
                continue;
            }
            for (k, name) in step.call.args.iter().enumerate() {
                if seen.insert(name.as_str()) && !pix.objects.contains_key(name.as_str()) {
                    unknown.push(step.args().nth(k).expect("the call's argument"));
                }
            }
        }
        NameFit {
            names: seen.len(),
            unknown,
        }
    }

    pub fn fits(&self) -> bool {
        self.unknown.is_empty()
    }

    /// Too many unknown names for typos: at least three, or at least half
    /// of the plan's names.
    pub fn looks_foreign(&self) -> bool {
        let u = self.unknown.len();
        u >= 3 || (u >= 1 && 2 * u >= self.names)
    }

    /// A plan that is not for this problem: names that look foreign, or a
    /// problem beside it (`fitting`) that has every name.
    pub fn misfits(&self, fitting: &[String]) -> bool {
        !self.fits() && (self.looks_foreign() || !fitting.is_empty())
    }

    /// The one diagnostic for a plan that does not fit `problem`, at the
    /// first unknown name; `fitting` are problems that have every name.
    pub fn diagnostic(
        &self,
        problem: &str,
        objects: Option<Span>,
        fitting: &[String],
    ) -> Diagnostic {
        let u = self.unknown.len();
        let shown: Vec<String> = self
            .unknown
            .iter()
            .take(5)
            .map(|n| format!("`{}`", n.name))
            .collect();
        let more = if u > shown.len() {
            format!(" and {} more", u - shown.len())
        } else {
            String::new()
        };
        let what = if u == 1 {
            format!("{} of its {} object names is", u, self.names)
        } else {
            format!("{} of its {} object names are", u, self.names)
        };
        let mut d = Diagnostic::error(
            codes::PLAN_MISFIT,
            self.unknown[0].span,
            format!(
                "this plan is not for problem `{problem}`: {what} not objects of it ({}{more})",
                shown.join(", ")
            ),
        );
        if let Some(s) = objects {
            d = d.with_label(s, "the problem's objects");
        }
        match fitting {
            [] => d.with_hint("no problem beside the plan has every object it names"),
            [one] => d.with_hint(format!("`{one}` beside it has every object the plan names")),
            many => d.with_hint(format!(
                "these problems beside it have every object the plan names: {}",
                many.iter()
                    .map(|p| format!("`{p}`"))
                    .collect::<Vec<_>>()
                    .join(", ")
            )),
        }
    }
}

/// The typing diagnostics of a plan with its unknown-object reports (L004)
/// replaced by one `misfit` diagnostic.
pub fn fold_unknown_objects(diags: &[Diagnostic], misfit: Diagnostic) -> Vec<Diagnostic> {
    let mut out = Vec::with_capacity(diags.len());
    let mut misfit = Some(misfit);
    for d in diags {
        if d.code == codes::PLAN_UNKNOWN_OBJECT.id {
            if let Some(m) = misfit.take() {
                out.push(m);
            }
        } else {
            out.push(d.clone());
        }
    }
    out.extend(misfit);
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::pipeline::{domain_unit_from, problem_unit_from};

    const DOMAIN: &str = "(define (domain d) (:types room)
        (:predicates (at ?r - room))
        (:action go :parameters (?from ?to - room)
          :precondition (at ?from) :effect (and (at ?to) (not (at ?from)))))";

    fn fit(problem: &str, plan: &str) -> (NameFit, Vec<Diagnostic>) {
        let du = domain_unit_from(DOMAIN, 0);
        let pu = problem_unit_from(problem, 1, du.domain.as_ref(), &du.index);
        let (plan, _) = crate::plan::parse_plan(plan, 2);
        let (_, diags) =
            crate::plan::type_plan(&plan, du.domain.as_ref().unwrap(), &du.index, &pu.index);
        (NameFit::of(&plan, &pu.index), diags)
    }

    const ABC: &str =
        "(define (problem p) (:domain d) (:objects a b c - room) (:init (at a)) (:goal (at c)))";

    #[test]
    fn a_typo_is_not_a_misfit() {
        let (f, _) = fit(ABC, "(go a b)\n(go b cc)\n");
        assert_eq!(f.names, 3);
        assert_eq!(f.unknown.len(), 1);
        assert!(!f.looks_foreign());
        assert!(!f.misfits(&[]));
        assert!(
            f.misfits(&["p02.pddl".into()]),
            "unless another problem has it"
        );
    }

    #[test]
    fn another_problems_names_fold_into_one_diagnostic() {
        let (f, diags) = fit(ABC, "(go x y)\n(go y z)\n(go z a)\n");
        assert_eq!(f.names, 4);
        assert!(f.looks_foreign());
        let l004 = diags.iter().filter(|d| d.code == "L004").count();
        assert_eq!(l004, 5, "x, y, y, z, z");
        let d = f.diagnostic("p.pddl", None, &["p02.pddl".into()]);
        assert_eq!(
            d.message,
            "this plan is not for problem `p.pddl`: 3 of its 4 object names are not objects of it (`x`, `y`, `z`)"
        );
        assert_eq!(
            d.hint.as_deref(),
            Some("`p02.pddl` beside it has every object the plan names")
        );
        let folded = fold_unknown_objects(&diags, d);
        assert_eq!(folded.iter().map(|d| d.code).collect::<Vec<_>>(), ["L010"]);
    }

    #[test]
    fn a_fitting_plan_fits() {
        let (f, diags) = fit(ABC, "(go a b)\n(go b c)\n");
        assert!(f.fits() && diags.is_empty());
        assert!(!f.misfits(&["other.pddl".into()]));
    }
}
