//! Which steps a rule can match, known before any plan: the actions its
//! name matches, whose parameter count its pattern fits, that its
//! `capture in table` guards let through, and for which its guards and
//! repeated variables can hold together given the types of the action's
//! parameters. A rule that can match no step is reported (R040-R043) and
//! covers nothing (R012).

use super::ast::{Guard, Operand, Rule};
use super::decls::{Decls, DomainCtx};
use super::matching::{bind_params, Captures};
use super::name::Key;
use btc_pddl::ast::Action;
use btc_pddl::source::Span;
use btc_pddl::types::{TypeId, TypeTable};

/// Why a rule can never match the steps of one action.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Never {
    /// `?a != ?b` where both sides always stand for the same object.
    SameObject { guard: Span },
    /// One variable would have to be two different objects.
    TwoObjects { first: Span, second: Span },
    /// A type guard the variable's type can never fit.
    TypeGuard {
        guard: Span,
        var: String,
        ty: String,
        has: String,
    },
    /// One object would have to stand in two parameters whose types share
    /// no object (a repeated variable, or an `==` guard).
    Disjoint {
        var: String,
        first: (Span, String),
        second: (Span, String),
    },
    /// An object compared with a variable can never stand there.
    ObjectType {
        object: Span,
        name: String,
        has: String,
        want: String,
    },
}

/// A rule against the domain: the actions its name matches (with
/// captures, in domain order) and, for each, whether its steps can match.
#[derive(Clone, Debug, PartialEq)]
pub struct Reach<'d> {
    pub named: Vec<(&'d Action, usize, Captures, Verdict)>,
}

#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Verdict {
    /// Some step of the action can match.
    Can,
    /// The pattern's parameters do not fit the action's (R003): a literal
    /// name, or a pattern with captures that fits none of the actions it
    /// names.
    Arity,
    /// A pattern with captures names the action, but its parameter count
    /// fits only others of the actions it names: the rule is for those.
    OtherCount,
    /// A `capture in table` guard leaves the action out.
    NotInTable,
    Never(Never),
}

impl Verdict {
    /// Whether the rule is for the action at all: its `capture in table`
    /// guards let it through and, for a pattern with captures, its
    /// parameter count is not one only other named actions fit.
    pub fn is_for(&self) -> bool {
        !matches!(self, Verdict::NotInTable | Verdict::OtherCount)
    }
}

impl<'d> Reach<'d> {
    /// The named actions the rule is for (see [`Verdict::is_for`]).
    pub fn meant(&self) -> Vec<&(&'d Action, usize, Captures, Verdict)> {
        self.named
            .iter()
            .filter(|(_, _, _, v)| v.is_for())
            .collect()
    }

    /// Indices (in the domain) of the actions some of whose steps can match.
    pub fn actions(&self) -> Vec<usize> {
        self.named
            .iter()
            .filter(|(_, _, _, v)| *v == Verdict::Can)
            .map(|(_, i, _, _)| *i)
            .collect()
    }

    /// The reason to report when the name matches and the argument counts
    /// fit, but no step can match.
    pub fn never(&self) -> Option<&Never> {
        let mut reasons = self.named.iter().filter_map(|(_, _, _, v)| match v {
            Verdict::Never(n) => Some(n),
            _ => None,
        });
        let first = reasons.next()?;
        self.named
            .iter()
            .all(|(_, _, _, v)| {
                matches!(
                    v,
                    Verdict::Never(_) | Verdict::Arity | Verdict::OtherCount | Verdict::NotInTable
                )
            })
            .then_some(first)
    }
}

/// Whether a rule matches every step of the actions it can match: no guard
/// but `capture in table`, no repeated variable. Only such a rule can make a
/// later one useless (R013).
pub fn matches_every_step(r: &Rule) -> bool {
    let mut vars = std::collections::BTreeSet::new();
    r.guards.iter().all(|g| matches!(g, Guard::InTable { .. }))
        && r.pattern.params.iter().all(|p| vars.insert(&p.var.text))
}

