//! Derived predicates in strata (stratified negation): the order they are
//! computed in, and the predicates that depend negatively on themselves.

use super::*;

/// Orders derived predicates into strata (stratified negation), reporting
/// predicates that depend negatively on themselves.
pub(super) fn stratify(
    domain: &Domain,
    index: &DomainIndex,
    diags: &mut Vec<Diagnostic>,
) -> Vec<Vec<usize>> {
    let n = domain.derived.len();
    if n == 0 {
        return Vec::new();
    }
    // uses[i]: (j, negative) — rule i's body mentions the predicate rule j derives.
    let uses: Vec<Vec<(usize, bool)>> = domain
        .derived
        .iter()
        .map(|d| {
            let mut out = Vec::new();
            collect_derived_uses(&d.body, true, &mut |name, positive| {
                if index.derived.contains(name) {
                    for (j, other) in domain.derived.iter().enumerate() {
                        if other.head.name.name == name {
                            out.push((j, !positive));
                        }
                    }
                }
            });
            out
        })
        .collect();
    match strata_of(&uses) {
        Some(strata) => strata,
        None => {
            let d = &domain.derived[0];
            diags.push(
                Diagnostic::error(
                    codes::NOT_STRATIFIED,
                    d.head.name.span,
                    "derived predicates depend on their own negation",
                )
                .with_hint(
                    "rewrite the `:derived` rules so no predicate depends on its own negation",
                ),
            );
            vec![(0..n).collect()]
        }
    }
}

/// Strata of derived rules from what each rule's body uses (`uses[i]`:
/// rules `j` it depends on, and whether through a negation): a rule comes
/// no earlier than what it uses, and after what it negates. `None` when a
/// rule depends on its own negation.
pub fn strata_of(uses: &[Vec<(usize, bool)>]) -> Option<Vec<Vec<usize>>> {
    let n = uses.len();
    let mut level = vec![0usize; n];
    // Bellman-Ford style relaxation; a level above n means a negative cycle.
    for _ in 0..=n {
        let mut changed = false;
        for i in 0..n {
            for &(j, neg) in &uses[i] {
                let need = level[j] + usize::from(neg);
                if level[i] < need {
                    level[i] = need;
                    changed = true;
                }
            }
        }
        if !changed {
            break;
        }
    }
    if level.iter().any(|&l| l > n) || has_negative_cycle(uses, n) {
        return None;
    }
    let max = level.iter().copied().max().unwrap_or(0);
    // Several rules may derive the same predicate: they share a level.
    Some(
        (0..=max)
            .map(|l| (0..n).filter(|&i| level[i] == l).collect())
            .filter(|v: &Vec<usize>| !v.is_empty())
            .collect(),
    )
}

fn has_negative_cycle(edges: &[Vec<(usize, bool)>], n: usize) -> bool {
    // A negative edge i -> j where j reaches i makes the program unstratifiable.
    let reach = |from: usize, to: usize| {
        let mut seen = vec![false; n];
        let mut stack = vec![from];
        while let Some(x) = stack.pop() {
            if x == to {
                return true;
            }
            if !std::mem::replace(&mut seen[x], true) {
                stack.extend(edges[x].iter().map(|e| e.0));
            }
        }
        false
    };
    (0..n).any(|i| edges[i].iter().any(|&(j, neg)| neg && reach(j, i)))
}

/// Calls `f(predicate, positive)` for each atom in a formula.
pub fn collect_derived_uses(f: &Formula, positive: bool, out: &mut impl FnMut(&str, bool)) {
    match f {
        Formula::Atom { atom } => out(atom.pred.as_str(), positive),
        Formula::Not { formula, .. } => collect_derived_uses(formula, !positive, out),
        Formula::And { parts, .. } | Formula::Or { parts, .. } => {
            for p in parts {
                collect_derived_uses(p, positive, out);
            }
        }
        Formula::Imply { left, right, .. } => {
            collect_derived_uses(left, !positive, out);
            collect_derived_uses(right, positive, out);
        }
        Formula::Exists { body, .. } | Formula::Forall { body, .. } => {
            collect_derived_uses(body, positive, out)
        }
        Formula::Equal { .. } | Formula::Compare { .. } => {}
    }
}
