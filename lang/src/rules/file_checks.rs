//! Checks that look at a whole rules file: one `domain` and one `plan`,
//! names declared once, every action covered by a rule that can match
//! (R012), no rule made useless by an earlier one (R013), no declaration
//! left unused (R014).
//!
//! They run over small per-item summaries ([`ItemHead`], [`ItemUses`],
//! [`RuleFacts`]) that an edit inside a rule's body leaves equal, so the
//! database does not run them again for such an edit; and each is linear
//! in the number of items (shadowing: in the number of rule-action pairs),
//! with no name matching of its own.

use super::ast::*;
use super::decls::{Decls, DomainCtx};
use super::reach::{matches_every_step, reach, Verdict};
use btc_pddl::ast::Domain;
use btc_pddl::diagnostic::{closest, codes, Diagnostic};
use btc_pddl::source::{FileId, Span};
use std::collections::{BTreeMap, BTreeSet};

/// What the file-level checks need of one item, none of it from a body.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct ItemHead {
    pub kind: HeadKind,
    /// The declared name of a node, tree or table, and its span.
    pub name: Option<(String, Span)>,
    /// A rule's pattern; the whole item otherwise (item-relative).
    pub span: Span,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum HeadKind {
    Domain,
    Problem,
    Import,
    Node,
    Tree,
    Table,
    Rule,
    Plan,
    Error,
}

pub fn head(item: &Item) -> ItemHead {
    let (kind, name) = match item {
        Item::Domain { .. } => (HeadKind::Domain, None),
        Item::Problem { .. } => (HeadKind::Problem, None),
        Item::Import { .. } => (HeadKind::Import, None),
        Item::Node(n) => (HeadKind::Node, Some(&n.name)),
        Item::Tree(t) => (HeadKind::Tree, Some(&t.name)),
        Item::Table(t) => (HeadKind::Table, Some(&t.name)),
        Item::Rule(_) => (HeadKind::Rule, None),
        Item::Plan { .. } => (HeadKind::Plan, None),
        Item::Error { .. } => (HeadKind::Error, None),
    };
    ItemHead {
        kind,
        name: name.map(|n| (n.text.clone(), n.span)),
        span: match item {
            Item::Rule(r) => r.pattern.span,
            other => other.span(),
        },
    }
}

/// The nodes, trees and tables an item refers to, and whether a part of it
/// did not parse (then nothing can be called unused).
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct ItemUses {
    pub names: BTreeSet<String>,
    pub broken: bool,
}

pub fn uses(item: &Item) -> ItemUses {
    fn value(v: &Value, out: &mut ItemUses) {
        if let Value::Lookup { table, key, .. } = v {
            out.names.insert(table.text.clone());
            value(key, out);
        }
    }
    fn template(t: &Template, out: &mut ItemUses) {
        t.walk(&mut |t| match t {
            Template::Decorator { args, .. } => args.iter().for_each(|a| value(&a.value, out)),
            Template::Call { name, args, .. } => {
                out.names.insert(name.text.clone());
                args.iter().for_each(|a| value(&a.value, out));
            }
            Template::Error { .. } => out.broken = true,
            Template::Control { .. } | Template::Steps { .. } | Template::Script { .. } => {}
        });
    }
    let mut out = ItemUses::default();
    match item {
        Item::Rule(r) => {
            for g in &r.guards {
                if let Guard::InTable { table, .. } = g {
                    out.names.insert(table.text.clone());
                }
            }
            if let RuleBody::Template { body, .. } = &r.body {
                body.iter().for_each(|t| template(t, &mut out));
            }
        }
        Item::Tree(t) => t.body.iter().for_each(|b| template(b, &mut out)),
        Item::Plan { body, .. } => body.iter().for_each(|b| template(b, &mut out)),
        Item::Error { .. } => out.broken = true,
        _ => {}
    }
    out
}

/// What the file-level checks need of one rule: the actions some of whose
/// steps it can match (indices into the domain's actions, ascending),
/// whether it matches every step of them, and the actions it was meant for
/// but cannot match for a reason reported as an error: the one its
/// misspelled name likely meant (R002), those whose parameter count it does
/// not fit (R003). R012 does not report those again.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct RuleFacts {
    pub actions: Vec<usize>,
    pub every_step: bool,
    pub meant: Vec<usize>,
}

pub fn rule_facts(r: &Rule, decls: &Decls, ctx: DomainCtx) -> RuleFacts {
    if r.pattern.name.is_empty() {
        return RuleFacts::default();
    }
    let reach = reach(r, decls, ctx);
    let named = reach.named.iter().any(|(_, _, _, v)| v.is_for());
    let mut meant: Vec<usize> = reach
        .named
        .iter()
        .filter(|(_, _, _, v)| *v == Verdict::Arity)
        .map(|(_, i, _, _)| *i)
        .collect();
    if !named {
        let want = r.pattern.name_key();
        let likely = closest(
            want.as_str(),
            ctx.domain.actions.iter().map(|a| a.name.as_str()),
        );
        meant.extend(likely.and_then(|n| ctx.domain.actions.iter().position(|a| a.name.name == n)));
    }
    RuleFacts {
        actions: reach.actions(),
        every_step: matches_every_step(r),
        meant,
    }
}

