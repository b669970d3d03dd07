//! Matching plan steps against rule patterns: action names with captures
//! (case-insensitive), optional parameters, repeated variables, guards.

use super::ast::{Guard, NamePart, Pattern, Rule, TableDecl};

/// Captured parts of an action name, by capture name, as written in the plan.
pub type Captures = Vec<(String, String)>;

/// Matches an action name against a pattern's name parts; each capture
/// takes at least one character.
pub fn match_name(parts: &[NamePart], action: &str) -> Option<Captures> {
    let action = action.to_lowercase();
    let mut caps = Vec::new();
    go(parts, &action, &mut caps).then_some(caps)
}

fn go(parts: &[NamePart], rest: &str, caps: &mut Captures) -> bool {
    let Some((first, more)) = parts.split_first() else {
        return rest.is_empty();
    };
    match first {
        NamePart::Lit { text, .. } => {
            let lit = text.to_lowercase();
            rest.strip_prefix(lit.as_str())
                .is_some_and(|r| go(more, r, caps))
        }
        NamePart::Capture { name } => {
            // Shortest capture first, so `{a}_{b}` splits at the first `_`.
            for (i, _) in rest
                .char_indices()
                .skip(1)
                .chain(std::iter::once((rest.len(), ' ')))
            {
                if i == 0 {
                    continue;
                }
                caps.push((name.text.clone(), rest[..i].to_owned()));
                if go(more, &rest[i..], caps) {
                    return true;
                }
                caps.pop();
            }
            false
        }
    }
}

/// Which pattern parameter each step argument binds: `None` when the step's
/// argument count does not fit. Optional parameters are filled in order.
pub fn bind_params(pattern: &Pattern, argc: usize) -> Option<Vec<usize>> {
    let required = pattern.params.iter().filter(|p| !p.optional).count();
    if argc < required || argc > pattern.params.len() {
        return None;
    }
    let mut optional_left = argc - required;
    let mut out = Vec::with_capacity(argc);
    for (i, p) in pattern.params.iter().enumerate() {
        if p.optional {
            if optional_left == 0 {
                continue;
            }
            optional_left -= 1;
        }
        out.push(i);
    }
    Some(out)
}

/// Variable bindings of a matched step: variable name to object name.
pub type Bindings = Vec<(String, String)>;

/// What a guard needs to know about objects.
pub trait ObjectTypes {
    /// Whether `object` has a type that fits PDDL type `ty`.
    fn object_is(&self, object: &str, ty: &str) -> bool;
}

/// Matches a step (action name and arguments, lower-case) against a rule:
/// name, argument count, repeated variables, guards.
pub fn match_step(
    rule: &Rule,
    action: &str,
    args: &[String],
    tables: &dyn Fn(&str) -> Option<TableDecl>,
    types: &dyn ObjectTypes,
) -> Option<(Captures, Bindings)> {
    let caps = match_name(&rule.pattern.name, action)?;
    match_args(rule, caps, args, tables, types)
}

/// The rest of [`match_step`] once the name matched with `caps` (callers
/// that see the same action name often match names once).
pub fn match_args(
    rule: &Rule,
    caps: Captures,
    args: &[String],
    tables: &dyn Fn(&str) -> Option<TableDecl>,
    types: &dyn ObjectTypes,
) -> Option<(Captures, Bindings)> {
    let slots = bind_params(&rule.pattern, args.len())?;
    let mut bindings: Bindings = Vec::with_capacity(args.len());
    for (arg, &slot) in args.iter().zip(&slots) {
        let var = &rule.pattern.params[slot].var.text;
        match bindings.iter().find(|(v, _)| v == var) {
            Some((_, bound)) if bound != arg => return None, // repeated variable: equality
            Some(_) => {}
            None => bindings.push((var.clone(), arg.clone())),
        }
    }
    let value = |v: &str| {
        bindings
            .iter()
            .find(|(n, _)| n == v)
            .map(|(_, o)| o.as_str())
    };
    for g in &rule.guards {
        let ok = match g {
            Guard::Ne { left, right, .. } => value(&left.text) != value(&right.text),
            Guard::Eq { left, right, .. } => {
                value(&left.text).is_some() && value(&left.text) == value(&right.text)
            }
            Guard::IsType { var, ty, .. } => {
                value(&var.text).is_some_and(|o| types.object_is(o, &ty.text.to_lowercase()))
            }
            Guard::InTable { key, table, .. } => {
                let cap = caps
                    .iter()
                    .find(|(n, _)| *n == key.text)
                    .map(|(_, v)| v.as_str());
                match (cap, tables(&table.text)) {
                    (Some(c), Some(t)) => {
                        t.entries.iter().any(|e| e.key.text.eq_ignore_ascii_case(c))
                    }
                    _ => false,
                }
            }
        };
        if !ok {
            return None;
        }
    }
    Some((caps, bindings))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rules::{parse_rules, Item};

    fn rule(text: &str) -> Rule {
        match parse_rules(text, 0).items.remove(0).item {
            Item::Rule(r) => r,
            other => panic!("{other:?}"),
        }
    }

    struct AllTypes;
    impl ObjectTypes for AllTypes {
        fn object_is(&self, o: &str, _: &str) -> bool {
            o.starts_with('r')
        }
    }

    fn m(r: &Rule, action: &str, args: &[&str]) -> Option<(Captures, Bindings)> {
        let args: Vec<String> = args.iter().map(|s| s.to_string()).collect();
        match_step(r, action, &args, &|_| None, &AllTypes)
    }

    #[test]
    fn names_match_case_insensitively_with_captures() {
        let r = rule("rule (PICK_{op} ?a ?t [?loc]) { X() }");
        let (caps, b) = m(&r, "pick_op1", &["a", "t"]).unwrap();
        assert_eq!(caps, vec![("op".to_string(), "op1".to_string())]);
        assert_eq!(b.len(), 2);
        assert!(m(&r, "pick_op1", &["a", "t", "l"]).is_some());
        assert!(m(&r, "pick_op1", &["a"]).is_none());
        assert!(m(&r, "pick_", &["a", "t"]).is_none());
        assert!(m(&r, "place_op1", &["a", "t"]).is_none());
    }

    #[test]
    fn repeated_variables_and_guards() {
        let skip = rule("rule (move ?r ?x ?x) => skip");
        assert!(m(&skip, "MOVE", &["r1", "a", "a"]).is_some());
        assert!(m(&skip, "move", &["r1", "a", "b"]).is_none());
        let g = rule("rule (move ?r ?a ?b) where ?a != ?b, ?r - robot { X() }");
        assert!(m(&g, "move", &["r1", "a", "b"]).is_some());
        assert!(m(&g, "move", &["r1", "a", "a"]).is_none());
        assert!(m(&g, "move", &["x1", "a", "b"]).is_none());
    }

    #[test]
    fn two_captures_split_at_the_first_literal() {
        let r = rule("rule ({verb}_{op} ?a) { X() }");
        let (caps, _) = m(&r, "pick_op_1", &["a"]).unwrap();
        assert_eq!(caps[0].1, "pick");
        assert_eq!(caps[1].1, "op_1");
    }
}
