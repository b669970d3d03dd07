//! PDDL text for logic values, as the front end reads it back: `Display`
//! writes what [`super::decode`] parses into an equal value.

use super::*;
use std::fmt::{self, Display, Formatter, Write};

fn list<T: Display>(f: &mut Formatter<'_>, head: &str, items: &[T]) -> fmt::Result {
    write!(f, "({head}")?;
    for i in items {
        write!(f, " {i}")?;
    }
    f.write_char(')')
}

impl Display for Term {
    fn fmt(&self, f: &mut Formatter<'_>) -> fmt::Result {
        match self {
            Term::Var(v) => write!(f, "?{v}"),
            Term::Obj(o) => f.write_str(o),
        }
    }
}

impl Display for Atom {
    fn fmt(&self, f: &mut Formatter<'_>) -> fmt::Result {
        write!(f, "({}", self.pred)?;
        for a in &self.args {
            write!(f, " {a}")?;
        }
        f.write_char(')')
    }
}

impl Display for Literal {
    fn fmt(&self, f: &mut Formatter<'_>) -> fmt::Result {
        if self.positive {
            write!(f, "{}", self.atom)
        } else {
            write!(f, "(not {})", self.atom)
        }
    }
}

/// A written type: `t`, `(either a b)`, or `object` for none.
pub struct TypeText<'a>(pub &'a [Name]);

impl Display for TypeText<'_> {
    fn fmt(&self, f: &mut Formatter<'_>) -> fmt::Result {
        match self.0 {
            [] => f.write_str("object"),
            [one] => f.write_str(one),
            many => list(f, "either", many),
        }
    }
}

impl Display for TypedVar {
    fn fmt(&self, f: &mut Formatter<'_>) -> fmt::Result {
        match self.types.as_slice() {
            [] => write!(f, "?{}", self.name),
            types => write!(f, "?{} - {}", self.name, TypeText(types)),
        }
    }
}

/// `(?x ?y - t)`: a quantifier's variables.
struct Vars<'a>(&'a [TypedVar]);

impl Display for Vars<'_> {
    fn fmt(&self, f: &mut Formatter<'_>) -> fmt::Result {
        f.write_char('(')?;
        for (i, v) in self.0.iter().enumerate() {
            if i > 0 {
                f.write_char(' ')?;
            }
            write!(f, "{v}")?;
        }
        f.write_char(')')
    }
}

fn num_op(op: NumOp) -> &'static str {
    match op {
        NumOp::Add => "+",
        NumOp::Sub => "-",
        NumOp::Mul => "*",
        NumOp::Div => "/",
    }
}

pub(crate) fn comparison(op: Comparison) -> &'static str {
    match op {
        Comparison::Lt => "<",
        Comparison::Le => "<=",
        Comparison::Gt => ">",
        Comparison::Ge => ">=",
        Comparison::Eq => "=",
    }
}

pub(crate) fn assign_op(op: AssignOp) -> &'static str {
    match op {
        AssignOp::Assign => "assign",
        AssignOp::Increase => "increase",
        AssignOp::Decrease => "decrease",
        AssignOp::ScaleUp => "scale-up",
        AssignOp::ScaleDown => "scale-down",
    }
}

impl Display for NumExpr {
    fn fmt(&self, f: &mut Formatter<'_>) -> fmt::Result {
        match self {
            NumExpr::Number(v) => write!(f, "{v}"),
            NumExpr::Fluent(a) => write!(f, "{a}"),
            NumExpr::Duration => f.write_str("?duration"),
            NumExpr::Binary(op, l, r) => write!(f, "({} {l} {r})", num_op(*op)),
            NumExpr::Neg(e) => write!(f, "(- {e})"),
        }
    }
}

impl Display for Formula {
    fn fmt(&self, f: &mut Formatter<'_>) -> fmt::Result {
        match self {
            Formula::Atom(a) => write!(f, "{a}"),
            Formula::Equal(l, r) => write!(f, "(= {l} {r})"),
            Formula::Not(x) => write!(f, "(not {x})"),
            Formula::And(ps) => list(f, "and", ps),
            Formula::Or(ps) => list(f, "or", ps),
            Formula::Imply(l, r) => write!(f, "(imply {l} {r})"),
            Formula::Exists(vs, b) => write!(f, "(exists {} {b})", Vars(vs)),
            Formula::Forall(vs, b) => write!(f, "(forall {} {b})", Vars(vs)),
            Formula::Compare(op, l, r) => write!(f, "({} {l} {r})", comparison(*op)),
        }
    }
}

impl Display for Effect {
    fn fmt(&self, f: &mut Formatter<'_>) -> fmt::Result {
        match self {
            Effect::Add(a) => write!(f, "{a}"),
            Effect::Delete(a) => write!(f, "(not {a})"),
            Effect::And(ps) => list(f, "and", ps),
            Effect::Forall(vs, b) => write!(f, "(forall {} {b})", Vars(vs)),
            Effect::When(c, b) => write!(f, "(when {c} {b})"),
            Effect::Numeric(op, fl, v) => write!(f, "({} {fl} {v})", assign_op(*op)),
        }
    }
}

impl Display for InitFact {
    fn fmt(&self, f: &mut Formatter<'_>) -> fmt::Result {
        match self {
            InitFact::Atom(a) => write!(f, "{a}"),
            InitFact::Value(a, v) => write!(f, "(= {a} {v})"),
        }
    }
}

impl Display for Signature {
    fn fmt(&self, f: &mut Formatter<'_>) -> fmt::Result {
        write!(f, "({}", self.name)?;
        for p in &self.params {
            write!(f, " {p}")?;
        }
        f.write_str(")")
    }
}
