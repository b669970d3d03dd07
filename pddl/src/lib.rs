//! The PDDL front end of btc: source text, diagnostics, the PDDL model and
//! its checks, plans, ground states and plan validation.
//!
//! Layering is one-way: text ([`source`]) -> syntax ([`lexer`], [`sexpr`])
//! -> model ([`ast`], checked by [`check`]) -> plans ([`plan`]) ->
//! simulation ([`state`], [`validate`]). Nothing here prints or touches the
//! file system; callers read files and render [`diagnostic::Diagnostic`]
//! values ([`render`]). The planner, the runtime's simulated world and the
//! rules language all build on this crate alone.

pub mod ast;
pub mod check;
pub mod diagnostic;
pub mod lexer;
pub mod limits;
pub mod logic;
pub mod parse;
pub mod pipeline;
pub mod plan;
pub mod print;
pub mod problem_text;
pub mod render;
pub mod sexpr;
pub mod source;
pub mod state;
pub mod types;
pub mod validate;
pub mod world;
pub mod written_problem;

pub use ast::{Domain, Problem};
pub use check::{check_domain, check_problem, DomainIndex, ProblemIndex};
pub use parse::{parse_document, parse_domain, parse_problem, Document};
