//! PDDL logic without spans: terms, atoms, numeric expressions, formulas,
//! effects and action schemas over lower-cased shared names. This is how
//! PDDL crosses every boundary after the front end: lowering grounds it,
//! the IR carries it, the runtime's KB evaluates it, emitters print it.
//!
//! The checked [`crate::ast`] (which keeps spans for diagnostics) is
//! converted once ([`Formula::from_ast`] and friends). [`fmt`] prints PDDL
//! text; [`decode`] reads PDDL text back through the front end's lexer and
//! parser — the only way text becomes logic outside the front end.
//! Variables are replaced by one fold ([`Terms::fold_terms`]), which serves
//! grounding (variables to objects) and renaming (variables to variables).

use crate::ast;
pub use crate::ast::{AssignOp, Comparison, NumOp};
use std::sync::Arc;

pub mod decode;
mod fmt;
pub use fmt::TypeText;
mod fold;
mod to_ast;

pub use fold::{Binding, Renaming, TermFolder, Terms};

/// A lower-cased PDDL name (predicate, object, type, variable without `?`).
pub type Name = Arc<str>;

pub fn name(s: &str) -> Name {
    Arc::from(s)
}

#[derive(Clone, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Term {
    /// `?x`, stored without the `?`.
    Var(Name),
    /// An object or a domain constant.
    Obj(Name),
}

impl Term {
    pub fn obj(s: &str) -> Term {
        Term::Obj(name(s))
    }

    pub fn var(s: &str) -> Term {
        Term::Var(name(s))
    }
}

/// `(pred t1 t2 ...)`, also a function application `(f t1 ...)`.
#[derive(Clone, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct Atom {
    pub pred: Name,
    pub args: Vec<Term>,
}

impl Atom {
    /// A ground atom from its names.
    pub fn ground(pred: &str, args: &[&str]) -> Atom {
        Atom {
            pred: name(pred),
            args: args.iter().map(|a| Term::obj(a)).collect(),
        }
    }

    /// Whether no argument is a variable.
    pub fn is_ground(&self) -> bool {
        self.args.iter().all(|t| matches!(t, Term::Obj(_)))
    }
}

/// A variable with the types it ranges over (none written: `object`).
#[derive(Clone, Debug, PartialEq, Eq, Hash)]
pub struct TypedVar {
    pub name: Name,
    /// One type, several (`either`), or none for `object`.
    pub types: Vec<Name>,
}

#[derive(Clone, Debug, PartialEq)]
pub enum NumExpr {
    Number(f64),
    Fluent(Atom),
    /// `?duration` inside a durative action.
    Duration,
    Binary(NumOp, Box<NumExpr>, Box<NumExpr>),
    Neg(Box<NumExpr>),
}

#[derive(Clone, Debug, PartialEq)]
pub enum Formula {
    Atom(Atom),
    Equal(Term, Term),
    Not(Box<Formula>),
    And(Vec<Formula>),
    Or(Vec<Formula>),
    Imply(Box<Formula>, Box<Formula>),
    Exists(Vec<TypedVar>, Box<Formula>),
    Forall(Vec<TypedVar>, Box<Formula>),
    /// Boxed operands, as in [`Effect`]'s wide variants: every `and` holds
    /// its parts inline, and comparisons are rare next to atoms.
    Compare(Comparison, Box<NumExpr>, Box<NumExpr>),
}

impl Formula {
    /// The empty conjunction, which always holds.
    pub fn truth() -> Formula {
        Formula::And(Vec::new())
    }

    /// Several formulas as one: `None` for none, the formula itself for
    /// one, their `and` otherwise.
    pub fn conjunction(mut parts: Vec<Formula>) -> Option<Formula> {
        match parts.len() {
            0 => None,
            1 => parts.pop(),
            _ => Some(Formula::And(parts)),
        }
    }

    /// The top-level conjuncts (the formula itself when it is no `and`).
    pub fn conjuncts(&self) -> &[Formula] {
        match self {
            Formula::And(parts) => parts,
            other => std::slice::from_ref(other),
        }
    }

    /// The literals of a plain conjunction (atoms and negated atoms;
    /// equalities are skipped); `None` when it has any other part.
    pub fn literals(&self) -> Option<Vec<Literal>> {
        let mut out = Vec::new();
        let mut stack = vec![self];
        while let Some(f) = stack.pop() {
            match f {
                Formula::Atom(a) => out.push(Literal::pos(a.clone())),
                Formula::Not(inner) => match &**inner {
                    Formula::Atom(a) => out.push(Literal::neg(a.clone())),
                    Formula::Equal(..) => {}
                    _ => return None,
                },
                Formula::And(parts) => stack.extend(parts.iter().rev()),
                Formula::Equal(..) => {}
                _ => return None,
            }
        }
        Some(out)
    }

