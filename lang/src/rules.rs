//! The `.btrules` language: lexer, syntax tree, parser, formatter.

pub mod actions;
pub mod ast;
pub mod btxml;
pub mod check;
pub mod decls;
pub mod file_checks;
pub mod fmt;
pub mod lexer;
pub mod matching;
pub mod name;
pub mod palette;
pub mod parse;
pub mod reach;
pub mod resolve;
pub mod skip;
pub mod typo;

pub use ast::*;
pub use parse::{parse_rules, ParsedRules};
