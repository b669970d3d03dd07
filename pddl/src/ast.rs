//! The PDDL model: domains and problems with a span on every node. Names are
//! lower-case (PDDL is case-insensitive); spans point at the text as written.

use crate::source::Span;
use serde::{Deserialize, Serialize};
pub use smol_str::SmolStr;

/// A name as written (lower-cased) and where. The text is a [`SmolStr`]:
/// PDDL names are short, so they live inline, and a long plan's thousands
/// of repeated object names cost no allocation each.
#[derive(Clone, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub struct Name {
    pub name: SmolStr,
    pub span: Span,
}

impl Name {
    pub fn as_str(&self) -> &str {
        &self.name
    }
}

/// The type after `-` in a typed list. `object` when none is written.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "lowercase")]
pub enum TypeSpec {
    Object,
    Named { name: Name },
    Either { names: Vec<Name>, span: Span },
}

impl TypeSpec {
    /// The type names this spec allows (`object` for none written).
    pub fn names(&self) -> Vec<&str> {
        match self {
            TypeSpec::Object => vec!["object"],
            TypeSpec::Named { name } => vec![name.as_str()],
            TypeSpec::Either { names, .. } => names.iter().map(Name::as_str).collect(),
        }
    }
}

impl std::fmt::Display for TypeSpec {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            TypeSpec::Object => f.write_str("object"),
            TypeSpec::Named { name } => f.write_str(&name.name),
            TypeSpec::Either { names, .. } => {
                f.write_str("(either")?;
                for n in names {
                    write!(f, " {}", n.name)?;
                }
                f.write_str(")")
            }
        }
    }
}

/// `name - type`: a type declaration, a constant, an object or a parameter
/// (for parameters `name` is the variable without `?`).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Typed {
    pub name: Name,
    pub ty: TypeSpec,
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "lowercase")]
pub enum Term {
    Var { name: Name },
    Const { name: Name },
}

impl Term {
    pub fn span(&self) -> Span {
        match self {
            Term::Var { name } | Term::Const { name } => name.span,
        }
    }
}

impl std::fmt::Display for Term {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Term::Var { name } => write!(f, "?{}", name.name),
            Term::Const { name } => f.write_str(&name.name),
        }
    }
}

/// `(pred t1 t2 ...)`, also used for function applications `(f t1 ...)`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Atom {
    pub pred: Name,
    pub args: Vec<Term>,
    pub span: Span,
}

impl std::fmt::Display for Atom {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "({}", self.pred.name)?;
        for a in &self.args {
            write!(f, " {a}")?;
        }
        f.write_str(")")
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Comparison {
    Lt,
    Le,
    Gt,
    Ge,
    Eq,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum NumOp {
    Add,
    Sub,
    Mul,
    Div,
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "lowercase")]
pub enum NumExpr {
    Number {
        value: f64,
        span: Span,
    },
    Fluent {
        app: Atom,
    },
    /// `?duration` inside a durative action.
    Duration {
        span: Span,
    },
    Binary {
        op: NumOp,
        left: Box<NumExpr>,
        right: Box<NumExpr>,
        span: Span,
    },
    Neg {
        expr: Box<NumExpr>,
        span: Span,
    },
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "lowercase")]
pub enum Formula {
    Atom {
        atom: Atom,
    },
    Equal {
        left: Term,
        right: Term,
        span: Span,
    },
    Not {
        formula: Box<Formula>,
        span: Span,
    },
    And {
        parts: Vec<Formula>,
        span: Span,
    },
    Or {
        parts: Vec<Formula>,
        span: Span,
    },
    Imply {
        left: Box<Formula>,
        right: Box<Formula>,
        span: Span,
    },
    Exists {
        vars: Vec<Typed>,
        body: Box<Formula>,
        span: Span,
    },
    Forall {
        vars: Vec<Typed>,
        body: Box<Formula>,
        span: Span,
    },
    Compare {
        op: Comparison,
        left: NumExpr,
        right: NumExpr,
        span: Span,
    },
}

