//! How a trial runs, and how it can fail.

use btc_pddl::diagnostic::Diagnostic;

/// How a trial runs.
#[derive(Clone, Debug)]
pub struct TrialOptions {
    /// Seeds what ARIAC leaves to chance: a random conveyor order, the
    /// human's moves.
    pub seed: u64,
    /// Record the trace (task events and every tree's status changes).
    pub trace: bool,
    /// Check the world after every tick: each part in one place, no
    /// resource held by two tasks, no robot holding two things (the soak
    /// test's invariants). A violation stops the trial with an error.
    pub check: bool,
    /// Attempts at one part task before it is given up.
    pub max_attempts: u32,
    /// Trial seconds to stop at when the trial has no time limit.
    pub max_seconds: f64,
    pub planner: btc_planner::Options,
}

impl Default for TrialOptions {
    fn default() -> Self {
        TrialOptions {
            seed: 1,
            trace: false,
            check: false,
            max_attempts: 4,
            max_seconds: 3600.0,
            // An agent replans on line, between ticks: it takes LAMA's
            // first plan (no restarts) rather than spend the default
            // improvement budget on every part task.
            planner: btc_planner::Options {
                timeout: Some(std::time::Duration::from_secs(10)),
                improve: 0,
                ..btc_planner::Options::default()
            },
        }
    }
}

#[derive(Debug)]
pub enum TrialError {
    /// The cell's rules or its problem for this trial do not check.
    Cell(Vec<Diagnostic>),
    /// The world broke an invariant (a bug in the simulation or the cell's
    /// domain): what, and at which tick.
    Inconsistent { tick: u64, what: String },
}
