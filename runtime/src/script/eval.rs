//! Evaluation with BT.CPP's value rules. Numbers are integers, doubles or
//! booleans; arithmetic computes in doubles; strings meet numbers only in
//! comparisons (a string is read as a number there) and in `..`.

use super::{Assign, Binary, Compare, ErrorClass, Expr, Literal, ScriptError, Unary};
use crate::engine::Value;

/// The blackboard a script reads and writes, by variable index.
pub trait Env {
    /// The entry's value; `None` when there is no such entry.
    fn get(&self, var: u32) -> Option<&Value>;
    /// The entry to write; `create`: make it when missing (`:=`).
    fn entry(&mut self, var: u32, create: bool) -> Option<&mut Value>;
}

fn err(class: ErrorClass, m: impl Into<String>) -> ScriptError {
    ScriptError::new(class, m)
}

fn type_err(m: impl Into<String>) -> ScriptError {
    err(ErrorClass::Type, m)
}

fn not_init(side: &str, op: &str) -> ScriptError {
    err(
        ErrorClass::NotInitialized,
        format!("the {side} operand of `{op}` holds no value"),
    )
}

fn number(v: &Value) -> Option<f64> {
    match v {
        Value::Int(n) => Some(*n as f64),
        Value::Float(f) => Some(*f),
        Value::Bool(b) => Some(f64::from(u8::from(*b))),
        _ => None,
    }
}

/// A number that must be an integer (bitwise operators).
fn integer(f: f64) -> Option<i64> {
    (f.fract() == 0.0 && f >= i64::MIN as f64 && f <= i64::MAX as f64).then_some(f as i64)
}

/// A number as a boolean, as BT.CPP's `cast<bool>`: a double that is not
/// negative (zero is false), but only the integers 0 and 1.
fn boolean(v: &Value) -> Option<bool> {
    match v {
        Value::Float(f) if *f >= 0.0 => Some(*f != 0.0),
        Value::Bool(b) => Some(*b),
        Value::Int(0) => Some(false),
        Value::Int(1) => Some(true),
        _ => None,
    }
}

/// A string where a number is wanted: `true`, `false`, or text that
/// starts with a number (BT.CPP reads the number and ignores the rest:
/// `'3a'` is 3).
fn string_number(s: &str) -> Result<f64, ScriptError> {
    match s {
        "true" => Ok(1.0),
        "false" => Ok(0.0),
        _ => number_prefix(s).ok_or_else(|| type_err(format!("`{s}` is not a number"))),
    }
}

/// The number at the start of `s` (`-`, digits, a fraction, an exponent),
/// as C++'s `from_chars` reads it.
fn number_prefix(s: &str) -> Option<f64> {
    let b = s.as_bytes();
    let at = |i: usize| b.get(i).copied().unwrap_or(0);
    let mut i = usize::from(at(0) == b'-');
    let lower = s[i..].to_ascii_lowercase();
    for (word, v) in [
        ("infinity", f64::INFINITY),
        ("inf", f64::INFINITY),
        ("nan", f64::NAN),
    ] {
        if lower.starts_with(word) {
            return Some(if i == 1 { -v } else { v });
        }
    }
    let digits = |i: &mut usize| {
        let from = *i;
        while at(*i).is_ascii_digit() {
            *i += 1;
        }
        *i - from
    };
    let mut n = digits(&mut i);
    if at(i) == b'.' {
        let mut j = i + 1;
        let f = digits(&mut j);
        if n + f > 0 {
            n += f;
            i = j;
        }
    }
    if n == 0 {
        return None;
    }
    if matches!(at(i), b'e' | b'E') {
        let mut j = i + 1;
        if matches!(at(j), b'+' | b'-') {
            j += 1;
        }
        if digits(&mut j) > 0 {
            i = j;
        }
    }
    s[..i].parse().ok()
}

/// A number as `..` writes it: integers plainly, doubles as C++'s
/// `std::to_string` does.
fn number_text(v: &Value) -> String {
    match v {
        Value::Float(f) => format!("{f:.6}"),
        other => other.text(),
    }
}

/// Whether a value counts as true for `?:`: a non-zero number, or a
/// string that reads as one.
pub fn truthy(v: &Value) -> Result<bool, ScriptError> {
    // BT.CPP tests a string's size only for its own string type, which
    // script literals are not: a string must read as a number here.
    match v {
        Value::Text(s) => number_prefix(s)
            .map(|f| f != 0.0)
            .ok_or_else(|| type_err(format!("`{s}` is not a number, which `?:` tests"))),
        Value::Empty => Err(type_err("`?:` tests a value that is not there")),
        n => Ok(number(n).is_some_and(|f| f != 0.0)),
    }
}

