//! Generated inputs for scaling benchmarks and shape tests: a PDDL domain of
//! `n` actions and a rules file with one rule per action, the shape in which
//! a user meets a large domain (issue #14). Action names are hyphenated and
//! come in four kinds, so the rules exercise templates, decorators, guards
//! and strings the way hand-written ones do.

use std::fmt::Write;

/// The four kinds of action, cycled: name, parameters, precondition, effect.
const KINDS: &[(&str, &str, &str, &str)] = &[
    (
        "move-{i}-fast",
        "?r - robot ?from - location ?to - location",
        "(at ?r ?from)",
        "(and (not (at ?r ?from)) (at ?r ?to))",
    ),
    (
        "pick-{i}-part",
        "?r - robot ?p - part ?l - location",
        "(and (at ?r ?l) (on ?p ?l) (free ?r))",
        "(and (holding ?r ?p) (not (on ?p ?l)) (not (free ?r)))",
    ),
    (
        "place-{i}-part",
        "?r - robot ?p - part ?l - location",
        "(and (at ?r ?l) (holding ?r ?p))",
        "(and (on ?p ?l) (free ?r) (not (holding ?r ?p)))",
    ),
    (
        "inspect-{i}",
        "?r - robot ?l - location",
        "(at ?r ?l)",
        "(inspected ?l)",
    ),
];

/// The name of action `i` of the generated domain.
pub fn action_name(i: usize) -> String {
    KINDS[i % KINDS.len()].0.replace("{i}", &i.to_string())
}

/// A STRIPS domain with typing and `n` actions.
pub fn domain(n: usize) -> String {
    let mut s = String::from(
        "(define (domain scale)\n  (:requirements :strips :typing)\n  (:types robot location part - object tool - part)\n  (:predicates (at ?r - robot ?l - location) (on ?p - part ?l - location)\n    (holding ?r - robot ?p - part) (free ?r - robot) (inspected ?l - location))\n",
    );
    for i in 0..n {
        let (_, params, pre, eff) = KINDS[i % KINDS.len()];
        let _ = writeln!(
            s,
            "  (:action {}\n    :parameters ({params})\n    :precondition {pre}\n    :effect {eff})",
            action_name(i)
        );
    }
    s.push_str(")\n");
    s
}

/// A rules file for [`domain`]`(n)` (at `domain_path`, relative to the
/// rules file) with one rule per action.
pub fn rules(n: usize, domain_path: &str) -> String {
    let mut s = format!(
        "domain \"{domain_path}\"\n\naction MoveTo(robot: robot, target: location)\naction Grasp(robot: robot, part: part)\naction Place(robot: robot, part: part, target: location)\naction Inspect(robot: robot, at: location)\naction Report(message: string)\ncondition Free(robot: robot) = (free ?robot)\n\ntree Approach(robot: robot, target: location) {{\n    retry(3) MoveTo(robot: ?robot, target: ?target)\n}}\n\n"
    );
    for i in 0..n {
        let name = action_name(i);
        let _ = match i % KINDS.len() {
            0 => writeln!(
                s,
                "rule ({name} ?r ?from ?to) where ?from != ?to {{\n    Approach(robot: ?r, target: ?to)\n}}"
            ),
            1 => writeln!(
                s,
                "rule ({name} ?r ?p ?l) {{\n    sequence \"pick {{?p}} at {{?l}}\" {{\n        Free(robot: ?r)\n        Grasp(robot: ?r, part: ?p)\n    }}\n}}"
            ),
            2 => writeln!(
                s,
                "rule ({name} ?r ?p ?l) {{\n    sequence {{\n        Place(robot: ?r, part: ?p, target: ?l)\n        Report(message: \"placed {{?p}}\")\n    }}\n}}"
            ),
            _ => writeln!(
                s,
                "rule ({name} ?r ?l) {{\n    timeout(500) Inspect(robot: ?r, at: ?l)\n}}"
            ),
        };
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn one_rule_per_action() {
        let d = domain(8);
        let r = rules(8, "domain.pddl");
        assert_eq!(d.matches("(:action ").count(), 8);
        assert_eq!(r.matches("\nrule (").count(), 8);
        assert!(r.contains("rule (inspect-7 ?r ?l)"));
    }
}
