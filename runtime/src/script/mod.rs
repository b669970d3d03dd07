//! BehaviorTree.CPP's scripting language (`Script`, `ScriptCondition`,
//! `Precondition` and the `_skipIf`/`_onSuccess`... attributes): text is
//! read once, when the tree is built, into an expression tree (the syntax
//! is crate `btc-script`'s, which the rules checker parses with too) whose
//! variables become blackboard slots; a tick evaluates it over the
//! blackboard with BT.CPP's value rules (numbers compute as doubles,
//! integer literals stay integers until they meet an operator,
//! `true`/`false` are 1 and 0). The differences from BT.CPP that are
//! intended are listed in `docs/runtime.md`.

mod eval;

pub use btc_script::{Assign, Binary, Compare, Expr, Literal, Unary};
pub use eval::{eval, truthy};

use std::fmt;

/// A parsed script: its statements and the variables they name.
#[derive(Clone, Debug, PartialEq)]
pub struct Script {
    pub statements: Vec<Expr>,
    pub vars: Vec<String>,
}

/// Parses a script (statements separated by `;`); a syntax error is of
/// class [`ErrorClass::Syntax`], at the bad token's offset.
pub fn parse(src: &str) -> Result<Script, ScriptError> {
    match btc_script::parse(src) {
        Ok(s) => Ok(Script {
            statements: s.statements,
            vars: s.vars,
        }),
        Err(e) => Err(ScriptError {
            class: ErrorClass::Syntax,
            message: e.to_string(),
            at: Some(e.span.start),
        }),
    }
}

/// What kind of error a script met: the classes BT.CPP's own messages fall
/// into, so that the two evaluators can be compared.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum ErrorClass {
    /// The text is not a script (BT.CPP refuses it when the tree is built).
    Syntax,
    /// A variable that is no blackboard entry.
    NotFound,
    /// An operand that holds no value yet.
    NotInitialized,
    /// Operands of types the operator does not take.
    Type,
}

impl ErrorClass {
    pub fn name(self) -> &'static str {
        match self {
            ErrorClass::Syntax => "syntax",
            ErrorClass::NotFound => "not_found",
            ErrorClass::NotInitialized => "not_initialized",
            ErrorClass::Type => "type",
        }
    }
}

#[derive(Clone, Debug, PartialEq)]
pub struct ScriptError {
    pub class: ErrorClass,
    pub message: String,
    /// Byte offset in the script text (syntax errors).
    pub at: Option<usize>,
}

impl ScriptError {
    pub(crate) fn new(class: ErrorClass, message: impl Into<String>) -> ScriptError {
        ScriptError {
            class,
            message: message.into(),
            at: None,
        }
    }
}

impl fmt::Display for ScriptError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.message)
    }
}

impl Script {
    /// Runs the statements in order; the value of the last one.
    pub fn run(&self, env: &mut dyn eval::Env) -> Result<crate::engine::Value, ScriptError> {
        let mut last = crate::engine::Value::Empty;
        for s in &self.statements {
            last = eval(s, env)?;
        }
        Ok(last)
    }
}

pub use eval::Env;

/// A script's value as BT.CPP's `cast<bool>` reads it (preconditions,
/// `ScriptCondition`): a boolean, a double that is not negative (zero is false), the integers
/// 0 and 1, or the text `true`/`false`/`1`/`0`.
pub fn as_bool(v: &crate::engine::Value) -> Result<bool, ScriptError> {
    use crate::engine::Value;
    let no = || ScriptError::new(ErrorClass::Type, format!("`{}` is not a boolean", v.text()));
    match v {
        Value::Bool(b) => Ok(*b),
        Value::Int(0) => Ok(false),
        Value::Int(1) => Ok(true),
        Value::Float(f) if *f >= 0.0 => Ok(*f != 0.0),
        Value::Text(s) => match s.trim() {
            "true" | "1" => Ok(true),
            "false" | "0" => Ok(false),
            _ => Err(no()),
        },
        Value::Empty => Err(ScriptError::new(
            ErrorClass::NotInitialized,
            "the script gives no value",
        )),
        _ => Err(no()),
    }
}

/// X040 for `text`, the script in attribute (or port) `attr` of node `node`,
/// that does not parse.
pub(crate) fn syntax_error(
    node: &str,
    attr: &str,
    text: &str,
    e: &ScriptError,
) -> crate::error::LoadError {
    crate::error::LoadError::new(
        btc_pddl::diagnostic::codes::X_SCRIPT,
        format!("`{attr}` of `{node}`: {e}"),
    )
    .hint(format!(
        "the script is `{text}`; BT.CPP's scripting language is described in docs/runtime.md"
    ))
}