/// Evaluates one expression.
pub fn eval(e: &Expr, env: &mut dyn Env) -> Result<Value, ScriptError> {
    Ok(match e {
        Expr::Lit(l) => match l {
            Literal::Int(n) => Value::Int(*n),
            Literal::Float(f) => Value::Float(*f),
            Literal::Text(s) => Value::Text(s.clone()),
        },
        Expr::Var(k) => env
            .get(*k)
            .cloned()
            .ok_or_else(|| err(ErrorClass::NotFound, "variable not found"))?,
        Expr::Unary(op, x) => {
            let v = eval(x, env)?;
            let Some(f) = number(&v) else {
                return Err(match v {
                    Value::Empty => not_init("right", "unary operator"),
                    _ => type_err("a unary operator does not take a string"),
                });
            };
            Value::Float(match op {
                Unary::Negate => -f,
                Unary::Complement => {
                    let n = (f >= i64::MIN as f64 && f <= i64::MAX as f64)
                        .then_some(f as i64)
                        .ok_or_else(|| type_err("number out of range for `~`"))?;
                    !n as f64
                }
                Unary::Not => f64::from(u8::from(f == 0.0)),
            })
        }
        Expr::Binary(op, l, r) => binary(*op, eval(l, env)?, eval(r, env)?)?,
        Expr::Compare(ops, xs) => {
            let mut left = eval(&xs[0], env)?;
            for (op, x) in ops.iter().zip(&xs[1..]) {
                let right = eval(x, env)?;
                if !compare(*op, &left, &right)? {
                    return Ok(Value::Float(0.0));
                }
                left = right;
            }
            Value::Float(1.0)
        }
        Expr::If(c, a, b) => {
            let c = eval(c, env)?;
            if truthy(&c)? {
                eval(a, env)?
            } else {
                eval(b, env)?
            }
        }
        Expr::Assign(op, l, r) => assign(*op, l, r, env)?,
    })
}

fn op_text(op: Binary) -> &'static str {
    match op {
        Binary::Plus => "+",
        Binary::Minus => "-",
        Binary::Times => "*",
        Binary::Div => "/",
        Binary::Concat => "..",
        Binary::BitAnd => "&",
        Binary::BitOr => "|",
        Binary::BitXor => "^",
        Binary::And => "&&",
        Binary::Or => "||",
    }
}

fn binary(op: Binary, l: Value, r: Value) -> Result<Value, ScriptError> {
    if l == Value::Empty {
        return Err(not_init("left", op_text(op)));
    }
    if r == Value::Empty {
        return Err(not_init("right", op_text(op)));
    }
    let text = |v: &Value| matches!(v, Value::Text(_));
    match (number(&l), number(&r)) {
        (Some(a), Some(b)) => Ok(match op {
            Binary::Plus => Value::Float(a + b),
            Binary::Minus => Value::Float(a - b),
            Binary::Times => Value::Float(a * b),
            Binary::Div => Value::Float(a / b),
            Binary::BitAnd | Binary::BitOr | Binary::BitXor => {
                let (Some(x), Some(y)) = (integer(a), integer(b)) else {
                    return Err(type_err(format!("`{}` takes integers only", op_text(op))));
                };
                Value::Float(match op {
                    Binary::BitAnd => x & y,
                    Binary::BitOr => x | y,
                    _ => x ^ y,
                } as f64)
            }
            Binary::And | Binary::Or => {
                let (Some(x), Some(y)) = (boolean(&l), boolean(&r)) else {
                    return Err(type_err(format!(
                        "`{}` takes booleans (0 or 1) only",
                        op_text(op)
                    )));
                };
                Value::Float(f64::from(u8::from(if op == Binary::And {
                    x && y
                } else {
                    x || y
                })))
            }
            // BT.CPP's `..` of two numbers gives no value.
            Binary::Concat => Value::Empty,
        }),
        _ if text(&l) && text(&r) && op == Binary::Plus => {
            Ok(Value::Text(format!("{}{}", l.text(), r.text()).into()))
        }
        _ if op == Binary::Concat && (text(&l) || text(&r)) => Ok(Value::Text(
            format!("{}{}", number_text(&l), number_text(&r)).into(),
        )),
        _ => Err(type_err(format!(
            "`{}` does not take these operands",
            op_text(op)
        ))),
    }
}