/// One finding of the file-level checks; items are positions in the file's
/// list of items, actions positions in the domain's.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Finding {
    NoDomain,
    SecondDomain {
        item: usize,
    },
    SecondPlan {
        item: usize,
    },
    Duplicate {
        item: usize,
        first: usize,
    },
    Uncovered {
        action: usize,
    },
    /// No rule at all, here or in an import: R025 once, not R012 per action.
    NoRules {
        actions: usize,
        file_name: String,
    },
    Shadowed {
        later: usize,
        earlier: usize,
    },
    Unused {
        item: usize,
    },
}

/// One `domain`, one `plan`, and each name declared once.
pub fn structure(heads: &[ItemHead]) -> Vec<Finding> {
    let mut out = Vec::new();
    let domains: Vec<usize> = positions(heads, HeadKind::Domain);
    if domains.is_empty() {
        out.push(Finding::NoDomain);
    }
    out.extend(
        domains
            .iter()
            .skip(1)
            .map(|&item| Finding::SecondDomain { item }),
    );
    out.extend(
        positions(heads, HeadKind::Plan)
            .into_iter()
            .skip(1)
            .map(|item| Finding::SecondPlan { item }),
    );
    let mut seen: BTreeMap<&str, usize> = BTreeMap::new();
    for (i, h) in heads.iter().enumerate() {
        if let Some((name, _)) = &h.name {
            match seen.get(name.as_str()) {
                Some(&first) => out.push(Finding::Duplicate { item: i, first }),
                None => {
                    seen.insert(name, i);
                }
            }
        }
    }
    out
}

fn positions(heads: &[ItemHead], kind: HeadKind) -> Vec<usize> {
    heads
        .iter()
        .enumerate()
        .filter(|(_, h)| h.kind == kind)
        .map(|(i, _)| i)
        .collect()
}

/// Actions no rule that can match covers (R012), and rules that an earlier
/// rule always matches first (R013). `rules` are (item position, facts) in
/// file order.
pub fn coverage(rules: &[(usize, &RuleFacts)], actions: usize) -> Vec<Finding> {
    let mut out = Vec::new();
    if rules.is_empty() {
        return out;
    }
    let mut covered = vec![false; actions];
    for (_, f) in rules {
        for &a in &f.actions {
            covered[a] = true;
        }
        // A misspelled rule is reported (R002) with the action it likely
        // meant; that action is not reported again as uncovered.
        for &m in &f.meant {
            covered[m] = true;
        }
    }
    out.extend(
        (0..actions)
            .filter(|&a| !covered[a])
            .map(|action| Finding::Uncovered { action }),
    );
    // Per action, the rules that match all of its steps, in file order.
    let mut total: Vec<Vec<usize>> = vec![Vec::new(); actions];
    for (k, (_, f)) in rules.iter().enumerate() {
        if f.every_step {
            for &a in &f.actions {
                total[a].push(k);
            }
        }
    }
    for (k, (later, f)) in rules.iter().enumerate() {
        // Candidates: the rules total on the later rule's action that has
        // the fewest; the first earlier one that covers all its actions.
        let Some(&pivot) = f.actions.iter().min_by_key(|&&a| total[a].len()) else {
            continue;
        };
        let earlier = total[pivot]
            .iter()
            .take_while(|&&e| e < k)
            .find(|&&e| is_subset(&f.actions, &rules[e].1.actions));
        if let Some(&e) = earlier {
            out.push(Finding::Shadowed {
                later: *later,
                earlier: rules[e].0,
            });
        }
    }
    out
}

/// Whether sorted `a` is a subset of sorted `b`.
fn is_subset(a: &[usize], b: &[usize]) -> bool {
    let mut j = 0;
    a.iter().all(|x| {
        while j < b.len() && b[j] < *x {
            j += 1;
        }
        j < b.len() && b[j] == *x
    })
}

/// Declarations of this file that nothing in it refers to (unknowable when
/// a part of it did not parse).
pub fn unused(heads: &[ItemHead], uses: &[&ItemUses]) -> Vec<Finding> {
    if uses.iter().any(|u| u.broken) || heads.iter().any(|h| h.kind == HeadKind::Error) {
        return Vec::new();
    }
    // Hashed: a huge file uses a hundred thousand names.
    let used: rustc_hash::FxHashSet<&str> = uses
        .iter()
        .flat_map(|u| u.names.iter().map(String::as_str))
        .collect();
    heads
        .iter()
        .enumerate()
        .filter(|(_, h)| matches!(h.kind, HeadKind::Node | HeadKind::Tree | HeadKind::Table))
        .filter(|(_, h)| {
            h.name
                .as_ref()
                .is_some_and(|(n, _)| !used.contains(n.as_str()))
        })
        .map(|(item, _)| Finding::Unused { item })
        .collect()
}

