//! The PDDL front end: lexing, s-expressions, the typed model, its checks.

pub mod ast;
pub mod check;
pub mod lexer;
pub mod parse;
pub mod print;
pub mod sexpr;
pub mod types;

pub use ast::{Domain, Problem};

pub use check::{check_domain, check_problem, DomainIndex, ProblemIndex};
pub use parse::{parse_document, parse_domain, parse_problem, Document};
