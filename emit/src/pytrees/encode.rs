//! Logic values and port values as Python literals: the nested tuples
//! `btc_runtime.py` evaluates (its docstring is the format's reference).
//! Nothing here prints PDDL text for Python to parse.
//!
//! A step's conditions and effects are written *lifted*: an object that is
//! the step's `i`-th argument becomes the variable `?#i` (a name PDDL cannot
//! spell), so the steps of one action share one shape and the runtime binds
//! `?#i` back to the argument. Regrounding gives back exactly the value
//! written, whichever argument an object is taken for.

use super::names::{push_py_str, py_str};
use btc_ir::{push_float, push_int, PortValue};
use btc_pddl::logic::TypedVar;
use btc_pddl::logic::{AssignOp, Atom, Comparison, Effect, Formula, NumExpr, NumOp, Term};
use std::fmt::Write;

/// Writes logic values into `out`; objects among `args` are lifted.
pub struct Encoder<'a> {
    pub out: &'a mut String,
    pub args: &'a [String],
}

impl Encoder<'_> {
    fn term(&mut self, t: &Term) {
        match t {
            Term::Var(v) => self.out.push_str(&py_str(&format!("?{v}"))),
            Term::Obj(o) => match self.args.iter().position(|a| **a == **o) {
                Some(i) => {
                    let _ = write!(self.out, "\"?#{i}\"");
                }
                None => push_py_str(self.out, o),
            },
        }
    }

    /// `("pred", t1, ...)`, with `head` before the arguments when given.
    fn atom(&mut self, head: Option<&str>, a: &Atom) {
        self.out.push('(');
        if let Some(h) = head {
            self.out.push_str(h);
            self.out.push_str(", ");
        }
        push_py_str(self.out, &a.pred);
        for t in &a.args {
            self.out.push_str(", ");
            self.term(t);
        }
        if a.args.is_empty() && head.is_none() {
            self.out.push(',');
        }
        self.out.push(')');
    }

    fn vars(&mut self, vs: &[TypedVar]) {
        self.out.push('(');
        for v in vs {
            self.out.push('(');
            self.out.push_str(&py_str(&format!("?{}", v.name)));
            self.out.push_str(", (");
            for t in &v.types {
                self.out.push_str(&py_str(t));
                self.out.push_str(", ");
            }
            self.out.push_str(")), ");
        }
        self.out.push(')');
    }

    fn tagged<T>(&mut self, tag: &str, parts: &[T], each: impl Fn(&mut Self, &T)) {
        self.out.push_str("(\"");
        self.out.push_str(tag);
        self.out.push('"');
        for p in parts {
            self.out.push_str(", ");
            each(self, p);
        }
        // `(":and",)`: without the comma Python reads a string, not a tuple.
        if parts.is_empty() {
            self.out.push(',');
        }
        self.out.push(')');
    }

    pub fn formula(&mut self, f: &Formula) {
        match f {
            Formula::Atom(a) => self.atom(None, a),
            Formula::Equal(l, r) => {
                self.out.push_str("(\":eq\", ");
                self.term(l);
                self.out.push_str(", ");
                self.term(r);
                self.out.push(')');
            }
            Formula::Not(x) => self.tagged(":not", std::slice::from_ref(&**x), Self::formula),
            Formula::And(ps) => self.tagged(":and", ps, Self::formula),
            Formula::Or(ps) => self.tagged(":or", ps, Self::formula),
            Formula::Imply(l, r) => {
                self.out.push_str("(\":imply\", ");
                self.formula(l);
                self.out.push_str(", ");
                self.formula(r);
                self.out.push(')');
            }
            Formula::Exists(vs, body) | Formula::Forall(vs, body) => {
                let tag = if matches!(f, Formula::Exists(..)) {
                    ":exists"
                } else {
                    ":forall"
                };
                let _ = write!(self.out, "(\"{tag}\", ");
                self.vars(vs);
                self.out.push_str(", ");
                self.formula(body);
                self.out.push(')');
            }
            Formula::Compare(op, l, r) => {
                let op = match op {
                    Comparison::Lt => "<",
                    Comparison::Le => "<=",
                    Comparison::Gt => ">",
                    Comparison::Ge => ">=",
                    Comparison::Eq => "=",
                };
                let _ = write!(self.out, "(\":cmp\", \"{op}\", ");
                self.num(l);
                self.out.push_str(", ");
                self.num(r);
                self.out.push(')');
            }
        }
    }

    fn num(&mut self, e: &NumExpr) {
        match e {
            NumExpr::Number(x) => self.out.push_str(&py_float(*x)),
            NumExpr::Fluent(a) => self.atom(Some("\":f\""), a),
            NumExpr::Duration => self.out.push_str("(\":duration\",)"),
            NumExpr::Binary(op, l, r) => {
                let op = match op {
                    NumOp::Add => "+",
                    NumOp::Sub => "-",
                    NumOp::Mul => "*",
                    NumOp::Div => "/",
                };
                let _ = write!(self.out, "(\":bin\", \"{op}\", ");
                self.num(l);
                self.out.push_str(", ");
                self.num(r);
                self.out.push(')');
            }
            NumExpr::Neg(x) => {
                self.out.push_str("(\":neg\", ");
                self.num(x);
                self.out.push(')');
            }
        }
    }

    pub fn effect(&mut self, e: &Effect) {
        match e {
            Effect::Add(a) => self.atom(None, a),
            Effect::Delete(a) => {
                self.out.push_str("(\":del\", ");
                self.atom(None, a);
                self.out.push(')');
            }
            Effect::And(ps) => self.tagged(":and", ps, Self::effect),
            Effect::Forall(vs, body) => {
                self.out.push_str("(\":forall\", ");
                self.vars(vs);
                self.out.push_str(", ");
                self.effect(body);
                self.out.push(')');
            }
            Effect::When(c, body) => {
                self.out.push_str("(\":when\", ");
                self.formula(c);
                self.out.push_str(", ");
                self.effect(body);
                self.out.push(')');
            }
            Effect::Numeric(op, f, v) => {
                let op = match op {
                    AssignOp::Assign => "assign",
                    AssignOp::Increase => "increase",
                    AssignOp::Decrease => "decrease",
                    AssignOp::ScaleUp => "scale-up",
                    AssignOp::ScaleDown => "scale-down",
                };
                let _ = write!(self.out, "(\":num\", \"{op}\", ");
                self.atom(None, f);
                self.out.push_str(", ");
                self.num(v);
                self.out.push(')');
            }
        }
    }

    pub fn opt_formula(&mut self, f: Option<&Formula>) {
        match f {
            Some(f) => self.formula(f),
            None => self.out.push_str("None"),
        }
    }

    pub fn opt_effect(&mut self, e: Option<&Effect>) {
        match e {
            Some(e) => self.effect(e),
            None => self.out.push_str("None"),
        }
    }
}

