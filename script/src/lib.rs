//! BehaviorTree.CPP's scripting language (`Script`, `ScriptCondition`,
//! `Precondition` and the `_skipIf`/`_onSuccess`... attributes) as syntax:
//! the tokens (`lex`), a Pratt parser with BT.CPP's binding powers
//! (`parse`) and the expression tree it builds, whose variables are
//! indexes into the script's list of names. Evaluation, with BT.CPP's
//! value rules, is the runtime's (`btc_runtime::script`); the rules
//! checker parses the scripts of a `.btrules` file here, so a script that
//! BT.CPP would refuse is reported where it is written.
//!
//! No dependencies: both the rules language and the runtime sit above it.

mod lex;
mod parse;

pub use parse::{parse, Assign, Binary, Compare, Expr, Literal, Script, Unary, MAX_NESTING};

use std::fmt;
use std::ops::Range;

/// What is wrong with a script's text.
#[derive(Clone, Debug, PartialEq)]
pub enum Problem {
    /// Text that is no token: a number glued to letters (`3foo`), `65.`,
    /// a character the language has no use for.
    BadToken(String),
    /// A string (`'...`) that does not end.
    Unterminated(String),
    /// A token where another was wanted; `got` is `None` at the end.
    Unexpected {
        expected: &'static str,
        got: Option<String>,
    },
    /// No statement at all.
    Empty,
    /// Nested deeper than [`MAX_NESTING`].
    TooDeep,
}

/// A script that does not parse: the problem and the bytes of the script
/// it is at (the bad token, or the empty range at the end).
#[derive(Clone, Debug, PartialEq)]
pub struct SyntaxError {
    pub problem: Problem,
    pub span: Range<usize>,
}

impl SyntaxError {
    /// The problem in words, without its position: for a message whose
    /// span shows where it is.
    pub fn describe(&self) -> String {
        match &self.problem {
            Problem::BadToken(t) => {
                format!("`{t}` is not a token of BT.CPP's scripting language")
            }
            Problem::Unterminated(_) => "this string has no closing `'`".into(),
            Problem::Unexpected { expected, got } => match got {
                Some(t) => format!("{expected}, got `{t}`"),
                None => format!("{expected}, but the script ends here"),
            },
            Problem::Empty => "the script is empty".into(),
            Problem::TooDeep => format!("the script nests deeper than {MAX_NESTING} levels"),
        }
    }
}

/// The message with the position in the script, as the runtime reports
/// it (X040) where it has only the attribute to point at.
impl fmt::Display for SyntaxError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let at = self.span.start;
        match &self.problem {
            Problem::BadToken(t) | Problem::Unterminated(t) => {
                write!(f, "invalid token `{t}` at position {at}")
            }
            Problem::Unexpected { expected, got } => match got {
                Some(t) => write!(f, "{expected} at position {at}, got `{t}`"),
                None => write!(f, "{expected} at position {at}, got the end"),
            },
            Problem::Empty | Problem::TooDeep => f.write_str(&self.describe()),
        }
    }
}

#[cfg(test)]
mod tests;
