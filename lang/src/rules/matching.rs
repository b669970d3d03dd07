//! Matching plan steps against rule patterns: action names with captures
//! (case-insensitive), optional parameters, repeated variables, guards.
//!
//! Names are compared by key: a pattern's literal parts are folded when the
//! rule is parsed and PDDL action names are folded by the PDDL lexer, so
//! matching allocates nothing but the captures it returns.

use super::ast::{Guard, NamePart, Operand, Pattern, Rule, TableDecl};
use std::cell::Cell;

/// Captured parts of an action name, by capture name, as they stand in the
/// (folded) action name.
pub type Captures = Vec<(String, String)>;

thread_local! {
    static COMPARISONS: Cell<u64> = const { Cell::new(0) };
}

/// How many action names this thread has compared with a pattern so far:
/// what the shape tests count to show that checking is linear.
pub fn name_comparisons() -> u64 {
    COMPARISONS.with(Cell::get)
}

/// Counts one comparison of a pattern with an action name (for callers
/// that compare without [`match_name`], such as a lookup by name).
pub fn count_comparison() {
    COMPARISONS.with(|c| c.set(c.get() + 1));
}

/// Matches a PDDL action name (folded, as the PDDL front end gives it)
/// against a pattern's name parts. Each capture takes at least one
/// character; when the name splits in more than one way, captures are
/// filled from left to right and each takes the shortest part that lets
/// the rest of the pattern match. Linear in parts x name length.
pub fn match_name(parts: &[NamePart], action: &str) -> Option<Captures> {
    count_comparison();
    if let [NamePart::Lit { key, .. }] = parts {
        return (key.as_str() == action).then(Vec::new);
    }
    let n = action.len();
    let width = n + 1;
    // fits[i * width + p]: parts[i..] match action[p..]. Filled from the
    // last part back; a capture fits at p when the rest fits anywhere
    // after p's first character, so one running "fits later" flag serves.
    let mut fits = vec![false; (parts.len() + 1) * width];
    fits[parts.len() * width + n] = true;
    for (i, part) in parts.iter().enumerate().rev() {
        let (row, next) = (i * width, (i + 1) * width);
        match part {
            NamePart::Lit { key, .. } => {
                let lit = key.as_str();
                for p in 0..=n.saturating_sub(lit.len()) {
                    fits[row + p] = action.as_bytes()[p..].starts_with(lit.as_bytes())
                        && fits[next + p + lit.len()];
                }
            }
            NamePart::Capture { .. } => {
                let mut later = false;
                for p in (0..n).rev() {
                    later |= fits[next + p + 1];
                    fits[row + p] = later && action.is_char_boundary(p);
                }
            }
        }
    }
    if !fits[0] {
        return None;
    }
    let mut caps = Vec::new();
    let mut p = 0;
    for (i, part) in parts.iter().enumerate() {
        match part {
            NamePart::Lit { key, .. } => p += key.as_str().len(),
            NamePart::Capture { name } => {
                let next = (i + 1) * width;
                let end = (p + 1..=n)
                    .find(|&q| fits[next + q] && action.is_char_boundary(q))
                    .expect("the table says the rest fits");
                caps.push((name.text.clone(), action[p..end].to_owned()));
                p = end;
            }
        }
    }
    Some(caps)
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

/// Variable bindings of a matched step: variable name to object name,
/// borrowed from the rule and the step (a plan binds a few per step).
pub type Bindings<'a> = Vec<(&'a str, &'a str)>;

/// What a guard needs to know about objects.
pub trait ObjectTypes {
    /// Whether `object` has a type that fits PDDL type `ty` (both folded).
    fn object_is(&self, object: &str, ty: &str) -> bool;
}

/// Matches a step (action name and arguments, folded) against a rule:
/// name, argument count, repeated variables, guards.
pub fn match_step<'a>(
    rule: &'a Rule,
    action: &str,
    args: &'a [impl AsRef<str>],
    tables: &dyn Fn(&str) -> Option<TableDecl>,
    types: &dyn ObjectTypes,
) -> Option<(Captures, Bindings<'a>)> {
    let caps = match_name(&rule.pattern.name, action)?;
    let bindings = match_args(rule, &caps, args, tables, types)?;
    Some((caps, bindings))
}

