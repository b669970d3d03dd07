//! The closed loop on top of the runtime, the planner and the rules
//! language: an agent that plans, compiles the plan into a tree, runs it in
//! the simulated world and replans from what a fault left ([`replan`]), and
//! the ARIAC task level above it: trial files ([`trial`]).
//!
//! This is the only crate that puts the three together; the runtime knows
//! nothing of planning or of the rules database.

pub mod cell;
pub mod execution;
pub mod faults;
pub mod matrix;
pub mod random;
pub mod replan;
pub mod sim;
pub mod trial;

pub use replan::{
    run_loop, run_loop_outside, run_loop_traced, run_loop_with, Executed, Executor, Handoff,
    InstallLeaves, LoopError, LoopOptions, LoopSummary,
};
