//! PDDL text for model values, for messages, quick fixes and emitters.

use super::ast::*;
use std::fmt::{self, Display, Formatter};

fn list<T: Display>(f: &mut Formatter<'_>, head: &str, items: &[T]) -> fmt::Result {
    write!(f, "({head}")?;
    for i in items {
        write!(f, " {i}")?;
    }
    f.write_str(")")
}

fn vars(vs: &[Typed]) -> String {
    let parts: Vec<String> = vs
        .iter()
        .map(|v| match v.ty {
            TypeSpec::Object => format!("?{}", v.name.name),
            _ => format!("?{} - {}", v.name.name, v.ty),
        })
        .collect();
    format!("({})", parts.join(" "))
}

impl Display for NumExpr {
    fn fmt(&self, f: &mut Formatter<'_>) -> fmt::Result {
        match self {
            NumExpr::Number { value, .. } => write!(f, "{value}"),
            NumExpr::Fluent { app } => write!(f, "{app}"),
            NumExpr::Duration { .. } => f.write_str("?duration"),
            NumExpr::Binary {
                op, left, right, ..
            } => {
                let o = match op {
                    NumOp::Add => "+",
                    NumOp::Sub => "-",
                    NumOp::Mul => "*",
                    NumOp::Div => "/",
                };
                write!(f, "({o} {left} {right})")
            }
            NumExpr::Neg { expr, .. } => write!(f, "(- {expr})"),
        }
    }
}

impl Display for Formula {
    fn fmt(&self, f: &mut Formatter<'_>) -> fmt::Result {
        match self {
            Formula::Atom { atom } => write!(f, "{atom}"),
            Formula::Equal { left, right, .. } => write!(f, "(= {left} {right})"),
            Formula::Not { formula, .. } => write!(f, "(not {formula})"),
            Formula::And { parts, .. } => list(f, "and", parts),
            Formula::Or { parts, .. } => list(f, "or", parts),
            Formula::Imply { left, right, .. } => write!(f, "(imply {left} {right})"),
            Formula::Exists { vars: vs, body, .. } => write!(f, "(exists {} {body})", vars(vs)),
            Formula::Forall { vars: vs, body, .. } => write!(f, "(forall {} {body})", vars(vs)),
            Formula::Compare {
                op, left, right, ..
            } => {
                let o = match op {
                    Comparison::Lt => "<",
                    Comparison::Le => "<=",
                    Comparison::Gt => ">",
                    Comparison::Ge => ">=",
                    Comparison::Eq => "=",
                };
                write!(f, "({o} {left} {right})")
            }
        }
    }
}

impl Display for Effect {
    fn fmt(&self, f: &mut Formatter<'_>) -> fmt::Result {
        match self {
            Effect::Add { atom } => write!(f, "{atom}"),
            Effect::Delete { atom, .. } => write!(f, "(not {atom})"),
            Effect::And { parts, .. } => list(f, "and", parts),
            Effect::Forall { vars: vs, body, .. } => write!(f, "(forall {} {body})", vars(vs)),
            Effect::When {
                condition, body, ..
            } => write!(f, "(when {condition} {body})"),
            Effect::Numeric {
                op, fluent, value, ..
            } => {
                let o = match op {
                    AssignOp::Assign => "assign",
                    AssignOp::Increase => "increase",
                    AssignOp::Decrease => "decrease",
                    AssignOp::ScaleUp => "scale-up",
                    AssignOp::ScaleDown => "scale-down",
                };
                write!(f, "({o} {fluent} {value})")
            }
        }
    }
}

/// Several formulas as one: the formula itself, or their `and`.
pub fn conjunction(parts: &[Formula]) -> String {
    match parts {
        [one] => one.to_string(),
        many => {
            let inner: Vec<String> = many.iter().map(ToString::to_string).collect();
            format!("(and {})", inner.join(" "))
        }
    }
}

pub fn effects(parts: &[Effect]) -> String {
    match parts {
        [one] => one.to_string(),
        many => {
            let inner: Vec<String> = many.iter().map(ToString::to_string).collect();
            format!("(and {})", inner.join(" "))
        }
    }
}

#[cfg(test)]
mod tests {
    use crate::parse::parse_domain;

    #[test]
    fn prints_what_it_parsed() {
        let text = "(define (domain d) (:predicates (p ?x) (q)) (:functions (c))
          (:action a :parameters (?x) :precondition (and (p ?x) (not (= ?x k)) (forall (?y - t) (imply (p ?y) (q))) (>= (c) 1))
           :effect (and (not (p ?x)) (forall (?y) (when (q) (p ?y))) (increase (c) (* 2 (c))))))";
        let (d, _) = parse_domain(text, 0);
        let a = &d.unwrap().actions[0];
        assert_eq!(
            a.pre_start[0].to_string(),
            "(and (p ?x) (not (= ?x k)) (forall (?y - t) (imply (p ?y) (q))) (>= (c) 1))"
        );
        assert_eq!(
            a.eff_end[0].to_string(),
            "(and (not (p ?x)) (forall (?y) (when (q) (p ?y))) (increase (c) (* 2 (c))))"
        );
    }
}
