//! Requirements: the flags a file declares (expanded, unknown and
//! unsupported ones reported), and the features it uses without declaring
//! the flag that allows them.

use super::*;

const KNOWN_REQUIREMENTS: &[&str] = &[
    "strips",
    "typing",
    "negative-preconditions",
    "disjunctive-preconditions",
    "equality",
    "existential-preconditions",
    "universal-preconditions",
    "quantified-preconditions",
    "conditional-effects",
    "fluents",
    "numeric-fluents",
    "object-fluents",
    "adl",
    "durative-actions",
    "duration-inequalities",
    "continuous-effects",
    "derived-predicates",
    "timed-initial-literals",
    "preferences",
    "constraints",
    "action-costs",
    "domain-axioms",
    "safety-constraints",
    "expression-evaluation",
    "open-world",
    "true-negation",
    "ucpop",
    "foreach-expansions",
    "dag-expansions",
    "subgoal-through-axioms",
];

const UNSUPPORTED_REQUIREMENTS: &[&str] = &[
    "object-fluents",
    "duration-inequalities",
    "continuous-effects",
    "timed-initial-literals",
    "preferences",
    "constraints",
    "domain-axioms",
    "safety-constraints",
    "open-world",
    "true-negation",
    "foreach-expansions",
    "dag-expansions",
    "subgoal-through-axioms",
    "expression-evaluation",
];

fn expand_requirement(r: &str, out: &mut FxHashSet<String>) {
    out.insert(r.to_owned());
    let implied: &[&str] = match r {
        "adl" | "ucpop" => &[
            "strips",
            "typing",
            "disjunctive-preconditions",
            "equality",
            "quantified-preconditions",
            "conditional-effects",
        ],
        "quantified-preconditions" => &["existential-preconditions", "universal-preconditions"],
        "fluents" => &["numeric-fluents"],
        "timed-initial-literals" => &["durative-actions"],
        _ => &[],
    };
    for i in implied {
        expand_requirement(i, out);
    }
}

/// Reads `:requirements` into a set, reporting unknown and unsupported flags.
pub(super) fn requirements(reqs: &[Name], diags: &mut Vec<Diagnostic>) -> FxHashSet<String> {
    let mut set = FxHashSet::default();
    for r in reqs {
        if !KNOWN_REQUIREMENTS.contains(&r.as_str()) {
            let d = Diagnostic::error(
                codes::UNKNOWN_REQUIREMENT,
                r.span,
                format!("`:{}` is not a PDDL requirement", r.name),
            );
            diags.push(
                match did_you_mean(&r.name, KNOWN_REQUIREMENTS.iter().copied()) {
                    Some(h) => d.with_hint(h),
                    None => d,
                },
            );
            continue;
        }
        if UNSUPPORTED_REQUIREMENTS.contains(&r.as_str()) {
            diags.push(
                Diagnostic::error(
                    codes::UNSUPPORTED,
                    r.span,
                    format!("the requirement `:{}` is not supported by btc", r.name),
                )
                .with_hint("btc supports STRIPS, typing, ADL conditions and effects, derived predicates, numeric fluents, action costs and durative actions"),
            );
        }
        expand_requirement(&r.name, &mut set);
    }
    if reqs.is_empty() {
        set.insert("strips".into());
    }
    set
}

/// A feature a file uses, for "used but not declared" warnings.
#[derive(Clone, Copy, PartialEq, Eq, Hash, Debug)]
pub(super) enum Feature {
    Typing,
    Negation,
    Disjunction,
    Equality,
    Existential,
    Universal,
    ConditionalEffects,
    Numeric,
    Durative,
    Derived,
}

impl Feature {
    /// The requirement flags that allow this feature (any one of them).
    pub(super) fn allowed_by(self) -> &'static [&'static str] {
        match self {
            Feature::Typing => &["typing"],
            Feature::Negation => &["negative-preconditions", "disjunctive-preconditions"],
            Feature::Disjunction => &["disjunctive-preconditions"],
            Feature::Equality => &["equality"],
            Feature::Existential => &["existential-preconditions"],
            Feature::Universal => &["universal-preconditions"],
            Feature::ConditionalEffects => &["conditional-effects"],
            Feature::Numeric => &["numeric-fluents", "action-costs"],
            Feature::Durative => &["durative-actions"],
            Feature::Derived => &["derived-predicates"],
        }
    }

    pub(super) fn describe(self) -> &'static str {
        match self {
            Feature::Typing => "typed names",
            Feature::Negation => "a negative condition (`not`)",
            Feature::Disjunction => "a disjunctive condition (`or` / `imply`)",
            Feature::Equality => "an equality test (`=`)",
            Feature::Existential => "an `exists` condition",
            Feature::Universal => "a `forall` condition",
            Feature::ConditionalEffects => "a conditional or quantified effect (`when` / `forall`)",
            Feature::Numeric => "numeric functions",
            Feature::Durative => "a durative action",
            Feature::Derived => "a derived predicate",
        }
    }
}

pub(super) fn undeclared_requirements(
    used: &FxHashMap<Feature, Span>,
    declared: &FxHashSet<String>,
) -> Vec<Diagnostic> {
    let mut out: Vec<Diagnostic> = used
        .iter()
        .filter(|(f, _)| !f.allowed_by().iter().any(|r| declared.contains(*r)))
        .map(|(f, span)| {
            let flag = f.allowed_by()[0];
            Diagnostic::warning(
                codes::UNDECLARED_REQUIREMENT,
                *span,
                format!(
                    "{} needs the requirement `:{flag}`, which is not declared",
                    f.describe()
                ),
            )
            .with_hint(format!("add `:{flag}` to `(:requirements ...)`"))
        })
        .collect();
    out.sort_by_key(|d| d.span.start);
    out
}
