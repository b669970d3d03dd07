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
//!
//! The parts, by the paper's figure: `world` (the cell's shared state, the
//! parts, the belt and AGV trips, who holds what), `task_manager` (orders
//! to part tasks, the queues, requeue on failure) with `allocation` (the
//! rules, pure) and `allocate` / `resolve` (handing tasks out), `agent` and
//! `execute` (the execution level: plan, compile, run, preempt),
//! `challenges` (each kind a type) with `agility` (what they do to the
//! world), `orders` (quality checks, submission), `scoring`, `events` (the
//! typed events and causes, the trace observer), `report`. `model` is the
//! simulation whose `step` calls them in that order; `run` is the runner.

pub mod allocation;
pub mod challenges;
pub mod events;
pub mod facts;
pub mod report;
pub mod scoring;
pub mod tasks;

mod agent;
mod agility;
mod allocate;
mod execute;
mod invariants;
mod model;
mod options;
mod orders;
mod resolve;
mod run;
mod task_manager;
mod world;

pub use options::{TrialError, TrialOptions};
pub use report::{OrderReport, Spread, TrialReport, TrialsSummary};
pub use run::Runner;