pub fn reach<'d>(r: &Rule, decls: &Decls, ctx: DomainCtx<'d>) -> Reach<'d> {
    let mut named: Vec<_> = ctx
        .actions
        .matches(&r.pattern.name, ctx.domain)
        .into_iter()
        .map(|(i, caps)| {
            let a = &ctx.domain.actions[i];
            // `capture in table` first: it says which actions a rule is for.
            let verdict = if !in_tables(r, decls, &caps) {
                Verdict::NotInTable
            } else if bind_params(&r.pattern, a.params.len()).is_none() {
                Verdict::Arity
            } else {
                match satisfiable(r, a, ctx) {
                    Ok(()) => Verdict::Can,
                    Err(n) => Verdict::Never(n),
                }
            };
            (a, i, caps, verdict)
        })
        .collect();
    // The docs' promise: a pattern with captures matches the actions it
    // names whose parameter count it fits (`{verb}-truck ?a ?b ?c` is for
    // the three-parameter truck actions); the count is an error only when
    // it fits none of them, or when the name is literal.
    let captures = r
        .pattern
        .name
        .iter()
        .any(|p| !matches!(p, super::ast::NamePart::Lit { .. }));
    let some_fit = named
        .iter()
        .any(|(_, _, _, v)| !matches!(v, Verdict::Arity | Verdict::NotInTable));
    if captures && some_fit {
        for (_, _, _, v) in &mut named {
            if *v == Verdict::Arity {
                *v = Verdict::OtherCount;
            }
        }
    }
    Reach { named }
}

/// Whether the `capture in table` guards let an action's captures through
/// (a guard naming an unknown table or capture is reported elsewhere and
/// lets everything through).
pub fn in_tables(r: &Rule, decls: &Decls, caps: &Captures) -> bool {
    r.guards.iter().all(|g| match g {
        Guard::InTable { key, table, .. } => match (
            caps.iter().find(|(n, _)| *n == key.text),
            decls.tables.get(&table.text),
        ) {
            (Some((_, v)), Some(t)) => t.entries.iter().any(|e| e.key.key.as_str() == v),
            _ => true,
        },
        _ => true,
    })
}

/// One thing a guard or a pattern says about the object a class of
/// variables and objects stands for.
#[derive(Clone, Debug)]
enum Constraint {
    /// It is bound to a parameter (at `span`) of these types.
    Param { span: Span, types: Vec<TypeId> },
    /// `?var - ty`.
    Guard {
        span: Span,
        ty: String,
        types: Vec<TypeId>,
    },
}

/// Equality classes of the rule's variables and named objects, by `==`.
struct Classes<'r> {
    terms: Vec<Term<'r>>,
    parent: Vec<usize>,
}

/// Borrowed from the rule: the check runs for every rule with a guard and
/// every action it names.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Term<'r> {
    Var(&'r str),
    Object(&'r Key),
}

impl<'r> Classes<'r> {
    fn id(&mut self, t: Term<'r>) -> usize {
        match self.terms.iter().position(|x| *x == t) {
            Some(i) => i,
            None => {
                self.terms.push(t);
                self.parent.push(self.parent.len());
                self.parent.len() - 1
            }
        }
    }

    fn find(&mut self, mut i: usize) -> usize {
        while self.parent[i] != i {
            self.parent[i] = self.parent[self.parent[i]];
            i = self.parent[i];
        }
        i
    }

    fn union(&mut self, a: usize, b: usize) {
        let (a, b) = (self.find(a), self.find(b));
        self.parent[b] = a;
    }
}

fn term(o: &Operand) -> Term<'_> {
    match o {
        Operand::Var { name } => Term::Var(&name.text),
        Operand::Object { name } => Term::Object(&name.key),
    }
}

