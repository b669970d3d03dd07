//! PDDL text to logic values, through the front end's lexer, s-expression
//! builder and parser (so the text means what it means in a domain file).
//! This is the decoder of the boundaries where PDDL arrives as text: the
//! JSON IR, BT.CPP XML attributes, fault scenarios. Names are checked
//! against a world only later ([`crate::state::World`] compiles them).
//!
//! Formulas, effects and atoms serialise as their PDDL text and
//! deserialise through these decoders.

use super::*;
use crate::sexpr::{self, Sexp};
use crate::{lexer, parse};
use serde::de::Error as _;
use serde::{Deserialize, Deserializer, Serialize, Serializer};

/// The one s-expression a text holds.
fn sexp(text: &str) -> Result<Sexp, String> {
    let (tokens, diags) = lexer::lex(text, 0);
    if let Some(d) = diags.first() {
        return Err(d.message.clone());
    }
    let (mut forest, diags) = sexpr::build(tokens);
    if let Some(d) = diags.first() {
        return Err(d.message.clone());
    }
    match forest.len() {
        1 => Ok(forest.remove(0)),
        0 => Err("expected a parenthesised PDDL expression, found nothing".into()),
        n => Err(format!(
            "expected one parenthesised PDDL expression, found {n}"
        )),
    }
}

fn first_error<T>(
    (value, diags): (Option<T>, Vec<crate::diagnostic::Diagnostic>),
    what: &str,
) -> Result<T, String> {
    if let Some(d) = diags.iter().find(|d| d.is_error()) {
        return Err(d.message.clone());
    }
    value.ok_or_else(|| format!("not a PDDL {what}"))
}

/// A condition, e.g. `(and (on a b) (not (clear b)))`.
pub fn formula(text: &str) -> Result<Formula, String> {
    let s = sexp(text)?;
    first_error(parse::formula_of(&s), "condition").map(|f| Formula::from_ast(&f))
}

/// An effect, e.g. `(and (on a b) (not (clear b)))`.
pub fn effect(text: &str) -> Result<Effect, String> {
    let s = sexp(text)?;
    first_error(parse::effect_of(&s), "effect").map(|e| Effect::from_ast(&e))
}

/// One atom, e.g. `(on a b)`.
pub fn atom(text: &str) -> Result<Atom, String> {
    match formula(text)? {
        Formula::Atom(a) => Ok(a),
        _ => Err(format!("`{text}` is not one atom such as `(on a b)`")),
    }
}

/// A fact of `:init`: an atom, or a fluent's value `(= (f a) 3)`.
pub fn init_fact(text: &str) -> Result<InitFact, String> {
    let s = sexp(text)?;
    Ok(match first_error(parse::init_fact_of(&s), "fact")? {
        ast::InitFact::Atom { atom } => InitFact::Atom(Atom::from_ast(&atom)),
        ast::InitFact::Value { fluent, value, .. } => {
            InitFact::Value(Atom::from_ast(&fluent), value)
        }
    })
}

/// A predicate or function declaration, e.g. `(at ?r - robot ?l)`.
pub fn signature(text: &str) -> Result<Signature, String> {
    let s = sexp(text)?;
    let d = first_error(parse::predicate_decl_of(&s), "declaration")?;
    Ok(Signature {
        name: name(&d.name.name),
        params: TypedVar::from_ast_list(&d.params),
    })
}

/// Serde as PDDL text: `Display` out, a decoder in.
macro_rules! as_pddl_text {
    ($t:ty, $decode:path) => {
        impl Serialize for $t {
            fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
                s.collect_str(self)
            }
        }

        impl<'de> Deserialize<'de> for $t {
            fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
                let text = std::borrow::Cow::<'de, str>::deserialize(d)?;
                $decode(&text).map_err(|m| D::Error::custom(format!("`{text}`: {m}")))
            }
        }
    };
}

as_pddl_text!(Formula, formula);
as_pddl_text!(Effect, effect);
as_pddl_text!(Atom, atom);
as_pddl_text!(InitFact, init_fact);
as_pddl_text!(Signature, signature);
