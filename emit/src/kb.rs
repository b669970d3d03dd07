//! A problem's world as one self-contained s-expression file (`.kb`), for
//! knowledge bases that do not parse PDDL domains: btc's C++ support
//! library for BehaviorTree.CPP (`integrations/btcpp/`) reads it. It holds
//! what evaluating the ground formulas and effects of a compiled tree needs:
//! the type hierarchy (each type with its ancestors), the objects in id
//! order with their types, the predicates and functions with their
//! parameter types, the derived predicates stratum by stratum, the initial
//! facts and values, and the goal.
//!
//! Objects are listed in btc's id order (domain constants first) because a
//! quantifier visits objects in that order, and so does the C++ side: the
//! order in which numeric updates of one effect are applied depends on it.

use btc_pddl::ast::{Domain, InitFact, Problem};
use btc_pddl::check::Signature;
use btc_pddl::types::{TypeId, TypeTable};
use btc_pddl::{DomainIndex, ProblemIndex};
use std::fmt::Write as _;

/// The version written in the file's head; readers refuse others.
pub const KB_FILE_VERSION: u32 = 1;

fn type_list(types: &TypeTable, ids: &[TypeId]) -> String {
    match ids {
        [one] => types.name(*one).to_owned(),
        many => {
            let names: Vec<&str> = many.iter().map(|&t| types.name(t)).collect();
            format!("(either {})", names.join(" "))
        }
    }
}

/// Signatures in declaration order (the index maps are unordered).
fn signatures<'a>(
    sigs: impl IntoIterator<Item = (&'a String, &'a Signature)>,
) -> Vec<(&'a str, &'a Signature)> {
    let mut v: Vec<(&str, &Signature)> = sigs.into_iter().map(|(n, s)| (n.as_str(), s)).collect();
    v.sort_by_key(|(_, s)| s.index);
    v
}

/// The `.kb` text of a checked problem.
pub fn emit(domain: &Domain, dix: &DomainIndex, problem: &Problem, pix: &ProblemIndex) -> String {
    let types = &dix.types;
    let mut out = String::with_capacity(4096 + pix.object_names.len() * 32);
    let _ = writeln!(
        out,
        "; btc knowledge base: the world of PDDL problem `{}` (domain `{}`)\n\
         ; for btc's C++ support library (integrations/btcpp): types with their\n\
         ; ancestors, objects with their types, predicates and functions with their\n\
         ; parameter types, derived predicates by stratum, the initial state, the goal.",
        problem.name.name, domain.name.name
    );
    let _ = writeln!(out, "(kb {KB_FILE_VERSION}");
    let _ = writeln!(out, "  (:domain {})", domain.name.name);
    let _ = writeln!(out, "  (:problem {})", problem.name.name);
    out.push_str("  (:types");
    for t in 0..types.len() as TypeId {
        let _ = write!(out, "\n    ({}", types.name(t));
        for a in 0..types.len() as TypeId {
            if a != t && types.is_subtype(t, a) {
                let _ = write!(out, " {}", types.name(a));
            }
        }
        out.push(')');
    }
    out.push_str(")\n  (:objects");
    for (name, ty) in pix.object_names.iter().zip(&pix.object_types) {
        let _ = write!(out, "\n    ({name}");
        for &t in ty {
            let _ = write!(out, " {}", types.name(t));
        }
        out.push(')');
    }
    for (section, sigs) in [
        ("predicates", signatures(&dix.predicates)),
        ("functions", signatures(&dix.functions)),
    ] {
        let _ = write!(out, ")\n  (:{section}");
        for (name, sig) in sigs {
            let _ = write!(out, "\n    ({name}");
            for p in &sig.params {
                let _ = write!(out, " {}", type_list(types, p));
            }
            out.push(')');
        }
    }
    out.push_str(")\n  (:derived");
    for stratum in &dix.derived_strata {
        out.push_str("\n    (:stratum");
        for &r in stratum {
            let rule = &domain.derived[r];
            let _ = write!(out, "\n      (:rule ({}", rule.head.name.name);
            for p in &rule.head.params {
                let ty = types.resolve(&p.ty, &mut Vec::new());
                let _ = write!(out, " ?{} - {}", p.name.name, type_list(types, &ty));
            }
            let _ = write!(out, ") {})", rule.body);
        }
        out.push(')');
    }
    out.push_str(")\n  (:init");
    for f in &problem.init {
        match f {
            InitFact::Atom { atom } => {
                let _ = write!(out, "\n    {atom}");
            }
            InitFact::Value { fluent, value, .. } => {
                // Shortest text that reads back as the same double.
                let _ = write!(out, "\n    (= {fluent} {value:?})");
            }
        }
    }
    out.push(')');
    if let Some(g) = &problem.goal {
        let _ = write!(out, "\n  (:goal {g})");
    }
    out.push_str(")\n");
    out
}
