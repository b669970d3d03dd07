//! The `.btrules` language: its syntax, its checks against a PDDL domain,
//! the salsa database that ties files together incrementally, and the
//! lowering of rules and a typed plan into the tree IR ([`btc_ir`]).
//!
//! The PDDL front end is [`btc_pddl`]; the emitters are `btc-emit`. Nothing
//! here prints or touches the file system: the CLI and the language server
//! read files and hand their texts to [`db`].

pub mod db;
pub mod declared;
pub mod lower;
pub mod path;
pub mod project;
pub mod resolutions;
pub mod rules;
pub mod stubs;
pub mod targets;