    pub fn from_ast(f: &ast::Formula) -> Formula {
        match f {
            ast::Formula::Atom { atom } => Formula::Atom(Atom::from_ast(atom)),
            ast::Formula::Equal { left, right, .. } => {
                Formula::Equal(Term::from_ast(left), Term::from_ast(right))
            }
            ast::Formula::Not { formula, .. } => Formula::Not(Box::new(Formula::from_ast(formula))),
            ast::Formula::And { parts, .. } => {
                Formula::And(parts.iter().map(Formula::from_ast).collect())
            }
            ast::Formula::Or { parts, .. } => {
                Formula::Or(parts.iter().map(Formula::from_ast).collect())
            }
            ast::Formula::Imply { left, right, .. } => Formula::Imply(
                Box::new(Formula::from_ast(left)),
                Box::new(Formula::from_ast(right)),
            ),
            ast::Formula::Exists { vars, body, .. } => Formula::Exists(
                TypedVar::from_ast_list(vars),
                Box::new(Formula::from_ast(body)),
            ),
            ast::Formula::Forall { vars, body, .. } => Formula::Forall(
                TypedVar::from_ast_list(vars),
                Box::new(Formula::from_ast(body)),
            ),
            ast::Formula::Compare {
                op, left, right, ..
            } => Formula::Compare(
                *op,
                Box::new(NumExpr::from_ast(left)),
                Box::new(NumExpr::from_ast(right)),
            ),
        }
    }
}

/// An atom that must be true (`positive`) or false.
#[derive(Clone, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct Literal {
    pub positive: bool,
    pub atom: Atom,
}

impl Literal {
    pub fn pos(atom: Atom) -> Literal {
        Literal {
            positive: true,
            atom,
        }
    }

    pub fn neg(atom: Atom) -> Literal {
        Literal {
            positive: false,
            atom,
        }
    }

    pub fn to_formula(&self) -> Formula {
        let a = Formula::Atom(self.atom.clone());
        if self.positive {
            a
        } else {
            Formula::Not(Box::new(a))
        }
    }
}

#[derive(Clone, Debug, PartialEq)]
pub enum Effect {
    Add(Atom),
    Delete(Atom),
    And(Vec<Effect>),
    Forall(Vec<TypedVar>, Box<Effect>),
    When(Box<Formula>, Box<Effect>),
    Numeric(AssignOp, Atom, Box<NumExpr>),
}

impl Effect {
    /// Whether the effect changes nothing: an `and` of nothing (nested).
    pub fn is_empty(&self) -> bool {
        match self {
            Effect::And(parts) => parts.iter().all(Effect::is_empty),
            _ => false,
        }
    }

    /// Several effects as one, empty ones left out: `None` when nothing
    /// remains.
    pub fn conjunction(parts: Vec<Effect>) -> Option<Effect> {
        let mut parts: Vec<Effect> = parts.into_iter().filter(|e| !e.is_empty()).collect();
        match parts.len() {
            0 => None,
            1 => parts.pop(),
            _ => Some(Effect::And(parts)),
        }
    }

    /// The literals of a plain effect (`and` of adds and deletes, in
    /// order), with action-cost increases left out (they commute with
    /// everything); `None` when it has quantified, conditional or other
    /// numeric parts.
    pub fn literals(&self) -> Option<Vec<Literal>> {
        let mut out = Vec::new();
        let mut stack = vec![self];
        while let Some(e) = stack.pop() {
            match e {
                Effect::Add(a) => out.push(Literal::pos(a.clone())),
                Effect::Delete(a) => out.push(Literal::neg(a.clone())),
                Effect::And(parts) => stack.extend(parts.iter().rev()),
                Effect::Numeric(_, f, _) if &*f.pred == "total-cost" => {}
                _ => return None,
            }
        }
        Some(out)
    }

    /// The literals that hold after the effect applies, one per atom: a
    /// delete and an add of one atom leave it true (adds win, as in
    /// [`crate::state::World::apply`]). `None` as for [`Effect::literals`].
    pub fn outcome(&self) -> Option<Vec<Literal>> {
        let mut out: Vec<Literal> = Vec::new();
        for l in self.literals()? {
            match out.iter_mut().find(|o| o.atom == l.atom) {
                Some(o) => o.positive |= l.positive,
                None => out.push(l),
            }
        }
        Some(out)
    }

    pub fn from_ast(e: &ast::Effect) -> Effect {
        match e {
            ast::Effect::Add { atom } => Effect::Add(Atom::from_ast(atom)),
            ast::Effect::Delete { atom, .. } => Effect::Delete(Atom::from_ast(atom)),
            ast::Effect::And { parts, .. } => {
                Effect::And(parts.iter().map(Effect::from_ast).collect())
            }
            ast::Effect::Forall { vars, body, .. } => Effect::Forall(
                TypedVar::from_ast_list(vars),
                Box::new(Effect::from_ast(body)),
            ),
            ast::Effect::When {
                condition, body, ..
            } => Effect::When(
                Box::new(Formula::from_ast(condition)),
                Box::new(Effect::from_ast(body)),
            ),
            ast::Effect::Numeric {
                op, fluent, value, ..
            } => Effect::Numeric(
                *op,
                Atom::from_ast(fluent),
                Box::new(NumExpr::from_ast(value)),
            ),
        }
    }
}

