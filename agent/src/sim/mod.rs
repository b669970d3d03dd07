//! The ARIAC task level (Liu et al. 2024, section 3, Figures 2 and 3): a
//! task manager that announces orders as their conditions come true,
//! breaks them into part tasks, keeps the kitting, assembly and combined
//! queues and hands part tasks to a floor agent and a ceiling agent by the
//! paper's rules; each agent plans its task from the shared world's state
//! with `btc_planner::plan_from`, compiles the plan with its robot's rules,
//! runs the tree with its monitors, and on failure returns the task with
//! its fault record. Both agents tick on one clock in one world; the
//! challenges happen as ARIAC triggers them; submitted orders are scored as
//! the competition scores them ([`scoring`]).

pub mod challenges;
pub mod facts;
pub mod report;
pub mod scoring;
pub mod tasks;

mod run;

pub use report::{OrderReport, Spread, TrialReport, TrialsSummary};
pub use run::{Runner, TrialError, TrialOptions};
