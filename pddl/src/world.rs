//! The world a compiled plan runs in, as plain data: the type hierarchy,
//! the objects with their types, predicate and function signatures, the
//! derived-predicate rules, the initial facts and fluent values, the goal.
//! Built once from a checked domain and problem, carried by the IR, and
//! serialised readably (formulas and facts as PDDL text). The runtime's
//! knowledge base, the py_trees module and the C++ support library all
//! start from it; [`crate::state::World`] makes it ready for evaluation.
//!
//! Order is meaning: predicate `i`, function `i` and object `i` are the
//! `i`-th of their lists, which are the checked domain's and problem's
//! ([`crate::check::Signature::index`], [`crate::check::ObjectInfo::id`]),
//! so ground-atom keys agree with the planner's.

use crate::ast::{Domain, Problem};
use crate::check::{DomainIndex, ProblemIndex};
use crate::logic::{self, Formula, InitFact, Name, Signature};
use serde::{Deserialize, Serialize};

#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct WorldModel {
    /// Every type but `object`, with its parents.
    pub types: Vec<TypeDecl>,
    /// Domain constants first, then the problem's objects.
    pub objects: Vec<ObjectDecl>,
    pub predicates: Vec<Signature>,
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub functions: Vec<Signature>,
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub derived: Vec<DerivedRule>,
    /// Initial facts and fluent values.
    pub init: Vec<InitFact>,
    #[serde(default)]
    pub goal: Option<Formula>,
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct TypeDecl {
    pub name: Name,
    /// Declared parents; none means `object`.
    #[serde(default, rename = "parent", with = "types_text")]
    pub parents: Vec<Name>,
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ObjectDecl {
    pub name: Name,
    /// Its type, or the types of `(either ...)`; none means `object`.
    #[serde(default, rename = "type", with = "types_text")]
    pub types: Vec<Name>,
}

/// `(:derived (head ?x - t) body)`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct DerivedRule {
    pub head: Signature,
    pub body: Formula,
}

impl WorldModel {
    /// The world of a checked domain and problem.
    pub fn from_checked(
        domain: &Domain,
        dix: &DomainIndex,
        problem: &Problem,
        pix: &ProblemIndex,
    ) -> WorldModel {
        let t = &dix.types;
        let names = |ids: &[u32]| -> Vec<Name> {
            ids.iter()
                .filter(|&&i| i != crate::types::OBJECT)
                .map(|&i| logic::name(t.name(i)))
                .collect()
        };
        let signature = |d: &crate::ast::PredicateDecl| Signature {
            name: logic::name(&d.name.name),
            params: logic::TypedVar::from_ast_list(&d.params),
        };
        WorldModel {
            types: (1..t.len() as u32)
                .map(|id| TypeDecl {
                    name: logic::name(t.name(id)),
                    parents: names(t.parents(id)),
                })
                .collect(),
            objects: pix
                .object_names
                .iter()
                .zip(&pix.object_types)
                .map(|(n, ty)| ObjectDecl {
                    name: logic::name(n),
                    types: names(ty),
                })
                .collect(),
            predicates: domain.predicates.iter().map(signature).collect(),
            functions: domain
                .functions
                .iter()
                .map(|f| Signature {
                    name: logic::name(&f.name.name),
                    params: logic::TypedVar::from_ast_list(&f.params),
                })
                .collect(),
            derived: domain
                .derived
                .iter()
                .map(|d| DerivedRule {
                    head: signature(&d.head),
                    body: Formula::from_ast(&d.body),
                })
                .collect(),
            init: problem
                .init
                .iter()
                .map(|f| match f {
                    crate::ast::InitFact::Atom { atom } => {
                        InitFact::Atom(logic::Atom::from_ast(atom))
                    }
                    crate::ast::InitFact::Value { fluent, value, .. } => {
                        InitFact::Value(logic::Atom::from_ast(fluent), *value)
                    }
                })
                .collect(),
            goal: problem.goal.as_ref().map(Formula::from_ast),
        }
    }

    /// The object's declared types, by name.
    pub fn object(&self, name: &str) -> Option<&ObjectDecl> {
        self.objects.iter().find(|o| &*o.name == name)
    }

    pub fn predicate(&self, name: &str) -> Option<&Signature> {
        self.predicates.iter().find(|p| &*p.name == name)
    }
}

/// Types as JSON: `"t"` for one, `["a", "b"]` for `(either a b)`, absent
/// (or `"object"`) for none.
mod types_text {
    use super::Name;
    use serde::{Deserialize, Deserializer, Serialize, Serializer};

    #[derive(Serialize, Deserialize)]
    #[serde(untagged)]
    enum Text {
        One(Name),
        Many(Vec<Name>),
    }

    pub fn serialize<S: Serializer>(types: &[Name], s: S) -> Result<S::Ok, S::Error> {
        match types {
            [] => Text::One("object".into()).serialize(s),
            [one] => Text::One(one.clone()).serialize(s),
            many => Text::Many(many.to_vec()).serialize(s),
        }
    }

    pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<Vec<Name>, D::Error> {
        Ok(match Text::deserialize(d)? {
            Text::One(t) if &*t == "object" => Vec::new(),
            Text::One(t) => vec![t],
            Text::Many(ts) => ts.into_iter().filter(|t| &**t != "object").collect(),
        })
    }
}