impl Term {
    pub fn from_ast(t: &ast::Term) -> Term {
        match t {
            ast::Term::Var { name: n } => Term::Var(name(&n.name)),
            ast::Term::Const { name: n } => Term::Obj(name(&n.name)),
        }
    }
}

impl Atom {
    pub fn from_ast(a: &ast::Atom) -> Atom {
        Atom {
            pred: name(&a.pred.name),
            args: a.args.iter().map(Term::from_ast).collect(),
        }
    }
}

impl TypedVar {
    pub fn from_ast(t: &ast::Typed) -> TypedVar {
        TypedVar {
            name: name(&t.name.name),
            types: type_names(&t.ty),
        }
    }

    pub fn from_ast_list(ts: &[ast::Typed]) -> Vec<TypedVar> {
        ts.iter().map(TypedVar::from_ast).collect()
    }
}

/// The names a written type allows; empty for `object` left unwritten.
pub fn type_names(t: &ast::TypeSpec) -> Vec<Name> {
    match t {
        ast::TypeSpec::Object => Vec::new(),
        ast::TypeSpec::Named { name: n } => vec![name(&n.name)],
        ast::TypeSpec::Either { names, .. } => names.iter().map(|n| name(&n.name)).collect(),
    }
}

impl NumExpr {
    pub fn from_ast(e: &ast::NumExpr) -> NumExpr {
        match e {
            ast::NumExpr::Number { value, .. } => NumExpr::Number(*value),
            ast::NumExpr::Fluent { app } => NumExpr::Fluent(Atom::from_ast(app)),
            ast::NumExpr::Duration { .. } => NumExpr::Duration,
            ast::NumExpr::Binary {
                op, left, right, ..
            } => NumExpr::Binary(
                *op,
                Box::new(NumExpr::from_ast(left)),
                Box::new(NumExpr::from_ast(right)),
            ),
            ast::NumExpr::Neg { expr, .. } => NumExpr::Neg(Box::new(NumExpr::from_ast(expr))),
        }
    }
}

/// A fact of `:init` as the logic layer has it.
#[derive(Clone, Debug, PartialEq)]
pub enum InitFact {
    Atom(Atom),
    Value(Atom, f64),
}

/// A predicate's or function's name and parameters.
#[derive(Clone, Debug, PartialEq)]
pub struct Signature {
    pub name: Name,
    pub params: Vec<TypedVar>,
}

/// An action schema: parameters, conditions and effects by when they apply
/// (a plain `:action` has only `pre_start` and `eff_end`).
#[derive(Clone, Debug, PartialEq)]
pub struct ActionSchema {
    pub name: Name,
    pub params: Vec<TypedVar>,
    pub durative: bool,
    /// `(= ?duration expr)`.
    pub duration: Option<NumExpr>,
    pub pre_start: Vec<Formula>,
    pub pre_over_all: Vec<Formula>,
    pub pre_end: Vec<Formula>,
    pub eff_start: Vec<Effect>,
    pub eff_end: Vec<Effect>,
}

impl ActionSchema {
    pub fn from_ast(a: &ast::Action) -> ActionSchema {
        ActionSchema {
            name: name(&a.name.name),
            params: TypedVar::from_ast_list(&a.params),
            durative: a.durative,
            duration: a.duration.as_ref().map(|d| NumExpr::from_ast(&d.value)),
            pre_start: a.pre_start.iter().map(Formula::from_ast).collect(),
            pre_over_all: a.pre_over_all.iter().map(Formula::from_ast).collect(),
            pre_end: a.pre_end.iter().map(Formula::from_ast).collect(),
            eff_start: a.eff_start.iter().map(Effect::from_ast).collect(),
            eff_end: a.eff_end.iter().map(Effect::from_ast).collect(),
        }
    }

    /// The parameters' names, in order.
    pub fn param_names(&self) -> Vec<Name> {
        self.params.iter().map(|p| p.name.clone()).collect()
    }
}

/// The span of the part of `f` that `path` leads to (child positions, as
/// [`crate::state::World::why_not`] reports them): the logic layer has no
/// spans, the AST it was converted from does.
pub fn span_at(f: &ast::Formula, path: &[usize]) -> crate::source::Span {
    let mut f = f;
    for &i in path {
        let next = match f {
            ast::Formula::Not { formula, .. } => Some(&**formula),
            ast::Formula::And { parts, .. } | ast::Formula::Or { parts, .. } => parts.get(i),
            ast::Formula::Imply { left, right, .. } => match i {
                0 => Some(&**left),
                _ => Some(&**right),
            },
            ast::Formula::Exists { body, .. } | ast::Formula::Forall { body, .. } => Some(&**body),
            _ => None,
        };
        match next {
            Some(n) => f = n,
            None => break,
        }
    }
    f.span()
}

#[cfg(test)]
mod tests;
