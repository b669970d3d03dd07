//! What a search is asked (the algorithm, heuristic, time and improvement
//! budget) and what it answers (a plan, unsolvable, a timeout, and its
//! statistics): shared by the eager searches, LAMA and its lazy search.

use crate::heuristic::Heuristic;
use std::time::Duration;

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Algorithm {
    /// LAMA's search: lazy greedy search with h_FF, landmarks and preferred
    /// operators, then restarts that improve the plan within
    /// [`Options::improve`] ([`crate::lama`]). The heuristic option is not
    /// used.
    Lama,
    /// Eager greedy best-first search: fast, not necessarily optimal.
    Gbfs,
    /// A*: optimal with an admissible heuristic.
    Astar,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Options {
    pub algorithm: Algorithm,
    pub heuristic: Heuristic,
    /// Stop after this long (with `Lama`, the best plan found by then is
    /// the answer).
    pub timeout: Option<Duration>,
    /// `Lama`: the work the restarts may spend improving the first plan
    /// ([`crate::lazy::Counts::work`]: about the facts, relaxed operators
    /// and state words visited).
    /// A measure of work rather than time keeps the plan the same on every
    /// machine; 0 stops at the first plan.
    pub improve: u64,
}

/// The default base budget of the restarts (plus four times the first
/// search's work): a tenth to a third of a second, see docs/planner.md. Enough
/// for the restarts to match or beat lama-first's costs on the corpus and
/// the held-out problems (barman/p02 needs it: 106 with 10M or 20M, 94
/// with 30M).
pub const DEFAULT_IMPROVE: u64 = 30_000_000;

impl Default for Options {
    fn default() -> Self {
        Options {
            algorithm: Algorithm::Lama,
            heuristic: Heuristic::Ff,
            timeout: None,
            improve: DEFAULT_IMPROVE,
        }
    }
}

#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct SearchStats {
    /// The heuristic used (LM-cut falls back to h_max where it does not apply).
    pub heuristic: Option<Heuristic>,
    pub expanded: usize,
    pub generated: usize,
    pub evaluated: usize,
    pub time: Duration,
    /// `Lama`: searches run, the cost of the first plan, and whether a
    /// search proved the last plan optimal.
    pub iterations: usize,
    pub first_cost: Option<u64>,
    pub proved_optimal: bool,
    /// `Lama`: the work done ([`crate::lazy::Counts::work`]).
    pub work: u64,
}

#[derive(Clone, Debug, PartialEq, Eq)]
pub enum SearchResult {
    /// Operator indexes, in order, and their total cost.
    Plan(Vec<u32>, u64),
    /// The search space is exhausted (or the relaxation proves it).
    Unsolvable,
    Timeout,
}