/// Whether some step of `a` can satisfy the rule's guards and repeated
/// variables, from the parameters' types (and the types of the objects the
/// guards name, where the domain or problem knows them).
fn satisfiable(r: &Rule, a: &Action, ctx: DomainCtx) -> Result<(), Never> {
    // A pattern has a handful of parameters: pairs are cheaper than a set.
    let params = &r.pattern.params;
    let repeats =
        (0..params.len()).any(|i| params[..i].iter().any(|q| q.var.text == params[i].var.text));
    if r.guards.iter().all(|g| matches!(g, Guard::InTable { .. })) && !repeats {
        return Ok(()); // nothing to contradict: the common case, kept cheap
    }
    let types = &ctx.index.types;
    let slots = bind_params(&r.pattern, a.params.len()).expect("arity checked");
    let mut classes = Classes {
        terms: Vec::new(),
        parent: Vec::new(),
    };
    for g in &r.guards {
        if let Guard::Eq { left, right, .. } = g {
            let (l, rt) = (classes.id(term(left)), classes.id(term(right)));
            classes.union(l, rt);
        }
    }
    for g in &r.guards {
        if let Guard::Ne { left, right, span } = g {
            let (l, rt) = (classes.id(term(left)), classes.id(term(right)));
            if classes.find(l) == classes.find(rt) {
                return Err(Never::SameObject { guard: *span });
            }
        }
    }
    // Two different objects in one class.
    let objects: Vec<&super::ast::Ident> = r
        .guards
        .iter()
        .filter_map(|g| match g {
            Guard::Eq { left, right, .. } => Some([left, right]),
            _ => None,
        })
        .flatten()
        .filter_map(|o| match o {
            Operand::Object { name } => Some(name),
            Operand::Var { .. } => None,
        })
        .collect();
    for (x, a) in objects.iter().enumerate() {
        for b in &objects[x + 1..] {
            let (ia, ib) = (
                classes.id(Term::Object(&a.key)),
                classes.id(Term::Object(&b.key)),
            );
            if a.key != b.key && classes.find(ia) == classes.find(ib) {
                return Err(Never::TwoObjects {
                    first: a.span,
                    second: b.span,
                });
            }
        }
    }
    // What each variable is: the types of the parameters it is bound to,
    // and its type guards, in that order.
    let mut per_var: Vec<(&str, Vec<Constraint>)> = Vec::new();
    for (k, &slot) in slots.iter().enumerate() {
        let p = &r.pattern.params[slot];
        let ty = types.resolve(&a.params[k].ty, &mut Vec::new());
        let c = Constraint::Param {
            span: p.span,
            types: ty,
        };
        match per_var.iter_mut().find(|(v, _)| *v == p.var.text) {
            Some((_, cs)) => cs.push(c),
            None => per_var.push((&p.var.text, vec![c])),
        }
    }
    // A repeated variable: its parameters' types must share an object.
    for (var, cs) in &per_var {
        if let Some((i, j)) = first_conflict(types, cs) {
            return Err(disjoint(var, &cs[i], &cs[j], types));
        }
    }
    for g in &r.guards {
        let Guard::IsType { var, ty, span } = g else {
            continue;
        };
        let Some(id) = types.id(ty.key.as_str()) else {
            continue; // an unknown type: reported by the item's checks
        };
        if let Some((_, cs)) = per_var.iter_mut().find(|(v, _)| *v == var.text) {
            cs.push(Constraint::Guard {
                span: *span,
                ty: ty.text.clone(),
                types: vec![id],
            });
            if let Some((i, _)) = first_conflict(types, cs) {
                return Err(Never::TypeGuard {
                    guard: *span,
                    var: var.text.clone(),
                    ty: ty.text.clone(),
                    has: describe(&cs[i], types),
                });
            }
        }
    }
    // Variables made equal by `==`, and the objects they are compared with.
    for g in &r.guards {
        let Guard::Eq { left, right, .. } = g else {
            continue;
        };
        match (left, right) {
            (Operand::Var { name: l }, Operand::Var { name: rt }) => {
                let (Some(lc), Some(rc)) = (
                    constraints_of(&per_var, &l.text),
                    constraints_of(&per_var, &rt.text),
                ) else {
                    continue;
                };
                let all: Vec<Constraint> = lc.iter().chain(rc).cloned().collect();
                if let Some((i, j)) = first_conflict(types, &all) {
                    return Err(disjoint(&l.text, &all[i], &all[j], types));
                }
            }
            (Operand::Var { name: v }, Operand::Object { name: o })
            | (Operand::Object { name: o }, Operand::Var { name: v }) => {
                let Some(cs) = constraints_of(&per_var, &v.text) else {
                    continue;
                };
                let Some(has) = object_types(ctx, &o.key) else {
                    continue; // unknown here: reported, or only the problem knows it
                };
                if let Some(c) = cs.iter().find(|c| !types.fits(has, c.types())) {
                    return Err(Never::ObjectType {
                        object: o.span,
                        name: o.text.clone(),
                        has: types.display(has),
                        want: describe(c, types),
                    });
                }
            }
            _ => {}
        }
    }
    Ok(())
}