/// The rest of [`match_step`] once the name matched with `caps`: the
/// bindings (callers that see the same action name often match names once,
/// and keep the captures: they are not copied per step).
pub fn match_args<'a>(
    rule: &'a Rule,
    caps: &Captures,
    args: &'a [impl AsRef<str>],
    tables: &dyn Fn(&str) -> Option<TableDecl>,
    types: &dyn ObjectTypes,
) -> Option<Bindings<'a>> {
    let slots = bind_params(&rule.pattern, args.len())?;
    let mut bindings: Bindings = Vec::with_capacity(args.len());
    for (arg, &slot) in args.iter().zip(&slots) {
        let (var, arg) = (rule.pattern.params[slot].var.text.as_str(), arg.as_ref());
        match bindings.iter().find(|(v, _)| *v == var) {
            Some((_, bound)) if *bound != arg => return None, // repeated variable: equality
            Some(_) => {}
            None => bindings.push((var, arg)),
        }
    }
    fn value<'a>(o: &'a Operand, bindings: &'a Bindings) -> Option<&'a str> {
        match o {
            Operand::Var { name } => bindings
                .iter()
                .find(|(n, _)| *n == name.text)
                .map(|(_, o)| *o),
            Operand::Object { name } => Some(name.key.as_str()),
        }
    }
    let value = |o| value(o, &bindings);
    for g in &rule.guards {
        let ok = match g {
            Guard::Ne { left, right, .. } => value(left) != value(right),
            Guard::Eq { left, right, .. } => value(left).is_some() && value(left) == value(right),
            Guard::IsType { var, ty, .. } => bindings
                .iter()
                .find(|(n, _)| *n == var.text)
                .is_some_and(|(_, o)| types.object_is(o, ty.key.as_str())),
            Guard::InTable { key, table, .. } => {
                let cap = caps
                    .iter()
                    .find(|(n, _)| *n == key.text)
                    .map(|(_, v)| v.as_str());
                match (cap, tables(&table.text)) {
                    (Some(c), Some(t)) => t.entries.iter().any(|e| e.key.key.as_str() == c),
                    _ => false,
                }
            }
        };
        if !ok {
            return None;
        }
    }
    Some(bindings)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rules::{parse_rules, Item};

    fn rule(text: &str) -> Rule {
        let parsed = parse_rules(text, 0);
        assert!(parsed.diagnostics.is_empty(), "{:#?}", parsed.diagnostics);
        match &*parsed.items[0].item {
            Item::Rule(r) => r.clone(),
            other => panic!("{other:?}"),
        }
    }

    struct AllTypes;
    impl ObjectTypes for AllTypes {
        fn object_is(&self, o: &str, _: &str) -> bool {
            o.starts_with('r')
        }
    }

    fn m<'a>(r: &'a Rule, action: &str, args: &'a [&'a str]) -> Option<(Captures, Bindings<'a>)> {
        match_step(r, action, args, &|_| None, &AllTypes)
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
        assert!(m(&skip, "move", &["r1", "a", "a"]).is_some());
        assert!(m(&skip, "move", &["r1", "a", "b"]).is_none());
        let g = rule("rule (move ?r ?a ?b) where ?a != ?b, ?r - robot { X() }");
        assert!(m(&g, "move", &["r1", "a", "b"]).is_some());
        assert!(m(&g, "move", &["r1", "a", "a"]).is_none());
        assert!(m(&g, "move", &["x1", "a", "b"]).is_none());
    }

    #[test]
    fn guards_compare_with_objects() {
        let g = rule("rule (move ?r ?a ?b) where ?r == \"Floor_Robot\", \"bin1\" != ?b { X() }");
        assert!(m(&g, "move", &["floor_robot", "a", "b"]).is_some());
        assert!(m(&g, "move", &["ceiling_robot", "a", "b"]).is_none());
        assert!(m(&g, "move", &["floor_robot", "a", "bin1"]).is_none());
    }

    #[test]
    fn two_captures_split_at_the_first_literal() {
        let r = rule("rule ({verb}_{op} ?a) { X() }");
        let (caps, _) = m(&r, "pick_op_1", &["a"]).unwrap();
        assert_eq!(caps[0].1, "pick");
        assert_eq!(caps[1].1, "op_1");
    }

    #[test]
    fn many_captures_stay_linear() {
        // Backtracking would try every split of the name for each capture.
        let r = rule("rule ({a}{b}{c}{d}{e}{f}x ?p) { X() }");
        let name = "y".repeat(5000);
        assert!(m(&r, &name, &["p"]).is_none());
        let (caps, _) = m(&r, &format!("{name}x"), &["p"]).unwrap();
        assert_eq!(caps[0].1, "y");
        assert_eq!(caps[5].1.len(), 4995);
    }
}