/// A formula written without lifting.
pub fn formula(f: &Formula) -> String {
    let mut out = String::new();
    Encoder {
        out: &mut out,
        args: &[],
    }
    .formula(f);
    out
}

/// A ground atom (a fact or a fluent) as a tuple of names.
pub fn ground_atom(a: &Atom) -> String {
    let mut out = String::new();
    Encoder {
        out: &mut out,
        args: &[],
    }
    .atom(None, a);
    out
}

pub fn py_float(f: f64) -> String {
    let mut s = String::new();
    push_py_float(&mut s, f);
    s
}

/// [`py_float`] appended to `out` (a duration per step of a long plan).
pub fn push_py_float(out: &mut String, f: f64) {
    if f.is_nan() {
        out.push_str("float(\"nan\")");
    } else if f.is_infinite() {
        out.push_str(if f > 0.0 {
            "float(\"inf\")"
        } else {
            "float(\"-inf\")"
        });
    } else {
        push_float(out, f);
    }
}

/// A port value as a Python expression: a parameter of the enclosing tree
/// is `("$", name)`, a KB formula or effect its tuple.
pub fn port_value(v: &PortValue, out: &mut String) {
    match v {
        PortValue::Text(s) => push_py_str(out, s),
        PortValue::Int(n) => push_int(out, *n),
        PortValue::Float(f) => push_py_float(out, *f),
        PortValue::Bool(b) => out.push_str(if *b { "True" } else { "False" }),
        PortValue::Param(p) => {
            let _ = write!(out, "(\"$\", {})", py_str(p));
        }
        PortValue::Formula(f) => Encoder { out, args: &[] }.formula(f),
        PortValue::Effect(e) => Encoder { out, args: &[] }.effect(e),
    }
}
