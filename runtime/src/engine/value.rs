//! Blackboard values.

use btc_ir::PortValue;
use std::rc::Rc;

/// A blackboard value. Text from XML is converted when a typed port reads it.
#[derive(Clone, Debug, PartialEq)]
pub enum Value {
    Empty,
    Text(Rc<str>),
    Int(i64),
    Float(f64),
    Bool(bool),
}

impl Value {
    pub(crate) fn from_port(v: &PortValue) -> Value {
        match v {
            PortValue::Text(s) => Value::Text(s.as_str().into()),
            PortValue::Int(n) => Value::Int(*n),
            PortValue::Float(f) => Value::Float(*f),
            PortValue::Bool(b) => Value::Bool(*b),
            PortValue::Param(p) => Value::Text(format!("{{{p}}}").into()),
            PortValue::Formula(_) | PortValue::Effect(_) => Value::Text(v.to_text().into()),
        }
    }

    pub fn as_int(&self) -> Option<i64> {
        match self {
            Value::Int(n) => Some(*n),
            Value::Float(f) if f.fract() == 0.0 => Some(*f as i64),
            Value::Text(s) => s.trim().parse().ok(),
            _ => None,
        }
    }

    pub fn text(&self) -> String {
        match self {
            Value::Empty => String::new(),
            Value::Text(s) => s.to_string(),
            Value::Int(n) => n.to_string(),
            Value::Float(f) => btc_ir::format_float(*f),
            Value::Bool(b) => b.to_string(),
        }
    }

    /// Converts text to a port's declared type (`int`, `float`, `bool`;
    /// anything else stays text).
    pub(crate) fn typed(self, ty: &str) -> Result<Value, String> {
        let Value::Text(s) = &self else {
            return Ok(self);
        };
        let t = s.trim();
        Ok(match ty {
            "int" => Value::Int(t.parse().map_err(|_| format!("`{s}` is not an int"))?),
            "float" => Value::Float(t.parse().map_err(|_| format!("`{s}` is not a float"))?),
            "bool" => match t {
                "true" | "1" => Value::Bool(true),
                "false" | "0" => Value::Bool(false),
                _ => return Err(format!("`{s}` is not a bool")),
            },
            _ => self,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn text_converts_to_the_declared_port_type() {
        let t = |s: &str| Value::Text(s.into());
        assert_eq!(t(" 42 ").typed("int"), Ok(Value::Int(42)));
        assert_eq!(t("2.5").typed("float"), Ok(Value::Float(2.5)));
        assert_eq!(t("true").typed("bool"), Ok(Value::Bool(true)));
        assert_eq!(t("bin1").typed("container"), Ok(t("bin1")));
        assert!(t("three").typed("int").is_err());
        assert_eq!(Value::Int(3).typed("int"), Ok(Value::Int(3)));
    }
}
