//! Errors in loaded trees and scenario files: a stable code, a message in
//! the user's terms, where in the file (a byte offset) and a hint. The CLI
//! turns them into diagnostics and renders them.

use btc_pddl::diagnostic::Code;
use std::fmt;

#[derive(Clone, Debug, PartialEq)]
pub struct LoadError {
    pub code: Code,
    pub message: String,
    /// Byte offset in the file the error is about.
    pub offset: Option<usize>,
    pub hint: Option<String>,
}

impl LoadError {
    pub fn new(code: Code, message: impl Into<String>) -> LoadError {
        LoadError {
            code,
            message: message.into(),
            offset: None,
            hint: None,
        }
    }

    pub fn at(mut self, offset: usize) -> LoadError {
        self.offset = Some(offset);
        self
    }

    pub fn at_opt(mut self, offset: Option<usize>) -> LoadError {
        if self.offset.is_none() {
            self.offset = offset;
        }
        self
    }

    pub fn hint(mut self, hint: impl Into<String>) -> LoadError {
        self.hint = Some(hint.into());
        self
    }
}

impl fmt::Display for LoadError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "[{}] {}", self.code.id, self.message)?;
        if let Some(h) = &self.hint {
            write!(f, " (hint: {h})")?;
        }
        Ok(())
    }
}

impl std::error::Error for LoadError {}