impl Formula {
    pub fn span(&self) -> Span {
        match self {
            Formula::Atom { atom } => atom.span,
            Formula::Equal { span, .. }
            | Formula::Not { span, .. }
            | Formula::And { span, .. }
            | Formula::Or { span, .. }
            | Formula::Imply { span, .. }
            | Formula::Exists { span, .. }
            | Formula::Forall { span, .. }
            | Formula::Compare { span, .. } => *span,
        }
    }

    /// The empty conjunction `(and)`, which always holds.
    pub fn truth(span: Span) -> Formula {
        Formula::And {
            parts: Vec::new(),
            span,
        }
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum AssignOp {
    Assign,
    Increase,
    Decrease,
    ScaleUp,
    ScaleDown,
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "lowercase")]
pub enum Effect {
    Add {
        atom: Atom,
    },
    Delete {
        atom: Atom,
        span: Span,
    },
    And {
        parts: Vec<Effect>,
        span: Span,
    },
    Forall {
        vars: Vec<Typed>,
        body: Box<Effect>,
        span: Span,
    },
    When {
        condition: Formula,
        body: Box<Effect>,
        span: Span,
    },
    Numeric {
        op: AssignOp,
        fluent: Atom,
        value: NumExpr,
        span: Span,
    },
}

impl Effect {
    pub fn span(&self) -> Span {
        match self {
            Effect::Add { atom } => atom.span,
            Effect::Delete { span, .. }
            | Effect::And { span, .. }
            | Effect::Forall { span, .. }
            | Effect::When { span, .. }
            | Effect::Numeric { span, .. } => *span,
        }
    }

    pub fn empty(span: Span) -> Effect {
        Effect::And {
            parts: Vec::new(),
            span,
        }
    }
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct PredicateDecl {
    pub name: Name,
    pub params: Vec<Typed>,
    pub span: Span,
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct FunctionDecl {
    pub name: Name,
    pub params: Vec<Typed>,
    /// `number` unless the declaration says otherwise.
    pub ty: Name,
    pub span: Span,
}

/// A duration constraint `(= ?duration expr)`; inequalities are refused.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Duration {
    pub value: NumExpr,
    pub span: Span,
}

/// Conditions and effects split by when they apply. A plain `:action` has
/// only `at_start` conditions and `at_end` effects: its precondition is
/// checked when it starts and its effect applies when it ends.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Action {
    pub name: Name,
    pub params: Vec<Typed>,
    pub durative: bool,
    pub duration: Option<Duration>,
    pub pre_start: Vec<Formula>,
    pub pre_over_all: Vec<Formula>,
    pub pre_end: Vec<Formula>,
    pub eff_start: Vec<Effect>,
    pub eff_end: Vec<Effect>,
    pub span: Span,
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Derived {
    pub head: PredicateDecl,
    pub body: Formula,
    pub span: Span,
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Domain {
    pub name: Name,
    pub requirements: Vec<Name>,
    pub types: Vec<Typed>,
    pub constants: Vec<Typed>,
    pub predicates: Vec<PredicateDecl>,
    pub functions: Vec<FunctionDecl>,
    pub actions: Vec<Action>,
    pub derived: Vec<Derived>,
    pub span: Span,
}

/// A fact of `:init`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "lowercase")]
pub enum InitFact {
    Atom {
        atom: Atom,
    },
    /// `(= (f a b) 3)`
    Value {
        fluent: Atom,
        value: f64,
        span: Span,
    },
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Optimize {
    Minimize,
    Maximize,
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Metric {
    pub optimize: Optimize,
    pub expr: NumExpr,
    pub span: Span,
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Problem {
    pub name: Name,
    pub domain: Name,
    pub requirements: Vec<Name>,
    pub objects: Vec<Typed>,
    pub init: Vec<InitFact>,
    pub goal: Option<Formula>,
    pub metric: Option<Metric>,
    pub span: Span,
}
