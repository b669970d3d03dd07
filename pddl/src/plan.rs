//! Plans as planners print them, and their typing against a problem.

pub mod parse;
pub mod typing;

pub use parse::{parse_plan, Plan, PlanFormat, PlanStep};
pub use typing::{type_plan, GroundStep};
