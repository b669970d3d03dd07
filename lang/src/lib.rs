//! The btc compiler library.
//!
//! Layering is one-way: text ([`source`]) -> syntax ([`pddl::lexer`],
//! [`pddl::sexpr`]) -> model ([`pddl::ast`], checked by [`pddl::check`]) ->
//! plans ([`plan`]) -> simulation ([`validate`]). Nothing here prints or
//! touches the file system except [`source::load`]; the CLI and the language
//! server do the IO and render [`diagnostic::Diagnostic`] values.

pub mod db;
pub mod diagnostic;
pub mod emit;
pub mod ir;
pub mod lower;
pub mod pddl;
pub mod pipeline;
pub mod plan;
pub mod render;
pub mod rules;
pub mod source;
pub mod state;
pub mod validate;
