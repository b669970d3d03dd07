//! Ground formulas in negation normal form, simplified as they are built
//! (`and`/`or` flattened, constants folded) and regressed over known
//! values.

use super::*;

/// A ground formula in negation normal form.
#[derive(Clone, Debug, PartialEq, Eq, Hash)]
pub(super) enum GF {
    True,
    False,
    Lit(Lit),
    And(Vec<GF>),
    Or(Vec<GF>),
}

pub(super) fn gand(parts: Vec<GF>) -> GF {
    let mut out = Vec::with_capacity(parts.len());
    for p in parts {
        match p {
            GF::True => {}
            GF::False => return GF::False,
            GF::And(ps) => out.extend(ps),
            p => out.push(p),
        }
    }
    out.dedup();
    match out.len() {
        0 => GF::True,
        1 => out.pop().unwrap_or(GF::True),
        _ => GF::And(out),
    }
}

pub(super) fn gor(parts: Vec<GF>) -> GF {
    let mut out = Vec::with_capacity(parts.len());
    for p in parts {
        match p {
            GF::False => {}
            GF::True => return GF::True,
            GF::Or(ps) => out.extend(ps),
            p => out.push(p),
        }
    }
    out.dedup();
    match out.len() {
        0 => GF::False,
        1 => out.pop().unwrap_or(GF::False),
        _ => GF::Or(out),
    }
}

pub(super) fn negate(f: GF) -> GF {
    match f {
        GF::True => GF::False,
        GF::False => GF::True,
        GF::Lit(l) => GF::Lit(Lit {
            fact: l.fact,
            positive: !l.positive,
        }),
        GF::And(ps) => gor(ps.into_iter().map(negate).collect()),
        GF::Or(ps) => gand(ps.into_iter().map(negate).collect()),
    }
}

/// Replaces facts a start effect sets by their value after it.
pub(super) fn regress(f: GF, value: &FxHashMap<u32, bool>) -> GF {
    match f {
        GF::Lit(l) => match value.get(&l.fact) {
            Some(&v) if v == l.positive => GF::True,
            Some(_) => GF::False,
            None => GF::Lit(l),
        },
        GF::And(ps) => gand(ps.into_iter().map(|p| regress(p, value)).collect()),
        GF::Or(ps) => gor(ps.into_iter().map(|p| regress(p, value)).collect()),
        f => f,
    }
}