fn constraints_of<'a>(
    per_var: &'a [(&str, Vec<Constraint>)],
    var: &str,
) -> Option<&'a [Constraint]> {
    per_var
        .iter()
        .find(|(v, _)| *v == var)
        .map(|(_, cs)| cs.as_slice())
}

/// The declared types of an object or constant, when the domain or problem
/// knows it.
fn object_types<'a>(ctx: DomainCtx<'a>, object: &Key) -> Option<&'a [TypeId]> {
    ctx.problem
        .and_then(|p| p.objects.get(object.as_str()))
        .or_else(|| ctx.index.constants.get(object.as_str()))
        .map(|o| o.types.as_slice())
}

impl Constraint {
    fn types(&self) -> &[TypeId] {
        match self {
            Constraint::Param { types, .. } | Constraint::Guard { types, .. } => types,
        }
    }

    fn span(&self) -> Span {
        match self {
            Constraint::Param { span, .. } | Constraint::Guard { span, .. } => *span,
        }
    }
}

fn describe(c: &Constraint, types: &TypeTable) -> String {
    match c {
        Constraint::Param { types: t, .. } => types.display(t),
        Constraint::Guard { ty, .. } => ty.clone(),
    }
}

fn disjoint(var: &str, a: &Constraint, b: &Constraint, types: &TypeTable) -> Never {
    Never::Disjoint {
        var: var.to_owned(),
        first: (a.span(), describe(a, types)),
        second: (b.span(), describe(b, types)),
    }
}

/// The first constraint that, with those before it, no object's type can
/// meet, as (an earlier constraint it conflicts with, it). An object of declared type `t` meets a
/// constraint when `t` fits one of its types; the constraints can be met
/// together when some type of the domain meets them all.
fn first_conflict(types: &TypeTable, cs: &[Constraint]) -> Option<(usize, usize)> {
    let meets = |t: TypeId, c: &Constraint| types.fits(&[t], c.types());
    // The common case, one parameter's type, without collecting types: it
    // runs for every variable of every rule with a guard.
    if let [c] = cs {
        let met = (0..types.len() as TypeId).any(|t| meets(t, c));
        return (!met).then_some((0, 0));
    }
    let mut possible: Vec<TypeId> = (0..types.len() as TypeId).collect();
    for (i, c) in cs.iter().enumerate() {
        let next: Vec<TypeId> = possible.iter().copied().filter(|&t| meets(t, c)).collect();
        let before = std::mem::replace(&mut possible, next);
        if possible.is_empty() {
            // Name the earlier constraint it conflicts with most directly.
            let j = (0..i)
                .rev()
                .find(|&j| {
                    !before
                        .iter()
                        .any(|&t| types.fits(&[t], cs[j].types()) && types.fits(&[t], c.types()))
                })
                .unwrap_or(0);
            return Some((j, i));
        }
    }
    None
}
