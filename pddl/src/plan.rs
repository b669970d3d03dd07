//! Plans as planners print them, and their typing against a problem.

pub mod fit;
pub mod parse;
pub mod step;
pub mod typing;
pub mod written;

pub use fit::NameFit;
pub use parse::{parse_plan, Plan, PlanFormat};
pub use step::{Call, PlanStep};
pub use typing::{type_plan, GroundStep};
pub use written::{PlanWriter, WrittenPlan};