/// A finding as a diagnostic with absolute spans: `offsets` are the items'
/// offsets in the file.
pub fn render(
    f: &Finding,
    heads: &[ItemHead],
    offsets: &[u32],
    domain: Option<&Domain>,
    file: FileId,
) -> Option<Diagnostic> {
    let abs = |s: Span, item: usize| Span {
        start: s.start + offsets[item],
        end: s.end + offsets[item],
        file,
    };
    let name_span = |item: usize| heads[item].name.as_ref().map(|(_, s)| abs(*s, item));
    Some(match f {
        Finding::NoDomain => Diagnostic::error(
            codes::R_NO_DOMAIN,
            Span::new(file, 0, 0),
            "this rules file does not say which PDDL domain it is for",
        )
        .with_hint("add `domain \"domain.pddl\"` (a path relative to this file)"),
        Finding::SecondDomain { item } => Diagnostic::error(
            codes::R_DUPLICATE,
            abs(heads[*item].span, *item),
            "a rules file names one domain; this is a second `domain`",
        ),
        Finding::SecondPlan { item } => Diagnostic::error(
            codes::R_PLAN_BLOCK,
            abs(heads[*item].span, *item),
            "a rules file has one `plan` block; this is a second one",
        ),
        Finding::Duplicate { item, first } => {
            let (name, _) = heads[*item].name.as_ref()?;
            Diagnostic::error(
                codes::R_DUPLICATE,
                name_span(*item)?,
                format!("`{name}` is declared twice"),
            )
            .with_label(name_span(*first)?, "first declared here")
            .with_hint("nodes, trees and tables share one namespace; rename one of them")
        }
        Finding::Uncovered { action } => {
            let a = domain?.actions.get(*action)?;
            let params: Vec<String> = a.params.iter().map(|p| format!("?{}", p.name.name)).collect();
            Diagnostic::warning(
                codes::R_UNCOVERED,
                a.name.span,
                format!("no rule covers the action `{}`", a.name.name),
            )
            .with_hint(format!(
                "add `rule ({} {}) {{ ... }}`, or `=> skip` to drop its steps",
                a.name.name,
                params.join(" ")
            ))
        }
        Finding::NoRules { actions, file_name } => {
            let item = heads.iter().position(|h| h.kind == HeadKind::Domain)?;
            Diagnostic::warning(
                codes::R_NO_RULES,
                abs(heads[item].span, item),
                format!(
                    "this rules file has no rules yet: no step of the domain's {actions} action{} can be compiled",
                    if *actions == 1 { "" } else { "s" }
                ),
            )
            .with_hint(format!("`btc stubs {file_name}` adds a rule per action, each calling a leaf named after it; then make the leaves your own"))
        }
        Finding::Shadowed { later, earlier } => Diagnostic::warning(
            codes::R_SHADOWED,
            abs(heads[*later].span, *later),
            "this rule never applies: an earlier rule matches every step it matches",
        )
        .with_label(abs(heads[*earlier].span, *earlier), "the earlier rule")
        .with_hint("the first rule that matches a step wins; move this rule up, or add a guard to the earlier one"),
        Finding::Unused { item } => {
            let h = &heads[*item];
            let kind = match h.kind {
                HeadKind::Node => "node",
                HeadKind::Tree => "tree",
                _ => "table",
            };
            let (name, _) = h.name.as_ref()?;
            Diagnostic::warning(
                codes::R_UNUSED,
                name_span(*item)?,
                format!("{kind} `{name}` is declared but never used"),
            )
            .with_hint("remove it, or use it in a rule")
        }
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn facts(actions: &[usize], every_step: bool) -> RuleFacts {
        RuleFacts {
            actions: actions.to_vec(),
            every_step,
            meant: Vec::new(),
        }
    }

    #[test]
    fn shadowing_needs_one_earlier_rule_covering_everything() {
        let a = facts(&[0], true);
        let b = facts(&[0, 1], true);
        let c = facts(&[0, 1], false);
        let d = facts(&[1], false);
        let rules = [(0, &a), (1, &b), (2, &c), (3, &d)];
        let found = coverage(&rules, 3);
        assert_eq!(
            found,
            vec![
                Finding::Uncovered { action: 2 },
                Finding::Shadowed {
                    later: 2,
                    earlier: 1
                },
                Finding::Shadowed {
                    later: 3,
                    earlier: 1
                },
            ]
        );
    }
}
