//! The domain's action names, indexed for patterns: a literal name is one
//! hash lookup; a pattern with captures is compared only with the actions
//! that start with its first literal part or end with its last (whichever
//! are fewer), found by binary search in the names sorted forwards and
//! backwards. Checking a file of one rule per action is then linear.

use super::ast::{NamePart, Pattern};
use super::matching::{count_comparison, match_name, Captures};
use btc_pddl::ast::{Domain, SmolStr};
use rustc_hash::FxHashMap;

#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct ActionIndex {
    /// Action name to its indices in `domain.actions`, in domain order
    /// (more than one only when the domain repeats a name).
    by_name: FxHashMap<SmolStr, Vec<usize>>,
    /// (name, index), sorted by name.
    forwards: Vec<(SmolStr, usize)>,
    /// (name reversed, index), sorted by reversed name.
    backwards: Vec<(SmolStr, usize)>,
}

impl ActionIndex {
    pub fn new(domain: &Domain) -> ActionIndex {
        let mut by_name = FxHashMap::default();
        let mut forwards = Vec::with_capacity(domain.actions.len());
        let mut backwards = Vec::with_capacity(domain.actions.len());
        for (i, a) in domain.actions.iter().enumerate() {
            by_name
                .entry(a.name.name.clone())
                .or_insert_with(Vec::new)
                .push(i);
            forwards.push((a.name.name.clone(), i));
            backwards.push((a.name.name.chars().rev().collect(), i));
        }
        forwards.sort();
        backwards.sort();
        ActionIndex {
            by_name,
            forwards,
            backwards,
        }
    }

    /// The actions (indices into `domain.actions`, in domain order) whose
    /// names a pattern matches, with their captures.
    pub fn matches(&self, parts: &[NamePart], domain: &Domain) -> Vec<(usize, Captures)> {
        if let [NamePart::Lit { key, .. }] = parts {
            count_comparison();
            // The indices themselves: scanning the actions after the first
            // made a file of one rule per action quadratic.
            return self
                .by_name
                .get(key.as_str())
                .map_or_else(Vec::new, |is| is.iter().map(|&j| (j, Vec::new())).collect());
        }
        let prefix = match parts.first() {
            Some(NamePart::Lit { key, .. }) => key.as_str(),
            _ => "",
        };
        let suffix: String = match parts.last() {
            Some(NamePart::Lit { key, .. }) if parts.len() > 1 => {
                key.as_str().chars().rev().collect()
            }
            _ => String::new(),
        };
        let with_prefix = starting_with(&self.forwards, prefix);
        let with_suffix = starting_with(&self.backwards, &suffix);
        let candidates = if with_prefix.len() <= with_suffix.len() {
            with_prefix
        } else {
            with_suffix
        };
        let mut out: Vec<(usize, Captures)> = candidates
            .iter()
            .filter_map(|&(_, i)| match_name(parts, &domain.actions[i].name.name).map(|c| (i, c)))
            .collect();
        out.sort_by_key(|(i, _)| *i);
        out
    }
}

/// The entries of a sorted list whose names start with `prefix`.
fn starting_with<'a>(sorted: &'a [(SmolStr, usize)], prefix: &str) -> &'a [(SmolStr, usize)] {
    let from = sorted.partition_point(|(n, _)| n.as_str() < prefix);
    let len = sorted[from..].partition_point(|(n, _)| n.starts_with(prefix));
    &sorted[from..from + len]
}

/// The domain actions a rule pattern's name matches, with their captures
/// (in domain order).
pub fn matched_actions<'d>(
    pattern: &Pattern,
    domain: &'d Domain,
    actions: &ActionIndex,
) -> Vec<(&'d btc_pddl::ast::Action, Captures)> {
    actions
        .matches(&pattern.name, domain)
        .into_iter()
        .map(|(i, c)| (&domain.actions[i], c))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rules::{parse_rules, Item};

    fn parts(pattern: &str) -> Vec<NamePart> {
        let p = parse_rules(&format!("rule ({pattern}) => skip"), 0);
        match &*p.items[0].item {
            Item::Rule(r) => r.pattern.name.clone(),
            other => panic!("{other:?}"),
        }
    }

    #[test]
    fn finds_what_a_scan_finds() {
        let text = "(define (domain d) (:action load-truck) (:action load-airplane) (:action unload-truck) (:action drive-truck) (:action fly-airplane) (:action load))";
        let (domain, _) = btc_pddl::parse::parse_domain(text, 0);
        let domain = domain.unwrap();
        let ix = ActionIndex::new(&domain);
        for p in [
            "load-{v}",
            "{op}-truck",
            "{op}-{v}",
            "load",
            "LOAD-Truck",
            "{x}",
            "un{op}-{v}",
            "nothing-{x}",
        ] {
            let ps = parts(p);
            let scan: Vec<(usize, Captures)> = domain
                .actions
                .iter()
                .enumerate()
                .filter_map(|(i, a)| match_name(&ps, &a.name.name).map(|c| (i, c)))
                .collect();
            assert_eq!(ix.matches(&ps, &domain), scan, "{p}");
        }
    }
}
