//! Plans as planners print them, and their typing against a problem.

pub mod fit;
pub mod parse;
pub mod typing;

pub use fit::NameFit;
pub use parse::{parse_plan, Plan, PlanFormat, PlanStep};
pub use typing::{type_plan, GroundStep};