// NaN makes the negated tests differ from the plain ones, on purpose.
#[allow(clippy::neg_cmp_op_on_partial_ord)]
fn compare(op: Compare, l: &Value, r: &Value) -> Result<bool, ScriptError> {
    if *l == Value::Empty {
        return Err(not_init("left", "comparison"));
    }
    if *r == Value::Empty {
        return Err(not_init("right", "comparison"));
    }
    // Each test is the negation of its opposite, as BT.CPP writes them:
    // with a NaN, `<` `>` `<=` `>=` and `!=` hold, `==` does not.
    let ord = |a: f64, b: f64| -> bool {
        let same = (a - b).abs() <= f64::from(f32::EPSILON);
        match op {
            Compare::Eq => same,
            Compare::Ne => !same,
            Compare::Lt => !(a >= b),
            Compare::Gt => !(a <= b),
            Compare::Le => !(a > b),
            Compare::Ge => !(a < b),
        }
    };
    Ok(match (l, r) {
        (Value::Text(a), Value::Text(b)) => match op {
            Compare::Eq => a == b,
            Compare::Ne => a != b,
            Compare::Lt => a < b,
            Compare::Gt => a > b,
            Compare::Le => a <= b,
            Compare::Ge => a >= b,
        },
        (Value::Text(a), b) => ord(string_number(a)?, number(b).unwrap_or(0.0)),
        (a, Value::Text(b)) => ord(number(a).unwrap_or(0.0), string_number(b)?),
        (a, b) => ord(number(a).unwrap_or(0.0), number(b).unwrap_or(0.0)),
    })
}

/// `value` stored into an entry that already holds `old`: converted to
/// the entry's type, as BT.CPP's `copyInto` does.
fn convert_into(old: &Value, value: Value) -> Result<Value, ScriptError> {
    let refuse = || {
        type_err(format!(
            "the entry holds `{}`, which `{}` cannot replace",
            old.text(),
            value.text()
        ))
    };
    Ok(match (old, &value) {
        (Value::Empty, _) => value,
        (Value::Text(_), Value::Text(_)) => value,
        (Value::Text(_), _) => return Err(refuse()),
        (_, Value::Text(s)) => Value::Float(string_number(s)?),
        (Value::Int(_), v) => {
            let f = number(v).ok_or_else(refuse)?;
            Value::Int(integer(f).ok_or_else(refuse)?)
        }
        (Value::Bool(_), v) => Value::Bool(boolean(v).ok_or_else(refuse)?),
        (_, v) => Value::Float(number(v).ok_or_else(refuse)?),
    })
}

fn assign(op: Assign, l: &Expr, r: &Expr, env: &mut dyn Env) -> Result<Value, ScriptError> {
    let Expr::Var(k) = l else {
        return Err(type_err(
            "the left side of an assignment is not a blackboard entry",
        ));
    };
    if env.entry(*k, op == Assign::Create).is_none() {
        return Err(err(
            ErrorClass::NotFound,
            "the entry does not exist yet (`:=` creates it)",
        ));
    }
    let value = eval(r, env)?;
    if value == Value::Empty {
        return Err(not_init("right", "assignment"));
    }
    let Some(dst) = env.entry(*k, false) else {
        return Err(err(ErrorClass::NotFound, "the entry does not exist"));
    };
    let new = match op {
        Assign::Create | Assign::Existing => convert_into(dst, value)?,
        _ => {
            if *dst == Value::Empty {
                return Err(not_init("left", "assignment"));
            }
            match (number(dst), number(&value), &value) {
                (Some(a), Some(b), _) => {
                    let f = match op {
                        Assign::Plus => a + b,
                        Assign::Minus => a - b,
                        Assign::Times => a * b,
                        _ => a / b,
                    };
                    convert_into(dst, Value::Float(f))?
                }
                (None, Some(_), _) => return Err(type_err("this assignment takes a number entry")),
                // A string joined to a number entry cannot go back into it.
                (None, None, Value::Text(s)) if op == Assign::Plus => {
                    Value::Text(format!("{}{s}", dst.text()).into())
                }
                _ => return Err(type_err("this assignment does not take strings")),
            }
        }
    };
    *dst = new.clone();
    Ok(new)
}

#[cfg(test)]
mod tests;
