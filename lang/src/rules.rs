//! The `.btrules` language: lexer, syntax tree, parser, formatter.

pub mod ast;
pub mod check;
pub mod fmt;
pub mod lexer;
pub mod matching;
pub mod palette;
pub mod parse;

pub use ast::*;
pub use parse::{parse_rules, ParsedRules};
